"""Brains that combine the four systems (issue 22): each module says which paper rules it composes."""
