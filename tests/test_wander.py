"""The wanderer: both forms drive the same, it behaves as documented, and bad input is refused."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control import registry
from teamnav.control.nav import wander_kernel as K
from teamnav.control.nav.wander import Wander, WanderBatched, WanderParams, kernel_params
from teamnav.control.protocol import RobotInfo, SensorInfo
from teamnav.control.types import BatchObservation, Observation, RangeScan

LASER = SensorInfo("laser", "laser", np.linspace(-np.pi / 2, np.pi / 2, 180), 10.0)
PROX = SensorInfo("proximity", "proximity", np.radians([-40.0, -20.0, 0.0, 20.0, 40.0, 160.0, 200.0]), 0.14)


def info(i=0, n=1, sensors=(LASER,), dt_s=0.1):
    return RobotInfo(i, n, 0.2, "unicycle", 0.5, 1.5, 0.1, dt_s, sensors={s.name: s for s in sensors})


def obs(ranges, sensor=LASER, step=0, stalled=False, robot_id=0):
    scan = RangeScan(np.asarray(ranges, float), sensor.angles_rad, sensor.max_range_m)
    return Observation(robot_id, step, step * 0.1, np.zeros(3), np.zeros(3), scans={sensor.name: scan}, stalled=stalled)


def ranges_where(sensor, fn):
    """Ranges of ``sensor`` with fn(angle_rad) giving each beam's range (capped at max)."""
    a = (sensor.angles_rad + np.pi) % (2 * np.pi) - np.pi
    return np.minimum(np.array([fn(x) for x in a], float), sensor.max_range_m)


# ------------------------------------------------------------------------ counter-based RNG
@settings(deadline=None)
@given(st.integers(0, 2**64 - 1), st.integers(0, 2**40), st.integers(0, K.N_DRAWS - 1))
def test_uniform01_matches_reference(key, step, k):
    u = K.uniform01(np.uint64(key), np.int64(step), np.int64(k))
    assert u == K.uniform01_reference(key, step, k)
    assert 0.0 <= u < 1.0


def test_uniform01_is_uniform_and_decorrelated():
    u = np.array([K.uniform01_reference(12345, s, 0) for s in range(4000)])
    assert abs(u.mean() - 0.5) < 0.02 and abs(u.var() - 1 / 12) < 0.01
    assert abs(np.corrcoef(u[:-1], u[1:])[0, 1]) < 0.05
    v = np.array([K.uniform01_reference(12346, s, 0) for s in range(4000)])
    assert abs(np.corrcoef(u, v)[0, 1]) < 0.05


# ------------------------------------------------------------------------ both forms agree
@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    n_robots=st.integers(1, 5),
    n_steps=st.integers(1, 40),
    use_prox=st.booleans(),
    p_open=st.sampled_from([0.0, 0.5, 1.0]),
)
def test_both_forms_give_identical_actions(seed, n_robots, n_steps, use_prox, p_open):
    sensor = PROX if use_prox else LASER
    params = WanderParams(p_turn_at_opening=p_open)
    infos = [info(i, n_robots, sensors=(LASER, PROX)) for i in range(n_robots)]
    params = params.model_copy(update={"sensor": sensor.name})
    singles = [Wander(params, np.random.default_rng([seed, i]), infos[i]) for i in range(n_robots)]
    batch = WanderBatched(params, [np.random.default_rng([seed, i]) for i in range(n_robots)], infos)
    assert batch.range_sensor == sensor.name
    data = np.random.default_rng(seed)
    for step in range(n_steps):
        # Mostly coherent scans with jumps, so every mode (turn, openings, back-off) is visited.
        r = data.uniform(0.0, 1.0, (n_robots, sensor.angles_rad.size)) ** 2 * sensor.max_range_m * 1.2
        r = np.minimum(r, sensor.max_range_m)
        stalled = data.random(n_robots) < 0.1
        out = batch.step_batch(BatchObservation(np.arange(n_robots), step, step * 0.1, np.zeros((n_robots, 3)),
                                                r, sensor.angles_rad, sensor.max_range_m, stalled))
        for i, brain in enumerate(singles):
            action, outbox = brain.step(obs(r[i], sensor, step, bool(stalled[i]), i))
            assert outbox == []
            assert action.v_mps == out.v_mps[i] and action.omega_radps == out.omega_radps[i]
    modes = [b.log()["mode"] for b in singles]
    assert list(batch.log()["mode"]) == modes


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), use_prox=st.booleans())
def test_compiled_kernel_matches_its_python_execution(seed, use_prox):
    """The numba kernel against the same source run by the interpreter (catches typing slips)."""
    sensor = PROX if use_prox else LASER
    rng = np.random.default_rng(seed)
    n, nb = 6, sensor.angles_rad.size
    p = kernel_params(WanderParams(p_turn_at_opening=0.7), sensor.max_range_m, 0.1)
    keys = rng.integers(0, 2**63, n, dtype=np.uint64)
    st_c, st_py = K.initial_state(n), K.initial_state(n)
    for step in range(30):
        r = np.minimum(rng.uniform(0.0, 1.0, (n, nb)) ** 2 * sensor.max_range_m * 1.2, sensor.max_range_m)
        stalled = rng.random(n) < 0.1
        out_c, out_py = (np.zeros(n), np.zeros(n)), (np.zeros(n), np.zeros(n))
        K.wander_step(r, sensor.angles_rad, sensor.max_range_m, stalled, keys, np.int64(step), p, st_c, *out_c)
        K.wander_step.py_func(r, sensor.angles_rad, sensor.max_range_m, stalled, keys, np.int64(step), p, st_py, *out_py)
        np.testing.assert_allclose(out_c, out_py, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(st_c, st_py, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("chunk", [1, 7, 64, 5000])
def test_rows_spread_over_threads_are_the_serial_kernels_bit_for_bit(chunk):
    """wander_step_parallel (rows in chunks over numba's threads) against wander_step: the same
    commands and states, byte for byte, for any chunk size (a chunk larger than the team too)."""
    import numba

    rng = np.random.default_rng(chunk)
    n, nb = 300, LASER.angles_rad.size
    p = kernel_params(WanderParams(p_turn_at_opening=0.5), LASER.max_range_m, 0.1)
    keys = rng.integers(0, 2**63, n, dtype=np.uint64)
    st_s, st_p = K.initial_state(n), K.initial_state(n)
    threads = numba.get_num_threads()
    numba.set_num_threads(max(1, min(2, numba.config.NUMBA_NUM_THREADS)))
    try:
        for step in range(20):
            r = np.minimum(rng.uniform(0.0, 1.0, (n, nb)) ** 2 * LASER.max_range_m * 1.2, LASER.max_range_m)
            stalled = rng.random(n) < 0.1
            out_s, out_p = (np.zeros(n), np.zeros(n)), (np.zeros(n), np.zeros(n))
            K.wander_step(r, LASER.angles_rad, LASER.max_range_m, stalled, keys, np.int64(step), p, st_s, *out_s)
            K.wander_step_parallel(r, LASER.angles_rad, LASER.max_range_m, stalled, keys, np.int64(step), p, st_p,
                                   *out_p, np.int64(chunk))
            assert np.array_equal(out_s[0], out_p[0]) and np.array_equal(out_s[1], out_p[1])
            assert st_s.tobytes() == st_p.tobytes()
    finally:
        numba.set_num_threads(threads)


def test_rows_do_not_depend_on_their_neighbours():
    params = WanderParams()
    infos = [info(i, 3) for i in range(3)]
    rng = np.random.default_rng(1)
    r = np.minimum(rng.uniform(0, 12, (3, 180)), 10.0)
    a = WanderBatched(params, [np.random.default_rng(i) for i in range(3)], infos)
    b = WanderBatched(params, [np.random.default_rng(i) for i in (0, 1)], infos[:2])
    out_a = a.step_batch(BatchObservation(np.arange(3), 0, 0.0, np.zeros((3, 3)), r, LASER.angles_rad, 10.0, np.ones(3, bool)))
    out_b = b.step_batch(BatchObservation(np.arange(2), 0, 0.0, np.zeros((2, 3)), r[:2], LASER.angles_rad, 10.0, np.ones(2, bool)))
    np.testing.assert_array_equal(out_a.v_mps[:2], out_b.v_mps)
    np.testing.assert_array_equal(out_a.omega_radps[:2], out_b.omega_radps)


# ------------------------------------------------------------------------ behaviour
def test_cruises_straight_in_open_space():
    brain = Wander(WanderParams(cruise_speed_mps=0.3), np.random.default_rng(0), info())
    for step in range(5):
        action, _ = brain.step(obs(np.full(180, 10.0), step=step))
        assert (action.v_mps, action.omega_radps) == (0.3, 0.0)


@pytest.mark.parametrize("open_side", [1.0, -1.0])
def test_blocked_front_turns_on_the_spot_towards_the_open_side(open_side):
    # Wall 0.3 m ahead; the `open_side` half sees far, the other half a wall at 0.6 m.
    r = ranges_where(LASER, lambda a: 0.3 if abs(a) < math.radians(35) else (10.0 if a * open_side > 0 else 0.6))
    brain = Wander(WanderParams(), np.random.default_rng(0), info())
    action, _ = brain.step(obs(r))
    assert action.v_mps == 0.0 and np.sign(action.omega_radps) == open_side
    # It keeps turning the same way while the front stays blocked (no dithering).
    for step in range(1, 30):
        a2, _ = brain.step(obs(r, step=step))
        assert a2.v_mps == 0.0 and np.sign(a2.omega_radps) == open_side


def test_proximity_layout_turns_at_any_front_return():
    r = ranges_where(PROX, lambda a: 0.05 if abs(a) < 0.1 else 0.14)
    brain = Wander(WanderParams(), np.random.default_rng(0), info(sensors=(PROX,)))
    action, _ = brain.step(obs(r, PROX))
    assert action.v_mps == 0.0 and action.omega_radps != 0.0


def test_stall_backs_off_then_turns():
    p = WanderParams(backoff_s=0.5, backoff_speed_mps=0.1)
    brain = Wander(p, np.random.default_rng(0), info())
    free = np.full(180, 10.0)
    first, _ = brain.step(obs(free, stalled=True))
    assert first.v_mps == -0.1 and first.omega_radps == 0.0
    actions = [brain.step(obs(free, step=s))[0] for s in range(1, 12)]
    assert all(a.v_mps == -0.1 for a in actions[:4])
    assert actions[4].v_mps == 0.0 and actions[4].omega_radps != 0.0


@pytest.mark.parametrize(("side_m", "turn_sign"), [(0.85, 1.0), (0.25, -1.0)])
def test_keeps_a_left_wall_at_the_set_distance(side_m, turn_sign):
    # A wall parallel on the left at side_m: its beam at angle a hits at side_m / sin(a).
    r = ranges_where(LASER, lambda a: side_m / math.sin(a) if a > 0.05 else 10.0)
    brain = Wander(WanderParams(wall_distance_m=0.5, wall_follow_max_m=1.0), np.random.default_rng(0), info())
    action, _ = brain.step(obs(r))
    assert action.v_mps > 0.0 and np.sign(action.omega_radps) == turn_sign
    assert brain.log()["wall"] == 1


@pytest.mark.parametrize(("p_open", "takes"), [(1.0, True), (0.0, False)])
def test_side_opening_is_taken_with_its_probability(p_open, takes):
    wall = ranges_where(LASER, lambda a: 0.5 / math.sin(a) if a > 0.05 else 10.0)
    door = wall.copy()
    door[np.abs(LASER.angles_rad - math.pi / 2) < math.radians(20)] = 6.0
    brain = Wander(WanderParams(p_turn_at_opening=p_open), np.random.default_rng(0), info())
    brain.step(obs(wall))
    actions = [brain.step(obs(door, step=s))[0] for s in range(1, 30)]
    turned_left_on_spot = [a.v_mps == 0.0 and a.omega_radps > 0 for a in actions]
    assert any(turned_left_on_spot) == takes
    if takes:  # drives on first to clear the near edge, then a quarter turn
        first = turned_left_on_spot.index(True)
        assert first > 0 and all(a.v_mps > 0 for a in actions[:first])
        assert sum(turned_left_on_spot) == round(0.5 * math.pi / 1.0 / 0.1)


def test_opening_probability_half_is_about_half():
    wall = ranges_where(LASER, lambda a: 0.5 / math.sin(a) if a > 0.05 else 10.0)
    door = wall.copy()
    door[np.abs(LASER.angles_rad - math.pi / 2) < math.radians(20)] = 6.0
    taken = 0
    for seed in range(300):
        brain = Wander(WanderParams(), np.random.default_rng(seed), info())
        brain.step(obs(wall))
        brain.step(obs(door, step=1))
        taken += brain.log()["mode"] == K.MODE_OPEN_ADVANCE
    assert 110 < taken < 190


# ------------------------------------------------------------------------ validation
@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"cruise_speed_mps": -0.1}, "cruise_speed_mps"),
        ({"p_turn_at_opening": 1.5}, "p_turn_at_opening"),
        ({"turn_rate_radps": float("nan")}, "turn_rate_radps"),
        ({"safe_distance_m": 0.8, "slow_distance_m": 0.5}, "slow_distance_m"),
        ({"wall_distance_m": 1.0, "wall_follow_max_m": 0.9}, "wall_follow_max_m"),
        ({"side_min_deg": 100.0, "side_max_deg": 90.0}, "side_max_deg"),
        ({"speed": 1.0}, "speed"),
    ],
)
def test_bad_params_are_refused_naming_the_field(kwargs, field):
    with pytest.raises(ValueError, match=field):
        WanderParams(**kwargs)


def test_params_are_the_registered_classes_params():
    assert registry.lookup("wander-v1") is Wander and registry.lookup("wander-batched-v1") is WanderBatched
    assert Wander.Params is WanderParams and WanderBatched.Params is WanderParams and WanderBatched.batched


def test_bad_construction_and_observations():
    with pytest.raises(ValueError, match="sensor must name one of robot 0's range sensors \\(laser\\), got 'sonar'"):
        Wander(WanderParams(sensor="sonar"), np.random.default_rng(0), info())
    with pytest.raises(ValueError, match="needs a range sensor"):
        Wander(WanderParams(), np.random.default_rng(0), info(sensors=()))
    with pytest.raises(ValueError, match="share one range sensor"):
        WanderBatched(WanderParams(), [np.random.default_rng(0)] * 2, [info(0, 2), info(1, 2, dt_s=0.2)])
    with pytest.raises(ValueError, match="non-empty and of one length"):
        WanderBatched(WanderParams(), [np.random.default_rng(0)], [info(0), info(1)])
    brain = WanderBatched(WanderParams(), [np.random.default_rng(0)] * 2, [info(0, 2), info(1, 2)])
    with pytest.raises(ValueError, match=r"shape \(2, n_beams\), got \(3, 180\)"):
        brain.step_batch(BatchObservation(np.arange(3), 0, 0.0, np.zeros((3, 3)), np.ones((3, 180)), LASER.angles_rad, 10.0, np.zeros(3, bool)))
    with pytest.raises(ValueError, match="must carry scan 'laser'"):
        Wander(WanderParams(), np.random.default_rng(0), info()).step(obs(np.full(7, 0.14), PROX))
    with pytest.raises(ValueError, match="dt_s must be a positive"):
        kernel_params(WanderParams(), 10.0, 0.0)
    scan = RangeScan(np.full(179, 10.0), LASER.angles_rad, 10.0)
    with pytest.raises(ValueError, match="179 ranges for 180 beam angles"):
        Wander(WanderParams(), np.random.default_rng(0), info()).step(
            Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan}))


def test_the_per_robot_form_reads_scans_of_any_layout_and_byte_order():
    """Strided rows, big-endian and float32 ranges drive as the same values in a plain array."""
    rng = np.random.default_rng(3)
    plain = [Wander(WanderParams(), np.random.default_rng(9), info()) for _ in range(4)]
    for step in range(25):
        r = np.minimum(rng.uniform(0.0, 1.0, 180) ** 2 * 12.0, 10.0).astype(np.float32).astype(np.float64)
        wide = np.repeat(r, 2)[::2]  # a strided view
        forms = [r, wide, r.astype(">f8"), r.astype(np.float32)]
        assert not wide.flags.c_contiguous
        acts = [b.step(obs(x, step=step, stalled=step % 7 == 3)) for b, x in zip(plain, forms)]
        assert len({(a.v_mps, a.omega_radps) for a, _ in acts}) == 1


def test_the_per_robot_form_follows_beam_angles_changed_in_place():
    """The per-robot wanderer keeps its beam classes while the scans carry one array nobody can
    change; an array changed in place between steps is classified again."""
    params = WanderParams(sensor="proximity")
    infos = [info(0, 1, sensors=(PROX,))]
    single = Wander(params, np.random.default_rng(5), infos[0])
    batch = WanderBatched(params, [np.random.default_rng(5)], infos)
    angles = PROX.angles_rad.copy()  # writeable: the brain may not trust it to stay the same
    r = np.array([0.14, 0.14, 0.14, 0.14, 0.14, 0.03, 0.14])  # only the beam at 160° sees something
    for step, turn in enumerate([0.0, np.pi, np.pi, 0.0]):
        angles[:] = PROX.angles_rad + turn  # rotated half a turn: the beam at 160° now looks ahead
        action, _ = single.step(Observation(0, step, 0.1 * step, np.zeros(3), np.zeros(3),
                                            scans={"proximity": RangeScan(r, angles, 0.14)}))
        out = batch.step_batch(BatchObservation(np.arange(1), step, 0.1 * step, np.zeros((1, 3)), r[None, :],
                                                angles, 0.14, np.zeros(1, bool)))
        assert (action.v_mps, action.omega_radps) == (out.v_mps[0], out.omega_radps[0])
    assert single.log()["mode"] == batch.log()["mode"][0]


def test_thresholds_are_capped_to_a_short_sensor():
    p = kernel_params(WanderParams(), 0.14, 0.1)
    assert p[K.P_SAFE_M] == pytest.approx(0.07) and p[K.P_WALL_MAX_M] < 0.14 and p[K.P_WALL_M] < p[K.P_WALL_MAX_M]


# ------------------------------------------------------------------------ in the simulator
def _room(side_m=4.0, res_m=0.05):
    from teamnav.world.grid import WALL, OccupancyGrid

    n = int(round(side_m / res_m))
    cells = np.zeros((n, n), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    cells[n // 2 - 2 : n // 2 + 2, n // 4 : 3 * n // 4] = WALL  # a wall stub in the middle
    return OccupancyGrid(cells, res_m, name="room")


def _sim(controller, n_robots, seed, sensors=None, grid=None, poses=None):
    engine = pytest.importorskip("teamnav.sim.engine", reason="the engine has not landed")
    pytest.importorskip("teamnav.sim.sensors", reason="the sensor models have not landed")
    from teamnav.sim.config import LaserConfig, RobotGroupConfig, SimConfig, StartConfig

    start = StartConfig(poses=poses) if poses is not None else StartConfig()
    group = RobotGroupConfig(count=n_robots, controller=controller, sensors=sensors or (LaserConfig(),), start=start)
    return engine.Simulation(grid if grid is not None else _room(6.0), SimConfig(robots=(group,), seed=seed))


def _pose(sim):
    s = sim.state
    return np.stack([np.array(s.x_m, float), np.array(s.y_m, float), np.array(s.theta_rad, float)], axis=1)


@pytest.mark.parametrize("sensor", ["laser", "proximity"])
def test_per_robot_and_batched_teams_drive_identically(sensor):
    from teamnav.sim.config import LaserConfig, ProximityConfig

    sensors = (LaserConfig(),) if sensor == "laser" else (ProximityConfig(),)
    a = _sim("wander-v1", 4, seed=7, sensors=sensors)
    b = _sim("wander-batched-v1", 4, seed=7, sensors=sensors)
    np.testing.assert_array_equal(_pose(a), _pose(b))
    start = _pose(a)
    for _ in range(150):
        a.step()
        b.step()
        np.testing.assert_array_equal(_pose(a), _pose(b))
    assert np.all(np.hypot(*(_pose(a)[:, :2] - start[:, :2]).T) > 0.2)  # they really moved


def test_robot_facing_a_wall_turns_and_keeps_moving():
    # One robot 0.6 m from a wall, facing it, in a closed 4 m room; 60 s at dt 0.1 s.
    sim = _sim("wander-v1", 1, seed=3, grid=_room(4.0), poses=((3.2, 1.0, 0.0),))
    prev = _pose(sim)[0]
    path_m, stalled_steps = 0.0, 0
    for _ in range(600):
        sim.step()
        now = _pose(sim)[0]
        step_m = float(np.hypot(*(now[:2] - prev[:2])))
        path_m += step_m
        stalled_steps += step_m < 1e-6 and abs(now[2] - prev[2]) < 1e-9
        prev = now
    assert path_m > 8.0, f"wandered only {path_m:.2f} m in 60 s"
    assert stalled_steps / 600 < 0.1, f"stood still {stalled_steps} of 600 steps"
