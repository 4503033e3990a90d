"""``paper_rules: true`` for the LOS brains and navigators (the paper as written),
the new flags' paper values, and a mix refused."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from teamnav.papers.los_help.brains.brain import los_gap_fills
from teamnav.papers.los_help.brains.explorer import LosExplorerParams
from teamnav.papers.los_help.brains.goal_sharing import GoalSharing, goal_id
from teamnav.papers.los_help.brains.helper import LosHelperParams
from teamnav.control.nav.local import NAVIGATORS, AvoidPastParams, PotentialFieldParams, VisBugParams
from teamnav.control.paper_rules import gap_fills

BRAINS = (LosExplorerParams, LosHelperParams)

#: the gap-fills that the paper-as-written column turns off, and the three new flags
ISSUE_LIST = ("see_past_teammates", "keep_direct_view", "report_margin_steps", "slide_when_blocked",
              "trust_direct_promise", "trouble_helper_towards_goal", "trouble_drop_stalled_helper",
              "keep_trouble_helper", "navigator_params.turn", "relay_hop_limit", "drop_stalled_ghost",
              "navigator_params.boundary_shortcut")


@pytest.mark.parametrize("cls", BRAINS + (VisBugParams, AvoidPastParams, PotentialFieldParams))
def test_every_rule_names_a_field_has_a_note_citing_the_paper(cls):
    assert set(cls.PAPER_RULES) == set(cls.PAPER_RULE_NOTES)
    for g in gap_fills(cls):
        assert g.note.split()[0] in ("Sgorbissa", "VisBug-21"), g
        assert g.field in cls.model_fields


def test_the_issue_list_is_covered_and_the_defaults_are_ours():
    fills = {g.field: g for g in los_gap_fills(LosExplorerParams, "visbug21")}
    for name in ISSUE_LIST:
        assert name in fills, name
        assert fills[name].teamnav_value != fills[name].paper_value, name
    assert fills["navigator_params.turn"].paper_value == "right"  # a fill of the paper column (TURN_RULE)
    assert fills["report_margin_steps"].paper_value == 0.0
    # Avoid-Past's memory lifetime is a fill the same in both columns, not a paper rule
    ap = {g.field: g for g in los_gap_fills(LosExplorerParams, "avoid_past")}
    assert not any(f.startswith("navigator_params.memory") for f in ap)
    # the same-step sighting is an artifact fix in both columns, not a paper rule
    assert "trouble_sighting_at_send" not in fills and LosExplorerParams(paper_rules=True).trouble_sighting_at_send
    # a helper has no explorer-only rule
    assert "trust_direct_promise" not in {g.field for g in los_gap_fills(LosHelperParams, "potential_field")}


@pytest.mark.parametrize("cls", BRAINS)
@pytest.mark.parametrize("navigator", sorted(NAVIGATORS))
def test_paper_rules_sets_every_listed_field_and_the_navigator_as_written(cls, navigator):
    p = cls(paper_rules=True, navigator=navigator)
    for key, value in cls.PAPER_RULES.items():
        assert getattr(p, key) == value, key
    nav = NAVIGATORS[navigator].Params(**p.navigator_params)
    assert nav.paper_rules
    for key, value in type(nav).PAPER_RULES.items():
        assert getattr(nav, key) == value, key
    # the default run is unchanged: teamnav's values
    d = cls(navigator=navigator)
    assert not d.paper_rules and d.see_past_teammates and d.relay_hop_limit and d.navigator_params == {}


@pytest.mark.parametrize("kwargs", [
    {"see_past_teammates": True},
    {"report_margin_steps": 1.0},
    {"relay_hop_limit": True},
    {"navigator": "visbug21", "navigator_params": {"turn": "nearer_end"}},
    {"navigator": "visbug21", "navigator_params": {"paper_rules": False}},
    {"keep_trouble_helper": True},
])
def test_a_mix_is_an_error_naming_the_field(kwargs):
    name = next(iter(kwargs.get("navigator_params", kwargs)))
    if name == "navigator":
        name = next(iter(kwargs["navigator_params"]))
    with pytest.raises(ValidationError, match=name):
        LosExplorerParams(paper_rules=True, **kwargs)


def test_explorer_only_rules():
    p = LosExplorerParams(paper_rules=True)
    assert (p.trust_direct_promise, p.drop_stalled_ghost, p.visbug_reverse_walk_factor) == (False, False, None)
    with pytest.raises(ValidationError, match="visbug_reverse_walk_factor"):
        LosExplorerParams(paper_rules=True, visbug_reverse_walk_factor=3.0)
    with pytest.raises(ValidationError, match="drop_stalled_ghost"):
        LosExplorerParams(paper_rules=True, drop_stalled_ghost=True)


def test_relay_without_the_hop_limit_relays_every_goal_with_id_minus_one():
    """§3.1 as written (``relay_hop_limit=False``): a goal at its last hop (Nr = 1) is relayed too,
    with an Id that names the owner's previous goal; an Id of 0 names no goal and is not sent."""
    for limit, want in ((True, []), (False, [(1, 3)])):
        gs = GoalSharing(2, 3, relay_hop_limit=limit)
        gs.receive_goal(1, goal_id(2, 3) - 2, (2.0, 2.0))  # robot 1's goal 2 relayed twice: Id 4, Nr = 1
        assert [(o, g) for o, g, _, _ in gs.shares()] == want
    gs = GoalSharing(2, 3, relay_hop_limit=False)
    gs.receive_goal(1, goal_id(1, 3) - 2, (2.0, 2.0))      # goal 1 at its last hop: Id 1
    assert gs.shares() == []
    # a robot holding the current goal refuses the relayed previous one (§3.1's Id rule)
    other = GoalSharing(0, 3)
    other.receive_goal(1, goal_id(2, 3), (2.0, 2.0))
    assert not other.receive_goal(1, 3, (2.0, 2.0))
