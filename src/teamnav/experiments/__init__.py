"""Scenario files, runner, metrics, sweeps and reports."""
