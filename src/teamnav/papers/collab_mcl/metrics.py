"""Localization metrics of Fox, Burgard, Kruppa & Thrun (collaborative MCL).

The paper's error measure (§5.1): "The estimation error is measured by the average distance
of all samples from the reference position". The brain (``mcl-wander-v1``) never sees the
truth, so it logs, every recorded step, ``pts``: K particles (K = 64 by default) drawn from
its weighted sample set by low-variance resampling. Their plain mean distance to the true
position is an unbiased estimate of the weighted average over all samples, with a sampling
error of about ``std(distance) / sqrt(K)`` (for a belief split 50/50 between two modes 20 m
apart, ±1.3 m; for a localized belief a few cm). The true position is the recorder's true
pose at the same step.

Per run:

- ``loc_time_to_localize_s``: mean over robots of the first time the error falls below
  ``LOCALIZED_M`` = 1.5 m (§5.2.1: "a robot has successfully localized itself, if the
  localization error falls below 1.5 meters"). A robot that never does is *censored* at the
  run's duration (its time counts as the duration: the mean is then a lower bound);
  ``loc_censored`` counts them;
- ``loc_localized_fraction``: robots whose error fell below 1.5 m at some time;
  ``loc_final_localized_fraction``: robots below 1.5 m at the end;
- ``loc_final_error_m``: mean error at the last recorded step; ``loc_mean_error_m``: mean
  over the whole run (area under the error curve over the duration);
- the same three, per sensor kind (``_sonar``, ``_laser``) and per robot group
  (``_g_<group>``) when a run has more than one;
- ``loc_syncs``: belief updates applied from detections (both directions), summed over robots;
- ``loc_error_series``: JSON ``{"t_s": [...], "mean": [...], "by_kind": {kind: [...]},
  "by_group": {group: [...]}, "per_robot": [[...], ...]}``, at most 300 time points.

Runs without ``pts`` logs (other papers' scenarios) give ``{}``.
"""

from __future__ import annotations

import json
import math

import numpy as np

from teamnav.experiments.metrics import RunData, register

__all__ = ["HEADLINE", "LOCALIZED_M", "MODE_RADIUS_M", "belief_modes", "error_matrix", "heaviest_mode"]

#: what ``teamnav run`` prints of these metrics (see :mod:`teamnav.experiments.metric_sets`)
HEADLINE: dict[str, tuple[tuple[str, str], ...]] = {
    "localization": (
        ("loc_time_to_localize_s", "s"),
        ("loc_censored", "robots"),
        ("loc_localized_fraction", "fraction"),
        ("loc_final_localized_fraction", "fraction"),
        ("loc_final_error_m", "m"),
        ("loc_mean_error_m", "m"),
        ("loc_syncs", "updates"),
    ),
}

#: Fox et al. §5.2.1: a robot is localized once its error is below this [m].
LOCALIZED_M: float = 1.5
_MAX_SERIES = 300


#: §5.1 precondition: a "mode" is the samples within this of one sample [m]
MODE_RADIUS_M: float = 1.0


def heaviest_mode(pts, radius_m: float = MODE_RADIUS_M) -> float:
    """The heaviest mode of a belief given as points drawn by weight: the largest share of the
    points within ``radius_m`` of one of them (the §5.1 precondition's measure, rule 3 of
    docs/report/collab-mcl.md "2026-11-29").

    Examples
    --------
    >>> heaviest_mode([[0, 0], [0.5, 0], [10, 0], [20, 0]])
    0.5
    """
    p = np.asarray(pts, dtype=float).reshape(-1, 2)
    if p.shape[0] == 0:
        raise ValueError("pts must hold at least one point")
    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    return float((d <= radius_m).sum(axis=1).max() / p.shape[0])


def belief_modes(pts, link_m: float = 1.5, min_share: float = 0.1) -> int:
    """Number of modes of a belief given as points drawn by weight: groups of points joined by
    single linkage at ``link_m`` that hold at least ``min_share`` of them (the hexagon's counts,
    rule 4 of docs/report/collab-mcl.md "2026-11-29").

    Examples
    --------
    >>> belief_modes([[0, 0], [1, 0], [2, 0], [9, 9], [9, 10], [30, 0]], min_share=0.2)
    2
    """
    p = np.asarray(pts, dtype=float).reshape(-1, 2)
    n = p.shape[0]
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    d = np.hypot(p[:, None, 0] - p[None, :, 0], p[:, None, 1] - p[None, :, 1])
    for i, j in zip(*np.nonzero(np.triu(d <= link_m, 1))):
        parent[find(i)] = find(j)
    roots = [find(i) for i in range(n)]
    sizes = np.unique(roots, return_counts=True)[1]
    return int((sizes >= min_share * n).sum())


def error_matrix(data: RunData) -> tuple[np.ndarray, np.ndarray, list[str], list[str]] | None:
    """Per-robot error over time from the brains' logged particle subsamples.

    Returns
    -------
    (t_s (T,), err (T, N) [m] with NaN where a robot logged nothing, kinds (N,), groups (N,)),
    or None when no robot logged ``pts``.
    """
    recs = [r for r in data.logs if isinstance(r.get("values"), dict) and "pts" in r["values"]]
    if not recs:
        return None
    steps = sorted({int(r["step"]) for r in recs})
    col = {s: i for i, s in enumerate(steps)}
    n = data.n_robots
    err = np.full((len(steps), n), np.nan)
    t = np.zeros(len(steps))
    kinds = [""] * n
    groups = [""] * n
    rec_t = np.asarray(data.t_s, dtype=float)
    for r in recs:
        v = r["values"]
        i = int(r["robot"])
        k = col[int(r["step"])]
        t[k] = float(r["t_s"])
        if "sensor_kind" in v:
            kinds[i] = str(v["sensor_kind"])
        if "group" in v:
            groups[i] = str(v["group"])
        j = int(np.argmin(np.abs(rec_t - float(r["t_s"]))))
        truth = data.true_pose[j, i]
        pts = np.asarray(v["pts"], dtype=float).reshape(-1, 2)
        err[k, i] = float(np.mean(np.hypot(pts[:, 0] - truth[0], pts[:, 1] - truth[1])))
    return t, err, kinds, groups


def _summary(t: np.ndarray, err: np.ndarray, horizon_s: float) -> dict[str, float]:
    """Time to localize (censored at ``horizon_s``), fractions and errors of a robot subset."""
    below = err < LOCALIZED_M
    first = np.where(below.any(axis=0), t[np.argmax(below, axis=0)], np.nan)
    censored = np.isnan(first)
    ttl = np.where(censored, horizon_s, first)
    last = np.array([e[~np.isnan(e)][-1] if (~np.isnan(e)).any() else np.nan for e in err.T])
    return {
        "time_to_localize_s": float(np.mean(ttl)),
        "censored": int(censored.sum()),
        "localized_fraction": float(np.mean(~censored)),
        "final_localized_fraction": float(np.mean(last < LOCALIZED_M)),
        "final_error_m": float(np.nanmean(last)),
        "mean_error_m": float(np.nanmean(err)),
    }


def localization(data: RunData) -> dict[str, float | int | str]:
    """The metrics of the module docstring."""
    m = error_matrix(data)
    if m is None:
        return {}
    t, err, kinds, groups = m
    horizon = float(data.n_steps * data.dt_s)
    out: dict[str, float | int | str] = {f"loc_{k}": v for k, v in _summary(t, err, horizon).items()}
    kind_set = sorted({k for k in kinds if k})
    group_set = sorted({g for g in groups if g})
    by_kind, by_group = {}, {}
    if len(kind_set) > 1:
        for kind in kind_set:
            sel = np.array([k == kind for k in kinds])
            s = _summary(t, err[:, sel], horizon)
            for key in ("time_to_localize_s", "localized_fraction", "final_localized_fraction", "final_error_m"):
                out[f"loc_{key}_{kind}"] = s[key]
            by_kind[kind] = np.nanmean(err[:, sel], axis=1)
    if len(group_set) > 1:
        for g in group_set:
            sel = np.array([x == g for x in groups])
            s = _summary(t, err[:, sel], horizon)
            for key in ("time_to_localize_s", "localized_fraction", "final_error_m", "mean_error_m"):
                out[f"loc_{key}_g_{g}"] = s[key]
            by_group[g] = np.nanmean(err[:, sel], axis=1)
    syncs = {}
    for r in data.logs:
        v = r.get("values")
        if isinstance(v, dict) and "syncs" in v:
            syncs[int(r["robot"])] = int(v["syncs"])
    out["loc_syncs"] = int(sum(syncs.values()))
    idx = np.unique(np.linspace(0, len(t) - 1, min(len(t), _MAX_SERIES)).round().astype(int))

    def r3(a):
        return [None if not math.isfinite(x) else round(float(x), 3) for x in np.asarray(a)[idx]]

    series = {
        "t_s": [round(float(x), 2) for x in t[idx]],
        "mean": r3(np.nanmean(err, axis=1)),
        "by_kind": {k: r3(v) for k, v in by_kind.items()},
        "by_group": {k: r3(v) for k, v in by_group.items()},
        "per_robot": [r3(err[:, i]) for i in range(err.shape[1])],
    }
    out["loc_error_series"] = json.dumps(series, separators=(",", ":"))
    return out


register("localization", localization,
         "Fox et al. localization error (mean distance of samples to the truth): time to < 1.5 m, fractions, series")
