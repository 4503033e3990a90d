"""Metrics of injected faults (scenario section ``faults``, :mod:`teamnav.sim.faults`).

The engine writes every fault, when it takes effect, into the run's event log as an entry
with a ``fault`` key (and ``event`` None, so task metrics ignore it). From those entries:

- ``fault_<kind>``: how many faults of each kind took effect: ``deaths``, ``radio_dropouts``,
  ``blackouts``, ``sensor_dropouts``, ``kidnappings``, ``false_positive_bursts``;
  ``fault_first_s``: the time of the first one [s];
- trail runs (:mod:`teamnav.papers.trails.metrics`): ``fault_units_per_hour_before`` / ``_after``: units delivered
  before / from the first fault, per hour of that part of the run (a robot lost at ``t`` leaves
  the team ``after``);
- localization runs (:mod:`teamnav.papers.collab_mcl.metrics`: brains that log particle subsamples), per
  kidnapping of robot ``i`` at ``t_k``: its error at the first logged sample at or after
  ``t_k`` (``fault_kidnap_error_m``, mean over kidnappings: how far the jump threw its belief),
  and the time from ``t_k`` until its error first falls below
  :data:`~teamnav.papers.collab_mcl.metrics.LOCALIZED_M` (1.5 m, Fox et al.'s "localized") again
  (``fault_relocalize_s``, mean; a robot that never does counts as the rest of the run:
  censored, the mean is then a lower bound; ``fault_relocalize_censored`` counts them,
  ``fault_relocalized_fraction`` is the share that did); a jump that left the error below
  1.5 m counts as re-localized at once. The error is the belief's distance to the true
  position, so a robot that drives through its own wrong (tight) belief cloud also counts:
  read it beside the localization metrics at the end of the run.

A run without faults gives ``{}``.
"""

from __future__ import annotations

import numpy as np

from teamnav.experiments.metrics import RunData, register

__all__ = ["FAULT_KINDS", "HEADLINE", "fault_entries", "fault_metrics"]

#: the fault entry that marks each kind taking effect -> the metric key's suffix
FAULT_KINDS: dict[str, str] = {
    "died": "deaths",
    "radio_off": "radio_dropouts",
    "blackout_start": "blackouts",
    "sensor_off": "sensor_dropouts",
    "kidnapped": "kidnappings",
    "false_positives_start": "false_positive_bursts",
}

#: what ``teamnav run`` prints of these metrics (see :mod:`teamnav.experiments.metric_sets`)
HEADLINE: dict[str, tuple[tuple[str, str], ...]] = {
    "faults": (
        ("fault_first_s", "s"),
        ("fault_units_per_hour_before", "units/h"),
        ("fault_units_per_hour_after", "units/h"),
        ("fault_kidnap_error_m", "m"),
        ("fault_relocalize_s", "s"),
        ("fault_relocalize_censored", "robots"),
    ),
}


def fault_entries(data: RunData) -> list[dict]:
    """The fault entries of the run's event log, in time order."""
    return sorted((e for e in data.event_log if isinstance(e, dict) and e.get("fault")), key=lambda e: e["t_s"])


def _trail_rates(data: RunData, t0: float) -> dict[str, float]:
    from teamnav.papers.trails.metrics import _is_trail_run, deliveries

    if not _is_trail_run(data):
        return {}
    dl = deliveries(data.event_log)
    end = float(data.n_steps * data.dt_s)
    out = {}
    before = sum(1 for t, _ in dl if t < t0)
    if t0 > 0:
        out["fault_units_per_hour_before"] = float(before * 3600.0 / t0)
    if end > t0:
        out["fault_units_per_hour_after"] = float((len(dl) - before) * 3600.0 / (end - t0))
    return out


def _relocalization(data: RunData, kidnaps: list[dict]) -> dict[str, float | int]:
    from teamnav.papers.collab_mcl.metrics import LOCALIZED_M, error_matrix

    m = error_matrix(data)
    if m is None:
        return {}
    t, err, _, _ = m
    end = float(data.n_steps * data.dt_s)
    thrown, times, censored = [], [], 0
    for e in kidnaps:
        i, tk = int(e["robot"]), float(e["t_s"])
        after = (t >= tk - 1e-9) & ~np.isnan(err[:, i])
        if not after.any():
            continue
        ts, es = t[after], err[after, i]
        thrown.append(float(es[0]))
        below = np.flatnonzero(es < LOCALIZED_M)
        if below.size:
            times.append(float(ts[below[0]] - tk))
        else:
            times.append(end - tk)
            censored += 1
    if not times:
        return {}
    return {
        "fault_kidnap_error_m": float(np.mean(thrown)),
        "fault_relocalize_s": float(np.mean(times)),
        "fault_relocalize_censored": int(censored),
        "fault_relocalized_fraction": float(1.0 - censored / len(times)),
    }


def fault_metrics(data: RunData) -> dict[str, float | int]:
    """The metrics of the module docstring; ``{}`` for a run without faults."""
    entries = fault_entries(data)
    if not entries:
        return {}
    out: dict[str, float | int] = {f"fault_{key}": 0 for key in FAULT_KINDS.values()}
    for e in entries:
        key = FAULT_KINDS.get(str(e["fault"]))
        if key is not None:
            out[f"fault_{key}"] += 1
    t0 = float(entries[0]["t_s"])
    out["fault_first_s"] = t0
    out.update(_trail_rates(data, t0))
    kidnaps = [e for e in entries if e["fault"] == "kidnapped"]
    if kidnaps:
        out.update(_relocalization(data, kidnaps))
    return out


register("faults", fault_metrics,
         "injected faults: how many of each kind, trail units per hour before / after the first, time to re-localize "
         "after a kidnapping")
