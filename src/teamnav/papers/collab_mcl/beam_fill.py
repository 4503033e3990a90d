"""The beam model's fill: how many beams the filter multiplies and ``sigma_hit``, chosen against a
grid filter on single-robot scans (Fox, Burgard, Kruppa & Thrun §2.2, §3.1; FIDELITY §1 "a fill").

The paper gives the perception model's shape only ("a mixture of a Gaussian ..., a Geometric
distribution ... and a Dirac", §2.2 Fig. 1) and the laser's hardware ("180 distance measurements
with approximately 5 cm accuracy, spaced at 1 degree", §4.1). How many of the 180 beams the filter
multiplies (``beam_stride``) and the Gaussian's width (``sigma_hit_m``) are silences. The rule
(docs/report/collab-mcl.md, "2026-11-29: rules written before the runs", rule 1), written before any
run:

- cases: tuning seeds, one pose each uniform over the free space (clearance >= 0.3 m) of the §5.1
  corridor and of the hexagon (a laser robot), one simulated scan;
- the sample posterior: ``K`` uniform samples weighted by the filter's own likelihood of that scan
  (eq. 12, exponent 1); the grid posterior: the same likelihood on every pose of a 0.2 m x 0.2 m x 5°
  grid over the free space (a grid filter's posterior after one scan from a uniform prior);
- per case ``m_s`` and ``m_g``: the mass each puts within 1 m and 30° of the true pose;
- the choice (:func:`choose`): the highest mean ``m_s`` among the settings whose mean
  ``|m_s - m_g|`` is at most 0.1; a tie within 0.01 goes to fewer beams.

The sonar's model (rule 8, written after the judged run's paper-column failures were traced to the
sonar's never-chosen ``sigma_hit_m`` 0.3 m and its 16 cones) is chosen by the same criterion over
``sigma_hit_m`` x cones used (``beam_stride`` over the 16 transducers), the cases on the symmetric
hallway and the hexagon with a sonar robot, each cone's expected range the minimum over the rays
the filter casts across it (:func:`cone_offsets`).

The criterion looks at the ground truth and at the grid, never at a claim. Deviation, said here:
the grid is 0.2 m and 5° (a pose's nearest grid cell is up to 0.14 m and 2.5° off, 0.35 m at 8 m of
range), so for the sharpest models the grid posterior is itself coarse; ``m_g`` is read as the
mass of a 1 m / 30° region, not of one cell, for that reason.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from teamnav.localization import BeamModelParams
from teamnav.localization.beam_model import BeamTable
from teamnav.world.distance import distance_field
from teamnav.world.grid import FREE, OccupancyGrid
from teamnav.world.raycast import RayCaster

__all__ = ["FillCase", "NEAR_M", "NEAR_DEG", "MAX_GAP", "TIE", "case_pose", "grid_poses", "masses", "choose"]

#: "near the true pose": within this distance [m] and heading [deg]
NEAR_M: float = 1.0
NEAR_DEG: float = 30.0
#: the sample posterior must match the grid's: mean |m_s - m_g| at most this
MAX_GAP: float = 0.1
#: a tie within this goes to fewer beams
TIE: float = 0.01


@dataclass(frozen=True)
class FillCase:
    """One case's result for every setting: ``m_s[i_sigma, i_stride]``, ``m_g[...]``."""

    seed: int
    pose: tuple[float, float, float]
    m_s: np.ndarray
    m_g: np.ndarray


def case_pose(grid: OccupancyGrid, seed: int, clearance_m: float = 0.3) -> np.ndarray:
    """A pose uniform over the free cells with at least ``clearance_m`` to the nearest obstacle."""
    rng = np.random.default_rng(seed)
    free = np.argwhere((grid.cells == FREE) & (distance_field(grid) >= clearance_m))
    r, c = free[rng.integers(free.shape[0])]
    u = rng.random(3)
    x = grid.origin_xy_m[0] + (c + u[0]) * grid.resolution_m
    y = grid.origin_xy_m[1] + (r + u[1]) * grid.resolution_m
    return np.array([x, y, -math.pi + 2 * math.pi * u[2]])


def grid_poses(grid: OccupancyGrid, step_m: float = 0.2, step_deg: float = 5.0,
               clearance_m: float = 0.2) -> np.ndarray:
    """The grid filter's poses: cell centres every ``step_m`` over the free space with the filter's
    clearance, each at every ``step_deg`` of heading, shape (P, 3)."""
    res = grid.resolution_m
    k = max(1, int(round(step_m / res)))
    ok = (grid.cells == FREE) & (distance_field(grid) >= clearance_m)
    rows, cols = np.nonzero(ok[::k, ::k])
    x = grid.origin_xy_m[0] + (cols * k + 0.5) * res
    y = grid.origin_xy_m[1] + (rows * k + 0.5) * res
    th = np.deg2rad(np.arange(-180.0, 180.0, step_deg))
    return np.column_stack([np.repeat(x, th.shape[0]), np.repeat(y, th.shape[0]), np.tile(th, x.shape[0])])


@njit(cache=True)
def _stride_sums(ranges, table, inv_step, strides, out):
    """``out[i, s] = sum over beams b with b % strides[s] == 0 of log P(z_b | ranges[i, b])``, the
    filter's table interpolation (``beam_model._beam_row`` with one ray per beam)."""
    last = table.shape[1] - 1
    ns = strides.shape[0]
    for i in range(ranges.shape[0]):
        for s in range(ns):
            out[i, s] = 0.0
        for b in range(ranges.shape[1]):
            u = ranges[i, b] * inv_step
            j = int(u)
            if j >= last:
                v = table[b, last]
            else:
                t0 = table[b, j]
                v = t0 + (u - j) * (table[b, j + 1] - t0)
            for s in range(ns):
                if b % strides[s] == 0:
                    out[i, s] += v
    return out


def _near_mass(ll: np.ndarray, poses: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """Posterior mass within NEAR_M / NEAR_DEG of ``truth`` per column of log-likelihoods ``ll`` (P, S)."""
    w = np.exp(ll - ll.max(axis=0))
    w /= w.sum(axis=0)
    dth = np.abs((poses[:, 2] - truth[2] + np.pi) % (2 * np.pi) - np.pi)
    near = (np.hypot(poses[:, 0] - truth[0], poses[:, 1] - truth[1]) <= NEAR_M) & (dth <= math.radians(NEAR_DEG))
    return w[near].sum(axis=0)


def cone_offsets(cone_deg: float, rays_per_cone: int) -> np.ndarray:
    """The filter's rays across one sonar cone [rad] (``localization.mcl``: ``linspace`` over the
    opening; one ray at 0 for a laser)."""
    if rays_per_cone > 1 and cone_deg > 0:
        half = math.radians(cone_deg) / 2
        return np.linspace(-half, half, rays_per_cone)
    return np.zeros(1)


def _ranges(caster: RayCaster, poses: np.ndarray, angles: np.ndarray, chunk: int = 50_000,
            offsets: np.ndarray | None = None) -> np.ndarray:
    """Expected ranges (P, B): one ray per beam, or for a sonar the minimum over the rays cast
    across each cone at ``angles[b] + offsets`` (the filter's own expected distance, Fox §5.2)."""
    k = 1 if offsets is None else int(offsets.shape[0])
    rays = angles if k == 1 else np.ascontiguousarray((angles[:, None] + offsets[None, :]).ravel())
    out = np.empty((poses.shape[0], angles.shape[0]), dtype=np.float32)
    buf = np.empty((min(chunk, poses.shape[0]), rays.shape[0]))
    for a in range(0, poses.shape[0], chunk):
        p = poses[a:a + chunk]
        r = caster.cast_xyt(p[:, 0], p[:, 1], p[:, 2], rays, out=buf[:p.shape[0]], parallel=False)
        out[a:a + p.shape[0]] = r if k == 1 else r.reshape(p.shape[0], angles.shape[0], k).min(axis=2)
    return out


class Criterion:
    """The rule's measurements on one map for one sensor: grid ranges cast once, then
    :meth:`case` per tuning seed.

    Parameters
    ----------
    grid : OccupancyGrid
        The robot's map.
    sensor : RangeSensor
        The simulated laser (its ``sense`` gives the case's scan; its beams are the filter's).
    beam : BeamModelParams
        The mixture; ``sigma_hit_m`` is replaced by each candidate.
    sigmas, strides : sequences
        The candidates.
    n_samples : int
        K uniform samples of the sample posterior.
    grid_step_m, grid_step_deg : float
        The grid filter's resolution.
    clearance_m : float
        The filter's uniform prior's clearance (``init_clearance_m``).
    cone_deg, rays_per_cone : float, int
        A sonar's cone as the filter models it (``sonar_cone_deg``, ``sonar_rays_per_cone``): the
        expected range of a cone is the minimum over its rays. ``rays_per_cone`` 1 for a laser.
    """

    def __init__(self, grid, sensor, beam: BeamModelParams, sigmas, strides, n_samples: int,
                 grid_step_m: float = 0.2, grid_step_deg: float = 5.0, clearance_m: float = 0.2,
                 cone_deg: float = 0.0, rays_per_cone: int = 1):
        self.grid = grid
        self.sensor = sensor
        self.beam = beam
        self.sigmas = tuple(float(s) for s in sigmas)
        self.strides = np.asarray(strides, dtype=np.int64)
        self.n_samples = int(n_samples)
        self.clearance_m = clearance_m
        self.caster = RayCaster(grid, sensor.sees, sensor.max_range_m)
        self.angles = np.ascontiguousarray(sensor.angles_rad, dtype=np.float64)
        self.offsets = None if rays_per_cone <= 1 else cone_offsets(cone_deg, rays_per_cone)
        self.poses = grid_poses(grid, grid_step_m, grid_step_deg, clearance_m)
        self.ranges = _ranges(self.caster, self.poses, self.angles, offsets=self.offsets)
        self._free = np.argwhere((grid.cells == FREE) & (distance_field(grid) >= clearance_m))

    def _uniform(self, rng: np.random.Generator, n: int) -> np.ndarray:
        cells = self._free[rng.integers(0, self._free.shape[0], size=n)]
        u = rng.random((n, 3))
        res = self.grid.resolution_m
        return np.column_stack([self.grid.origin_xy_m[0] + (cells[:, 1] + u[:, 0]) * res,
                                self.grid.origin_xy_m[1] + (cells[:, 0] + u[:, 1]) * res,
                                -math.pi + 2 * math.pi * u[:, 2]])

    def case(self, seed: int, pose=None) -> FillCase:
        """``m_s``, ``m_g`` of every (sigma, stride) for the case of tuning seed ``seed``."""
        rng = np.random.default_rng([seed, 7])
        truth = case_pose(self.grid, seed) if pose is None else np.asarray(pose, dtype=float)
        scan = self.sensor.sense(truth[:1], truth[1:2], truth[2:3], rng)[0]
        scan = np.minimum(scan, self.sensor.max_range_m)
        samples = self._uniform(rng, self.n_samples)
        s_ranges = _ranges(self.caster, samples, self.angles, offsets=self.offsets)
        m_s = np.empty((len(self.sigmas), self.strides.shape[0]))
        m_g = np.empty_like(m_s)
        for i, sigma in enumerate(self.sigmas):
            bt = BeamTable(self.beam.model_copy(update={"sigma_hit_m": sigma, "table_step_m": None}),
                           self.sensor.max_range_m)
            table = bt(scan)
            inv = 1.0 / bt.step_m
            ll_g = _stride_sums(self.ranges, table, inv, self.strides,
                                np.empty((self.poses.shape[0], self.strides.shape[0])))
            ll_s = _stride_sums(s_ranges, table, inv, self.strides, np.empty((samples.shape[0], self.strides.shape[0])))
            m_g[i] = _near_mass(ll_g, self.poses, truth)
            m_s[i] = _near_mass(ll_s, samples, truth)
        return FillCase(int(seed), tuple(float(v) for v in truth), m_s, m_g)


def choose(cases: list[FillCase], sigmas, strides, n_beams: int) -> dict:
    """The rule: among settings with mean ``|m_s - m_g|`` <= :data:`MAX_GAP`, the highest mean
    ``m_s``; a tie within :data:`TIE` goes to fewer beams (then the smaller sigma).

    Returns ``{"sigma_hit_m", "beam_stride", "mean_m_s", "mean_m_g", "mean_gap", "interior",
    "table"}``; ``interior`` says whether the choice is inside the grid in both dimensions;
    ``table`` holds ``(sigma, stride, beams, mean m_s, mean m_g, mean gap, admissible)`` rows.
    Raises ``ValueError`` when no setting is admissible.

    Examples
    --------
    >>> c = FillCase(1000, (0, 0, 0), np.array([[0.2, 0.5, 0.3]]), np.array([[0.9, 0.55, 0.3]]))
    >>> r = choose([c], [0.1], [1, 2, 4], 8)
    >>> r["beam_stride"], r["interior"]
    (2, True)
    """
    ms = np.mean([c.m_s for c in cases], axis=0)
    mg = np.mean([c.m_g for c in cases], axis=0)
    gap = np.mean([np.abs(c.m_s - c.m_g) for c in cases], axis=0)
    ok = gap <= MAX_GAP
    if not ok.any():
        raise ValueError(f"no setting has a mean |m_s - m_g| <= {MAX_GAP}; smallest {gap.min():.3f}")
    best = ms[ok].max()
    beams = np.array([len(range(0, n_beams, s)) for s in strides])
    cand = [(beams[j], sigmas[i], i, j) for i in range(len(sigmas)) for j in range(len(strides))
            if ok[i, j] and ms[i, j] >= best - TIE]
    _, _, i, j = min(cand)
    table = [(float(sigmas[a]), int(strides[b]), int(beams[b]), float(ms[a, b]), float(mg[a, b]), float(gap[a, b]),
              bool(ok[a, b])) for a in range(len(sigmas)) for b in range(len(strides))]
    interior = (0 < i < len(sigmas) - 1 or len(sigmas) == 1) and (0 < j < len(strides) - 1)
    return {"sigma_hit_m": float(sigmas[i]), "beam_stride": int(strides[j]), "mean_m_s": float(ms[i, j]),
            "mean_m_g": float(mg[i, j]), "mean_gap": float(gap[i, j]), "interior": bool(interior), "table": table}
