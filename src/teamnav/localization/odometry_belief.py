"""A sample-based pose belief without a map: the odometry motion model only (prediction only).

Fox, Burgard, Kruppa & Thrun, "A probabilistic approach to collaborative multi-robot
localization" (2000): the belief ``Bel_n(L)`` is a set of weighted samples (eq. 11), moved by the
motion model (eq. 6, §3.1 step 2) and reweighted by evidence (eq. 12 for the robot's own sensor,
eq. 14 for a teammate's detection). This class keeps eqs. 6, 11 and 14 and drops eq. 12: a
robot with no map has no sensor model, so between detections its belief only spreads, and only
a teammate's detection (:mod:`~teamnav.localization.sync`, eqs. 13-14) concentrates it again.

It offers what :class:`~teamnav.localization.sync.BeliefSync` reads of a filter
(:attr:`particles`, :attr:`weights`, :attr:`free_area_m2`, :meth:`multiply_weights`) and
:meth:`estimate` like :class:`~teamnav.localization.mcl.MCL`, so the sync code runs on it unchanged.

Where it fills gaps (none of the papers has a belief without a map; each a parameter):

- **Heading drift as a per-sample rate.** Vaughan et al.'s odometry drifts at a rate in *time*
  (2000 §5.1, 2002 §3.6: 0.35-2 deg/min, one sign per robot), which the zero-mean per-step noise
  of Table 5.6 (:mod:`~teamnav.localization.motion`) cannot describe: a random walk wide enough
  to cover a drift of ``r T`` after ``T`` is far too wide early on. Every sample carries its own
  drift rate ``b_i ~ N(0, heading_rate_std_deg_per_min²)``, drawn at :meth:`init_pose`; a motion
  step of ``dt`` takes ``b_i dt`` off the reported rotation, half before and half after the
  translation (the simulator's convention for the drift, :mod:`teamnav.sim.odometry`). A
  detection that favours samples whose position fits thereby favours the rates that put them
  there: the belief learns its robot's drift relative to its teammates'. After each resampling
  the rates get ``N(0, heading_rate_jitter_deg_per_min²)`` of jitter, so a depleted set can
  still move its rate (regularised resampling). ``heading_rate_std_deg_per_min = 0`` and no
  jitter is the plain Table 5.6 model.
- ``free_area_m2``: eq. 14's false-positive term is uniform over the free space, whose area a
  robot without a map does not know; it is a parameter (the area the team works in).
- resampling (§3.1 step 1) happens before the motion step that follows a reweighting, never
  otherwise: prediction alone leaves the weights equal.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import BaseModel, ConfigDict, Field

from teamnav.geometry.angles import wrap_angle
from teamnav.localization._checks import SampleSetState, array, generator, read_only
from teamnav.localization.mcl import MCL, gaussian_poses
from teamnav.localization.motion import MotionParams, motion_kernel_serial
from teamnav.localization.resample import low_variance_kernel

__all__ = ["OdometryBelief", "OdometryBeliefParams"]


class OdometryBeliefParams(BaseModel):
    """Parameters of :class:`OdometryBelief` (see the module docstring).

    Attributes
    ----------
    n_particles : int
        Samples K (fixed).
    motion : MotionParams
        Table 5.6 noise of each motion step (the random part of the odometry error).
    heading_rate_std_deg_per_min : float
        Spread of the samples' drift rates at start [deg/min] (gap-fill; 0: no drift modelled).
    heading_rate_jitter_deg_per_min : float
        Jitter added to the rates at each resampling [deg/min] (gap-fill).
    free_area_m2 : float
        Area of eq. 14's uniform false-positive term [m²] (gap-fill: no map, no free area).
    cluster_cell_m : float
        Cell of the grid whose connected components are the clusters of :meth:`OdometryBelief.estimate`.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    n_particles: int = Field(300, ge=2, le=1_000_000)
    motion: MotionParams = MotionParams(alpha=(0.01, 0.001, 0.001, 0.001))
    heading_rate_std_deg_per_min: float = Field(2.0, ge=0.0, le=360.0)
    heading_rate_jitter_deg_per_min: float = Field(0.1, ge=0.0, le=360.0)
    free_area_m2: float = Field(200.0, gt=0.0, le=1e9)
    cluster_cell_m: float = Field(0.5, gt=0.0, le=100.0)


class OdometryBelief(SampleSetState):
    """A map-less sample belief: motion model plus eq. 14, nothing else (module docstring).

    Parameters
    ----------
    params : OdometryBeliefParams
    rng : numpy.random.Generator
        The belief's own stream.

    Examples
    --------
    >>> b = OdometryBelief(OdometryBeliefParams(n_particles=200), np.random.default_rng(0))
    >>> b.init_pose([0.0, 0.0, 0.0], np.diag([1e-4, 1e-4, 1e-4]))
    >>> b.predict([1.0, 0.0, 0.0], 1.0)
    >>> bool(abs(b.estimate().pose[0] - 1.0) < 0.05), b.particles.shape
    (True, (200, 3))
    """

    _EMPTY_HINT = "the belief has no samples yet; call init_pose() first"

    def __init__(self, params: OdometryBeliefParams, rng: np.random.Generator) -> None:
        if not isinstance(params, OdometryBeliefParams):
            raise ValueError(f"params must be an OdometryBeliefParams, got {type(params).__name__}")
        self.params = params
        self.rng = generator("rng", rng)
        #: Free area of eq. 14's false-positive term [m²] (a parameter: no map).
        self.free_area_m2 = float(params.free_area_m2)
        self._particles = np.zeros((0, 3))
        self._weights = np.zeros(0)
        self._rates = np.zeros(0)  # drift rate of each sample's odometry [rad/s]
        self._weighted = False
        self._alpha = np.asarray(params.motion.alpha, dtype=np.float64)

    # ------------------------------------------------------------------ state
    @property
    def rates_radps(self) -> np.ndarray:
        """Each sample's drift rate of the odometry's heading [rad/s] (read-only view)."""
        return read_only(self._rates)

    # ------------------------------------------------------------------ the phases
    def init_pose(self, pose, cov) -> None:
        """K samples of ``N(pose, cov)``, each with a drift rate of ``N(0, heading_rate_std²)``.

        Parameters
        ----------
        pose : array_like of shape (3,)
            Mean ``x [m], y [m], theta [rad]``.
        cov : array_like of shape (3, 3)
            Symmetric positive semi-definite covariance [m², m², rad²].
        """
        n = self.params.n_particles
        self._particles = np.ascontiguousarray(gaussian_poses(self.rng, pose, cov, n))
        self._weights = np.full(n, 1.0 / n)
        self._rates = self.rng.standard_normal(n) * math.radians(self.params.heading_rate_std_deg_per_min) / 60.0
        self._weighted = False

    def predict(self, odom_delta, dt_s: float) -> None:
        """Resample if weighted (§3.1 step 1), then move every sample (eq. 6).

        Parameters
        ----------
        odom_delta : array_like of shape (3,)
            Odometry step ``(dx [m], dy [m], dtheta [rad])`` in the previous body frame.
        dt_s : float
            Time the step took [s] (the drift rates are per time).
        """
        self._require_particles("predict")
        d = array("odom_delta", odom_delta, (3,))
        if not (math.isfinite(dt_s) and dt_s >= 0.0):
            raise ValueError(f"dt_s must be a finite number >= 0, got {dt_s!r}")
        if self._weighted:
            self.resample()
        half = 0.5 * dt_s * self._rates
        self._particles[:, 2] -= half
        noise = self.rng.standard_normal((self._particles.shape[0], 3))
        motion_kernel_serial(self._particles, float(d[0]), float(d[1]), float(d[2]), self._alpha, noise)
        self._particles[:, 2] = wrap_angle(self._particles[:, 2] - half)

    #: ``p_i <- alpha p_i f_i`` (eq. 14), False (unchanged) when every product is 0: MCL's own method,
    #: which reads only the state both classes keep (``_particles``, ``_weights``, ``_weighted``).
    multiply_weights = MCL.multiply_weights

    def resample(self) -> None:
        """Low-variance draw of K equally weighted samples; the rates travel with their samples and
        get the jitter."""
        self._require_particles("resample")
        n = self.params.n_particles
        idx = low_variance_kernel(self._weights, n, float(self.rng.random()), np.empty(n, dtype=np.int64))
        self._particles = np.ascontiguousarray(self._particles[idx])
        jitter = math.radians(self.params.heading_rate_jitter_deg_per_min) / 60.0
        self._rates = self._rates[idx] + (self.rng.standard_normal(n) * jitter if jitter > 0 else 0.0)
        self._weights = np.full(n, 1.0 / n)
        self._weighted = False

    # ------------------------------------------------------------------ estimates
    #: Weighted mean and covariance, and the heaviest cluster's mean (:class:`Estimate`): MCL's own
    #: method (it reads ``_particles``, ``_weights`` and ``params.cluster_cell_m``).
    estimate = MCL.estimate
