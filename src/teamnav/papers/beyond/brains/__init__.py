"""Brains that combine the four systems: each module says which paper rules it composes."""
