"""paper_rules: true sets every declared gap-fill to the paper's value, refuses a mix, and lists both values."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from teamnav.papers.trails.brains.blazing_trail import BlazingTrail, BlazingTrailParams, navigate_params
from teamnav.papers.trails.brains.trail_share import TrailShareParams
from teamnav.control.nav.navigate import NavigateParams
from teamnav.control.nav.wall_follow import SlidingBox
from teamnav.control.paper_rules import gap_fills

BRAINS = (BlazingTrailParams, TrailShareParams)


@pytest.mark.parametrize("cls", BRAINS + (NavigateParams,))
def test_every_rule_names_a_field_has_a_note_and_differs_from_ours(cls):
    assert set(cls.PAPER_RULES) == set(cls.PAPER_RULE_NOTES)
    for g in gap_fills(cls):
        assert g.note.split()[0] in ("Blazing", "Try"), g
        if g.field != "cruise_speed_mps":  # 0.25 is the class default; the scenarios drive 0.4
            assert g.teamnav_value != g.paper_value, g


@pytest.mark.parametrize("cls", BRAINS)
def test_paper_rules_sets_every_listed_field_and_navigates_as_written(cls):
    p = cls(paper_rules=True)
    for key, value in cls.PAPER_RULES.items():
        assert getattr(p, key) == value, key
    nav = navigate_params(p.navigate, p.cruise_speed_mps)
    assert nav.paper_rules
    for key, value in NavigateParams.PAPER_RULES.items():
        assert getattr(nav, key) == value, key
    # the lane reach and the side rule are not gap-fills with a paper value: kept
    assert nav.box_reach_m == 2.0 and nav.trail_rule == "side"
    # every listed gap-fill appears in the table, the nested ones with their prefix
    fields = {g.field for g in gap_fills(cls)}
    assert set(cls.PAPER_RULES) <= fields
    assert {f"navigate.{k}" for k in NavigateParams.PAPER_RULES} <= fields


def test_the_issue_list_is_covered():
    fields = {g.field for g in gap_fills(BlazingTrailParams)} | {g.field for g in gap_fills(TrailShareParams)}
    for name in ("crumb_min_move_m", "prune_loops", "lookahead_m", "recover_radius_m", "descend_only",
                 "turn_at_place", "cruise_speed_mps", "navigate.reverse_cooldown_s",
                 "navigate.reverse_cooldown_m", "navigate.reverse_memory_m", "navigate.box_ahead_free",
                 "navigate.panic_on_stall"):
        assert name in fields, name


def test_the_2000_paper_rules_keep_the_single_trail_backwards_and_leave_the_speed_to_the_column():
    """Try §1: the 2000 trail "was followed forwards towards the 'goal' and backwards towards 'home'":
    crumbs laid while carrying stored reversed is the paper's rule, not a gap-fill; the 2000 paper
    states no speed (the report's paper column sets the one its numbers imply)."""
    blazing = {g.field for g in gap_fills(BlazingTrailParams)}
    assert "reverse_carried_crumbs" not in blazing and "cruise_speed_mps" not in blazing
    p = BlazingTrailParams(paper_rules=True, cruise_speed_mps=0.4)
    assert p.reverse_carried_crumbs and p.cruise_speed_mps == 0.4
    # the literal reading is still a run: the ablation row
    assert not BlazingTrailParams(paper_rules=True, reverse_carried_crumbs=False).reverse_carried_crumbs
    # the 2002 paper states its speed: trail-share-v1's paper rules still set it
    assert TrailShareParams(paper_rules=True).cruise_speed_mps == 0.25
    with pytest.raises(ValidationError, match="cruise_speed_mps"):
        TrailShareParams(paper_rules=True, cruise_speed_mps=0.4)


@pytest.mark.parametrize("kwargs, name", [
    ({"lookahead_m": 1.0}, "lookahead_m"),
    ({"navigate": {"reverse_cooldown_s": 5.0}}, "navigate.reverse_cooldown_s"),
    ({"navigate": {"box_ahead_free": True}}, "navigate.box_ahead_free"),
    ({"navigate": {"paper_rules": False}}, "navigate"),
])
def test_a_mix_is_an_error_naming_the_field(kwargs, name):
    with pytest.raises(ValidationError, match=name.replace(".", r"\.")):
        BlazingTrailParams(paper_rules=True, **kwargs)


def test_the_paper_value_set_twice_is_fine_and_default_is_teamnav():
    p = BlazingTrailParams(paper_rules=True, lookahead_m=0.0, navigate={"reverse_memory_m": 0})
    assert p.lookahead_m == 0.0
    q = BlazingTrailParams()
    assert not q.paper_rules and q.lookahead_m == 1.0 and q.reverse_carried_crumbs
    assert navigate_params(q.navigate, q.cruise_speed_mps).box_ahead_free


def test_gap_fills_take_the_scenario_values():
    g = {x.field: x for x in gap_fills(TrailShareParams, {"cruise_speed_mps": 0.4, "navigate": {"reverse_memory_m": 1.5}})}
    assert g["cruise_speed_mps"].teamnav_value == 0.4 and g["cruise_speed_mps"].paper_value == 0.25
    assert g["navigate.reverse_memory_m"].teamnav_value == 1.5
    assert g["navigate.reverse_cooldown_s"].teamnav_value == 5.0


def test_sliding_box_first_box_alone_decides_without_the_ahead_check():
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    r = np.full(181, 8.0)
    r[np.abs(angles) < 0.05] = 0.6  # a post straight ahead, the left box free
    strict = SlidingBox(angles, 0.8, 1.0, 0.1, 0.8, 0.05, 0.4, 2.0, 1.5, 0.25)
    paper = SlidingBox(angles, 0.8, 1.0, 0.1, 0.8, 0.05, 0.4, 2.0, 1.5, 0.25, ahead_must_be_free=False)
    assert strict.command(r).state == "follow"
    assert paper.command(r).state == "open"


def test_crumbs_laid_while_carrying_keep_the_robots_heading_under_paper_rules():
    from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo

    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    info = RobotInfo(0, 1, 0.25, "unicycle", 0.5, 2.0, 0.1, 0.1,
                     sensors={"laser": SensorInfo("laser", "laser", angles, 8.0)})
    heads = {}
    for flag in (True, False):
        brain = BlazingTrail(BlazingTrailParams(reverse_carried_crumbs=flag), np.random.default_rng(0), info)
        brain.round.observe(["took_resource"], 0.0)  # reached the source: carrying
        assert brain.carrying
        scan = RangeScan(np.full(181, 8.0), angles, 8.0)
        brain.step(Observation(0, 0, 0.0, np.array([1.0, 0.0, 0.5]), np.zeros(3), scans={"laser": scan}))
        heads[flag] = float(brain.private.heading_rad[0])
    assert heads[False] == pytest.approx(0.5)
    assert heads[True] == pytest.approx(0.5 - np.pi) or heads[True] == pytest.approx(0.5 + np.pi)
