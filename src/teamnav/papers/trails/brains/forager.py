"""The forager's task state: which place of the round to seek next.

Vaughan et al., "Blazing a trail" §4.1 and "Try to see it my way" §2 / §3.5: robots start at
home, seek the source, and on reaching it (the experimenter "gives" a unit of resource) return
home with it, then fetch more, "repeatedly for the length of the trial". "Try to see it my way"
§2.1 generalises the two places to N ("a mail-delivery application", §4): here a *round* is the
cyclic list of task-event names the robot visits in order; with two places it is home ↔ source.

Place events arrive as strings in ``Observation.events`` (a scenario's places fire them when a
robot enters within their radius). Only the event of the place being sought advances the round
(passing another place does not: the robot is not delivering there); every event is still
reported to the caller, which may use it (a 2002 Place is updated on *any* task event, §2.2
step 1).

Gap filled here: the papers' robots "are started ... from the same spot at the home position"
and "each robot is told it is at Home" (§3.5); a robot starting inside a place's radius does not
fire its event, so a round starts *at* ``round[start_index]`` and seeks the next place.
"""

from __future__ import annotations

from typing import Sequence

__all__ = ["PlaceRound"]


class PlaceRound:
    """Cyclic round of places, by their event names.

    Parameters
    ----------
    events : sequence of str
        Event names of the places in visiting order (N >= 2, unique).
    start_index : int, default 0
        The place the robot starts at; it first seeks ``events[start_index + 1]``.
    start_time_s : float, default 0.0
        Time of that start "visit" [s].

    Attributes
    ----------
    index : int
        Index of the place being sought.
    trips : int
        Places reached in order (a home → source leg is one trip).
    last_place : str
        Event name of the last place visited (the start place at first).
    last_place_time_s : float
        When it was visited [s].

    Examples
    --------
    >>> r = PlaceRound(["home", "source"])
    >>> r.goal, r.trips
    ('source', 0)
    >>> r.observe(("home",), 3.0)      # passing home while seeking the source: no progress
    []
    >>> r.observe(("source",), 9.0), r.goal, r.trips
    (['source'], 'home', 1)
    """

    def __init__(self, events: Sequence[str], *, start_index: int = 0, start_time_s: float = 0.0) -> None:
        events = list(events)
        if len(events) < 2 or len(set(events)) != len(events) or not all(isinstance(e, str) and e for e in events):
            raise ValueError(f"a round must name at least 2 distinct places by non-empty event names, got {events!r}")
        if not isinstance(start_index, int) or not 0 <= start_index < len(events):
            raise ValueError(f"start_index must be an int in [0, {len(events)}), got {start_index!r}")
        self.events = events
        self.index = (start_index + 1) % len(events)
        self.trips = 0
        self.last_place = events[start_index]
        self.last_place_time_s = float(start_time_s)

    @property
    def goal(self) -> str:
        """Event name of the place being sought."""
        return self.events[self.index]

    def observe(self, events: Sequence[str], time_s: float) -> list[str]:
        """Advance on this step's events; returns the goals reached, in order (usually 0 or 1).

        Events of places in the round update :attr:`last_place` whether sought or not (the
        robot *was* there); only the sought one counts a trip and advances the round.
        """
        reached = []
        for e in events:
            if e not in self.events:
                continue
            self.last_place = e
            self.last_place_time_s = float(time_s)
            if e == self.goal:
                reached.append(e)
                self.trips += 1
                self.index = (self.index + 1) % len(self.events)
        return reached
