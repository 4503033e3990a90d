"""Helpers shared by the two trail-paper sections (``blazing_a_trail``, ``try_to_see_it_my_way``).

Rows are the sweep store's rows (one per trial; metrics flattened into the row). Everything here
is plain numbers in, report blocks out.
"""

from __future__ import annotations

import json
import math
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from teamnav.experiments.report.model import Missing, Series

#: cruise speed of every trail scenario [m/s] (robots' ``params.cruise_speed_mps``)
CRUISE_MPS = 0.4
#: the drift grid of the blazing-drift / try-drift sweeps [deg/min]
DRIFT_KEY = "robots.0.odometry.heading_drift_deg_per_min"
TRAIL_BRAINS = ("blazing-trail-v1", "trail-share-v1")
#: a team "works" when it delivers at least this many units per 10 minutes (the paper's 4 robots
#: delivered ~9 per 10 min before the breakdown; one optimal robot delivers ~4)
WORKING_UNITS_PER_10MIN = 1.0


def brains_missing(names: Iterable[str]) -> Missing | None:
    """A Missing block when a brain the section needs is not registered yet."""
    from teamnav.control import registry

    lacking = [n for n in names if n not in registry.names()]
    if not lacking:
        return None
    return Missing(f"runs of {', '.join(lacking)}", "the brain is not registered yet (teamnav.control.registry)")


def ok(result: Any) -> list[dict]:
    """Rows of a sweep result whose trial finished."""
    return [r for r in result.rows() if r.get("status") == "ok"]


def values(rows: Sequence[dict], key: str) -> np.ndarray:
    """Finite values of metric ``key`` over ``rows``."""
    out = []
    for r in rows:
        v = r.get(key)
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            out.append(float(v))
    return np.asarray(out, dtype=float)


def msd(xs: np.ndarray, fmt: str = "{:.1f}", unit: str = "") -> str:
    """``"m ± s (n = k)"``, or ``"n/a"`` for no values."""
    if xs.size == 0:
        return "n/a"
    sd = float(xs.std(ddof=1)) if xs.size > 1 else 0.0
    u = f" {unit}" if unit else ""
    return f"{fmt.format(float(xs.mean()))} ± {fmt.format(sd)}{u} (n = {xs.size})"


def mean(xs: np.ndarray) -> float:
    return float(xs.mean()) if xs.size else float("nan")


def by_param(rows: Sequence[dict], key: str) -> dict[Any, list[dict]]:
    """Rows grouped by the value of sweep parameter ``key`` (in first-seen order)."""
    out: dict[Any, list[dict]] = {}
    for r in rows:
        v = (r.get("params") or {}).get(key)
        out.setdefault(json.dumps(v) if isinstance(v, (list, dict)) else v, []).append(r)
    return out


def cumulative(rows: Sequence[dict], t_s: np.ndarray, key: str = "units_series") -> np.ndarray:
    """(n_rows, len(t_s)) cumulative count at each time from each row's ``[[t, k], ...]`` series."""
    out = np.zeros((len(rows), t_s.size))
    for i, r in enumerate(rows):
        text = r.get(key)
        if not isinstance(text, str):
            continue
        pts = np.asarray(json.loads(text), dtype=float).reshape(-1, 2)
        idx = np.searchsorted(pts[:, 0], t_s, side="right") - 1
        out[i] = np.where(idx >= 0, pts[np.clip(idx, 0, None), 1], 0.0)
    return out


def band_series(label: str, rows: Sequence[dict], t_s: np.ndarray, *, scale_x: float = 1 / 60.0,
                key: str = "units_series") -> Series | None:
    """Mean cumulative units over time with a 10–90 % band over the rows (None for no rows)."""
    if not rows:
        return None
    c = cumulative(rows, t_s, key)
    lo, hi = np.percentile(c, 10, axis=0), np.percentile(c, 90, axis=0)
    return Series(f"{label} (n = {len(rows)})", (t_s * scale_x).tolist(), c.mean(axis=0).tolist(),
                  lo.tolist(), hi.tolist())


def per_drift(rows: Sequence[dict], key: str, stat: Callable[[np.ndarray], float] = np.median) -> tuple[list, list, list, list]:
    """(drift, stat, 25 %, 75 %) of metric ``key`` per drift value of the drift sweeps."""
    xs, ys, lo, hi = [], [], [], []
    groups = by_param(rows, DRIFT_KEY)
    for d in sorted(groups, key=lambda v: float(v)):
        v = values(groups[d], key)
        if v.size == 0:
            continue
        xs.append(float(d))
        ys.append(float(stat(v)))
        lo.append(float(np.percentile(v, 25)))
        hi.append(float(np.percentile(v, 75)))
    return xs, ys, lo, hi


def time_grid(duration_s: float, n: int = 61) -> np.ndarray:
    return np.linspace(0.0, float(duration_s), n)
