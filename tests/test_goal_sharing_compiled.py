"""Compiled goal sharing (``papers/los_help/brains/goal_sharing_compiled.py``) is the reference's,
bit for bit (Sgorbissa & Arkin §3-§4; ``docs/concepts/group-brains.md``).

The recorder runs a 4-robot team (R1 explorer, helpers R2..R4) of the reference brains and
captures, for every robot and step, what its goal sharing receives at its seam with the brain:

- inputs: the step, the odometry pose, the sightings (id → range, bearing), the call of
  ``set_own_goal`` made by the robot's task this step, the inbox (the delivered
  :class:`LosHelpMsg` and their senders), the scan of its visibility tests (``_vis_r64``), and
  what the brain's decision did to it (``mark_reached``, ``go_via`` with its answer), and the
  Tr bit sent;
- outputs: the known goals and the stored paths (every field, in dict order) after ``refresh``
  and after the step, the outgoing message (packed), ``msgs_received``, and the teammates'
  Tr bits of §5 with where each sender stood (``_teammate_tr``, ``_teammate_tr_xy``), which
  the receive path also yields.

Two replays of those inputs must give the same outputs: the reference's own goal sharing
(``GoalSharing`` with the brain's ``_receive`` / ``_broadcast``: this checks that the capture is
complete), and the compiled kernels, all robots of the team in one call per phase. Floats are
compared by their bits. Nothing is stored on disk: the capture runs in the test.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav import load_scenario
from teamnav.experiments.spec import build_grid
from teamnav.papers.los_help.brains import goal_sharing_compiled as GC
from teamnav.papers.los_help.brains.brain import _LosBrain
from teamnav.papers.los_help.brains.goal_sharing import GoalSharing, sender_frame
from teamnav.papers.los_help.brains.messages import LosHelpMsg
from teamnav.papers.los_help.brains.packed import pack, row_width
from teamnav.papers.los_help.tasks import task_targets_xy, team_overrides
from teamnav.sim.engine import Simulation

STEPS = 1500
M = 4  # owner slots: R1..R4 are robots 0..3


def _scenario(task: int, paper: bool, **extra):
    """The full team R1..R4 on office_simple, one tuning task's targets; ``paper``: every robot
    with ``paper_rules: true`` (the report's paper column)."""
    ov = dict(team_overrides("simple", 3))
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", task)
    if paper:
        for k in range(4):
            ov[f"robots.{k}.params.paper_rules"] = True
    ov.update(extra)
    return load_scenario("los-help-simple", overrides=ov, duration_s=STEPS * 0.1, seed=0)


# ----------------------------------------------------------------- the recorder
class _RecordingSharing(GoalSharing):
    """The reference's GoalSharing, noting what the brain does to it (the class of a brain's
    ``sharing`` is swapped for this one after construction)."""

    def set_own_goal(self, k, goal_xy=None):
        self.rec_own = (k, None if goal_xy is None else (float(goal_xy[0]), float(goal_xy[1])))
        super().set_own_goal(k, goal_xy)

    def refresh(self, *args, **kwargs):
        super().refresh(*args, **kwargs)
        self.rec_after_refresh = _snapshot(self)

    def mark_reached(self, owner):
        self.rec_events.append(("mark", int(owner)))
        super().mark_reached(owner)

    def go_via(self, owner, step):
        res = super().go_via(owner, step)
        self.rec_events.append(("via", int(owner), int(step), bool(res)))
        return res


def _snapshot(gs: GoalSharing):
    """Known goals and paths in dict order, every field (paths as ``GC.path_columns``)."""
    known = [(g.owner, g.goal_id, g.gx_m, g.gy_m) for g in gs.known.values()]
    paths = [(o, GC.path_columns(p)) for o, p in gs.paths.items()]
    own = None if gs.own_k is None else (gs.own_k, *gs.own_goal)
    return known, paths, own


def record(scn, steps: int = STEPS):
    """Run the reference team ``steps`` steps; returns (per-robot setup, per-step records)."""
    sim = Simulation(build_grid(scn), scn)
    brains = [b for grp in sim.brains for b in grp]
    assert [b.me for b in brains] == list(range(len(brains))) and len(brains) == M
    setup = []
    for b in brains:
        gs = b.sharing
        gs.__class__ = _RecordingSharing
        setup.append(dict(params=b.params, me=b.me, team_size=b.team_size, radius=b.radius_m, step_m=b.step_m,
                          vis_r=b.vis_radius_m, own=None if gs.own_k is None else (gs.own_k, gs.own_goal)))
    frames: list[list[dict]] = []
    current: list[dict] = []

    def wrap(b):
        orig = b.step

        def step(obs):
            gs = b.sharing
            gs.rec_own, gs.rec_events, gs.rec_after_refresh = None, [], None
            inbox = [m for m in obs.inbox if isinstance(m.body, LosHelpMsg)]
            dets = [(-1 if d.robot_id is None else int(d.robot_id), float(d.range_m), float(d.bearing_rad))
                    for d in obs.detections]
            ranges = np.array(obs.scans[b.params.laser].ranges_m, dtype=np.float64)
            max_range = float(obs.scans[b.params.laser].max_range_m)
            action, outbox = orig(obs)
            k = int(obs.step)
            body = outbox[0].body if outbox else None
            current.append(dict(
                me=b.me, dets=dets, see_past=bool(b.params.see_past_teammates), radius=b.radius_m, ranges=ranges, max_range=max_range, step=k, time_s=float(obs.time_s), pose=(b._px, b._py, b._th), sight=dict(b._history[k][1]),
                own=gs.rec_own, inbox=inbox, vis=b._vis_r64.copy(), angles=b._a64, gap=b._gap_rad,
                events=list(gs.rec_events), after_refresh=gs.rec_after_refresh, after=_snapshot(gs), out=body,
                msgs_received=b.msgs_received, tr=dict(b._teammate_tr), tr_xy=dict(b._teammate_tr_xy)))
            return action, outbox

        b.step = step

    for b in brains:
        wrap(b)
    for _ in range(steps):
        sim.step()
    by_step: dict[int, list[dict]] = {}
    for f in current:
        by_step.setdefault(f["step"], []).append(f)
    for k in sorted(by_step):
        frame = sorted(by_step[k], key=lambda f: f["me"])  # robot order
        assert [f["me"] for f in frame] == list(range(M)), k
        frames.append(frame)
    return setup, frames


# ----------------------------------------------------------------- replay 1: the reference's own goal sharing
class _RefReplay:
    """The reference's goal-sharing part of a brain's step (``_LosBrain``'s own methods), fed the
    captured inputs: what the compiled kernels stand for, and the timing peer."""

    _receive = _LosBrain._receive
    _bearing_frame = _LosBrain._bearing_frame
    _body_to_odom = _LosBrain._body_to_odom
    _broadcast = _LosBrain._broadcast
    _sees = _LosBrain._sees
    _keeps = _LosBrain._keeps
    _set_pose = _LosBrain._set_pose
    _me_xy = _LosBrain._me_xy

    def __init__(self, s: dict) -> None:
        p = s["params"]
        self.params, self.me, self.team_size = p, s["me"], s["team_size"]
        self.vis_radius_m, self.radius_m = s["vis_r"], s["radius"]
        self.sharing = GoalSharing(self.me, self.team_size, delayed=p.delayed_visibility,
                                   point_margin_m=2.5 * self.radius_m,
                                   report_margin_m=p.report_margin_steps * s["step_m"], lead_on=p.lead_on,
                                   relay_hop_limit=p.relay_hop_limit)
        if s["own"] is not None:
            self.sharing.set_own_goal(*s["own"])
        self._history = {}
        self._prev_xy = None
        self._scan = True
        self.msgs_received = self.msgs_sent = self.bytes_sent = 0
        self.trouble = SimpleNamespace(tr=False)

    def step(self, f: dict, snap: bool = True):
        p = self.params
        k = f["step"]
        self._set_pose(np.array(f["pose"]))
        self._vis_r64, self._a64, self._gap_rad = f["vis"], f["angles"], f["gap"]
        sightings = f["sight"]
        self._history[k] = ((self._px, self._py, self._th), sightings)
        for old in [j for j in self._history if j <= k - 4]:
            del self._history[old]
        gs = self.sharing
        if p.goal_sharing:
            gs.begin_step()
        if f["own"] is not None:
            gs.set_own_goal(*f["own"])
        self._receive(SimpleNamespace(inbox=f["inbox"]))
        me = self._me_xy()
        if p.goal_sharing:
            gs.refresh(me, self._prev_xy, self._sees, k, keeps=self._keeps if p.keep_direct_view else None)
        after_refresh = _snapshot(gs) if snap and p.goal_sharing else None
        vias = []
        for e in f["events"]:
            if e[0] == "mark":
                gs.mark_reached(e[1])
            else:
                vias.append(gs.go_via(e[1], e[2]))
        if f["out"] is not None and f["out"].trouble is not None:
            self.trouble.tr = f["out"].trouble
        out = self._broadcast(SimpleNamespace(step=k, time_s=f["time_s"]), sightings)
        self._prev_xy = me
        return after_refresh, vias, out


# ----------------------------------------------------------------- replay 2: the compiled kernels
def _bits(a) -> bytes:
    a = np.array(a, dtype=np.float64)
    return np.where(np.isnan(a), np.nan, a).tobytes()  # one NaN; -0.0 and 0.0 stay apart


def _same_snapshot(ga: GC.GoalSharingArrays, r: int, snap, where: str) -> None:
    known, paths, own = snap
    assert ga.known_goals(r) == known, f"known goals differ: {where}"
    assert _bits([k[2:] for k in ga.known_goals(r)]) == _bits([k[2:] for k in known]), where
    got = ga.path_rows(r)
    assert [o for o, _ in got] == [o for o, _ in paths], f"paths (owners, dict order) differ: {where}"
    for (o, a), (_, b) in zip(got, paths):
        assert _bits(a) == _bits(b), f"path to R{o + 1}'s goal differs: {where}: {a} vs {b}"
    assert ga.own_goal(r) == own, where


def _same_sensing(frame: list[dict], sight: np.ndarray, vis: np.ndarray) -> bool:
    """``GC.team_sightings`` from the step's raw detections and scan gives the brains' sightings
    and visibility scans (``_vis_r64``: with ``see_past_teammates``, the beams on teammates
    filled in)."""
    n = len(frame)
    k = max(1, max(len(f["dets"]) for f in frame))
    count = np.array([len(f["dets"]) for f in frame], dtype=np.int64)
    ids = np.full((n, k), -1, dtype=np.int64)
    rng, brg = np.full((n, k), np.nan), np.full((n, k), np.nan)
    for r, f in enumerate(frame):
        for j, (rid, rr, bb) in enumerate(f["dets"]):
            ids[r, j], rng[r, j], brg[r, j] = rid, rr, bb
    got_sight, got_vis = np.empty_like(sight), np.empty_like(vis)
    see_past = np.array([f["see_past"] for f in frame])
    radius = np.array([f["radius"] for f in frame])
    GC.team_sightings(np.arange(n, dtype=np.int64), count, ids, rng, brg, np.array([f["ranges"] for f in frame]),
                      np.ascontiguousarray(frame[0]["angles"]), frame[0]["max_range"], radius, see_past, got_sight,
                      got_vis)
    assert _bits(got_sight) == _bits(sight), f"sightings differ at step {frame[0]['step']}"
    assert _bits(got_vis) == _bits(vis), f"visibility scans differ at step {frame[0]['step']}"
    return True


def _inputs(frame: list[dict], width: int):
    n = len(frame)
    pose = np.array([f["pose"] for f in frame])
    sight = np.full((n, M, 2), np.nan)
    for r, f in enumerate(frame):
        for rid, (rng_m, b) in f["sight"].items():
            sight[r, rid] = rng_m, b
    own_set = np.array([f["own"] is not None for f in frame], dtype=np.int64)
    own_k = np.array([-1 if f["own"] is None or f["own"][0] is None else f["own"][0] for f in frame],
                     dtype=np.int64)
    own_xy = np.array([(0.0, 0.0) if f["own"] is None or f["own"][1] is None else f["own"][1] for f in frame])
    rows, senders, start = [], [], [0]
    for f in frame:
        for m in f["inbox"]:
            rows.append(pack(m.body, M))
            senders.append(m.sender)
        start.append(len(rows))
    in_rows = np.array(rows).reshape(-1, width)
    vis = np.array([f["vis"] for f in frame])
    assert _same_sensing(frame, sight, vis)
    trouble = np.array([-1.0 if f["out"] is None or f["out"].trouble is None else float(f["out"].trouble)
                        for f in frame])
    return (pose, sight, own_set, own_k, own_xy, in_rows, np.array(senders, dtype=np.int64),
            np.array(start, dtype=np.int64), vis, trouble)


def compiled_setup(setup, frames) -> tuple[GC.GoalSharingArrays, np.ndarray]:
    """The compiled state of the recorded team, with the brains' goals at construction, and the beam angles."""
    f0 = frames[0]
    ga = GC.GoalSharingArrays([s["params"] for s in setup], [s["me"] for s in setup],
                              [s["team_size"] for s in setup], [s["radius"] for s in setup],
                              [s["step_m"] for s in setup], [s["vis_r"] for s in setup], [f["gap"] for f in f0], M)
    angles = np.ascontiguousarray(f0[0]["angles"])
    for f in f0:
        assert np.array_equal(f["angles"], angles)
    for r, s in enumerate(setup):
        if s["own"] is not None:
            ga.set_own_goal(r, *s["own"])
    return ga, angles


def compiled_inputs(frames) -> list[tuple]:
    """Each step's inputs as the kernels take them (the inbox as stacked packed rows)."""
    width = row_width(M)
    return [(frame[0]["step"], *_inputs(frame, width), [f["events"] for f in frame]) for frame in frames]


def compiled_replay(setup, frames, check: bool = True, inputs=None) -> GC.GoalSharingArrays:
    """Replay the captured inputs through the compiled kernels; with ``check``, demand the
    reference's outputs at every step and robot."""
    ga, angles = compiled_setup(setup, frames)
    if inputs is None:
        inputs = compiled_inputs(frames)
    for frame, (k, pose, sight, own_set, own_k, own_xy, in_rows, senders, start, vis, trouble, events) in zip(
            frames, inputs):
        ga.begin_step(k, pose, sight, own_set, own_k, own_xy, in_rows, senders, start, vis, angles)
        for r, ev in enumerate(events):
            f = frame[r]
            if check and f["after_refresh"] is not None:
                _same_snapshot(ga, r, f["after_refresh"], f"step {k}, R{r + 1}, after refresh")
            for e in ev:
                if e[0] == "mark":
                    GC.gs_mark_reached(ga.paths, r, e[1])
                else:
                    got = GC.gs_go_via(ga.paths, r, e[1], e[2])
                    assert not check or got == e[3], f"go_via differs: step {k}, R{r + 1}"
        sent = ga.end_step(k, pose, sight, trouble)
        if not check:
            continue
        for r, f in enumerate(frame):
            where = f"step {k}, R{r + 1}"
            _same_snapshot(ga, r, f["after"], where + ", after the step")
            assert int(ga.gist[r, GC.I_MSGS_RECEIVED]) == f["msgs_received"], where
            assert ga.teammate_tr(r) == f["tr"], f"Tr bits differ: {where}"
            got_xy = ga.teammate_tr_xy(r)
            assert list(got_xy) == list(f["tr_xy"]), f"Tr senders differ: {where}"
            assert _bits(list(got_xy.values())) == _bits(list(f["tr_xy"].values())), f"Tr positions differ: {where}"
            assert bool(sent[r]) == (f["out"] is not None), f"sent differs: {where}"
            if f["out"] is not None:
                assert _bits(ga.out[r]) == _bits(pack(f["out"], M)), f"message differs: {where}"
    return ga


def reference_replay(setup, frames, check: bool = True) -> None:
    reps = [_RefReplay(s) for s in setup]
    for frame in frames:
        for r, f in enumerate(frame):
            after_refresh, vias, out = reps[r].step(f, check)
            if not check:
                continue
            where = f"step {f['step']}, R{r + 1}"
            assert _bits_snap(after_refresh) == _bits_snap(f["after_refresh"]), where
            assert _bits_snap(_snapshot(reps[r].sharing)) == _bits_snap(f["after"]), where
            assert vias == [e[3] for e in f["events"] if e[0] == "via"], where
            assert bool(out) == (f["out"] is not None), where
            if out:
                assert _bits(pack(out[0].body, M)) == _bits(pack(f["out"], M)), where
            assert reps[r].msgs_received == f["msgs_received"], where
            assert reps[r]._teammate_tr == f["tr"] and reps[r]._teammate_tr_xy == f["tr_xy"], where


def _bits_snap(snap):
    if snap is None:
        return None
    known, paths, own = snap
    return known, [(o, _bits(p)) for o, p in paths], own


# ----------------------------------------------------------------- the tests
@pytest.fixture(scope="module")
def captures():
    cache: dict = {}

    def get(task: int, paper: bool):
        if (task, paper) not in cache:
            cache[(task, paper)] = record(_scenario(task, paper))
        return cache[(task, paper)]

    return get


def _coverage(frames) -> dict[str, int]:
    """What the run reached (so that the identity is not trivially about empty memories)."""
    kinds = {"direct": 0, "self": 0, "ghost": 0}
    c = {"msgs": 0, "relayed": 0, "reports": 0, "marks": 0, "vias": 0, **kinds}
    for frame in frames:
        for f in frame:
            c["msgs"] += len(f["inbox"])
            if f["out"] is not None:
                c["relayed"] += sum(1 for g in f["out"].goals if g.owner != f["out"].goals[0].owner)
                c["reports"] += len(f["out"].reports)
            for _o, p in f["after"][1]:
                c[GC.KINDS[int(p[GC.P_KIND])]] += 1
            c["marks"] += sum(1 for e in f["events"] if e[0] == "mark")
            c["vias"] += sum(1 for e in f["events"] if e[0] == "via" and e[3])
    return c


@pytest.mark.parametrize("paper", [False, True], ids=["teamnav", "paper"])
@pytest.mark.parametrize("task", [1001, 1002])
def test_compiled_goal_sharing_is_the_reference_bit_for_bit(captures, task, paper):
    setup, frames = captures(task, paper)
    c = _coverage(frames)
    assert c["msgs"] > 500 and c["reports"] > 100 and c["relayed"] > 100, c
    assert c["direct"] > 0 and c["self"] > 0 and c["ghost"] > 0, c
    reference_replay(setup, frames)  # the capture holds every input
    compiled_replay(setup, frames)


def test_reflected_visibility_and_state_sharing(captures):
    """V_R only (``delayed_visibility`` false, §3: non-direct points forgotten each step) with the
    Tr bit of §5 in the messages."""
    scn = _scenario(1003, False, **{f"robots.{k}.params.{f}": v for k in range(4)
                                    for f, v in (("delayed_visibility", False), ("state_sharing", True))})
    setup, frames = record(scn, 800)
    assert sum(f["out"] is not None and f["out"].trouble is not None for fr in frames for f in fr) > 100
    assert sum(len(f["tr_xy"]) for fr in frames for f in fr) > 100
    reference_replay(setup, frames)
    compiled_replay(setup, frames)


# ----------------------------------------------------------------- the rules alone, on random sequences
_angle = st.floats(-7.0, 7.0, allow_nan=False)


@given(_angle, _angle, st.floats(0.0, 20.0, allow_nan=False))
def test_sender_frame_kernel_is_the_reference(b1, b2, d):
    """§3.1's frame from mutual bearings, θ21 = 180° + α21 − α12, the same bits."""
    assert _bits(GC._sender_frame(b1, b2, d)) == _bits(sender_frame(b1, b2, d))


_coord = st.sampled_from([-2.0, -0.5, 0.0, 0.3, 0.5, 1.0, 1.7, 2.0, 3.0])  # few values: ties and equal points
_owner = st.sampled_from([0, 0, 0, 1, 2, 3])  # the robot's own goal (0) most often: lead_on, go_via
_report = st.tuples(st.just("report"), _owner, st.sampled_from([1, 2, 2, 3, 5]), st.integers(1, 3), _coord, _coord,
                    st.sampled_from([0.0, 0.5, 1.0, 2.5, 0.5, 1.0, 2.0, -1.0, math.inf, math.nan]), _coord, _coord,
                    st.one_of(st.none(), st.tuples(_coord, _coord, st.sampled_from([0.0, 1.0, 2.0, math.inf]))))
_op = st.one_of(
    st.tuples(st.just("goal"), _owner, st.integers(1, 6), _coord, _coord),
    _report, _report, _report,
    st.tuples(st.just("mark"), _owner),
    st.tuples(st.just("via"), _owner, st.integers(0, 50)),
    st.tuples(st.just("own"), st.sampled_from([None, 1, 1, 1, 2]), _coord, _coord),
)


@settings(max_examples=500, deadline=None)
@given(st.lists(_op, min_size=5, max_size=40), st.booleans(), st.sampled_from([0.0, 0.2, 0.5]), st.integers(2, 3))
def test_rules_on_random_sequences_are_the_reference(ops, lead_on, margin, team):
    """The Id rule (§3.1, §4.1), D arbitration with the report margin and ``lead_on`` (§4.2),
    ``mark_reached`` and ``go_via`` on random sequences with ties, against ``GoalSharing``."""
    me = 0
    ref = GoalSharing(me, team, report_margin_m=margin, lead_on=lead_on)
    p = SimpleNamespace(frame_source="bearings", goal_sharing=True, delayed_visibility=True,
                        report_margin_steps=margin, lead_on=lead_on, relay_hop_limit=True, share_via=True,
                        keep_direct_view=False, state_sharing=False)
    ga = GC.GoalSharingArrays([p], [me], [team], [0.2], [1.0], [8.0], [0.1], M)
    start = [("own", 1, 1.0, 2.0)] + [("goal", o, team, 0.5 * o, -1.0) for o in (1, 2, 3)]  # goals to report on
    for op in start + ops:
        if op[0] == "goal":
            _, o, gid, x, y = op
            assert GC._receive_goal(ga.gpar, ga.gist, ga.known, ga.kord, ga.paths, 0, o, gid, x, y) == \
                ref.receive_goal(o, gid, (x, y))
        elif op[0] == "report":
            _, o, gid, rep, rx, ry, d, mx, my, via = op
            vx, vy, vd = via if via is not None else (math.nan, math.nan, math.nan)
            got = GC._receive_report(ga.gpar, ga.gist, ga.known, ga.paths, 0, o, gid, rep, rx, ry, d, mx, my, 7, vx,
                                     vy, vd)
            assert got == ref.receive_report(o, gid, rep, (rx, ry), d, me_xy=(mx, my), step=7,
                                             via_xy=None if via is None else via[:2],
                                             via_d_m=None if via is None else via[2])
        elif op[0] == "mark":
            GC.gs_mark_reached(ga.paths, 0, op[1])
            ref.mark_reached(op[1])
        elif op[0] == "via":
            assert GC.gs_go_via(ga.paths, 0, op[1], op[2]) == ref.go_via(op[1], op[2])
        else:
            _, k, x, y = op
            ga.set_own_goal(0, k, (x, y))
            ref.set_own_goal(k, (x, y))
        _same_snapshot(ga, 0, _snapshot(ref), str(op))


# ----------------------------------------------------------------- the helpers compiled, in the engine
def _same_log(la: dict, lb: dict, where: str) -> None:
    layers_a, layers_b = la.pop("layers", None), lb.pop("layers", None)
    assert la == lb, f"logs differ: {where}: {la} vs {lb}"
    assert list(la) == list(lb), where
    assert (layers_a is None) == (layers_b is None), where
    if layers_a is not None:
        for name in layers_a:
            assert _bits(layers_a[name]["data"]) == _bits(layers_b[name]["data"]), (name, where)


def side_by_side(scn, steps: int):
    """The reference R1..R4 and the same run with the team's group brain (R1, with state sharing
    or VisBug-21, runs its per-robot brain inside it), step by step: true poses, odometry, commands, every robot's
    log and the radio's totals must be equal."""
    ref = Simulation(build_grid(scn), scn)
    grp = Simulation(build_grid(scn), scn, group_brains=True)
    assert len(grp.group_teams) == 1 and grp.group_teams[0][1:3] == (0, 4), "the team's group brain must run R1..R4"
    brains_ref = [b for g in ref.brains for b in g]
    brains_grp = [b for g in grp.brains for b in g]
    for k in range(steps):
        ref.step()
        grp.step()
        where = f"step {ref.step_index}"
        assert np.array_equal(ref.state.poses(), grp.state.poses()), f"true poses differ at {where}"
        assert np.array_equal(ref.odometry.pose, grp.odometry.pose), f"odometry differs at {where}"
        assert np.array_equal(ref._dir_cmd, grp._dir_cmd, equal_nan=True), f"commands differ at {where}"
        for i, (a, b) in enumerate(zip(brains_ref, brains_grp)):
            _same_log(a.log(), b.log(), f"{where}, R{i + 1}")
    return brains_ref, brains_grp


_SHARING = {
    "state-only": {"goal_sharing": False, "state_sharing": True},  # §5 alone: messages carry only Tr
    "reflected": {"delayed_visibility": False, "state_sharing": True},  # V_R (§3) with §5
}


@pytest.mark.parametrize("paper,task,navigator,sharing", [
    (False, 1001, None, None), (True, 1001, None, None), (False, 1002, "avoid_past", None),
    (True, 1002, "potential_field", None), (False, 1003, None, "state-only"), (True, 1003, None, "reflected")],
    ids=["teamnav", "paper", "teamnav-avoid_past", "paper-potential_field", "teamnav-state-only", "paper-reflected"])
def test_helpers_group_brain_runs_the_reference_team(paper, task, navigator, sharing):
    """R1..R4 in the team's group brain (R1 compiled with its teammates since 2026-11-29, VisBug-21
    included; the helpers' patrol, goal sharing, the broadcast): the same run, step by step,
    with the scenario's VisBug-21 or another algorithm A for every robot, and with other sharing
    rules (state sharing alone, reflected visibility with state sharing)."""
    extra = {} if navigator is None else {f"robots.{k}.params.navigator": navigator for k in range(4)}
    for field, value in (_SHARING[sharing] if sharing else {}).items():
        extra.update({f"robots.{k}.params.{field}": value for k in range(4)})
    refs, grps = side_by_side(_scenario(task, paper, **extra), STEPS)
    for a, b in zip(refs[1:], grps[1:]):
        assert a.waypoints_reached == b.waypoints_reached and a.mode_steps == b.mode_steps
        assert a.msgs_sent > 100 and a.msgs_received > 100
    assert refs[0].msgs_received > 100 and refs[0].targets_reached >= 1
