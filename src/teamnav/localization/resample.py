"""Resampling of MCL's weighted sample set.

Fox et al. §3.1 step 1: new samples are drawn from the previous set "with likelihood
determined by their p-values", in O(K) time (Carpenter et al. 1997). This is the
low-variance (systematic) resampler of Thrun, Burgard & Fox, *Probabilistic Robotics*
Table 4.4: one uniform ``r`` in ``[0, 1/M)`` and the M equally spaced pointers
``r + m/M`` into the cumulative weights.

Ref: Carpenter, Clifford & Fearnhead, IEE Proc. Radar Sonar Navig. 146(1), 1999,
doi:10.1049/ip-rsn:19990255; Probabilistic Robotics Table 4.4.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from teamnav.localization._checks import array, generator

__all__ = ["effective_sample_size", "low_variance_indices", "low_variance_kernel", "low_variance_reference", "normalize_log_weights"]


@njit(cache=True)
def low_variance_kernel(weights, m, r, out):
    """Indices of ``m`` low-variance draws from ``weights`` (sum > 0), written to ``out`` (m,).

    ``r`` is the single uniform in ``[0, 1)``; pointer ``k`` is ``(r + k) / m`` of the total.
    """
    n = weights.shape[0]
    total = 0.0
    for i in range(n):
        total += weights[i]
    step = total / m
    u = r * step
    c = weights[0]
    i = 0
    for k in range(m):
        while u > c and i < n - 1:
            i += 1
            c += weights[i]
        out[k] = i
        u += step
    return out


def low_variance_indices(weights, m: int, rng: np.random.Generator) -> np.ndarray:
    """``m`` indices drawn by low-variance resampling (Probabilistic Robotics Table 4.4).

    Parameters
    ----------
    weights : ndarray of shape (n,)
        Non-negative weights, not all zero (need not sum to one).
    m : int
        Number of draws, >= 1.
    rng : numpy.random.Generator
        Draws one ``rng.random()``.

    Returns
    -------
    ndarray of shape (m,), int64
        Indices in ascending order; index ``i`` appears ``floor`` or ``ceil`` of ``m w_i / sum w``
        times.

    Examples
    --------
    >>> low_variance_indices(np.array([0.0, 3.0, 1.0]), 4, np.random.default_rng(0)).tolist()
    [1, 1, 1, 2]
    """
    w = array("weights", weights, (-1,))
    if w.shape[0] == 0 or (w < 0).any() or not w.sum() > 0:
        raise ValueError("weights must be a non-empty array of finite numbers >= 0 with a positive sum, got "
                         f"{w.shape[0]} weights summing to {w.sum() if w.shape[0] else 0.0!r}")
    if not (isinstance(m, (int, np.integer)) and m >= 1):
        raise ValueError(f"m must be an integer >= 1, got {m!r}")
    rng = generator("rng", rng)
    return low_variance_kernel(w, int(m), float(rng.random()), np.empty(int(m), dtype=np.int64))


def low_variance_reference(weights, m: int, r: float) -> np.ndarray:
    """Pure-NumPy reference of :func:`low_variance_kernel` (``searchsorted`` on the cumsum)."""
    w = np.asarray(weights, dtype=np.float64)
    c = np.cumsum(w)
    u = (r + np.arange(m)) * (c[-1] / m)
    return np.minimum(np.searchsorted(c, u, side="left"), w.shape[0] - 1)


def effective_sample_size(weights) -> float:
    """Kish's effective sample size ``(sum w)^2 / sum w^2`` of a weight vector.

    Examples
    --------
    >>> effective_sample_size(np.ones(4)), effective_sample_size([1.0, 0.0, 0.0])
    (4.0, 1.0)
    """
    w = np.asarray(weights, dtype=np.float64)
    s2 = float(np.dot(w, w))
    return float(w.sum() ** 2 / s2) if s2 > 0 else 0.0


def normalize_log_weights(log_w: np.ndarray) -> tuple[np.ndarray, float]:
    """Normalised weights ``exp(log_w - logsumexp(log_w))`` and ``logsumexp(log_w)``.

    This is the normaliser alpha of Fox et al. eq. (12), computed without underflow: a 60-beam
    scan easily gives likelihoods of ``1e-300``.
    """
    top = float(np.max(log_w))
    w = np.exp(log_w - top)
    s = float(w.sum())
    w /= s
    return w, top + float(np.log(s))
