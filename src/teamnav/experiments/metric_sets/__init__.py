"""Paper-specific metrics: the contract of a paper's metric set, and where the sets are found.

Each paper declares its metric sets (:attr:`teamnav.plugins.Paper.metric_sets`, ``{set name:
module}``, e.g. ``teamnav.papers.los_help.metrics``); :mod:`teamnav.experiments.metrics`
imports every installed paper's sets in the order of their names
(:func:`metric_set_modules`), and each module calls
:func:`teamnav.experiments.metrics.register` for its metrics. A metric function takes a
:class:`~teamnav.experiments.metrics.RunData` and returns a flat dict of numbers (or a JSON
string for a time series, key ending in ``_series``); it returns ``{}`` when the run lacks
its data (e.g. no brain logged what it reads), because ``metrics: []`` computes them all.

Headline metrics
----------------
A module may also declare ``HEADLINE``: for each metric it registers, the few keys (with
their units) that ``teamnav run`` prints in its table, in order; the rest stays in the run's
``metrics.json``. A metric listed with ``()`` has no headline (series only). A metric that
is declared nowhere gets its scalar keys shown, units read from the key's suffix (``_s``,
``_m``, ``_mps``, ...). :data:`CORE_HEADLINE` declares the general metrics of
:mod:`teamnav.experiments.metrics`.
"""

#: ``teamnav run``'s headline keys of the general metrics (:mod:`teamnav.experiments.metrics`
#: registers them; they are declared here with the paper metric sets' headlines):
#: ``{metric name: ((key, unit), ...)}``
CORE_HEADLINE: dict[str, tuple[tuple[str, str], ...]] = {
    "path_length": (("path_length_m_mean", "m"),),
    "mean_speed": (("mean_speed_mps", "m/s"),),
    "stall_fraction": (("stall_fraction", "fraction"),),
    "collisions": (("collisions_wall", "samples"), ("collisions_robot", "pairs")),
    "odometry_error": (("odom_error_m_mean", "m"),),
    "messages": (("messages_sent", "messages"),),
    "events": (("events_total", "events"),),
    "steps": (("sim_time_s", "s"),),
    "wall_time": (("wall_time_s", "s"),),
    "throughput": (("robot_steps_per_s", "robot-steps/s"),),
}


def metric_set_modules() -> dict[str, str]:
    """``{metric set name: module}`` of every installed paper, sorted by set name (the order
    in which they register, hence the order of a ``metrics: []`` run's ``metrics.json``)."""
    from teamnav import plugins

    found: dict[str, str] = {}
    for paper in plugins.papers().values():
        for name, module in paper.metric_sets.items():
            found.setdefault(name, module)
    return dict(sorted(found.items()))
