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

Faults (:mod:`teamnav.sim.faults`; only when a scenario lists them): ``send(..., muted=,
blocked=)`` and ``collect(muted=, blocked=)``. A muted robot (dead, or its radio failed) sends
nothing (its messages are not counted as sent) and hears nothing; a blocked radio (a blackout)
carries nothing: what is sent then is not sent, what is due then is not delivered. The counts
of what faults stopped appear under ``"faults"`` in :meth:`Radio.counts` once a fault has
touched the radio, and never otherwise.

Bandwidth cap (``RadioConfig.bandwidth_bps``, ours: no paper caps its radio; None, unlimited,
is the papers' rule): each sender has a token bucket of bytes, full (``bandwidth_bps *
bandwidth_burst_s``) at the start and refilled at each step ``k`` by ``bandwidth_bps * dt_s``
per step since its last refill, never above the burst. A message that fits goes out and takes
its ``size_bytes`` from the bucket; one that does not is dropped at the sender: not sent, no
loss drawn for it, counted under ``"over_cap"`` (messages and bytes, per robot) in
:meth:`Radio.counts` (present only when a cap is set). So over any window of steps ``a..b`` a
sender transmits at most ``burst + bandwidth_bps * dt_s * (b - a)`` bytes. Faults come first:
a muted or blacked-out sender's messages never reach the bucket.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
from numba import njit

from teamnav.control.types import Message
from teamnav.world.grid import OccupancyGrid
from teamnav.world.los import _PARALLEL_MIN_SEGMENTS, _los_kernel, _los_kernel_serial, _segment_visible
from teamnav.world.raycast import _check_blocking

__all__ = ["Radio"]

_MODE_CODE = {"broadcast": 0, "range": 1, "line_of_sight": 2}

#: Teams whose sender-receiver pairs number at most this go through :func:`_receivers_kernel`
#: (one call instead of ~15 small numpy operations); larger ones keep the numpy path, whose
#: line-of-sight kernel runs in parallel from ``_PARALLEL_MIN_SEGMENTS`` pairs on.
_KERNEL_MAX_PAIRS = 256
_NO_MAP = np.zeros((1, 1), dtype=np.uint8)  # the kernel's map argument when no mode needs one


@njit(cache=True)
def _receivers_kernel(blocking, ox, oy, inv, xs, ys, sidx, r2, mode, ok):
    """:meth:`Radio._receivers_of` in one pass (same arithmetic, same answers): ``ok[k, j]``
    is whether robot ``j`` hears sender ``sidx[k]``; ``mode`` 0 broadcast, 1 range, 2 line
    of sight (range first, then the segment through ``blocking`` as ``line_of_sight``)."""
    n = xs.shape[0]
    for k in range(sidx.shape[0]):
        s = sidx[k]
        sx = xs[s]
        sy = ys[s]
        for j in range(n):
            if mode == 0:
                hear = True
            else:
                dx = xs[j] - sx
                dy = ys[j] - sy
                hear = dx * dx + dy * dy <= r2
                if hear and mode == 2 and j != s:
                    hear = _segment_visible(blocking, (sx - ox) * inv, (sy - oy) * inv, (xs[j] - ox) * inv,
                                            (ys[j] - oy) * inv)
            ok[k, j] = hear
        ok[k, s] = False


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
    dt_s : float, optional
        The step [s]; required with a bandwidth cap (``cfg.bandwidth_bps``), which refills
        ``bandwidth_bps * dt_s`` bytes per step.

    Examples
    --------
    >>> from teamnav.sim.config import RadioConfig
    >>> r = Radio(RadioConfig(mode="range", range_m=2.0), OccupancyGrid.empty(10, 10, 0.5), 3,
    ...           np.random.default_rng(0))
    >>> r.send([(0, Message(0, 0.0, "hi"))], np.array([1.0, 2.0, 8.0]), np.array([1.0, 1.0, 1.0]))
    >>> [len(box) for box in r.collect()]
    [0, 1, 0]
    """

    def __init__(self, cfg, grid: OccupancyGrid, n_robots: int, rng: np.random.Generator, *,
                 dt_s: float | None = None) -> None:
        if n_robots < 1:
            raise ValueError(f"n_robots must be >= 1, got {n_robots!r}")
        cap = getattr(cfg, "bandwidth_bps", None)
        if cap is not None and not (dt_s is not None and math.isfinite(dt_s) and dt_s > 0.0):
            raise ValueError(f"dt_s: a radio with bandwidth_bps={cap!r} needs the step, a finite number > 0 [s]; "
                             f"got {dt_s!r}")
        self.cfg = cfg
        self.n = int(n_robots)
        self.rng = rng
        self._blocking = grid.blocking(cfg.sees) if cfg.mode == "line_of_sight" else None
        self._grid = grid
        self._geo = (grid.origin_xy_m[0], grid.origin_xy_m[1], grid.resolution_m)
        if self._blocking is not None:
            self._blocking = _check_blocking(self._blocking)
        # a rotated map: positions go to the kernels in the grid's local frame, origin (0, 0)
        ox, oy = (0.0, 0.0) if grid.rotated else (float(self._geo[0]), float(self._geo[1]))
        self._geo_inv = (ox, oy, 1.0 / float(self._geo[2]))
        # per-robot counts as Python ints (a numpy scalar update costs more than the rest of a
        # delivery); read as int64 arrays through the properties below
        self._sent_messages = [0] * self.n
        self._sent_bytes = [0] * self.n
        self._delivered_messages = [0] * self.n
        self._delivered_bytes = [0] * self.n
        self.lost = 0
        self.by_kind: dict[str, int] = {}
        self._pending: list[list[tuple[Message, int]]] = [[] for _ in range(self.n)]
        self.has_pending = False
        #: what faults stopped (None until a fault touches the radio): messages not sent
        #: (their sender muted, or a blackout) and deliveries dropped (receiver muted, blackout)
        self.fault_counts: dict[str, int] | None = None
        #: the bandwidth cap (None: unlimited): bytes per step, burst, each sender's bucket and
        #: the step it was last refilled at, and what the cap dropped per sender
        self._cap = cap
        if cap is not None:
            self._refill = float(cap) * float(dt_s)
            self._burst = float(cap) * float(cfg.bandwidth_burst_s)
            self._tokens = [self._burst] * self.n
            self._refilled_at = [0] * self.n
            self._over_messages = [0] * self.n
            self._over_bytes = [0] * self.n

    @property
    def sent_messages(self) -> np.ndarray:
        """int64 (N,): messages each robot sent."""
        return np.array(self._sent_messages, dtype=np.int64)

    @property
    def sent_bytes(self) -> np.ndarray:
        """int64 (N,): bytes each robot sent (:meth:`Message.size_bytes`)."""
        return np.array(self._sent_bytes, dtype=np.int64)

    @property
    def delivered_messages(self) -> np.ndarray:
        """int64 (N,): messages delivered to each robot (in its inbox)."""
        return np.array(self._delivered_messages, dtype=np.int64)

    @property
    def delivered_bytes(self) -> np.ndarray:
        """int64 (N,): bytes delivered to each robot."""
        return np.array(self._delivered_bytes, dtype=np.int64)

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
        if mode == "line_of_sight" and self._grid.rotated:
            xs, ys = self._grid.kernel_frame(xs, ys)[:2]  # distances do not change
        if sidx.shape[0] * self.n <= _KERNEL_MAX_PAIRS:
            ok = np.empty((sidx.shape[0], self.n), dtype=np.bool_)
            blocking = self._blocking if self._blocking is not None else _NO_MAP
            ox, oy, inv = self._geo_inv
            r = self.cfg.range_m
            _receivers_kernel(blocking, ox, oy, inv, np.ascontiguousarray(xs, dtype=np.float64),
                              np.ascontiguousarray(ys, dtype=np.float64), sidx,
                              0.0 if mode == "broadcast" else r * r, _MODE_CODE[mode], ok)
            return ok
        return self._receivers_of_numpy(sidx, xs, ys)

    def _receivers_of_numpy(self, sidx: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        """:meth:`_receivers_of` with numpy (large teams; the reference of the kernel's tests)."""
        mode = self.cfg.mode
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

    def _fault_count(self, key: str, k: int) -> None:
        if self.fault_counts is None:
            self.fault_counts = {"messages_not_sent": 0, "deliveries_dropped": 0}
        self.fault_counts[key] += int(k)

    def _within_cap(self, outgoing: Sequence[tuple[int, Message]], step: int) -> list[tuple[int, Message]]:
        """The messages of ``outgoing`` that fit their sender's bucket at ``step`` (in order);
        the others are counted as over the cap (see the module docstring)."""
        kept = []
        tokens, at = self._tokens, self._refilled_at
        for s, msg in outgoing:
            if not isinstance(msg, Message):
                raise ValueError(f"robot {s}'s outbox must hold Message objects, got {type(msg).__name__}")
            s = int(s)
            if at[s] != step:
                tokens[s] = min(self._burst, tokens[s] + self._refill * (step - at[s]))
                at[s] = step
            size = msg.size_bytes()
            if size <= tokens[s]:
                tokens[s] -= size
                kept.append((s, msg))
            else:
                self._over_messages[s] += 1
                self._over_bytes[s] += size
        return kept

    def send(self, outgoing: Sequence[tuple[int, Message]], xs: np.ndarray, ys: np.ndarray, *,
             muted: np.ndarray | None = None, blocked: bool = False, step: int | None = None) -> None:
        """Queue messages sent this step for delivery at the next :meth:`collect`.

        Parameters
        ----------
        outgoing : sequence of (sender index, Message)
            In sending order (the engine lists robots by id, each robot's outbox in order).
        xs, ys : ndarray of shape (N,)
            True positions now [m].
        muted : ndarray of shape (N,), bool, optional
            Robots whose radio is off (faults): their messages are not sent, nobody hears them
            and they hear nobody.
        blocked : bool
            The radio carries nothing now (a blackout): no message is sent.
        step : int, optional
            The step index now; required with a bandwidth cap (its buckets refill per step,
            and steps must not go back).
        """
        if not outgoing:
            return
        if blocked:
            self._fault_count("messages_not_sent", len(outgoing))
            return
        if muted is not None:
            kept = [(s, m) for s, m in outgoing if not muted[int(s)]]
            if len(kept) < len(outgoing):
                self._fault_count("messages_not_sent", len(outgoing) - len(kept))
            outgoing = kept
            if not outgoing:
                return
        if self._cap is not None:
            if step is None or step < max(self._refilled_at):
                raise ValueError(f"step: a radio with bandwidth_bps={self._cap!r} needs the step index now, an int "
                                 f">= the last one sent at ({max(self._refilled_at)}); got {step!r}")
            outgoing = self._within_cap(outgoing, int(step))
            if not outgoing:
                return
        senders = sorted({int(s) for s, _ in outgoing})
        ok = self._receivers_of(senders, xs, ys)
        if muted is not None:
            ok &= ~np.asarray(muted, dtype=bool)[None, :]
        hears = dict(zip(senders, ok.tolist()))
        listeners: dict[int, list[int]] = {}  # sender -> the robots that hear its broadcasts
        p_loss = self.cfg.p_loss
        n = self.n
        by_kind = self.by_kind
        pending = self._pending
        for s, msg in outgoing:
            if not isinstance(msg, Message):
                raise ValueError(f"robot {s}'s outbox must hold Message objects, got {type(msg).__name__}")
            s = int(s)
            size = msg.size_bytes()
            self._sent_messages[s] += 1
            self._sent_bytes[s] += size
            by_kind[msg.kind] = by_kind.get(msg.kind, 0) + 1
            to = msg.to
            if to is not None:
                idx = [int(to)] if isinstance(to, (int, np.integer)) and 0 <= to < n and hears[s][to] else []
            else:
                idx = listeners.get(s)
                if idx is None:
                    idx = listeners[s] = [j for j, hear in enumerate(hears[s]) if hear]
            if p_loss > 0.0 and idx:
                keep = (self.rng.random(len(idx)) >= p_loss).tolist()
                self.lost += len(idx) - sum(keep)
                idx = [r for r, k in zip(idx, keep) if k]
            for r in idx:
                pending[r].append((msg, size))
            if idx:
                self.has_pending = True

    def collect(self, *, muted: np.ndarray | None = None, blocked: bool = False) -> list[tuple[Message, ...]]:
        """Inboxes for this step (messages sent last step), one tuple per robot, and clear them.

        With ``blocked`` (a blackout) every pending delivery is dropped; a ``muted`` robot's
        (faults) are dropped.
        """
        if not self.has_pending:
            return [()] * self.n
        if blocked or muted is not None:
            drop = sum(len(p) for r, p in enumerate(self._pending) if blocked or muted[r])
            if drop:
                self._fault_count("deliveries_dropped", drop)
                self._pending = [[] if blocked or muted[r] else p for r, p in enumerate(self._pending)]
        boxes = []
        for r, pend in enumerate(self._pending):
            if pend:
                self._delivered_messages[r] += len(pend)
                self._delivered_bytes[r] += sum(size for _, size in pend)
                boxes.append(tuple(m for m, _ in pend))
            else:
                boxes.append(())
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
            **({"faults": dict(self.fault_counts)} if self.fault_counts is not None else {}),
            **({"over_cap": self.over_cap()} if self._cap is not None else {}),
        }

    def over_cap(self) -> dict:
        """What the bandwidth cap dropped: ``messages``, ``bytes`` and ``per_robot`` lists of
        both, with the cap ``bandwidth_bps`` (zeros without a cap)."""
        om = self._over_messages if self._cap is not None else [0] * self.n
        ob = self._over_bytes if self._cap is not None else [0] * self.n
        return {"bandwidth_bps": self._cap, "burst_bytes": self._burst if self._cap is not None else None,
                "messages": int(sum(om)), "bytes": int(sum(ob)),
                "per_robot": {"messages": list(om), "bytes": list(ob)}}
