"""Metrics of a finished run, found by name (scenario field ``metrics``).

Metrics score a run, so they may read the truth (DESIGN: "metrics and experiments may read
the truth, to score, never to steer"). Each metric is a function of a :class:`RunData` (the
recorded trajectories, events and radio traffic plus a few facts about the run) returning a
flat ``{key: number}`` dict; keys carry units. Metrics marked non-deterministic (wall time,
throughput) are left out when two runs are compared (:func:`deterministic`).

Trajectories are those the recorder kept, one sample every ``record_every`` steps; path
lengths are sums of straight chords between samples, so a coarse ``record_every`` shortens
them slightly.
"""

from __future__ import annotations

import difflib
import math
from collections import Counter
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from teamnav.world.grid import OccupancyGrid

__all__ = ["RunData", "compute", "deterministic", "describe", "names", "register"]


@dataclass(frozen=True)
class RunData:
    """What metrics read: the run as recorded, in world (truth) and odometry (belief) frames.

    Attributes
    ----------
    t_s : ndarray of shape (T,)
        Sample times [s].
    true_pose : ndarray of shape (T, N, 3)
        True (x [m], y [m], theta [rad]) per sample and robot.
    odom_pose : ndarray of shape (T, N, 3)
        Odometry pose per sample and robot, each in the robot's own odometry frame.
    stalled : ndarray of shape (T, N), bool
        Whether the robot's commanded motion was blocked at that sample.
    radius_m : ndarray of shape (N,)
        Body radius per robot [m].
    grid : OccupancyGrid
        The true map.
    events : list of str
        Name of every task event that fired (one entry per firing).
    messages_sent : int
        Radio messages sent (before loss).
    bytes_sent : int
        Their total size [bytes].
    messages_delivered : int
        Deliveries the radio made (one message can reach several robots).
    n_steps : int
        Steps the engine ran.
    dt_s : float
        Step length [s].
    wall_s : float
        Wall-clock time of the stepping loop [s].
    warmup_s : float
        Wall-clock time of its first step [s], part of ``wall_s``: numba compiles the kernels
        there on a first run (then whenever a source file changed) and loads them from its
        cache afterwards. 0 when not measured.
    event_log : list of dict
        Every task event that fired, in order: ``{"step", "t_s", "robot", "place", "event"}``.
    logs : list of dict
        The brains' ``log()`` values as recorded: ``{"step", "t_s", "robot", "values"}``
        (belief-side data: what the robot believed or decided; metrics compare it with the truth).
    finished : bool
        The run stopped early because every brain that reports ``finished`` said so
        (scenario ``stop_when_finished``).
    """

    t_s: np.ndarray
    true_pose: np.ndarray
    odom_pose: np.ndarray
    stalled: np.ndarray
    radius_m: np.ndarray
    grid: OccupancyGrid
    events: list[str] = field(default_factory=list)
    messages_sent: int = 0
    bytes_sent: int = 0
    messages_delivered: int = 0
    n_steps: int = 0
    dt_s: float = 0.1
    wall_s: float = 0.0
    warmup_s: float = 0.0
    event_log: list[dict] = field(default_factory=list)
    logs: list[dict] = field(default_factory=list)
    finished: bool = False

    @property
    def n_robots(self) -> int:
        return int(self.true_pose.shape[1])


@dataclass(frozen=True)
class _Metric:
    fn: Callable[[RunData], dict[str, float | int]]
    doc: str
    deterministic: bool


_REGISTRY: dict[str, _Metric] = {}


def register(name: str, fn: Callable[[RunData], dict[str, Any]], doc: str, *, deterministic: bool = True) -> None:
    """Add metric ``name``; a second registration of a name raises ``ValueError``."""
    if name in _REGISTRY:
        raise ValueError(f"metric {name!r} is already registered")
    _REGISTRY[name] = _Metric(fn, doc, deterministic)


def names() -> list[str]:
    """All metric names, in registration order."""
    return list(_REGISTRY)


def describe(name: str) -> str:
    """One line saying what metric ``name`` measures."""
    return _REGISTRY[name].doc


def _get(name: str) -> _Metric:
    try:
        return _REGISTRY[name]
    except KeyError:
        close = difflib.get_close_matches(name, _REGISTRY, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"unknown metric {name!r}{hint} (known: {', '.join(_REGISTRY)})") from None


def compute(metric_names: list[str] | tuple[str, ...], data: RunData) -> dict[str, float | int]:
    """Evaluate metrics ``metric_names`` on ``data``: one flat dict of plain Python numbers."""
    out: dict[str, float | int] = {}
    for name in metric_names:
        for key, value in _get(name).fn(data).items():
            out[key] = value.item() if isinstance(value, np.generic) else value
    return out


def deterministic(values: dict[str, Any], metric_names: list[str] | tuple[str, ...] | None = None) -> dict[str, Any]:
    """``values`` without the keys of non-deterministic metrics (wall time, throughput)."""
    drop: set[str] = set()
    for name, m in _REGISTRY.items():
        if not m.deterministic and (metric_names is None or name in metric_names):
            drop.update(_KEYS.get(name, ()))
    return {k: v for k, v in values.items() if k not in drop}


# ---------------------------------------------------------------------------- the metrics
def _chords_m(data: RunData) -> np.ndarray:
    """(N,) summed chord length of each robot's recorded true path [m]."""
    if data.true_pose.shape[0] < 2:
        return np.zeros(data.n_robots)
    d = np.diff(data.true_pose[:, :, :2], axis=0)
    return np.hypot(d[..., 0], d[..., 1]).sum(axis=0)


def path_length(data: RunData) -> dict[str, float]:
    """Length of each robot's true path: mean, min, max and the team total [m]."""
    L = _chords_m(data)
    return {
        "path_length_m_mean": float(L.mean()),
        "path_length_m_min": float(L.min()),
        "path_length_m_max": float(L.max()),
        "path_length_m_total": float(L.sum()),
    }


def mean_speed(data: RunData) -> dict[str, float]:
    """True path length over elapsed time, averaged over robots [m/s]."""
    elapsed = float(data.t_s[-1] - data.t_s[0]) if data.t_s.size > 1 else 0.0
    return {"mean_speed_mps": float(_chords_m(data).mean() / elapsed) if elapsed > 0 else 0.0}


def stall_fraction(data: RunData) -> dict[str, float]:
    """Fraction of recorded robot-samples whose commanded motion was blocked."""
    return {"stall_fraction": float(np.mean(data.stalled)) if data.stalled.size else 0.0}


#: teams up to this size have their robot pairs checked all at once, larger ones with a k-d tree
_ALL_PAIRS_MAX = 48


def _present(data: RunData) -> np.ndarray | None:
    """(T, N) True where a robot has started (a scenario's ``launch``: robots started one at a
    time, each ``launched`` in the event log; one not started waits at the spot, out of the
    arena); None when every robot is there from the start."""
    launched = {int(e["robot"]): float(e["t_s"]) for e in getattr(data, "event_log", ())
                if isinstance(e, dict) and e.get("launched")}
    if not launched:
        return None
    t0 = np.array([launched.get(i, np.inf) for i in range(data.n_robots)])
    return np.asarray(data.t_s)[:, None] >= t0[None, :] - 1e-9


def collisions(data: RunData) -> dict[str, int]:
    """Recorded robot-samples overlapping a wall, and robot pairs overlapping each other.

    Both should be 0: the engine refuses motion into walls and robots. A robot overlaps a
    wall when the distance from its cell centre to the nearest obstacle cell centre is below
    ``radius - resolution`` (the distance field is exact between cell centres only, so one
    cell of tolerance); two robots overlap when their centres are closer than the sum of
    their radii minus 1 mm. Robots not started yet (a scenario's ``launch``) are not counted:
    they wait at the spot, outside the arena.
    """
    from teamnav.world.distance import distance_field

    present = _present(data)

    grid = data.grid
    dist = distance_field(grid)
    xy = data.true_pose[:, :, :2]
    rc = grid.world_to_cell(xy)
    h, w = grid.shape
    inside = (rc[..., 0] >= 0) & (rc[..., 0] < h) & (rc[..., 1] >= 0) & (rc[..., 1] < w)
    clear = np.zeros(inside.shape)
    clear[inside] = dist[rc[..., 0][inside], rc[..., 1][inside]]
    hit = ~inside | (clear < data.radius_m[None, :] - grid.resolution_m)
    wall_hits = int(np.count_nonzero(hit if present is None else hit & present))

    robot_hits = 0
    if 1 < data.n_robots <= _ALL_PAIRS_MAX:
        # every pair, a block of samples at a time (no scipy.spatial: ~0.07 s to import); a
        # pair farther apart than the k-d tree's reach below cannot overlap, so the counts agree
        i, j = np.triu_indices(data.n_robots, 1)
        rsum = data.radius_m[i] + data.radius_m[j]
        for k in range(0, xy.shape[0], 512):
            f = xy[k:k + 512]
            gap = np.hypot(f[:, i, 0] - f[:, j, 0], f[:, i, 1] - f[:, j, 1]) - rsum
            over = gap < -1e-3
            if present is not None:
                over &= present[k:k + 512][:, i] & present[k:k + 512][:, j]
            robot_hits += int(np.count_nonzero(over))
    elif data.n_robots > 1:
        from scipy.spatial import cKDTree

        reach = 2.0 * float(data.radius_m.max())
        for k, frame in enumerate(xy):
            pairs = cKDTree(frame).query_pairs(reach, output_type="ndarray")
            if len(pairs):
                i, j = pairs[:, 0], pairs[:, 1]
                gap = np.hypot(*(frame[i] - frame[j]).T) - (data.radius_m[i] + data.radius_m[j])
                over = gap < -1e-3
                if present is not None:
                    over &= present[k, i] & present[k, j]
                robot_hits += int(np.count_nonzero(over))
    return {"collisions_wall": wall_hits, "collisions_robot": robot_hits}


def odometry_error(data: RunData) -> dict[str, float]:
    """How far each robot's odometry has drifted from the truth by the end.

    Odometry lives in each robot's own frame; it is put in the world frame through the
    first sample (``T_world = T0 · O0⁻¹ · O_end``), so the error is pure drift, for frames
    that start at the robot's pose or aligned with the world alike.
    Keys: position error mean/max [m], heading error mean [deg].
    """
    T0, O0 = data.true_pose[0], data.odom_pose[0]
    Oe, Te = data.odom_pose[-1], data.true_pose[-1]
    # relative motion in the odometry frame, expressed in the first odometry pose's frame
    dx, dy = Oe[:, 0] - O0[:, 0], Oe[:, 1] - O0[:, 1]
    c0, s0 = np.cos(O0[:, 2]), np.sin(O0[:, 2])
    lx, ly = c0 * dx + s0 * dy, -s0 * dx + c0 * dy
    dth = Oe[:, 2] - O0[:, 2]
    # the same relative motion applied to the first true pose
    c, s = np.cos(T0[:, 2]), np.sin(T0[:, 2])
    ex = T0[:, 0] + c * lx - s * ly
    ey = T0[:, 1] + s * lx + c * ly
    eth = T0[:, 2] + dth
    err = np.hypot(ex - Te[:, 0], ey - Te[:, 1])
    herr = np.abs((eth - Te[:, 2] + math.pi) % (2 * math.pi) - math.pi)
    return {
        "odom_error_m_mean": float(err.mean()),
        "odom_error_m_max": float(err.max()),
        "odom_heading_error_deg_mean": float(np.degrees(herr).mean()),
    }


def messages(data: RunData) -> dict[str, int]:
    """Radio traffic: messages sent, their bytes, and deliveries made."""
    return {
        "messages_sent": int(data.messages_sent),
        "bytes_sent": int(data.bytes_sent),
        "messages_delivered": int(data.messages_delivered),
    }


def events(data: RunData) -> dict[str, int]:
    """Task events counted by name (``events.<name>``), and their total (``events_total``)."""
    counts = Counter(data.events)
    out = {f"events.{k}": int(v) for k, v in sorted(counts.items())}
    out["events_total"] = int(sum(counts.values()))
    return out


def steps(data: RunData) -> dict[str, float | int]:
    """Steps run and the simulated time they cover [s]."""
    return {"steps": int(data.n_steps), "sim_time_s": float(data.n_steps * data.dt_s)}


def wall_time(data: RunData) -> dict[str, float]:
    """Wall-clock time of the stepping loop [s], and of its first step alone (``warmup_s``:
    numba compiling or loading its kernels) (both vary between runs)."""
    return {"wall_time_s": float(data.wall_s), "warmup_s": float(data.warmup_s)}


def throughput(data: RunData) -> dict[str, float]:
    """Robot-steps simulated per wall-clock second after the first step (varies between runs).

    The first step is left out when its time was measured (``warmup_s``): on a first run it
    holds numba's compilation of every kernel (measured: 6.4 s of a 6.5-s demo run, which
    made 740 robot-steps/s of a 55 000 robot-steps/s simulator). Kernels first needed later
    in a run still count.
    """
    steps, wall = data.n_steps, data.wall_s
    if 0.0 < data.warmup_s < wall and steps > 1:
        steps, wall = steps - 1, wall - data.warmup_s
    rate = steps * data.n_robots / wall if wall > 0 else float("nan")
    return {"robot_steps_per_s": float(rate)}


register("path_length", path_length, "length of each robot's true path [m]: mean, min, max, total")
register("mean_speed", mean_speed, "true path length over elapsed time, mean over robots [m/s]")
register("stall_fraction", stall_fraction, "fraction of robot-samples whose motion was blocked")
register("collisions", collisions, "robot-samples overlapping a wall, overlapping robot pairs (should be 0)")
register("odometry_error", odometry_error, "distance from odometry to truth at the end [m] (mean, max), heading [deg]")
register("messages", messages, "radio messages sent, bytes sent, deliveries")
register("events", events, "task events counted by name")
register("steps", steps, "steps run and simulated time [s]")
register("wall_time", wall_time, "wall-clock time of the run [s]; warmup_s: of its first step alone (numba compiles "
         "its kernels there on a first run)", deterministic=False)
register("throughput", throughput, "robot-steps per wall-clock second, after the first step (numba's compile / "
         "warm-up time is warmup_s)", deterministic=False)


def _discover_metric_sets() -> None:
    """Import every installed paper's metric sets (:attr:`teamnav.plugins.Paper.metric_sets`,
    in the order of their names) so that their metrics register themselves. A metric set's
    functions return ``{}`` for a run that lacks their data (another paper's scenario), because
    a scenario with ``metrics: []`` computes all."""
    import importlib

    from teamnav.experiments.metric_sets import metric_set_modules

    for module in metric_set_modules().values():
        importlib.import_module(module)


#: keys each non-deterministic metric produces (for :func:`deterministic`)
_KEYS: dict[str, tuple[str, ...]] = {"wall_time": ("wall_time_s", "warmup_s"), "throughput": ("robot_steps_per_s",)}

_discover_metric_sets()
