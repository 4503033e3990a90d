"""Likelihood-field perception model: the fast alternative to the beam model.

Instead of ray casting the expected distance of every beam (Fox et al. §2.2), the end point
of each measured beam is projected into the map and scored by its distance ``d`` to the
nearest obstacle (Thrun, Burgard & Fox, *Probabilistic Robotics* §6.4, Table 6.3)::

    q = prod_b ( z_hit N(d_b; 0, sigma_hit^2) + z_rand / z_max )      (max-range beams skipped)

The distance ``d`` is to the *surface* of the obstacles the sensor sees, on both sides: from a
free cell the distance to the nearest blocking cell, from a blocking cell the distance to the
nearest free cell (each minus half a cell, so both cells at a wall face score ``d = 0``). The
book's one-sided distance is 0 everywhere inside obstacles, so a pose whose end points all fall
deep into a large blocked area (the unknown space around a building) would score as well as
the true pose; with the surface distance such end points score as misses. It is computed once
(:func:`teamnav.world.distance.distance_field`), and so is the per-cell table
``log(z_hit N(min(d, d_max); 0, sigma^2) + z_rand / z_max)``; an update is then one table
load per particle-beam. End points outside the map score as if ``d = d_max``. A particle whose
own pose is not in free space (inside a wall, outside the map) scores ``log(z_rand / z_max)``
per beam, the worst a beam can score: the end-point model alone cannot see that a pose is
impossible, the beam model can (its rays have length 0 there).

Ref: Probabilistic Robotics §6.4, Table 6.3 (likelihood_field_range_finder_model).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from pydantic import BaseModel, ConfigDict, Field

from teamnav.world.distance import distance_field
from teamnav.world.grid import OccupancyGrid

__all__ = ["LikelihoodFieldParams", "build_log_field", "lf_loglik_kernel", "lf_loglik_kernel_serial",
           "lf_log_likelihood_reference"]


class LikelihoodFieldParams(BaseModel):
    """Parameters of the likelihood field (Table 6.3): ``z_hit + z_rand`` need not be 1 (the
    end-point model is not a density over ranges); ``max_distance_m`` [m] clips the distance."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    z_hit: float = Field(0.9, gt=0.0, le=1.0)
    z_rand: float = Field(0.1, gt=0.0, le=1.0)
    sigma_hit_m: float = Field(0.1, gt=0.0, le=100.0)
    max_distance_m: float = Field(2.0, gt=0.0, le=1000.0)


def build_log_field(grid: OccupancyGrid, blocking: np.ndarray, params: LikelihoodFieldParams,
                    max_range_m: float) -> tuple[np.ndarray, float]:
    """Per-cell ``log(z_hit N(d; 0, sigma^2) + z_rand / z_max)`` (float32, (H, W)) and the value
    used for end points outside the map (``d = max_distance_m``)."""
    res = grid.resolution_m
    outside_walls = distance_field(blocking, res)  # 0 in blocking cells
    inside_walls = distance_field((blocking == 0).astype(np.uint8), res)  # 0 in free cells
    d = np.clip(np.maximum(outside_walls, inside_walls) - 0.5 * res, 0.0, params.max_distance_m)
    d = np.where(np.isfinite(d), d, params.max_distance_m)
    s = params.sigma_hit_m
    norm = 1.0 / (s * math.sqrt(2.0 * math.pi))
    rand = params.z_rand / max_range_m
    table = np.log(params.z_hit * norm * np.exp(-0.5 * (d / s) ** 2) + rand).astype(np.float32)
    dm = params.max_distance_m
    outside = math.log(params.z_hit * norm * math.exp(-0.5 * (dm / s) ** 2) + rand)
    return table, outside


@njit(cache=True, inline="always")
def _lf_row(poses, i, ax, ay, table, free, ox, oy, inv_res, outside, worst):
    """Unscaled log-likelihood of particle ``i`` (see :func:`lf_loglik_kernel`)."""
    h, w = table.shape
    nb = ax.shape[0]
    x = poses[i, 0]
    y = poses[i, 1]
    c = int(math.floor((x - ox) * inv_res))
    r = int(math.floor((y - oy) * inv_res))
    if r < 0 or r >= h or c < 0 or c >= w or free[r, c] == 0:
        return worst * nb
    ct = math.cos(poses[i, 2])
    st = math.sin(poses[i, 2])
    s = 0.0
    for b in range(nb):
        ex = x + ct * ax[b] - st * ay[b]
        ey = y + st * ax[b] + ct * ay[b]
        c = int(math.floor((ex - ox) * inv_res))
        r = int(math.floor((ey - oy) * inv_res))
        if r < 0 or r >= h or c < 0 or c >= w:
            s += outside
        else:
            s += table[r, c]
    return s


@njit(cache=True, parallel=True)
def lf_loglik_kernel(poses, ax, ay, table, free, ox, oy, inv_res, outside, worst, exponent, out):
    """Log-likelihood of one scan for every particle under the likelihood field.

    Parameters
    ----------
    poses : (P, 3) float64
        Particles.
    ax, ay : (B,) float64
        End points of the valid (non-max) beams in the body frame: ``z_b cos(beam_b)``,
        ``z_b sin(beam_b)`` [m].
    table : (H, W) float32
        :func:`build_log_field`.
    free : (H, W) uint8
        1 where a robot's pose may be.
    ox, oy, inv_res : float
        Grid origin [m] and ``1 / resolution`` [1/m].
    outside, worst : float
        Log-likelihood of an end point outside the map; of a beam from a non-free pose.
    exponent : float
        Multiplies the sum.
    out : (P,) float64
        Written.
    """
    for i in prange(poses.shape[0]):
        out[i] = _lf_row(poses, i, ax, ay, table, free, ox, oy, inv_res, outside, worst) * exponent
    return out


@njit(cache=True)
def lf_loglik_kernel_serial(poses, ax, ay, table, free, ox, oy, inv_res, outside, worst, exponent, out):
    """Serial twin of :func:`lf_loglik_kernel` (small calls on busy cores lose milliseconds to
    a thread launch). A function of its own: numba's on-disk cache does not key entries by
    the ``parallel`` flag, so ``njit(lf_loglik_kernel.py_func)`` could load threaded code."""
    for i in range(poses.shape[0]):
        out[i] = _lf_row(poses, i, ax, ay, table, free, ox, oy, inv_res, outside, worst) * exponent
    return out


def lf_log_likelihood_reference(poses, measured, angles, table, free, origin_xy, resolution, outside, worst,
                                max_range_m) -> np.ndarray:
    """Pure-NumPy reference of :func:`lf_loglik_kernel` (one scan, all particles)."""
    poses = np.asarray(poses, dtype=np.float64)
    z = np.asarray(measured, dtype=np.float64)
    keep = z < max_range_m - 1e-6
    z, a = z[keep], np.asarray(angles, dtype=np.float64)[keep]
    ex = poses[:, :1] + z * np.cos(poses[:, 2:3] + a)
    ey = poses[:, 1:2] + z * np.sin(poses[:, 2:3] + a)
    h, w = table.shape
    c = np.floor((ex - origin_xy[0]) / resolution).astype(np.int64)
    r = np.floor((ey - origin_xy[1]) / resolution).astype(np.int64)
    ins = (r >= 0) & (r < h) & (c >= 0) & (c < w)
    vals = np.where(ins, table[np.clip(r, 0, h - 1), np.clip(c, 0, w - 1)].astype(np.float64), outside)
    s = vals.sum(axis=1)
    pc = np.floor((poses[:, 0] - origin_xy[0]) / resolution).astype(np.int64)
    pr = np.floor((poses[:, 1] - origin_xy[1]) / resolution).astype(np.int64)
    pin = (pr >= 0) & (pr < h) & (pc >= 0) & (pc < w)
    ok = pin & (free[np.clip(pr, 0, h - 1), np.clip(pc, 0, w - 1)] == 1)
    return np.where(ok, s, worst * z.shape[0])
