"""Message bodies of the line-of-sight help system (Sgorbissa & Arkin §3.1, §4.4, §5).

One robot broadcasts one :class:`LosHelpMsg` per step while it sees at least one teammate
(the radio in ``line_of_sight`` mode delivers it one step later only to robots in sight).
Its parts are exactly the terms §4.4 counts, so a message is O(M) for a team of M robots:

- ``sightings``: for every teammate the sender sees, the direction (and range) at which it sees
  it, in the sender's body frame. §3.1 item 2 ("the angle α_2i, corresponding to the
  direction in which R_1 sees R_i"): the receiver combines it with its own bearing of the
  sender to compute the frame between the two (θ21 = 180° + α21 − α12).
- ``goals``: "(G_ik, α, Id_ik)" terms: the sender's own current goal with ``Id = k·M`` and the
  goals of other robots it knows, relayed with ``Id − 1`` (§3.1, rule 2), each in the
  sender's *body* frame at the sending step (gap filled here: the paper says "with respect to
  F_1", a frame centred on the robot; the body frame is the one the bearings are measured in).
- ``reports``: "(Id_ik, D_ik)" pairs: for every goal the sender sees directly, by reflection
  (V_R) or with delay (V_D), its estimated path length D to that goal (§3 rule 3, §4.2).
  With ``share_via`` (gap filled, see :class:`VisReport`) a report also carries the point the
  sender's D leads through and that point's own distance to the goal: 24 bytes more, still
  O(M).
- ``trouble``: the one-bit internal state Tr of §5 (None when state sharing is off).
- ``pose``, ``pose_cov``: beyond the paper (the beyond section's combination 2, the brains' ``frame_source``
  other than ``"bearings"``): the sender's pose in its own (common, map) frame and its six
  covariance numbers (:mod:`teamnav.papers.beyond.brains.localized_los`); None (0 bytes) under the
  paper's §3.1 rule.

All fields are plain numbers so :meth:`teamnav.control.types.Message.size_bytes` counts them
(8 bytes per number, 1 per bool).
"""

from __future__ import annotations

from dataclasses import dataclass

from teamnav.control.types import _fast_frozen_init, payload_size_bytes, register_payload_sizer

__all__ = ["GoalShare", "LosHelpMsg", "Sighting", "VisReport", "MESSAGE_KIND", "message_size_bytes"]

#: ``Message.kind`` of the system's messages (per-kind traffic counts).
MESSAGE_KIND = "los_help"


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class Sighting:
    """A teammate the sender sees: its id, bearing [rad] and range [m] in the sender's body frame."""

    robot_id: int
    bearing_rad: float
    range_m: float


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class GoalShare:
    """Robot ``owner``'s goal, identifier ``goal_id`` (Id = k·M, minus one per hop), at
    (``gx_m``, ``gy_m``) in the *sender's* body frame at the sending step."""

    owner: int
    goal_id: int
    gx_m: float
    gy_m: float


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class VisReport:
    """The sender sees (directly, reflected or delayed) goal ``goal_id`` of ``owner`` with
    estimated path length ``d_m`` [m] from the sender to the goal (§3 rule 3, §4.2 D_1j).

    ``via_x_m``, ``via_y_m`` (sender's body frame) and ``via_d_m``: the point the sender's D
    leads through (the goal itself when it sees it; its own last viewpoint of §4.3; a ghost)
    and that point's promised distance to the goal, so ``d_m = dist(sender, via) + via_d_m``.
    Gap filled: §4.4 sends only (Id, D); with the point, a robot that reaches the sender's
    position without seeing its goal can go on to where the sender saw it from (a straight
    line: the sender keeps its viewpoint only while it sees it, §4.3). None: not sent.
    """

    owner: int
    goal_id: int
    d_m: float
    via_x_m: float | None = None
    via_y_m: float | None = None
    via_d_m: float | None = None


@_fast_frozen_init
@dataclass(frozen=True, slots=True)
class LosHelpMsg:
    """One step's broadcast of a robot (see the module docstring).

    Attributes
    ----------
    step : int
        The sender's step index when it sent (robots' clocks agree); the receiver pairs the
        message with its own sighting of the sender at that step.
    sightings : tuple of Sighting
    goals : tuple of GoalShare
    reports : tuple of VisReport
    trouble : bool or None
        Tr of §5, None when the sender does not share its state.
    pose : (x, y, θ) or None
        The sender's pose at the sending step (``frame_source`` "mcl" / "fused"; beyond the paper).
    pose_cov : six floats or None
        Its covariance, xx, xy, xθ, yy, yθ, θθ (``frame_source`` "fused").
    """

    step: int
    sightings: tuple[Sighting, ...] = ()
    goals: tuple[GoalShare, ...] = ()
    reports: tuple[VisReport, ...] = ()
    trouble: bool | None = None
    pose: tuple[float, float, float] | None = None
    pose_cov: tuple[float, ...] | None = None


def message_size_bytes(body: LosHelpMsg) -> int:
    """``Message.size_bytes()`` of a message carrying ``body``: the 24-byte header and the body
    by :func:`_payload_size_bytes`'s formula (no recursive walk; the tests check both against
    the walk)."""
    return 24 + _payload_size_bytes(body)


def _payload_size_bytes(body: LosHelpMsg) -> int:
    """``payload_size_bytes(body)`` by formula: the radio sizes every message it carries
    (:meth:`teamnav.control.types.Message.size_bytes`), and the per-field walk cost ~2 % of a
    4-robot step (py-spy, 2026-11-29).

    8 bytes per number, as the fields declare them (ints and floats, numpy's included): step 8,
    24 per sighting, 32 per goal, 24 per report plus 8 per via field present, 1 for a Tr bit;
    a pose and its covariance (beyond the paper, rare) are walked. Equal to the walk
    (``tests/test_payload_size.py``).
    """
    n = 8 + 24 * len(body.sightings) + 32 * len(body.goals) + 24 * len(body.reports)
    for r in body.reports:
        if r.via_x_m is not None:
            n += 8
        if r.via_y_m is not None:
            n += 8
        if r.via_d_m is not None:
            n += 8
    if body.trouble is not None:
        n += 1
    if body.pose is not None:
        n += payload_size_bytes(body.pose)
    if body.pose_cov is not None:
        n += payload_size_bytes(body.pose_cov)
    return n


register_payload_sizer(LosHelpMsg, _payload_size_bytes)
