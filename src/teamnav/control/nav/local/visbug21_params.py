"""VisBug-21's parameters (:class:`VisBugParams`) and the rules of its paper as written.

The settings of :class:`~teamnav.control.nav.local.visbug21.VisBug21`, algorithm A = 3 of
Sgorbissa & Arkin §6 ("the VisBug21 algorithm [7]": Lumelsky & Skewis 1990, "Incorporating range
sensing in the robot navigation function", IEEE Trans. SMC 20(5)). Each field sets a rule that
:mod:`teamnav.control.nav.local.visbug21`'s docstring states: Step 1's free corridor, Step 2's
boundary offset and leave test, Bug2's termination test, the local direction at a hit point.
``PAPER_RULES`` lists where our defaults fill a gap or deviate (Lumelsky & Skewis' local
direction fixed a priori; their Step 2 intermediate target on the obstacle boundary), and
``paper_rules: true`` sets their values (:mod:`teamnav.control.paper_rules`). Split from
:mod:`~teamnav.control.nav.local.visbug21` to keep the algorithm's flow and its settings apart.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import BaseModel, ConfigDict, Field, model_validator

from teamnav.control.paper_rules import paper_rules_validator

__all__ = ["VisBugParams"]


class VisBugParams(BaseModel):
    """Parameters of VisBug-21 (units in the names; :mod:`teamnav.control.nav.local.visbug21`'s
    docstring gives the rules).

    Attributes
    ----------
    turn : {"nearer_end", "left", "right", "random"}, default "nearer_end"
        Local direction at a hit point ("left": the obstacle stays on the robot's right).
        "random": drawn (fair coin from the robot's ``rng``) at every new goal and kept for
        that goal, so a map whose doors all sit on one side of the rooms does not favour
        or punish the algorithm systematically. "nearer_end" (our default; a deviation, see
        :mod:`~teamnav.control.nav.local.visbug21`): chosen at every hit point, towards the sensed end of the hit
        obstacle that promises the shorter way to T; "left" until the first choice.
    safety_margin_m : float, default 0.05
        Free corridors keep ``R = radius + this`` from sensed points [m].
    follow_margin_m : float, default 0.08
        The boundary is followed at ``R + this`` [m]. It must leave room to pass a door:
        ``2 (R + follow_margin_m)`` below the narrowest door (0.9 m in ``office_complex``;
        0.76 m with a 0.25 m robot and the defaults).
    leave_hysteresis_m : float, default 0.03
        The leave test's free corridor is this much wider than Step 1's [m]; it must be
        smaller than ``follow_margin_m`` (a robot following at ``R + follow_margin_m`` must
        be able to see a leave point from where it is).
    follow_gain : float, default 1.5
        Heading correction per relative distance error while following (rad per unit).
    leave_margin_m : float, default 0.1
        A leave point must be this much closer to the goal than the hit point [m].
    leave_run_m : float, default 0.5
        From a leave point the M-line must run on free this far (or up to the goal) [m].
    mline_sample_m : float, default 0.1
        Spacing of the M-line points tested as intermediate targets [m].
    return_tol_m : float, default 0.3
        Back within this of the hit point (after leaving it) = goal unreachable [m].
    guard_margin_m : float, default 0.03
        Collision guard: each step keeps radius + this from sensed points [m].
    follow_patience_m : float, default 20.0
        Boundary walk after which the robot no longer counts as progressing [m].
    progress_window_steps : int, default 30
    progress_fraction : float, default 0.5
        As for the potential field (Step 1's progress estimate).
    reverse_walk_factor : float or None, default None
        Alternating boundary walk (our deviation; None: Lumelsky & Skewis' walk in one local
        direction until a leave point or back at H). A walk longer than this many times the
        hit point's distance to T, ``d_H`` (at least ``2 m``), turns back in the other local
        direction, passes H and goes on twice as far beyond H; each reversal doubles the reach
        (the doubling of the "reverse" Bug variants: the walk stays within a constant factor
        of the shorter side's), and the lap count at H starts over, so T is still declared unreachable
        only after a full lap in one direction. Meant for the trap that ``turn="nearer_end"``
        falls into in an office: T straight behind the side wall of a room whose door is the
        nearer sensed end (office_simple, S1 -> N5: a lap of every north room, ~1300 steps).
    boundary_shortcut : bool, default False
        Lumelsky & Skewis' second kind of Step 2 intermediate target, which our follower omits
        (:mod:`~teamnav.control.nav.local.visbug21`, "Where we deviate"): while walking the boundary with no leave point
        in sight, head straight for the *farthest visible point of the followed obstacle's
        boundary in the local direction*
        (:meth:`~teamnav.control.nav.local.visbug21.VisBug21._boundary_target`), so that concave
        stretches are cut across; the constant-offset follower takes over when no such point is
        at least a step away. True: VisBug-21 as its authors wrote it (``paper_rules``); False:
        the reactive follower alone (our default, unchanged behaviour).
    paper_rules : bool, default False
        Every gap-fill of :attr:`PAPER_RULES` at its paper value (:mod:`teamnav.control.paper_rules`).
    """

    #: VisBug-21 as Lumelsky & Skewis wrote it (Sgorbissa & Arkin §6 run "the VisBug21 algorithm
    #: [7]"): {field: the paper's value}; ``paper_rules: true`` sets them.
    PAPER_RULES: ClassVar[dict[str, Any]] = {
        # Lumelsky & Skewis fix the local direction a priori; which one is a silence of the paper, a
        # fill chosen by teamnav.papers.los_help.tasks.TURN_RULE on tuning tasks 1001-1005 (2026-11-29):
        # right (R1 alone 5/5 at 517 steps per target, left 5/5 at 735); nearer_end is TangentBug's heuristic
        "turn": "right",
        # Lumelsky & Skewis: Ti is also the farthest visible boundary point in the local direction
        "boundary_shortcut": True,
    }
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {
        "turn": "VisBug-21 (Lumelsky & Skewis): one local direction fixed a priori; right, a fill chosen on "
                "tuning tasks (which direction is not given)",
        "boundary_shortcut": "VisBug-21 (Lumelsky & Skewis): Step 2's Ti may be the farthest visible boundary point",
    }

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    turn: Literal["left", "right", "random", "nearer_end"] = "nearer_end"
    safety_margin_m: float = Field(0.05, ge=0.0, le=2.0)
    follow_margin_m: float = Field(0.08, ge=0.0, le=2.0)
    leave_hysteresis_m: float = Field(0.03, ge=0.0, le=2.0)
    follow_gain: float = Field(1.5, ge=0.0, le=20.0)
    leave_margin_m: float = Field(0.1, ge=0.0, le=10.0)
    leave_run_m: float = Field(0.5, ge=0.0, le=10.0)
    mline_sample_m: float = Field(0.1, gt=0.0, le=5.0)
    return_tol_m: float = Field(0.3, gt=0.0, le=10.0)
    guard_margin_m: float = Field(0.03, ge=0.0, le=1.0)
    follow_patience_m: float = Field(20.0, gt=0.0, le=10_000.0)
    progress_window_steps: int = Field(30, ge=1, le=100_000)
    progress_fraction: float = Field(0.5, gt=0.0, le=10.0)
    reverse_walk_factor: float | None = Field(None, gt=0.0, le=1000.0)
    boundary_shortcut: bool = False
    paper_rules: bool = False

    _paper_rules = paper_rules_validator()

    @model_validator(mode="after")
    def _hysteresis_below_follow(self) -> "VisBugParams":
        if not self.leave_hysteresis_m < self.follow_margin_m:
            raise ValueError(
                f"leave_hysteresis_m must be < follow_margin_m ({self.follow_margin_m}), got {self.leave_hysteresis_m}"
            )
        return self
