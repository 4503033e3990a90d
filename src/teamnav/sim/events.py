"""Task events at places: "the robot got a resource at the source", "it took it home".

Vaughan et al. (*Blazing a trail* §5, *Try to see it my way* §3) give a robot a task signal
when it reaches the source or home. Places are discs (:class:`~teamnav.sim.config.PlaceConfig`);
a robot is *inside* when its centre is within ``radius_m`` of the place (inclusive).

- ``on="enter"``: the event fires on the step a robot goes from outside to inside; it fires
  again only after the robot has left and come back. A robot that *starts* inside does not
  fire until it has left and re-entered.
- ``on="inside"``: the event fires on every step the robot is inside (not at step 0).
- A place with ``event=None`` is a marker only and fires nothing.

Timing: events are evaluated in step ``k`` **after** motion, from the new true positions,
and go into the robot's observation of the same step ``k`` (no extra step of delay: the
robot learns it has arrived in the very observation that shows it there). Every firing is
also recorded as ``(step, time, robot, place, event)`` for metrics.

Moving places (beyond the papers: Vaughan et al. 2000 §6 leave a moving resource as future work
and say nothing of how it moves; the rules here are ours): a place with a ``motion``
(:class:`~teamnav.sim.config.PlaceMotion`) is tested at its position at the step's time
(:func:`place_positions`), linear interpolation between waypoints or jumps at waypoint times.
Who is *inside* is judged against the disc where it is now, so a disc that moves onto a robot
fires ``on="enter"`` for it like a robot driving in, and one that leaves it marks it outside.
A static place (no motion) is handled exactly as before, bit for bit. :attr:`Places.track`
records where each moving place was: at t = 0, at every jump, and in linear motion whenever it
has moved :data:`TRACK_MIN_M` from its last record.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["TRACK_MIN_M", "Places", "motion_table", "place_positions"]

#: a moving place's :attr:`Places.track` gets a record once it has moved this far [m]
TRACK_MIN_M = 0.25


def motion_table(place) -> tuple[np.ndarray, np.ndarray, np.ndarray, float | None]:
    """``(t, x, y, period)`` of a place's motion: knots from t = 0 (the place's ``x_m``, ``y_m``)
    through its waypoints, and with a ``period_s`` the return to the start at ``period_s``."""
    m = place.motion
    t = [0.0] + [w.t_s for w in m.path]
    x = [place.x_m] + [w.x_m for w in m.path]
    y = [place.y_m] + [w.y_m for w in m.path]
    if m.period_s is not None:
        t.append(m.period_s)
        x.append(place.x_m)
        y.append(place.y_m)
    return np.array(t), np.array(x), np.array(y), m.period_s


def place_positions(place, times_s) -> tuple[np.ndarray, np.ndarray]:
    """Where a place is at each time of ``times_s`` [s] (world metres), per
    :class:`~teamnav.sim.config.PlaceMotion`; a static place is at ``x_m``, ``y_m`` always.

    >>> from teamnav.sim.config import PlaceConfig
    >>> p = PlaceConfig.model_validate({"name": "source", "x_m": 0.0, "y_m": 0.0, "motion":
    ...     {"path": [{"t_s": 10.0, "x_m": 10.0, "y_m": 0.0}], "period_s": 20.0}})
    >>> place_positions(p, [0.0, 5.0, 10.0, 15.0, 25.0])[0].tolist()
    [0.0, 5.0, 10.0, 5.0, 5.0]
    >>> jump = p.model_copy(update={"motion": p.motion.model_copy(update={"mode": "jump"})})
    >>> place_positions(jump, [0.0, 9.9, 10.0, 19.9, 20.0])[0].tolist()
    [0.0, 0.0, 10.0, 10.0, 0.0]
    """
    ts = np.atleast_1d(np.asarray(times_s, dtype=np.float64))
    if place.motion is None:
        return np.full(ts.shape, float(place.x_m)), np.full(ts.shape, float(place.y_m))
    t, x, y, period = motion_table(place)
    if period is not None:
        ts = np.mod(ts, period)
    if place.motion.mode == "jump":
        k = np.searchsorted(t, ts, side="right") - 1
        k = np.clip(k, 0, len(t) - 1)
        return x[k], y[k]
    return np.interp(ts, t, x), np.interp(ts, t, y)



class Places:
    """All places of a run and who is inside which.

    Parameters
    ----------
    places : sequence of PlaceConfig
    xs, ys : ndarray of shape (N,)
        True start positions [m] (sets who starts inside).

    Examples
    --------
    >>> from teamnav.sim.config import PlaceConfig
    >>> p = Places([PlaceConfig(name="home", x_m=0.0, y_m=0.0, radius_m=1.0, event="home")],
    ...            np.array([5.0]), np.array([0.0]))
    >>> p.update(1, 0.1, np.array([0.5]), np.array([0.0]))[0]
    ('home',)
    >>> p.update(2, 0.2, np.array([0.4]), np.array([0.0]))[0]
    ()
    """

    def __init__(self, places, xs: np.ndarray, ys: np.ndarray) -> None:
        self.places = tuple(p for p in places if p.event is not None)
        self.names = [p.name for p in self.places]
        self.events = [p.event for p in self.places]
        self.px = np.array([p.x_m for p in self.places], dtype=np.float64)
        self.py = np.array([p.y_m for p in self.places], dtype=np.float64)
        self.r2 = np.array([p.radius_m for p in self.places], dtype=np.float64) ** 2
        self.on_enter = np.array([p.on == "enter" for p in self.places], dtype=bool)
        #: indices (in :attr:`places`) of the places that move
        self.moving = [k for k, p in enumerate(self.places) if p.motion is not None]
        #: where each moving place was: dicts with step, t_s, place, x_m, y_m (see the module doc)
        self.track: list[dict] = []
        for k in self.moving:
            self.track.append({"step": 0, "t_s": 0.0, "place": self.names[k], "x_m": float(self.px[k]),
                               "y_m": float(self.py[k])})
        self._last = {k: (float(self.px[k]), float(self.py[k])) for k in self.moving}
        self.inside = self._inside(np.asarray(xs, float), np.asarray(ys, float))
        #: Every firing: dicts with step, t_s, robot, place, event.
        self.log: list[dict] = []

    def _move(self, step: int, time_s: float) -> None:
        """Put the moving places where they are at ``time_s`` and extend :attr:`track`."""
        for k in self.moving:
            p = self.places[k]
            x, y = place_positions(p, time_s)
            x, y = float(x[0]), float(y[0])
            self.px[k], self.py[k] = x, y
            lx, ly = self._last[k]
            if (x, y) != (lx, ly) and (p.motion.mode == "jump" or math.hypot(x - lx, y - ly) >= TRACK_MIN_M):
                self.track.append({"step": int(step), "t_s": float(time_s), "place": self.names[k], "x_m": x, "y_m": y})
                self._last[k] = (x, y)

    @property
    def active(self) -> bool:
        """Whether any place can fire."""
        return bool(self.places)

    def _inside(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        return (xs[:, None] - self.px[None, :]) ** 2 + (ys[:, None] - self.py[None, :]) ** 2 <= self.r2[None, :]

    def update(self, step: int, time_s: float, xs: np.ndarray, ys: np.ndarray,
               muted: np.ndarray | None = None) -> list[tuple[str, ...]]:
        """Events fired this step, one tuple per robot (in place order); recorded in :attr:`log`.
        Robots where ``muted`` is True (not started yet: :class:`~teamnav.sim.config.LaunchConfig`)
        fire nothing, though who is inside is still tracked."""
        n = xs.shape[0]
        if not self.places:
            return [()] * n
        if self.moving:
            self._move(step, time_s)
        now = self._inside(xs, ys)
        fire = np.where(self.on_enter[None, :], now & ~self.inside, now)
        if muted is not None:
            fire &= ~muted[:, None]
        self.inside = now
        out: list[tuple[str, ...]] = [()] * n
        if fire.any():
            robots, places = np.nonzero(fire)  # row-major: by robot, then place
            per: dict[int, list[str]] = {}
            for r, k in zip(robots.tolist(), places.tolist()):
                ev = self.events[k]
                per.setdefault(r, []).append(ev)
                self.log.append({"step": int(step), "t_s": float(time_s), "robot": r, "place": self.names[k], "event": ev})
            for r, evs in per.items():
                out[r] = tuple(evs)
        return out
