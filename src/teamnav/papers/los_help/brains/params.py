"""The parameters both line-of-sight help brains share, and which of them are the paper's rules.

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".

:class:`_CommonParams` holds the knobs of the step in :mod:`.brain`: the local navigation
algorithm A (§6), ε and the visibility region V(R) (§2), goal sharing (§3 rules 1–5,
``Id = k·M`` and relaying of §3.1), delayed visibility with ghost robots (§4, §4.2's D
arbitration, §4.4's message) and state sharing (§5's Cr, Pr, Tr, Nt), each gap-fill one flag
away. Its ``paper_rules`` validator sets every gap-fill of :attr:`_CommonParams.PAPER_RULES` to
the paper's value (:mod:`teamnav.control.paper_rules`); :func:`los_gap_fills` lists a brain's
gap-fills with our value and the paper's (the report's two columns). The brains' own
parameters extend it: :class:`~.explorer_params.LosExplorerParams` and :class:`~.helper.LosHelperParams`.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from teamnav.control.paper_rules import GapFill, apply_paper_rules, gap_fills

__all__ = ["NavigatorName", "los_gap_fills"]

NavigatorName = Literal["potential_field", "avoid_past", "visbug21"]


class _CommonParams(BaseModel):
    """Parameters shared by both brains (units in the names).

    Attributes
    ----------
    navigator : {"potential_field", "avoid_past", "visbug21"}
        The local navigation algorithm A (§6).
    navigator_params : dict
        Its parameters (validated by the navigator).
    goal_tolerance_m : float
        ε: a target (or waypoint, or ghost point) is reached when closer than this (§2).
        Should be at least half a step length.
    goal_sharing : bool
        Rules 1–5 of §3 (share goals, relay, report D, head to the shortest D).
    delayed_visibility : bool
        Delayed visibility V_D with ghost robots and §4.3 bookkeeping (§4); False keeps only
        reflected visibility V_R (§3). Ignored without goal sharing.
    state_sharing : bool
        §5: share Tr and, for the explorer, head to a teammate not in trouble when in trouble.
    id_gain_k : int or None
        M in ``Id = k·M`` (§3.1); None uses the team size (all robots must agree).
    trouble_cr : int
        Cr of §5 (steps without progress before the first "in trouble").
    reset_trouble_on_target : bool
        Restart Pr, Tr, Nt when a new target is taken (gap filled; the paper has one goal).
    laser : str
        Name of the omnidirectional range sensor used for visibility and navigation.
    visibility_radius_m : float or None
        Radius of the visibility region V(R) (§2); None uses the laser's maximum range.
    progress_min_fraction : float
        Progress while heading straight to a point: its distance fell by at least this
        fraction of the step length since the last step.
    straight_when_visible : bool
        Head straight to a visible target, suppressing A (§2 point 4); False asks A.
    log_layers : bool
        Add the ``"layers"`` entry (goal and ghost points) to :meth:`log`.
    restart_navigator_on_give_up : bool
        When A returns no heading for a target (VisBug-21 found it "unreachable"), build A
        afresh so it starts over from the current position (gap filled; False: stay).
    ghost_tolerance_m : float
        A ghost point (§4.2) is reached when closer than this (gap filled; the robot must
        stand where the teammate saw the goal from, often a narrow stretch in front of a
        door). Should be at least half a step length.
    slide_when_blocked : bool
        Heading for a point it sees whose straight corridor is too narrow for its body, step
        along the nearest free direction (see ``driving._Driving._slide_heading``) instead of asking
        A (gap filled; False: ask A, the earlier behaviour).
    slide_lookahead_m : float
        Length of the corridor that must be clear for a sliding direction [m].
    trust_direct_promise : bool
        Explorer only: at a ghost whose teammate saw the goal itself from there (its D is the
        straight distance), head for the goal straight (sliding past door jambs) even when the
        robot's own scan does not show it, until the target changes or the robot is in
        trouble (gap filled: §3 rule 3 lets R1 head to its goal once it perceives it from
        where R2 stood; our 72-beam scan and 0.2 m tolerance often miss a room centre seen
        through a door at a slant from a point a few centimetres away; False: explore with A).
    report_margin_steps : float
        A visibility report replaces a stored path only when it is shorter by more than this
        many step lengths (``GoalSharing.report_margin_m``; gap filled, 0: §4.2's strict
        "shorter").
    lead_on : bool
        At a reached ghost, accept a teammate's report that leads further along the same light
        path (``GoalSharing.lead_on``; gap filled, False: §4.2 as written).
    share_via : bool
        Send with each visibility report the point the D leads through (the goal, the own last
        viewpoint of §4.3, or a ghost) and its distance (:class:`~.messages.VisReport`); the
        explorer, reaching a teammate's point without seeing its goal, goes on to that via
        point instead of handing over to A. Gap filled (§4.4 sends only (Id, D)): measured,
        R1 reached a helper's corridor position next to room N5's door, did not see the
        goal the helper had seen from the doorway, and A took it round the corridor. False:
        the paper's message.
    via_in_sight : bool
        Explorer only, with ``share_via``: go on to a via point only while it is in the robot's
        own sight (``_sees``, with the margin of stored points); otherwise the reached point is
        handled as §4.2 says (A starts again). Gap filled (fixes ``share_via``): the via point
        is where the *reporter* saw the goal or the next point from, a straight line from the
        reporter's position, not from R1's; measured, office_simple, Avoid-Past, task 5, R1..3:
        R1 reached R3's promise at N3's door and went on towards the point from which R3 saw
        N2's centre, straight into the N3/N2 wall, and stuck in N3's south-west corner (task
        lost at target 8). Measured, office_simple, 5 tasks x 20 targets, False -> True,
        steps per target over finished tasks (tasks finished, targets reached): Avoid-Past
        R1+R2 541 (2/5, 78/100) -> 516 (4/5, 87/100), R1..3 374 (3/5, 82/100) -> 373 (5/5,
        100/100), R1..4 295 -> 325 (5/5 both; +10 % paired, the cost of the via points
        dropped); VisBug R1+R2 227 (5/5) -> 201 (4/5, 85/100), R1..3 199 (4/5) -> 178 (4/5),
        R1..4 178 (3/5, 91/100) -> 168 (5/5) (the VisBug losses left are laps at the N5
        target, see the explorer's ``visbug_reverse_walk_factor``); R1 alone: Avoid-Past 0/5
        (53/100), VisBug 253 (5/5). False: follow any via point (the earlier gap-fill).
    keep_direct_view : bool
        Hysteresis of the direct view of a goal (§2 point 4): it is *acquired* when the beam
        nearest its bearing reaches past it, and *kept* while any beam within 1.5 beam spacings
        does (``_keeps``). Gap filled: the paper's visibility is exact; with 72 beams a room
        centre seen through a door at a slant flickers in and out as the robot moves, and each
        flicker handed the robot back to A, which walked it away from the door it had just
        found (measured: R1 saw N3's centre for one step from the corridor and VisBug then
        resumed a boundary 8 m west, 129 steps). False: one test, every step.
    see_past_teammates : bool
        The visibility tests (V(R) of a goal, a via point, a ghost: ``_sees``, ``_keeps``) give
        the beams that end on a teammate this robot detects this step the reading of the beams
        beside its body (:func:`~.goal_sharing.see_past_teammates`); navigation and the
        straight-corridor test still see the teammate's body. Gap filled: the paper's V(R) is
        bounded by the environment (§2), and its robots do not hide goals from each other; ours
        have bodies that the laser sees. Why (measured 2026-11-26, office_simple, Avoid-Past, R1+R2,
        5 tasks x 200 targets, steps per target): R1 alone 214, R2 patrolling silent 236,
        silent R2 with R1's laser blind to robots 221: R2's body hid goals that R1 would have
        driven straight to. Measured (2026-11-26, same tasks, R1..R3, paired against False):
        227 -> 210; the full tables with it: docs/report/los-help.md. False: a teammate
        occludes like a wall.
    navigate_past_teammates_beyond_m : float or None
        None (the default): the navigator A sees teammates as obstacles, as the laser does.
        A distance d: A's scan reads past the teammates this robot detects farther than d
        (the beams on their bodies read what the beams beside them read, as for
        ``see_past_teammates``); nearer ones stay obstacles, and the engine's contact rule keeps
        bodies apart whatever A does. Measured (2026-11-26, office_simple, Avoid-Past, R1+R2,
        5 tasks x 200 targets): silent R2 236 steps per target against 214 alone; helping R2
        225 with None and 226 with 1.0 on R1: the teammate's cost is not its body seen from afar
        (docs/report/los-help.md). Kept off; kept for the next trace.
    relay_hop_limit : bool
        Relay a goal only while its hop count ``Nr = Id − (k − 1)·M`` is above 1
        (:func:`~.goal_sharing.can_relay`), so that a relayed Id never names the owner's previous
        goal. Gap filled; False: §3.1 as written, every known goal is relayed with ``Id − 1``
        (an Id of 0 names no goal and is not sent). In a team of M robots that accept a report only
        with an Id at least the stored one, a goal relayed at ``Nr = 1`` reaches only robots that
        already hold it first- or second-hand, so both values give the same runs there.
    frame_source : {"bearings", "mcl", "fused"}
        Where the frame between sender and receiver comes from (the beyond section's combination 2;
        :mod:`teamnav.papers.beyond.brains.localized_los` documents the rules and the frames they need).
        ``"bearings"``: §3.1's mutual bearings, θ21 = 180° + α21 − α12 (the paper's rule; messages
        and behaviour exactly as without this parameter). ``"mcl"``: from the sender's pose, sent in
        each message, and the receiver's, both in one common frame (the map, under ``localized-v1``);
        no sighting needed. ``"fused"``: both, inverse-covariance weighted, when both robots saw
        each other; the poses alone otherwise. Beyond the paper, so not a gap-fill of
        :attr:`PAPER_RULES` (its default is the paper's rule).
    frame_err_max : float
        ``"fused"`` only: the err_max of eqs. 1-2 the robots assume for their detector (§6.1).
    frame_robot_size_m : float or None
        ``"fused"`` only: eq. 2's robot size [m]; None: twice the robot's own radius.
    paper_rules : bool
        Every gap-fill of :attr:`PAPER_RULES` at the paper's value, and ``navigator_params``
        with ``paper_rules: true`` (the navigator's own, e.g. VisBug-21's ``boundary_shortcut``);
        setting one of them to another value as well is an error
        (:mod:`teamnav.control.paper_rules`). The report's "paper as written" column.
    """

    #: Gap-fills whose other value is Sgorbissa & Arkin's rule: {field: the paper's value}.
    #: ``paper_rules: true`` sets them (and passes ``paper_rules`` to the navigator's params).
    PAPER_RULES: ClassVar[dict[str, Any]] = {
        # §3: "robots ... can obstruct the visibility of each other"; V(R) is the line of sight (§2)
        "see_past_teammates": False,
        # §2 point 4: one visibility test per step, no hysteresis
        "keep_direct_view": False,
        # §4.2: a report replaces the stored path when its D is shorter (strictly, no margin)
        "report_margin_steps": 0.0,
        # §2 point 4 / §3 rule 5: straight to a point in sight, otherwise A (no sliding)
        "slide_when_blocked": False,
        # §4.2: at a reached ghost "start again ... with A"; no lead-on along the light path
        "lead_on": False,
        # §4.4: a report is the pair (Id, D), no via point
        "share_via": False,
        # §3.1: relay every known goal with Id − 1
        "relay_hop_limit": False,
    }
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {
        "see_past_teammates": "Sgorbissa §2-§3: V(R) is line of sight; teammates occlude each other",
        "keep_direct_view": "Sgorbissa §2 point 4: the goal is seen or not, one test per step",
        "report_margin_steps": "Sgorbissa §4.2: a report replaces the stored D when strictly shorter",
        "slide_when_blocked": "Sgorbissa §2 point 4: straight to a point in sight, else algorithm A",
        "lead_on": "Sgorbissa §4.2: at a reached ghost the robot starts again with A",
        "share_via": "Sgorbissa §4.4: a report is the pair (Id, D)",
        "relay_hop_limit": "Sgorbissa §3.1: every known goal is relayed with Id - 1",
    }
    #: Gap-fills the paper gives no value for, kept in both columns (what the report says of each).
    GAP_FILLS_KEPT: ClassVar[dict[str, str]] = {
        "goal_tolerance_m": "ε of §2 has no value in the paper: 0.5 m (R1's targets)",
        "ghost_tolerance_m": "when a ghost point counts as reached: 0.2 m (§4.2 gives no tolerance)",
        "progress_min_fraction": "progress towards a point in sight (§5 rule 1 names no metric): a quarter step",
        "trouble_cr": "Cr of §5 has no value in the paper: 50 steps",
        "reset_trouble_on_target": "Pr, Tr, Nt restart at each new target (the paper has one goal per §5 example)",
        "via_in_sight": "moot without share_via",
    }

    #: Behaviours of our simulator the paper does not have, fixed in both columns (FIDELITY §1):
    #: {field: what it removes}; the brains extend it (the ledger's ``artifact-fix`` rows).
    ARTIFACT_FIXES: ClassVar[dict[str, str]] = {
        "restart_navigator_on_give_up": "VisBug-21 on our grid with a robot radius declares a reachable target "
                                        "unreachable (the paper's VisBug, 'guaranteed to find a path to the goal "
                                        "(whenever it exists)', §6, never does): A starts over from where the robot is",
    }

    @model_validator(mode="before")
    @classmethod
    def _paper_rules(cls, data: Any) -> Any:
        """:func:`~teamnav.control.paper_rules.apply_paper_rules`, and ``paper_rules`` passed to
        the navigator's params (their model, which depends on ``navigator``, applies its own
        rules; a conflicting value there is an error here, not at the first step)."""
        data = apply_paper_rules(cls, data)
        if isinstance(data, dict) and data.get("paper_rules") is True:
            nav = data.get("navigator_params", {})
            if isinstance(nav, dict):
                if nav.get("paper_rules", True) is not True:
                    raise ValueError("paper_rules: true also applies to navigator_params; "
                                     "navigator_params.paper_rules must not be false")
                nav = {**nav, "paper_rules": True}
                from teamnav.control.nav.local import NAVIGATORS

                model = NAVIGATORS.get(str(data.get("navigator", "potential_field")))
                if model is not None:
                    try:
                        model.Params(**nav)
                    except ValidationError as e:
                        raise ValueError(f"navigator_params: {e.errors()[0]['msg']}") from None
                data["navigator_params"] = nav
        return data

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    navigator: NavigatorName = "potential_field"
    navigator_params: dict[str, Any] = Field(default_factory=dict)
    goal_tolerance_m: float = Field(0.5, gt=0.0, le=100.0)
    goal_sharing: bool = True
    delayed_visibility: bool = True
    state_sharing: bool = True
    id_gain_k: int | None = Field(None, ge=1, le=1_000_000)
    trouble_cr: int = Field(50, ge=1, le=10_000_000)
    reset_trouble_on_target: bool = True
    laser: str = Field("laser", min_length=1)
    visibility_radius_m: float | None = Field(None, gt=0.0, le=1000.0)
    progress_min_fraction: float = Field(0.25, ge=0.0, le=1.0)
    straight_when_visible: bool = True
    log_layers: bool = True
    restart_navigator_on_give_up: bool = True
    ghost_tolerance_m: float = Field(0.2, gt=0.0, le=100.0)
    slide_when_blocked: bool = True
    slide_lookahead_m: float = Field(1.0, gt=0.0, le=100.0)
    trust_direct_promise: bool = True
    report_margin_steps: float = Field(1.0, ge=0.0, le=1000.0)
    lead_on: bool = True
    share_via: bool = True
    via_in_sight: bool = True
    keep_direct_view: bool = True
    see_past_teammates: bool = True
    navigate_past_teammates_beyond_m: float | None = Field(None, gt=0.0, le=100.0)
    relay_hop_limit: bool = True
    frame_source: Literal["bearings", "mcl", "fused"] = "bearings"
    frame_err_max: float = Field(0.0, ge=0.0, le=1.0)
    frame_robot_size_m: float | None = Field(None, gt=0.0, le=100.0)
    paper_rules: bool = False


def los_gap_fills(params_cls: type, navigator: str, ours: dict[str, Any] | None = None) -> list[GapFill]:
    """The gap-fills of a LOS brain's params (``LosExplorerParams`` / ``LosHelperParams``) and of
    its ``navigator``'s, the latter as ``navigator_params.<field>``, with our value (``ours``,
    a scenario's params, over the defaults) and the paper's (:func:`~teamnav.control.paper_rules.gap_fills`)."""
    from teamnav.control.nav.local import NAVIGATORS

    given = dict(ours or {})
    nav_given = given.pop("navigator_params", None) or {}
    out = gap_fills(params_cls, given)
    for g in gap_fills(NAVIGATORS[navigator].Params, nav_given):
        out.append(g._replace(field=f"navigator_params.{g.field}"))
    return out
