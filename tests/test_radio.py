"""Radio: who hears a message (broadcast, range, line of sight, address), loss, traffic counts."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.types import Message
from teamnav.sim.config import RadioConfig
from teamnav.sim.radio import Radio
from teamnav.world.grid import WALL, OccupancyGrid


def _grid():
    cells = np.zeros((20, 40), np.uint8)
    cells[:, 20] = WALL  # a wall at x in [2.0, 2.1)
    return OccupancyGrid(cells, 0.1)


# robots 0, 1 left of the wall (1 m apart), 2 right of it, 3 far left
XS = np.array([0.5, 1.5, 3.0, 0.5])
YS = np.array([1.0, 1.0, 1.0, 1.9])


def _radio(**kw):
    return Radio(RadioConfig(**kw), _grid(), 4, np.random.default_rng(0))


def _heard(radio, sender=0, to=None):
    radio.send([(sender, Message(sender, 0.0, {"x": 1.0}, to=to))], XS, YS)
    return [len(b) for b in radio.collect()]


def test_broadcast_reaches_everyone_but_the_sender():
    assert _heard(_radio(mode="broadcast")) == [0, 1, 1, 1]


def test_range_mode_is_inclusive_and_cuts_off():
    assert _heard(_radio(mode="range", range_m=1.0)) == [0, 1, 0, 1]  # robot 1 at exactly 1.0 m
    assert _heard(_radio(mode="range", range_m=0.99)) == [0, 0, 0, 1]


def test_line_of_sight_mode_needs_range_and_sight():
    assert _heard(_radio(mode="line_of_sight", range_m=10.0)) == [0, 1, 0, 1]  # the wall hides robot 2
    assert _heard(_radio(mode="line_of_sight", range_m=10.0, sees=("unknown",))) == [0, 1, 1, 1]  # radio sees no walls
    assert _heard(_radio(mode="line_of_sight", range_m=0.95)) == [0, 0, 0, 1]


def test_address_restricts_delivery():
    r = _radio(mode="broadcast")
    assert _heard(r, to=2) == [0, 0, 1, 0]
    assert _heard(r, to=0) == [0, 0, 0, 0]  # a sender never hears itself
    assert _heard(r, to=17) == [0, 0, 0, 0]  # no such robot
    assert _heard(_radio(mode="line_of_sight", range_m=10.0), to=2) == [0, 0, 0, 0]  # mode still applies


def test_messages_arrive_once_at_the_next_collect():
    r = _radio()
    msg = Message(1, 0.5, "hello", kind="hi")
    r.send([(1, msg)], XS, YS)
    boxes = r.collect()
    assert boxes[0] == (msg,) and boxes[1] == () and boxes[2] == (msg,)
    assert r.collect() == [(), (), (), ()]


def test_counts_messages_and_bytes():
    r = _radio()
    m = Message(0, 0.0, np.zeros(4))  # 24 header + 32 body bytes
    r.send([(0, m), (0, m), (2, Message(2, 0.0, "ab", to=1))], XS, YS)
    r.collect()
    c = r.counts()
    assert c["messages_sent"] == 3 and c["bytes_sent"] == 56 * 2 + 26
    assert c["per_robot"]["messages_sent"] == [2, 0, 1, 0]
    assert c["per_robot"]["messages_delivered"] == [0, 3, 2, 2]
    assert c["per_robot"]["bytes_delivered"] == [0, 56 * 2 + 26, 112, 112]
    assert c["messages_delivered"] == 7 and c["deliveries_lost"] == 0


@pytest.mark.parametrize("p_loss", [0.0, 0.3, 1.0])
def test_loss_rate(p_loss):
    n = 50
    radio = Radio(RadioConfig(p_loss=p_loss), _grid(), n, np.random.default_rng(4))
    xs = np.linspace(0.2, 1.8, n)
    ys = np.full(n, 0.5)
    for k in range(40):
        radio.send([(k % n, Message(k % n, 0.0, k))], xs, ys)
        radio.collect()
    c = radio.counts()
    attempts = 40 * (n - 1)
    assert c["messages_delivered"] + c["deliveries_lost"] == attempts
    assert c["deliveries_lost"] / attempts == pytest.approx(p_loss, abs=0.03)


def test_loss_is_seeded():
    def run(seed):
        radio = Radio(RadioConfig(p_loss=0.5), _grid(), 4, np.random.default_rng(seed))
        out = []
        for _ in range(20):
            radio.send([(0, Message(0, 0.0, 1))], XS, YS)
            out.append([len(b) for b in radio.collect()])
        return out

    assert run(1) == run(1) and run(1) != run(2)


def test_outbox_must_hold_messages():
    with pytest.raises(ValueError, match="Message"):
        _radio().send([(0, "not a message")], XS, YS)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 12), st.sampled_from(["broadcast", "range", "line_of_sight"]))
def test_receivers_of_many_senders_equal_one_sender_at_a_time(seed, n, mode):
    """All senders' receivers in one call equal the rule applied sender by sender: in range
    ``(x - x_s)**2 + (y - y_s)**2 <= range_m**2``, in sight by :func:`line_of_sight`, never the sender."""
    from teamnav.world.los import line_of_sight

    g = np.random.default_rng(seed)
    cells = np.zeros((80, 80), np.uint8)
    cells[40:42, 5:75] = WALL
    grid = OccupancyGrid(cells, 0.1)
    radio = Radio(RadioConfig(mode=mode, range_m=3.0), grid, n, np.random.default_rng(0))
    xs, ys = g.uniform(0.1, 7.9, n), g.uniform(0.1, 7.9, n)
    senders = sorted(set(g.integers(0, n, 3).tolist()))
    got = radio._receivers_of(senders, xs, ys)
    for k, s in enumerate(senders):
        want = np.ones(n, bool) if mode == "broadcast" else (xs - xs[s]) ** 2 + (ys - ys[s]) ** 2 <= 9.0
        want[s] = False
        if mode == "line_of_sight":
            idx = np.flatnonzero(want)
            seen = line_of_sight(grid.blocking(RadioConfig().sees), 0.0, 0.0, 0.1, np.full(idx.size, xs[s]),
                                 np.full(idx.size, ys[s]), xs[idx], ys[idx])
            want[idx[~seen]] = False
        assert np.array_equal(got[k], want), (s, got[k], want)
