"""scripts/trail_fill_tuning.py: its ground-truth criteria (lane share, off-route share) measure
what they say on the trail office's geometry, and the values the trail brains use are the picks
its rules make on the stored tuning-seed runs (docs/report/trails-fill-tuning.jsonl)."""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.papers.trails.brains.blazing_trail import NAVIGATE_DEFAULTS, BlazingTrailParams
from teamnav.papers.trails.brains.trail_share import TrailShareParams

_ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("trail_fill_tuning", _ROOT / "scripts" / "trail_fill_tuning.py")
ft = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ft)
DATA = _ROOT / "docs" / "report" / "trails-fill-tuning.jsonl"


@settings(max_examples=60, deadline=None)
@given(stretch=st.sampled_from(ft.STRETCHES), t=st.floats(0.0, 1.0), off=st.floats(0.05, 0.85),
       side=st.sampled_from([-1.0, 1.0]), back=st.booleans(), jitter=st.floats(-0.5, 0.5))
def test_lane_share_counts_the_left_of_travel_on_the_straight_stretches(stretch, t, off, side, back, jitter):
    _, axis, centre, lo, hi, (xlo, xhi) = stretch
    along = lo + t * (hi - lo)
    if xlo < along < xhi:  # a passing place: not counted
        along = lo
    th = (0.0 if axis == "x" else math.pi / 2) + (math.pi if back else 0.0) + jitter  # within 30 deg of the axis
    xy = (along, centre + side * off) if axis == "x" else (centre + side * off, along)
    share, n = ft.lane_share(np.array([[[xy[0], xy[1], th]]]))
    assert n == 1
    # left of travel: north of C1/C3 going east, west of C2 going north; the reverse going back
    left_side = (1.0 if axis == "x" else -1.0) * (-1.0 if back else 1.0)
    assert share == (1.0 if side == left_side else 0.0)
    # across the corridor's axis (a turn) nothing is counted
    _, n_across = ft.lane_share(np.array([[[xy[0], xy[1], th + math.pi / 2]]]))
    assert n_across == 0


def test_off_route_share_is_time_outside_the_route_corridors():
    on = [(2.0, 4.9), (14.9, 10.0), (5.4, 15.9), (15.5, 16.5)]  # home, C2, the source, corner 2
    off = [(25.0, 4.9), (14.9, 20.0), (25.0, 15.9), (2.0, 15.9)]  # C1's, C2's and C3's dead ends, C3 west
    pose = np.array([[[x, y, 0.0] for x, y in on + off]])
    assert ft.off_route_share(pose) == pytest.approx(0.5)


@pytest.mark.skipif(not DATA.exists(), reason="the stored tuning runs are not beside this checkout")
def test_the_brains_use_the_values_the_rules_pick_on_the_stored_tuning_runs():
    rows = [json.loads(line) for line in DATA.read_text().splitlines() if line]
    assert {r["seed"] for r in rows} <= set(ft.SEEDS) and min(ft.SEEDS) >= 1000
    for r in rows:  # each run drove the value it is filed under
        assert r["box_reach_m"] == r["extra"]["navigate"]["box_reach_m"]
        if "radius_m" in r["extra"]:
            assert r["radius_m"] == r["extra"]["radius_m"]
    recover = [r for r in rows if "recover_radius_m" in r["extra"]]
    rows = [r for r in rows if "recover_radius_m" not in r["extra"]]
    box = [dict(r, value=r["extra"]["navigate"]["box_reach_m"]) for r in rows if "radius_m" not in r["extra"]]
    table, pick = ft._pick(box, "lane_share", sorted({r["value"] for r in box}), "max")
    assert all(n == len(ft.SEEDS) for *_, n in table)
    values = [v for v, *_ in table]
    assert min(values) < pick < max(values)  # the grid brackets the pick (FIDELITY §3)
    assert NAVIGATE_DEFAULTS["box_reach_m"] == pick
    rad = [dict(r, value=r["extra"]["radius_m"]) for r in rows if "radius_m" in r["extra"]]
    if rad:
        assert {r["extra"]["navigate"]["box_reach_m"] for r in rad} == {pick}  # run at the box rule's pick
        table, rpick = ft._pick(rad, "off_route_share", sorted({r["value"] for r in rad}), "min")
        values = [v for v, *_ in table]
        assert min(values) < rpick < max(values)
        assert TrailShareParams().radius_m == rpick
    for section, cls in (("blazing-a-trail", BlazingTrailParams), ("try-to-see-it-my-way", TrailShareParams)):
        rec = [dict(r, value=r["extra"]["recover_radius_m"]) for r in recover if r["section"] == section]
        if not rec:
            continue
        assert all(r["recover_radius_m"] == r["value"] and r["column"] == "teamnav" for r in rec)
        table, pick = ft._pick(rec, "off_route_share", sorted({r["value"] for r in rec}), "min")
        assert pick < max(v for v, *_ in table)  # 0 (the paper's rule) may be picked; the top may not
        assert cls().recover_radius_m == pick
