"""The parameters of ``los-explorer-v1`` (R1, :class:`~.explorer.LosExplorer`), field by field.

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".
:class:`LosExplorerParams` extends :class:`~.params._CommonParams` (the knobs both brains share)
with R1's own:

- its task: the targets reached in sequence (§2, §6) and the step budget per target;
- §4.2's ghost points: starting A again at a reached ghost, VisBug-21's walk there, and giving
  up a ghost R1 makes no progress towards;
- §5 rule 3, heading to a teammate not in trouble while in trouble: which teammate qualifies,
  what counts as progress while following it, and what R1 does when it goes out of sight;
- ``paper_rules``: the class dicts ``PAPER_RULES`` (the gap-fills whose other value is the
  paper's rule, each with the section it restores), ``PAPER_RULE_NOTES`` (the same in one line
  for the reports) and ``GAP_FILLS_KEPT`` (what the paper gives no value for), read by
  :mod:`teamnav.control.paper_rules` through :class:`~.params._CommonParams`'s validator.

Each gap-fill is documented at its field with what was measured. What R1 does with them is in
:mod:`.explorer`.
"""

from __future__ import annotations

from typing import Any, ClassVar, Literal

from pydantic import Field

from teamnav.papers.los_help.brains.params import _CommonParams

__all__ = ["LosExplorerParams"]


class LosExplorerParams(_CommonParams):
    """R1's parameters: :class:`_CommonParams` plus its task.

    Attributes
    ----------
    targets_xy : list of (x, y)
        Targets [m] in the robot's own odometry frame, reached in sequence (§2, §6). Empty:
        finished at once (the robot stays and still relays).
    keep_trouble_helper : bool
        In trouble, keep heading to the chosen helper's last seen position when it goes out of
        sight, until no longer in trouble or the goal is seen (a teamnav gap-fill: §5 names only
        these two ends). False (the paper column, ``PAPER_RULES``): §5 rule 3's teammate is one
        "in V(R_i)", so it is followed only while in sight (seen now, or, with
        ``trouble_sighting_at_send``, seen at the step it sent the Tr bit that arrived now).
    trouble_progress : {"helper", "goal", "moved"}
        While following a teammate in trouble (§5 rule 3), what counts as progress for Pr.
        Default ``"helper"`` (the paper's rule, see below). ``"goal"`` (a gap-fill, the default
        until H7d): its straight distance to its own goal fell by ``progress_min_fraction`` of
        a step (§5 rule 1: "progressing well towards the goal"; measured: with ``"moved"`` R1
        left trouble wherever the teammate had led it, 40 m away, and was trapped again; but
        with ``"goal"`` a teammate walking away keeps R1 following it until it leaves R1's
        sight, 50-80 % of R1's steps on the potential field, after which A takes R1 back to the
        same trap. Measured, office_simple, potential field, 5 tasks x 10 targets, tasks
        finished: R1..R3 4/5 -> 5/5, R1..R4 4/5 -> 5/5 with ``"helper"`` (on the tasks both
        finished 376 -> 388 and 294 -> 328 steps per target, within the task-to-task spread);
        R1+R2 0/5 either way. office_complex, same protocol, targets reached (tasks finished)
        "goal" -> "helper": R1+R2 24/50 (0/5) -> 31/50 (2/5), R1..R3 22/50 (0/5) -> 23/50 (0/5),
        R1..R4 40/50 (3/5) -> 31/50 (1/5): no net change there);
        ``"moved"``, any step that was not blocked; ``"helper"``, the paper's own reading of
        Fig. 10 ("R_1 is now progressing towards its goal (by setting G_icurr = R_2)"): its
        distance to the teammate it heads for fell (its best so far, ``_head_to``), so Pr falls
        while R1 closes in and R1 leaves the teammate after about Nt·Cr steps, each episode
        longer than the last (Nt grows).
    trouble_helper_towards_goal : bool
        In trouble (§5 rule 3), do not head to a teammate that is *walking away from R1's
        goal*: one whose straight distance (seen position, own frame) to R1's current goal grew
        by more than ``trouble_recede_m`` / 10 over its sightings of the last
        ``trouble_heading_steps`` steps is no candidate, and a teammate being followed is let
        go once that distance has grown by more than ``trouble_recede_m`` above the smallest
        seen while following it. Without a candidate R1 drives with A as if not in trouble
        (Pr keeps its value, so the next teammate that qualifies is followed at once).
        Gap filled: §5 says R1 "believes temporarily that R_j is in a better area of the
        environment for reaching its own goal"; a patrolling helper walking away from the
        goal is not, and following it was where the potential field's steps went on
        office_complex (traced: R1 trapped by room 2's west wall with its goal in room 1
        followed R2 east 26 m to the corridor's end, was released there and trapped in room 5;
        1868 of 3637 steps of that task). A first version that followed only a teammate
        already *closing in* on the goal lost R1 in office_simple's room N5, whose door shows
        R1 a helper only while it steps into the doorway and out (away, then towards).
        Measured, potential field, 5 tasks x 10 targets, paper rule -> this, targets reached
        (tasks finished): office_complex R1+R2 31/50 (2/5) -> 38/50 (3/5), R1..3 23/50 (0/5)
        -> 32/50 (2/5), R1..4 31/50 (1/5) -> 43/50 (3/5); office_simple unchanged within the
        task-to-task spread (R1+R2 19/50 both; R1..3 383 -> 363 steps per target, 5/5 -> 4/5;
        R1..4 331 -> 341, 5/5 both).
        False: the nearest teammate not in trouble (the paper's rule).
    trouble_heading_steps : int
        Steps of a teammate's sightings over which its approach to the goal is judged
        (``trouble_helper_towards_goal``).
    trouble_recede_m : float
        Hysteresis [m] of ``trouble_helper_towards_goal`` (a helper stepping into a doorway
        moves across the goal's direction by about a metre). Measured with it, office_complex
        PF, 5 tasks x 10 targets, targets reached with R1+R2 / R1..3 / R1..4: 2 m 38 / 32 / 43
        of 50; 1 m 43 / 31 / 36 (no gain); and ``trouble_progress="goal"`` with the
        filter 14 / 24 / 36 (worse: "helper" stays the default).
    max_steps_per_target : int or None
        Step budget per target: when the current target is not reached within this many steps
        (from the step it became current), R1 abandons the task (``gave_up``, and ``finished``
        so that a run with ``stop_when_finished`` ends). Gap filled: §6 reports the potential
        field alone as failing without saying after how long; a budget per target, not per
        task, ends a hopeless run at its first trap instead of burning the whole task's
        budget. None: never abandon.
    restart_navigator_at_ghost : bool
        At a teammate's point (ghost) reached without seeing the goal, A starts again from
        there (§4.2: "it will have to start again to explore the environment by relying on its
        own navigation algorithm A, possibly from a better position"): VisBug-21 drops the
        M-line and hit point it had suspended for the excursion and takes a new M-line from
        the ghost. False: resume the suspended ones (measured: resuming walked R1 from the
        corridor back into the south rooms it had been led out of).
    visbug_reverse_walk_factor : float or None
        With ``navigator="visbug21"`` and ``restart_navigator_at_ghost``: when VisBug starts
        again at a ghost reached without the goal in sight (§4.2), its boundary walks towards
        that target alternate (``VisBug21.start_again(reverse_walk_factor=...)``, see
        ``VisBugParams.reverse_walk_factor``): a walk longer than this many times the hit
        point's distance to the goal turns back. R1's walks elsewhere, and R1 alone, are
        VisBug's as before. Gap filled (a deviation from VisBug-21's one local direction;
        near the ghost the goal is close, and a wrong side is a lap): traced, office_simple,
        R1..3, task 3, target N5 from S1: R3's §4.3 point led R1 east to the corridor below
        N4's door; VisBug, restarted there (§4.2), hit the corridor's north wall and took the
        west side (the sensed end nearer to the goal is N4's east door jamb, with the N4/N5
        wall behind it): a lap of every north room, the target's 1500-step budget spent
        (R1 alone laps too on this target, 1270 steps). Measured, office_simple, VisBug,
        5 tasks x 20 targets, None -> 3, steps per target over finished tasks (tasks
        finished, targets reached): R1+R2 201 (4/5, 85/100) -> 226 (5/5, 100/100), R1..3
        178 (4/5, 85/100) -> 190 (5/5, 100/100), R1..4 168 -> 169 (5/5 both); on the tasks
        finished both ways unchanged (R1+R2 identical, R1..3 178 -> 176); R1 alone
        unaffected (253, 5/5). None: VisBug's one-direction walk (the paper's A).
    trouble_sighting_at_send : bool
        §5 rule 3 counts a teammate R_j in sight that is not in trouble; its Tr bit, sent at step
        k, arrives at k + 1 (the radio's one-step delay), when a teammate seen for one step only
        is out of sight again, so it was never a candidate. True: a teammate whose Tr bit (false)
        arrived and which R1 saw at the sending step is a candidate at the position R1 saw it
        at (kept with ``keep_trouble_helper``). Defect against §5 fixed (R_j was in V(R_i) when
        it shared its state): traced, office_complex, potential field, R1..R4, task 1, target
        room 5 from room 6: R1 trapped in room 7's south-east corner (26.6, 14.0) saw a
        helper through room 7's door for one step every ~100 steps, 2500 steps long, and never
        headed to it. Measured (H7pf), potential field, 40-target prefixes of tasks 1-10,
        paired, False -> True, tasks finished (targets reached): office_complex R1+R2 0/10
        (178/400) -> 4/10 (245/400), R1..3 1/10 (167/400) -> 4/10 (244/400), R1..4 4/10
        (279/400) -> 5/10 (271/400); office_simple R1+R2 2/10 (161/400) -> 2/10 (205/400),
        R1..3 9/10 (387/400) -> 9/10 (367/400), 349 -> 330 steps per target on the 8 tasks
        both finished, R1..4 10/10 both, 299 -> 290. R1 alone is unaffected (no teammate).
        The default since H7pf, and since 2026-11-29 in the paper column too: an artifact fix
        (``ARTIFACT_FIXES``), not a gap-fill, since the paper's radio has no such delay.
        False: only teammates in sight at the step the bit arrives (the earlier behaviour).
    trouble_return : bool
        In trouble with no teammate in sight to head to (§5 rule 3 needs one), head back to the
        position where R1 last saw a teammate not in trouble (own frame; with
        ``trouble_helper_towards_goal`` not one walking away from R1's goal), and wait there
        (not counted as progress: Pr stays) until a teammate comes in sight or
        ``trouble_wait_steps`` have passed (then A drives again and the point is forgotten).
        Gap filled: §5 does not say what a robot in trouble does while nobody is in sight;
        helpers patrol the corridors, and R1 trapped in a room corner (office_complex
        (28.0, 18.6) behind room 8's U, (16.0, 5.4) against room 2's east wall) is out of every
        helper's sight (traced: helper in sight 17 of 2500 steps). R1 alone never saw a
        teammate and stays trapped (§6). Measured (H7pf), office_complex, R1+R2, tasks 1-5 x
        40 targets, with ``trouble_sighting_at_send``, targets reached (tasks finished): off
        116/200 (2/5); on, waiting 600 steps 42/200 (0/5); ``trouble_wait_steps=0`` with
        ``trouble_return_progress`` 26/200; 150 steps with it 27/200 (0/5): R1 kept in
        trouble walks the helper's trail and spends each target's budget (traced: Pr at its
        bound for 2000 steps, never back on its own goal). Off by default. False: A drives as
        if not in trouble.
    trouble_wait_steps : int
        Steps R1 waits at the point of ``trouble_return`` for a teammate before A drives again
        (0: no wait, A drives as soon as R1 is there).
    trouble_return_progress : bool
        With ``trouble_return``: closing in on the point counts as progress (Pr falls, as when
        heading to a teammate, §5 Fig. 10); False: Pr stays at its bound while returning.
    trouble_release_to_helper : bool
        With ``trouble_helper_towards_goal``: when a followed teammate is let go because it
        walks away from R1's goal, R1 first goes on to the position where it last saw it (own
        frame; progress as towards a teammate, §5 Fig. 10) before A drives again; the point is
        dropped when reached, after ``trouble_cr`` steps without progress towards it, when R1
        sees its goal or follows another teammate, or at the next target. Gap filled: §5 does
        not say where a robot released by its helper resumes A; R1 follows a helper at the
        helper's own speed, never gains on it, so Pr does not reach 0 and, once the helper
        turns away, A walked R1 back from the doorway into the trap it had been led out of
        (traced (H7pf), office_complex, potential field: room 7's SE corner (26.6, 14.0)).
        Measured (H7pf2), office_complex, potential field, 40-target prefixes of tasks 1-5,
        paired, False -> True, tasks finished (targets reached): R1+R2 2/5 (116/200) -> 1/5
        (115/200), R1..R4 2/5 (105/200) -> 0/5 (55/200): worse, off by default. False: A
        drives at once (the earlier behaviour).
    trouble_near_helper_m : float or None
        While following a teammate in trouble (§5 rule 3), a step taken from within this many
        metres [m] of the teammate, in sight, counts as progress (Pr falls) whatever
        ``trouble_progress`` says. Gap filled: following at the teammate's own speed R1 never
        gains on it, so with the paper's rule Pr stays up and Nt grows; close behind its
        helper R1 is "progressing" in the sense of Fig. 10. Measured (H7pf2), same protocol as
        ``trouble_release_to_helper``, None -> 1.5 m: R1+R2 2/5 (116/200) -> 1/5 (131/200),
        R1..R4 2/5 (105/200) -> 1/5 (94/200); 3 m: 2/5 (131/200), 1/5 (67/200): no clear
        gain (R1..R4 worse), off by default.
        None: ``trouble_progress`` alone (the earlier behaviour).
    trouble_drop_stalled_helper : bool
        With ``keep_trouble_helper``: the last seen position of a followed teammate now out of
        sight is dropped after ``trouble_drop_after_steps`` steps without progress towards it
        (as a ghost is after ``trouble_cr``, ``temp_dropped``), so that A, or another teammate
        in sight, takes over. Gap filled:
        §5 ends the following only when R1 is no longer in trouble or sees its goal, and a
        point behind a wall pinned R1 for good: traced (2026-11-26), office_simple, potential
        field, R1..R3, task 5, target 59 (room N2 from room S5): R1 saw R3 through S5's door,
        kept heading for R3's last seen position in the corridor (28.8, 7.8) and stood against
        S5's north wall below it, Tr set and the same robot never in sight again, for 5800 steps
        until it gave up. Measured (2026-11-26, 200-target tasks of Tables 1-2, VisBug helpers,
        paired against False): after ``trouble_cr`` = 50 steps, office_simple tasks finished
        R1..R3 3/5 -> 5/5 (R1+R2, R1..R4 5/5 both; the 13 tasks both finished 343 -> 342 steps
        per target on average), but on office_complex R1..R4 two tasks that finished gave up
        (tasks 1 and 2 at targets 74 and 70: R1 let go of a helper it was still working its
        way round to) and R1..R3 task 1 at target 186, for R1+R2 task 2 and R1..R3 task 2
        fixed. After 500 steps (the default) office_complex R1..R4 tasks 1 and 2 pass those
        targets again (80/80 and 75/75) and office_simple R1..R3 task 5 its (59/59); R1+R2
        task 2 on office_complex gives up at 140 again (as with False). The tables' numbers
        with this default: ``docs/report/los-help.md``. False: kept until Tr clears or the goal
        is seen (the earlier behaviour).
    trouble_drop_after_steps : int
        Steps without progress towards a kept helper position out of sight after which
        ``trouble_drop_stalled_helper`` drops it (default 500, ten times ``trouble_cr``).
    drop_unreachable_ghost : bool
        A teammate's point or ghost (§3 rule 5, §4.2) that the navigator A declares unreachable
        (VisBug-21's Bug2 termination test: back at its hit point after a full lap) is dropped
        like a reached one (``ghosts_unreachable``), so that A starts again on R1's own goal.
        Artifact fixed, in both columns (not a gap-fill: the paper's rule does not cover the
        case): §4.2 takes the ghost to be reachable (R1's path to R2(t1) "is by definition a
        straight one" and "we assume odometry to be adequate to guarantee R2(t2)
        reachability"), while ours can stand 0.11 m from a wall line, closer than our robot's
        radius, where VisBug-21 on our grid calls it unreachable. Traced (office_simple,
        R1..R4, paper rules, task 1, first 12 targets): 3,479 of 5,251 ghost steps were R1
        standing still at such a ghost (R2's doorway stop, 5.3 m away in R1's own corridor),
        the explorer picking the same ghost every step; dropping it once, the same prefix
        finished 12 of 12 targets. False: R1 keeps the ghost and A keeps answering
        "unreachable" (R1 stands still until a shorter D replaces it).
    drop_stalled_ghost : bool
        A teammate's point or ghost (§3 rule 5, §4.2) that R1 makes no progress towards for
        ``trouble_cr`` steps (A trapped on the way, a teammate standing still in a doorway) is
        given up like a reached one (``temp_dropped``), so that A, or §5 when in trouble, takes
        over. Gap filled: §4.2 assumes the straight path to a ghost is free. False: §4.2 as
        written, R1 heads to the ghost until it reaches it or a shorter D replaces it.
    """

    #: The brain's gap-fills whose other value is the paper's rule (the common ones and R1's).
    PAPER_RULES: ClassVar[dict[str, Any]] = {
        **_CommonParams.PAPER_RULES,
        # §3 rule 3: R1 heads to its goal once it perceives it from where R2 stood, not on trust
        "trust_direct_promise": False,
        # §5 rule 3: any teammate in sight that is not in trouble
        "trouble_helper_towards_goal": False,
        # §5 rule 3: followed "until it is no longer in trouble or ... perceive[s] its own goal"
        "trouble_drop_stalled_helper": False,
        # §5 rule 3: R_i heads to a teammate R_j "in V(R_i)"; one out of sight is not followed
        "keep_trouble_helper": False,
        # §4.2 / §6: VisBug-21's one local direction at a ghost too
        "visbug_reverse_walk_factor": None,
        # §4.2: R1 heads to the ghost that promised the shortest D until it reaches it
        "drop_stalled_ghost": False,
    }
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {
        **_CommonParams.PAPER_RULE_NOTES,
        "trust_direct_promise": "Sgorbissa §3 rule 3: R1 heads to its goal once it perceives it itself",
        "trouble_helper_towards_goal": "Sgorbissa §5 rule 3: any teammate in sight not in trouble",
        "trouble_drop_stalled_helper": "Sgorbissa §5 rule 3: followed until not in trouble or the goal is seen",
        "keep_trouble_helper": "Sgorbissa §5 rule 3: a teammate in V(R_i) not in trouble is headed for, "
                               "so only while it is in sight",
        "visbug_reverse_walk_factor": "Sgorbissa §6 / Lumelsky & Skewis: one local direction, at a ghost too",
        "drop_stalled_ghost": "Sgorbissa §4.2: the ghost is headed for until reached or replaced by a shorter D",
    }
    GAP_FILLS_KEPT: ClassVar[dict[str, str]] = {
        **_CommonParams.GAP_FILLS_KEPT,
        "max_steps_per_target": "a step budget per target ends a hopeless task (§6 says the potential field "
                                "alone fails, not after how long)",
        "trouble_progress": "'helper': closing in on the followed teammate is progress (the paper's Fig. 10 reading)",
        "restart_navigator_at_ghost": "§4.2's 'start again with A' at a reached ghost",
    }

    #: Behaviours of our simulator that the paper's robots do not have, fixed in both columns
    #: (FIDELITY §1: never "the paper's rule"): {field: what it removes} (the ledger's
    #: ``artifact-fix`` rows; each field's docstring has the trace).
    ARTIFACT_FIXES: ClassVar[dict[str, str]] = {
        **_CommonParams.ARTIFACT_FIXES,
        "trouble_sighting_at_send": "our radio delivers a Tr bit one step after it is sent, when a teammate seen "
                                    "through a door for one step is out of sight again; the teammate seen at the "
                                    "sending step is a candidate (it was in V(R_i) when it shared its state, §5)",
        "drop_unreachable_ghost": "VisBug-21 on our grid with a robot radius declares a ghost unreachable (one "
                                  "0.11 m from a wall line) and R1 stood still at it; §4.2 assumes the ghost "
                                  "reachable, so the point is dropped as a reached one",
    }

    targets_xy: list[tuple[float, float]] = Field(default_factory=list, max_length=100_000)
    restart_navigator_at_ghost: bool = True
    keep_trouble_helper: bool = True
    max_steps_per_target: int | None = Field(None, ge=1, le=100_000_000)
    trouble_progress: Literal["goal", "moved", "helper"] = "helper"
    trouble_helper_towards_goal: bool = True
    trouble_heading_steps: int = Field(5, ge=1, le=1000)
    trouble_recede_m: float = Field(2.0, ge=0.0, le=100.0)
    visbug_reverse_walk_factor: float | None = Field(3.0, gt=0.0, le=1000.0)
    trouble_sighting_at_send: bool = True
    trouble_return: bool = False
    trouble_wait_steps: int = Field(600, ge=0, le=10_000_000)
    trouble_return_progress: bool = False
    trouble_release_to_helper: bool = False
    trouble_near_helper_m: float | None = Field(None, gt=0.0, le=100.0)
    trouble_drop_stalled_helper: bool = True
    trouble_drop_after_steps: int = Field(500, ge=1, le=10_000_000)
    drop_stalled_ghost: bool = True
    drop_unreachable_ghost: bool = True
