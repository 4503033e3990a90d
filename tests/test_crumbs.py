"""Crumb lists of "Blazing a trail" (Vaughan et al. 2000 §4.1): average heading within a radius,
broadcast-and-clear (the waggle dance), carrying robots follow the opposite heading."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.coop.crumbs import CrumbBatch, CrumbList, average_heading, preferred_heading
from teamnav.geometry.angles import angle_diff


def test_average_heading_is_circular_and_ignores_crumbs_outside_the_radius():
    c = CrumbList()
    c.drop(0.0, 0.0, math.pi - 0.2)
    c.drop(1.0, 0.0, -math.pi + 0.1)   # across the +-pi cut: arithmetic mean would be ~0
    c.drop(2.0, 0.0, math.pi)
    c.drop(6.0, 0.0, 0.0)              # outside the 3 m radius
    m = c.average_heading(1.0, 0.0, 3.0)
    assert abs(angle_diff(m, math.pi - (0.2 - 0.1) / 3)) < 1e-3
    assert c.average_heading(1.0, 0.0, 5.0) != pytest.approx(m)  # the far crumb now counts
    assert c.average_heading(20.0, 20.0, 3.0) is None
    # boundary is inclusive
    assert c.average_heading(9.0, 0.0, 3.0) == pytest.approx(0.0)


def test_opposite_headings_cancel_to_no_preference():
    xy = np.zeros((2, 2))
    assert average_heading(xy, np.array([0.3, 0.3 + math.pi]), 0.0, 0.0, 1.0) is None
    with pytest.raises(ValueError, match="radius_m must be a positive"):
        average_heading(xy, np.zeros(2), 0.0, 0.0, 0.0)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(-math.pi, math.pi), min_size=1, max_size=30), st.floats(-math.pi, math.pi))
def test_average_heading_rotates_with_the_crumbs(headings, rot):
    """Rotating every crumb heading by rot rotates the mean by rot (equivariance)."""
    h = np.array(headings)
    xy = np.zeros((h.size, 2))
    m0 = average_heading(xy, h, 0.0, 0.0, 1.0)
    m1 = average_heading(xy, h + rot, 0.0, 0.0, 1.0)
    if m0 is None or np.hypot(np.sin(h).sum(), np.cos(h).sum()) < 1e-3:
        return  # directions cancel out: undefined mean
    assert abs(angle_diff(m1, m0 + rot)) < 1e-6


def test_broadcast_and_clear_sender_keeps_its_own_crumbs_globally():
    """§4.1: on arrival the private list goes out; everyone, the sender too, appends it to the
    global list; the sender's private list is cleared."""
    private, glob_sender, glob_other = CrumbList(), CrumbList(), CrumbList()
    glob_other.drop(-5.0, -5.0, 1.0)
    for k in range(5):
        private.drop(float(k), 0.0, 0.0)
    body = private.to_batch()
    private.clear()
    for g in (glob_sender, glob_other):
        g.extend(body)
    assert len(private) == 0 and len(body) == 5
    np.testing.assert_array_equal(glob_sender.xy_m[:, 0], np.arange(5.0))
    assert len(glob_other) == 6
    private.drop(9.0, 9.0, 0.0)  # clearing the private list did not touch what was broadcast
    assert len(body) == 5 and len(glob_sender) == 5


def test_carrying_robot_follows_the_opposite_heading_home():
    """Crumbs dropped while carrying point back to the source, so the average still points
    to the source and a carrying robot turns the other way."""
    c = CrumbList()
    c.drop(0.0, 0.0, 0.0)                       # outbound, heading east to the source
    c.drop(0.5, 0.0, math.pi, outbound=False)   # carrying, heading west to home
    m = c.average_heading(0.0, 0.0, 1.0)
    assert m == pytest.approx(0.0, abs=1e-12)
    assert preferred_heading(m, carrying=False) == pytest.approx(0.0, abs=1e-12)
    assert abs(preferred_heading(m, carrying=True)) == pytest.approx(math.pi)
    assert preferred_heading(None, carrying=True) is None


def test_crumb_list_grows_and_can_be_capped():
    c = CrumbList()
    c.extend(CrumbBatch(np.arange(2000.0).repeat(2).reshape(-1, 2), np.zeros(2000)))
    assert len(c) == 2000 and c.xy_m[-1, 0] == 1999.0
    capped = CrumbList(max_crumbs=3)
    for k in range(5):
        capped.drop(float(k), 0.0, 0.0)
    np.testing.assert_array_equal(capped.xy_m[:, 0], [2.0, 3.0, 4.0])
    with pytest.raises(ValueError, match="xy_m has 2 rows"):
        CrumbBatch(np.zeros((2, 2)), np.zeros(3))
