"""Density trees: a weighted sample set as a piecewise-constant density (Fox et al. §3.2).

Fox, Burgard, Kruppa & Thrun §3.2 (Fig. 5, eqs. 13–14): to multiply the belief a teammate
sends into one's own samples, "our approach transforms sample sets into density functions
using density trees (Koller and Fratkina, 1998; Moore et al., 1997; Omohundro, 1987, 1991)".
The rules, as the paper gives them:

- all samples start in the root, a box covering the samples' space;
- a node is split until a stopping condition holds; "if a node is split, its interval is
  divided into two equally sized intervals along its longest dimension";
- "each leaf's density is given by the quotient of the sum of all weights p of all samples
  that fall into this leaf, divided by the volume of the region covered by the leaf" (the
  maximum-likelihood piecewise-constant density).

Choices the paper leaves to Thrun et al. (1999b), made here:

- *Stopping rule*: a node becomes a leaf when it holds fewer than ``2 min_samples`` samples or
  less than ``min_weight`` of the total weight, or is at ``max_depth``.
- *Root box*: the samples' bounding box, widened by ``padding`` on each side (a density has
  no support outside it: it is 0 there).
- *Longest dimension*: lengths are compared after scaling each dimension by ``scale`` (for
  (x, y, theta): metres and ``heading_scale_m`` metres per radian).
- *Heading is circular*: a circular dimension's root interval is the whole circle
  ``(-pi, pi]`` and queries are wrapped into it, so densities near ±pi are not split apart.

Detections and the heading. A detection (range and bearing of robot n seen by robot m, §4)
observes n's *position*, not its heading: ``P(L_n = (x, y, theta) | L_m = l', r_m)`` does not
depend on ``theta``. The density of eq. (13), ``int P(L_n = l | L_m = l', r_m) Bel_m(l') dl'``,
is therefore ``q(x, y) / (2 pi)``: the heading is uniform, and the constant ``1 / 2 pi``
disappears in the normaliser alpha of eq. (14). :mod:`~teamnav.localization.sync` builds a
2-D tree over (x, y) and evaluates it at the detected robot's samples' positions; the 3-D
form (``circular=(False, False, True)``) is there for beliefs over full poses.

Speed: the build is one serial numba pass; a batch query runs :func:`query_kernel` (threaded)
from ``_PARALLEL_MIN_POINTS`` points and its serial twin :func:`query_kernel_serial` below, both
around one ``inline="always"`` body (a thread launch costs milliseconds on busy cores).

Serialisation: a tree is a handful of flat arrays (:attr:`DensityTree.nbytes`), small enough
for a radio message (:class:`~teamnav.localization.sync.SyncMessage`).

Ref: Koller & Fratkina, "Using learning for approximation in stochastic processes", ICML 1998;
Moore, Schneider & Deng, "Efficient locally weighted polynomial regression predictions",
ICML 1997; Thrun, Langford & Fox, "Monte Carlo hidden Markov models", ICML 1999.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from teamnav.localization._checks import array

__all__ = ["DensityTree", "build_tree_kernel", "query_kernel", "query_kernel_serial"]


@njit(cache=True)
def build_tree_kernel(samples, weights, lo, hi, scale, min_samples, min_weight, max_depth,
                      split_dim, split_val, child, density):
    """Grow a density tree; returns the number of nodes.

    ``split_dim`` (int8, -1 = leaf), ``split_val`` (float32), ``child`` (int32, left child; the
    right child is ``child + 1``), ``density`` (float32) are written for nodes
    ``0 .. n_nodes - 1``; their length bounds the node count (a node that would not fit stays a
    leaf). ``weights`` must sum to one.
    """
    n, d = samples.shape
    cap = split_dim.shape[0]
    idx = np.arange(n)
    # explicit stack of nodes to process: node id, [start, end) into idx, depth, box
    st_node = np.empty(cap, np.int64)
    st_a = np.empty(cap, np.int64)
    st_b = np.empty(cap, np.int64)
    st_depth = np.empty(cap, np.int64)
    st_lo = np.empty((cap, d))
    st_hi = np.empty((cap, d))
    top = 0
    st_node[0] = 0
    st_a[0] = 0
    st_b[0] = n
    st_depth[0] = 0
    st_lo[0, :] = lo
    st_hi[0, :] = hi
    top = 1
    n_nodes = 1
    while top > 0:
        top -= 1
        node = st_node[top]
        a = st_a[top]
        b = st_b[top]
        depth = st_depth[top]
        blo = st_lo[top].copy()
        bhi = st_hi[top].copy()
        w = 0.0
        for j in range(a, b):
            w += weights[idx[j]]
        vol = 1.0
        for k in range(d):
            vol *= bhi[k] - blo[k]
        if (b - a < 2 * min_samples or w < min_weight or depth >= max_depth or n_nodes + 2 > cap or vol <= 0.0):
            split_dim[node] = -1
            density[node] = w / vol if vol > 0.0 else 0.0
            child[node] = -1
            split_val[node] = 0.0
            continue
        best = 0
        best_len = -1.0
        for k in range(d):
            ln = (bhi[k] - blo[k]) * scale[k]
            if ln > best_len:
                best_len = ln
                best = k
        mid = np.float32(0.5 * (blo[best] + bhi[best]))
        midf = float(mid)
        # partition idx[a:b]: samples < mid first
        i = a
        j = b - 1
        while i <= j:
            if samples[idx[i], best] < midf:
                i += 1
            else:
                t = idx[i]
                idx[i] = idx[j]
                idx[j] = t
                j -= 1
        left = n_nodes
        n_nodes += 2
        split_dim[node] = best
        split_val[node] = mid
        child[node] = left
        density[node] = 0.0
        # push right then left
        st_node[top] = left + 1
        st_a[top] = i
        st_b[top] = b
        st_depth[top] = depth + 1
        st_lo[top, :] = blo
        st_hi[top, :] = bhi
        st_lo[top, best] = midf
        top += 1
        st_node[top] = left
        st_a[top] = a
        st_b[top] = i
        st_depth[top] = depth + 1
        st_lo[top, :] = blo
        st_hi[top, :] = bhi
        st_hi[top, best] = midf
        top += 1
    return n_nodes


@njit(cache=True, inline="always")
def _query_one(points, i, lo, hi, circular, split_dim, split_val, child, density):
    """Density of the tree at ``points[i]`` (0 outside the root box); circular dims wrapped."""
    d = lo.shape[0]
    for k in range(d):
        v = points[i, k]
        if circular[k]:
            v = v - 2.0 * math.pi * math.floor((v - lo[k]) / (2.0 * math.pi))
        if not (lo[k] <= v < hi[k] or (circular[k] and v == hi[k])):
            return 0.0
    node = 0
    while split_dim[node] >= 0:
        k = split_dim[node]
        v = points[i, k]
        if circular[k]:
            v = v - 2.0 * math.pi * math.floor((v - lo[k]) / (2.0 * math.pi))
        node = child[node] + (0 if v < split_val[node] else 1)
    return density[node]


@njit(cache=True, parallel=True)
def query_kernel(points, lo, hi, circular, split_dim, split_val, child, density, out):
    """Density of the tree at every point (0 outside the root box); circular dims wrapped."""
    for i in prange(points.shape[0]):
        out[i] = _query_one(points, i, lo, hi, circular, split_dim, split_val, child, density)
    return out


@njit(cache=True)
def query_kernel_serial(points, lo, hi, circular, split_dim, split_val, child, density, out):
    """Serial twin of :func:`query_kernel` (small calls on busy cores lose milliseconds to a
    thread launch). A function of its own: numba's on-disk cache does not key entries by the
    ``parallel`` flag, so ``njit(query_kernel.py_func)`` could load threaded code."""
    for i in range(points.shape[0]):
        out[i] = _query_one(points, i, lo, hi, circular, split_dim, split_val, child, density)
    return out


#: Below this many query points :meth:`DensityTree.__call__` runs :func:`query_kernel_serial`.
#: Measured on the shared 2-core machine under load (tree of 765 nodes, 2 numba threads, median
#: wall per call, serial vs threaded): 1k points 0.15 vs 12 ms, 10k 1.5 vs 12 ms, 50k 11 vs 12 ms,
#: 100k 21 vs 24 ms, 300k 63 vs 50 ms. The build (:func:`build_tree_kernel`) is serial already.
_PARALLEL_MIN_POINTS = 50_000


@dataclass(frozen=True)
class DensityTree:
    """A density tree as flat arrays (plain data: it travels in radio messages).

    Attributes
    ----------
    lo, hi : ndarray of shape (d,), float64
        Root box [units of each dimension: m, m, rad].
    circular : ndarray of shape (d,), bool
        Which dimensions are angles with period ``2 pi`` (their root interval is ``[-pi, pi]``).
    split_dim : ndarray of shape (m,), int8
        Dimension a node splits, -1 for a leaf.
    split_val : ndarray of shape (m,), float32
        Split coordinate (the middle of the node's interval).
    child : ndarray of shape (m,), int32
        Left child's index (right child: ``child + 1``), -1 for a leaf.
    density : ndarray of shape (m,), float32
        Leaf density (weight / volume) [1 / (m² or m² rad)]; 0 for inner nodes.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> t = DensityTree.fit(rng.normal(size=(5000, 2)), min_samples=50)
    >>> round(float(t.integral()), 6)
    1.0
    >>> bool(t(np.array([[0.0, 0.0]]))[0] > t(np.array([[2.0, 2.0]]))[0])
    True
    """

    lo: np.ndarray
    hi: np.ndarray
    circular: np.ndarray
    split_dim: np.ndarray
    split_val: np.ndarray
    child: np.ndarray
    density: np.ndarray

    @classmethod
    def fit(cls, samples, weights=None, *, circular=None, scale=None, min_samples: int = 10,
            min_weight: float = 0.0, max_depth: int = 24, padding=None, max_nodes: int | None = None) -> "DensityTree":
        """Grow a tree from weighted samples (Fox et al. §3.2).

        Parameters
        ----------
        samples : ndarray of shape (n, d)
            Sample coordinates, ``d >= 1``.
        weights : ndarray of shape (n,), optional
            Non-negative, positive sum (normalised here); default equal weights.
        circular : sequence of bool of length d, optional
            Angular dimensions (default: none).
        scale : sequence of float of length d, optional
            Multipliers making dimensions comparable when choosing the longest (default 1).
        min_samples : int, default 10
            A node with fewer than ``2 min_samples`` samples is a leaf.
        min_weight : float, default 0
            A node with less than this share of the weight is a leaf.
        max_depth : int, default 24
            Depth of the deepest leaf.
        padding : sequence of float of length d, optional
            Widening of the root box on each side (default: 1 % of its extent, at least 1e-6).
        max_nodes : int, optional
            Node budget (default ``4 n / min_samples + 1``, enough for the stopping rule).
        """
        x = array("samples", samples, (-1, -1))
        n, d = x.shape
        if n == 0 or d == 0:
            raise ValueError(f"samples must be a non-empty (n, d) array with d >= 1, got shape {x.shape}")
        if weights is None:
            w = np.full(n, 1.0 / n)
        else:
            w = array("weights", weights, (n,))
            if (w < 0).any() or not w.sum() > 0:
                raise ValueError(f"weights must be >= 0 with a positive sum, got sum {w.sum()!r}")
            w = w / w.sum()
        circ = np.zeros(d, dtype=np.bool_) if circular is None else np.asarray(circular, dtype=np.bool_)
        if circ.shape != (d,):
            raise ValueError(f"circular must have {d} entries (one per dimension), got {circ.shape}")
        sc = np.ones(d) if scale is None else array("scale", scale, (d,))
        if (sc <= 0).any():
            raise ValueError(f"scale must be > 0 in every dimension, got {sc.tolist()}")
        for name, v, lo_ in (("min_samples", min_samples, 1), ("max_depth", max_depth, 0)):
            if not (isinstance(v, (int, np.integer)) and v >= lo_):
                raise ValueError(f"{name} must be an integer >= {lo_}, got {v!r}")
        if not (math.isfinite(min_weight) and 0.0 <= min_weight <= 1.0):
            raise ValueError(f"min_weight must be in [0, 1], got {min_weight!r}")
        x = x.copy()
        if circ.any():
            x[:, circ] = x[:, circ] - 2 * np.pi * np.floor((x[:, circ] + np.pi) / (2 * np.pi))
        lo = x.min(axis=0)
        hi = x.max(axis=0)
        if padding is None:
            pad = np.maximum(0.01 * (hi - lo), 1e-6)
        else:
            pad = array("padding", padding, (d,))
            if (pad < 0).any():
                raise ValueError(f"padding must be >= 0, got {pad.tolist()}")
            pad = np.maximum(pad, 1e-9)
        lo = lo - pad
        hi = hi + pad
        lo[circ] = -np.pi
        hi[circ] = np.pi
        cap = int(max_nodes) if max_nodes is not None else int(4 * n // min_samples + 1)
        if cap < 1:
            raise ValueError(f"max_nodes must be >= 1, got {max_nodes!r}")
        cap = cap if cap % 2 == 1 else cap + 1
        split_dim = np.empty(cap, np.int8)
        split_val = np.empty(cap, np.float32)
        child = np.empty(cap, np.int32)
        density = np.empty(cap, np.float32)
        m = build_tree_kernel(x, w, lo, hi, sc, int(min_samples), float(min_weight), int(max_depth),
                              split_dim, split_val, child, density)
        return cls(lo, hi, circ, split_dim[:m].copy(), split_val[:m].copy(), child[:m].copy(), density[:m].copy())

    # ------------------------------------------------------------------ queries
    @property
    def dim(self) -> int:
        return int(self.lo.shape[0])

    @property
    def n_nodes(self) -> int:
        return int(self.split_dim.shape[0])

    @property
    def n_leaves(self) -> int:
        return int((self.split_dim < 0).sum())

    @property
    def nbytes(self) -> int:
        """Bytes of the arrays (what a message carrying the tree costs)."""
        return int(sum(a.nbytes for a in (self.lo, self.hi, self.circular, self.split_dim, self.split_val,
                                          self.child, self.density)))

    def __call__(self, points) -> np.ndarray:
        """Densities at ``points`` (k, d) in one call; 0 outside the root box."""
        p = array("points", points, (-1, self.dim))
        kernel = query_kernel if p.shape[0] >= _PARALLEL_MIN_POINTS else query_kernel_serial
        return kernel(p, self.lo, self.hi, self.circular, self.split_dim, self.split_val, self.child,
                      self.density, np.empty(p.shape[0]))

    def leaves(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Boxes and densities of the leaves: ``(lo (L, d), hi (L, d), density (L,))``."""
        los, his, dens = [], [], []
        stack = [(0, self.lo.astype(np.float64).copy(), self.hi.astype(np.float64).copy())]
        while stack:
            node, lo, hi = stack.pop()
            k = int(self.split_dim[node])
            if k < 0:
                los.append(lo)
                his.append(hi)
                dens.append(float(self.density[node]))
                continue
            mid = float(self.split_val[node])
            l_hi = hi.copy()
            l_hi[k] = mid
            r_lo = lo.copy()
            r_lo[k] = mid
            c = int(self.child[node])
            stack.append((c, lo, l_hi))
            stack.append((c + 1, r_lo, hi))
        return np.array(los), np.array(his), np.array(dens)

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        """``n`` points drawn from the tree's density: a leaf by its mass (density x volume),
        then uniformly inside its box. Circular dimensions are wrapped to ``[-pi, pi)``.

        Examples
        --------
        >>> rng = np.random.default_rng(0)
        >>> t = DensityTree.fit(rng.normal(size=(4000, 2)), min_samples=40)
        >>> pts = t.sample(2000, rng)
        >>> pts.shape, bool(abs(pts[:, 0].mean()) < 0.1)
        ((2000, 2), True)
        """
        n = int(n)
        if n < 0:
            raise ValueError(f"n must be >= 0, got {n}")
        lo, hi, dens = self.leaves()
        mass = dens * np.prod(hi - lo, axis=1)
        if not mass.sum() > 0:
            raise ValueError("the tree has no mass to sample from")
        leaf = rng.choice(mass.shape[0], size=n, p=mass / mass.sum())
        pts = lo[leaf] + rng.random((n, lo.shape[1])) * (hi[leaf] - lo[leaf])
        for k in np.flatnonzero(self.circular):
            pts[:, k] = (pts[:, k] + math.pi) % (2 * math.pi) - math.pi
        return pts

    def integral(self) -> float:
        """``sum density x volume`` over the leaves (1 up to float32 rounding)."""
        lo, hi, dens = self.leaves()
        return float(np.sum(dens * np.prod(hi - lo, axis=1)))
