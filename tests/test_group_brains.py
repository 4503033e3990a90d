"""The group-brain path: a compiled group brain runs the same runs, bit for bit, as the per-robot
reference brains it stands for (``docs/concepts/group-brains.md``).

The compiled piece so far is R1 alone (Sgorbissa & Arkin §2, §5, §6; Tables 1-2's "R1 alone"
rows): ``los-explorer-v1`` with the potential field, Avoid-Past or VisBug-21 as algorithm A, in
both of the report's columns (teamnav's gap-fills, and the paper as written: ``paper_column_r1``).
Each identity run steps the reference (``Simulation(...)``) and the group brain
(``Simulation(..., group_brains=True)``) side by side from the same scenario and seed and
demands, at every step, the same true poses, odometry, commands (the body-frame direction
of each step) and the same log of R1 (modes, Tr/Pr/Nt, targets, counters), and at the end the
same steps per target. 2500 steps reach targets, Avoid-Past's decay (inflation
``2^(t/h)``), goal switches, slides (teamnav column) and the collision guard; the first
version of the compiled step differed only at step 1632 (a constant ``2.0 ** x`` compiled to
``exp2``), so short runs would not do.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from teamnav import load_scenario
from teamnav.control.nav.local import compiled as N
from teamnav.experiments.spec import build_grid
from teamnav.papers.los_help.tasks import _alone, task_targets_xy
from teamnav.sim.engine import Simulation

STEPS = 2500


def _scenario(navigator: str, paper: bool, task: int, **extra):
    """R1 alone on office_simple (Table 1's scenario), one of the tuning tasks' target lists."""
    if paper:
        ov = dict(_alone(navigator))  # the paper column's settings, R1 alone
    else:
        ov = {"robots.0.params.navigator": navigator, "robots.1.count": 0, "robots.2.count": 0,
              "robots.3.count": 0}
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", task)
    ov.update(extra)
    return load_scenario("los-help-simple", overrides=ov, duration_s=STEPS * 0.1, seed=0)


def _same_log(la: dict, lb: dict, k: int) -> None:
    layers_a, layers_b = la.pop("layers", None), lb.pop("layers", None)
    assert la == lb, f"logs differ at step {k}"
    assert list(la) == list(lb)
    assert (layers_a is None) == (layers_b is None)
    if layers_a is not None:
        assert list(layers_a) == list(layers_b)
        for name in layers_a:
            assert np.array_equal(layers_a[name]["data"], layers_b[name]["data"]), (name, k)
            assert layers_a[name]["data"].shape == layers_b[name]["data"].shape
            assert {k2: v for k2, v in layers_a[name].items() if k2 != "data"} == \
                   {k2: v for k2, v in layers_b[name].items() if k2 != "data"}


def _side_by_side(scn, steps: int = STEPS, watch=None):
    """Step both; ``watch(reference R1)`` after every step (what the run reached)."""
    ref = Simulation(build_grid(scn), scn)
    grp = Simulation(build_grid(scn), scn, group_brains=True)
    assert len(grp.group_teams) == 1, "the group brain must run R1"
    r_ref, r_grp = ref.brains[0][0], grp.brains[0][0]
    _same_log(r_ref.log(), r_grp.log(), 0)
    for _ in range(steps):
        ref.step()
        grp.step()
        k = ref.step_index
        assert np.array_equal(ref.state.poses(), grp.state.poses()), f"true poses differ at step {k}"
        assert np.array_equal(ref.odometry.pose, grp.odometry.pose), f"odometry differs at step {k}"
        assert np.array_equal(ref._dir_cmd, grp._dir_cmd, equal_nan=True), f"commands differ at step {k}"
        _same_log(r_ref.log(), r_grp.log(), k)
        if watch is not None:
            watch(r_ref)
    assert r_ref.target_steps == r_grp.target_steps
    for attr in ("finished", "gave_up", "targets_reached", "target_index", "moves", "msgs_sent", "bytes_sent",
                 "msgs_received", "mode", "nav_restarts"):
        assert getattr(r_ref, attr) == getattr(r_grp, attr), attr
    return r_ref


@pytest.mark.parametrize("paper", [False, True], ids=["teamnav", "paper"])
@pytest.mark.parametrize("navigator", ["avoid_past", "potential_field", "visbug21"])
@pytest.mark.parametrize("task", [1001, 1002])
def test_r1_alone_compiled_is_the_reference_bit_for_bit(navigator, paper, task):
    modes = set()
    r1 = _side_by_side(_scenario(navigator, paper, task),
                       watch=lambda b: modes.add(b._nav.mode) if navigator == "visbug21" and b._nav else None)
    if navigator in ("avoid_past", "visbug21"):
        assert r1.targets_reached >= 3  # the identity covers goal switches
    if navigator == "visbug21":  # both of VisBug's steps: towards Ti on the M-line, along the boundary
        from teamnav.control.nav.local.visbug21 import MODE_FOLLOW, MODE_TO_GOAL

        assert {MODE_TO_GOAL, MODE_FOLLOW} <= modes
    assert r1.moves > STEPS // 2 and r1.mode_steps["own_goal"] == STEPS + 1  # step 0 decides too
    assert r1._nav is not None  # algorithm A drove (the potential field alone is soon trapped, §6)


def test_identity_covers_giving_up_layers_and_memory_scope():
    """A step budget that runs out (gave_up), the goal and ghost layers, Avoid-Past's memory
    forgotten at each new goal (``memory_scope="goal"``) and without decay."""
    scn = _scenario("avoid_past", False, 1003, **{
        "robots.0.params.max_steps_per_target": 150, "robots.0.params.log_layers": True,
        "robots.0.params.navigator_params": {"memory_scope": "goal", "memory_half_life_steps": None}})
    r1 = _side_by_side(scn, 1200)
    assert r1.gave_up and r1.mode == "gave_up"


_VISBUG_CASES = {
    # Bug2's termination test with return_tol_m wide enough that a walk round a room is a lap:
    # the goal is "unreachable" and A starts afresh (restart_navigator_on_give_up) ...
    "restart": (False, 1001, {"return_tol_m": 2.0}, True),
    # ... or, without the restart, gives no heading from then on (the paper column's VisBug)
    "unreachable": (True, 1001, {"return_tol_m": 3.0, "turn": "right", "boundary_shortcut": True}, False),
    # the alternating walk, with turn="left"
    "reverse": (True, 1002, {"return_tol_m": 2.0, "turn": "left", "boundary_shortcut": True,
                             "reverse_walk_factor": 1.5}, True),
}


@pytest.mark.parametrize("case", sorted(_VISBUG_CASES))
def test_visbug_identity_covers_giving_up_reversals_and_the_numpy_calls(case, monkeypatch):
    """VisBug-21's rarer branches, bit for bit: Bug2's termination test, A started afresh
    after it or left giving no heading, the alternating walk (``reverse_walk_factor``),
    ``turn="left"``, and the leave test's seen-free run (one of the two calls kept in numpy;
    the other, the boundary target's bearings, runs at most steps of the paper column)."""
    from teamnav.control.nav.local import visbug21
    from teamnav.control.nav.local.visbug21 import MODE_UNREACHABLE

    paper, task, nav, restart = _VISBUG_CASES[case]
    calls = {"seen_free": 0}
    seen_free = visbug21.seen_free

    def counted(*a, **k):
        calls["seen_free"] += 1
        return seen_free(*a, **k)

    monkeypatch.setattr(visbug21, "seen_free", counted)  # the reference's and the group brain's calls
    extra = {"robots.0.params.navigator_params": nav, "robots.0.params.restart_navigator_on_give_up": restart}
    reached = {"unreachable": 0, "reversed": 0}

    def watch(b):
        if b._nav is not None:
            reached["unreachable"] += b._nav.mode == MODE_UNREACHABLE
            lim = b._nav._reverse_limit_m
            reached["reversed"] += math.isfinite(lim) and lim != b._nav._reverse_reach_m

    r1 = _side_by_side(_scenario("visbug21", paper, task, **extra), watch=watch)
    assert calls["seen_free"] > 0
    if case == "restart":
        assert r1.nav_restarts > 0
    elif case == "unreachable":
        assert reached["unreachable"] > 100 and r1.nav_restarts == 0
    else:
        assert reached["reversed"] > 0


def test_identity_without_targets():
    scn = _scenario("potential_field", True, 1001, **{"robots.0.params.targets_xy": []})
    r1 = _side_by_side(scn, 5)
    assert r1.finished and r1.mode == "done"


def test_teams_with_helpers_step_in_one_group_brain():
    """R1 and a helper form one team of the team's group brain: with VisBug-21 or Avoid-Past R1
    is compiled too (identity with the reference: tests/test_team_compiled.py and
    tests/test_goal_sharing_compiled.py); with VisBug-21's ``turn="random"`` (a draw per task goal,
    declined) R1 runs its per-robot brain inside the group, beside the compiled helper."""
    ov = {"robots.1.count": 1, "robots.2.count": 0, "robots.3.count": 0}
    cases = (({"robots.0.params.navigator": "visbug21",
               "robots.0.params.navigator_params": {"turn": "random"}}, "LosExplorer", 1),
             ({"robots.0.params.navigator": "visbug21"}, "_R1TeamView", 2),
             ({"robots.0.params.navigator": "avoid_past"}, "_R1TeamView", 2))
    for r1_over, r1, compiled in cases:
        scn = load_scenario("los-help-simple", overrides={**ov, **r1_over}, duration_s=1.0, seed=0)
        sim = Simulation(build_grid(scn), scn, group_brains=True)
        assert [type(t).__name__ for t, *_ in sim.group_teams] == ["LosTeamGroup"]
        assert sim.group_teams[0][1:3] == (0, 2)
        assert type(sim.brains[0][0]).__name__ == r1
        assert type(sim.brains[1][0]).__name__ == "_HelperView"
        assert sim.group_teams[0][0].compiled_robots == compiled


def test_runs_with_faults_keep_the_reference_brains():
    """Faults shape each robot's observation (a scan not published, phantom detections), which
    the group observation does not carry yet: such runs use the per-robot brains; an empty
    ``faults`` section is no fault and keeps the group brain."""
    base = {"robots.0.params.navigator": "avoid_past", "robots.1.count": 0, "robots.2.count": 0, "robots.3.count": 0}
    with_fault = {**base, "faults": {"blackouts": [{"t0_s": 0.5, "t1_s": 0.8}]}}
    for ov, teams in ((with_fault, 0), ({**base, "faults": {}}, 1)):
        scn = load_scenario("los-help-simple", overrides=ov, duration_s=1.0, seed=0)
        sim = Simulation(build_grid(scn), scn, group_brains=True)
        assert len(sim.group_teams) == teams


def test_subclasses_do_not_inherit_the_group_brain():
    """A brain that extends R1's step (the beyond section's trail explorer) is not run by R1's
    group brain: only the class that names ``group_brain`` is."""
    from teamnav.control.group import group_brain_class
    from teamnav.papers.los_help.brains.explorer import LosExplorer

    class Extended(LosExplorer):
        pass

    assert group_brain_class(LosExplorer) is not None
    assert group_brain_class(Extended) is None


def test_py_hypot_is_pythons_hypot():
    """CPython's ``math.hypot`` is not libm's (which numba calls): the compiled step uses a
    port of CPython's algorithm. Random magnitudes over 20 decades, signs, zeros, subnormals,
    infinities and NaN."""
    rng = np.random.default_rng(7)
    xs = rng.standard_normal(20000) * 10.0 ** rng.integers(-10, 10, 20000)
    ys = rng.standard_normal(20000) * 10.0 ** rng.integers(-10, 10, 20000)
    special = [0.0, -0.0, 5e-324, -2.5e-320, 1e-310, 1e308, -1.7e308, math.inf, -math.inf, math.nan, 3.0]
    pairs = list(zip(xs.tolist(), ys.tolist())) + [(a, b) for a in special for b in special]
    for x, y in pairs:
        want, got = math.hypot(x, y), N.py_hypot(x, y)
        assert (want == got and math.copysign(1, want) == math.copysign(1, got)) or (want != want and got != got), \
            (x, y, want, got)


def test_compiled_dot_sums_as_numpys_matmul():
    """The potential field sums its terms with numpy's matmul (OpenBLAS ``dgemv``); the compiled
    field calls ``np.dot``, which numba sends to SciPy's BLAS. Bit-identical runs rest on the two
    summing in one order (a plain loop does not), checked here for the shapes the field uses."""
    from numba import njit

    @njit
    def dot(c, a):
        return np.dot(c, a)

    rng = np.random.default_rng(3)
    for n in list(range(1, 40)) + [72, 100, 360, 529, 600]:
        c = rng.standard_normal(n)
        a = rng.standard_normal((n, 2))
        assert np.array_equal(dot(c, a), c @ a), n


def test_py_wrap_is_wrap_scalar():
    from teamnav.control.nav.local.base import wrap_scalar

    for a in np.concatenate([np.linspace(-20, 20, 4001), [math.pi, -math.pi, 3 * math.pi, -0.0, 1e17, math.nan]]):
        want, got = wrap_scalar(float(a)), N.py_wrap(float(a))
        assert want == got or (want != want and got != got), a


# ---------------------------------------------------------------------------- the engine side
# A toy brain and its group brain: both decide with the same pure function of the robot's own
# observation, and record what they were given, so the test can compare, row by row, what the
# group brain receives with what each per-robot brain receives (truth and belief never mix).
from teamnav.control import NoParams  # noqa: E402
from teamnav.control.group import GroupAction  # noqa: E402
from teamnav.control.types import Action, Message  # noqa: E402


def _decide(rid: int, odom, ranges, n_det: int, n_inbox: int) -> tuple[float, float]:
    return 0.2 + 0.01 * n_inbox, (0.3 if float(np.min(ranges)) > 1.0 else -0.6) + 0.05 * n_det - 0.01 * rid + 0.0 * odom[2]


class EchoGroup:
    def __init__(self, params, rngs, infos):
        self.ids = [int(i.robot_id) for i in infos]
        self.seen = []
        self.robots = [_EchoView() for _ in infos]

    @classmethod
    def unsupported(cls, params, infos):
        return None

    def step_group(self, obs):
        self.seen.append(obs)
        n = len(self.ids)
        v, w = np.zeros(n), np.zeros(n)
        out = []
        for r, rid in enumerate(self.ids):
            v[r], w[r] = _decide(rid, obs.odom_pose[r], obs.ranges_m["laser"][r], int(obs.det_count[r]),
                                 len(obs.inbox[r]))
            out.append((rid, Message(rid, obs.time_s, {"step": obs.step}, kind="echo")))
        return GroupAction(v, w, np.full(n, np.nan), out)


class _EchoView:
    def log(self):
        return {}


class Echo:
    Params = NoParams
    group_brain = EchoGroup

    def __init__(self, params, rng, info):
        self.id = int(info.robot_id)
        self.seen = []

    def step(self, obs):
        self.seen.append(obs)
        v, w = _decide(self.id, obs.odom_pose, obs.scans["laser"].ranges_m, len(obs.detections), len(obs.inbox))
        return Action(v, w), [Message(self.id, obs.time_s, {"step": obs.step}, kind="echo")]

    def log(self):
        return {}


def _toy_config():
    from teamnav.sim.config import DetectorConfig, RadioConfig, RobotGroupConfig, SimConfig

    echo = f"{__name__}:Echo"
    det = DetectorConfig(range_noise_std_m=0.05, bearing_noise_std_deg=2.0)
    groups = (RobotGroupConfig(name="a", count=2, controller=echo, detector=det),
              RobotGroupConfig(name="none", count=0, controller=echo, detector=det),
              RobotGroupConfig(name="b", count=1, controller=echo, detector=det),
              RobotGroupConfig(name="other", count=1, controller="wander-v1", detector=det),
              RobotGroupConfig(name="c", count=2, controller=echo, detector=det))
    return SimConfig(robots=groups, radio=RadioConfig(mode="range", range_m=4.0), seed=11)


def test_teams_of_consecutive_groups_see_what_per_robot_brains_see():
    """Groups naming one group brain form a team when consecutive (a group without robots does
    not break it, another controller does); each row of the team's observation is the robot's
    own observation (odometry, scan, detections, inbox, stall flag), and the runs are the same."""
    from teamnav.world.grid import OccupancyGrid

    grid = OccupancyGrid.empty(8.0, 6.0, 0.05)
    ref = Simulation(grid, _toy_config())
    grp = Simulation(grid, _toy_config(), group_brains=True)
    assert [(start, stop, members) for _, start, stop, members in grp.group_teams] == [(0, 3, (0, 2)), (4, 6, (4,))]
    ref.run(60)
    grp.run(60)
    assert np.array_equal(ref.state.poses(), grp.state.poses())
    per_robot = {b.id: b.seen for g in ref.brains if isinstance(g, list) for b in g if isinstance(b, Echo)}
    delivered = detected = 0
    for team, start, stop, _ in grp.group_teams:
        assert len(team.seen) == 61  # the first decision and 60 steps
        for k, gobs in enumerate(team.seen):
            for r, rid in enumerate(range(start, stop)):
                o = per_robot[rid][k]
                assert gobs.robot_ids[r] == rid and gobs.step == o.step and gobs.time_s == o.time_s
                assert np.array_equal(gobs.odom_pose[r], o.odom_pose)
                assert np.array_equal(gobs.odom_delta[r], o.odom_delta)
                assert bool(gobs.stalled[r]) == o.stalled
                assert np.array_equal(gobs.ranges_m["laser"][r], o.scans["laser"].ranges_m)
                assert np.array_equal(gobs.angles_rad["laser"], o.scans["laser"].angles_rad)
                c = int(gobs.det_count[r])
                assert c == len(o.detections)
                for j, d in enumerate(o.detections):
                    assert (gobs.det_id[r, j], gobs.det_range_m[r, j], gobs.det_bearing_rad[r, j]) == \
                           (d.robot_id, d.range_m, d.bearing_rad)
                assert [(m.sender, m.body) for m in gobs.inbox[r]] == [(m.sender, m.body) for m in o.inbox]
                delivered += len(o.inbox)
                detected += c
    assert delivered > 0 and detected > 0  # messages were carried and teammates detected


def test_stale_numba_caches_of_callers_are_renewed(tmp_path):
    """numba's cache checks only the compiled function's own file: a caller cached before its
    callee changed runs the callee's old code. ``renew_stale_caches`` stamps the callees'
    sources and empties the caller's cache when they change (the compiled group brains call
    it at import)."""
    import subprocess
    import sys
    import textwrap

    pkg = tmp_path / "stalepkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    callee = pkg / "callee.py"
    (pkg / "caller.py").write_text(textwrap.dedent("""
        import sys
        from numba import njit
        from stalepkg import callee

        @njit(cache=True)
        def outer(x):
            return callee.inner(x)

        if "--renew" in sys.argv:
            from teamnav.control.group import renew_stale_caches
            renew_stale_caches([outer], [callee.__file__])
        print(outer(1))
        """))
    env = {**__import__("os").environ, "PYTHONPATH": f"{tmp_path}:{__import__('os').pathsep.join(sys.path)}"}

    def run(value: int, *flags: str) -> int:
        callee.write_text(f"from numba import njit\n\n@njit(cache=True)\ndef inner(x):\n    return x + {value}\n")
        out = subprocess.run([sys.executable, "-c", "import sys; sys.argv += %r; import stalepkg.caller" % (list(flags),)],
                             env=env, cwd=tmp_path, check=True, capture_output=True, text=True)
        return int(out.stdout.split()[-1])

    assert run(1) == 2
    assert run(10) == 2  # stale: the caller's cache still holds the old callee
    assert run(10, "--renew") == 11
    assert run(200, "--renew") == 201  # (sizes differ: the callee's own cache sees its change whatever the clock)


# ---------------------------------------------------------------------------- packed messages
def _random_msgs(rng, m: int, count: int):
    from teamnav.papers.los_help.brains.messages import GoalShare, LosHelpMsg, Sighting, VisReport

    for _ in range(count):
        ns, ng, nr = (int(rng.integers(0, m + 1)) for _ in range(3))
        sights = tuple(Sighting(int(rng.integers(0, m)), float(rng.uniform(-math.pi, math.pi)),
                                float(rng.uniform(0.1, 8.0))) for _ in range(ns))
        goals = tuple(GoalShare(int(rng.integers(0, m)), int(rng.integers(1, 10**6)), float(rng.normal(0, 20)),
                                float(rng.normal(0, 20))) for _ in range(ng))
        reports = []
        for _ in range(nr):
            via = [float(rng.normal(0, 5)) if rng.random() < 0.6 else None for _ in range(3)]
            reports.append(VisReport(int(rng.integers(0, m)), int(rng.integers(1, 10**6)), float(rng.uniform(0, 40)), *via))
        tr = [None, False, True][int(rng.integers(0, 3))]
        yield LosHelpMsg(int(rng.integers(0, 10**7)), sights, goals, tuple(reports), tr)


def test_packed_messages_round_trip_and_size_as_the_message():
    """A line-of-sight message packed into one row and back is the same message (every number,
    None where a field is not sent), and the radio sizes the row as the message (traffic counts
    and bandwidth caps unchanged)."""
    from teamnav.control.types import Message, payload_size_bytes
    from teamnav.papers.los_help.brains.messages import message_size_bytes
    from teamnav.papers.los_help.brains.packed import PackedLosMsg, pack, row_width, unpack

    rng = np.random.default_rng(5)
    for m in (1, 2, 4, 9):
        for msg in _random_msgs(rng, m, 200):
            row = pack(msg, m)
            assert row.shape == (row_width(m),)
            assert unpack(row) == msg
            body = PackedLosMsg(row)
            assert payload_size_bytes(body) == payload_size_bytes(msg)
            assert Message(0, 0.0, body, kind="los_help").size_bytes() == message_size_bytes(msg)
            sized = PackedLosMsg.sized(row)  # the size computed once, as a compiled team sends it
            assert sized.size == payload_size_bytes(msg) and payload_size_bytes(sized) == sized.size
    from teamnav.papers.los_help.brains.messages import LosHelpMsg

    with pytest.raises(ValueError):
        pack(LosHelpMsg(1, pose=(0.0, 0.0, 0.0)), 2)
