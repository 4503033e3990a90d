"""Beam-based perception model ``P(o | l)`` for laser range finders and sonar cones.

Fox et al. §2.2, Fig. 1: for proximity sensors ``P(o | l)`` is approximated by
``P(o | o_l)``, the probability of the measured distance ``o`` given the distance ``o_l``
expected at pose ``l`` by ray tracing in the map; it is "a mixture of a Gaussian (centered
around the correct distance o_l), a Geometric distribution (modeling overly short readings)
and a Dirac distribution (modeling max-range readings)", plus the probability of a "random"
measurement. In the continuous form of Thrun, Burgard & Fox, *Probabilistic Robotics* §6.3
(eqs. 6.4–6.12), with ``z`` the measured and ``z*`` the expected range, ``z_max`` the
sensor's maximum range::

    p_hit(z | z*)   = eta_hit   N(z; z*, sigma_hit^2)         for 0 <= z <= z_max
    p_short(z | z*) = eta_short lambda exp(-lambda z)         for 0 <= z <= z*
    p_max(z)        = 1 (a point mass)                        at z = z_max
    p_rand(z)       = 1 / z_max                               for 0 <= z < z_max
    p = z_hit p_hit + z_short p_short + z_max p_max + z_rand p_rand

``eta_hit = 1 / (Phi((z_max - z*) / sigma) - Phi(-z* / sigma))`` and
``eta_short = 1 / (1 - exp(-lambda z*))`` make each part integrate to one, so the
continuous part integrates to ``1 - z_max`` and the point mass holds the rest (the exponential
is the continuous form of Fox et al.'s geometric distribution). ``z* = 0`` (a pose inside a
wall) has no short readings. A reading ``z >= z_max`` is a max-range reading; its probability
is ``z_max + z_hit p_hit(z_max | z*) + z_short p_short(z_max | z*)``.

Sonar (Fox et al. §5.2): a transducer's reading is the nearest echo over its cone, so the
expected distance ``o_l`` of a cone is the minimum over several rays cast across it — the
same rule the simulator's sonar uses.

Speed: the beams of one scan are fixed during an update, so ``log p(z_b | z*)`` is tabulated
per beam over ``z*`` on a grid of step ``table_step_m`` (default ``sigma_hit / 4``) and the
kernel interpolates it linearly: one ray cast (or k for a cone) and two loads per
particle-beam, no ``exp``/``log`` (the error is ≤ ``step² / (8 sigma²)`` per beam, 0.008 at
the default, away from the one-step jump of ``p_short`` at ``z* = z``).
:func:`beam_log_likelihood_reference` is the exact NumPy evaluation it is tested against.

Ref: Fox, Burgard, Kruppa & Thrun, Autonomous Robots 8(3), 2000, doi:10.1023/A:1008937911390,
§2.2 Fig. 1; Thrun, Burgard & Fox, Probabilistic Robotics §6.3, Table 6.1.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from pydantic import BaseModel, ConfigDict, Field, model_validator
from scipy.special import ndtr

from teamnav.localization._checks import array, positive
from teamnav.world.raycast_stretched import (
    _POSES_PER_WAVE_ST,
    _cast_group_st,
    _scratch_st,
)

__all__ = [
    "BeamModelParams", "BeamTable", "beam_density", "beam_table_kernel", "beam_probability", "beam_log_table", "beam_loglik_kernel",
    "beam_log_likelihood_reference", "beam_loglik_cast_kernel", "beam_loglik_kernel_serial", "max_reading",
]

#: A reading within this of the maximum range is a max-range reading [m].
MAX_READING_TOL_M: float = 1e-6


class BeamModelParams(BaseModel):
    """Mixture weights and shape of the beam model (Probabilistic Robotics Table 6.1 names).

    ``z_hit + z_short + z_max + z_rand`` must be 1; ``z_rand > 0`` keeps every likelihood
    positive (one odd beam cannot zero a particle). ``sigma_hit_m`` [m] is the Gaussian's
    deviation, ``lambda_short_per_m`` [1/m] the exponential's rate, ``table_step_m`` [m] the
    step of the per-scan table over the expected range (None: ``sigma_hit_m / 4``).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    z_hit: float = Field(0.8, ge=0.0, le=1.0)
    z_short: float = Field(0.1, ge=0.0, le=1.0)
    z_max: float = Field(0.05, ge=0.0, le=1.0)
    z_rand: float = Field(0.05, gt=0.0, le=1.0)
    sigma_hit_m: float = Field(0.1, gt=0.0, le=100.0)
    lambda_short_per_m: float = Field(0.5, gt=0.0, le=100.0)
    table_step_m: float | None = Field(None, gt=0.0, le=10.0)

    @model_validator(mode="after")
    def _weights_sum_to_one(self) -> "BeamModelParams":
        s = self.z_hit + self.z_short + self.z_max + self.z_rand
        if abs(s - 1.0) > 1e-6:
            raise ValueError(f"beam: z_hit + z_short + z_max + z_rand must be 1, got {s!r}")
        return self

    @property
    def step_m(self) -> float:
        return self.table_step_m if self.table_step_m is not None else self.sigma_hit_m / 4.0


def max_reading(z, max_range_m: float):
    """Whether readings ``z`` are max-range readings (``z >= max_range_m - 1e-6``)."""
    return np.asarray(z) >= max_range_m - MAX_READING_TOL_M


def beam_density(z, z_expected, params: BeamModelParams, max_range_m: float) -> np.ndarray:
    """Continuous part of the mixture, ``z_hit p_hit + z_short p_short + z_rand p_rand`` [1/m].

    Broadcasts ``z`` against ``z_expected``; 0 outside ``[0, z_max]``. Its integral over
    ``[0, z_max)`` is ``1 - params.z_max``; the point mass ``params.z_max`` sits at ``z_max``.

    Examples
    --------
    >>> p = BeamModelParams(z_hit=0.9, z_short=0.0, z_max=0.05, z_rand=0.05, sigma_hit_m=0.1)
    >>> round(float(beam_density(2.0, 2.0, p, 10.0)), 4)   # 0.9 N(0; 0, 0.1^2) + 0.05 / 10
    3.5955
    """
    zmax = positive("max_range_m", max_range_m)
    z = np.asarray(z, dtype=np.float64)
    ze = np.clip(np.asarray(z_expected, dtype=np.float64), 0.0, zmax)
    s = params.sigma_hit_m
    lam = params.lambda_short_per_m
    inside = (z >= 0.0) & (z <= zmax)
    eta_hit = 1.0 / (ndtr((zmax - ze) / s) - ndtr(-ze / s))
    hit = eta_hit * np.exp(-0.5 * ((z - ze) / s) ** 2) / (s * math.sqrt(2.0 * math.pi))
    with np.errstate(divide="ignore", invalid="ignore"):
        eta_short = np.where(ze > 0.0, 1.0 / -np.expm1(-lam * ze), 0.0)
    short = np.where((z <= ze) & (ze > 0.0), eta_short * lam * np.exp(-lam * z), 0.0)
    rand = np.where(z < zmax, 1.0 / zmax, 0.0)
    return np.where(inside, params.z_hit * hit + params.z_short * short + params.z_rand * rand, 0.0)


def beam_probability(z, z_expected, params: BeamModelParams, max_range_m: float) -> np.ndarray:
    """``P(z | z*)`` as the filter uses it: :func:`beam_density` below ``z_max``, and for a
    max-range reading the point mass ``z_max`` plus the continuous part at ``z_max``.

    Examples
    --------
    >>> p = BeamModelParams()
    >>> bool(beam_probability(10.0, 9.95, p, 10.0) > p.z_max)
    True
    """
    zmax = positive("max_range_m", max_range_m)
    z = np.asarray(z, dtype=np.float64)
    is_max = max_reading(z, zmax)
    dens = beam_density(np.where(is_max, zmax, z), z_expected, params, zmax)
    return np.where(is_max, params.z_max + dens, dens)


def beam_log_table(measured: np.ndarray, params: BeamModelParams, max_range_m: float) -> tuple[np.ndarray, float]:
    """Per-beam table ``log P(z_b | z*_j)`` with ``z*_j = j step``, ``j = 0 .. ceil(z_max/step)``.

    Returns ``(table (B, J + 1) float64, step_m)``. The random part ``p_rand`` is 0 at a
    max-range reading (it covers ``[0, z_max)``).
    """
    zmax = float(max_range_m)
    step = params.step_m
    n = int(math.ceil(zmax / step)) + 1
    grid = np.minimum(np.arange(n) * step, zmax)
    p = beam_probability(measured[:, None], grid[None, :], params, zmax)
    return np.log(p), step


@njit(cache=True)
def beam_table_kernel(z, grid, eta_hit, eta_short, z_hit, z_short, z_max, z_rand, sigma, lam, zmax, out):
    """Compiled :func:`beam_log_table`: ``out[b, j] = log P(z_b | grid_j)`` with the per-``z*``
    normalisers ``eta_hit``, ``eta_short`` precomputed (:class:`BeamTable`).

    Where the Gaussian term is below a quarter of the last bit of the constant part ``base``
    (``|z - z*|`` beyond about 9.5 sigma at the defaults) adding it cannot change the sum, so
    it is not computed; an entry that is ``base`` alone (no short-reading term either) takes
    ``log(base)`` computed once per beam. The same bits as evaluating every term, at 0.4 of
    the cost (most of a 10 m table lies far from the measured range).
    """
    inv_norm = 1.0 / (sigma * math.sqrt(2.0 * math.pi))
    top = 0.0  # the largest factor z_hit eta_hit[j] / (sigma sqrt(2 pi)) of the Gaussian term
    for j in range(grid.shape[0]):
        top = max(top, z_hit * eta_hit[j] * inv_norm)
    for b in range(z.shape[0]):
        bu = np.uint64(b)  # unsigned indices: no negative-index wraparound code
        zb = z[bu]
        is_max = zb >= zmax - MAX_READING_TOL_M
        if is_max:
            zb = zmax
        base = z_max if is_max else z_rand / zmax
        e_short = lam * math.exp(-lam * zb)
        # beyond d^2 = skip_d2, top exp(-d^2 / 2) < 2^(e - 55) = ulp(base) / 4 (base = m 2^e, m in
        # [1/2, 1)), so base + the term == base exactly; e^-0.5 of margin covers the rounding
        skip_d2 = math.inf
        log_base = 0.0
        if base > 0.0 and top > 0.0:
            _, e = math.frexp(base)
            skip_d2 = 2.0 * (math.log(top) - (e - 55) * math.log(2.0)) + 1.0
            log_base = math.log(base)
        lim = min(1400.0, skip_d2)  # below 1400 the term was always added
        for j in range(grid.shape[0]):
            ju = np.uint64(j)
            ze = grid[ju]
            d = (zb - ze) / sigma
            short = zb <= ze and ze > 0.0
            if d * d >= lim and not short:  # the entry is base alone
                out[bu, ju] = log_base if base > 0.0 else math.log(base)
                continue
            p = base
            if d * d < lim:
                p += z_hit * eta_hit[ju] * inv_norm * math.exp(-0.5 * d * d)
            if short:
                p += z_short * eta_short[ju] * e_short
            out[bu, ju] = math.log(p)
    return out


class BeamTable:
    """Per-scan tables of one beam model and range (normalisers over ``z*`` computed once).

    Examples
    --------
    >>> bt = BeamTable(BeamModelParams(), 10.0)
    >>> t = bt(np.array([2.0, 10.0]))
    >>> t.shape == (2, bt.grid.shape[0]), bool(np.allclose(t, beam_log_table(np.array([2.0, 10.0]), BeamModelParams(), 10.0)[0]))
    (True, True)
    """

    def __init__(self, params: BeamModelParams, max_range_m: float) -> None:
        self.params = params
        self.max_range_m = positive("max_range_m", max_range_m)
        self.step_m = params.step_m
        n = int(math.ceil(self.max_range_m / self.step_m)) + 1
        self.grid = np.minimum(np.arange(n) * self.step_m, self.max_range_m)
        s, zmax = params.sigma_hit_m, self.max_range_m
        self.eta_hit = 1.0 / (ndtr((zmax - self.grid) / s) - ndtr(-self.grid / s))
        with np.errstate(divide="ignore"):
            self.eta_short = np.where(self.grid > 0, 1.0 / -np.expm1(-params.lambda_short_per_m * self.grid), 0.0)

    def __call__(self, measured: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``log P(z_b | z*_j)``, shape (B, J + 1), for the scan ``measured`` (B,)."""
        z = np.ascontiguousarray(measured, dtype=np.float64)
        if out is None or out.shape != (z.shape[0], self.grid.shape[0]):
            out = np.empty((z.shape[0], self.grid.shape[0]))
        p = self.params
        return beam_table_kernel(z, self.grid, self.eta_hit, self.eta_short, p.z_hit, p.z_short, p.z_max, p.z_rand,
                                 p.sigma_hit_m, p.lambda_short_per_m, self.max_range_m, out)


@njit(cache=True, inline="always")
def _beam_row(rays, i, k, table, inv_step):
    """``sum_b log P(z_b | z*_b)`` of particle ``i`` (see :func:`beam_loglik_kernel`).

    Indices are unsigned (ranges are >= 0, so is every index): numba then emits no
    negative-index wraparound code, which took half of this loop's time.
    """
    nb = table.shape[0]
    last = table.shape[1] - 1
    iu = np.uint64(i)
    s = 0.0
    for b in range(nb):
        bu = np.uint64(b)
        e = rays[iu, np.uint64(b * k)]
        for q in range(1, k):
            e = min(e, rays[iu, np.uint64(b * k + q)])
        u = e * inv_step
        j = int(u)
        if j >= last:
            s += table[bu, np.uint64(last)]
        else:
            ju = np.uint64(j)
            t0 = table[bu, ju]
            s += t0 + (u - j) * (table[bu, ju + np.uint64(1)] - t0)
    return s


@njit(cache=True, parallel=True)
def beam_loglik_kernel(rays, k, table, inv_step, exponent, out):
    """Log-likelihood of one scan for every particle, from ray-cast ranges and the table.

    Parameters
    ----------
    rays : (P, B * k) float64
        Ray-cast ranges; beam ``b`` owns columns ``b k .. b k + k - 1`` (a sonar cone's rays;
        ``k = 1`` for a laser) and its expected distance is their minimum.
    k : int
        Rays per beam.
    table : (B, J + 1) float64
        :func:`beam_log_table` of the measured scan.
    inv_step : float
        ``1 / step`` of the table [1/m].
    exponent : float
        Multiplies the sum (``1`` for the plain product of beam likelihoods).
    out : (P,) float64
        Written: ``exponent * sum_b log P(z_b | z*_b(l))``.
    """
    for i in prange(rays.shape[0]):
        out[i] = _beam_row(rays, i, k, table, inv_step) * exponent
    return out


@njit(cache=True)
def beam_loglik_kernel_serial(rays, k, table, inv_step, exponent, out):
    """Serial twin of :func:`beam_loglik_kernel` (small calls on busy cores lose milliseconds
    to a thread launch). A function of its own: numba's on-disk cache does not key entries by
    the ``parallel`` flag, so ``njit(beam_loglik_kernel.py_func)`` could load threaded code."""
    for i in range(rays.shape[0]):
        out[i] = _beam_row(rays, i, k, table, inv_step) * exponent
    return out


@njit(cache=True, inline="always")
def _beam_sum(buf, first, nb, k, table, inv_step):
    """:func:`_beam_row` of the rays ``buf[first : first + nb k]`` of one pose (the same
    operations in the same order, so the same bits)."""
    last = table.shape[1] - 1
    s = 0.0
    for b in range(nb):
        bu = np.uint64(b)
        e = buf[np.uint64(first + b * k)]
        for q in range(1, k):
            e = min(e, buf[np.uint64(first + b * k + q)])
        u = e * inv_step
        j = int(u)
        if j >= last:
            s += table[bu, np.uint64(last)]
        else:
            ju = np.uint64(j)
            t0 = table[bu, ju]
            s += t0 + (u - j) * (table[bu, ju + np.uint64(1)] - t0)
    return s


@njit(cache=True)
def beam_loglik_cast_kernel(clear, ext, ox, oy, res, xs, ys, ct, st, tmax, cb, sb, k, table, inv_step, exponent, out):
    """Ray casting and :func:`beam_loglik_kernel_serial` in one pass, a few poses at a time.

    The first ten arguments are ``RayCaster._kernel_inputs`` of a caster built with
    ``stretched=True``; ``cb, sb`` the cos and sin of the ray angles (beam ``b`` owns rays
    ``b k .. b k + k - 1``); the rest as in :func:`beam_loglik_kernel`. The ranges of a group
    of poses stay in a small buffer and are summed at once, so the (P, B k) range array is
    neither written nor read back (480 kB for 1000 particles and 60 beams). The same ranges
    (``_cast_serial_st``) and the same sums, so the same bits as casting then summing.
    """
    nr = cb.shape[0]
    nbeams = table.shape[0]
    scratch = _scratch_st(nr)
    ranges = scratch[-1]
    n = xs.shape[0]
    for g0 in range(0, n, _POSES_PER_WAVE_ST):
        g1 = min(n, g0 + _POSES_PER_WAVE_ST)
        _cast_group_st(clear, ext, ox, oy, res, xs, ys, ct, st, cb, sb, tmax, g0, g1, scratch)
        for p in range(g0, g1):
            out[p] = _beam_sum(ranges, (p - g0) * nr, nbeams, k, table, inv_step) * exponent
    return out


def beam_log_likelihood_reference(expected: np.ndarray, measured: np.ndarray, params: BeamModelParams,
                                  max_range_m: float) -> np.ndarray:
    """Exact NumPy ``sum_b log P(z_b | z*_{p,b})`` for expected ranges (P, B) and a scan (B,)."""
    e = array("expected", expected, (-1, -1))
    z = array("measured", measured, (e.shape[1],))
    return np.log(beam_probability(z[None, :], e, params, max_range_m)).sum(axis=1)
