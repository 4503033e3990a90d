"""Kinematics and collisions: exact arcs, clipping, and discs that never penetrate walls or each other."""

from __future__ import annotations

import decimal
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from teamnav.geometry.angles import wrap_angle
from teamnav.sim.collisions import SUBSTEP_FRACTION, discs_hit_walls, move_discs
from teamnav.sim.kinematics import arc_point, motion_primitives, unicycle_arc_reference, wrap
from teamnav.world.distance import distance_field
from teamnav.world.grid import WALL, OccupancyGrid

BASEMENT = Path(__file__).resolve().parents[1] / "src/teamnav/world/maps/mit/basement_hallways_5cm.png"


# ------------------------------------------------------------------------ references
def wall_distance_ref(blocking, ox, oy, res, xs, ys, window_m=0.5):
    """Distance from each point to the nearest blocking cell square or map edge, capped at
    ``window_m`` (brute force over the cells within the window: nothing farther can be nearer)."""
    h, w = blocking.shape
    out = np.empty(len(xs))
    k = int(math.ceil(window_m / res)) + 1
    for i, (x, y) in enumerate(zip(xs, ys)):
        c = int(math.floor((x - ox) / res))
        r = int(math.floor((y - oy) / res))
        sub = blocking[max(r - k, 0): r + k + 1, max(c - k, 0): c + k + 1]
        rows, cols = np.nonzero(sub)
        x0 = ox + (cols + max(c - k, 0)) * res
        y0 = oy + (rows + max(r - k, 0)) * res
        dx = np.maximum(np.maximum(x0 - x, 0.0), x - (x0 + res))
        dy = np.maximum(np.maximum(y0 - y, 0.0), y - (y0 + res))
        d = np.sqrt(dx * dx + dy * dy).min() if len(x0) else np.inf
        out[i] = min(d, window_m, x - ox, ox + w * res - x, y - oy, oy + h * res - y)
    return out


def pair_gaps(xs, ys, rs):
    """min over pairs of (centre distance - r_i - r_j)."""
    d = np.hypot(xs[:, None] - xs[None, :], ys[:, None] - ys[None, :]) - (rs[:, None] + rs[None, :])
    np.fill_diagonal(d, np.inf)
    return d.min()


def path_blocked_ref(blocking, clear, geo, x, y, th0, arc, turn, r, others_x, others_y, others_r):
    """Reference: is any collision sample of this arc blocked (walls, or the other discs)?"""
    n = max(1, math.ceil(abs(arc) / (SUBSTEP_FRACTION * r)))
    for k in range(1, n + 1):
        px, py, _ = arc_point(x, y, th0, arc, turn, k / n)
        if discs_hit_walls(blocking, clear, geo, np.array([px]), np.array([py]), np.array([r]))[0]:
            return True
        if len(others_x) and np.any(np.hypot(others_x - px, others_y - py) < others_r + r):
            return True
    return False


def load_basement() -> OccupancyGrid:
    try:
        from teamnav.world.mapio import load_map

        return load_map(BASEMENT.with_suffix(".yaml"))
    except ImportError:  # pragma: no cover - map I/O always ships with the package
        from PIL import Image

        img = np.asarray(Image.open(BASEMENT).convert("L"))[::-1]
        cells = np.where(img >= 254, 0, np.where(img == 0, WALL, 2)).astype(np.uint8)
        return OccupancyGrid(cells, 0.05, name="basement")


# ------------------------------------------------------------------------ kinematics
@settings(deadline=None)
@given(st.floats(-50, 50), st.floats(-4, 4), st.floats(-math.pi, math.pi))
def test_wrap_matches_geometry_wrap_angle(a, b, c):
    for v in (a, b, c, a * 1e3):
        assert wrap(v) == wrap_angle(v)


def _dsin_dcos(a: decimal.Decimal) -> tuple[decimal.Decimal, decimal.Decimal]:
    """sin and cos of ``a`` (|a| < 8) by their Taylor series in the current decimal context."""
    s = c = decimal.Decimal(0)
    term = decimal.Decimal(1)  # a^k / k!
    k = 0
    eps = decimal.Decimal(10) ** (-decimal.getcontext().prec - 5)
    while abs(term) > eps or k < 4:
        if k % 4 == 0:
            c += term
        elif k % 4 == 1:
            s += term
        elif k % 4 == 2:
            c -= term
        else:
            s -= term
        k += 1
        term = term * a / k
    return s, c


def exact_arc_end(x, y, th, v, w, dt):
    """End of the unicycle arc by eq. 5.9 of Probabilistic Robotics, evaluated in 60-digit
    decimal arithmetic from the exact values of the float inputs: the cancellation of
    ``sin(th + w dt) - sin(th)`` costs at most ~12 of the 60 digits for |w dt| >= 1e-12
    (an independent check of the chord form the simulator uses; below that, a straight line
    whose error is < 1e-24 m)."""
    with decimal.localcontext() as ctx:
        ctx.prec = 60
        X, Y, TH, V, W, DT = (decimal.Decimal(float(a)) for a in (x, y, th, v, w, dt))
        phi = W * DT
        if abs(phi) < decimal.Decimal("1e-12"):
            s0, c0 = _dsin_dcos(TH)
            return float(X + V * DT * c0), float(Y + V * DT * s0)
        s0, c0 = _dsin_dcos(TH)
        s1, c1 = _dsin_dcos(TH + phi)
        rho = V / W
        return float(X + rho * (s1 - s0)), float(Y - rho * (c1 - c0))


def test_exact_reference_is_exact_on_a_quarter_circle():
    ex, ey = exact_arc_end(0.0, 0.0, 0.0, 1.0, math.pi / 2, 1.0)
    assert (ex, ey) == pytest.approx((2 / math.pi, 2 / math.pi), abs=1e-15)


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-5, 5), st.floats(-5, 5), st.floats(-math.pi, math.pi),
    st.floats(-2, 2), st.one_of(st.floats(-4, 4), st.floats(-1e-6, 1e-6)), st.floats(0.01, 1.0),
)
@example(0.0, 0.0, 1.0, 1.0, 3.9e-11, 1.0)  # eq. 5.9 in floats: 1.8e-6 m off (cancellation)
@example(0.0, 0.0, 1.0, 1.0, 1.0000001e-12, 1.0)  # just above the former straight-line cutoff
@example(3.0, -2.0, -2.5, -2.0, 2e-9, 0.37)
def test_arc_end_matches_reference_and_fine_euler(x, y, th, v, w, dt):
    px, py, pth = arc_point(x, y, th, v * dt, w * dt, 1.0)
    # 1e-9 m of the exact arc for every turn rate in [-4, 4] rad/s, tiny ones included
    np.testing.assert_allclose([px, py], exact_arc_end(x, y, th, v, w, dt), rtol=0, atol=1e-9)
    assert pth == th + w * dt
    ref = unicycle_arc_reference(x, y, th, v, w, dt)
    np.testing.assert_allclose([px, py, wrap(pth)], ref, rtol=0, atol=1e-12)  # NumPy's twin
    # exact integration == the limit of many tiny Euler steps
    k = 2000
    ex, ey, eth = x, y, th
    for _ in range(k):
        ex += v * dt / k * math.cos(eth + 0.5 * w * dt / k)
        ey += v * dt / k * math.sin(eth + 0.5 * w * dt / k)
        eth += w * dt / k
    np.testing.assert_allclose([px, py], [ex, ey], atol=1e-6)


def test_quarter_circle_by_hand():
    # v = 1 m/s, omega = pi/2 rad/s for 1 s: a quarter circle of radius 2/pi to the left.
    px, py, pth = arc_point(0.0, 0.0, 0.0, 1.0, math.pi / 2, 1.0)
    assert px == pytest.approx(2 / math.pi) and py == pytest.approx(2 / math.pi) and pth == pytest.approx(math.pi / 2)


def test_motion_primitives_clip_and_holonomic():
    n = 4
    holo = np.array([False, False, True, True])
    v = np.array([3.0, -3.0, 9.0, 0.0])
    w = np.array([10.0, -0.1, 9.0, 0.0])
    d = np.array([np.nan, np.nan, 3 * math.pi / 2, np.nan])
    maxv = np.full(n, 0.5)
    maxw = np.full(n, 1.0)
    step = np.full(n, 0.3)
    out = [np.zeros(n) for _ in range(5)]
    motion_primitives(holo, v, w, d, maxv, maxw, step, 0.1, *out)
    vo, wo, pre, arc, turn = out
    np.testing.assert_allclose(vo[:2], [0.5, -0.5])
    np.testing.assert_allclose(wo[:2], [1.0, -0.1])
    np.testing.assert_allclose(arc, [0.05, -0.05, 0.3, 0.0])
    np.testing.assert_allclose(turn, [0.1, -0.01, 0.0, 0.0])
    np.testing.assert_allclose(pre, [0.0, 0.0, -math.pi / 2, 0.0])  # direction wrapped; NaN = stay


# ------------------------------------------------------------------------ collisions
def _room(side_m=4.0, res=0.05):
    n = int(round(side_m / res))
    cells = np.zeros((n, n), np.uint8)
    cells[:2, :] = cells[-2:, :] = cells[:, :2] = cells[:, -2:] = WALL
    return OccupancyGrid(cells, res, name="room")


def _move(grid, x, y, th, r, pre, arc, turn, collide=True):
    b = grid.blocking(None)
    clear = distance_field(b, grid.resolution_m)
    geo = np.array([*grid.origin_xy_m, grid.resolution_m])
    stalled = np.zeros(len(x), bool)
    move_discs(x, y, th, r, pre, arc, turn, b, clear, geo, collide, stalled)
    return stalled


def test_robot_stops_at_last_safe_substep_before_wall_and_may_rotate():
    g = _room()  # walls at x >= 3.9
    x, y, th = np.array([3.5]), np.array([2.0]), np.array([0.0])
    stalled = _move(g, x, y, th, np.array([0.2]), np.zeros(1), np.array([0.5]), np.array([0.3]))
    assert stalled[0]
    d = wall_distance_ref(g.blocking(None), 0.0, 0.0, 0.05, x, y)[0]
    assert 0.2 - 1e-9 <= d <= 0.2 + SUBSTEP_FRACTION * 0.2  # close to the wall, never inside it
    assert th[0] == pytest.approx(0.3)  # the heading turned anyway


def test_thin_wall_is_never_tunnelled():
    cells = np.zeros((40, 40), np.uint8)
    cells[:, 20] = WALL  # one cell (5 cm) thick
    g = OccupancyGrid(cells, 0.05)
    x, y, th = np.array([0.8]), np.array([1.0]), np.array([0.0])
    stalled = _move(g, x, y, th, np.array([0.05]), np.zeros(1), np.array([0.9]), np.zeros(1))  # a long jump
    assert stalled[0] and x[0] <= 1.0 - 0.05 + 1e-12


def test_rotation_in_place_is_always_allowed():
    g = _room()
    x, y, th = np.array([0.3]), np.array([0.3]), np.array([0.0])  # touching two walls
    stalled = _move(g, x, y, th, np.array([0.2]), np.array([1.0]), np.zeros(1), np.array([0.5]))
    assert not stalled[0] and th[0] == pytest.approx(1.5) and (x[0], y[0]) == (0.3, 0.3)


def test_robots_resolve_in_index_order():
    g = _room(6.0)
    # two robots drive head-on into the same spot; robot 0 moves first and gets there
    x, y, th = np.array([2.0, 3.0]), np.array([3.0, 3.0]), np.array([0.0, math.pi])
    r = np.array([0.2, 0.2])
    stalled = _move(g, x, y, th, r, np.zeros(2), np.array([0.35, 0.35]), np.zeros(2))
    assert x[0] == pytest.approx(2.35) and not stalled[0]
    assert stalled[1] and x[1] - x[0] >= 0.4 - 1e-9
    # without robot collisions both go straight through each other's place
    x, y, th = np.array([2.0, 3.0]), np.array([3.0, 3.0]), np.array([0.0, math.pi])
    stalled = _move(g, x, y, th, r, np.zeros(2), np.array([0.35, 0.35]), np.zeros(2), collide=False)
    assert not stalled.any() and x.tolist() == pytest.approx([2.35, 2.65])


def test_random_driving_on_basement_never_penetrates_and_stall_is_exact():
    grid = load_basement()
    b = grid.blocking(None)
    clear = distance_field(b, grid.resolution_m)
    ox, oy = grid.origin_xy_m
    res = grid.resolution_m
    geo = np.array([ox, oy, res])
    rng = np.random.default_rng(5)
    # 60 robots of two sizes, uniformly over the free space
    from teamnav.sim.config import RobotGroupConfig, StartConfig
    from teamnav.sim.start import start_poses

    # 30 robots over the whole map, 30 smaller ones crowded into 3 m x 3 m of open floor
    row, col = np.unravel_index(np.argmax(clear), clear.shape)
    cx, cy = ox + (col + 0.5) * res, oy + (row + 0.5) * res
    crowd = StartConfig(region=(cx - 1.5, cx + 1.5, cy - 1.5, cy + 1.5))
    groups = [RobotGroupConfig(count=30, radius_m=0.2), RobotGroupConfig(count=30, radius_m=0.12, start=crowd)]
    poses = start_poses(grid, groups, rng, clear)
    x, y, th = poses[:, 0].copy(), poses[:, 1].copy(), poses[:, 2].copy()
    r = np.repeat([0.2, 0.12], 30)
    n = len(x)
    stalled = np.zeros(n, bool)
    total_stalls = 0
    closest = np.inf
    for step in range(400):
        v = rng.uniform(-0.3, 1.2, n)  # fast: up to 12 cm per 0.1 s step
        w = rng.uniform(-2.0, 2.0, n)
        pre, arc, turn = np.zeros(n), v * 0.1, w * 0.1
        x0, y0, th0 = x.copy(), y.copy(), th.copy()
        move_discs(x, y, th, r, pre, arc, turn, b, clear, geo, True, stalled)
        # never inside a wall or another robot
        dw = wall_distance_ref(b, ox, oy, res, x, y)
        assert np.all(dw >= r - 1e-9), f"step {step}: penetration {np.min(dw - r)}"
        gap = pair_gaps(x, y, r)
        assert gap >= -1e-9
        closest = min(closest, gap)
        # stall flag exactly when the commanded path was blocked (sequential, index order)
        for i in np.flatnonzero(~stalled):
            ex, ey, eth = arc_point(x0[i], y0[i], th0[i], arc[i], turn[i], 1.0)
            assert (x[i], y[i]) == (ex, ey) and th[i] == pytest.approx(wrap(eth), abs=1e-12)
        for i in range(n) if step % 40 == 0 else ():
            ox_ = np.concatenate([x[:i], x0[i + 1:]])
            oy_ = np.concatenate([y[:i], y0[i + 1:]])
            or_ = np.concatenate([r[:i], r[i + 1:]])
            assert stalled[i] == path_blocked_ref(b, clear, geo, x0[i], y0[i], th0[i], arc[i], turn[i], r[i], ox_, oy_, or_)
        total_stalls += int(stalled.sum())
    assert total_stalls > 100 and closest < 0.01  # the test really drove into walls and into robots


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_hypothesis_crowd_in_a_box_never_overlaps(seed):
    rng = np.random.default_rng(seed)
    cells = np.zeros((30, 30), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    cells[10:20, 14:16] = WALL
    g = OccupancyGrid(cells, 0.1)
    b = g.blocking(None)
    clear = distance_field(b, 0.1)
    geo = np.array([0.0, 0.0, 0.1])
    from teamnav.sim.config import RobotGroupConfig
    from teamnav.sim.start import start_poses

    poses = start_poses(g, [RobotGroupConfig(count=12, radius_m=0.15)], rng, clear)
    x, y, th = poses[:, 0].copy(), poses[:, 1].copy(), poses[:, 2].copy()
    r = np.full(12, 0.15)
    stalled = np.zeros(12, bool)
    for _ in range(30):
        arc = rng.uniform(-0.2, 0.6, 12)
        turn = rng.uniform(-1, 1, 12)
        move_discs(x, y, th, r, np.zeros(12), arc, turn, b, clear, geo, True, stalled)
        assert np.all(wall_distance_ref(b, 0.0, 0.0, 0.1, x, y) >= r - 1e-9)
        assert pair_gaps(x, y, r) >= -1e-9


def test_discs_hit_walls_touching_is_allowed():
    b = np.zeros((10, 10), np.uint8)
    b[:, 5] = 1  # wall square x in [0.625, 0.75) (binary fractions: exact arithmetic)
    clear = distance_field(b, 0.125)
    xs = np.array([0.375, 0.375 + 1e-9, 0.25, 0.2])
    hit = discs_hit_walls(b, clear, (0.0, 0.0, 0.125), xs, np.full(4, 0.625), np.full(4, 0.25))
    assert hit.tolist() == [False, True, False, True]  # 0.2 - 0.25 < 0: leaves the map


def _move_reference(blocking, clear, geo, x, y, th, r, pre, arc, turn):
    """move_discs written out without a hash: robot i against every other disc where it is now
    (the kernel's own arithmetic), in index order."""
    x, y, th = x.copy(), y.copy(), th.copy()
    stalled = np.zeros(len(x), bool)
    for i in range(len(x)):
        th0 = th[i] + pre[i]
        if arc[i] != 0.0:
            n = max(1, math.ceil(abs(arc[i]) / (SUBSTEP_FRACTION * r[i])))
            bx, by = x[i], y[i]
            for k in range(1, n + 1):
                px, py, _ = arc_point(x[i], y[i], th0, arc[i], turn[i], k / n)
                hit = bool(discs_hit_walls(blocking, clear, geo, np.array([px]), np.array([py]), np.array([r[i]]))[0])
                for j in range(len(x)):
                    dx, dy, rr = px - x[j], py - y[j], r[i] + r[j]
                    if j != i and dx * dx + dy * dy < rr * rr:
                        hit = True
                if hit:
                    stalled[i] = True
                    break
                bx, by = px, py
            x[i], y[i] = bx, by
        th[i] = wrap(th0 + turn[i])
    return x, y, th, stalled


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_move_discs_hash_finds_every_contact(seed):
    """The hash only chooses which robots are tested: a crowd of mixed sizes and arcs (some
    standing, some parked far outside the map, many touching) moves exactly as with every
    robot tested against every other."""
    rng = np.random.default_rng(seed)
    cells = np.zeros((60, 60), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    g = OccupancyGrid(cells, 0.1)
    b = g.blocking(None)
    clear = distance_field(b, 0.1)
    geo = np.array([0.0, 0.0, 0.1])
    n = int(rng.integers(2, 150))
    r = rng.choice([0.02, 0.05, 0.1, 0.3]) * rng.uniform(0.5, 1.0, n)
    x, y = rng.uniform(0.5, 5.5, n), rng.uniform(0.5, 5.5, n)
    if rng.random() < 0.5:  # a tight crowd: many pairs in contact or within one arc
        x, y = rng.uniform(2.5, 3.5, n), rng.uniform(2.5, 3.5, n)
    if rng.random() < 0.5:
        r[:] = r[0]  # one size: the reach of the look-up is as tight as it gets
    th = rng.uniform(-4, 4, n)
    arc = rng.uniform(-1.0, 1.5, n) * r * rng.choice([0.0, 0.5, 2.0], n)
    for i in range(1, n):  # most robots just out of reach of an earlier one, in any direction
        if rng.random() < 0.7:
            j = int(rng.integers(0, i))
            d = r[i] + r[j] + rng.uniform(0.0, 1.0) * (abs(arc[i]) + abs(arc[j])) + rng.choice([0.0, 1e-12, 1e-3])
            a = rng.uniform(-math.pi, math.pi)
            x[i], y[i] = x[j] + d * math.cos(a), y[j] + d * math.sin(a)
            th[i] = a + math.pi + rng.uniform(-0.5, 0.5)  # heading back towards it
    park = (rng.random(n) < 0.1) & (rng.random() < 0.3)  # in some crowds: the hashed buckets
    x[park], y[park], arc[park] = 1e6 + np.arange(park.sum()), -1e6, 0.0  # waiting robots, parked
    turn = rng.uniform(-1.5, 1.5, n)
    pre = np.where(rng.random(n) < 0.2, rng.uniform(-1, 1, n), 0.0)
    want = _move_reference(b, clear, geo, x, y, th, r, pre, arc, turn)
    stalled = np.zeros(n, bool)
    move_discs(x, y, th, r, pre, arc, turn, b, clear, geo, True, stalled)
    for got, ref in zip((x, y, th, stalled), want):
        np.testing.assert_array_equal(got, ref)


@pytest.mark.parametrize("layout", ["dense", "hashed"])
def test_move_discs_contact_at_the_edge_of_the_look_up_in_every_direction(layout):
    """Robot 1 drives straight at robot 0, whose disc it reaches just before the end of its
    arc (start points 2r + arc - 1 nm apart), in 16 directions and from 40 places across the
    cells of the grid of start points: it always stalls, as with every robot tested against
    every other. "dense": still robots spread over the arena (the grid spans their box);
    "hashed": one robot parked far away (the buckets are hashed)."""
    cells = np.zeros((200, 200), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = WALL
    g = OccupancyGrid(cells, 0.1)
    b = g.blocking(None)
    clear = distance_field(b, 0.1)
    geo = np.array([0.0, 0.0, 0.1])
    rad, a = 0.08, 0.05
    rng = np.random.default_rng(3)
    if layout == "dense":
        fill_x = np.concatenate([[1.0, 19.0], rng.uniform(1.0, 19.0, 60)])
        fill_y = np.concatenate([[1.0, 19.0], rng.uniform(10.0, 19.0, 60)])
    else:
        fill_x, fill_y = np.array([1e6]), np.array([-1e6])
    for k in range(16):
        phi = k * math.pi / 8
        for s in np.linspace(0.0, 2.1, 40):
            d = 2 * rad + a - 1e-9
            x1, y1 = 5.0 + s, 5.0 + 0.77 * s
            x = np.concatenate([[x1 + d * math.cos(phi), x1], fill_x])
            y = np.concatenate([[y1 + d * math.sin(phi), y1], fill_y])
            n = x.shape[0]
            th = np.zeros(n)
            th[1] = phi
            arc = np.zeros(n)
            arc[1] = a
            r = np.full(n, rad)
            want = _move_reference(b, clear, geo, x, y, th, r, np.zeros(n), arc, np.zeros(n))
            stalled = np.zeros(n, bool)
            move_discs(x, y, th, r, np.zeros(n), arc, np.zeros(n), b, clear, geo, True, stalled)
            assert stalled[1] and want[3][1]
            np.testing.assert_array_equal(x, want[0])
            np.testing.assert_array_equal(y, want[1])
