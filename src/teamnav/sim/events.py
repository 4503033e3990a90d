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
"""

from __future__ import annotations

import numpy as np

__all__ = ["Places"]


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
        self.inside = self._inside(np.asarray(xs, float), np.asarray(ys, float))
        #: Every firing: dicts with step, t_s, robot, place, event.
        self.log: list[dict] = []

    @property
    def active(self) -> bool:
        """Whether any place can fire."""
        return bool(self.places)

    def _inside(self, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        return (xs[:, None] - self.px[None, :]) ** 2 + (ys[:, None] - self.py[None, :]) ** 2 <= self.r2[None, :]

    def update(self, step: int, time_s: float, xs: np.ndarray, ys: np.ndarray) -> list[tuple[str, ...]]:
        """Events fired this step, one tuple per robot (in place order); recorded in :attr:`log`."""
        n = xs.shape[0]
        if not self.places:
            return [()] * n
        now = self._inside(xs, ys)
        fire = np.where(self.on_enter[None, :], now & ~self.inside, now)
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
