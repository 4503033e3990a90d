"""The line-of-sight help message (Sgorbissa & Arkin §3.1, §4.4, §5) as one float64 row, for the
compiled team step (``docs/concepts/group-brains.md``, "Messages").

A compiled team writes and reads messages as rows of one array; the radio carries each row as a
message body (:class:`PackedLosMsg`), sized exactly as the :class:`~.messages.LosHelpMsg` it
stands for, so that traffic counts and bandwidth caps do not change. :func:`pack` and
:func:`unpack` convert between the two without loss (the tests run both ways), so compiled and
Python brains can share one radio.

Row layout for a team of at most ``m`` robots (``row_width(m)`` numbers; §4.4: O(M)):

- header ``H_*``: step, Tr (-1: not shared, 0, 1), and the counts of sightings, goals and
  reports;
- ``m`` sightings of 3 (robot id, bearing [rad], range [m]), from ``sightings_at(m)``;
- ``m`` goal terms of 4 (owner, Id, x, y in the sender's body frame), from ``goals_at(m)``;
- ``m`` reports of 6 (owner, Id, D, via x, via y, via D; NaN: a via field not sent), from
  ``reports_at(m)``.

Unused entries are NaN. Integers (ids, steps, counts) are exact in a float64 up to 2^53. The
``pose`` and ``pose_cov`` fields (the beyond section's ``frame_source`` other than
``"bearings"``) have no place in the row: those brains are not compiled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from teamnav.control.types import register_payload_sizer
from teamnav.papers.los_help.brains.messages import GoalShare, LosHelpMsg, Sighting, VisReport

__all__ = ["PackedLosMsg", "pack", "row_sizes", "row_width", "unpack"]

H_STEP = 0
H_TROUBLE = 1
H_N_SIGHT = 2
H_N_GOAL = 3
H_N_REPORT = 4
N_HEADER = 5
SIGHT_W = 3
GOAL_W = 4
REPORT_W = 6


def sightings_at(m: int) -> int:
    return N_HEADER


def goals_at(m: int) -> int:
    return N_HEADER + SIGHT_W * m


def reports_at(m: int) -> int:
    return N_HEADER + (SIGHT_W + GOAL_W) * m


def row_width(m: int) -> int:
    """Numbers in a row for a team of at most ``m`` robots."""
    return N_HEADER + (SIGHT_W + GOAL_W + REPORT_W) * m


@dataclass(frozen=True, slots=True, eq=False)
class PackedLosMsg:
    """A message body that is one packed row (read-only); sized as its :class:`LosHelpMsg`.

    ``size``: :meth:`size_bytes` computed once by the sender (-1: computed on each call; the
    radio sizes a message each time it sends or delivers it)."""

    row: np.ndarray
    size: int = -1

    @classmethod
    def sized(cls, row: np.ndarray) -> "PackedLosMsg":
        """A body for ``row`` that carries its size (:meth:`size_bytes`, computed once)."""
        return cls(row, cls(row).size_bytes())

    def size_bytes(self) -> int:
        """``payload_size_bytes`` of the :class:`LosHelpMsg` this row packs (its sizer's formula:
        8 for the step, 24 per sighting, 32 per goal, 24 per report and 8 per via field sent,
        1 for a Tr bit)."""
        if self.size >= 0:
            return self.size
        r = self.row
        m = (r.shape[0] - N_HEADER) // (SIGHT_W + GOAL_W + REPORT_W)
        n_r = int(r[H_N_REPORT])
        n = 8 + 24 * int(r[H_N_SIGHT]) + 32 * int(r[H_N_GOAL]) + 24 * n_r
        at = reports_at(m)
        for k in range(n_r):
            for j in (3, 4, 5):
                if not math.isnan(r[at + REPORT_W * k + j]):
                    n += 8
        if r[H_TROUBLE] >= 0:
            n += 1
        return n


register_payload_sizer(PackedLosMsg, PackedLosMsg.size_bytes)


@njit(cache=True)
def row_sizes(rows: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """:meth:`PackedLosMsg.size_bytes` of the rows ``rows[idx[i]]`` (a team's outgoing rows), in
    one call: the same formula, so the same integers (a test compares them). A team of 64 sends
    about 50 messages a step, each with up to 64 reports: sizing them one by one in Python was
    an O(robots²) loop of the compiled team step."""
    m = (rows.shape[1] - N_HEADER) // (SIGHT_W + GOAL_W + REPORT_W)
    at = N_HEADER + (SIGHT_W + GOAL_W) * m
    out = np.empty(idx.shape[0], dtype=np.int64)
    for i in range(idx.shape[0]):
        r = rows[idx[i]]
        n_r = int(r[H_N_REPORT])
        n = 8 + 24 * int(r[H_N_SIGHT]) + 32 * int(r[H_N_GOAL]) + 24 * n_r
        for k in range(n_r):
            for j in range(3, 6):
                if not math.isnan(r[at + REPORT_W * k + j]):
                    n += 8
        if r[H_TROUBLE] >= 0:
            n += 1
        out[i] = n
    return out


def pack(msg: LosHelpMsg, m: int) -> np.ndarray:
    """``msg`` as a row for a team of at most ``m`` robots (see the module docstring)."""
    if msg.pose is not None or msg.pose_cov is not None:
        raise ValueError("a packed row carries no pose (frame_source 'bearings' only)")
    sights, goals, reports = msg.sightings, msg.goals, msg.reports
    if max(len(sights), len(goals), len(reports)) > m:
        raise ValueError(f"more than m={m} sightings, goals or reports")
    # one list, one conversion (speed: a compiled team packs what R1's per-robot brain sends)
    nan = math.nan
    vals = [msg.step, -1.0 if msg.trouble is None else float(bool(msg.trouble)), len(sights), len(goals),
            len(reports)]
    for s in sights:
        vals += (s.robot_id, s.bearing_rad, s.range_m)
    vals += [nan] * (SIGHT_W * (m - len(sights)))
    for g in goals:
        vals += (g.owner, g.goal_id, g.gx_m, g.gy_m)
    vals += [nan] * (GOAL_W * (m - len(goals)))
    for r in reports:
        vals += (r.owner, r.goal_id, r.d_m, nan if r.via_x_m is None else r.via_x_m,
                 nan if r.via_y_m is None else r.via_y_m, nan if r.via_d_m is None else r.via_d_m)
    vals += [nan] * (REPORT_W * (m - len(reports)))
    return np.array(vals, dtype=np.float64)


def unpack(row: np.ndarray) -> LosHelpMsg:
    """The :class:`LosHelpMsg` a row packs (exactly: the same numbers, ints as ints)."""
    m = (row.shape[0] - N_HEADER) // (SIGHT_W + GOAL_W + REPORT_W)
    v = row.tolist()  # Python floats, read once (speed)
    tr = v[H_TROUBLE]
    at = sightings_at(m)
    sights = tuple([Sighting(int(v[e]), v[e + 1], v[e + 2]) for e in range(at, at + SIGHT_W * int(v[H_N_SIGHT]),
                                                                            SIGHT_W)])
    at = goals_at(m)
    goals = tuple([GoalShare(int(v[e]), int(v[e + 1]), v[e + 2], v[e + 3])
                   for e in range(at, at + GOAL_W * int(v[H_N_GOAL]), GOAL_W)])
    at = reports_at(m)
    reports = tuple([VisReport(int(v[e]), int(v[e + 1]), v[e + 2],
                               *[None if math.isnan(x) else x for x in v[e + 3:e + 6]])
                     for e in range(at, at + REPORT_W * int(v[H_N_REPORT]), REPORT_W)])
    return LosHelpMsg(int(v[H_STEP]), sights, goals, reports, None if tr < 0 else bool(tr))
