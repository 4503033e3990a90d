"""Distance field and likelihood field."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.world.distance import distance_field, likelihood_field
from teamnav.world.grid import OccupancyGrid


def brute_distance(blocking, res):
    occ = np.argwhere(blocking != 0)
    h, w = blocking.shape
    rr, cc = np.mgrid[0:h, 0:w]
    d = np.full((h, w), np.inf)
    for r, c in occ:
        d = np.minimum(d, np.hypot(rr - r, cc - c) * res)
    return d


@settings(max_examples=80, deadline=None)
@given(
    h=st.integers(1, 15),
    w=st.integers(1, 15),
    seed=st.integers(0, 2**32 - 1),
    density=st.sampled_from([0.02, 0.1, 0.5, 1.0]),
    res=st.sampled_from([0.05, 1.0, 0.3]),
)
def test_matches_brute_force(h, w, seed, density, res):
    b = (np.random.default_rng(seed).random((h, w)) < density).astype(np.uint8)
    if not b.any():
        b[0, 0] = 1
    d = distance_field(b, res)
    np.testing.assert_allclose(d, brute_distance(b, res), rtol=1e-12, atol=1e-12)
    assert (d[b != 0] == 0).all() and (d[b == 0] > 0).all()


def test_grid_input_uses_every_obstacle_and_grid_resolution():
    cells = np.zeros((3, 5), np.uint8)
    cells[1, 0] = 3  # glass still counts: the field is about every obstacle
    g = OccupancyGrid(cells, 0.5)
    d = distance_field(g)
    np.testing.assert_allclose(d[1], [0.0, 0.5, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(distance_field(g, 0.5), d)


def test_no_obstacle_is_infinitely_far():
    assert np.isinf(distance_field(np.zeros((2, 3), np.uint8), 1.0)).all()


def test_likelihood_field():
    d = np.array([[0.0, 0.2, np.inf]])
    lf = likelihood_field(d, 0.2)
    np.testing.assert_allclose(lf, [[1.0, np.exp(-0.5), 0.0]])
    clipped = likelihood_field(d, 0.2, max_distance_m=0.2)
    np.testing.assert_allclose(clipped, [[1.0, np.exp(-0.5), np.exp(-0.5)]])


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: distance_field(np.zeros((2, 2), np.uint8)), "resolution_m"),
        (lambda: distance_field(np.zeros((2, 2), np.uint8), -1.0), "resolution_m"),
        (lambda: distance_field(OccupancyGrid.empty(1.0, 1.0, 0.5), 0.1), "resolution_m"),
        (lambda: distance_field(np.zeros(3, np.uint8), 1.0), "blocking"),
        (lambda: likelihood_field(np.zeros(2), 0.0), "sigma_m"),
        (lambda: likelihood_field(np.array([-1.0]), 1.0), "distance_m"),
        (lambda: likelihood_field(np.zeros(2), 1.0, max_distance_m=np.nan), "max_distance_m"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_a_repeated_field_is_shared_read_only():
    # distance_field keeps its last field (a run asks for its map's twice): the second answer
    # is the same array, which nobody can write into (a 10 000-robot arena's field is 200 MB:
    # not copied per caller)
    b = np.zeros((5, 7), np.uint8)
    b[2, 3] = 1
    first = distance_field(b, 0.1)
    second = distance_field(b, 0.1)
    assert second is first and not first.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        second[:] = -1.0
    mine = second.copy()
    mine[:] = -1.0  # a copy is the caller's own
    assert distance_field(b, 0.1)[2, 2] == pytest.approx(0.1)
    b[0, 0] = 1  # the caller's mask changed: computed afresh
    assert distance_field(b, 0.1)[0, 0] == 0.0 and first[0, 0] > 0.0
    assert distance_field(b, 0.2)[2, 1] == 0.2 * 2
