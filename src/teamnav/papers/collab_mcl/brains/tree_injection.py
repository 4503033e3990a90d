"""How a received detection tree enters a robot's particle set: sensor resetting + eq. 14.

Fox, Burgard, Kruppa & Thrun §3.2, eq. 14 multiply the received density tree into the
receiver's weights. Our brain (:mod:`teamnav.papers.collab_mcl.brains.localizing`, ``mcl-wander-v1``) first
replaces (or adds) ``inject_*`` draws from the tree, because its sample sets lose the true mode
of a symmetric belief long before a detection arrives and eq. 14 alone cannot move weight onto
samples that do not exist. This module holds that step and the weighting that keeps the
detection from being counted twice; the parameters (``inject_*``) live on
:class:`~teamnav.papers.collab_mcl.brains.mcl_wander_params.MCLWanderParams`, where each deviation is documented.
Belief only: the tree, the own particles and the own scan; no true pose.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from teamnav.localization.resample import low_variance_kernel
from teamnav.localization.sync import detection_factors

if TYPE_CHECKING:
    from teamnav.localization import MCL
    from teamnav.localization.sync import SyncMessage

InjectParams = Any  # an MCLWanderParams (its inject_* fields); not imported, to keep one direction


def inject_tree(p: InjectParams, rng: np.random.Generator, scan: np.ndarray | None, mcl: MCL,
            body: SyncMessage) -> np.ndarray:
    """Sensor resetting on a received detection tree, then eq. 14 (see ``inject_*`` params).

    ``inject_weighting="tree"`` (the first version): ``k`` random samples are replaced by
    draws from the tree with the set's mean weight and eq. 14 multiplies the tree into all
    of them, so when the tree contradicts the belief the ``k`` draws take nearly all the
    weight: the receiver adopts the sender's belief whether the sender is right or not.

    ``inject_weighting="bayes"``: two hypotheses, "my belief holds" (prior ``1 - eps``) and
    "I am lost" (prior ``eps`` = ``inject_lost_prior``, pose uniform over the free space).
    Their evidences for the tree ``f = (1 - p_fp) tree + p_fp / A`` are ``E_own = sum_i w_i
    f(x_i)`` and ``E_lost = 1 / A``; the draws (the posterior under "lost", ``U f ∝ f``)
    get the share ``s = eps E_lost / (eps E_lost + (1 - eps) E_own)`` of the weight, the
    kept samples ``1 - s`` in proportion to ``w_i f(x_i)`` (eq. 14). A confident belief the
    tree contradicts keeps ``1 - s`` (0.08 with the default ``eps`` = 0.3, 0.64 with 0.02;
    ``p_fp`` = 3.5 %) and the robot's own sensors decide between it and the draws over the
    next scans; a belief the tree confirms gives the draws almost nothing. ``eps`` = 0.3 is
    about how often a globally localizing robot alone was wrong at the time of a
    detection in our runs (Robin in §5.1: 5 of 10 runs still wrong at the end); with 0.02
    Robin kept a confident wrong belief 2.2 m behind the truth (seed 7).
    """
    n = mcl.n_particles
    area = mcl.free_area_m2
    k = int(round(p.inject_fraction * n))
    append = p.inject_weighting == "bayes" and p.inject_min_draws > k
    if append:
        k = p.inject_min_draws
    if k == 0:
        return detection_factors(body.tree, mcl.particles, body.p_false_positive, area)
    xy = body.tree.sample(k, rng)
    th = rng.uniform(-math.pi, math.pi, size=k)
    m = int(round(p.inject_heading_belief_share * k))
    if m > 0:  # heading of a sample drawn by weight from the own belief (a detection sees no heading)
        idx = low_variance_kernel(mcl.weights, m, float(rng.random()), np.empty(m, dtype=np.int64))
        th[:m] = mcl.particles[idx, 2] + rng.normal(0.0, math.radians(p.inject_heading_std_deg), size=m)
    ms = int(round(p.inject_heading_scan_share * (k - m)))
    if ms > 0 and scan is not None:
        th[m:m + ms] = scan_headings(p, rng, scan, mcl, xy[m:m + ms])
    q = np.column_stack([xy, th])
    if p.inject_weighting == "tree":
        mcl.replace_samples(q)
        return detection_factors(body.tree, mcl.particles, body.p_false_positive, area)
    f_own = detection_factors(body.tree, mcl.particles, sender_floor(p, body), area)
    e_own = float(np.dot(mcl.weights, f_own))
    eps = p.inject_lost_prior
    share = eps / area / (eps / area + (1.0 - eps) * e_own)
    if append:
        mcl.append_samples(q)
        n = mcl.n_particles
        new = np.zeros(n, dtype=bool)
        new[n - k:] = True
        return bayes_factors(mcl, body, new, share, k, sender_floor(p, body))
    before = mcl.particles.copy()
    mcl.replace_samples(q)
    after = mcl.particles
    new = np.any(after != before, axis=1)
    if int(new.sum()) != k:  # a draw equal to the sample it replaced (never in practice): locate by value
        new = np.zeros(n, dtype=bool)
        new[np.argsort(np.any(after != before, axis=1))[-k:]] = True
    return bayes_factors(mcl, body, new, share, k, sender_floor(p, body))

def sender_floor(p: InjectParams, body: SyncMessage) -> float:
    """Probability that the tree says nothing about this robot: a false positive, or a
    sender whose belief is wrong (``inject_sender_lost_prior``)."""
    pf = body.p_false_positive
    return pf + (1.0 - pf) * p.inject_sender_lost_prior

def bayes_factors(mcl: MCL, body: SyncMessage, new: np.ndarray, share: float, k: int,
              floor: float) -> np.ndarray:
    """Factors that give the ``k`` draws (``new``) the share ``share`` of the weight, evenly,
    and the kept samples ``1 - share`` in proportion to ``w_i f(x_i)`` (eq. 14)."""
    n = mcl.n_particles
    w = mcl.weights  # kept samples: w_i / Z, draws: 1 / (n Z)
    f = detection_factors(body.tree, mcl.particles, floor, mcl.free_area_m2)
    own_mass = float(np.dot(w[~new], f[~new]))
    factors = np.empty(n)
    factors[~new] = f[~new] * (1.0 - share) / own_mass if own_mass > 0 else 0.0
    factors[new] = share / k / w[new]
    return factors

def scan_headings(p: InjectParams, rng: np.random.Generator, scan: np.ndarray, mcl: MCL,
              xy: np.ndarray) -> np.ndarray:
    """One heading per position, drawn in proportion to this step's scan likelihood among
    ``inject_heading_candidates`` jittered headings (``inject_heading_scan_share``)."""
    h = p.inject_heading_candidates
    n = xy.shape[0]
    cand = (np.arange(h)[None, :] + rng.random((n, 1))) * (2.0 * math.pi / h) - math.pi
    poses = np.column_stack([np.repeat(xy, h, axis=0), cand.ravel()])
    ll = mcl.pose_log_likelihood(poses, scan).reshape(n, h)
    pr = np.exp(ll - ll.max(axis=1, keepdims=True))
    c = np.cumsum(pr, axis=1)
    pick = (c < rng.random((n, 1)) * c[:, -1:]).sum(axis=1)
    return cand[np.arange(n), np.minimum(pick, h - 1)]
