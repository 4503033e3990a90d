"""Brain ``localized-v1``: any brain, driven by a Monte Carlo localization pose instead of odometry.

Beyond the papers, combination 1 ("localized trails"): the trail papers' robots have only drifting
odometry, and their trails break down as the frames drift apart (Vaughan et al. 2000 §5.1,
2002 §3.6); Fox et al.'s robots localize against a map and do nothing else. This brain composes
the two without copying either:

- **Localization** is the library's :class:`~teamnav.localization.MCL` (Fox et al. §3.1): the
  odometry motion model, the robot's own range sensor through the likelihood field (or the beam
  model), resampling after each weighted update. The filter runs once odometry accumulated
  ``min_update_m`` / ``min_update_deg`` (the steps between are composed, as ``mcl-wander-v1``
  and AMCL do).
- **Everything else** is the inner brain (``brain``, default ``blazing-trail-v1``; any
  registered brain or ``module:Class``) with its own parameters (``brain_params``, e.g.
  ``{paper_rules: true}``) and its own rules unchanged. It gets the robot's observation with
  one field replaced: ``odom_pose`` is the filter's pose (map frame), moved on by odometry
  between filter updates. For the trail brains that is where crumbs are dropped and looked up
  (Blazing §4.1, Try §3.2), so trails are laid in the map frame.

Two hooks for inner brains that want them (duck-typed; brains without them see nothing new):
``set_pose_cov(cov)``, when the inner brain has it, is called before each step with the filter's
sample covariance (3 x 3, map frame) at its last update (the LOS brains' ``frame_source:
fused``, :mod:`teamnav.papers.beyond.brains.localized_los`); and ``finished`` is the inner brain's own
(None when it has none), so ``stop_when_finished`` sees a wrapped LOS explorer's task end.

What the inner brain still sees unchanged: ``odom_delta`` (the odometry's own motion since the
last step: a relative measurement, true to what the wheels report), the scans, detections,
inbox and events. The filter sees only the observation and the map the scenario gives
(``give_map: true``); no truth.

Where this fills gaps (none of the papers combines these; each is a parameter):

- ``init="odometry"`` (default): the filter starts as a Gaussian (``init_std_m``,
  ``init_std_deg``) at the first odometry pose. Right when the scenario's odometry frame is the
  map frame at start (``odometry: {frame: world}``, as in both trail scenarios, whose robots'
  frames "start aligned"); ``init="global"`` localizes from a uniform prior instead.
- ``pose="cluster"`` (default): the heaviest cluster's mean (:class:`~teamnav.localization.mcl.Estimate`),
  robust to a second mode; ``"mean"``: the weighted mean of all samples.
- a fixed sample count (``particles``) and every ``beam_stride``-th beam, for cost: a trail
  robot tracks from a known start, it never has to localize globally.

Logs (per robot): ``mcl_spread_m`` (square root of the trace of the position covariance),
``mcl_updates`` and ``pts`` (``LOG_SAMPLES`` samples drawn by weight, from a stream of their
own: the ``localization`` metric's error against the truth, as for ``mcl-wander-v1``), beside
the inner brain's own logs and layers.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator

from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Action, Message, Observation
from teamnav.geometry import se2
from teamnav.localization import MCL, MCLParams
from teamnav.localization.likelihood_field import LikelihoodFieldParams
from teamnav.localization.motion import MotionParams
from teamnav.localization.resample import low_variance_indices

__all__ = ["LOG_SAMPLES", "Localized", "LocalizedParams", "belief_log"]

#: samples logged per record step (``pts``), read by :mod:`teamnav.papers.collab_mcl.metrics`
LOG_SAMPLES = 32


class LocalizedParams(BaseModel):
    """Parameters of ``localized-v1`` (see the module docstring).

    Attributes
    ----------
    brain : str
        The inner brain: a registered name or ``module:Class``.
    brain_params : dict
        Its parameters (validated by its own ``Params``).
    sensor : str or None
        The range sensor the filter reads (None: the robot's first).
    particles : int
        Samples of the filter (fixed).
    sensor_model : {"likelihood_field", "beam"}
    likelihood_field, motion
        The library's model parameters.
    beam_stride : int
        The filter uses every n-th beam.
    likelihood_exponent : float
        Tempering of ``P(o | l)`` (1: none, Fox et al. as written).
    min_update_m, min_update_deg : float
        Filter update once odometry accumulated this much motion.
    init : {"odometry", "global"}
        Start at the first odometry pose (frames aligned at start) or from a uniform prior.
    init_std_m, init_std_deg : float
        Spread of the start Gaussian (``init="odometry"``).
    pose : {"cluster", "mean"}
        The estimate handed to the inner brain.
    """

    model_config = ConfigDict(extra="forbid")

    brain: str = Field("blazing-trail-v1", min_length=1)
    brain_params: dict[str, Any] = Field(default_factory=dict)
    sensor: str | None = Field(None, min_length=1)
    particles: int = Field(500, ge=10, le=200_000)
    sensor_model: Literal["likelihood_field", "beam"] = "likelihood_field"
    likelihood_field: LikelihoodFieldParams = LikelihoodFieldParams()
    motion: MotionParams = MotionParams()
    beam_stride: int = Field(5, ge=1, le=4096)
    likelihood_exponent: float = Field(1.0, gt=0.0, le=1.0)
    min_update_m: float = Field(0.1, ge=0.0)
    min_update_deg: float = Field(5.0, ge=0.0)
    init: Literal["odometry", "global"] = "odometry"
    init_std_m: float = Field(0.1, gt=0.0)
    init_std_deg: float = Field(5.0, gt=0.0)
    pose: Literal["cluster", "mean"] = "cluster"

    @field_validator("brain")
    @classmethod
    def _not_itself(cls, v: str) -> str:
        if v == "localized-v1":
            raise ValueError("brain: expected the brain to localize (e.g. 'blazing-trail-v1'), received 'localized-v1' itself")
        return v

    def mcl_params(self) -> MCLParams:
        """The library's filter parameters these stand for."""
        return MCLParams(n_particles=self.particles, sensor_model=self.sensor_model,
                         likelihood_field=self.likelihood_field, motion=self.motion, beam_stride=self.beam_stride,
                         likelihood_exponent=self.likelihood_exponent, recovery="none")


def _child_rng(rng: np.random.Generator) -> np.random.Generator:
    """A stream for the filter that leaves ``rng`` (the inner brain's) where it was, so the
    inner brain draws what it would draw alone."""
    try:
        return rng.spawn(1)[0]
    except (AttributeError, TypeError, ValueError):  # a generator built without a SeedSequence
        return np.random.Generator(rng.bit_generator.jumped())


class Localized:
    """``localized-v1``: the inner brain on the filter's pose (see the module docstring).

    Parameters
    ----------
    params : LocalizedParams
    rng : numpy.random.Generator
        The inner brain's stream (the filter gets a stream spawned from it).
    info : RobotInfo
        Must carry ``known_map`` (``give_map: true``) and a range sensor.
    """

    Params = LocalizedParams
    needs_map = True

    def __init__(self, params: LocalizedParams, rng: np.random.Generator, info: RobotInfo) -> None:
        from teamnav.control import registry

        if not isinstance(params, LocalizedParams):
            raise ValueError(f"params must be a Localized.Params, got {type(params).__name__}")
        if info.known_map is None:
            raise ValueError(f"robot {info.robot_id}: localized-v1 needs a map; set 'give_map: true' in the scenario")
        ranged = [name for name, s in info.sensors.items() if getattr(s, "max_range_m", None) is not None]
        name = params.sensor if params.sensor is not None else (ranged[0] if ranged else None)
        if name is None or name not in info.sensors:
            raise ValueError(f"robot {info.robot_id}: localized-v1 sensor: expected one of {sorted(info.sensors)}, "
                             f"received {params.sensor!r}")
        self.params = params
        self.sensor = name
        cls = registry.lookup(params.brain)
        inner_params = cls.Params(**params.brain_params)
        self.inner = cls(inner_params, rng, info)
        self.mcl = MCL(params.mcl_params(), info.known_map, info.sensors[name], _child_rng(rng))
        self._log_rng = _child_rng(self.mcl.rng)  # the logged subsample draws nothing from the filter's stream
        self._started = False
        self._acc = np.zeros(3)  # odometry composed since the last filter update
        self._base = np.zeros(3)  # the filter's pose at its last update
        self._min_rot = math.radians(params.min_update_deg)
        self._spread = float("nan")
        self._updates = 0
        self._cov: np.ndarray | None = None
        self._cov_hook = getattr(self.inner, "set_pose_cov", None)

    @property
    def finished(self) -> bool | None:
        """The inner brain's ``finished`` (None when it has none: a brain without a task)."""
        return getattr(self.inner, "finished", None)

    def step(self, obs: Observation) -> tuple[Action, list[Message]]:
        """Filter (when odometry moved enough), then the inner brain on the filter's pose."""
        p = self.params
        if not self._started:
            if p.init == "odometry":
                sd, sa = p.init_std_m, math.radians(p.init_std_deg)
                self.mcl.init_pose(np.asarray(obs.odom_pose, dtype=float), np.diag([sd * sd, sd * sd, sa * sa]))
            else:
                self.mcl.init_global()
        self._acc = se2.compose(self._acc, np.asarray(obs.odom_delta, dtype=float))
        acc = self._acc
        if not self._started or math.hypot(acc[0], acc[1]) >= p.min_update_m or abs(acc[2]) >= self._min_rot:
            self.mcl.step(acc, obs.scans[self.sensor].ranges_m)
            est = self.mcl.estimate()
            self._base = np.array(est.cluster_pose if p.pose == "cluster" else est.pose, dtype=float)
            self._spread = float(math.sqrt(max(0.0, est.cov[0, 0] + est.cov[1, 1])))
            if self._cov_hook is not None:
                self._cov = np.array(est.cov, dtype=float)
            self._acc = np.zeros(3)
            self._updates += 1
            self._started = True
        pose = se2.compose(self._base, self._acc)
        if self._cov_hook is not None:
            self._cov_hook(self._cov)
        return self.inner.step(dataclasses.replace(obs, odom_pose=pose))

    def log(self) -> dict[str, Any]:
        """The inner brain's log, plus ``mcl_spread_m`` and ``mcl_updates``; the inner brain's
        ``odom``-frame layers are relabelled ``world`` (its "odometry" pose is the map's here)."""
        return belief_log(self.inner, self.mcl if self._started else None, self._log_rng, self._spread, self._updates)


def belief_log(inner: Any, belief: Any, log_rng: np.random.Generator, spread_m: float, updates: int) -> dict[str, Any]:
    """The log of a brain that drives ``inner`` with a sample belief's pose (``localized-v1`` and
    ``detecting-trails-v1``): ``inner``'s log, ``mcl_spread_m``, ``mcl_updates`` and ``pts``
    (``LOG_SAMPLES`` samples of ``belief`` drawn by weight with ``log_rng``; none while ``belief``
    is None), the inner brain's ``odom``-frame layers relabelled ``world``."""
    log = getattr(inner, "log", None)
    out = dict(log() or {}) if callable(log) else {}
    out["mcl_spread_m"] = spread_m
    out["mcl_updates"] = updates
    if belief is not None:  # K samples by weight: the localization metric's error estimate (Fox et al. §5.1)
        idx = low_variance_indices(belief.weights, min(LOG_SAMPLES, belief.n_particles), log_rng)
        out["pts"] = [round(float(v), 2) for v in belief.particles[idx, :2].ravel()]
    layers = out.get("layers")
    if isinstance(layers, dict):
        out["layers"] = {k: ({**v, "frame": "world"} if isinstance(v, dict) and v.get("frame") == "odom" else v)
                         for k, v in layers.items()}
    return out
