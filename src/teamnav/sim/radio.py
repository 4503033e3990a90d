"""The radio: who hears which message, one step later, with losses and traffic counts.

Modes (``RadioConfig.mode``):

- ``"broadcast"``: every other robot hears it;
- ``"range"``: robots whose centre is within ``range_m`` of the sender's (inclusive);
- ``"line_of_sight"``: within ``range_m`` *and* in line of sight through the cells the radio
  ``sees`` (:func:`teamnav.world.los.line_of_sight`, the same kernel as
  :func:`~teamnav.world.los.visible_pairs`, run only on the sender–receiver pairs in range):
  Sgorbissa & Arkin's robots talk only while they see each other (§3).

Rules:

- A message sent at step ``k`` is delivered at step ``k + 1`` (it is in the inbox of the
  observation of step ``k + 1``). Who can hear it is decided **when it is sent**, from the
  true positions at step ``k`` (the positions the sender observed from).
- ``Message.to`` restricts delivery to that robot (still subject to mode and loss); an
  address that is not a robot id reaches nobody.
- A sender never hears itself. The sending robot is the one whose outbox held the message
  (the ``sender`` field a brain wrote is not trusted for geometry).
- Each (message, receiver) delivery is lost independently with probability ``p_loss``.
- Counted per robot: messages and bytes (:meth:`Message.size_bytes`) sent, and messages and
  bytes delivered to it (counted when they reach its inbox, so messages still in the air
  when a run ends are not delivered); and in total, deliveries lost.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from teamnav.control.types import Message
from teamnav.world.grid import OccupancyGrid
from teamnav.world.los import _PARALLEL_MIN_SEGMENTS, _los_kernel, _los_kernel_serial
from teamnav.world.raycast import _check_blocking

__all__ = ["Radio"]


class Radio:
    """The comm model of one run.

    Parameters
    ----------
    cfg : RadioConfig
    grid : OccupancyGrid
        The true map (for line of sight).
    n_robots : int
    rng : numpy.random.Generator
        The radio's loss stream.

    Examples
    --------
    >>> from teamnav.sim.config import RadioConfig
    >>> r = Radio(RadioConfig(mode="range", range_m=2.0), OccupancyGrid.empty(10, 10, 0.5), 3,
    ...           np.random.default_rng(0))
    >>> r.send([(0, Message(0, 0.0, "hi"))], np.array([1.0, 2.0, 8.0]), np.array([1.0, 1.0, 1.0]))
    >>> [len(box) for box in r.collect()]
    [0, 1, 0]
    """

    def __init__(self, cfg, grid: OccupancyGrid, n_robots: int, rng: np.random.Generator) -> None:
        if n_robots < 1:
            raise ValueError(f"n_robots must be >= 1, got {n_robots!r}")
        self.cfg = cfg
        self.n = int(n_robots)
        self.rng = rng
        self._blocking = grid.blocking(cfg.sees) if cfg.mode == "line_of_sight" else None
        self._geo = (grid.origin_xy_m[0], grid.origin_xy_m[1], grid.resolution_m)
        if self._blocking is not None:
            self._blocking = _check_blocking(self._blocking)
        self._geo_inv = (float(self._geo[0]), float(self._geo[1]), 1.0 / float(self._geo[2]))
        self.sent_messages = np.zeros(self.n, np.int64)
        self.sent_bytes = np.zeros(self.n, np.int64)
        self.delivered_messages = np.zeros(self.n, np.int64)
        self.delivered_bytes = np.zeros(self.n, np.int64)
        self.lost = 0
        self.by_kind: dict[str, int] = {}
        self._pending: list[list[tuple[Message, int]]] = [[] for _ in range(self.n)]
        self.has_pending = False

    def _receivers(self, s: int, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Bool (N,): robots that can hear sender ``s`` now (mode only; no loss, no address)."""
        return self._receivers_of([s], xs, ys)[0]

    def _receivers_of(self, senders: list[int], xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """Bool (S, N): row k, the robots that can hear ``senders[k]`` now (mode only).

        In range: ``(x - x_s)**2 + (y - y_s)**2 <= range_m**2``; in line of sight: the
        segment from the sender to the receiver is clear (one kernel call for every
        sender–receiver pair in range).
        """
        mode = self.cfg.mode
        sidx = np.asarray(senders, dtype=np.int64)
        rows = np.arange(sidx.shape[0])
        if mode == "broadcast":
            ok = np.ones((sidx.shape[0], self.n), dtype=bool)
        else:
            r = self.cfg.range_m
            ok = (xs[None, :] - xs[sidx][:, None]) ** 2 + (ys[None, :] - ys[sidx][:, None]) ** 2 <= r * r
            if mode == "line_of_sight":
                ok[rows, sidx] = False
                k, j = np.nonzero(ok)
                if k.size:
                    # line_of_sight's kernels, called directly: the map was checked once in __init__
                    ox, oy, inv = self._geo_inv
                    seen = np.empty(k.size, dtype=np.bool_)
                    kernel = _los_kernel if k.size >= _PARALLEL_MIN_SEGMENTS else _los_kernel_serial
                    s_of = sidx[k]
                    kernel(self._blocking, ox, oy, inv, np.ascontiguousarray(xs[s_of], dtype=np.float64),
                           np.ascontiguousarray(ys[s_of], dtype=np.float64), np.ascontiguousarray(xs[j], dtype=np.float64),
                           np.ascontiguousarray(ys[j], dtype=np.float64), seen)
                    ok[k[~seen], j[~seen]] = False
        ok[rows, sidx] = False
        return ok

    def send(self, outgoing: Sequence[tuple[int, Message]], xs: np.ndarray, ys: np.ndarray) -> None:
        """Queue messages sent this step for delivery at the next :meth:`collect`.

        Parameters
        ----------
        outgoing : sequence of (sender index, Message)
            In sending order (the engine lists robots by id, each robot's outbox in order).
        xs, ys : ndarray of shape (N,)
            True positions now [m].
        """
        if not outgoing:
            return
        cache: dict[int, np.ndarray] = {}
        senders = sorted({int(s) for s, _ in outgoing})
        for s, ok in zip(senders, self._receivers_of(senders, xs, ys)):
            cache[s] = ok
        p_loss = self.cfg.p_loss
        for s, msg in outgoing:
            if not isinstance(msg, Message):
                raise ValueError(f"robot {s}'s outbox must hold Message objects, got {type(msg).__name__}")
            size = msg.size_bytes()
            self.sent_messages[s] += 1
            self.sent_bytes[s] += size
            self.by_kind[msg.kind] = self.by_kind.get(msg.kind, 0) + 1
            ok = cache[int(s)]
            if msg.to is not None:
                to = msg.to
                hear = np.zeros(self.n, dtype=bool)
                if isinstance(to, (int, np.integer)) and 0 <= to < self.n:
                    hear[to] = ok[to]
                idx = np.flatnonzero(hear)
            else:
                idx = np.flatnonzero(ok)
            if p_loss > 0.0 and idx.size:
                keep = self.rng.random(idx.size) >= p_loss
                self.lost += int(idx.size - keep.sum())
                idx = idx[keep]
            for r in idx.tolist():
                self._pending[r].append((msg, size))
            self.has_pending = self.has_pending or idx.size > 0

    def collect(self) -> list[tuple[Message, ...]]:
        """Inboxes for this step (messages sent last step), one tuple per robot, and clear them."""
        if not self.has_pending:
            return [()] * self.n
        boxes = []
        for r, pend in enumerate(self._pending):
            if pend:
                self.delivered_messages[r] += len(pend)
                self.delivered_bytes[r] += sum(size for _, size in pend)
            boxes.append(tuple(m for m, _ in pend))
        self._pending = [[] for _ in range(self.n)]
        self.has_pending = False
        return boxes

    def counts(self) -> dict:
        """Traffic totals and per-robot counts (JSON-ready)."""
        return {
            "mode": self.cfg.mode,
            "messages_sent": int(self.sent_messages.sum()),
            "bytes_sent": int(self.sent_bytes.sum()),
            "messages_delivered": int(self.delivered_messages.sum()),
            "bytes_delivered": int(self.delivered_bytes.sum()),
            "deliveries_lost": int(self.lost),
            "sent_by_kind": dict(sorted(self.by_kind.items())),
            "per_robot": {
                "messages_sent": self.sent_messages.tolist(),
                "bytes_sent": self.sent_bytes.tolist(),
                "messages_delivered": self.delivered_messages.tolist(),
                "bytes_delivered": self.delivered_bytes.tolist(),
            },
        }
