"""The trail brains under ``group_brains`` (``papers/trails/brains/trail_compiled.py``: the
reference brains over a compiled Navigate) run as the reference does, bit for bit.

Vaughan et al. 2000 §4.1-4.2 (``blazing-a-trail``, ``blazing-trail-v1``) and 2002 §3
(``try-to-see-it-my-way``, ``trail-share-v1``), each in both report columns (teamnav and the
paper as written, ``paper_rules: true``), with the scenarios' heading drift and their launch
(robots started one at a time): the engine steps the reference and the compiled team side by
side and requires, at every step, the same true poses, odometry, commands and logs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from teamnav import load_scenario
from teamnav.control import registry
from teamnav.control.nav.navigate import NavigateParams
from teamnav.control.nav.navigate_compiled import py_remainder, unsupported
from teamnav.experiments.spec import build_grid
from teamnav.sim.engine import Simulation

STEPS = 1200


def _scenario(name: str, paper: bool, steps: int = STEPS, seed: int = 1000, navigate: dict | None = None):
    """``name`` for ``steps`` steps; ``paper``: every robot with ``paper_rules: true`` (the
    params those rules set dropped, as the reports' paper column does)."""
    base = load_scenario(name)
    ov: dict = {}
    for k, g in enumerate(base.robots):
        params = dict(g.params)
        if paper:
            rules = registry.lookup(g.controller).Params.PAPER_RULES
            params = {**{a: b for a, b in params.items() if a not in rules}, "paper_rules": True}
        if navigate is not None:
            params["navigate"] = dict(navigate)
        ov[f"robots.{k}.params"] = params
    return load_scenario(name, overrides=ov, duration_s=steps * 0.1, seed=seed)


def _log_equal(a, b) -> bool:
    if isinstance(a, dict):
        return isinstance(b, dict) and list(a) == list(b) and all(_log_equal(a[k], b[k]) for k in a)
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.shape == b.shape and a.tobytes() == b.tobytes()
    return type(a) is type(b) and a == b


def side_by_side(scn, steps: int) -> tuple[Simulation, Simulation]:
    """Step the reference and the group-brain simulation together; assert equal at every step."""
    ref = Simulation(build_grid(scn), scn)
    cmp_ = Simulation(build_grid(scn), scn, group_brains=True)
    assert not ref.group_teams and len(cmp_.group_teams) == 1
    for step in range(steps):
        ref.step()
        cmp_.step()
        where = f"step {step + 1}"
        for name in ("x_m", "y_m", "theta_rad"):
            a, b = getattr(ref.state, name), getattr(cmp_.state, name)
            assert a.tobytes() == b.tobytes(), f"{where}: true {name} {a} vs {b}"
        assert ref.odometry.pose.tobytes() == cmp_.odometry.pose.tobytes(), where
        assert ref._v_cmd.tobytes() == cmp_._v_cmd.tobytes() and ref._w_cmd.tobytes() == cmp_._w_cmd.tobytes(), where
        if step % 10 == 0 or step == steps - 1:
            for ga, gb in zip(ref.brains, cmp_.brains):
                for ba, bb in zip(ga, gb):
                    la, lb = ba.log(), bb.log()
                    assert _log_equal(la, lb), f"{where}: logs differ {la} vs {lb}"
    return ref, cmp_


@pytest.mark.parametrize("team_call", [False, True], ids=["per-robot", "team-call"])
@pytest.mark.parametrize("paper", [False, True], ids=["teamnav", "paper"])
@pytest.mark.parametrize("name", ["blazing-a-trail", "try-to-see-it-my-way"])
def test_compiled_trail_team_runs_as_the_reference(name, paper, team_call, monkeypatch):
    """Both forms of the group brain: one call per robot (four robots, the default) and the team
    in one call (the default from TEAM_MIN robots on, forced here for four)."""
    from teamnav.papers.trails.brains import trail_compiled

    if team_call:
        monkeypatch.setattr(trail_compiled._TrailGroup, "TEAM_MIN", 1)
    scn = _scenario(name, paper)
    ref, cmp_ = side_by_side(scn, STEPS)
    team = cmp_.group_teams[0][0]
    assert team.compiled_robots == 4  # every robot's Navigate compiled
    assert team._team == team_call
    modes = {b.nav.mode for g in cmp_.brains for b in g}
    assert modes <= {"navigate", "advance", "turn", "panic"}
    # the launch started every robot, and the radio carried the same crumbs or trails
    assert not (ref.waiting is not None and ref.waiting.any())
    assert ref.radio.sent_messages.sum() > 0
    assert ref.radio.sent_messages.tolist() == cmp_.radio.sent_messages.tolist()
    assert ref.radio.sent_bytes.tolist() == cmp_.radio.sent_bytes.tolist()


def test_declined_navigate_flags_keep_the_reference_navigate_and_the_same_run():
    """A give-way (not compiled) leaves those robots on the reference Navigate inside the group:
    the team still runs (nothing compiles here), and per robot, as the reference does."""
    scn = _scenario("blazing-a-trail", False, steps=300, navigate={"give_way_s": 3.0})
    sim = Simulation(build_grid(scn), scn, group_brains=True)
    assert sim.group_teams == []  # no robot compiles: the group brain declines the team
    assert "give_way_s" in unsupported(NavigateParams(give_way_s=3.0))
    assert unsupported(NavigateParams(paper_rules=True)) is None


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False))
def test_py_remainder_is_pythons_math_remainder(x):
    for y in (2.0 * math.pi, 1.0, 0.3):
        assert py_remainder(x, y) == math.remainder(x, y) and math.copysign(1.0, py_remainder(x, y)) == \
            math.copysign(1.0, math.remainder(x, y)), (x, y)


def test_py_remainder_at_the_half_way_points():
    two_pi = 2.0 * math.pi
    for k in range(-7, 8):
        for x in (k * math.pi, k * two_pi, np.nextafter(k * math.pi, math.inf), np.nextafter(k * math.pi, -math.inf)):
            assert py_remainder(float(x), two_pi) == math.remainder(float(x), two_pi), x


@given(st.integers(0, 2**32 - 1), st.sampled_from(["left", "right"]), st.floats(0.3, 3.0), st.booleans())
def test_sparse_box_scan_answers_as_the_sliding_box(seed, side, reach, walls):
    """Each box's crossing beams, the followed side's first (``box_beams``), give the first free
    slide position and "ahead blocked" of the reference kernel, on random scans."""
    from teamnav.control.nav.navigate_compiled import box_beams, first_free_box_sparse
    from teamnav.control.nav.wall_follow import SlidingBox, first_free_box

    rng = np.random.default_rng(seed)
    angles = np.linspace(-np.pi / 2, np.pi / 2, 361)
    box = SlidingBox(angles, 0.8, 1.0, 0.1, max(0.05, reach - 0.4), 0.05, 0.4, 1.5, 1.0, 0.3, side)
    r = rng.uniform(0.05, 8.0, 361)
    if walls:  # a wall beside the robot at a random distance, and clutter ahead
        lateral = rng.uniform(0.2, 2.5)
        s = np.abs(np.sin(angles))
        wall = np.where(s > 1e-6, lateral / np.maximum(s, 1e-6), 8.0)
        on_side = angles > 0 if side == "left" else angles < 0
        r = np.where(on_side, np.minimum(wall, 8.0), np.maximum(r, rng.uniform(0.5, 8.0)))
    idx, cnt = box_beams(box.exit_m, box.sign)
    assert first_free_box_sparse(r, box._cos, box.box_near_m, box.exit_m, idx, cnt) == \
        first_free_box(r, box._cos, box.box_near_m, box.exit_m)


@given(st.integers(0, 2**32 - 1), st.sampled_from([0, 1, 7, 8, 9, 127, 128, 129, 300, 1000, 8192, 8193, 20000]))
def test_pairwise_sum_is_numpys_sum(seed, n):
    from teamnav.papers.trails.brains.trail_compiled import pairwise_sum

    a = np.sin(np.random.default_rng(seed).uniform(-4.0, 4.0, n))
    assert 0.0 + pairwise_sum(a, 0, n) == float(a.sum())


@given(st.integers(0, 2**32 - 1), st.integers(0, 400), st.floats(0.1, 5.0))
def test_compiled_crumb_mean_is_the_reference_mean(seed, n, radius):
    """The crumbs' mean heading around a point (Blazing §4.1), compiled and reference, bit for bit,
    on random crumb lists (headings from -pi to pi, cancelling ones included)."""
    from teamnav.papers.trails.brains.crumbs import average_heading
    from teamnav.papers.trails.brains.trail_compiled import average_heading_kernel

    rng = np.random.default_rng(seed)
    buf = np.zeros((n + 1, 4))
    buf[:n, :2] = rng.uniform(-3.0, 3.0, (n, 2))
    buf[:n, 2] = rng.uniform(-np.pi, np.pi, n)
    if n >= 2 and seed % 3 == 0:  # two crumbs that cancel
        buf[1, :2] = buf[0, :2]
        buf[1, 2] = buf[0, 2] - np.pi if buf[0, 2] > 0 else buf[0, 2] + np.pi
    x, y = rng.uniform(-3.0, 3.0, 2)
    ref = average_heading(buf[:n, :2], buf[:n, 2], float(x), float(y), radius)
    found, mean = average_heading_kernel(buf, n, float(x), float(y), radius)
    assert (ref is not None) == found
    if found:
        assert mean == ref


def test_blazing_team_with_two_navigate_settings_steps_robot_by_robot_as_the_reference(monkeypatch):
    """Robots whose Navigate parameters differ do not share a geometry: the group brain steps
    them one call per robot (not the team call), and the run is still the reference's."""
    scn = _scenario("blazing-a-trail", False, steps=600)
    scn = scn.model_copy(update={"robots": [
        g.model_copy(update={"params": {**g.params, "navigate": {"p_take_opening": 0.6}}}) if k == 1 else g
        for k, g in enumerate(scn.robots)]})
    from teamnav.papers.trails.brains import trail_compiled

    monkeypatch.setattr(trail_compiled._TrailGroup, "TEAM_MIN", 1)  # would step as a team if it could
    ref, cmp_ = side_by_side(scn, 600)
    team = cmp_.group_teams[0][0]
    assert team.compiled_robots == 4 and not team._team


@pytest.mark.parametrize("controller", ["blazing-trail-v1", "trail-share-v1"])
def test_ten_robots_step_as_a_team_in_one_call_as_the_reference(controller):
    """Ten robots of ``trail-team`` (one group, one geometry) on the open building, started at
    random spots (no launch): the default team call, side by side with the reference."""
    ov = {"robots.0.count": 10, "map": {"builtin": "trail_office"}, "launch": None,
          "robots.0.start": {"theta_deg": None}, "robots.0.controller": controller}
    if controller == "trail-share-v1":
        ov["robots.0.params"] = {"cruise_speed_mps": 0.4, "communicate": True, "layer_every_steps": 6000}
    scn = load_scenario("trail-team", overrides=ov, duration_s=60.0, seed=1001)
    ref, cmp_ = side_by_side(scn, 600)
    team = cmp_.group_teams[0][0]
    assert team._team and team.compiled_robots == 10
    assert ref.radio.sent_messages.tolist() == cmp_.radio.sent_messages.tolist()
