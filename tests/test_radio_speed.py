"""The radio's fast paths (H7a-2) deliver exactly what the numpy version did.

``Radio._receivers_of`` runs one numba kernel for small teams; ``_receivers_of_numpy`` (the
code it replaced, still used for large teams) is the reference. ``send``/``collect`` keep their
counts in Python ints and the robots that hear a sender once per step; the reference below is
the numpy ``send``/``collect`` they replaced, written out: same inboxes, counts, loss draws.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from teamnav.control.types import Message
from teamnav.sim.config import RadioConfig
from teamnav.sim.radio import _KERNEL_MAX_PAIRS, Radio
from teamnav.world.grid import WALL, OccupancyGrid

FAST = settings(max_examples=40, deadline=None)
modes = st.sampled_from(["broadcast", "range", "line_of_sight"])


def _grid(seed: int) -> OccupancyGrid:
    rng = np.random.default_rng(seed)
    cells = np.zeros((40, 60), np.uint8)
    cells[rng.random(cells.shape) < 0.04] = WALL
    cells[:, 30] = WALL
    cells[rng.integers(0, 40, 8), 30] = 0  # doors
    return OccupancyGrid(cells, 0.1, origin_xy_m=(-1.0, 0.5))


def _positions(rng, n):
    xs = rng.uniform(-1.5, 5.5, n)  # some robots off the map
    ys = rng.uniform(0.0, 5.0, n)
    xs[rng.random(n) < 0.2] = xs[0]  # ties
    return xs, ys


@given(st.integers(0, 2**32 - 1), st.integers(1, 12), modes, st.sampled_from([0.5, 1.5, 3.0, 1e9]))
@FAST
def test_receivers_kernel_equals_numpy(seed, n, mode, range_m):
    rng = np.random.default_rng(seed)
    radio = Radio(RadioConfig(mode=mode, range_m=range_m), _grid(seed), n, np.random.default_rng(0))
    xs, ys = _positions(rng, n)
    senders = sorted(set(rng.integers(0, n, rng.integers(1, n + 1)).tolist()))
    assert len(senders) * n <= _KERNEL_MAX_PAIRS
    got = radio._receivers_of(senders, xs, ys)
    want = radio._receivers_of_numpy(np.asarray(senders, np.int64), xs, ys)
    assert got.dtype == want.dtype and got.shape == want.shape
    assert np.array_equal(got, want)


class _Reference:
    """The numpy send/collect before H7a-2 (counts in int64 arrays, flatnonzero per message)."""

    def __init__(self, radio: Radio, n: int, p_loss: float, seed: int) -> None:
        self.radio, self.n, self.p_loss, self.rng = radio, n, p_loss, np.random.default_rng(seed)
        self.sent_messages = np.zeros(n, np.int64)
        self.sent_bytes = np.zeros(n, np.int64)
        self.delivered_messages = np.zeros(n, np.int64)
        self.delivered_bytes = np.zeros(n, np.int64)
        self.lost = 0
        self.pending = [[] for _ in range(n)]

    def send(self, outgoing, xs, ys):
        senders = sorted({int(s) for s, _ in outgoing})
        cache = dict(zip(senders, self.radio._receivers_of_numpy(np.asarray(senders, np.int64), xs, ys)))
        for s, msg in outgoing:
            size = msg.size_bytes()
            self.sent_messages[s] += 1
            self.sent_bytes[s] += size
            ok = cache[int(s)]
            if msg.to is not None:
                hear = np.zeros(self.n, dtype=bool)
                if isinstance(msg.to, (int, np.integer)) and 0 <= msg.to < self.n:
                    hear[msg.to] = ok[msg.to]
                idx = np.flatnonzero(hear)
            else:
                idx = np.flatnonzero(ok)
            if self.p_loss > 0.0 and idx.size:
                keep = self.rng.random(idx.size) >= self.p_loss
                self.lost += int(idx.size - keep.sum())
                idx = idx[keep]
            for r in idx.tolist():
                self.pending[r].append((msg, size))

    def collect(self):
        boxes = []
        for r, pend in enumerate(self.pending):
            if pend:
                self.delivered_messages[r] += len(pend)
                self.delivered_bytes[r] += sum(size for _, size in pend)
            boxes.append(tuple(m for m, _ in pend))
        self.pending = [[] for _ in range(self.n)]
        return boxes


@given(st.integers(0, 2**32 - 1), st.integers(1, 6), modes, st.sampled_from([0.0, 0.3]))
@settings(max_examples=25, deadline=None)
def test_send_and_collect_equal_the_numpy_version(seed, n, mode, p_loss):
    rng = np.random.default_rng(seed)
    radio = Radio(RadioConfig(mode=mode, range_m=2.0, p_loss=p_loss), _grid(seed), n, np.random.default_rng(seed))
    ref = _Reference(radio, n, p_loss, seed)
    for step in range(6):
        xs, ys = _positions(rng, n)
        outgoing = []
        for s in range(n):
            for k in range(int(rng.integers(0, 3))):
                to = None if rng.random() < 0.6 else int(rng.integers(-1, n + 1))  # some addresses nobody has
                outgoing.append((s, Message(s, 0.1 * step, (k, "x" * k, np.zeros(k)), to=to, kind=f"k{k}")))
        radio.send(outgoing, xs, ys)
        ref.send(outgoing, xs, ys)
        got, want = radio.collect(), ref.collect()
        assert [[id(m) for m in box] for box in got] == [[id(m) for m in box] for box in want]
    counts = radio.counts()["per_robot"]
    for key, name in (("messages_sent", "sent_messages"), ("bytes_sent", "sent_bytes"),
                      ("messages_delivered", "delivered_messages"), ("bytes_delivered", "delivered_bytes")):
        assert counts[key] == getattr(ref, name).tolist()
        assert np.array_equal(getattr(radio, name), getattr(ref, name)) and getattr(radio, name).dtype == np.int64
    assert radio.lost == ref.lost
