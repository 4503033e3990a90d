"""Monte Carlo localization (MCL): the per-robot sample-based belief of Fox et al. §3.1.

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization", Autonomous Robots 8(3), 2000, doi:10.1023/A:1008937911390.

The belief ``Bel_n(L)`` is a set of K weighted samples ``<l_i, p_i>`` (eq. 11). One step:

1. *resample* (§3.1 step 1): draw K samples with likelihood given by their p-values
   (low-variance resampling, :mod:`~teamnav.localization.resample`); replace a few with
   samples uniform over free space (§3.1, "a small number of uniformly distributed, random
   samples after each estimation step"), a fixed fraction or, with ``recovery="augmented"``,
   the adaptive fraction ``max(0, 1 - w_fast / w_slow)`` of *Probabilistic Robotics* Table 8.3;
   with ``adaptive=True`` the count K itself follows KLD-sampling
   (:mod:`~teamnav.localization.kld`: many samples when lost, few when tracking);
2. *predict* (eq. 6): move every sample by a draw of the odometry motion model
   (:mod:`~teamnav.localization.motion`);
3. *update* (eq. 12): ``p <- alpha P(o | l) p`` with the beam model (Fig. 1, laser or sonar
   cones; :mod:`~teamnav.localization.beam_model`) or the likelihood field
   (:mod:`~teamnav.localization.likelihood_field`).

Detections from teammates enter through :meth:`MCL.multiply_weights` (eq. 14; see
:mod:`~teamnav.localization.sync`). The filter sees only its robot's map, sensor datasheet,
odometry and ranges; scoring against a reference pose is the caller's business
(:func:`sample_error_m`, :func:`pose_error`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator
from numba import njit

from teamnav.control.protocol import SensorInfo
from teamnav.geometry.angles import wrap_angle
from teamnav.localization._checks import SampleSetState, array, generator
from teamnav.localization.beam_model import (BeamModelParams, BeamTable, beam_loglik_cast_kernel, beam_loglik_kernel,
                                             beam_loglik_kernel_serial)
from teamnav.localization.kld import KLDParams, kld_count_kernel
from teamnav.localization.likelihood_field import (
    LikelihoodFieldParams, build_log_field, lf_loglik_kernel, lf_loglik_kernel_serial,
)
from teamnav.localization.motion import MotionParams, _wrap, motion_kernel, motion_kernel_serial
from teamnav.localization.resample import effective_sample_size, low_variance_kernel, normalize_log_weights
from teamnav.world.distance import distance_field
from teamnav.world.grid import DEFAULT_SEES, FREE, OccupancyGrid
from teamnav.world.raycast import RayCaster

__all__ = ["Estimate", "MCL", "MCLParams", "pose_error", "sample_error_m"]



def gaussian_poses(rng: np.random.Generator, pose, cov, n: int) -> np.ndarray:
    """``n`` poses drawn from ``N(pose, cov)`` (headings wrapped), shape (n, 3): the tracking
    prior of :meth:`MCL.init_pose` and of :class:`~teamnav.localization.odometry_belief.OdometryBelief`.

    Raises
    ------
    ValueError
        ``pose`` not of shape (3,), or ``cov`` not a symmetric positive semi-definite (3, 3) matrix.
    """
    mu = array("pose", pose, (3,))
    c = array("cov", cov, (3, 3))
    if not np.allclose(c, c.T, atol=1e-12) or np.linalg.eigvalsh(c).min() < -1e-12:
        raise ValueError(f"cov must be a symmetric positive semi-definite (3, 3) matrix, got {c.tolist()}")
    z = rng.standard_normal((n, 3))
    vals, vecs = np.linalg.eigh(c)
    p = mu + (z * np.sqrt(np.clip(vals, 0.0, None))) @ vecs.T
    p[:, 2] = wrap_angle(p[:, 2])
    return p

class MCLParams(BaseModel):
    """Parameters of one robot's MCL filter.

    Attributes
    ----------
    n_particles : int, default 1000
        Sample set size K (with ``adaptive``: the size used by :meth:`MCL.init_pose`; global
        initialisation uses ``kld.max_particles``).
    sensor_model : {"beam", "likelihood_field"}, default "beam"
        Perception model (§2.2 Fig. 1, or Probabilistic Robotics §6.4).
    beam, likelihood_field, motion, kld
        Parameters of each part.
    beam_stride : int, default 1
        Use every ``beam_stride``-th beam of the scan (neighbouring beams are far from
        independent, Probabilistic Robotics §6.3.4).
    likelihood_exponent : float in (0, 1], default 1
        ``P(o | l)`` is raised to this power (tempering against correlated beams).
    sonar_cone_deg, sonar_rays_per_cone
        Opening [deg] of a sonar transducer's cone and rays cast across it (its expected
        distance is their minimum); used when the sensor's ``kind`` is ``"sonar"``.
    sees : tuple of str or None
        Materials the sensor perceives; None: ``DEFAULT_SEES[sensor.kind]``.
    recovery : {"none", "fixed", "augmented"}, default "fixed"
        Random samples per resampling: none; ``random_fraction`` of them (Fox et al. §3.1);
        ``max(0, 1 - w_fast / w_slow)`` of them (Probabilistic Robotics Table 8.3).
    random_fraction : float in [0, 0.5], default 0.01
    alpha_slow, alpha_fast : float
        Averaging rates of ``w_slow``, ``w_fast`` (``0 < alpha_slow < alpha_fast <= 1``).
    adaptive : bool, default False
        Adapt the sample count at each resampling (``adapt`` says how).
    adapt : {"kld", "likelihood"}, default "kld"
        ``"kld"``: KLD-sampling (Fox 2003). ``"likelihood"``: the likelihood-based adaptation of
        Fox et al. (1999a), the method Fox et al. 2000 §3.1 cites for "MCL determines the sample set
        size on-the-fly": samples are drawn until the sum of their non-normalised likelihoods
        exceeds a threshold ``eta``. Here the next set's count is the number expected to reach it,
        ``n = eta / mean_i P(o | l_i)`` of the last applied scan, with ``eta = min_particles *
        P_ref`` and ``log P_ref = likelihood_ref_per_beam * (beams used) * likelihood_exponent``,
        clipped to ``[kld.min_particles, kld.max_particles]`` (:meth:`MCL.likelihood_count`): a
        robot whose samples fit the scan as well as a tracking robot's keeps about
        ``min_particles``, one whose samples fit worse (lost) gets more.
    likelihood_ref_per_beam : float or None
        ``log P_ref`` per used beam (untempered) for ``adapt="likelihood"``: a tracking filter's
        per-beam log mean likelihood (a fill; :attr:`MCL.last_log_mean_likelihood_per_beam`).
    init_clearance_m : float, default 0
        Uniform samples are drawn only where the nearest obstacle is at least this far [m].
    min_update_trans_m, min_update_rot_rad : float, default 0
        :meth:`MCL.step` applies the scan only once the robot moved this far since the last
        applied scan (a standing robot would re-apply the same evidence); 0: every step.
    cluster_cell_m : float, default 0.5
        Cell of the grid whose connected components are the belief's clusters [m].
    parallel : bool, default True
        Use numba's threads for calls of at least ``parallel_min_work`` particle-beams
        (smaller calls run serially: on busy cores a thread launch costs milliseconds).
    parallel_min_work : int, default 200000
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    n_particles: int = Field(1000, ge=1, le=10_000_000)
    sensor_model: Literal["beam", "likelihood_field"] = "beam"
    beam: BeamModelParams = BeamModelParams()
    likelihood_field: LikelihoodFieldParams = LikelihoodFieldParams()
    motion: MotionParams = MotionParams()
    beam_stride: int = Field(1, ge=1, le=4096)
    likelihood_exponent: float = Field(1.0, gt=0.0, le=1.0)
    sonar_cone_deg: float = Field(15.0, ge=0.0, le=90.0)
    sonar_rays_per_cone: int = Field(5, ge=1, le=64)
    sees: tuple[str, ...] | None = None
    recovery: Literal["none", "fixed", "augmented"] = "fixed"
    random_fraction: float = Field(0.01, ge=0.0, le=0.5)
    alpha_slow: float = Field(0.001, gt=0.0, lt=1.0)
    alpha_fast: float = Field(0.1, gt=0.0, le=1.0)
    adaptive: bool = False
    adapt: Literal["kld", "likelihood"] = "kld"
    likelihood_ref_per_beam: float | None = Field(None, ge=-1e6, le=1e6)
    kld: KLDParams = KLDParams()
    init_clearance_m: float = Field(0.0, ge=0.0, le=10.0)
    min_update_trans_m: float = Field(0.0, ge=0.0, le=100.0)
    min_update_rot_rad: float = Field(0.0, ge=0.0, le=2 * math.pi)
    cluster_cell_m: float = Field(0.5, gt=0.0, le=100.0)
    parallel: bool = True
    parallel_min_work: int = Field(200_000, ge=0, le=10**12)

    @model_validator(mode="after")
    def _rates(self) -> "MCLParams":
        if self.recovery == "augmented" and not self.alpha_slow < self.alpha_fast:
            raise ValueError(f"alpha_slow must be < alpha_fast ({self.alpha_fast}) for recovery='augmented', "
                             f"got {self.alpha_slow}")
        if self.adapt == "likelihood" and self.likelihood_ref_per_beam is None:
            raise ValueError("adapt='likelihood' needs likelihood_ref_per_beam (a tracking filter's per-beam log "
                             "mean likelihood)")
        return self


@dataclass(frozen=True)
class Estimate:
    """A summary of the belief.

    Attributes
    ----------
    pose : ndarray of shape (3,)
        Weighted mean ``x [m], y [m]`` and circular mean heading [rad] of all samples.
    cov : ndarray of shape (3, 3)
        Weighted covariance (heading deviations wrapped around the mean).
    cluster_pose : ndarray of shape (3,)
        Weighted mean of the heaviest cluster (connected cells of ``cluster_cell_m`` holding
        samples): the estimate to act on when the belief is multi-modal.
    cluster_weight : float
        Total weight of that cluster, in (0, 1]. Not a concentration measure on its own: a
        uniform belief over a connected free space fills every cell and is one cluster of
        weight 1 (2000 samples in the symmetric hallway); read it with ``cluster_spread_m``.
    n_clusters : int
        Number of clusters.
    ess : float
        Effective sample size of the weights.
    n_particles : int
    cluster_spread_m : float
        Position spread of the heaviest cluster, ``sqrt(var x + var y)`` of its samples under
        their weights [m].
    """

    pose: np.ndarray
    cov: np.ndarray
    cluster_pose: np.ndarray
    cluster_weight: float
    n_clusters: int
    ess: float
    n_particles: int
    cluster_spread_m: float


@njit(cache=True)
def _weighted_pose_kernel(p, w, sel, out_mean, out_cov):
    """Weighted mean (circular in heading) and covariance of the samples with ``sel[i]``."""
    s = 0.0
    sx = 0.0
    sy = 0.0
    ss = 0.0
    sc = 0.0
    for i in range(p.shape[0]):
        if sel[i]:
            wi = w[i]
            s += wi
            sx += wi * p[i, 0]
            sy += wi * p[i, 1]
            ss += wi * math.sin(p[i, 2])
            sc += wi * math.cos(p[i, 2])
    x = sx / s
    y = sy / s
    th = math.atan2(ss, sc)
    out_mean[0] = x
    out_mean[1] = y
    out_mean[2] = th
    out_cov[:, :] = 0.0
    d = np.empty(3)
    for i in range(p.shape[0]):
        if sel[i]:
            wi = w[i] / s
            d[0] = p[i, 0] - x
            d[1] = p[i, 1] - y
            d[2] = _wrap(p[i, 2] - th)
            for a in range(3):
                for b in range(a, 3):
                    out_cov[a, b] += wi * d[a] * d[b]
    for a in range(3):
        for b in range(a):
            out_cov[a, b] = out_cov[b, a]


@njit(cache=True)
def _find(parent, a):
    while parent[a] != a:
        parent[a] = parent[parent[a]]
        a = parent[a]
    return a


@njit(cache=True)
def _clusters_kernel(p, w, cell, sel):
    """Clusters of the samples: 8-connected components of the cells of side ``cell`` that hold
    samples (``scipy.ndimage.label`` with a 3 x 3 structure), numbered in raster order of the
    cells. Marks in ``sel`` the samples of the heaviest cluster (the first on a tie); returns
    ``(n_clusters, its weight)``."""
    n = p.shape[0]
    xmin = p[0, 0]
    ymin = p[0, 1]
    for i in range(n):
        xmin = min(xmin, p[i, 0])
        ymin = min(ymin, p[i, 1])
    ix = np.empty(n, np.int64)
    iy = np.empty(n, np.int64)
    nx = 0
    ny = 0
    for i in range(n):
        ix[i] = int((p[i, 0] - xmin) / cell)
        iy[i] = int((p[i, 1] - ymin) / cell)
        nx = max(nx, ix[i] + 1)
        ny = max(ny, iy[i] + 1)
    # occupied cells, sorted in raster order, and the cell of every sample
    key = iy * nx + ix
    order = np.argsort(key, kind="mergesort")
    cell_of = np.empty(n, np.int64)
    keys = np.empty(n, np.int64)
    m = 0
    for k in range(n):
        i = order[k]
        if m == 0 or keys[m - 1] != key[i]:
            keys[m] = key[i]
            m += 1
        cell_of[i] = m - 1
    keys = keys[:m]
    parent = np.arange(m)
    # union with the already-seen neighbours (left, and the three below) found by binary search
    for a in range(m):
        r = keys[a] // nx
        c = keys[a] - r * nx
        for dr, dc in ((0, -1), (-1, -1), (-1, 0), (-1, 1)):
            rr = r + dr
            cc = c + dc
            if rr < 0 or cc < 0 or cc >= nx:
                continue
            kb = rr * nx + cc
            b = np.searchsorted(keys, kb)
            if b < m and keys[b] == kb:
                ra = _find(parent, a)
                rb = _find(parent, b)
                if ra != rb:
                    if ra < rb:
                        parent[rb] = ra
                    else:
                        parent[ra] = rb
    # roots are the lowest cell (raster order) of each component: number them in that order
    label = np.empty(m, np.int64)
    n_clusters = 0
    for a in range(m):
        ra = _find(parent, a)
        if ra == a:
            label[a] = n_clusters
            n_clusters += 1
        else:
            label[a] = label[ra]
    cw = np.zeros(n_clusters)
    for i in range(n):
        cw[label[cell_of[i]]] += w[i]
    best = 0
    for k in range(1, n_clusters):
        if cw[k] > cw[best]:
            best = k
    for i in range(n):
        sel[i] = label[cell_of[i]] == best
    return n_clusters, cw[best]


class MCL(SampleSetState):
    """One robot's Monte Carlo localization filter (Fox et al. §3.1).

    Parameters
    ----------
    params : MCLParams
    known_map : OccupancyGrid
        The map the robot was given (:attr:`RobotInfo.known_map`).
    sensor : SensorInfo
        The range sensor whose scans :meth:`update` receives (beam directions, range, kind).
    rng : numpy.random.Generator
        This filter's own stream.

    Attributes
    ----------
    particles : ndarray of shape (n, 3)
        Sample poses ``x [m], y [m], theta [rad]`` (read-only view).
    weights : ndarray of shape (n,)
        Normalised p-values (read-only view).

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> g = OccupancyGrid.empty(4.0, 2.0, 0.1)
    >>> s = SensorInfo("laser", "laser", np.linspace(-np.pi / 2, np.pi / 2, 5), 5.0)
    >>> f = MCL(MCLParams(n_particles=200), g, s, np.random.default_rng(0))
    >>> f.init_pose([1.0, 1.0, 0.0], np.diag([0.01, 0.01, 0.01]))
    >>> f.step([0.1, 0.0, 0.0], np.array([1.0, 1.0, 2.9, 1.0, 1.0]))
    >>> est = f.estimate()
    >>> bool(abs(est.pose[0] - 1.1) < 0.1), f.particles.shape
    (True, (200, 3))
    """

    _EMPTY_HINT = "the filter has no samples yet; call init_global() or init_pose() first"

    def __init__(self, params: MCLParams, known_map: OccupancyGrid, sensor: SensorInfo, rng: np.random.Generator):
        if not isinstance(params, MCLParams):
            raise ValueError(f"params must be an MCLParams, got {type(params).__name__}")
        if not isinstance(known_map, OccupancyGrid):
            raise ValueError(f"known_map must be an OccupancyGrid, got {type(known_map).__name__}")
        if not isinstance(sensor, SensorInfo):
            raise ValueError(f"sensor must be a SensorInfo, got {type(sensor).__name__}")
        self.params = params
        self.map = known_map
        self.sensor = sensor
        self.rng = generator("rng", rng)
        angles = array("sensor.angles_rad", sensor.angles_rad, (-1,))
        if angles.shape[0] == 0:
            raise ValueError("sensor.angles_rad must hold at least one beam direction, got none")
        if not (math.isfinite(sensor.max_range_m) and sensor.max_range_m > 0):
            raise ValueError(f"sensor.max_range_m must be a finite number > 0, got {sensor.max_range_m!r}")
        sees = params.sees
        if sees is None:
            if sensor.kind not in DEFAULT_SEES:
                raise ValueError(f"sensor.kind must be one of {sorted(DEFAULT_SEES)} when params.sees is None, "
                                 f"got {sensor.kind!r}")
            sees = DEFAULT_SEES[sensor.kind]
        self.sees = tuple(sees)
        self.max_range_m = float(sensor.max_range_m)
        self.n_beams = int(angles.shape[0])
        self._beam_idx = np.arange(0, self.n_beams, params.beam_stride)
        used = angles[self._beam_idx]
        if sensor.kind == "sonar" and params.sonar_rays_per_cone > 1 and params.sonar_cone_deg > 0:
            half = math.radians(params.sonar_cone_deg) / 2
            offsets = np.linspace(-half, half, params.sonar_rays_per_cone)
        else:
            offsets = np.zeros(1)
        self._k = int(offsets.shape[0])
        self._ray_angles = np.ascontiguousarray((used[:, None] + offsets[None, :]).ravel())
        self._ray_cs = (np.cos(self._ray_angles), np.sin(self._ray_angles))  # what cast_xyt computes per call
        self._used_angles = used
        blocking = known_map.blocking(self.sees)
        self._caster = (RayCaster(known_map, self.sees, self.max_range_m, stretched=True)
                        if params.sensor_model == "beam" else None)
        self._beam_table = BeamTable(params.beam, self.max_range_m) if params.sensor_model == "beam" else None
        free = known_map.cells == FREE
        if params.init_clearance_m > 0:
            free &= distance_field(known_map) >= params.init_clearance_m
        self._free_cells = np.argwhere(free)
        if self._free_cells.shape[0] == 0:
            raise ValueError(f"known_map {known_map.name} has no free cell with clearance >= "
                             f"{params.init_clearance_m} m to sample poses in")
        #: Free area a pose can be in [m²] (the support of the uniform prior).
        self.free_area_m2 = float(self._free_cells.shape[0] * known_map.resolution_m ** 2)
        if params.sensor_model == "likelihood_field":
            self._lf_table, self._lf_outside = build_log_field(known_map, blocking, params.likelihood_field,
                                                               self.max_range_m)
            self._lf_free = (known_map.cells == FREE).astype(np.uint8)
            self._lf_worst = math.log(params.likelihood_field.z_rand / self.max_range_m)
        # KLD histogram over the map's bounding box
        kp = params.kld
        xmin, xmax, ymin, ymax = known_map.bounds_m
        self._kld_geom = (xmin, ymin, kp.bin_xy_m, math.radians(kp.bin_theta_deg),
                          max(1, int(math.ceil((xmax - xmin) / kp.bin_xy_m))),
                          max(1, int(math.ceil((ymax - ymin) / kp.bin_xy_m))),
                          max(1, int(math.ceil(360.0 / kp.bin_theta_deg))))
        self._kld_hist = None
        self._particles = np.zeros((0, 3))
        self._weights = np.zeros(0)
        self._weighted = False
        self._rays = np.empty((0, 0))
        self._table = None
        self._ll = np.empty(0)
        self._log_w_slow = None
        self._log_w_fast = None
        self._since_update = np.zeros(2)  # |trans| [m], |rot| [rad] since the last applied scan
        self._updated_once = False
        #: Log of the average likelihood ``sum_i p_i P(o | l_i)`` of the last applied scan.
        self.last_log_mean_likelihood = float("nan")

    # ------------------------------------------------------------------ state
    def _set(self, particles: np.ndarray) -> None:
        self._particles = np.ascontiguousarray(particles, dtype=np.float64)
        n = self._particles.shape[0]
        self._weights = np.full(n, 1.0 / n)
        self._weighted = False

    def _uniform_poses(self, n: int) -> np.ndarray:
        """``n`` poses uniform over free space (cells with the clearance), headings uniform."""
        cells = self._free_cells[self.rng.integers(0, self._free_cells.shape[0], size=n)]
        res = self.map.resolution_m
        u = self.rng.random((n, 3))
        out = np.empty((n, 3))
        if not self.map.rotated:
            out[:, 0] = self.map.origin_xy_m[0] + (cells[:, 1] + u[:, 0]) * res
            out[:, 1] = self.map.origin_xy_m[1] + (cells[:, 0] + u[:, 1]) * res
        else:
            out[:, :2] = self.map.cell_to_world(cells[:, 0] + u[:, 1], cells[:, 1] + u[:, 0])
        out[:, 2] = wrap_angle(-math.pi + 2.0 * math.pi * u[:, 2])
        return out

    # ------------------------------------------------------------------ initialisation
    def init_global(self) -> None:
        """Uniform belief over the free space (Fox et al. §2.2: ``Bel(0)`` uniform; Fig. 4a).

        K samples (``kld.max_particles`` when ``adaptive``) uniform over free cells, headings
        uniform in (-pi, pi].
        """
        n = self.params.kld.max_particles if self.params.adaptive else self.params.n_particles
        self._set(self._uniform_poses(n))
        self._reset_recovery()

    def init_pose(self, pose, cov) -> None:
        """Gaussian belief ``N(pose, cov)`` of K = ``n_particles`` samples (position tracking).

        Parameters
        ----------
        pose : array_like of shape (3,)
            Mean ``x [m], y [m], theta [rad]``.
        cov : array_like of shape (3, 3)
            Symmetric positive semi-definite covariance [m², m², rad²].
        """
        self._set(gaussian_poses(self.rng, pose, cov, self.params.n_particles))
        self._reset_recovery()

    def _reset_recovery(self) -> None:
        self._log_w_slow = None
        self._log_w_fast = None
        self._since_update[:] = 0.0
        self._updated_once = False

    # ------------------------------------------------------------------ the three phases
    def predict(self, odom_delta) -> None:
        """Motion update (eq. 6): move every sample by a draw of ``P(l | l', a)``.

        Parameters
        ----------
        odom_delta : array_like of shape (3,)
            Odometry step ``(dx [m], dy [m], dtheta [rad])`` in the previous body frame
            (:attr:`Observation.odom_delta`).
        """
        self._require_particles("predict")
        d = array("odom_delta", odom_delta, (3,))
        noise = self.rng.standard_normal((self._particles.shape[0], 3))
        kernel = motion_kernel if self._threads(self._particles.shape[0] * 3) else motion_kernel_serial
        kernel(self._particles, float(d[0]), float(d[1]), float(d[2]),
                      np.asarray(self.params.motion.alpha, dtype=np.float64), noise)
        self._since_update[0] += math.hypot(d[0], d[1])
        self._since_update[1] += abs(float(wrap_angle(d[2])))

    def _threads(self, work: int) -> bool:
        return self.params.parallel and work >= self.params.parallel_min_work

    def log_likelihood(self, scan_ranges) -> np.ndarray:
        """``log P(o | l_i)`` (times ``likelihood_exponent``) of a scan for every sample, (n,)."""
        self._require_particles("log_likelihood")
        z = array("scan_ranges", scan_ranges, (self.n_beams,))
        if (z < 0).any():
            raise ValueError(f"scan_ranges must be >= 0 m, got {z[z < 0][0]!r}")
        z = np.minimum(z[self._beam_idx], self.max_range_m)
        n = self._particles.shape[0]
        if self._ll.shape[0] != n:
            self._ll = np.empty(n)
        exponent = self.params.likelihood_exponent
        if self.params.sensor_model == "beam":
            r = self._ray_angles.shape[0]
            p = self._particles
            threads = self._threads(n * r)
            if not np.isfinite(p).all():
                raise ValueError("particle poses must be finite")
            self._table = table = self._beam_table(z, out=self._table)  # reuses the last scan's buffer
            inv_step = 1.0 / self._beam_table.step_m
            if not threads and self._caster.stretch is not None:  # cast and sum in one pass
                beam_loglik_cast_kernel(*self._caster._kernel_inputs(p[:, 0], p[:, 1], p[:, 2]), *self._ray_cs,
                                        self._k, table, inv_step, exponent, self._ll)
            else:
                if self._rays.shape != (n, r):
                    self._rays = np.empty((n, r))
                self._caster._cast_into(p[:, 0], p[:, 1], p[:, 2], *self._ray_cs, self._rays, threads)
                kernel = beam_loglik_kernel if threads else beam_loglik_kernel_serial
                kernel(self._rays, self._k, table, inv_step, exponent, self._ll)
        else:
            keep = z < self.max_range_m - 1e-6
            a = self._used_angles[keep]
            zz = z[keep]
            g = self.map
            kernel = lf_loglik_kernel if self._threads(n * zz.shape[0]) else lf_loglik_kernel_serial
            parts, ox, oy = self._particles, g.origin_xy_m[0], g.origin_xy_m[1]
            if g.rotated:  # the field is read in the grid's local frame
                lx, ly, ox, oy = g.kernel_frame(parts[:, 0], parts[:, 1])
                parts = np.ascontiguousarray(np.stack([lx, ly, g.kernel_theta(parts[:, 2])], axis=1))
            kernel(parts, np.ascontiguousarray(zz * np.cos(a)), np.ascontiguousarray(zz * np.sin(a)),
                             self._lf_table, self._lf_free, ox, oy, 1.0 / g.resolution_m,
                             self._lf_outside, self._lf_worst, exponent, self._ll)
        return self._ll

    def pose_log_likelihood(self, poses, scan_ranges) -> np.ndarray:
        """``log P(o | l)`` (times ``likelihood_exponent``) of a scan at arbitrary ``poses``, (k,).

        The same model as :meth:`log_likelihood`, evaluated at poses that are not samples of the
        set (the brain's sensor resetting picks the heading of a sample drawn from a received
        tree with it); the sample set is left as it was.

        Parameters
        ----------
        poses : array_like of shape (k, 3)
            Poses [m, m, rad].
        scan_ranges : array_like of shape (B,)
            As in :meth:`update`.
        """
        q = np.ascontiguousarray(array("poses", poses, (-1, 3)), dtype=np.float64)
        keep = (self._particles, self._weights, self._ll, self._rays, self._weighted)
        try:
            self._particles = q
            self._ll = np.empty(q.shape[0])
            self._rays = np.empty((0, 0))
            return self.log_likelihood(scan_ranges).copy()
        finally:
            self._particles, self._weights, self._ll, self._rays, self._weighted = keep

    def update(self, scan_ranges) -> None:
        """Perception update (eq. 12): ``p <- alpha P(o | l) p``.

        Parameters
        ----------
        scan_ranges : array_like of shape (B,)
            The sensor's ranges [m] (``RangeScan.ranges_m``), one per beam of ``sensor``;
            readings at or beyond ``max_range_m`` are max-range readings.
        """
        ll = self.log_likelihood(scan_ranges)
        with np.errstate(divide="ignore"):
            log_w = np.log(self._weights) + ll
        self._weights, log_mean = normalize_log_weights(log_w)
        self.last_log_mean_likelihood = log_mean
        self._weighted = True
        self._since_update[:] = 0.0
        self._updated_once = True
        if self.params.recovery == "augmented":  # Table 8.3 lines 8-10, in log space
            ps = self.params
            if self._log_w_slow is None:
                self._log_w_slow = self._log_w_fast = log_mean
            else:
                self._log_w_slow = float(np.logaddexp(math.log1p(-ps.alpha_slow) + self._log_w_slow,
                                                      math.log(ps.alpha_slow) + log_mean))
                self._log_w_fast = float(np.logaddexp(math.log1p(-ps.alpha_fast) + self._log_w_fast if ps.alpha_fast < 1
                                                      else -math.inf, math.log(ps.alpha_fast) + log_mean))

    @property
    def last_log_mean_likelihood_per_beam(self) -> float:
        """:attr:`last_log_mean_likelihood` per used beam, untempered (NaN before the first scan)."""
        return self.last_log_mean_likelihood / (self._beam_idx.shape[0] * self.params.likelihood_exponent)

    def likelihood_count(self) -> int:
        """Sample count of the next set under ``adapt="likelihood"`` (see :class:`MCLParams`): the
        number of samples whose likelihoods are expected to sum to ``eta``; ``max_particles`` before
        the first scan."""
        ps = self.params
        kp = ps.kld
        ll = self.last_log_mean_likelihood
        if not math.isfinite(ll) or ps.likelihood_ref_per_beam is None:
            return kp.max_particles
        ref = ps.likelihood_ref_per_beam * self._beam_idx.shape[0] * ps.likelihood_exponent
        n = kp.min_particles * math.exp(min(ref - ll, 50.0))
        return int(min(kp.max_particles, max(kp.min_particles, math.ceil(n))))

    def random_sample_probability(self) -> float:
        """Share of samples the next :meth:`resample` draws uniformly over free space."""
        ps = self.params
        if ps.recovery == "fixed":
            return ps.random_fraction
        if ps.recovery == "augmented" and self._log_w_slow is not None:
            return max(0.0, 1.0 - math.exp(min(self._log_w_fast - self._log_w_slow, 50.0)))
        return 0.0

    def resample(self) -> None:
        """Draw a new, equally weighted sample set from the weighted one (§3.1 step 1).

        Low-variance draws; the count is ``n_particles`` or, with ``adaptive``, the
        KLD-sampling bound (Fox 2003) over the drawn samples or the likelihood-based count
        (Fox et al. 1999a, :meth:`likelihood_count`); then each sample is replaced with
        probability :meth:`random_sample_probability` by one uniform over free space.
        """
        self._require_particles("resample")
        ps = self.params
        w = self._weights
        if ps.adaptive and ps.adapt == "likelihood":
            n = self.likelihood_count()
            idx = low_variance_kernel(w, n, float(self.rng.random()), np.empty(n, dtype=np.int64))
        elif ps.adaptive:
            kp = ps.kld
            m = kp.max_particles
            idx = low_variance_kernel(w, m, float(self.rng.random()), np.empty(m, dtype=np.int64))
            idx = idx[self.rng.permutation(m)]
            xmin, ymin, bxy, bth, nx, ny, nth = self._kld_geom
            if self._kld_hist is None:
                self._kld_hist = np.zeros(nx * ny * nth, dtype=np.uint8)
            n = kld_count_kernel(self._particles, idx, xmin, ymin, bxy, bth, self._kld_hist, nx, ny, nth,
                                 kp.epsilon, kp.z, kp.min_particles, m)
            idx = np.sort(idx[:n])
        else:
            n = ps.n_particles
            idx = low_variance_kernel(w, n, float(self.rng.random()), np.empty(n, dtype=np.int64))
        new = self._particles[idx]
        p_rand = self.random_sample_probability()
        if p_rand > 0:
            k = int(self.rng.binomial(n, p_rand))
            if k:
                where = self.rng.choice(n, size=k, replace=False)
                new[where] = self._uniform_poses(k)
        self._set(new)

    def step(self, odom_delta, scan_ranges) -> None:
        """One MCL step: :meth:`resample` (if weighted), :meth:`predict`, :meth:`update`.

        The scan is applied only once the robot moved ``min_update_trans_m`` or turned
        ``min_update_rot_rad`` since the last applied scan (always the first time), and the set
        is resampled only after a scan was applied.
        """
        self._require_particles("step")
        if self._weighted:
            self.resample()
        self.predict(odom_delta)
        ps = self.params
        moved = (self._since_update[0] >= ps.min_update_trans_m) or (self._since_update[1] >= ps.min_update_rot_rad)
        if moved or not self._updated_once:
            self.update(scan_ranges)

    # ------------------------------------------------------------------ detections
    def multiply_weights(self, factors) -> bool:
        """``p_i <- alpha p_i f_i``: fold external evidence into the weights (eq. 14).

        Parameters
        ----------
        factors : array_like of shape (n,)
            Finite, >= 0, one per sample (e.g. a density tree evaluated at the samples).

        Returns
        -------
        bool
            False (weights unchanged) when every product is 0: the evidence contradicts the
            whole belief and is ignored rather than wiping it out.
        """
        self._require_particles("multiply_weights")
        f = array("factors", factors, (self._particles.shape[0],))
        if (f < 0).any():
            raise ValueError(f"factors must be >= 0, got {f[f < 0][0]!r}")
        w = self._weights * f
        s = float(w.sum())
        if not s > 0:
            return False
        self._weights = w / s
        self._weighted = True
        return True

    def replace_samples(self, poses) -> None:
        """Replace randomly chosen samples by ``poses``, each with the set's mean weight.

        Sensor resetting (Lenser & Veloso 2000; Thrun et al. 2001 Mixture-MCL), not in Fox et
        al.: a detection can only reweight samples that already exist (eq. 14), so a belief
        whose samples all lie elsewhere cannot take it in; drawing a few samples from the
        detection's density gives the evidence somewhere to land.

        Parameters
        ----------
        poses : array_like of shape (k, 3)
            ``k <= n`` poses [m, m, rad].
        """
        self._require_particles("replace_samples")
        q = array("poses", poses, (-1, 3))
        n = self._particles.shape[0]
        k = q.shape[0]
        if k > n:
            raise ValueError(f"poses must hold at most {n} rows (the sample count), got {k}")
        if k == 0:
            return
        where = self.rng.choice(n, size=k, replace=False)
        p = self._particles.copy()
        p[where] = q
        p[:, 2] = wrap_angle(p[:, 2])
        w = self._weights.copy()
        w[where] = 1.0 / n
        self._particles = np.ascontiguousarray(p)
        self._weights = w / w.sum()
        self._weighted = True

    def append_samples(self, poses) -> None:
        """Add ``poses`` to the set, each with the set's mean weight (sensor resetting that keeps
        every existing sample; the next resampling brings the count back within the KLD bounds).

        Parameters
        ----------
        poses : array_like of shape (k, 3)
            Poses [m, m, rad].
        """
        self._require_particles("append_samples")
        q = array("poses", poses, (-1, 3))
        if q.shape[0] == 0:
            return
        n = self._particles.shape[0]
        q = q.copy()
        q[:, 2] = wrap_angle(q[:, 2])
        self._particles = np.ascontiguousarray(np.vstack([self._particles, q]), dtype=np.float64)
        w = np.concatenate([self._weights, np.full(q.shape[0], 1.0 / n)])
        self._weights = w / w.sum()
        self._weighted = True

    def move_samples(self, poses) -> None:
        """Give every sample a new pose, weights kept (not in Fox et al.: delayed integration,
        :mod:`teamnav.papers.collab_mcl.brains.delayed_integration`, moves the set into the frame of a past
        detection and back).

        Parameters
        ----------
        poses : array_like of shape (n, 3)
            One pose per sample [m, m, rad], in the order of :attr:`particles`.
        """
        self._require_particles("move_samples")
        q = array("poses", poses, (self._particles.shape[0], 3)).copy()
        q[:, 2] = wrap_angle(q[:, 2])
        self._particles = np.ascontiguousarray(q, dtype=np.float64)

    # ------------------------------------------------------------------ estimates
    def estimate(self) -> Estimate:
        """Weighted mean and covariance, and the heaviest cluster's mean (see :class:`Estimate`)."""
        self._require_particles("estimate")
        p, w = self._particles, self._weights
        n = p.shape[0]
        mean, cov = np.empty(3), np.empty((3, 3))
        _weighted_pose_kernel(p, w, np.ones(n, dtype=np.bool_), mean, cov)
        sel = np.empty(n, dtype=np.bool_)
        n_clusters, cluster_weight = _clusters_kernel(p, w, float(self.params.cluster_cell_m), sel)
        cmean, ccov = np.empty(3), np.empty((3, 3))
        _weighted_pose_kernel(p, w, sel, cmean, ccov)
        spread = math.sqrt(max(0.0, float(ccov[0, 0] + ccov[1, 1])))
        return Estimate(mean, cov, cmean, float(cluster_weight), int(n_clusters), effective_sample_size(w), int(n),
                        spread)


# ---------------------------------------------------------------------------- scoring helpers
def sample_error_m(particles, weights, reference_xy) -> float:
    """Weighted average distance of all samples from a reference position [m].

    Fox et al. §5.1: "The estimation error is measured by the average distance of all samples
    from the reference position." The reference comes from the caller (an experiment reading
    the simulator); the filter never has it.

    Examples
    --------
    >>> sample_error_m(np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 1.0]]), np.array([0.5, 0.5]), [1.0, 0.0])
    1.0
    """
    p = array("particles", particles, (-1, 3))
    w = array("weights", weights, (p.shape[0],))
    ref = array("reference_xy", reference_xy, (-1,))
    if ref.shape[0] not in (2, 3):
        raise ValueError(f"reference_xy must have 2 (x, y) or 3 (x, y, theta) entries, got {ref.shape[0]}")
    if (w < 0).any() or not w.sum() > 0:
        raise ValueError("weights must be >= 0 with a positive sum")
    d = np.hypot(p[:, 0] - ref[0], p[:, 1] - ref[1])
    return float(np.dot(w, d) / w.sum())


def pose_error(estimate_pose, reference_pose) -> tuple[float, float]:
    """Position error [m] and absolute heading error [rad] of an estimate against a reference.

    Examples
    --------
    >>> [round(v, 12) for v in pose_error([1.0, 1.0, 3.1], [1.0, 2.0, -3.1])]
    [1.0, 0.08318530718]
    """
    e = array("estimate_pose", estimate_pose, (3,))
    r = array("reference_pose", reference_pose, (3,))
    return float(math.hypot(e[0] - r[0], e[1] - r[1])), abs(float(wrap_angle(e[2] - r[2])))
