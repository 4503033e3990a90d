"""Paper-specific metrics, one module per system, registered on import.

Every module here is imported by :mod:`teamnav.experiments.metrics` and calls
:func:`teamnav.experiments.metrics.register` for its metrics. A metric function takes a
:class:`~teamnav.experiments.metrics.RunData` and returns a flat dict of numbers (or a JSON
string for a time series, key ending in ``_series``); it returns ``{}`` when the run lacks
its data (e.g. no brain logged what it reads), because ``metrics: []`` computes them all.
"""
