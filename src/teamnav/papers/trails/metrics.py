"""Metrics of the trail papers (Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* 2000 and
*Try to see it my way* 2002): resource transported, trips, breakdown, efficiency, memory.

They read the task events (``RunData.event_log``: which robot reached which place when; the
experimenter's notes of §5 / §3.5), the true trajectories (distance travelled) and the brains'
logs (``n_crumbs``); they never steer. Event names are the scenarios' (``trail_office``):
``took_resource`` fires at the source, ``given_resource`` at home.

Definitions (each with the paper passage it stands for):

- **unit delivered** (Blazing §5: "every time a robot has completed a home-resource-home round
  trip ... the time and the name of the robot is noted"): a home event (``given_resource``) of
  a robot that has had a source event (``took_resource``) since its previous home event.
- **trip** (Try §3.5: "every time a robot completed an A-B or B-A trip"): two consecutive place
  events of one robot at *different* places; its time is the time between them. Robots start at
  home inside its radius (no event fires there), so each robot's first event, when not at home,
  closes a trip that started at t = 0 (its initial search).
- **first trail** (Blazing §5.1: "Ant was the first robot to reach the resource, at 1.25
  minutes. It broadcasts the first crumb trail"): the first source event of any robot. Trips
  that *start* at or after it are "after the first broadcast".
- **throughput**: units delivered in consecutive 10-minute windows from t = 0 (Blazing Fig. 5
  right); ``units_per_10min_peak`` is the best window.
- **breakdown time** (Blazing §5.1: "the slope of the curve levels out at around 27 minutes;
  no more units were transported after this time"): the time of the last delivery when the run
  went on for at least :data:`BREAKDOWN_GAP_S` (180 s, about one optimal round trip, the paper's
  "approximately 3 minutes") without another one; otherwise the run did not break down within
  its length and ``breakdown_s`` is the run's duration with ``breakdown_censored = 1``. A run
  with no delivery at all breaks down at 0.
- **Table 1** (Try §3.6) per robot: trips, distance [m] (true path length), lifetime [min] =
  from the robot's start (t = 0, or its ``launched`` entry when robots are started one at a
  time, Try §3.5) to its last place event (the paper's robots stopped when they failed; ours
  stop being useful when they stop reaching places).
- **efficiency** (Try §3.6: "average time between Places was (9h43m40s / 262) = 2m13s. This
  gives an average speed of 0.23 m/s ... approximately 92 % of maximum efficiency"): total
  lifetime / trips = ``place_interval_s``; ``place_speed_mps`` = route length / interval, with
  the route length of :data:`ROUTE_LENGTH_M` (home-source through trail_office's corners, what a
  robot of radius 0.25 m drives: 31.5 m, the paper used 31 m). Divide by the cruise speed for
  the efficiency (the report does; the metric does not know the brain's speed).
- **memory**: ``n_crumbs`` from the brains' logs: max and last value over robots, and the max
  in the first and the second half of the run (flat memory: the second is not above the first).
- **crumbs for the figures** (``trails_crumbs``, opt-in: sweeps list it in ``metrics``): every
  :data:`CRUMB_EVERY_S` seconds each robot's odometry position, i.e. the crumb it drops there, in
  its own frame (Try Fig. 3, Blazing Fig. 6: "the trails announced by each robot"), and the same
  crumbs in a fixed global frame where Places A and B are held at fixed points (Try Fig. 4): each
  crumb is mapped by the similarity that takes the robot's Place estimates *at that time* (its
  odometry position at its last home / source event; home starts at its start pose, §3.5 "on
  start-up each robot is told it is at Home") onto the mean true positions of all robots' events
  at home and at the source (our stand-in for the paper's fixed points, within the 1 m event
  discs). Before a robot's first source event it has one Place only and its crumbs are used as
  they are (the optimistic policy, §3.5).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from teamnav.experiments.metrics import RunData, register

__all__ = [
    "BREAKDOWN_GAP_S",
    "CRUMB_EVERY_S",
    "HEADLINE",
    "HOME_EVENT",
    "ROUTE_LENGTH_M",
    "SOURCE_EVENT",
    "WINDOW_S",
    "deliveries",
    "trail_crumbs",
    "trail_metrics",
    "trail_series",
    "trips",
]

HOME_EVENT = "given_resource"
SOURCE_EVENT = "took_resource"
#: no delivery for this long before the run ends = broken down [s] (≈ one optimal round trip)
BREAKDOWN_GAP_S = 180.0
#: one crumb per robot this often in the figure series [s] (the 2002 robots broadcast every 2 s;
#: one in five keeps a 3-hour run's series small)
CRUMB_EVERY_S = 10.0
#: throughput window [s] (10 minutes)
WINDOW_S = 600.0
#: driven route length between pairs of places [m] (trail_office; see module docstring)
ROUTE_LENGTH_M: dict[frozenset, float] = {frozenset({"home", "source"}): 31.5}

#: what ``teamnav run`` prints of these metrics (see :mod:`teamnav.experiments.metric_sets`);
#: the series are for the report's figures only
HEADLINE: dict[str, tuple[tuple[str, str], ...]] = {
    "trails": (
        ("units_total", "units"),
        ("trips_total", "trips"),
        ("first_trail_s", "s"),
        ("trip_time_s_before_mean", "s"),
        ("trip_time_s_after_mean", "s"),
        ("units_per_10min_peak", "units/10 min"),
        ("breakdown_s", "s"),
        ("place_speed_mps", "m/s"),
        ("crumbs_max", "crumbs"),
    ),
    "trails_series": (),
    "trails_crumbs": (),
}


def _is_trail_run(data: RunData) -> bool:
    if any(e.get("event") in (HOME_EVENT, SOURCE_EVENT) for e in data.event_log):
        return True
    return any("trips" in (r.get("values") or {}) for r in data.logs)


def _duration_s(data: RunData) -> float:
    return float(data.n_steps * data.dt_s) if data.n_steps else float(data.t_s[-1] if data.t_s.size else 0.0)


def deliveries(event_log: list[dict]) -> list[tuple[float, int]]:
    """(time [s], robot) of every unit delivered, in time order (module docstring)."""
    loaded: dict[int, bool] = {}
    out = []
    for e in sorted(event_log, key=lambda e: (e["t_s"], e["robot"])):
        r = int(e["robot"])
        if e.get("event") == SOURCE_EVENT:
            loaded[r] = True
        elif e.get("event") == HOME_EVENT:
            if loaded.get(r):
                out.append((float(e["t_s"]), r))
            loaded[r] = False
    return out


def trips(event_log: list[dict], n_robots: int, start_place: str = "home") -> list[tuple[int, float, float, str, str]]:
    """Every trip (robot, start [s], end [s], from place, to place), in time order.

    Consecutive events of a robot at the same place (it left the disc and came back) are not
    trips. Each robot is taken to start at ``start_place`` at t = 0, or when it was started (a
    ``launched`` entry: robots started one at a time, Blazing §5, Try §3.5).
    """
    last: dict[int, tuple[float, str]] = {r: (0.0, start_place) for r in range(n_robots)}
    out = []
    for e in sorted(event_log, key=lambda e: (e["t_s"], e["robot"])):
        if e.get("launched"):
            last[int(e["robot"])] = (float(e["t_s"]), start_place)
            continue
        if e.get("event") is None:
            continue
        r = int(e["robot"])
        t, place = float(e["t_s"]), str(e["place"])
        t0, p0 = last.get(r, (0.0, start_place))
        if place != p0:
            out.append((r, t0, t, p0, place))
        last[r] = (t, place)
    return sorted(out, key=lambda x: (x[2], x[0]))


def _stats(prefix: str, xs: list[float]) -> dict[str, float]:
    if not xs:
        return {f"{prefix}_n": 0}
    a = np.asarray(xs, dtype=float)
    return {f"{prefix}_n": int(a.size), f"{prefix}_mean": float(a.mean()), f"{prefix}_median": float(np.median(a))}


def _windows(times: list[float], duration_s: float) -> np.ndarray:
    n = max(1, int(math.ceil(duration_s / WINDOW_S - 1e-9)))
    counts = np.zeros(n, dtype=int)
    for t in times:
        counts[min(n - 1, int(t // WINDOW_S))] += 1
    return counts


def _distance_m(data: RunData, until_s: np.ndarray | None = None) -> np.ndarray:
    """Distance each robot drove [m] over the run, or, with ``until_s`` (N,), up to its own
    time ``until_s[i]`` (the samples at or before it)."""
    if data.true_pose.shape[0] < 2:
        return np.zeros(data.n_robots)
    d = np.diff(data.true_pose[:, :, :2], axis=0)
    step = np.hypot(d[..., 0], d[..., 1])  # (T-1, N): from sample k to k+1
    if until_s is None:
        return step.sum(axis=0)
    keep = data.t_s[1:, None] <= np.asarray(until_s, dtype=float)[None, :]
    return np.where(keep, step, 0.0).sum(axis=0)


def _crumbs(data: RunData, duration_s: float) -> dict[str, float]:
    rows = [(float(r["t_s"]), int(r["robot"]), r["values"]["n_crumbs"]) for r in data.logs
            if isinstance(r.get("values"), dict) and "n_crumbs" in r["values"]]
    if not rows:
        return {}
    t = np.array([x[0] for x in rows])
    n = np.array([float(x[2]) for x in rows])
    last_t: dict[int, tuple[float, float]] = {}
    for ti, r, v in rows:
        if r not in last_t or ti >= last_t[r][0]:
            last_t[r] = (ti, float(v))
    half = 0.5 * duration_s
    first, second = n[t < half], n[t >= half]
    return {
        "crumbs_max": float(n.max()),
        "crumbs_last_max": float(max(v for _, v in last_t.values())),
        "crumbs_max_first_half": float(first.max()) if first.size else 0.0,
        "crumbs_max_second_half": float(second.max()) if second.size else 0.0,
    }


def trail_metrics(data: RunData) -> dict[str, Any]:
    """Units, trips, trip times before/after the first trail, throughput, breakdown, Table 1, memory."""
    if not _is_trail_run(data):
        return {}
    n = data.n_robots
    dur = _duration_s(data)
    dl = deliveries(data.event_log)
    tr = trips(data.event_log, n)
    out: dict[str, Any] = {"units_total": len(dl)}
    per_units = np.bincount([r for _, r in dl], minlength=n) if dl else np.zeros(n, dtype=int)
    per_trips = np.bincount([x[0] for x in tr], minlength=n) if tr else np.zeros(n, dtype=int)
    dist = _distance_m(data)
    last_place_s = np.zeros(n)  # each robot's last place event [s from the run's start]
    for r, _, t1, _, _ in tr:
        last_place_s[r] = max(last_place_s[r], t1)
    started_s = np.zeros(n)  # when each robot was started (robots started one at a time)
    for e in data.event_log:
        if e.get("launched") and 0 <= int(e["robot"]) < n:
            started_s[int(e["robot"])] = float(e["t_s"])
    # the lifetime counts from the robot's own start: a robot started later has not lived before
    life = np.where(last_place_s > 0.0, last_place_s - started_s, 0.0)
    for i in range(n):
        out[f"units.robot{i}"] = int(per_units[i])
        out[f"trips.robot{i}"] = int(per_trips[i])
        out[f"distance_m.robot{i}"] = float(dist[i])
        out[f"lifetime_min.robot{i}"] = float(life[i] / 60.0)
    out["trips_total"] = int(per_trips.sum())
    out["distance_m_total"] = float(dist.sum())
    out["lifetime_min_total"] = float(life.sum() / 60.0)
    # distance over the same window as the lifetime (each robot up to its last place event):
    # the mean speed over the lifetime is this over lifetime_min_total (3b49c8d, 2026-11-27)
    out["distance_m_lifetime_total"] = float(_distance_m(data, last_place_s).sum())
    out["units_per_robot_min"] = int(per_units.min())
    out["units_per_robot_max"] = int(per_units.max())
    if dl:  # keys left out when there is nothing to time (NaN would not compare equal to itself)
        out["first_delivery_s"] = float(dl[0][0])
    sources = [float(e["t_s"]) for e in data.event_log if e.get("event") == SOURCE_EVENT]
    first_trail = min(sources) if sources else math.inf
    if sources:
        out["first_trail_s"] = first_trail
    before = [t1 - t0 for _, t0, t1, _, _ in tr if not (t0 >= first_trail)]
    after = [t1 - t0 for _, t0, t1, _, _ in tr if t0 >= first_trail]
    out.update(_stats("trip_time_s_before", before))
    out.update(_stats("trip_time_s_after", after))
    # after the first 10 minutes: the steady state the papers' robots reached
    out.update(_stats("trip_time_s_after_10min", [t1 - t0 for _, t0, t1, _, _ in tr if t0 >= WINDOW_S]))
    win = _windows([t for t, _ in dl], dur)
    out["units_per_10min_peak"] = int(win.max())
    out["units_per_10min_last"] = int(win[-1])
    out["units_per_10min_mean"] = float(len(dl) / (dur / WINDOW_S)) if dur > 0 else 0.0
    if not dl:
        out["breakdown_s"], out["breakdown_censored"] = 0.0, 0
    elif dur - dl[-1][0] >= BREAKDOWN_GAP_S:
        out["breakdown_s"], out["breakdown_censored"] = float(dl[-1][0]), 0
    else:
        out["breakdown_s"], out["breakdown_censored"] = float(dur), 1
    if tr:
        interval = float(life.sum() / len(tr))
        out["place_interval_s"] = interval
        lengths = {ROUTE_LENGTH_M.get(frozenset({a, b})) for _, _, _, a, b in tr}
        if len(lengths) == 1 and None not in lengths and interval > 0:
            out["place_speed_mps"] = float(lengths.pop() / interval)
    out.update(_crumbs(data, dur))
    return out


def trail_series(data: RunData) -> dict[str, str]:
    """Time series as JSON strings: cumulative units (total and per robot), 10-min windows, arrivals.

    ``units_series``: ``[[t_s, cumulative units], ...]`` at each delivery (starting at [0, 0]);
    ``units_by_robot_series``: ``{robot: [[t_s, cumulative], ...]}``;
    ``units_per_10min_series``: units per window; ``arrivals_series``: ``[[t_s, robot, place], ...]``
    (the papers' Fig. 2 top).
    """
    if not _is_trail_run(data):
        return {}
    dl = deliveries(data.event_log)
    total = [[0.0, 0]] + [[round(t, 2), k + 1] for k, (t, _) in enumerate(dl)]
    by_robot: dict[str, list] = {str(r): [[0.0, 0]] for r in range(data.n_robots)}
    for t, r in dl:
        by_robot[str(r)].append([round(t, 2), by_robot[str(r)][-1][1] + 1])
    arrivals = [[round(float(e["t_s"]), 2), int(e["robot"]), str(e["place"])] for e in data.event_log if e.get("event")]
    return {
        "units_series": json.dumps(total, separators=(",", ":")),
        "units_by_robot_series": json.dumps(by_robot, separators=(",", ":")),
        "units_per_10min_series": json.dumps(_windows([t for t, _ in dl], _duration_s(data)).tolist()),
        "arrivals_series": json.dumps(arrivals, separators=(",", ":")),
    }


def _place_track(data: RunData, robot: int, event: str, t_s: np.ndarray) -> np.ndarray:
    """(len(t_s), 2) the robot's own-frame estimate of the place of ``event`` at each time (NaN before
    its first such event): its odometry position at the latest such event (nearest sample)."""
    out = np.full((t_s.size, 2), np.nan)
    evs = sorted(float(e["t_s"]) for e in data.event_log if e.get("event") == event and int(e["robot"]) == robot)
    if not evs:
        return out
    k = np.clip(np.searchsorted(data.t_s, evs), 0, data.t_s.size - 1)
    at = data.odom_pose[k, robot, :2]
    idx = np.searchsorted(np.asarray(evs), t_s, side="right") - 1
    ok = idx >= 0
    out[ok] = at[idx[ok]]
    return out


def trail_crumbs(data: RunData) -> dict[str, str]:
    """Crumbs for the papers' trail figures (module docstring), as JSON strings.

    ``crumbs_own_series``: ``{robot: [[x_m, y_m], ...]}`` in each robot's own odometry frame;
    ``crumbs_global_series``: the same crumbs in the fixed global frame of the places.
    """
    if not _is_trail_run(data) or data.t_s.size == 0:
        return {}
    step = max(1, int(round(CRUMB_EVERY_S / max(float(np.median(np.diff(data.t_s))) if data.t_s.size > 1 else 1.0, 1e-9))))
    k = np.arange(0, data.t_s.size, step)
    t = data.t_s[k]

    def fixed(event: str) -> np.ndarray | None:
        at = [data.true_pose[min(int(np.searchsorted(data.t_s, e["t_s"])), data.t_s.size - 1), int(e["robot"]), :2]
              for e in data.event_log if e.get("event") == event]
        return np.mean(at, axis=0) if at else None

    qa, qb = fixed(HOME_EVENT), fixed(SOURCE_EVENT)
    own, glob = {}, {}
    for r in range(data.n_robots):
        p = data.odom_pose[k, r, :2]
        own[str(r)] = np.round(p, 2).tolist()
        g = p.copy()
        if qa is not None and qb is not None:
            a = _place_track(data, r, HOME_EVENT, t)
            a[np.isnan(a[:, 0])] = data.odom_pose[0, r, :2]  # told it is at Home at start-up
            b = _place_track(data, r, SOURCE_EVENT, t)
            za = a[:, 0] + 1j * a[:, 1]
            zb = b[:, 0] + 1j * b[:, 1]
            zq_a, zq_b = complex(*qa), complex(*qb)
            use = np.isfinite(zb) & (np.abs(zb - za) > 1e-6)
            zp = p[:, 0] + 1j * p[:, 1]
            m = (zq_b - zq_a) / np.where(use, zb - za, 1.0)  # scale * e^{i rotation}
            zg = np.where(use, zq_a + m * (zp - za), zp)
            g = np.stack([zg.real, zg.imag], axis=1)
        glob[str(r)] = np.round(g, 2).tolist()
    return {"crumbs_own_series": json.dumps(own, separators=(",", ":")),
            "crumbs_global_series": json.dumps(glob, separators=(",", ":"))}


register("trails", trail_metrics,
         "trail papers: units delivered, trips, trip times before/after the first trail, 10-min throughput, "
         "breakdown time, Table 1 per robot, place interval, crumb memory")
register("trails_series", trail_series,
         "trail papers: cumulative units over time, per robot, per 10-min window, arrivals (JSON strings)")
register("trails_crumbs", trail_crumbs,
         "trail papers' figures: each robot's crumbs (odometry positions every 10 s) in its own frame and in the "
         "fixed global frame of the places (JSON strings; opt-in, large)")
