"""Line-of-sight help (Sgorbissa & Arkin): the rules of §3–§5 on hand-made situations, the
brains on synthetic observations, and one short run through the experiment runner."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from pydantic import ValidationError

from teamnav.control import Detection, Message, Observation, RangeScan, RobotInfo, SensorInfo
from teamnav.papers.los_help.brains import brain as brain_mod
from teamnav.papers.los_help.brains import LosExplorer, LosHelper
from teamnav.papers.los_help.brains.goal_sharing import (
    GoalSharing,
    accept_goal_id,
    can_relay,
    goal_id,
    goal_index,
    hops,
    point_visible,
    relayed_id,
    see_past_teammates,
    sender_frame,
)
from teamnav.papers.los_help.brains.messages import (
    MESSAGE_KIND,
    GoalShare,
    LosHelpMsg,
    Sighting,
    VisReport,
    message_size_bytes,
)
from teamnav.papers.los_help.brains.state_sharing import TroubleState, choose_helper
from teamnav.geometry import wrap_angle
from teamnav.geometry.bearings import relative_frame_from_bearings
from teamnav.geometry.se2 import relative, transform_points

N_BEAMS = 360
ANGLES = np.linspace(-np.pi, np.pi, N_BEAMS, endpoint=False)
MAX_RANGE = 8.0


# ---------------------------------------------------------------------------- test doubles
class StraightNav:
    """Algorithm A stand-in: heads straight at the goal; ``stuck`` makes it report no progress."""

    name = "straight"

    def __init__(self, stuck: bool = False) -> None:
        self.goal = None
        self.stuck = stuck
        self.progressing = True
        self.temporary = False
        self.calls: list[tuple[tuple[float, float], bool]] = []

    def set_goal(self, goal_xy, temporary: bool = False) -> None:
        self.goal = np.asarray(goal_xy, dtype=float)
        self.temporary = temporary
        self.calls.append((tuple(self.goal.tolist()), temporary))

    def direction(self, pose, scan):
        self.progressing = not self.stuck
        if self.goal is None:
            return None
        return math.atan2(self.goal[1] - pose[1], self.goal[0] - pose[0])


@pytest.fixture
def straight_nav(monkeypatch):
    made = []

    def make(name, params, *, rng, step_length_m, radius_m):
        nav = StraightNav()
        made.append(nav)
        return nav

    monkeypatch.setattr(brain_mod, "make_navigator", make)
    return made


def info(robot_id: int = 0, team_size: int = 4) -> RobotInfo:
    laser = SensorInfo("laser", "laser", ANGLES, MAX_RANGE)
    return RobotInfo(robot_id, team_size, 0.2, "holonomic_step", 0.5, 1.5, 0.1, 0.1, sensors={"laser": laser})


def scan(walls=()) -> RangeScan:
    """Omnidirectional scan, free to MAX_RANGE except ``walls``: (bearing_rad, half_width_rad, range_m)."""
    r = np.full(N_BEAMS, MAX_RANGE)
    for b, hw, rng in walls:
        r[np.abs(wrap_angle(ANGLES - b)) <= hw] = rng
    return RangeScan(r, ANGLES.copy(), MAX_RANGE)


def obs(step, pose=(0.0, 0.0, 0.0), *, walls=(), seen=(), inbox=(), robot_id=0) -> Observation:
    dets = tuple(Detection(float(r), float(b), int(i)) for i, r, b in seen)
    return Observation(robot_id, step, 0.1 * step, np.array(pose, float), np.zeros(3), scans={"laser": scan(walls)},
                       detections=dets, stalled=False, inbox=tuple(inbox))


def msg(sender, step, *, sightings=(), goals=(), reports=(), trouble=None) -> Message:
    return Message(sender, 0.1 * step, LosHelpMsg(step, tuple(sightings), tuple(goals), tuple(reports), trouble),
                   kind=MESSAGE_KIND)


def polar(xy_from, xy_to, heading=0.0):
    dx, dy = xy_to[0] - xy_from[0], xy_to[1] - xy_from[1]
    return math.hypot(dx, dy), float(wrap_angle(math.atan2(dy, dx) - heading))


# ---------------------------------------------------------------------------- identifiers (§3.1)
def test_goal_identifiers_follow_section_3_1():
    m = 4
    assert goal_id(3, m) == 12 and relayed_id(12) == 11
    # k = 1 + (Id - 1) / M still names goal 3 after M - 1 relays; Nr counts down from M
    assert [goal_index(i, m) for i in (12, 11, 10, 9)] == [3, 3, 3, 3]
    assert [hops(i, m) for i in (12, 11, 10, 9)] == [4, 3, 2, 1]
    assert can_relay(10, m) and not can_relay(9, m)  # Id 8 would name goal 2
    with pytest.raises(ValueError, match="k and team_size"):
        goal_id(0, m)


def test_id_arbitration_second_hand_never_overrides_first_hand():
    """§3.1 / Fig. 5: a report is accepted only if its Id >= the stored one."""
    gs = GoalSharing(0, 4)
    assert gs.receive_goal(1, goal_id(2, 4), (5.0, 1.0))  # directly from R2 (owner 1)
    assert not gs.receive_goal(1, relayed_id(goal_id(2, 4)), (9.0, 9.0))  # via R3: rejected
    assert gs.goal_of(1) == (8, 5.0, 1.0)
    assert gs.receive_goal(1, goal_id(2, 4), (5.1, 1.0))  # the same Id again: accepted (fresher frame)
    assert gs.goal_of(1)[1] == pytest.approx(5.1)
    # the owner's next goal (k = 3) replaces goal 2 even second-hand: 12 - 1 > 8
    assert gs.receive_goal(1, relayed_id(goal_id(3, 4)), (-2.0, 0.0))
    assert gs.goal_of(1) == (11, -2.0, 0.0)
    assert accept_goal_id(None, 1) and not accept_goal_id(12, 11)
    # a robot never takes a report of its own goal
    assert not gs.receive_goal(0, 100, (0.0, 0.0))


def test_relay_decrements_id_and_stops_at_last_hop():
    gs = GoalSharing(2, 3)
    gs.set_own_goal(1, (0.0, 0.0))
    gs.receive_goal(0, goal_id(1, 3), (1.0, 1.0))  # first hand from robot 0: Nr = 3
    gs.receive_goal(1, goal_id(1, 3) - 2, (2.0, 2.0))  # already relayed twice: Nr = 1
    shared = {owner: gid for owner, gid, _, _ in gs.shares()}
    assert shared == {2: 3, 0: 2}  # own goal k·M; robot 0's with Id - 1; robot 1's not relayed


# ---------------------------------------------------------------------------- visibility (§2)
def test_point_visible_reads_the_beam_towards_the_point():
    s = scan(walls=[(0.0, 0.05, 2.0)])
    assert point_visible((1.9, 0.0), s.ranges_m, s.angles_rad, 8.0)
    assert not point_visible((2.5, 0.0), s.ranges_m, s.angles_rad, 8.0)
    assert point_visible((2.5, 0.0), s.ranges_m, s.angles_rad, 8.0, margin_m=0.6)  # a robot stands there
    assert point_visible((0.0, 5.0), s.ranges_m, s.angles_rad, 8.0)
    assert not point_visible((0.0, 5.0), s.ranges_m, s.angles_rad, 4.0)  # beyond the visibility radius
    half = np.linspace(-np.pi / 2, np.pi / 2, 181)
    assert not point_visible((-3.0, 0.0), np.full(181, 8.0), half, 8.0)  # behind a 180° laser


# ---------------------------------------------------------------------------- D arbitration (§3–§4)
def test_mirror_chain_rules_shortest_distance_wins():
    """Fig. 3: R1 takes R2's reflection, then R3's when dist + D is shorter, never a longer one."""
    gs = GoalSharing(0, 4)
    gs.set_own_goal(1, (10.0, 0.0))
    me = (0.0, 0.0)
    assert gs.receive_report(0, 4, 1, (0.0, 4.0), 11.0, me_xy=me, step=1)  # D = 4 + 11 = 15
    assert gs.path(0).source == 1 and gs.path(0).distance_m(me) == pytest.approx(15.0)
    assert not gs.receive_report(0, 4, 2, (0.0, -3.0), 13.0, me_xy=me, step=2)  # 16 > 15
    assert gs.receive_report(0, 4, 3, (3.0, 0.0), 7.0, me_xy=me, step=2)  # 10 < 15
    assert gs.path(0).source == 3
    assert not gs.receive_report(0, 8, 1, (1.0, 0.0), 0.5, me_xy=me, step=3)  # report of goal 2: wrong goal
    # a direct view beats everything and is never replaced by a report
    gs.refresh(me, me, lambda x, y, m: (x, y) == (10.0, 0.0), step=4)
    assert gs.path(0).kind == "direct"
    assert not gs.receive_report(0, 4, 3, (9.0, 0.0), 0.1, me_xy=me, step=4)


def test_reflected_visibility_only_forgets_reports_each_step():
    gs = GoalSharing(0, 2, delayed=False)
    gs.set_own_goal(1, (10.0, 0.0))
    gs.receive_report(0, 2, 1, (0.0, 4.0), 11.0, me_xy=(0.0, 0.0), step=1)
    assert gs.path(0) is not None
    gs.begin_step()
    assert gs.path(0) is None


def test_ghost_kept_when_the_helper_walks_away():
    """§4.2 / Fig. 7: R2 later promises a longer path: R1 keeps its ghost R2(t1)."""
    gs = GoalSharing(0, 2)
    gs.set_own_goal(1, (10.0, 0.0))
    me = (0.0, 0.0)
    gs.receive_report(0, 2, 1, (4.0, 0.0), 6.0, me_xy=me, step=1)  # D11(t1) = 10
    me = (1.0, 0.0)
    assert not gs.receive_report(0, 2, 1, (0.0, 5.0), 10.5, me_xy=me, step=2)  # walked away: 15.6 > 9
    p = gs.path(0)
    assert (p.kind, p.source, p.px_m, p.py_m, p.step) == ("ghost", 1, 4.0, 0.0, 1)
    # the owner keeps its ghost even when out of sight (it heads there)
    gs.refresh(me, (0.0, 0.0), lambda x, y, m: False, step=3)
    assert gs.path(0).kind == "ghost"


def test_owner_compares_reports_with_the_stored_promise():
    """§4.2: R1 stores D11(t1) and takes a later report only if it beats it; after reaching the
    ghost and wandering off, a promise no better than the followed one does not pull it back."""
    gs = GoalSharing(0, 2)
    gs.set_own_goal(1, (10.0, 0.0))
    gs.receive_report(0, 2, 1, (4.0, 0.0), 6.0, me_xy=(0.0, 0.0), step=1)  # D11(t1) = 10
    gs.mark_reached(0)
    far = (4.0, 10.0)  # wandered off: current D = 10 + 6 = 16
    assert not gs.receive_report(0, 2, 1, (4.0, 5.0), 7.0, me_xy=far, step=9)  # 12: < 16 but not < 10
    assert gs.receive_report(0, 2, 1, (4.0, 8.0), 2.0, me_xy=far, step=10)  # 4 < 10
    p = gs.path(0)
    assert (p.px_m, p.py_m, p.reached, p.d_promised_m) == (4.0, 8.0, False, pytest.approx(4.0))
    # a relay (R2 for R1's goal) compares with its current D only (§4.3)
    relay = GoalSharing(1, 3)
    relay.receive_goal(0, goal_id(1, 3), (10.0, 0.0))
    relay.receive_report(0, 3, 2, (4.0, 0.0), 6.0, me_xy=(0.0, 0.0), step=1)
    assert relay.receive_report(0, 3, 2, (4.0, 5.0), 7.0, me_xy=(4.0, 10.0), step=9)


def test_report_margin_keeps_ghost_when_helper_walks_back_along_the_light_path():
    """A helper walking back towards R1 along the light path leaves dist + D unchanged (a tie up
    to millimetres): with the margin R1 keeps its point; with the strict rule (margin 0) a
    millimetre shorter report wins and R1 follows the helper away from its goal."""
    for margin, follows in ((0.2, False), (0.0, True)):
        gs = GoalSharing(0, 2, report_margin_m=margin)
        gs.set_own_goal(1, (20.0, 0.0))
        me = (0.0, 0.0)
        assert gs.receive_report(0, 2, 1, (10.0, 0.0), 10.0, me_xy=me, step=1)  # D = 20
        me = (0.2, 0.0)  # R1 one step on; R2 one step back towards it, its D one step longer
        taken = gs.receive_report(0, 2, 1, (9.8, 0.01), 10.2 - 0.002, me_xy=me, step=2)
        assert taken is follows
        # a real shortcut (more than the margin) is still taken
        assert gs.receive_report(0, 2, 1, (5.0, 5.0), 12.0, me_xy=me, step=3)  # 7.07 + 12 < 19.6


def test_lead_on_from_a_reached_ghost_but_never_back():
    """At a reached ghost, a teammate further along the light path leads on (a tie); one behind
    R1 does not (its dist + D counts the way back twice); without lead_on neither does."""
    for lead_on in (True, False):
        gs = GoalSharing(0, 2, report_margin_m=0.2, lead_on=lead_on)
        gs.set_own_goal(1, (20.0, 0.0))
        gs.receive_report(0, 2, 1, (10.0, 0.0), 10.0, me_xy=(0.0, 0.0), step=1)
        gs.mark_reached(0)
        me = (10.0, 0.0)
        assert not gs.receive_report(0, 2, 1, (7.0, 0.0), 13.0, me_xy=me, step=5)  # behind: 16 > 10
        assert not gs.receive_report(0, 2, 1, (10.1, 0.0), 9.9, me_xy=me, step=6)  # the same spot
        assert gs.receive_report(0, 2, 1, (14.0, 0.0), 6.0, me_xy=me, step=7) is lead_on  # ahead: 10
        if lead_on:
            p = gs.path(0)
            assert (p.px_m, p.d_point_m, p.reached) == (14.0, 6.0, False)


def test_go_via_leads_to_where_the_reporter_saw_the_goal():
    gs = GoalSharing(0, 2)
    gs.set_own_goal(1, (5.0, 5.0))
    # R2 at (5, 0) reports D = 3 + 2: its D leads through (5, 3), 2 m from the goal
    gs.receive_report(0, 2, 1, (5.0, 0.0), 5.0, me_xy=(0.0, 0.0), step=1, via_xy=(5.0, 3.0), via_d_m=2.0)
    assert gs.go_via(0, step=9)
    p = gs.path(0)
    assert (p.px_m, p.py_m, p.d_point_m, p.reached, p.via_d_m) == (5.0, 3.0, 2.0, False, None)
    assert not gs.go_via(0, step=10)  # one link only: the next needs a new report
    # the relayed terms carry the point (own frame) and its promised distance
    relay = GoalSharing(1, 2)
    relay.receive_goal(0, goal_id(1, 2), (5.0, 5.0))
    relay.refresh((5.0, 0.0), None, lambda x, y, m: True, step=0)
    assert relay.reports_via((5.0, 0.0)) == [(0, 2, 5.0, 5.0, 5.0, 0.0)]


def test_distance_bookkeeping_of_section_4_3():
    """Fig. 8: a helper that saw R1's goal and moved on reports D(t1) + dist(me, R_i(t1)); when
    R_i(t1) leaves its view, R_i(t2) and D(t2) replace them."""
    gs = GoalSharing(1, 2)  # the helper R2 (id 1) knows R1's goal
    goal = (5.0, 0.0)
    gs.receive_goal(0, goal_id(1, 2), goal)
    visible = {goal: True}

    def sees(x, y, margin):
        return visible.get((x, y), False)

    p0 = (0.0, 0.0)
    gs.refresh(p0, None, sees, step=0)
    assert gs.reports(p0) == [(0, 2, pytest.approx(5.0))]  # direct: dist(R2, G)
    visible[goal] = False  # t1: the helper turned a corner
    visible[p0] = True
    p1 = (0.0, 2.0)
    gs.refresh(p1, p0, sees, step=1)
    p = gs.path(0)
    assert (p.kind, p.px_m, p.py_m, p.d_point_m) == ("self", 0.0, 0.0, pytest.approx(5.0))
    assert gs.reports(p1)[0][2] == pytest.approx(5.0 + 2.0)  # D(t1) + dist(R2, R2(t1))
    visible[p1] = True
    p2 = (1.0, 3.0)
    gs.refresh(p2, p1, sees, step=2)  # R2(t1) still in view: only the distance grows
    assert gs.reports(p2)[0][2] == pytest.approx(5.0 + math.hypot(1.0, 3.0))
    visible[p0] = False  # R2(t1) out of view: substitute the last position it was seen from
    p3 = (2.0, 4.0)
    gs.refresh(p3, p2, sees, step=3)
    p = gs.path(0)
    d_t2 = 5.0 + math.hypot(1.0, 3.0)
    assert (p.px_m, p.py_m, p.d_point_m) == (1.0, 3.0, pytest.approx(d_t2))
    assert gs.reports(p3)[0][2] == pytest.approx(d_t2 + math.hypot(1.0, 1.0))


# ---------------------------------------------------------------------------- state sharing (§5)
def test_trouble_sequence_of_fig_10():
    """Pr += Nt when stuck, -1 when progressing, bound Nt·Cr; Tr at the bound, back at 0, Nt + 1."""
    s = TroubleState(cr=3)
    trace = []
    for progressing in [False] * 3 + [True] * 3 + [False] * 4 + [True] * 6:
        s.update(progressing)
        trace.append((s.pr, s.tr, s.nt))
    assert trace == [
        (1, False, 1), (2, False, 1), (3, True, 1),  # stuck: Tr after Cr steps
        (2, True, 1), (1, True, 1), (0, False, 2),  # follows R2, recovers: Nt = 2
        (2, False, 2), (4, False, 2), (6, True, 2), (6, True, 2),  # +Nt, bound 2·Cr
        (5, True, 2), (4, True, 2), (3, True, 2), (2, True, 2), (1, True, 2), (0, False, 3),  # twice as long
    ]
    s.reset()
    assert (s.pr, s.tr, s.nt) == (0, False, 1)
    with pytest.raises(ValueError, match="cr must be"):
        TroubleState(cr=0)


def test_choose_helper_picks_nearest_not_in_trouble():
    mates = [(3, 1.0, 0.0, True), (2, 4.0, 0.0, False), (1, 3.0, 0.0, False), (4, 0.5, 0.0, None)]
    assert choose_helper(True, (0.0, 0.0), mates) == 1
    assert choose_helper(False, (0.0, 0.0), mates) is None


# ---------------------------------------------------------------------------- brains on synthetic observations
def test_brain_mirror_chain_heads_to_r2_then_r3(straight_nav):
    """R1 cannot see its goal (a wall ahead); R2 reports it sees it: R1 heads to R2; R3 then
    reports a shorter D: R1 turns to R3 (§3 rule 5, Fig. 3)."""
    goal = (6.0, 0.0)
    r2, r3 = (0.0, 4.0), (3.0, -3.0)
    wall = [(0.0, 0.1, 2.0)]
    m = 4
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal]), np.random.default_rng(0), info(0, m))
    seen = [(1, *polar((0, 0), r2)), (2, *polar((0, 0), r3))]
    a, out = r1.step(obs(0, walls=wall, seen=seen))
    assert r1.mode == "own_goal" and a.direction_rad == pytest.approx(0.0)  # A heads at the goal
    assert len(out) == 1 and out[0].kind == MESSAGE_KIND  # it sees teammates: it talks
    back2 = Sighting(0, polar(r2, (0, 0))[1], 4.0)  # R2 faces +x in this test
    d2 = math.dist(r2, goal)
    a, _ = r1.step(obs(1, walls=wall, seen=seen, inbox=[
        msg(1, 0, sightings=[back2], reports=[VisReport(0, goal_id(1, m), d2)])]))
    assert r1.mode == "follow_teammate"
    assert a.direction_rad == pytest.approx(math.pi / 2, abs=1e-9)
    back3 = Sighting(0, polar(r3, (0, 0))[1], math.dist(r3, (0, 0)))
    d3 = math.dist(r3, goal)
    assert math.dist((0, 0), r3) + d3 < 4.0 + d2
    a, _ = r1.step(obs(2, walls=wall, seen=seen, inbox=[
        msg(1, 1, sightings=[back2], reports=[VisReport(0, goal_id(1, m), d2)]),
        msg(2, 1, sightings=[back3], reports=[VisReport(0, goal_id(1, m), d3)])]))
    assert r1.mode == "follow_teammate" and r1.sharing.path(0).source == 2
    assert a.direction_rad == pytest.approx(-math.pi / 4, abs=1e-9)
    # without a mutual bearing (R3 did not see R1) there is no frame: the report is ignored
    r1b = LosExplorer(LosExplorer.Params(targets_xy=[goal]), np.random.default_rng(0), info(0, m))
    r1b.step(obs(0, walls=wall, seen=seen))
    r1b.step(obs(1, walls=wall, seen=seen, inbox=[msg(2, 0, reports=[VisReport(0, goal_id(1, m), d3)])]))
    assert r1b.sharing.path(0) is None and r1b.mode == "own_goal"


def test_brain_keeps_ghost_and_falls_back_to_a_when_there(straight_nav):
    goal = (6.0, 0.0)
    wall = [(0.0, 0.3, 2.0)]
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal], goal_tolerance_m=0.3), np.random.default_rng(0), info(0, 2))
    r2 = (0.0, 3.0)
    r1.step(obs(0, walls=wall, seen=[(1, *polar((0, 0), r2))]))
    r1.step(obs(1, walls=wall, seen=[(1, *polar((0, 0), r2))], inbox=[
        msg(1, 0, sightings=[Sighting(0, -math.pi / 2, 3.0)], reports=[VisReport(0, 2, 6.7)])]))
    assert r1.mode == "follow_teammate"
    # R2 walks away out of sight: R1 keeps heading to where R2 promised (a ghost)
    a, _ = r1.step(obs(2, pose=(0.0, 1.0, 0.0), walls=wall))
    assert r1.mode == "ghost" and a.direction_rad == pytest.approx(math.pi / 2)
    # at the ghost, without a view of the goal: back to A, the promise kept only to arbitrate
    a, _ = r1.step(obs(3, pose=(0.0, 2.9, 0.0), walls=[(-0.45, 0.2, 1.0)]))
    assert r1.mode == "own_goal" and r1.sharing.path(0).reached
    assert straight_nav and straight_nav[0].goal.tolist() == [6.0, 0.0]


@pytest.mark.parametrize("via_in_sight, blocked, goes_via", [
    (True, False, True), (True, True, False), (False, True, True)])
def test_at_a_ghost_r1_goes_on_to_the_via_point_only_while_it_sees_it(straight_nav, via_in_sight, blocked, goes_via):
    # share_via: R2 at (0, 3), facing +x, reports D = 3 + 4.3 through its via point (3, 3);
    # via_in_sight: R1 at the ghost goes on to the via point only if its own scan shows it
    # (office_simple, Avoid-Past: a via point behind the N3/N2 wall pulled R1 into the wall)
    goal = (6.0, 0.0)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal], goal_tolerance_m=0.3, via_in_sight=via_in_sight),
                     np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.3, 2.0)]
    r2 = (0.0, 3.0)
    r1.step(obs(0, walls=wall, seen=[(1, *polar((0, 0), r2))]))
    r1.step(obs(1, walls=wall, seen=[(1, *polar((0, 0), r2))], inbox=[
        msg(1, 0, sightings=[Sighting(0, -math.pi / 2, 3.0)], reports=[VisReport(0, 2, 7.3, 3.0, 0.0, 4.3)])]))
    assert r1.mode == "follow_teammate"
    r1.step(obs(2, pose=(0.0, 1.0, 0.0), walls=wall))
    hide_goal = (math.atan2(-2.9, 6.0), 0.2, 1.0)
    via_bearing = math.atan2(0.1, 3.0)
    walls = [hide_goal, (via_bearing, 0.1, 1.0)] if blocked else [hide_goal]
    a, _ = r1.step(obs(3, pose=(0.0, 2.9, 0.0), walls=walls))
    assert r1.vias_taken == int(goes_via)
    if goes_via:
        assert r1.mode == "ghost" and a.direction_rad == pytest.approx(via_bearing, abs=1e-6)
        assert (r1.sharing.path(0).px_m, r1.sharing.path(0).py_m) == pytest.approx((3.0, 3.0))
    else:  # §4.2: at the ghost without its goal in sight, A again
        assert r1.mode == "own_goal" and r1.sharing.path(0).reached


def test_brain_state_sharing_follows_teammate_not_in_trouble(monkeypatch):
    """Fig. 10: stuck R1 (A makes no progress) is in trouble after Cr steps, heads to R2 which
    is not, recovers (Pr back to 0, Nt = 2) and returns to its own goal."""
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    cr = 3
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=cr, goal_sharing=False,
                                        trouble_progress="moved",  # any unblocked step is progress
                                        trouble_helper_towards_goal=False),  # §5 rule 3 as written
                     np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.1, 0.5)]
    for k in range(cr):
        r1.step(obs(k, walls=wall))
    assert r1.trouble.tr and r1.mode == "own_goal"  # in trouble, nobody in sight
    # R2 comes in sight, not in trouble: follow it while getting closer
    y = 5.0
    k = cr
    modes = []
    while r1.trouble.tr:
        pose = (0.0, 5.0 - y, 0.0)
        inbox = [msg(1, k - 1, trouble=False)]
        a, _ = r1.step(obs(k, pose=pose, walls=wall, seen=[(1, y, math.pi / 2)], inbox=inbox))
        modes.append(r1.mode)
        y -= 0.1
        k += 1
    assert modes[0] == "trouble_follow" and set(modes[:-1]) == {"trouble_follow"}
    assert len(modes) == cr and r1.trouble.nt == 2 and r1.trouble.pr == 0
    a, _ = r1.step(obs(k, pose=(0.0, 5.0 - y, 0.0), walls=wall, seen=[(1, y, math.pi / 2)],
                       inbox=[msg(1, k - 1, trouble=False)]))
    assert r1.mode == "own_goal"
    # a teammate in trouble is no help
    r1.trouble.tr, r1.trouble.pr = True, r1.trouble.bound
    r1.step(obs(k + 1, walls=wall, seen=[(1, 3.0, 1.0)], inbox=[msg(1, k, trouble=True)]))
    assert r1.mode == "own_goal"
    # a helper that walks out of sight stays the temporary goal at its last seen position
    r1.step(obs(k + 2, walls=wall, seen=[(1, 3.0, math.pi / 2)], inbox=[msg(1, k + 1, trouble=False)]))
    assert r1.mode == "trouble_follow"
    a, _ = r1.step(obs(k + 3, pose=(0.0, 0.5, 0.0), walls=wall))
    assert r1.mode == "trouble_follow" and a.direction_rad == pytest.approx(math.pi / 2)
    a, _ = r1.step(obs(k + 4, pose=(0.0, 2.6, 0.0), walls=wall))  # there: nobody in sight, back to A
    assert r1.mode == "own_goal"


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-math.pi, math.pi)),
    st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-math.pi, math.pi)),
    st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-math.pi, math.pi)),
    st.tuples(st.floats(-20, 20), st.floats(-20, 20)),
)
def test_receive_path_maps_goals_through_mutual_bearings(start1, p1, p2, g):
    """§3.1: with exact bearings, R2's goal sent in R2's body frame lands where it is in R1's own
    (odometry) frame, for any two poses and any start frame of R1."""
    d = math.dist(p1[:2], p2[:2])
    if d < 0.05:
        return
    m = 3
    r1 = LosExplorer(LosExplorer.Params(), np.random.default_rng(0), info(0, m))
    odom1 = relative(np.array(start1), np.array(p1))  # R1's pose in its own frame
    _, b21 = polar(p1, p2, p1[2])
    _, b12 = polar(p2, p1, p2[2])
    g_in_2 = transform_points(relative(np.array(p2), np.zeros(3)), np.array(g))  # world -> R2 body
    r1.step(obs(0, pose=odom1, seen=[(1, d, b21)]))
    r1.step(obs(1, pose=odom1, seen=[(1, d, b21)], inbox=[
        msg(1, 0, sightings=[Sighting(0, b12, d)], goals=[GoalShare(1, goal_id(1, m), *g_in_2)])]))
    want = transform_points(relative(np.array(start1), np.zeros(3)), np.array(g))  # world -> R1 odom
    got = r1.sharing.goal_of(1)
    assert got is not None and got[0] == goal_id(1, m)
    np.testing.assert_allclose(got[1:], want, atol=1e-6)


@settings(max_examples=200, deadline=None)
@given(st.floats(-10, 10), st.floats(-10, 10), st.floats(0, 50))
def test_scalar_frame_equals_relative_frame_from_bearings(b21, b12, d):
    np.testing.assert_allclose(sender_frame(b21, b12, d), relative_frame_from_bearings(b21, b12, d), atol=1e-9)


@pytest.mark.parametrize("n", [0, 1, 3])
def test_message_size_formula_matches_message_size_bytes(n):
    body = LosHelpMsg(7, tuple(Sighting(i, 0.1, 2.0) for i in range(n)), tuple(GoalShare(i, 4, 1.0, 2.0) for i in range(n)),
                      tuple(VisReport(i, 4, 3.0) for i in range(n)), None if n == 1 else bool(n))
    assert message_size_bytes(body) == Message(0, 0.0, body, kind=MESSAGE_KIND).size_bytes()


def test_broadcast_shares_goals_relays_and_counts_bytes(straight_nav):
    m = 3
    r = LosHelper(LosHelper.Params(patrol_xy=[(1.0, 0.0), (5.0, 0.0)]), np.random.default_rng(0), info(2, m))
    seen = [(0, 2.0, math.pi / 2)]
    _, first = r.step(obs(0, seen=seen, robot_id=2))
    # robot 0 (2 m to the left, facing +x: it sees this robot at -90°) shares its goal 3 m to its right
    _, out = r.step(obs(1, seen=seen, robot_id=2, inbox=[
        msg(0, 0, sightings=[Sighting(2, -math.pi / 2, 2.0)], goals=[GoalShare(0, goal_id(1, m), 0.0, -3.0)])]))
    (message,) = out
    body = message.body
    assert body.sightings == (Sighting(0, math.pi / 2, 2.0),)
    by_owner = {g.owner: g for g in body.goals}
    assert by_owner[2].goal_id == goal_id(1, m) and by_owner[0].goal_id == goal_id(1, m) - 1
    assert (by_owner[0].gx_m, by_owner[0].gy_m) == pytest.approx((0.0, -1.0))  # in this robot's body frame
    # it sees robot 0's goal directly (1 m away) and reports D
    # (share_via: with the point its D leads through, here the goal itself in its body frame)
    (rep,) = body.reports
    assert (rep.owner, rep.goal_id, rep.d_m) == (0, goal_id(1, m), pytest.approx(1.0))
    assert (rep.via_x_m, rep.via_y_m, rep.via_d_m) == pytest.approx((0.0, -1.0, 0.0))
    log = r.log()
    assert log["msgs_sent"] == 2 and log["bytes_sent"] == first[0].size_bytes() + message.size_bytes()
    assert message.size_bytes() > first[0].size_bytes()  # one more goal, one report
    assert log["mode"] == "patrol" and log["known_goals"] == 1


def test_navigator_that_gives_up_is_started_afresh(monkeypatch):
    class GiveUp(StraightNav):
        def direction(self, pose, scan):
            return None

    made = []

    def make(*a, **k):
        made.append(GiveUp() if not made else StraightNav())
        return made[-1]

    monkeypatch.setattr(brain_mod, "make_navigator", make)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)]), np.random.default_rng(0), info(0, 1))
    wall = [(0.0, 0.3, 2.0)]
    a, _ = r1.step(obs(0, walls=wall))
    assert a.direction_rad is None and r1.log()["nav_restarts"] == 1 and r1.moves == 0
    a, _ = r1.step(obs(1, walls=wall))
    assert len(made) == 2 and a.direction_rad == pytest.approx(0.0) and r1.moves == 1
    stay = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], restart_navigator_on_give_up=False),
                       np.random.default_rng(0), info(0, 1))
    made.clear()
    stay.step(obs(0, walls=wall))
    stay.step(obs(1, walls=wall))
    assert len(made) == 1 and stay.moves == 0


def test_params_are_validated():
    with pytest.raises(ValidationError):
        LosExplorer.Params(targets=[(1, 2)])
    with pytest.raises(ValidationError):
        LosHelper.Params(navigator="a_star")
    with pytest.raises(ValueError, match="laser must name"):
        LosExplorer(LosExplorer.Params(laser="lidar"), np.random.default_rng(0), info())


def test_empty_targets_finish_at_once_and_stay():
    r = LosExplorer(LosExplorer.Params(), np.random.default_rng(0), info())
    a, out = r.step(obs(0))
    assert r.finished and a.direction_rad is None and out == []
    assert r.log()["mode"] == "done" and r.log()["moves"] == 0


# ---------------------------------------------------------------------------- end to end
@pytest.mark.parametrize("navigator", ["potential_field", "visbug21"])
def test_end_to_end_r1_reaches_a_target_seen_through_a_helper(navigator):
    """office_simple: R1 in the corridor, its target in room S2 out of its sight; a helper
    standing inside the room's door sees the target and R1: R1 heads to the helper (mirror),
    sees its target, reaches it, and the run stops early (``stop_when_finished``)."""
    pytest.importorskip("teamnav.control.nav.local")
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import Scenario

    # world frame: room S2 spans x 6.0-11.8, y 0.2-5.6; its door x 6.6-7.8 at y 5.6-5.8
    start1 = (6.4, 7.4, 0.0)
    target_world = (6.5, 1.0)  # hidden from the start by the wall west of the door
    helper_at = (7.5, 5.0, 0.0)
    target_own = (target_world[0] - start1[0], target_world[1] - start1[1])  # R1's frame: its start pose
    laser = {"kind": "laser", "n_beams": 360, "fov_deg": 360, "max_range_m": 8.0, "noise_std_m": 0.0}
    det = {"fov_deg": 360, "max_range_m": 8.0, "noise_model": "gaussian"}
    common = {"radius_m": 0.2, "kinematics": "holonomic_step", "step_length_m": 0.1, "sensors": [laser],
              "detector": det}
    scen = Scenario.model_validate({
        "name": "los-e2e", "map": {"builtin": "office_simple"}, "duration_s": 30.0, "dt_s": 0.1,
        "stop_when_finished": True, "metrics": [],
        "radio": {"mode": "line_of_sight", "range_m": 8.0},
        "robots": [
            {**common, "name": "r1", "controller": "los-explorer-v1", "start": {"poses": [start1]},
             "params": {"navigator": navigator, "targets_xy": [target_own], "goal_tolerance_m": 0.3}},
            {**common, "name": "helper", "controller": "los-helper-v1", "start": {"poses": [helper_at]},
             "params": {"navigator": navigator, "patrol_xy": []}},
        ],
    })
    data = run(scen, progress=False).data
    assert data.finished, "the run should stop once R1 reached its target"
    assert data.n_steps < 150  # of a 300-step budget
    r1_logs = [e["values"] for e in data.logs if e["robot"] == 0]
    modes = [v["mode"] for v in r1_logs]
    assert modes[2] == "follow_teammate" and modes[-1] == "done"
    assert "own_goal" in modes[modes.index("follow_teammate"):]  # then it sees the target itself
    assert r1_logs[-1]["targets_reached"] == 1 and r1_logs[-1]["msgs_sent"] > 0
    assert math.dist(data.true_pose[-1, 0, :2], target_world) < 0.3 + 1e-3
    assert data.true_pose[-1, 1, :2].tolist() == pytest.approx(helper_at[:2], abs=1e-5)  # never left its post


# ---------------------------------------------------------------------------- budget, slide, promise
def test_a_target_not_reached_within_its_step_budget_ends_the_task(straight_nav):
    p = LosExplorer.Params(targets_xy=[(1.0, 0.0), (100.0, 0.0)], goal_tolerance_m=0.3, max_steps_per_target=5)
    r1 = LosExplorer(p, np.random.default_rng(0), info(0, 1))
    for k in range(4):
        r1.step(obs(k))  # stuck at the start (the test does not move it)
    r1.step(obs(4, pose=(1.0, 0.0, 0.0)))  # first target reached at step 4: its budget starts again
    assert r1.target_index == 1 and not r1.finished
    for k in range(5, 9):
        a, _ = r1.step(obs(k, pose=(1.0, 0.0, 0.0)))
        assert not r1.gave_up and a.direction_rad is not None
    a, _ = r1.step(obs(9, pose=(1.0, 0.0, 0.0)))  # 5 steps on the second target: gives up
    assert r1.gave_up and r1.finished and r1.mode == "gave_up" and a.direction_rad is None
    log = r1.log()
    assert log["gave_up"] and log["finished"] and log["targets_reached"] == 1
    never = LosExplorer(LosExplorer.Params(targets_xy=[(100.0, 0.0)]), np.random.default_rng(0), info(0, 1))
    for k in range(50):
        never.step(obs(k))
    assert not never.finished  # no budget: never abandons


@pytest.mark.parametrize("slide", [True, False])
def test_a_seen_goal_behind_a_door_jamb_is_reached_by_sliding_not_by_a(straight_nav, slide):
    # the goal 4 m ahead is in sight (the beam towards it is free), but a jamb 1 m ahead,
    # 0.1 m to the left of the line, leaves no room for the robot's 0.2 m radius
    p = LosExplorer.Params(targets_xy=[(4.0, 0.0)], goal_tolerance_m=0.3, slide_when_blocked=slide)
    r1 = LosExplorer(p, np.random.default_rng(0), info(0, 1))
    a, _ = r1.step(obs(0, walls=[(0.1, 0.01, 1.0)]))
    assert r1.mode == "own_goal" and r1.sharing.path(0).kind == "direct"
    if slide:
        # the nearest free direction, on the side away from the jamb, within 90 degrees of the goal
        assert -math.pi / 2 <= a.direction_rad < -0.05 and r1.slide_steps == 1 and not straight_nav
    else:
        assert a.direction_rad == pytest.approx(0.0) and r1.slide_steps == 0 and straight_nav  # A decides


@pytest.mark.parametrize("d_m, promised", [(6.71, True), (9.0, False)])
def test_at_a_ghost_that_saw_the_goal_itself_r1_heads_for_the_goal(straight_nav, d_m, promised):
    goal = (6.0, 0.0)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal], goal_tolerance_m=0.3), np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.3, 2.0)]
    r2 = (0.0, 3.0)
    r1.step(obs(0, walls=wall, seen=[(1, *polar((0, 0), r2))]))
    # R2 at (0, 3) reports D for R1's goal: 6.71 m is the straight distance (it sees the goal), 9 m is not
    r1.step(obs(1, walls=wall, seen=[(1, *polar((0, 0), r2))], inbox=[
        msg(1, 0, sightings=[Sighting(0, -math.pi / 2, 3.0)], reports=[VisReport(0, 2, d_m)])]))
    # on the way to the ghost something hides it: A takes R1 there, as a temporary goal
    r1.step(obs(2, pose=(0.0, 1.5, 0.0), walls=[*wall, (math.pi / 2, 0.05, 0.8)]))
    (gx, gy), temporary = straight_nav[-1].calls[-1]
    assert r1.mode == "ghost" and temporary and (gx, gy) == (pytest.approx(0.0, abs=1e-9), pytest.approx(3.0))
    # at the ghost, R1's own scan does not show the goal (a return 1 m along its bearing)
    bearing = math.atan2(-2.95, 6.0)
    a, _ = r1.step(obs(3, pose=(0.0, 2.95, 0.0), walls=[(bearing, 0.01, 1.0)]))
    assert r1.mode == "own_goal" and r1.sharing.path(0).reached
    assert (r1.promised_steps == 1) is promised
    if not promised:  # explore again with A (§4.2), towards the task goal: A resumes it
        assert a.direction_rad == pytest.approx(bearing, abs=1e-9)
        assert straight_nav[-1].calls[-1] == ((6.0, 0.0), False)
    else:  # straight for the goal, sliding past what blocks the line
        assert a.direction_rad != pytest.approx(bearing, abs=1e-3) and abs(wrap_angle(a.direction_rad - bearing)) < math.pi / 2


def test_in_trouble_progress_is_towards_the_own_goal_so_following_away_keeps_following(monkeypatch):
    # §5 rule 1 ("progressing well towards the goal"): R1 follows R2 while that takes it away from
    # its goal, and is out of trouble only once following brings it nearer
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    cr = 3
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=cr, goal_sharing=False,
                                        trouble_progress="goal", trouble_helper_towards_goal=False),
                     np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.1, 0.5)]
    for k in range(cr):
        r1.step(obs(k, walls=wall))
    assert r1.trouble.tr
    x, k = 0.0, cr
    for _ in range(20):  # R2 walks away from the goal (-x), R1 after it: still in trouble
        r1.step(obs(k, pose=(x, 0.0, 0.0), walls=wall, seen=[(1, 2.0, math.pi)], inbox=[msg(1, k - 1, trouble=False)]))
        assert r1.mode == "trouble_follow" and r1.trouble.tr
        x -= 0.2
        k += 1
    for _ in range(3 * cr):  # R2 turns back towards R1's goal: R1 gets nearer and recovers
        r1.step(obs(k, pose=(x, 0.0, 0.0), walls=wall, seen=[(1, 2.0, 0.0)], inbox=[msg(1, k - 1, trouble=False)]))
        x += 0.2
        k += 1
        if not r1.trouble.tr:
            break
    assert not r1.trouble.tr and r1.trouble.nt == 2


@pytest.mark.parametrize("keep", [True, False])
def test_direct_view_is_kept_while_a_neighbouring_beam_still_reaches_the_goal(straight_nav, keep):
    """A goal seen through a door at a slant: acquired when the nearest beam reaches past it; one
    step later that beam hits the jamb but its neighbour still passes. With ``keep_direct_view``
    R1 keeps heading straight (own_goal with a direct path); without it, it drops to A."""
    goal = (4.0, 0.0)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal], keep_direct_view=keep), np.random.default_rng(0),
                     info(0, 2))
    gap = 2 * math.pi / N_BEAMS
    r1.step(obs(0))  # nothing in the way: seen (acquired)
    assert r1.sharing.path(0).kind == "direct"
    # the beam nearest the goal's bearing now hits a jamb 2 m away; the next one over is free
    jamb = [(0.0, 0.4 * gap, 2.0), (-gap, 0.4 * gap, 2.0)]
    r1.step(obs(1, walls=jamb))
    path = r1.sharing.path(0)
    assert (path is not None and path.kind == "direct") is keep
    # with every beam near the bearing blocked the view is lost either way
    r1.step(obs(2, walls=[(0.0, 2.0 * gap, 2.0)]))
    assert r1.sharing.path(0) is None


@pytest.mark.parametrize("rule", ["goal", "helper"])
def test_in_trouble_progress_towards_the_helper_is_fig_10s_reading(monkeypatch, rule):
    # §5, Fig. 10: "R_1 is now progressing towards its goal (by setting G_icurr = R_2)": with
    # trouble_progress="helper" closing in on a teammate that stands behind R1 (away from R1's
    # goal) is progress, so Pr falls to 0 in about Nt·Cr steps and R1 leaves it (Nt -> 2); with
    # "goal" the same steps take R1 away from its goal and it stays in trouble
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    cr = 3
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=cr, goal_sharing=False,
                                        trouble_progress=rule, trouble_helper_towards_goal=False),
                     np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.1, 0.5)]
    for k in range(cr):
        r1.step(obs(k, walls=wall))
    assert r1.trouble.tr
    x, k, out_at = 0.0, cr, None
    for i in range(2 * cr):  # R2 stands at x = -4, R1 walks to it, away from its goal at +6
        r1.step(obs(k, pose=(x, 0.0, 0.0), walls=wall, seen=[(1, 4.0 + x, math.pi)],
                    inbox=[msg(1, k - 1, trouble=False)]))
        if out_at is None and r1.trouble.tr:
            assert r1.mode == "trouble_follow"
        elif out_at is None:
            out_at = i
        x -= 0.2
        k += 1
    if rule == "helper":
        assert out_at is not None and out_at <= cr + 1 and r1.trouble.nt == 2
    else:
        assert out_at is None and r1.trouble.tr and r1.trouble.nt == 1


@pytest.mark.parametrize("towards", [True, False])
def test_in_trouble_a_teammate_walking_away_from_the_goal_is_let_go(monkeypatch, towards):
    # trouble_helper_towards_goal (gap-fill of §5 rule 3): stuck R1 (goal at +x) sees R2 walk
    # away from its goal (-x): followed at first sight, let go once R2 is trouble_recede_m
    # farther from the goal than its nearest while followed, and not taken again while it
    # recedes (the paper's rule follows it all along); R2 turns back: followed again
    stuck = StraightNav(stuck=True)
    monkeypatch.setattr(brain_mod, "make_navigator", lambda *a, **k: stuck)
    cr, recede = 3, 1.0
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], trouble_cr=cr, goal_sharing=False,
                                        trouble_helper_towards_goal=towards, trouble_recede_m=recede,
                                        trouble_heading_steps=3, keep_trouble_helper=False,
                                        trouble_progress="goal"),  # R1 stands still: stays in trouble
                     np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.1, 0.5)]
    for k in range(cr):
        r1.step(obs(k, walls=wall))
    assert r1.trouble.tr
    k = cr

    def see(x2):  # R2 at (x2, 3) seen from R1 standing at the origin
        nonlocal k
        r, b = polar((0.0, 0.0), (x2, 3.0))
        r1.step(obs(k, walls=wall, seen=[(1, r, b)], inbox=[msg(1, k - 1, trouble=False)]))
        k += 1
        return r1.mode

    xs = [-0.2 * i for i in range(12)]
    away = [see(x) for x in xs]
    back = [see(-2.2 + 0.2 * i) for i in range(8)]
    if not towards:
        assert set(away) == {"trouble_follow"} and set(back) == {"trouble_follow"}
        return
    off = away.index("own_goal")
    assert set(away[:off]) == {"trouble_follow"} and set(away[off:]) == {"own_goal"}
    d = [math.hypot(6.0 - x, 3.0) for x in xs]
    assert d[off] - d[0] > recede >= d[off - 1] - d[0]  # let go just past the hysteresis
    assert back[0] == "own_goal" and set(back[1:]) == {"trouble_follow"}  # turned back: followed


@pytest.mark.parametrize("navigator, factor, want", [
    ("visbug21", 3.0, {"reverse_walk_factor": 3.0}), ("visbug21", None, {}), ("straight", 3.0, {})])
def test_at_a_ghost_visbug_starts_again_with_the_explorers_reverse_walk_factor(monkeypatch, navigator, factor, want):
    # visbug_reverse_walk_factor: at a ghost reached without the goal in sight (§4.2, A starts
    # again), VisBug's boundary walks to this goal alternate; other navigators start as before
    class Restartable(StraightNav):
        def start_again(self, **kw):
            self.restarts.append(kw)

    def make(name, params, *, rng, step_length_m, radius_m):
        nav = Restartable()
        nav.restarts = []
        made.append(nav)
        return nav

    made = []
    monkeypatch.setattr(brain_mod, "make_navigator", make)
    nav_name = "visbug21" if navigator == "visbug21" else "avoid_past"
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(6.0, 0.0)], goal_tolerance_m=0.3, navigator=nav_name,
                                        visbug_reverse_walk_factor=factor), np.random.default_rng(0), info(0, 2))
    wall = [(0.0, 0.3, 2.0)]
    r2 = (0.0, 3.0)
    r1.step(obs(0, walls=wall, seen=[(1, *polar((0, 0), r2))]))
    r1.step(obs(1, walls=wall, seen=[(1, *polar((0, 0), r2))], inbox=[
        msg(1, 0, sightings=[Sighting(0, -math.pi / 2, 3.0)], reports=[VisReport(0, 2, 9.0)])]))
    r1.step(obs(2, pose=(0.0, 1.0, 0.0), walls=wall))
    r1.step(obs(3, pose=(0.0, 2.95, 0.0), walls=[(math.atan2(-2.95, 6.0), 0.2, 1.0)]))
    assert r1.sharing.path(0).reached and made[0].restarts == [want]


@pytest.mark.parametrize("see_past", [True, False])
def test_a_teammate_between_r1_and_its_goal_does_not_hide_the_goal(straight_nav, see_past):
    """R2 stands 2 m ahead of R1 on the line to R1's goal 5 m ahead; R1's laser reads R2's body
    (0.2 m radius) there. With ``see_past_teammates`` R1 sees its goal past the teammate it
    detects (the paper's V(R) is bounded by the environment, §2); without it R2 hides it."""
    goal = (5.0, 0.0)
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[goal], see_past_teammates=see_past), np.random.default_rng(0),
                     info(0, 2))
    body = [(0.0, math.atan(0.2 / 1.8), 1.8)]
    r1.step(obs(0, walls=body, seen=[(1, 2.0, 0.0)]))
    path = r1.sharing.path(0)
    assert (path is not None and path.kind == "direct") is see_past
    # an undetected body (no identity, or out of the detector's sight) still occludes
    r1b = LosExplorer(LosExplorer.Params(targets_xy=[goal], see_past_teammates=True), np.random.default_rng(0),
                      info(0, 2))
    r1b.step(obs(0, walls=body))
    assert r1b.sharing.path(0) is None
    # beside the body, inside the widened sector (bearing and range noise), a beam that passes
    # the teammate and ends on a far wall keeps its reading (reach 1.7 d + 2 radius): a goal
    # 0.2 rad off R2's bearing, 7.8 m away behind a wall at 7.5 m, stays hidden
    off = (7.8 * math.cos(0.2), 7.8 * math.sin(0.2))
    r1c = LosExplorer(LosExplorer.Params(targets_xy=[off], see_past_teammates=True), np.random.default_rng(0),
                      info(0, 2))
    wall = [(0.0, 0.5, 7.5)]
    r1c.step(obs(0, walls=wall + body, seen=[(1, 2.0, 0.0)]))
    assert r1c.sharing.path(0) is None
    r1c.step(obs(1, walls=body, seen=[(1, 2.0, 0.0)]))  # without the wall it is seen
    assert r1c.sharing.path(0) is not None and r1c.sharing.path(0).kind == "direct"
    # straight behind the body the laser knows nothing: the body's beams read what its flanks
    # read, so the wall seen past both flanks hides a goal right behind R2 too
    r1d = LosExplorer(LosExplorer.Params(targets_xy=[(7.8, 0.0)], see_past_teammates=True), np.random.default_rng(0),
                      info(0, 2))
    r1d.step(obs(0, walls=wall + body, seen=[(1, 2.0, 0.0)]))
    assert r1d.sharing.path(0) is None


@settings(max_examples=200, deadline=None)
@given(d=st.floats(0.5, 7.0), b=st.floats(-math.pi, math.pi), err=st.floats(-0.4, 0.4), berr=st.floats(-1.0, 1.0))
def test_see_past_teammates_frees_every_beam_on_the_body_under_eq_1_2_noise(d, b, err, berr):
    """Whatever the detector's eq. 1-2 noise (range error up to 0.4 d_r, bearing error up to
    atan(radius / d_r)), every beam that the true body (radius 0.2 m at range d, bearing b)
    blocks reads what the beams beside it read (a room 6 m deep here), and beams far outside
    the body's sector keep their reading."""
    radius = 0.2
    half_true = math.asin(min(1.0, radius / d))
    r = np.full(N_BEAMS, 6.0)
    on_body = np.abs(wrap_angle(ANGLES - b)) <= half_true
    r[on_body] = d - radius
    d_p = d + d * err
    b_p = float(wrap_angle(b + math.atan(radius / d) * berr))
    out = see_past_teammates(r, ANGLES, MAX_RANGE, np.array([d_p]), np.array([b_p]), radius)
    assert np.all(out[on_body] == 6.0)
    far = np.abs(wrap_angle(ANGLES - b)) > 2.0 * math.atan(1.5 * radius / d_p) + 2.0 * math.atan(radius / d) + 1e-9
    assert np.all(out[far] == r[far])
    assert np.all(r[~on_body] == 6.0)  # the input is not modified


@pytest.mark.parametrize("beyond, dist, read_past", [(None, 3.0, False), (1.0, 3.0, True), (1.0, 0.8, False)])
def test_navigator_scan_reads_past_teammates_beyond_the_set_distance(straight_nav, monkeypatch, beyond, dist,
                                                                     read_past):
    """``navigate_past_teammates_beyond_m``: A's scan reads past a teammate detected farther than
    the distance (its body's beams read what the beams beside it read); a nearer one, or any with
    the default None, stays an obstacle in A's scan."""
    r1 = LosExplorer(LosExplorer.Params(targets_xy=[(0.0, 6.0)], navigate_past_teammates_beyond_m=beyond,
                                        straight_when_visible=False),
                     np.random.default_rng(0), info(0, 2))
    seen_scans = []
    real = StraightNav.direction

    def spy(self, pose, scan):
        seen_scans.append(scan)
        return real(self, pose, scan)

    monkeypatch.setattr(StraightNav, "direction", spy)
    body = [(0.0, math.atan(0.2 / (dist - 0.2)), dist - 0.2)]
    r1.step(obs(0, walls=body, seen=[(1, dist, 0.0)]))
    assert seen_scans, "the navigator was not asked for a heading"
    ahead = seen_scans[-1].ranges_m[np.argmin(np.abs(ANGLES))]
    assert bool(ahead == MAX_RANGE) is read_past
    assert read_past or ahead == pytest.approx(dist - 0.2)
