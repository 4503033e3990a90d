"""Density trees (Fox et al. §3.2): normalisation, accuracy against a known Gaussian, the
halving rule, circular heading, batch queries and serialised size."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import multivariate_normal

from teamnav.localization import DensityTree


def test_densities_integrate_to_one_2d_and_3d():
    rng = np.random.default_rng(0)
    x2 = rng.normal(size=(5000, 2))
    w = rng.random(5000)
    assert abs(DensityTree.fit(x2, w, min_samples=20).integral() - 1.0) < 1e-5
    x3 = np.c_[rng.normal(size=(5000, 2)), rng.uniform(-np.pi, np.pi, 5000)]
    t3 = DensityTree.fit(x3, circular=[False, False, True], min_samples=20)
    assert abs(t3.integral() - 1.0) < 1e-5
    # Monte Carlo integral of the query over the root box agrees too
    u = rng.uniform(t3.lo, t3.hi, size=(200_000, 3))
    assert abs(t3(u).mean() * np.prod(t3.hi - t3.lo) - 1.0) < 0.02


def test_matches_a_known_gaussian():
    rng = np.random.default_rng(1)
    cov = np.array([[0.5, 0.1], [0.1, 0.2]])
    x = rng.multivariate_normal([2.0, -1.0], cov, size=20_000)
    t = DensityTree.fit(x, min_samples=100)
    q = rng.multivariate_normal([2.0, -1.0], cov, size=2000)  # where the mass is
    truth = multivariate_normal([2.0, -1.0], cov).pdf(q)
    est = t(q)
    assert np.median(np.abs(est - truth) / truth) < 0.25
    assert abs(np.corrcoef(est, truth)[0, 1]) > 0.9
    assert t(np.array([[50.0, 50.0]]))[0] == 0.0  # outside the root box


def test_splits_halve_the_longest_dimension():
    x = np.random.default_rng(2).uniform([0.0, 0.0], [8.0, 1.0], size=(4000, 2))
    t = DensityTree.fit(x, min_samples=1000, padding=[0.0, 0.0])
    assert t.split_dim[0] == 0  # x is the longest
    assert math.isclose(t.split_val[0], 0.5 * (t.lo[0] + t.hi[0]), rel_tol=1e-6)
    lo, hi, _ = t.leaves()
    assert np.all((hi - lo)[:, 0] >= (hi - lo)[:, 1] / 2 - 1e-6)  # splitting kept boxes near square


def test_heading_is_circular():
    rng = np.random.default_rng(3)
    th = np.angle(np.exp(1j * rng.normal(np.pi, 0.2, 5000)))  # a mode straddling +-pi
    x = np.c_[rng.normal(size=5000), rng.normal(size=5000), th]
    t = DensityTree.fit(x, circular=[False, False, True], min_samples=25)
    assert t.lo[2] == -np.pi and t.hi[2] == np.pi
    d = t(np.array([[0.0, 0.0, np.pi - 0.05], [0.0, 0.0, -np.pi + 0.05], [0.0, 0.0, 3 * np.pi - 0.05],
                    [0.0, 0.0, 0.0]]))
    assert d[0] > 0 and d[1] > 0 and d[0] == d[2]  # wrapped queries land in the same leaf
    assert d[3] < 0.05 * min(d[0], d[1])


def test_serialised_size_and_bad_input():
    x = np.random.default_rng(4).normal(size=(10_000, 2))
    t = DensityTree.fit(x, min_samples=20)
    assert t.nbytes == sum(a.nbytes for a in (t.lo, t.hi, t.circular, t.split_dim, t.split_val, t.child, t.density))
    assert t.nbytes < 13 * t.n_nodes + 64
    assert t.n_leaves == (t.n_nodes + 1) // 2
    with pytest.raises(ValueError, match="weights must be >= 0"):
        DensityTree.fit(x, -np.ones(10_000))
    with pytest.raises(ValueError, match=r"samples must have shape \(n, n\)"):
        DensityTree.fit(np.ones(3))
    with pytest.raises(ValueError, match="circular must have 2 entries"):
        DensityTree.fit(x, circular=[True])
    with pytest.raises(ValueError, match=r"points must have shape \(n, 2\)"):
        t(np.ones((4, 3)))


def test_serial_and_threaded_queries_agree_and_have_their_own_cache():
    """The serial twin (small queries skip the thread launch) gives the threaded kernel's
    densities bit for bit, including outside the root box and across the circular seam, and has
    its own cache file (numba's cache does not key by ``parallel``; see tests/test_mcl.py)."""
    from teamnav.localization import density_tree as dt

    rng = np.random.default_rng(5)
    x = np.c_[rng.normal(size=(3000, 2)), rng.uniform(-np.pi, np.pi, 3000)]
    t = dt.DensityTree.fit(x, rng.random(3000), circular=[False, False, True], min_samples=15)
    q = np.c_[rng.normal(scale=2.0, size=(4000, 2)), rng.uniform(-3 * np.pi, 3 * np.pi, 4000)]
    q[:5] = [[0.0, 0.0, np.pi], [0.0, 0.0, -np.pi], [50.0, 0.0, 0.0], [t.lo[0], 0.0, 0.0], [t.hi[0], 0.0, 0.0]]
    args = (t.lo, t.hi, t.circular, t.split_dim, t.split_val, t.child, t.density)
    ser = dt.query_kernel_serial(q, *args, np.empty(len(q)))
    par = dt.query_kernel(q, *args, np.empty(len(q)))
    np.testing.assert_array_equal(ser, par)
    assert ser[2] == 0.0 and ser[4] == 0.0 and ser[0] > 0.0  # outside the box; hi is open
    assert (ser > 0).sum() > 1000 and (ser == 0).sum() > 100  # both branches exercised
    np.testing.assert_array_equal(t(q), ser)  # below the threshold __call__ runs the serial twin
    big = np.tile(q, (dt._PARALLEL_MIN_POINTS // len(q) + 1, 1))
    np.testing.assert_array_equal(t(big), np.tile(ser, dt._PARALLEL_MIN_POINTS // len(q) + 1))
    assert dt.query_kernel_serial._cache._cache_file._index_name != dt.query_kernel._cache._cache_file._index_name
