"""Probabilistic robot-detection model ``P(L_n | L_m, r_m)``, learned by maximum likelihood.

Fox, Burgard, Kruppa & Thrun §4.2: a detection ``r_m`` by robot m reports the identity of
robot n and its location relative to m in polar coordinates. The model is "a parametric
mixture model": a binary variable for false-positive and false-negative detections (Table 2:
6.7 % missed, 3.5 % phantom) and a Gaussian over the error in range and bearing, "obtained
through maximum likelihood estimation based on the training data", zero-centred, with
independent components (Fig. 7: "the correlation between both components ... approximately
zero").

Learning (:func:`fit_detection_model`), from training samples in which a reference relative
position is known (the paper takes it from MCL with a known start; the experiment layer takes
it from the simulator):

- Gaussian: for every positive detection of a robot that was in the field of view, the
  errors ``e_r = detected range - reference range`` and
  ``e_b = wrap(detected bearing - reference bearing)``; the ML estimates are their means
  (biases) and their ``1/N`` standard deviations;
- ``p_false_negative`` = missed / in view; ``p_false_positive`` = detections / frames with
  no robot in view (Table 2's two rows).

Using the model (:meth:`DetectionModel.sample_positions`): given m's pose ``l' = (x, y,
theta)`` and a detection ``(d, phi)``, n's position is ``(x + rho cos(theta + beta),
y + rho sin(theta + beta))`` with ``rho = d - bias_r - e``, ``beta = phi - bias_b - f`` and
``e ~ N(0, sigma_r^2)``, ``f ~ N(0, sigma_b^2)`` (``rho`` reflected at 0): drawing one such
position per sample of m's belief samples the integral of eq. (13). A detection is a false
positive with probability ``p_false_positive``; :mod:`~teamnav.localization.sync` mixes that
case in as a uniform density over the map.

Files: :meth:`DetectionModel.save` / :meth:`DetectionModel.load` (JSON); a malformed file
raises ``ValueError`` naming the file, the field and what was expected.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from teamnav.geometry.angles import wrap_angle
from teamnav.localization._checks import array, generator

__all__ = ["DetectionModel", "DetectionSamples", "fit_detection_model"]

_FORMAT = "teamnav.detection_model/1"


class DetectionModel(BaseModel):
    """Learned detection model (Fox et al. §4.2).

    Attributes
    ----------
    range_bias_m, range_std_m : float
        Mean and deviation of ``detected - reference`` range [m].
    bearing_bias_rad, bearing_std_rad : float
        Mean and deviation of the wrapped bearing error [rad].
    p_false_negative : float
        Probability of not detecting a robot in the field of view (Table 2: 0.067).
    p_false_positive : float
        Probability of a detection when no robot is in view (Table 2: 0.035).
    n_detections, n_frames : int
        Training positives used for the Gaussian; training frames used for the rates.

    Examples
    --------
    >>> m = DetectionModel(range_std_m=0.1, bearing_std_rad=0.04)
    >>> pts = m.sample_positions(np.zeros((3, 3)), 2.0, 0.0, np.random.default_rng(0))
    >>> pts.shape, bool(np.all(np.abs(pts[:, 0] - 2.0) < 0.5))
    ((3, 2), True)
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    range_bias_m: float = Field(0.0, ge=-100.0, le=100.0)
    range_std_m: float = Field(0.1, ge=0.0, le=100.0)
    bearing_bias_rad: float = Field(0.0, ge=-math.pi, le=math.pi)
    bearing_std_rad: float = Field(0.04, ge=0.0, le=math.pi)
    p_false_negative: float = Field(0.0, ge=0.0, le=1.0)
    p_false_positive: float = Field(0.0, ge=0.0, lt=1.0)
    n_detections: int = Field(0, ge=0)
    n_frames: int = Field(0, ge=0)

    # ------------------------------------------------------------------ use
    def sample_positions(self, poses, range_m: float, bearing_rad: float, rng: np.random.Generator) -> np.ndarray:
        """Positions of the detected robot, one per observer pose (eq. 13 sampled).

        Parameters
        ----------
        poses : ndarray of shape (n, 3)
            Observer poses (samples of its belief) [m, m, rad].
        range_m, bearing_rad : float
            The detection, in the observer's body frame.
        rng : numpy.random.Generator
            Draws one ``standard_normal((n, 2))``.

        Returns
        -------
        ndarray of shape (n, 2)
            World positions [m].
        """
        p = array("poses", poses, (-1, 3))
        d = float(range_m)
        if not (math.isfinite(d) and d >= 0):
            raise ValueError(f"range_m must be a finite number >= 0, got {range_m!r}")
        phi = float(bearing_rad)
        if not math.isfinite(phi):
            raise ValueError(f"bearing_rad must be finite, got {bearing_rad!r}")
        z = generator("rng", rng).standard_normal((p.shape[0], 2))
        rho = np.abs(d - self.range_bias_m - self.range_std_m * z[:, 0])
        beta = p[:, 2] + phi - self.bearing_bias_rad - self.bearing_std_rad * z[:, 1]
        return np.stack([p[:, 0] + rho * np.cos(beta), p[:, 1] + rho * np.sin(beta)], axis=1)

    def sample_offsets(self, range_m: float, bearing_rad: float, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` draws of the reference relative position ``(rho, beta)`` given a detection."""
        z = generator("rng", rng).standard_normal((int(n), 2))
        rho = np.abs(float(range_m) - self.range_bias_m - self.range_std_m * z[:, 0])
        beta = float(bearing_rad) - self.bearing_bias_rad - self.bearing_std_rad * z[:, 1]
        return np.stack([rho, beta], axis=1)

    # ------------------------------------------------------------------ files
    def save(self, path) -> None:
        """Write the model as JSON (``{"format": ..., fields...}``)."""
        data = {"format": _FORMAT, **self.model_dump()}
        Path(path).write_text(json.dumps(data, indent=2) + "\n")

    @classmethod
    def load(cls, path) -> "DetectionModel":
        """Read a model written by :meth:`save`; ValueError names file, field and expectation."""
        p = Path(path)
        try:
            text = p.read_text()
        except OSError as e:
            raise ValueError(f"{p}: cannot read detection model file ({e.strerror})") from None
        try:
            data = json.loads(text)
        except json.JSONDecodeError as e:
            raise ValueError(f"{p}: not valid JSON (line {e.lineno}, column {e.colno}: {e.msg}); "
                             "expected a detection model object") from None
        if not isinstance(data, dict):
            raise ValueError(f"{p}: expected a JSON object with the detection model fields, got {type(data).__name__}")
        fmt = data.pop("format", None)
        if fmt != _FORMAT:
            raise ValueError(f"{p}: field 'format' must be {_FORMAT!r}, got {fmt!r}")
        try:
            return cls(**data)
        except ValidationError as e:
            err = e.errors()[0]
            field = ".".join(str(v) for v in err["loc"]) or "<root>"
            raise ValueError(f"{p}: field {field!r}: {err['msg']} (got {err.get('input')!r})") from None


@dataclass(frozen=True)
class DetectionSamples:
    """Training data for :func:`fit_detection_model`, one row per (frame, observer, target slot).

    Attributes
    ----------
    in_view : ndarray (K,) bool
        A robot was in the detector's field of view (reference geometry says so).
    detected : ndarray (K,) bool
        The detector reported a robot.
    reference_range_m, reference_bearing_rad : ndarray (K,) float64
        Reference relative position of the robot in view (NaN where none).
    detected_range_m, detected_bearing_rad : ndarray (K,) float64
        What the detector reported (NaN where nothing).
    """

    in_view: np.ndarray
    detected: np.ndarray
    reference_range_m: np.ndarray
    reference_bearing_rad: np.ndarray
    detected_range_m: np.ndarray
    detected_bearing_rad: np.ndarray


def fit_detection_model(samples: DetectionSamples) -> DetectionModel:
    """Maximum-likelihood detection model from training samples (Fox et al. §4.2).

    Raises
    ------
    ValueError
        On mismatched lengths, missing values where a row needs them, or too little data
        (at least 2 true positives and at least one frame with and one without a robot in view).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> ref = rng.uniform(1, 5, 2000); err = rng.normal(0.0, 0.2, 2000)
    >>> s = DetectionSamples(np.r_[np.ones(2000, bool), np.zeros(100, bool)], np.r_[np.ones(2000, bool),
    ...     np.zeros(100, bool)], np.r_[ref, np.full(100, np.nan)], np.r_[np.zeros(2000), np.full(100, np.nan)],
    ...     np.r_[ref + err, np.full(100, np.nan)], np.r_[np.zeros(2000), np.full(100, np.nan)])
    >>> round(fit_detection_model(s).range_std_m, 1)
    0.2
    """
    if not isinstance(samples, DetectionSamples):
        raise ValueError(f"samples must be a DetectionSamples, got {type(samples).__name__}")
    in_view = np.asarray(samples.in_view)
    detected = np.asarray(samples.detected)
    if in_view.dtype != np.bool_ or detected.dtype != np.bool_ or in_view.ndim != 1:
        raise ValueError(f"samples.in_view and samples.detected must be 1-D bool arrays, got "
                         f"{in_view.dtype} {in_view.shape} and {detected.dtype} {detected.shape}")
    k = in_view.shape[0]
    if detected.shape != (k,):
        raise ValueError(f"samples.detected must have shape ({k},) like in_view, got {detected.shape}")
    cols = {}
    for name in ("reference_range_m", "reference_bearing_rad", "detected_range_m", "detected_bearing_rad"):
        cols[name] = array(f"samples.{name}", getattr(samples, name), (k,), allow_nan=True)
    tp = in_view & detected
    for name in cols:
        if np.isnan(cols[name][tp]).any():
            raise ValueError(f"samples.{name} must be a number in every row where in_view and detected, got NaN")
    n_tp = int(tp.sum())
    n_in, n_out = int(in_view.sum()), int((~in_view).sum())
    if n_tp < 2 or n_in < 1 or n_out < 1:
        raise ValueError(f"samples must hold >= 2 true detections and frames with and without a robot in view, got "
                         f"{n_tp} true detections, {n_in} frames in view, {n_out} without")
    e_r = cols["detected_range_m"][tp] - cols["reference_range_m"][tp]
    e_b = wrap_angle(cols["detected_bearing_rad"][tp] - cols["reference_bearing_rad"][tp])
    b_bias = math.atan2(float(np.mean(np.sin(e_b))), float(np.mean(np.cos(e_b))))
    return DetectionModel(
        range_bias_m=float(e_r.mean()),
        range_std_m=float(e_r.std()),
        bearing_bias_rad=b_bias,
        bearing_std_rad=float(np.sqrt(np.mean(wrap_angle(e_b - b_bias) ** 2))),
        p_false_negative=float((in_view & ~detected).sum() / n_in),
        p_false_positive=float((~in_view & detected).sum() / n_out),
        n_detections=n_tp,
        n_frames=k,
    )
