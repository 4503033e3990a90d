"""Navigate: the trail robots' low-level controller (wall following, openings, sharp turns, Panic).

Vaughan, Støy, Sukhatme & Matarić, *Blazing a trail* §4.2 (and *Try to see it my way* §3.3,
which reuses it): "Navigation and obstacle avoidance is provided by two simple high-level
behaviours: Navigate and panic." Navigate "drives the robot around the environment following
walls, turning down corridors and following crumb trails"; an emergency stop runs in parallel
and hands control to Panic when an obstacle is critically close. The trail algorithms "provide
a hint of a 'good' heading" (§4.1): here ``preferred_heading_rad``, in the robot's own odometry
frame, or None to explore.

One step, in priority order:

1. **Panic** (:mod:`teamnav.control.nav.panic`) overrides everything: an obstacle critically
   close to the front, or the stall flag (``panic_on_stall``, a gap-fill), stops the robot and starts Panic; Navigate resumes
   when Panic times out.
2. A **sharp turn** under way (on the spot, by odometry heading) runs to its end; an
   **advance** to the centre of a chosen opening runs until the odometry has covered the
   distance, then the 90 deg turn starts, to the heading chosen when the opening was seen. The
   advance follows the wall (``advance_hold_heading=True`` holds the heading along the wall
   instead); a left-wall follower at a T-junction can swing into the left branch before it gets
   to turn right: swung more than 90 deg past the chosen heading, it turns the long way round
   (gap filled; it used to skip the turn and carry on down the wrong branch).
3. **Against the trail**: "If the robot is heading in approximately the opposite direction to
   the trail it makes a sharp 180° right turn" (§4.2). "Approximately opposite" is taken as
   more than ``reverse_threshold_deg`` (default 150 deg) between the odometry heading and the
   preferred heading; afterwards no second reversal for ``reverse_cooldown_s`` nor before the
   robot has driven ``reverse_cooldown_m`` (gap filled: with a time cooldown alone, a robot whose
   hint flips at the end of a trail, or near a place, turned back and forth on the spot every
   few seconds; 0 m gives the time rule alone). A caller may veto a reversal for one step
   (``allow_reverse=False``, e.g. a hint from too few crumbs). Nor does a robot reverse within
   ``reverse_memory_m`` of a spot (odometry) where it reversed since its last
   :meth:`Navigate.turn_around` (gap filled: a drifted trail that points into a dead end made
   robots reverse at the same spot, follow the dead end round and come back to it, for tens of
   minutes; 0 m: no memory).
4. **Openings** (:mod:`teamnav.control.nav.openings`): "If the robot detects a corridor and it
   is not already turning, there is a 50% chance that the robot will decide to take the new
   corridor and make a sharp 90° turn into the corridor" (exploring; ``p_take_opening``). The
   robot drives on to the opening's centre, then turns on the spot until it faces square to
   the wall the opening is cut into (90 deg when it was driving parallel to the wall). With a
   trail, "the corridor-seeking behaviour is overridden by a trail-following component if the
   trail points away from the opening": the robot takes the direction, among continuing
   straight along the corridor (when some beam within ``straight_half_angle_deg`` of it reads
   ``straight_clear_m``) and the detected openings (square to the wall, left or right), closest
   to the preferred heading. This is our reading; the
   paper's results paragraph (§5.1) says the robot turns "if the average heading of the crumbs
   points to the side where the opening is detected", i.e. within 90 deg of the opening
   direction; ``trail_rule="side"`` gives that rule instead (any preferred heading more than
   ``side_rule_min_deg`` to that side, or any at all when straight on is blocked, as at a
   T-junction: there the wall follower would otherwise take its own side whatever the hint).
   Exploring, each opening is decided once: a side is not
   looked at again until the robot has driven ``opening_cooldown_m`` (or the opening's width)
   further; with a trail, an opening passed by is looked at again while it stays in sight (a
   trail's hint changes as the robot nears a corner), and the cooldown follows a turn.
5. Otherwise **wall following** with the sliding box (:mod:`teamnav.control.nav.wall_follow`).

Meeting flags (gap-fills, all off by default, i.e. the rules above; for trail robots that meet
at corners, where Panic or the wall follower tracing round the other robot leaves a robot facing
a wrong branch; see :mod:`teamnav.papers.trails.brains.trail_share` for their measurements, all made
before 8a4187d (2026-11-26) gave the trail brains ``box_reach_m = 2.0``; with Navigate's 1.2 m a robot in
the oncoming lane of a 1.8 m corridor never saw its own wall, which was the larger part of those
meetings: :data:`teamnav.papers.trails.brains.blazing_trail.NAVIGATE_DEFAULTS`):

6. ``hint_skips_cooldown``: with a trail hint, the opening cool-down that follows a Panic or a
   sharp turn is ignored (an opening already decided keeps its own cool-down).
   ``face_hint_after_panic``: the first hint after a Panic more than ``face_hint_min_deg`` off
   the heading (and short of the 180 deg rule) turns the robot on the spot towards it before the
   wall follower picks a side. ``give_way_s`` > 0: an obstacle within ``give_way_m`` inside
   ``±give_way_half_angle_deg`` that was not there ``give_way_window_s`` ago (the front's
   nearest return fell by more than the distance driven plus ``give_way_jump_m``, heading held
   within 15 deg: another robot, not a wall approached) stops the robot (v = w = 0) until it is
   gone or ``give_way_s`` has passed, before Panic's emergency stop; once per metre driven.
   ``step(..., reverse_ignore_memory=True)`` lets the 180 deg rule ignore the reversal memory and
   distance cool-down for one step (the caller's recovery hint points back to its trail).
   ``meet_guard_deg`` > 0 (the meeting guard): for ``meet_guard_m`` of odometry and at most
   ``meet_guard_s`` after a meeting (a Panic ended, or an obstacle appeared ahead as for
   ``give_way_s``), the wall follower may not turn the robot further than ``meet_guard_deg``
   from the trail's hint nor hold a heading that far off: while it would, the robot turns
   towards the hint instead, at ``min_speed_fraction`` of cruise (standing, when the box is
   blocked). Why: in the traced head-on meetings (``try-to-see-it-my-way``, seeds 0-3) the
   robot blocked by the other turned on the spot, its wall follower came round past 90 deg and
   took it back the way it came, or down the wrong branch at the corner (the rules above then
   keep it there: cool-downs, reversal memory). A 2002 robot can do this with its own sensing:
   its odometry heading over a few seconds and the trail's hint. The time limit stops two
   guarded robots from facing each other for ever (without it, 24 % efficiency on seed 0).
   Measured (trail_share's docstring): no gain at 90 or 60 deg, so it stays off.
   ``give_way_bold_s`` (None = off: both robots wait ``give_way_s``, a symmetric rule): an
   asymmetric give-way after Vaughan, Støy, Sukhatme & Matarić, "Go ahead, make my day: robot
   conflict resolution by aggressive competition" (SAB 2000) and the "local investment"
   aggression of their ICAR 2005 follow-up: when two robots block each other one yields and the
   other proceeds, and the robot that has invested more wins. Gap-fill: those robots displayed
   and compared aggression; ours see each other only in the laser, so each decides from its own
   state alone: the caller passes ``step(..., bold=True)`` for the robot with the higher
   investment (trail-share-v1: loaded, heading home), which then waits only
   ``give_way_bold_s`` and drives on (its wall follower takes it round the other robot); a
   ``bold=False`` robot waits the full ``give_way_s`` while the obstacle stays ahead. A head-on
   meeting on the route (one robot out, one back) is thus resolved without a contest.
   Measured (f9f4cf8, 2026-11-24) on ``try-to-see-it-my-way`` with its drift, 30 min, seeds 0-11, paired
   against trail-share-v1's default (give_way_s = 3, symmetric), eff = ``place_speed_mps`` / 0.4,
   trip = ``trip_time_s_after_10min_mean``: bold 0.5 s (yielder 3 s): eff 54.8 % against 54.5 %
   (paired +0.2 ± 2.8 points, 7/12 seeds better), trip 120.4 s against 129.6 s (-9.1 ± 8.0 s,
   7/12); bold 0 s with the yielder at give_way_s = 6: eff -0.05 ± 2.1 points (6/12), trip
   -8.9 ± 6.2 s (6/12). Within the noise either way: it stays off (no 3-h runs).

Odometry is used only as the robot's own dead reckoning over short spans (how far it has turned,
how far it has driven), never as a position in any shared frame.
"""

from __future__ import annotations

import math
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, model_validator

from teamnav.control.paper_rules import paper_rules_validator

from teamnav.control.nav.openings import Opening, OpeningDetector
from teamnav.control.nav.panic import Panic
from teamnav.control.nav.wall_follow import BoxCommand, SlidingBox
from teamnav.control.protocol import RobotInfo
from teamnav.control.types import Observation

__all__ = ["Navigate", "NavigateParams"]

_TWO_PI = 2.0 * math.pi


def _wrap(a_rad: float) -> float:
    """Scalar angle wrap to [-pi, pi] (the hot-path twin of ``teamnav.geometry.wrap_angle``)."""
    return math.remainder(a_rad, _TWO_PI)


class NavigateParams(BaseModel):
    """Parameters of :class:`Navigate` (units in the names; module docstring for the rules).

    Speeds and turn rates above the robot's limits are capped at construction. Defaults follow
    the papers where they give a number: cruise 0.25 m/s (*Try to see it my way* §3.6), a 50 %
    chance at openings (*Blazing* §4.2), a box "a little bigger than the robot"; the rest are
    ours, tuned on the trail office (1.8 m corridors, 1 m doors, Pioneer-sized robots).

    Groups: sliding box (``box_*``, ``slide_step_m``, ``steer_gain_per_s``,
    ``min_speed_fraction``, ``wall_side``; the box is the robot's diameter plus two
    ``box_margin_m`` wide, spans ``box_near_m``..``box_length_m`` ahead, and its first position
    reaches ``box_reach_m`` to the followed side: walls further away than that are not
    followed); openings (``opening_*``, ``p_take_opening``; an opening must be the robot's
    diameter plus ``opening_margin_m`` wide); trail (``trail_rule``, ``side_rule_min_deg``,
    ``straight_*``, ``reverse_*``); sharp turns (``turn_rate_radps``, ``turn_tolerance_deg``,
    ``turn_timeout_s``); Panic (``panic_*``: critical within ``panic_clearance_m`` of the body
    inside ``±panic_half_angle_deg``; free when a box ``panic_free_m`` deep is clear ahead).

    Meeting flags (all off by default = the behaviour above; gap-fills for robots that meet at
    corners, module docstring item 6): ``hint_skips_cooldown``, ``face_hint_after_panic``
    (``face_hint_min_deg``), ``give_way_s`` (``give_way_*``), ``meet_guard_deg``
    (``meet_guard_m``, ``meet_guard_s``).

    ``paper_rules=True`` (:mod:`teamnav.control.paper_rules`): every gap-fill of
    :attr:`PAPER_RULES` takes the paper's value (the trail brains pass it down with theirs).
    ``box_ahead_free`` (True, a gap-fill): the sliding box drives straight only when the box
    straight ahead is free too (:mod:`~teamnav.control.nav.wall_follow`, "Big open space");
    ``panic_on_stall`` (True, a gap-fill): the stall flag starts Panic like an obstacle
    critically close to the front.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    #: Navigate's gap-fills whose other value is the paper's rule (Blazing §4.2, reused by Try §3.3)
    PAPER_RULES: ClassVar[dict[str, Any]] = {
        # Blazing §4.2: "If the robot is heading in approximately the opposite direction to the trail it
        # makes a sharp 180° right turn" -- no time cool-down, no distance cool-down, no memory of spots
        "reverse_cooldown_s": 0.0,
        "reverse_cooldown_m": 0.0,
        "reverse_memory_m": 0.0,
        # Blazing §4.2: "If there are no obstacles in the first box that is placed it is assumed that the
        # robot is in a big open space and therefore moves forward" -- the first box alone decides
        "box_ahead_free": False,
        # Blazing §4.2: "An emergency-stop mechanism ... monitoring the laser sensor; if the robot gets
        # too close to any obstacle it will stop and switch to the panic behaviour" -- the laser only
        "panic_on_stall": False,
    }
    PAPER_RULE_NOTES: ClassVar[dict[str, str]] = {
        "reverse_cooldown_s": "Blazing §4.2: the 180° turn whenever heading against the trail (no 5 s time cool-down)",
        "reverse_cooldown_m": "Blazing §4.2: no distance cool-down after a 180° turn",
        "reverse_memory_m": "Blazing §4.2: no memory of the spots where the robot reversed",
        "box_ahead_free": "Blazing §4.2: first box free = big open space, straight on (no check of the box ahead)",
        "panic_on_stall": "Blazing §4.2: the emergency stop watches the laser only (no stall-triggered Panic)",
    }

    cruise_speed_mps: float = Field(0.25, gt=0.0, le=10.0)
    turn_rate_radps: float = Field(1.0, gt=0.0, le=20.0)
    steer_gain_per_s: float = Field(1.5, gt=0.0, le=50.0)
    min_speed_fraction: float = Field(0.3, ge=0.0, le=1.0)
    wall_side: Literal["left", "right"] = "left"
    box_margin_m: float = Field(0.15, ge=0.0, le=5.0)
    box_length_m: float = Field(1.0, gt=0.0, le=20.0)
    box_near_m: float = Field(0.1, ge=-1.0, le=20.0)
    box_reach_m: float = Field(1.2, gt=0.0, le=20.0)
    slide_step_m: float = Field(0.05, gt=0.0, le=1.0)
    p_take_opening: float = Field(0.5, ge=0.0, le=1.0)
    advance_hold_heading: bool = False
    opening_near_m: float = Field(2.0, gt=0.0, le=50.0)
    opening_jump_m: float = Field(1.5, gt=0.0, le=50.0)
    opening_margin_m: float = Field(0.2, ge=0.0, le=5.0)
    opening_extreme_deg: float = Field(20.0, gt=0.0, le=90.0)
    opening_sector_deg: float = Field(80.0, gt=0.0, le=180.0)
    opening_wall_tolerance_m: float = Field(0.4, ge=0.0, le=10.0)
    opening_cooldown_m: float = Field(1.5, ge=0.0, le=50.0)
    straight_clear_m: float = Field(3.0, ge=0.0, le=1000.0)
    straight_half_angle_deg: float = Field(20.0, gt=0.0, le=90.0)
    trail_rule: Literal["closest", "side"] = "closest"
    side_rule_min_deg: float = Field(20.0, ge=0.0, le=90.0)
    reverse_threshold_deg: float = Field(150.0, ge=90.0, le=180.0)
    reverse_cooldown_s: float = Field(5.0, ge=0.0, le=600.0)
    reverse_cooldown_m: float = Field(3.0, ge=0.0, le=1000.0)
    reverse_memory_m: float = Field(3.0, ge=0.0, le=1000.0)
    turn_tolerance_deg: float = Field(3.0, gt=0.0, le=45.0)
    turn_timeout_s: float = Field(8.0, gt=0.0, le=600.0)
    panic_clearance_m: float = Field(0.12, gt=0.0, le=5.0)
    panic_half_angle_deg: float = Field(60.0, gt=0.0, le=180.0)
    panic_free_m: float = Field(0.8, gt=0.0, le=20.0)
    panic_forward_s: float = Field(2.0, ge=0.0, le=60.0)
    panic_turn_timeout_s: float = Field(8.0, gt=0.0, le=600.0)
    hint_skips_cooldown: bool = False
    face_hint_after_panic: bool = False
    face_hint_min_deg: float = Field(45.0, ge=0.0, le=180.0)
    give_way_s: float = Field(0.0, ge=0.0, le=600.0)
    give_way_m: float = Field(1.0, gt=0.0, le=20.0)
    give_way_half_angle_deg: float = Field(30.0, gt=0.0, le=90.0)
    give_way_window_s: float = Field(1.0, gt=0.0, le=60.0)
    give_way_jump_m: float = Field(0.1, ge=0.0, le=20.0)
    give_way_bold_s: float | None = Field(None, ge=0.0, le=600.0)
    meet_guard_deg: float = Field(0.0, ge=0.0, le=180.0)
    meet_guard_m: float = Field(3.0, gt=0.0, le=100.0)
    meet_guard_s: float = Field(8.0, gt=0.0, le=600.0)
    box_ahead_free: bool = True
    panic_on_stall: bool = True
    paper_rules: bool = False

    _paper_rules = paper_rules_validator()

    @model_validator(mode="after")
    def _ordered(self) -> "NavigateParams":
        if self.opening_sector_deg < self.opening_extreme_deg:
            raise ValueError(
                f"opening_sector_deg must be >= opening_extreme_deg ({self.opening_extreme_deg}), "
                f"got {self.opening_sector_deg}"
            )
        if self.box_near_m >= self.box_length_m:
            raise ValueError(f"box_near_m must be < box_length_m ({self.box_length_m}), got {self.box_near_m}")
        return self


class Navigate:
    """The Navigate + Panic controller of the trail papers, as a library the trail brains call.

    Parameters
    ----------
    params : NavigateParams
    rng : numpy.random.Generator
        The robot's own stream (openings taken at random, Panic's turn direction).
    info : RobotInfo
        The robot's radius, limits, ``dt_s`` and sensors.
    laser : str, default "laser"
        Name of the range sensor to read (a scanning laser in the papers).

    Attributes
    ----------
    mode : str
        ``"navigate"``, ``"advance"`` (driving to an opening's centre), ``"turn"`` (a sharp
        90 or 180 deg turn) or ``"panic"``.

    Examples
    --------
    >>> import numpy as np
    >>> from teamnav.control import Observation, RangeScan, RobotInfo, SensorInfo
    >>> angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    >>> info = RobotInfo(0, 1, 0.25, "unicycle", 0.5, 2.0, 0.1, 0.1,
    ...                  sensors={"laser": SensorInfo("laser", "laser", angles, 8.0)})
    >>> nav = Navigate(NavigateParams(), np.random.default_rng(0), info)
    >>> scan = RangeScan(np.full(181, 8.0), angles, 8.0)
    >>> obs = Observation(0, 0, 0.0, np.zeros(3), np.zeros(3), scans={"laser": scan})
    >>> nav.step(obs), nav.mode
    ((0.25, 0.0), 'navigate')
    """

    def __init__(self, params: NavigateParams, rng: np.random.Generator, info: RobotInfo, laser: str = "laser") -> None:
        if not isinstance(params, NavigateParams):
            raise ValueError(f"params must be a NavigateParams, got {type(params).__name__}")
        try:
            sensor = info.sensors[laser]
        except KeyError:
            raise ValueError(
                f"laser must name one of robot {info.robot_id}'s range sensors ({', '.join(sorted(info.sensors))}), "
                f"got {laser!r}"
            ) from None
        self.params = params
        self.info = info
        self.rng = rng
        self.laser = laser
        self.angles_rad = np.asarray(sensor.angles_rad, dtype=np.float64).copy()
        self.max_range_m = float(sensor.max_range_m)
        self.max_v_mps = float(info.max_v_mps)
        self.max_omega_radps = float(info.max_omega_radps)
        self.dt_s = float(info.dt_s)
        p = params
        self.cruise_mps = min(p.cruise_speed_mps, self.max_v_mps)
        self.turn_rate_radps = min(p.turn_rate_radps, self.max_omega_radps)
        self.side_sign = 1.0 if p.wall_side == "left" else -1.0
        radius = float(info.radius_m)
        width = 2.0 * radius + 2.0 * p.box_margin_m
        offset_max = max(p.slide_step_m, p.box_reach_m - 0.5 * width)
        self.box = SlidingBox(self.angles_rad, width, p.box_length_m, p.box_near_m, offset_max,
                              p.slide_step_m, self.cruise_mps, p.steer_gain_per_s, self.turn_rate_radps,
                              p.min_speed_fraction, p.wall_side, ahead_must_be_free=p.box_ahead_free)
        self.openings = OpeningDetector(self.angles_rad, p.opening_near_m, p.opening_jump_m,
                                        2.0 * radius + p.opening_margin_m, p.opening_extreme_deg,
                                        p.opening_sector_deg, p.opening_wall_tolerance_m)
        self.panic = Panic(self.angles_rad, radius, p.panic_clearance_m, p.panic_half_angle_deg, width,
                           p.panic_free_m, self.cruise_mps, self.turn_rate_radps, p.panic_forward_s,
                           p.panic_turn_timeout_s, self.dt_s)
        self._straight_half_rad = math.radians(p.straight_half_angle_deg)
        self._reverse_rad = math.radians(p.reverse_threshold_deg)
        self._side_rule_rad = math.radians(p.side_rule_min_deg)
        self._turn_tol_rad = math.radians(p.turn_tolerance_deg)
        self._turn_max_steps = max(1, int(round(p.turn_timeout_s / self.dt_s)))
        self._gw_front = np.flatnonzero(np.abs(self.angles_rad) <= math.radians(p.give_way_half_angle_deg))
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Forget every manoeuvre and cooldown (e.g. after arriving at a place); back to navigate."""
        self.mode = "navigate"
        self.panic.reset()
        self.box.reset()
        self.box_state = "open"
        self.box_offset_m = math.nan
        self.last_opening: str | None = None
        self._odo_m = 0.0  # odometry path length so far [m]
        self._last_pose: tuple[float, float, float] | None = None
        self._cool_until_m = [0.0, 0.0]  # per side (left, right): no decision before this odometry length
        self._reverse_after_s = -math.inf
        self._reverse_after_m = -math.inf
        self._reversed_at: list[tuple[float, float]] = []  # odometry spots of this leg's reversals
        #: 180 deg turns made by the trail rule (step 3) so far; the brains log it (``reversals``)
        self.n_reversals = 0
        self._turn_dir = 0.0
        self._turn_goal_rad = 0.0
        self._turned_rad = 0.0
        self._turn_steps = 0
        self._advance_to_m = 0.0
        self._advance_steps = 0
        self._advance_max_steps = 0
        self._pending_dir = 0.0
        self._pending_heading_rad = 0.0
        self._advance_heading_rad = 0.0
        self._leave_until_m = 0.0  # no reversal and no openings before this odometry length
        self._cool_manoeuvre = [False, False]  # per side: the cool-down follows a Panic or a turn
        self._face_hint = False  # a Panic just ended: turn to the hint first (face_hint_after_panic)
        self._front_hist: list[tuple[float, float, float]] = []  # (front min [m], odo [m], th [rad])
        self._give_way_until_s = -math.inf
        self._give_way_after_m = -math.inf
        self._gw_active = False
        self._meet_until_m = -math.inf  # meet_guard_deg: the guard holds until this odometry length
        self._meet_until_s = -math.inf  # ... and this time
        self.guarded = False  # the meeting guard overrode the wall follower this step

    def turn_around(self, leave_m: float = 0.0) -> None:
        """Start a sharp 180 deg right turn now (any manoeuvre or Panic is dropped), then wall
        follow for ``leave_m`` of odometry with no reversal and no opening decisions.

        For a robot that has reached a place and must go back the way it came (*Blazing* §5.1:
        "Ant turned around at the resource position and followed its trail back"). Gap filled:
        the paper's 180 deg rule does this only when the trail near the place points clearly
        the other way; near a place the trail holds both legs and the robots' turning on the
        spot, and robots were seen spinning there for minutes (180 deg turns every few seconds).
        """
        if not (leave_m >= 0.0 and math.isfinite(leave_m)):
            raise ValueError(f"leave_m must be a finite number of metres >= 0, got {leave_m!r}")
        self.panic.reset()
        self.box.reset()
        self._start_turn(-self.side_sign, math.pi)
        self._leave_until_m = self._odo_m + leave_m
        self._reverse_after_s = -math.inf
        self._reverse_after_m = -math.inf
        self._reversed_at = []

    @property
    def leaving(self) -> bool:
        """True while a :meth:`turn_around` has the robot turning or driving off (no trail rules)."""
        return self._odo_m < self._leave_until_m

    def _reversed_near(self, x: float, y: float) -> bool:
        r2 = self.params.reverse_memory_m ** 2
        return any((x - a) ** 2 + (y - b) ** 2 < r2 for a, b in self._reversed_at)

    def _cool(self, extra_m: float) -> None:
        self._cool_until_m = [self._odo_m + extra_m, self._odo_m + extra_m]
        self._cool_manoeuvre = [True, True]

    def _appeared_ahead(self, ranges_m: np.ndarray, th: float) -> bool:
        """``give_way_s``: an obstacle within ``give_way_m`` ahead that was not there
        ``give_way_window_s`` ago (the front's nearest return has dropped by more than the
        distance driven plus ``give_way_jump_m``, while the heading held within 15 deg)."""
        p = self.params
        front = float(ranges_m[self._gw_front].min()) if self._gw_front.size else math.inf
        hist = self._front_hist
        hist.append((front, self._odo_m, th))
        n = max(1, int(round(p.give_way_window_s / self.dt_s)))
        if len(hist) > n + 1:
            del hist[0]
        if front >= p.give_way_m or len(hist) <= n:
            return False
        f0, o0, th0 = hist[0]
        return (abs(_wrap(th - th0)) < math.radians(15.0)
                and f0 - front > (self._odo_m - o0) + p.give_way_jump_m)

    def _meet(self, t_s: float) -> None:
        """A meeting (a Panic ended, or an obstacle appeared ahead): the guard holds for the next
        ``meet_guard_m`` of odometry and at most ``meet_guard_s``."""
        self._meet_until_m = self._odo_m + self.params.meet_guard_m
        self._meet_until_s = t_s + self.params.meet_guard_s

    def _start_turn(self, direction: float, amount_rad: float) -> None:
        self.mode = "turn"
        self._turn_dir = direction
        self._turn_goal_rad = amount_rad
        self._turned_rad = 0.0
        self._turn_steps = 0

    # ------------------------------------------------------------------ rules
    def _turn_command(self) -> tuple[float, float] | None:
        """One step of a sharp turn on the spot, or None when it is done (or timed out)."""
        remaining = self._turn_goal_rad - self._turn_dir * self._turned_rad
        self._turn_steps += 1
        if remaining <= self._turn_tol_rad or self._turn_steps > self._turn_max_steps:
            return None
        # Full rate, easing off over the last ~0.3 rad so the turn does not overshoot.
        rate = self.turn_rate_radps * min(1.0, max(0.3, remaining / 0.3))
        return 0.0, self._turn_dir * rate

    def _straight_ok(self, ranges_m: np.ndarray, along_rad: float) -> bool:
        """Continuing straight on is an option: some beam within ``straight_half_angle_deg`` of the
        corridor's direction ``along_rad`` (body frame) reads at least ``straight_clear_m``."""
        near = np.abs(self.angles_rad - along_rad) <= self._straight_half_rad
        return bool(near.any()) and float(ranges_m[near].max()) >= self.params.straight_clear_m

    def _choose_opening(self, found: list[Opening], ranges_m: np.ndarray, heading_rad: float,
                        preferred_rad: float | None) -> Opening | None:
        """Which detected opening to take, if any (*Blazing* §4.2 rules; module docstring, item 4)."""
        if preferred_rad is None:
            # Exploring: each opening is taken with p_take_opening; both chosen: one at random.
            draws = [self.rng.random() for _ in found]
            taken = [o for o, u in zip(found, draws) if u < self.params.p_take_opening]
            if len(taken) > 1:
                return taken[int(self.rng.integers(len(taken)))]
            return taken[0] if taken else None
        along = found[0].wall_rad  # straight on = along the corridor's wall
        if self.params.trail_rule == "side":
            rel = _wrap(preferred_rad - heading_rad - along)
            # Straight on blocked (a T-junction): any hint to an opening's side takes it.
            margin = self._side_rule_rad if self._straight_ok(ranges_m, along) else 0.0
            for o in found:
                if o.side * rel > margin:
                    return o
            return None
        best: Opening | None = None
        best_err = abs(_wrap(preferred_rad - heading_rad - along)) if self._straight_ok(ranges_m, along) else math.inf
        for o in found:
            err = abs(_wrap(preferred_rad - (heading_rad + o.direction_rad)))
            if err < best_err:
                best, best_err = o, err
        return best

    def _clip(self, v: float, w: float) -> tuple[float, float]:
        return (float(min(max(v, 0.0), self.max_v_mps)),
                float(min(max(w, -self.max_omega_radps), self.max_omega_radps)))

    # ------------------------------------------------------------------ step
    def step(self, obs: Observation, preferred_heading_rad: float | None = None, *,
             allow_reverse: bool = True, reverse_ignore_memory: bool = False,
             bold: bool = False) -> tuple[float, float]:
        """The command ``(v_mps, omega_radps)`` for this step.

        Parameters
        ----------
        obs : Observation
            The robot's own observation; reads its laser scan, odometry pose and stall flag.
        preferred_heading_rad : float or None
            Heading suggested by a trail, in the robot's own odometry frame [rad]; None to
            explore (random turns at openings).
        allow_reverse : bool, default True
            False: no 180 deg reversal this step whatever the hint (the hint still steers at
            openings).
        reverse_ignore_memory : bool, default False
            True: a reversal this step ignores ``reverse_memory_m`` and ``reverse_cooldown_m``
            (the time cooldown still holds), e.g. for a hint back to a trail the robot left.
        bold : bool, default False
            The robot's investment is the higher one (e.g. loaded): with ``give_way_bold_s``
            set, a give-way lasts only ``give_way_bold_s`` (module docstring item 6).

        Returns
        -------
        (float, float)
            Forward speed [m/s] (never negative) and turn rate [rad/s], within the robot's limits.
        """
        try:
            scan = obs.scans[self.laser]
        except KeyError:
            raise ValueError(
                f"observation of robot {obs.robot_id} must carry scan {self.laser!r}, has {sorted(obs.scans)}"
            ) from None
        r = np.asarray(scan.ranges_m, dtype=np.float64)
        if r.shape != self.angles_rad.shape:
            raise ValueError(f"scan {self.laser!r} must have {self.angles_rad.size} beams, got shape {r.shape}")
        if not np.isfinite(r).all():
            r = np.where(np.isfinite(r), r, self.max_range_m)
        x, y, th = np.asarray(obs.odom_pose, dtype=np.float64)[:3].tolist()
        if self._last_pose is not None:
            lx, ly, lth = self._last_pose
            self._odo_m += math.hypot(x - lx, y - ly)
            self._turned_rad += _wrap(th - lth)
        self._last_pose = (x, y, th)

        self.guarded = False
        # 1. Panic overrides Navigate (emergency stop running in parallel).
        if self.mode == "panic":
            v, w = self.panic.step(r)
            if not self.panic.active:
                self.mode = "navigate"
                self._cool(self.params.opening_cooldown_m)
                self._face_hint = self.params.face_hint_after_panic
                if self.params.meet_guard_deg > 0.0:
                    self._meet(obs.time_s)
            return self._clip(v, w)
        appeared = False
        if self.params.give_way_s > 0.0 or self.params.meet_guard_deg > 0.0:
            appeared = self._appeared_ahead(r, th) and self.mode in ("navigate", "advance")
            if appeared and self.params.meet_guard_deg > 0.0 and self._odo_m >= self._meet_until_m:
                self._meet(obs.time_s)
        # 1b. Give way (give_way_s > 0): an obstacle that has just appeared ahead (another
        # robot) stops the robot for up to give_way_s, until it is gone.
        if self.params.give_way_s > 0.0:
            if (appeared and obs.time_s >= self._give_way_until_s and self._odo_m >= self._give_way_after_m
                    and not obs.stalled):
                wait_s = self.params.give_way_s
                if bold and self.params.give_way_bold_s is not None:  # SAB 2000 / ICAR 2005 (gap-fill)
                    wait_s = min(wait_s, self.params.give_way_bold_s)
                self._give_way_until_s = obs.time_s + wait_s
                self._give_way_after_m = self._odo_m + 1.0  # drive 1 m before giving way again
                self._gw_active = True
            if self._gw_active:
                gw_front = float(r[self._gw_front].min()) if self._gw_front.size else math.inf
                if obs.time_s < self._give_way_until_s and gw_front < self.params.give_way_m and not obs.stalled:
                    return 0.0, 0.0
                self._gw_active = False
        if (obs.stalled and self.params.panic_on_stall) or self.panic.critical(r):
            self.panic.start(self.rng)
            self.mode = "panic"
            return self._clip(*self.panic.step(r))

        # 2. Manoeuvres under way.
        if self.mode == "turn":
            cmd = self._turn_command()
            if cmd is not None:
                return self._clip(*cmd)
            self.mode = "navigate"
            self._cool(self.params.opening_cooldown_m)
        elif self.mode == "advance":
            self._advance_steps += 1
            if self._odo_m >= self._advance_to_m or self._advance_steps > self._advance_max_steps:
                # Square to the wall: the heading chosen when the opening was seen (odometry frame).
                # A robot swung more than 90 deg the wrong way (its wall follower took an opening
                # on the other side) turns the long way round to the chosen heading.
                amount = self._pending_dir * _wrap(self._pending_heading_rad - th)
                self._start_turn(self._pending_dir, amount + _TWO_PI if amount < -0.5 * math.pi else max(0.0, amount))
                cmd = self._turn_command()
                if cmd is not None:
                    return self._clip(*cmd)
                self.mode = "navigate"
            else:
                box = self.box.command(r)
                self.box_state, self.box_offset_m = box.state, box.offset_m
                if self.params.advance_hold_heading and box.state != "blocked":
                    err = _wrap(self._advance_heading_rad - th)
                    return self._clip(self.cruise_mps * max(self.params.min_speed_fraction, math.cos(err)),
                                      self.params.steer_gain_per_s * err)
                return self._clip(box.v_mps, box.omega_radps)

        leaving = self._odo_m < self._leave_until_m
        if leaving:
            preferred_heading_rad = None
        # 3. Heading against the trail: a sharp 180 deg right turn.
        if (preferred_heading_rad is not None and allow_reverse and obs.time_s >= self._reverse_after_s
                and abs(_wrap(preferred_heading_rad - th)) > self._reverse_rad
                and (reverse_ignore_memory or (self._odo_m >= self._reverse_after_m and not self._reversed_near(x, y)))):
            self._reversed_at = self._reversed_at[-15:] + [(x, y)]  # bounded: a leg may never end
            self.n_reversals += 1
            self._reverse_after_s = obs.time_s + self.params.reverse_cooldown_s
            self._reverse_after_m = self._odo_m + self.params.reverse_cooldown_m
            self._start_turn(-self.side_sign, math.pi)
            cmd = self._turn_command()
            if cmd is not None:
                return self._clip(*cmd)
            self.mode = "navigate"
        # 3b. face_hint_after_panic: the first hint after a Panic turns the robot on the spot
        # towards it (more than face_hint_min_deg away) before the wall follower picks a side.
        if self._face_hint and preferred_heading_rad is not None and self.mode == "navigate":
            self._face_hint = False
            err = _wrap(preferred_heading_rad - th)
            if abs(err) > math.radians(self.params.face_hint_min_deg):
                self._start_turn(1.0 if err > 0 else -1.0, abs(err))
                cmd = self._turn_command()
                if cmd is not None:
                    return self._clip(*cmd)
                self.mode = "navigate"

        box: BoxCommand = self.box.command(r)
        self.box_state, self.box_offset_m = box.state, box.offset_m
        # 4. Openings: decided once each, not while the box has the robot turning on the spot.
        if box.state != "blocked" and not leaving:
            left, right = self.openings.detect(r)
            skip = self.params.hint_skips_cooldown and preferred_heading_rad is not None
            found = [o for k, o in enumerate((left, right))
                     if o is not None and (self._odo_m >= self._cool_until_m[k] or (skip and self._cool_manoeuvre[k]))]
            if found:
                choice = self._choose_opening(found, r, th, preferred_heading_rad)
                # A random decision is made once per opening; a trail decision is looked at
                # again while the opening stays in sight (the hint may change meanwhile).
                if preferred_heading_rad is None or choice is not None:
                    for o in found:
                        k = 0 if o.side > 0 else 1
                        span = o.width_m if math.isfinite(o.width_m) else 0.0
                        self._cool_until_m[k] = self._odo_m + max(self.params.opening_cooldown_m, span)
                        self._cool_manoeuvre[k] = False
                if choice is not None:
                    self.last_opening = "left" if choice.side > 0 else "right"
                    self.mode = "advance"
                    self._pending_dir = float(choice.side)
                    self._pending_heading_rad = th + choice.direction_rad
                    self._advance_heading_rad = th + choice.wall_rad
                    self._advance_to_m = self._odo_m + choice.advance_m
                    self._advance_steps = 0
                    self._advance_max_steps = int(round((choice.advance_m / self.cruise_mps + 3.0) / self.dt_s))
        # 5b. Meeting guard (meet_guard_deg > 0): within meet_guard_m after a meeting, the wall
        # follower may not turn the robot further from the trail's hint than meet_guard_deg
        # (nor hold a heading that far off): it turns towards the hint instead, slowly.
        if (self.params.meet_guard_deg > 0.0 and preferred_heading_rad is not None and self.mode == "navigate"
                and self._odo_m < self._meet_until_m and obs.time_s < self._meet_until_s):
            err = _wrap(preferred_heading_rad - th)
            if abs(err) > math.radians(self.params.meet_guard_deg) and box.omega_radps * err <= 0.0:
                self.guarded = True
                w = math.copysign(min(self.turn_rate_radps, self.params.steer_gain_per_s * abs(err)), err)
                return self._clip(min(box.v_mps, self.cruise_mps * self.params.min_speed_fraction), w)
        # 5. Wall following.
        return self._clip(box.v_mps, box.omega_radps)
