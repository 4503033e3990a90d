"""Simulated range sensors: scanning laser, sonar ring, infrared proximity.

Simulator side (truth): each sensor ray-casts from the robots' *true* poses through the map
cells its configuration ``sees`` (a laser passes through glass, a sonar echoes off it;
:meth:`OccupancyGrid.blocking`), optionally stops on other robots' discs
(:mod:`teamnav.sim.sensors.robot_hits`), then corrupts the ranges with a beam-model mixture:

- Gaussian measurement noise ``N(0, noise_std_m)``, clipped to ``[0, max_range_m]``;
- a *max-range* reading with probability ``p_max`` (laser) / ``p_specular`` (sonar: the
  echo was reflected away and never came back);
- a *short* reading, uniform in ``[0, true range)``, with probability ``p_short`` (an
  unmodelled object, or sonar crosstalk).

These are the three parts of the perception model of Fox et al. §2.2 (Fig. 1: a Gaussian
around the expected distance, overly short readings, a Dirac at max range), as in Thrun et
al., *Probabilistic Robotics* §6.3, which MCL (``teamnav.localization``) then models. Fox et
al. fit the short readings with a geometric distribution; the simulator draws them uniformly
below the true range, as :class:`~teamnav.sim.config.LaserConfig` specifies (Thrun's
exponential "short" term fitted to such data is then a modelling approximation, as on a real
robot). The three cases are exclusive: a beam is max with probability ``p_max``, short with
probability ``p_short``, else true + noise (so ``p_max + p_short`` may not exceed 1).

Every step draws at most one ``standard_normal((n, B))`` (skipped when ``noise_std_m`` is 0)
and one ``random((n, B))`` (skipped when ``p_max + p_short`` is 0); the short reading reuses
that uniform (``(u - p_max) / p_short`` is again uniform on ``[0, 1)`` given the beam is
short), so there is no per-beam or per-robot call and a run is deterministic given the
``Generator``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from teamnav.control.protocol import SensorInfo
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.config import LaserConfig, ProximityConfig, SonarConfig
from teamnav.sim.sensors.robot_hits import PARALLEL_MIN_RAYS, beam_plan, check_bodies, default_cell_m, robot_hits_unchecked
from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import RayCaster

__all__ = ["RangeSensor", "beam_angles", "build_range_sensor", "apply_beam_noise"]


# ---------------------------------------------------------------------------- geometry
def beam_angles(n: int, fov_rad: float) -> np.ndarray:
    """``n`` directions evenly spread over a field of view centred on the front (body x axis).

    For ``fov < 2 pi`` both edges get a beam (``linspace(-fov/2, fov/2, n)``; one beam points
    straight ahead). For a full circle the spacing is ``2 pi / n`` with a beam straight ahead
    and no duplicate at ``+-pi``: ``k 2 pi / n`` for ``k = -(n-1)//2 .. n//2``, ascending, in
    ``(-pi, pi]``.

    Parameters
    ----------
    n : int
        Number of beams, >= 1.
    fov_rad : float
        Field of view [rad], in ``(0, 2 pi]``.

    Returns
    -------
    ndarray of shape (n,), float64

    Examples
    --------
    >>> np.degrees(beam_angles(4, 2 * np.pi)).round(6).tolist()
    [-90.0, 0.0, 90.0, 180.0]
    >>> np.degrees(beam_angles(3, np.pi)).round(6).tolist()
    [-90.0, 0.0, 90.0]
    """
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    if not (np.isfinite(fov_rad) and 0.0 < fov_rad <= 2 * np.pi + 1e-12):
        raise ValueError(f"fov_rad must be in (0, 2 pi], got {fov_rad!r}")
    if n == 1:
        return np.zeros(1)
    if fov_rad >= 2 * np.pi - 1e-12:
        k = np.arange(n) - (n - 1) // 2
        return np.minimum(k * (2 * np.pi / n), np.pi)  # k = n/2 may round past pi
    return np.linspace(-fov_rad / 2, fov_rad / 2, n)


# ---------------------------------------------------------------------------- noise kernel
@njit(cache=True)
def _mixture_kernel(true, z, u, sigma, p_max, p_short, max_range, out):
    """Beam mixture, elementwise; ``z`` / ``u`` may be empty (that part is off)."""
    n, nb = true.shape
    use_z = z.shape[0] > 0
    use_u = u.shape[0] > 0
    for i in range(n):
        for b in range(nb):
            t = true[i, b]
            if use_u:
                v = u[i, b]
                if v < p_max:
                    out[i, b] = max_range
                    continue
                if v < p_max + p_short:
                    out[i, b] = t * ((v - p_max) / p_short)
                    continue
            r = t + sigma * z[i, b] if use_z else t
            out[i, b] = min(max(r, 0.0), max_range)


def apply_beam_noise(true_m, rng, noise_std_m, p_max, p_short, max_range_m, out=None) -> np.ndarray:
    """Observed ranges from true ranges: the beam mixture of Fox et al. §2.2 (Fig. 1).

    Parameters
    ----------
    true_m : ndarray of shape (n, B), float64
        Noise-free ranges [m].
    rng : numpy.random.Generator
        Draws ``standard_normal((n, B))`` if ``noise_std_m > 0``, then ``random((n, B))`` if
        ``p_max + p_short > 0``.
    noise_std_m : float
        Standard deviation of the Gaussian part [m].
    p_max, p_short : float
        Probabilities of a max-range reading and of a uniform short reading in
        ``[0, true)``; ``p_max + p_short`` must not exceed 1.
    max_range_m : float
        Sensor range [m]; readings are clipped to ``[0, max_range_m]``.
    out : ndarray of shape (n, B), optional
        Filled and returned (may be ``true_m`` itself).

    Returns
    -------
    ndarray of shape (n, B), float64

    Examples
    --------
    >>> r = apply_beam_noise(np.array([[1.0, 9.0]]), np.random.default_rng(0), 0.0, 0.0, 0.0, 5.0)
    >>> r.tolist()
    [[1.0, 5.0]]
    """
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    true_m = np.asarray(true_m, dtype=np.float64)
    if true_m.ndim != 2:
        raise ValueError(f"true_m must be a 2-D array (n, B), got shape {true_m.shape}")
    for name, v in (("noise_std_m", noise_std_m), ("p_max", p_max), ("p_short", p_short)):
        if not (np.isfinite(v) and v >= 0):
            raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")
    if p_max + p_short > 1.0 + 1e-12:
        raise ValueError(f"p_max + p_short must be <= 1, got {p_max} + {p_short}")
    if not (np.isfinite(max_range_m) and max_range_m > 0):
        raise ValueError(f"max_range_m must be a positive number of metres, got {max_range_m!r}")
    if out is None:
        out = np.empty(true_m.shape, dtype=np.float64)
    elif not (isinstance(out, np.ndarray) and out.shape == true_m.shape and out.dtype == np.float64
              and out.flags.writeable):
        raise ValueError(
            f"out must be a writeable float64 array of shape {true_m.shape}, got "
            f"{getattr(out, 'dtype', type(out).__name__)} {getattr(out, 'shape', '')}"
        )
    empty = np.empty((0, 0))
    z = rng.standard_normal(true_m.shape) if noise_std_m > 0 else empty
    u = rng.random(true_m.shape) if p_max + p_short > 0 else empty
    _mixture_kernel(true_m, z, u, float(noise_std_m), float(p_max), float(p_short), float(max_range_m), out)
    return out


# ---------------------------------------------------------------------------- the sensor
class RangeSensor:
    """One range sensor model, shared by every robot of a group that carries it.

    Build it with :func:`build_range_sensor`. A sensor casts ``R = B * rays_per_beam`` rays
    per robot (``rays_per_beam`` is 1 except for a sonar's cone) and reports ``B`` ranges:
    the nearest return of each beam's rays.

    Attributes
    ----------
    name : str
        The sensor's name in observations (``Observation.scans[name]``).
    kind : str
        ``"laser"``, ``"sonar"`` or ``"proximity"``.
    angles_rad : ndarray of shape (B,)
        Reported beam directions in the body frame [rad] (read-only; a sonar's transducer
        axes).
    ray_angles_rad : ndarray of shape (B * rays_per_beam,)
        Directions of every ray cast, beam by beam [rad].
    max_range_m : float
        Range reported for "no return" [m].
    noise_std_m, p_max, p_short : float
        Beam-mixture parameters (:func:`apply_beam_noise`); for a sonar ``p_max`` is its
        ``p_specular``.
    sees_robots : bool
        Whether rays stop on other robots' discs (when ``bodies`` are passed).

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> g = OccupancyGrid.empty(10.0, 4.0, 0.1)
    >>> s = build_range_sensor(LaserConfig(n_beams=3, fov_deg=180, noise_std_m=0.0), g)
    >>> s.true_ranges(np.array([5.0]), np.array([2.0]), np.array([0.0])).round(6).tolist()
    [[2.0, 5.0, 2.0]]
    """

    def __init__(self, name: str, kind: str, grid: OccupancyGrid, sees, angles_rad: np.ndarray,
                 ray_offsets_rad: np.ndarray, max_range_m: float, noise_std_m: float, p_max: float,
                 p_short: float, sees_robots: bool):
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
        self.name = str(name)
        self.kind = str(kind)
        angles = np.ascontiguousarray(angles_rad, dtype=np.float64)
        angles.setflags(write=False)
        self.angles_rad = angles
        offsets = np.asarray(ray_offsets_rad, dtype=np.float64)
        self.rays_per_beam = int(offsets.shape[0])
        rays = (angles[:, None] + offsets[None, :]).ravel()
        rays.setflags(write=False)
        self.ray_angles_rad = rays
        self.max_range_m = float(max_range_m)
        self.noise_std_m = float(noise_std_m)
        self.p_max = float(p_max)
        self.p_short = float(p_short)
        if self.p_max + self.p_short > 1.0:
            raise ValueError(
                f"sensor {self.name!r}: the max-range and short-reading probabilities must sum to <= 1, "
                f"got {self.p_max} + {self.p_short}"
            )
        self.sees_robots = bool(sees_robots)
        self.sees = tuple(sees)
        self.caster = RayCaster(grid, self.sees, self.max_range_m)
        self._plan = beam_plan(rays)

    def __repr__(self) -> str:
        return (f"RangeSensor(name={self.name!r}, kind={self.kind!r}, beams={self.angles_rad.shape[0]}, "
                f"rays_per_beam={self.rays_per_beam}, max_range_m={self.max_range_m}, sees={self.sees})")

    def info(self) -> SensorInfo:
        """What a robot knows of this sensor: name, kind, beam directions, range, noise."""
        return SensorInfo(self.name, self.kind, self.angles_rad.copy(), self.max_range_m, self.noise_std_m)

    # ------------------------------------------------------------------ truth
    def true_ranges(self, xs, ys, thetas, bodies=None) -> np.ndarray:
        """Noise-free ranges from true poses.

        Parameters
        ----------
        xs, ys, thetas : ndarray of shape (n,)
            True poses of the robots carrying the sensor [m, m, rad].
        bodies : tuple or None
            ``(all_x (N,), all_y (N,), all_radius (N,), self_index (n,))``: every robot's
            disc, and each sensing robot's own index into them (its own disc is skipped).
            Used only when the sensor ``sees_robots``.

        Returns
        -------
        ndarray of shape (n, B), float64
            Range [m] of each beam (nearest over its rays), in ``[0, max_range_m]``.
        """
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        ys = np.ascontiguousarray(ys, dtype=np.float64)
        thetas = np.ascontiguousarray(thetas, dtype=np.float64)
        if not (xs.ndim == 1 and ys.shape == xs.shape and thetas.shape == xs.shape):
            raise ValueError(f"xs, ys and thetas must be 1-D arrays of one shape (n,), got {xs.shape}, {ys.shape}, "
                             f"{thetas.shape}")
        if not (np.isfinite(xs).all() and np.isfinite(ys).all() and np.isfinite(thetas).all()):
            raise ValueError("xs, ys and thetas must be finite")
        if bodies is not None and self.sees_robots:
            bodies = check_bodies(bodies, xs.shape[0])
        return self._true_ranges(xs, ys, thetas, bodies)

    def _true_ranges(self, xs, ys, thetas, bodies) -> np.ndarray:
        """:meth:`true_ranges` without input checks (the engine's per-step path).

        ``xs, ys, thetas``: contiguous float64 (n,); ``bodies``: None or as returned by
        :func:`~teamnav.sim.sensors.robot_hits.check_bodies`. Small calls run serially
        (below ``PARALLEL_MIN_RAYS`` rays, waking numba's threads costs more than it saves).
        """
        n = xs.shape[0]
        parallel = n * self.ray_angles_rad.shape[0] >= PARALLEL_MIN_RAYS
        rays = self.caster.cast_xyt(xs, ys, thetas, self.ray_angles_rad, parallel=parallel)
        if bodies is not None and self.sees_robots:
            all_x, all_y, all_r, self_idx = bodies
            robot_hits_unchecked(xs, ys, thetas, self._plan, all_x, all_y, all_r, self_idx, rays,
                                 default_cell_m(self.max_range_m, all_r), parallel)
        if self.rays_per_beam == 1:
            return rays
        return rays.reshape(n, self.angles_rad.shape[0], self.rays_per_beam).min(axis=2)

    # ------------------------------------------------------------------ observation
    def sense(self, xs, ys, thetas, rng: np.random.Generator, bodies=None, out: np.ndarray | None = None) -> np.ndarray:
        """Observed ranges: :meth:`true_ranges` corrupted by the beam mixture.

        Parameters
        ----------
        xs, ys, thetas : ndarray of shape (n,)
            True poses [m, m, rad].
        rng : numpy.random.Generator
            The sensor's stream (see :func:`apply_beam_noise` for the draws).
        bodies : tuple or None
            As in :meth:`true_ranges`.
        out : ndarray of shape (n, B), float64, optional
            Filled and returned; otherwise a fresh array is returned.

        Returns
        -------
        ndarray of shape (n, B), float64
            Observed ranges [m] in ``[0, max_range_m]``, ``max_range_m`` meaning no return.
        """
        true = self.true_ranges(xs, ys, thetas, bodies)
        if out is None:
            out = true  # a fresh array already; noise is applied in place
        return apply_beam_noise(true, rng, self.noise_std_m, self.p_max, self.p_short, self.max_range_m, out)

    def _sense(self, xs, ys, thetas, rng: np.random.Generator, bodies=None) -> np.ndarray:
        """:meth:`sense` without input checks, into a fresh array (the engine's per-step path;
        arrays as in :meth:`_true_ranges`)."""
        true = self._true_ranges(xs, ys, thetas, bodies)
        return apply_beam_noise(true, rng, self.noise_std_m, self.p_max, self.p_short, self.max_range_m, true)


def build_range_sensor(cfg: LaserConfig | SonarConfig | ProximityConfig, grid: OccupancyGrid) -> RangeSensor:
    """The sensor model a configuration describes, bound to a map.

    - :class:`LaserConfig`: ``n_beams`` over ``fov_deg`` (:func:`beam_angles`), one ray each;
      mixture ``noise_std_m``, ``p_max``, ``p_short``.
    - :class:`SonarConfig`: ``n_transducers`` axes over ``fov_deg``; each a cone of
      ``cone_deg`` sampled by ``rays_per_cone`` rays evenly from edge to edge (one ray on the
      axis when ``rays_per_cone`` is 1); its reading is the nearest return over the cone,
      then the mixture with ``p_max = p_specular``.
    - :class:`ProximityConfig`: one ray per ``angles_deg`` (wrapped to ``(-pi, pi]``),
      Gaussian noise only.

    Parameters
    ----------
    cfg : LaserConfig, SonarConfig or ProximityConfig
    grid : OccupancyGrid

    Returns
    -------
    RangeSensor

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> s = build_range_sensor(SonarConfig(n_transducers=8, rays_per_cone=3), OccupancyGrid.empty(4, 4, 0.5))
    >>> s.angles_rad.shape, s.ray_angles_rad.shape, s.kind
    ((8,), (24,), 'sonar')
    """
    if isinstance(cfg, LaserConfig):
        return RangeSensor(cfg.name, "laser", grid, cfg.sees, beam_angles(cfg.n_beams, math.radians(cfg.fov_deg)),
                           np.zeros(1), cfg.max_range_m, cfg.noise_std_m, cfg.p_max, cfg.p_short, cfg.sees_robots)
    if isinstance(cfg, SonarConfig):
        axes = beam_angles(cfg.n_transducers, math.radians(cfg.fov_deg))
        half = math.radians(cfg.cone_deg) / 2
        offsets = np.zeros(1) if cfg.rays_per_cone == 1 else np.linspace(-half, half, cfg.rays_per_cone)
        return RangeSensor(cfg.name, "sonar", grid, cfg.sees, axes, offsets, cfg.max_range_m, cfg.noise_std_m,
                           cfg.p_specular, cfg.p_short, cfg.sees_robots)
    if isinstance(cfg, ProximityConfig):
        angles = np.atleast_1d(wrap_angle(np.radians(np.asarray(cfg.angles_deg, dtype=np.float64))))
        return RangeSensor(cfg.name, "proximity", grid, cfg.sees, angles, np.zeros(1), cfg.max_range_m,
                           cfg.noise_std_m, 0.0, 0.0, cfg.sees_robots)
    raise ValueError(
        f"cfg must be a LaserConfig, SonarConfig or ProximityConfig, got {type(cfg).__name__}"
    )
