"""R1's side of state sharing: heading to a teammate when in trouble (Sgorbissa & Arkin §5 rule 3).

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots".

:class:`_TroubleFollowing` is a mixin of :class:`~.explorer.LosExplorer`. §5's bookkeeping (Cr,
Pr, Tr, Nt) is :mod:`.state_sharing`; what R1 does with it is here: in trouble, a teammate in
sight that is not becomes its temporary goal "until it realizes it is no longer in trouble or
... perceives its own goal" (rule 3), closing in on it counting as progress (Fig. 10). The
gap-fills around that rule, each a field of
:class:`~.explorer_params.LosExplorerParams` documented there with what was measured:

- which teammate qualifies: one whose Tr bit arrived and that R1 saw when it was sent
  (``trouble_sighting_at_send``, an artifact fix of our radio's one-step delay, in both
  columns), not one walking away from R1's goal
  (``trouble_helper_towards_goal``, :meth:`_TroubleFollowing._watch_mates` keeps the teammates'
  distances to it);
- what R1 does when it goes out of sight: head on to its last seen position
  (``keep_trouble_helper``, teamnav only: the paper column follows a teammate only while it is
  in V(R_i), §5 rule 3), given up when R1 does not close in on it
  (``trouble_drop_stalled_helper``);
- what counts as progress while following it (``trouble_progress``, ``trouble_near_helper_m``);
- where R1 goes when nobody is in sight (``trouble_return``) and when a followed teammate is let
  go (``trouble_release_to_helper``).

The host provides ``params``, ``trouble`` (:class:`~.state_sharing.TroubleState`), this step's
pose and sightings (``_pose``, ``_me_xy()``, ``_seen_now``, ``_step``), the teammates' Tr bits
(``_teammate_tr``, ``_teammate_tr_xy``), ``_prev_goal_d`` and the driving helpers of
:class:`~.driving._Driving`.
"""

from __future__ import annotations

import math

from teamnav.papers.los_help.brains.driving import XY
from teamnav.papers.los_help.brains.state_sharing import choose_helper
from teamnav.control.types import Action, Observation


class _TroubleFollowing:
    """R1's §5 rule 3 and its gap-fills (see the module docstring)."""

    def _init_trouble_following(self) -> None:
        """The state of this mixin (called by the host's ``__init__``)."""
        self._trouble_target: tuple[int, XY] | None = None
        #: teammates' recent straight distances to R1's goal, (step, d) (trouble_helper_towards_goal)
        self._mate_goal_d: dict[int, list[tuple[int, float]]] = {}
        self._tt_best_d = math.inf
        #: where a teammate not in trouble was last seen (``trouble_return``), and since when R1 waits there
        self._last_helper_xy: XY | None = None
        self._return_since: int | None = None
        #: where a followed teammate let go for walking away was last seen (``trouble_release_to_helper``)
        self._release_xy: XY | None = None
        self._release_stall = 0
        self._tt_stall = 0
        self.trouble_helpers_dropped = 0

    def _watch_mates(self, goal: XY) -> None:
        """Each step: forget the trouble helper once out of trouble, and keep the teammates'
        distances to ``goal`` (``trouble_helper_towards_goal``) and where one not in trouble was
        last seen (``trouble_return``)."""
        p = self.params
        if not self.trouble.tr:
            self._trouble_target = None
        if p.state_sharing and p.trouble_helper_towards_goal:
            self._track_mates(goal)
        if p.state_sharing and p.trouble_return:
            self._remember_helper()

    def _follow_in_trouble(self, obs: Observation, goal: XY, me_xy: XY, goal_d: float,
                           progressing: bool) -> tuple[Action | None, bool]:
        """In trouble with nothing else leading R1: head to a teammate not in trouble (§5 rule 3),
        or back to where one was last seen (``trouble_return``); (action, or None when neither
        applies, and progressing)."""
        p = self.params
        action: Action | None = None
        # §5 rule 3: in trouble, a teammate in sight that is not becomes the temporary goal
        # "until it realizes it is no longer in trouble or ... perceives its own goal"; with
        # ``keep_trouble_helper`` (teamnav's gap-fill) kept at its last seen position when it
        # goes out of sight, without it (the paper column) followed only while in V(R_i)
        near = 2.0 * self.radius_m + self.step_m
        seen = self._seen_now
        if p.trouble_sighting_at_send:
            # a teammate whose Tr bit arrived, seen when it sent it though not now (see
            # ``trouble_sighting_at_send``): a candidate at the position it was seen at
            seen = {**{rid: xy for rid, xy in self._teammate_tr_xy.items() if rid not in seen}, **seen}
        cands = [(rid, xy[0], xy[1], self._teammate_tr.get(rid)) for rid, xy in seen.items()]
        if p.trouble_helper_towards_goal:
            # not a teammate walking away from R1's goal (see ``trouble_helper_towards_goal``)
            cands = [(rid, x, y, None if self._mate_recedes(rid) else tr) for rid, x, y, tr in cands]
        tt = self._trouble_target
        if tt is not None and tt[0] in self._seen_now and p.trouble_helper_towards_goal:
            d_mate = self._mate_goal_d[tt[0]][-1][1]
            self._tt_best_d = min(self._tt_best_d, d_mate)
            if d_mate > self._tt_best_d + p.trouble_recede_m:
                if p.trouble_release_to_helper:
                    # on to where it was last seen first (see ``trouble_release_to_helper``)
                    self._release_xy, self._release_stall = self._seen_now[tt[0]], 0
                tt = self._trouble_target = None  # it turned away from the goal: let it go
        # in V(R_i): seen now, or (``trouble_sighting_at_send``) seen at the step it sent the Tr
        # bit that arrived now; without ``keep_trouble_helper`` (the paper column, §5 rule 3:
        # R_j in V(R_i)) a helper is followed only while it is in V(R_i) in this sense
        visible = self._seen_now if p.keep_trouble_helper else seen
        if tt is not None and tt[0] in visible:
            tt = self._trouble_target = (tt[0], visible[tt[0]])
        elif tt is None or math.hypot(tt[1][0] - self._px, tt[1][1] - self._py) <= near:
            helper = choose_helper(True, self._me_xy(), cands)
            tt = self._trouble_target = None if helper is None else (helper, seen[helper])
            self._tt_stall = 0
            if helper is not None and p.trouble_helper_towards_goal:
                hist = self._mate_goal_d.get(helper)
                self._tt_best_d = hist[-1][1] if hist else math.hypot(seen[helper][0] - goal[0],
                                                                      seen[helper][1] - goal[1])
        if tt is not None and (tt[0] in visible or p.keep_trouble_helper):
            self.mode = "trouble_follow"
            action, towards = self._head_to(tt[1], ("helper", tt[0]), stop_within_m=near, end_margin_m=near)
            if p.trouble_drop_stalled_helper:
                # a kept position out of sight that R1 does not close in on is given up
                # (see ``trouble_drop_stalled_helper``)
                self._tt_stall = 0 if (towards or tt[0] in self._seen_now) else self._tt_stall + 1
                if self._tt_stall >= p.trouble_drop_after_steps:
                    self._tt_stall = 0
                    self.trouble_helpers_dropped += 1
                    self._trouble_target = None
            if p.trouble_progress == "helper":
                # Sgorbissa & Arkin §5, Fig. 10: progress towards G_icurr = R_j
                progressing = towards
            elif p.trouble_progress == "moved":
                # a step that was not blocked counts (the distance to a teammate seen with
                # noise, eqs. 1-2, jumps by up to err_max·d)
                progressing = not obs.stalled
            else:
                # §5 rule 1: progress "towards the goal", R1's own: following a teammate away
                # from it keeps R1 in trouble (and following), so it is led along the
                # patrol until it sees its goal or the teammate takes it nearer
                progressing = goal_d < self._prev_goal_d - p.progress_min_fraction * self.step_m
            if (p.trouble_near_helper_m is not None and tt[0] in self._seen_now
                    and math.hypot(tt[1][0] - me_xy[0], tt[1][1] - me_xy[1]) <= p.trouble_near_helper_m):
                progressing = True  # close behind its helper (see ``trouble_near_helper_m``)
            self._return_since = None
            self._release_xy = None
        elif p.trouble_return and self._last_helper_xy is not None:
            # in trouble, no teammate in sight: back to where one was last seen, and wait
            # there (see ``trouble_return``); not progress towards the goal (Pr stays)
            self.mode = "trouble_return"
            point = self._last_helper_xy
            progressing = False
            if math.hypot(point[0] - me_xy[0], point[1] - me_xy[1]) > near:
                action, towards = self._head_to(point, ("return", point), stop_within_m=near, end_margin_m=near)
                progressing = towards and p.trouble_return_progress
            elif p.trouble_wait_steps == 0:
                self._last_helper_xy = None  # there, nobody in sight: A again
                self.mode = "own_goal"
            else:
                if self._return_since is None:
                    self._return_since = self._step
                action = Action()
                if self._step - self._return_since >= p.trouble_wait_steps:
                    self._last_helper_xy = self._return_since = None  # nobody came: A again
        return action, progressing

    def _go_to_release_point(self, me_xy: XY, progressing: bool) -> tuple[Action | None, bool]:
        """On to the last seen position of a teammate let go for walking away from R1's goal
        (``trouble_release_to_helper``); (action, or None once there or given up, and progressing)."""
        p = self.params
        action: Action | None = None
        # released by a helper walking away: on to its last seen position before A drives
        # (see ``trouble_release_to_helper``)
        near = 2.0 * self.radius_m + self.step_m
        point = self._release_xy
        if math.hypot(point[0] - me_xy[0], point[1] - me_xy[1]) > near:
            self.mode = "trouble_follow"
            action, progressing = self._head_to(point, ("release", point), stop_within_m=near,
                                                end_margin_m=near)
            self._release_stall = 0 if progressing else self._release_stall + 1
            if self._release_stall >= p.trouble_cr:
                self._release_xy = None
        else:
            self._release_xy = None
        return action, progressing

    def _remember_helper(self) -> None:
        """Keep where a teammate not in trouble was last seen (own frame; ``trouble_return``):
        the nearest one seen now, else one seen when it sent the Tr bit that arrived now."""
        me = self._me_xy()
        for source in (self._seen_now, self._teammate_tr_xy):
            ok = [xy for rid, xy in source.items() if self._teammate_tr.get(rid) is False
                  and not (self.params.trouble_helper_towards_goal and self._mate_recedes(rid))]
            if ok:
                self._last_helper_xy = min(ok, key=lambda xy: math.hypot(xy[0] - me[0], xy[1] - me[1]))
                self._return_since = None
                return

    def _track_mates(self, goal: XY) -> None:
        """Keep each teammate's straight distance to R1's goal over the last
        ``trouble_heading_steps`` steps it was seen (``trouble_helper_towards_goal``)."""
        keep = self._step - self.params.trouble_heading_steps
        for rid, xy in self._seen_now.items():
            hist = self._mate_goal_d.setdefault(rid, [])
            hist.append((self._step, math.hypot(xy[0] - goal[0], xy[1] - goal[1])))
        for rid in list(self._mate_goal_d):
            hist = [e for e in self._mate_goal_d[rid] if e[0] >= keep]
            if hist:
                self._mate_goal_d[rid] = hist
            else:
                del self._mate_goal_d[rid]

    def _mate_recedes(self, rid: int) -> bool:
        """Whether teammate ``rid`` went farther from R1's goal over its kept sightings."""
        hist = self._mate_goal_d.get(rid)
        if not hist or len(hist) < 2:
            return False
        return hist[-1][1] > hist[0][1] + 0.1 * self.params.trouble_recede_m
