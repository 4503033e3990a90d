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

# the profiled runs (memory and CPU over a long run) are in _trails_profile; importable from here as before
from teamnav.papers.trails.report._trails_profile import (  # noqa: F401
    _rss_mb, long_run_profile, profile_run, profile_trial,
)

#: the 2002 paper's per-robot heading drift [deg/min] (Try §3.6: "Bug's coordinate system rotated
#: clockwise; the other robots' systems drifted anti-clockwise. Tanis' system rotated only by
#: around 0.35° per minute, while Fly's rotated at 2° per minute"; Bug's and Ant's rates are not
#: given: 1 deg/min). The drift sweeps (blazing-drift, try-drift) scale it by k, case ``x<k>``.
DRIFT_PATTERN = {"Bug": -1.0, "Ant": 1.0, "Fly": 2.0, "Tanis": 0.35}
#: the pattern as text ("Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min")
DRIFT_TEXT = ", ".join(f"{n} {v:+g}" for n, v in DRIFT_PATTERN.items()) + " deg/min"
#: drift-sweep runs shorter than this [s] get no breakdown verdict (quick mode: a 5-minute run
#: cannot show a 27-minute breakdown)
MIN_VERDICT_S = 1800.0
#: how the drift sweeps' axis reads in the figures
DRIFT_AXIS = "drift scale k (x Bug -1, Ant +1, Fly +2, Tanis +0.35 deg/min)"
TRAIL_BRAINS = ("blazing-trail-v1", "trail-share-v1")
#: a team "works" when it delivers at least this many units per 10 minutes (the paper's 4 robots
#: delivered ~9 per 10 min before the breakdown; one optimal robot delivers ~4)
WORKING_UNITS_PER_10MIN = 1.0
#: the map every trail scenario runs on (the U shape since 9fe1783, 2026-11-27; trail_office_z_corridors
#: is the Z map before it)
TRAIL_MAP = "trail_office_corridors"
#: the 2002 paper's cruise speed (Try §3.6: "The Navigate behavior drives the robots at 0.25m s^-1
#: when cruising freely"), the try-to-see-it-my-way paper column's
PAPER_CRUISE_MPS = 0.25
#: the 2000 paper's route [m], round trip [s] and first arrival at the resource [s] (Blazing §5:
#: "approximately 33m of corridors"; §5.1: "the time for a round-trip from home to resource is
#: approximately 3 minutes", "Ant was the first robot to reach the resource, at 1.25 minutes")
BLAZING_ROUTE_M, BLAZING_ROUND_TRIP_S, BLAZING_FIRST_ARRIVAL_S = 33.0, 180.0, 75.0
#: the cruise speed the 2000 paper's numbers imply, the blazing-a-trail paper column's [m/s]: a round
#: trip of 2 x 33 m in ~180 s is 0.367 m/s on average, and at the 2002 paper's 92 % of cruise (the same
#: robots, Navigate and building) a cruise of 0.367 / 0.92 = 0.40 m/s; Ant's first 33 m in 75 s is
#: 0.44 m/s on average: 0.37-0.44 m/s, and 0.4 inside it (0.25 m/s cannot give a round trip under
#: 2 x 33 / 0.25 = 264 s). The 2000 paper states no speed: ``implied`` in the ledger.
BLAZING_IMPLIED_CRUISE_MPS = 0.4
#: the two columns of every trail table: (key, heading)
COLUMNS = (("paper_rules", "paper as written"), ("teamnav", "teamnav"))


def paper_rules_spec(name_or_spec: Any, cruise_mps: float | None = None, **kwargs: Any):
    """Sweep ``name_or_spec`` (with ``resolve_spec``'s ``seeds``, ``duration_s``, ``set``...) as
    the papers wrote it: every robot group whose brain declares ``PAPER_RULES``
    (:mod:`teamnav.control.paper_rules`) gets ``paper_rules: true`` and loses the params those rules
    set (for trail-share-v1 its cruise speed among them: 0.25 m/s); any other brain with a cruise
    speed (the route-follow-v1 baseline) drives at :data:`PAPER_CRUISE_MPS`. Named
    ``<sweep>-paper-rules``.

    ``cruise_mps``: the column's cruise speed for every group whose paper rules do not set one
    (blazing-trail-v1: the 2000 paper states none, :data:`BLAZING_IMPLIED_CRUISE_MPS`) and for
    the other brains with a cruise speed; None: as above (the route-follow baseline at
    :data:`PAPER_CRUISE_MPS`, rule brains as their rules and scenario leave them). A name other
    than 0.25 m/s gets its speed in the sweep's name (``<sweep>-paper-rules-0.4``).
    """
    from teamnav.control import registry
    from teamnav.experiments.spec import load_scenario
    from teamnav.experiments.sweep import resolve_spec

    spec = resolve_spec(name_or_spec, **kwargs)
    scen = load_scenario(spec.scenario)
    extra: dict[str, Any] = {}
    for i, group in enumerate(scen.robots):
        controller = spec.set.get(f"robots.{i}.controller", group.controller)
        params = dict(spec.set.get(f"robots.{i}.params", group.params) or {})
        cls = getattr(registry.lookup(controller), "Params", None)
        rules = getattr(cls, "PAPER_RULES", None)
        if rules:
            for key in rules:
                head, _, tail = key.partition(".")
                if not tail:
                    params.pop(head, None)
                elif isinstance(params.get(head), dict):
                    params[head] = {k: v for k, v in params[head].items() if k != tail}
            nested = getattr(cls, "PAPER_RULES_NESTED", {})
            for head, (model, _) in nested.items():
                if isinstance(params.get(head), dict):
                    params[head] = {k: v for k, v in params[head].items() if k not in getattr(model, "PAPER_RULES", {})}
            params["paper_rules"] = True
            if cruise_mps is not None and "cruise_speed_mps" not in rules and "cruise_speed_mps" in cls.model_fields:
                params["cruise_speed_mps"] = float(cruise_mps)
        elif "cruise_speed_mps" in params:
            params["cruise_speed_mps"] = PAPER_CRUISE_MPS if cruise_mps is None else float(cruise_mps)
        extra[f"robots.{i}.params"] = params
    tail = "" if cruise_mps is None or float(cruise_mps) == PAPER_CRUISE_MPS else f"-{float(cruise_mps):g}"
    return resolve_spec(spec, set=extra, name=f"{spec.sweep_name}-paper-rules{tail}")


def column_sweep(ctx: Any, column: str, name_or_spec: Any, *, cruise_mps: float | None = None,
                 **kwargs: Any) -> list[dict]:
    """The finished rows of a sweep in one of the :data:`COLUMNS` (``"paper_rules"`` or ``"teamnav"``);
    ``cruise_mps``: the paper column's cruise speed (:func:`paper_rules_spec`; ignored for teamnav)."""
    if column == "paper_rules":
        # the spec carries the paper's params; seeds, duration and the rest are applied by ctx.sweep as for teamnav
        return ok(ctx.sweep(paper_rules_spec(name_or_spec, cruise_mps), **kwargs))
    return ok(ctx.sweep(name_or_spec, **kwargs))


def claim_rows(claims: Any, values: dict[str, dict[str, float]], verdicts: dict[str, dict[str, tuple]]) -> list[list]:
    """Rows of a section's claim table: claim, paper's number, rule (claim file), then per column the
    claim's metric and its verdict, and the rule's history."""
    from teamnav.experiments.claims import history_text, rule_text

    rows = []
    for c in claims.claims:
        row = [c.title, c.paper_number, rule_text(c)]
        for col, _ in COLUMNS:
            v = values.get(col, {}).get(c.id, {}).get(c.metric, float("nan"))
            h, _text = verdicts.get(col, {}).get(c.id, (None, ""))
            verdict = "holds" if h else ("does not hold" if h is not None else "not judged")
            row.append(f"{c.metric} = {v:.3g} ({verdict})" if isinstance(v, float) and math.isfinite(v) else f"n/a ({verdict})")
        row.append(history_text(c))
        rows.append(row)
    return rows


def gap_fill_rows(params_cls: type, ours: dict) -> list[list]:
    """Rows of a gap-fill table: field, teamnav value, paper value, where the paper says so."""
    from teamnav.control.paper_rules import gap_fills

    return [[g.field, repr(g.teamnav_value), repr(g.paper_value), g.note] for g in gap_fills(params_cls, ours)]


def cruise_mps(scenario: str = "try-to-see-it-my-way") -> float:
    """The cruise speed of the scenario's first robot group [m/s] (the efficiency's denominator)."""
    from teamnav.experiments.spec import load_scenario

    return float(load_scenario(scenario).robots[0].params["cruise_speed_mps"])


def drift_scale(row_or_case: dict) -> float | None:
    """k of a drift-sweep case (``"x0.5"`` -> 0.5), from a case dict or a row's params; None if none."""
    label = row_or_case.get("case", (row_or_case.get("params") or {}).get("case"))
    if not isinstance(label, str) or not label.startswith("x"):
        return None
    try:
        return float(label[1:])
    except ValueError:
        return None


def drift_spec(name: str, scales: Sequence[float]):
    """Sweep ``name`` (blazing-drift / try-drift) with only the cases of drift scales ``scales``.

    Raises
    ------
    ValueError
        A scale that the sweep has no case for.
    """
    from teamnav.experiments.sweep import load_sweep

    spec = load_sweep(name)
    have = {drift_scale(c): c for c in spec.cases}
    lacking = [k for k in scales if k not in have]
    if lacking:
        raise ValueError(f"sweep {name!r}: no drift case for scale(s) {lacking}; it has {sorted(k for k in have if k is not None)}")
    return spec.model_copy(update={"cases": [have[k] for k in scales]})


#: the drift sweeps' wheel-scale-error cases (Bug +5 %, Ant -5 %, Fly +3 %, Tanis -3 %): alone and with k = 1
SCALE_CASES = ("scale5", "x1-scale5")


def case_spec(name: str, labels: Sequence[str]):
    """Sweep ``name`` with only the cases labelled ``labels`` (in that order).

    Raises
    ------
    ValueError
        A label the sweep has no case for.
    """
    from teamnav.experiments.sweep import load_sweep

    spec = load_sweep(name)
    have = {c.get("case"): c for c in spec.cases}
    lacking = [k for k in labels if k not in have]
    if lacking:
        raise ValueError(f"sweep {name!r}: no case {lacking}; it has {sorted(str(k) for k in have)}")
    return spec.model_copy(update={"cases": [have[k] for k in labels]})


def by_case(rows: Sequence[dict]) -> dict[str, list[dict]]:
    """Rows grouped by their case label."""
    out: dict[str, list[dict]] = {}
    for r in rows:
        out.setdefault(str((r.get("params") or {}).get("case")), []).append(r)
    return out


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


def by_scale(rows: Sequence[dict]) -> dict[float, list[dict]]:
    """Drift-sweep rows grouped by drift scale k, in increasing k."""
    out: dict[float, list[dict]] = {}
    for r in rows:
        k = drift_scale(r)
        if k is not None:
            out.setdefault(k, []).append(r)
    return dict(sorted(out.items()))


def per_drift(rows: Sequence[dict], key: str, stat: Callable[[np.ndarray], float] = np.median) -> tuple[list, list, list, list]:
    """(drift scale k, stat, 25 %, 75 %) of metric ``key`` per case of the drift sweeps."""
    xs, ys, lo, hi = [], [], [], []
    for k, group in by_scale(rows).items():
        v = values(group, key)
        if v.size == 0:
            continue
        xs.append(k)
        ys.append(float(stat(v)))
        lo.append(float(np.percentile(v, 25)))
        hi.append(float(np.percentile(v, 75)))
    return xs, ys, lo, hi


def first_part(row: dict, t_end_s: float, case: str | None = None) -> dict:
    """The first ``t_end_s`` seconds of a longer run, as the row of a run that long.

    The drift sweeps' 1-hour point at a drift k is read from the first hour of the long runs at
    that drift (the 3-hour try-paper runs at k = 1, the hours runs at k = 4) instead of being run
    again: a run does not know its length (no brain reads the clock's end), so its first hour is a
    1-hour run of the same seed. Recomputed from the row's ``units_series`` (delivery times to
    0.01 s): ``units_total``, the 10-minute windows (``units_per_10min_series``, ``_last``,
    ``_peak``, ``_mean``) and the breakdown (:data:`teamnav.papers.trails.metrics.BREAKDOWN_GAP_S`);
    ``params`` get ``duration_s`` and, when given, ``case`` (e.g. ``"x4"``). Every other metric
    of the long run is left out (it belongs to the whole run).

    Raises
    ------
    ValueError
        ``t_end_s`` not positive or the row has no ``units_series``.

    >>> r = {"seed": 3, "status": "ok", "params": {}, "units_series": "[[0,0],[100,1],[700,2],[3500,3],[4000,4]]"}
    >>> p = first_part(r, 3600.0, "x4")
    >>> p["units_total"], p["units_per_10min_last"], p["breakdown_censored"], p["params"]["case"]
    (3, 1, 1, 'x4')
    >>> first_part(r, 3000.0)["breakdown_s"]
    700.0
    """
    from teamnav.papers.trails.metrics import BREAKDOWN_GAP_S, WINDOW_S

    text = row.get("units_series")
    if not (t_end_s > 0) or not isinstance(text, str):
        raise ValueError(f"first_part: expected t_end_s > 0 and a row with units_series, got {t_end_s!r} and "
                         f"{'no' if not isinstance(text, str) else 'a'} units_series")
    pts = np.asarray(json.loads(text), dtype=float).reshape(-1, 2)
    times = [float(t) for t, k in pts if k > 0 and t <= t_end_s]
    n_win = max(1, int(math.ceil(t_end_s / WINDOW_S - 1e-9)))
    win = np.zeros(n_win, dtype=int)
    for t in times:
        win[min(n_win - 1, int(t // WINDOW_S))] += 1
    if not times:
        bd, cens = 0.0, 0
    elif t_end_s - times[-1] >= BREAKDOWN_GAP_S:
        bd, cens = times[-1], 0
    else:
        bd, cens = float(t_end_s), 1
    params = {**(row.get("params") or {}), "duration_s": float(t_end_s)}
    if case is not None:
        params["case"] = case
    return {
        "seed": row.get("seed"), "status": row.get("status", "ok"), "params": params,
        "units_total": len(times), "units_per_10min_last": int(win[-1]), "units_per_10min_peak": int(win.max()),
        "units_per_10min_mean": float(len(times) / (t_end_s / WINDOW_S)), "breakdown_s": float(bd),
        "breakdown_censored": cens, "units_per_10min_series": json.dumps(win.tolist()),
        "units_series": json.dumps([[0.0, 0]] + [[t, i + 1] for i, t in enumerate(times)], separators=(",", ":")),
        "from_long_run_s": float(((row.get("params") or {}).get("duration_s")) or float("nan")),
    }


def survival(rows: Sequence[dict], t_s: np.ndarray) -> np.ndarray:
    """Fraction of runs not broken down by each time in ``t_s`` (Kaplan–Meier).

    A run's time is its ``breakdown_s``; ``breakdown_censored = 1`` marks a run that did not
    break down before it ended (censored at its length). With runs of one length this is the
    fraction of runs whose breakdown comes after t; the product-limit form also takes runs of
    different lengths.

    >>> rows = [{"breakdown_s": 600.0, "breakdown_censored": 0}, {"breakdown_s": 1200.0, "breakdown_censored": 0},
    ...         {"breakdown_s": 3600.0, "breakdown_censored": 1}, {"breakdown_s": 3600.0, "breakdown_censored": 1}]
    >>> survival(rows, np.array([0.0, 600.0, 900.0, 1200.0, 3600.0])).tolist()
    [1.0, 0.75, 0.75, 0.5, 0.5]
    """
    t_s = np.asarray(t_s, dtype=float)
    runs = [(float(r["breakdown_s"]), not bool(r.get("breakdown_censored")))
            for r in rows if isinstance(r.get("breakdown_s"), (int, float)) and math.isfinite(r["breakdown_s"])]
    out = np.ones(t_s.size)
    if not runs:
        return np.full(t_s.size, np.nan)
    times = np.array([t for t, _ in runs])
    s = 1.0
    for te in sorted({t for t, broke in runs if broke}):
        at_risk = int((times >= te).sum())
        d = sum(1 for t, broke in runs if broke and t == te)
        s *= 1.0 - d / at_risk
        out[t_s >= te] = s
    return out


def breakdown_marks(rows: Sequence[dict]) -> tuple[list, list, list, list]:
    """Each run's breakdown against its drift scale: (k, min) of the runs that broke down and
    (k, min) of those that did not (censored: at the run's length)."""
    bx, by, cx, cy = [], [], [], []
    for k, group in by_scale(rows).items():
        for r in group:
            t = r.get("breakdown_s")
            if not isinstance(t, (int, float)):
                continue
            if r.get("breakdown_censored"):
                cx.append(k)
                cy.append(float(t) / 60.0)
            else:
                bx.append(k)
                by.append(float(t) / 60.0)
    return bx, by, cx, cy


def spearman(x: Sequence[float], y: Sequence[float]) -> float:
    """Spearman's rank correlation (average ranks for ties); NaN for fewer than 3 pairs or a constant.

    >>> round(spearman([0, 1, 2, 3], [9, 7, 7, 1]), 3)
    -0.949
    """
    a, b = np.asarray(x, float), np.asarray(y, float)
    if a.size < 3 or a.size != b.size:
        return float("nan")

    def ranks(v: np.ndarray) -> np.ndarray:
        order = np.argsort(v, kind="mergesort")
        r = np.empty(v.size)
        r[order] = np.arange(v.size, dtype=float)
        for u in np.unique(v):  # ties share their mean rank
            m = v == u
            r[m] = r[m].mean()
        return r

    ra, rb = ranks(a), ranks(b)
    if ra.std() == 0 or rb.std() == 0:
        return float("nan")
    return float(np.corrcoef(ra, rb)[0, 1])


def drift_trend(rows: Sequence[dict], key: str) -> float:
    """Spearman correlation of metric ``key`` with the drift scale k over all runs of a drift sweep."""
    xs, ys = [], []
    for k, group in by_scale(rows).items():
        v = values(group, key)
        xs += [k] * v.size
        ys += v.tolist()
    return spearman(xs, ys)


def units_per_hour(row: dict, duration_s: float) -> list[int]:
    """Units delivered in each whole hour of a run (from its ``units_series``).

    >>> units_per_hour({"units_series": "[[0,0],[100,1],[3700,2],[3800,3]]"}, 7200.0)
    [1, 2]
    """
    text = row.get("units_series")
    if not isinstance(text, str):
        return []
    pts = np.asarray(json.loads(text), dtype=float).reshape(-1, 2)
    times = pts[pts[:, 1] > 0, 0]
    n = int(duration_s // 3600.0)
    return [int(((times > 3600.0 * h) & (times <= 3600.0 * (h + 1))).sum()) for h in range(n)]


def crumb_views(row: dict, names: Sequence[str], what: str) -> list:
    """The papers' crumb figures from one run's ``trails_crumbs`` series (MapView blocks).

    Own frame per robot (Try Fig. 3 top, Blazing Fig. 6) and every robot's crumbs in the fixed
    global frame of the places (Try Fig. 4). A Missing block when the row has no crumbs.
    """
    from teamnav.experiments.report.model import MapView
    from teamnav.world import builtin_map

    own, glob = row.get("crumbs_own_series"), row.get("crumbs_global_series")
    if not isinstance(own, str) or not isinstance(glob, str):
        return [Missing(f"crumb plots ({what})", "the run has no trails_crumbs metric (add it to the sweep's metrics)")]
    grid = builtin_map(TRAIL_MAP).grid
    own_d, glob_d = json.loads(own), json.loads(glob)

    def clouds(d: dict) -> list:
        return [(names[int(r)] if int(r) < len(names) else f"robot {r}", np.asarray(v, float).reshape(-1, 2))
                for r, v in sorted(d.items(), key=lambda kv: int(kv[0]))]

    seed = row.get("seed", "?")
    return [
        MapView(f"Crumbs each robot dropped, in its own odometry frame ({what}, seed {seed})", grid, clouds(own_d),
                caption="one crumb per 10 s; frames start aligned with the map, so drift shows as each robot's "
                        "trail rotating away from the corridors (Try Fig. 3, Blazing Fig. 6)"),
        MapView(f"All crumbs in a fixed global frame of the Places ({what}, seed {seed})", grid, clouds(glob_d),
                caption="each crumb mapped by the similarity that takes its robot's Place estimates at that time "
                        "onto fixed home and source points: what a receiver makes of them (Try Fig. 4)"),
    ]


def time_grid(duration_s: float, n: int = 61) -> np.ndarray:
    return np.linspace(0.0, float(duration_s), n)
