"""The distance field without scipy's full-grid temporaries is scipy's field, bit for bit.

``teamnav.world.distance._edt`` computes the distances from scipy's feature transform a block
of rows at a time (a 10 000-robot arena has 25 M cells: scipy's own temporaries were 815 MB).
Every collision, start pose and potential field reads this field, so a last-bit difference
would change runs: the values are compared as raw bits.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays
from scipy import ndimage

from teamnav.world import distance


@settings(max_examples=60, deadline=None)
@given(free=arrays(np.bool_, st.tuples(st.integers(1, 40), st.integers(1, 40)), elements=st.booleans()),
       res=st.sampled_from([0.01, 0.02, 0.05, 0.1, 0.013, 0.3, 1.0, 2.5]),
       block=st.integers(1, 200))
def test_the_blocked_field_is_scipys_bit_for_bit(free, res, block):
    if free.all():
        free = free.copy()
        free[0, 0] = False  # scipy's transform needs one feature
    old = distance._EDT_BLOCK_CELLS
    distance._EDT_BLOCK_CELLS = block  # blocks of a few rows, down to one
    try:
        got = distance._edt(free, res)
    finally:
        distance._EDT_BLOCK_CELLS = old
    want = ndimage.distance_transform_edt(free, sampling=res)
    assert got.dtype == np.float64 and got.shape == want.shape
    assert np.array_equal(got.view(np.uint64), want.view(np.uint64))


def test_distance_field_uses_it_and_stays_exact(tmp_path, monkeypatch):
    monkeypatch.setenv("TEAMNAV_CACHE_DIR", str(tmp_path))  # no cached field: compute it
    distance._LAST[0] = None
    blocking = np.zeros((300, 500), np.uint8)
    blocking[0, :] = blocking[-1, :] = blocking[:, 0] = blocking[:, -1] = 1
    blocking[120:180, 200:260] = 1
    got = distance.distance_field(blocking, 0.02)
    want = ndimage.distance_transform_edt(blocking == 0, sampling=0.02)
    assert np.array_equal(got.view(np.uint64), want.view(np.uint64))
    assert got[150, 230] == 0.0 and got[150, 100] == pytest.approx(0.02 * 100)  # the west wall, 100 cells away
