"""Figures and replays: read recorded runs only."""
