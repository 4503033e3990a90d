"""Entry checks shared by the localization modules (one message format everywhere).

Every public function checks its inputs here and raises ``ValueError`` naming the
parameter, what is allowed and the value received (STYLE.md habit 10); kernels check
nothing.
"""

from __future__ import annotations

import math

import numpy as np


def finite(name: str, value) -> float:
    """``value`` as a float; ValueError unless finite."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be a finite number, got {value!r}")
    return v


def positive(name: str, value) -> float:
    """``value`` as a float; ValueError unless finite and > 0."""
    v = finite(name, value)
    if v <= 0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def array(name: str, value, shape: tuple, *, allow_nan: bool = False) -> np.ndarray:
    """``value`` as a C-contiguous float64 array of ``shape`` (``-1``: any length)."""
    try:
        a = np.ascontiguousarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric array of shape {_fmt(shape)}, got {type(value).__name__}") from None
    if a.ndim != len(shape) or any(s != -1 and s != d for s, d in zip(shape, a.shape)):
        raise ValueError(f"{name} must have shape {_fmt(shape)}, got {a.shape}")
    bad = np.isinf(a) if allow_nan else ~np.isfinite(a)
    if bad.any():
        raise ValueError(f"{name} must hold finite numbers, got {a[bad].ravel()[0]!r} at index "
                         f"{tuple(int(i) for i in np.argwhere(bad)[0])}")
    return a


def generator(name: str, value) -> np.random.Generator:
    """``value`` unless it is not a ``numpy.random.Generator``."""
    if not isinstance(value, np.random.Generator):
        raise ValueError(f"{name} must be a numpy.random.Generator, got {type(value).__name__}")
    return value


def read_only(a: np.ndarray) -> np.ndarray:
    """A read-only view of ``a`` (the filters' ``particles`` / ``weights`` properties)."""
    v = a.view()
    v.flags.writeable = False
    return v


class SampleSetState:
    """The sample set's read-only state, shared by :class:`~teamnav.localization.mcl.MCL` and
    :class:`~teamnav.localization.odometry_belief.OdometryBelief` (both keep ``_particles`` of
    shape (n, 3) and normalised ``_weights``). ``_EMPTY_HINT`` says how to fill an empty set."""

    _particles: np.ndarray
    _weights: np.ndarray
    _EMPTY_HINT = "has no samples yet"

    @property
    def particles(self) -> np.ndarray:
        return read_only(self._particles)

    @property
    def weights(self) -> np.ndarray:
        return read_only(self._weights)

    @property
    def n_particles(self) -> int:
        return int(self._particles.shape[0])

    def _require_particles(self, what: str) -> None:
        if self._particles.shape[0] == 0:
            raise ValueError(f"{what}: {self._EMPTY_HINT}")


def _fmt(shape: tuple) -> str:
    return "(" + ", ".join("n" if s == -1 else str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"
