"""State sharing: the one-bit "in trouble" state Tr and its update rule (Sgorbissa & Arkin §5).

Paper: A. Sgorbissa and R. C. Arkin, "Local navigation strategies for a team of robots", §5.

Rules (§5):

1. *Evaluate my progress* — each robot keeps Tr (false: progressing well, true: in trouble);
2. *Share state* — it tells every robot it sees its Tr;
3. *Head to helper* — a robot in trouble heads to a teammate it sees that is not in trouble,
   until it is no longer in trouble or it sees its own goal.

Update of Tr (§5, the paragraph after Fig. 9), implemented exactly by :class:`TroubleState`:

- Pr increases by Nt at each step without progress and decreases by 1 at each step with
  progress; it never goes below 0 nor above its upper bound ``Nt·Cr``;
- Tr becomes true when Pr reaches the bound ``Nt·Cr`` (the paper: "Tr changes to true when
  Pr = Cr", where Cr "establishes an upper limit on the value of Pr" and "the upper bound ...
  is set to Nt·Cr"), and false again when Pr reaches 0;
- each change of Tr to false increments Nt (initially 1), so every later episode lasts longer
  (Fig. 10: the second time R1 follows R2 for longer).

Gap filled (the paper has one goal in Fig. 10): :meth:`TroubleState.reset` restarts Pr, Tr
and Nt for a new goal (the brains do this when a target is reached, configurable).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

__all__ = ["TroubleState", "choose_helper"]


@dataclass
class TroubleState:
    """Tr, Pr, Nt of one robot with the constant Cr (§5).

    Parameters
    ----------
    cr : int
        Cr ≥ 1: steps without progress before the robot declares itself in trouble (first time).

    Examples
    --------
    >>> s = TroubleState(cr=2)
    >>> [s.update(False) for _ in range(2)], s.pr
    ([False, True], 2)
    >>> [s.update(True) for _ in range(2)], s.nt
    ([True, False], 2)
    """

    cr: int
    pr: int = 0
    nt: int = 1
    tr: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.cr, int) or self.cr < 1:
            raise ValueError(f"cr must be an int >= 1, got {self.cr!r}")

    @property
    def bound(self) -> int:
        """The upper bound ``Nt·Cr`` of Pr."""
        return self.nt * self.cr

    def update(self, progressing: bool) -> bool:
        """One computation step of §5's rule; returns the new Tr."""
        if progressing:
            self.pr = max(self.pr - 1, 0)
        else:
            self.pr = min(self.pr + self.nt, self.bound)
        if not self.tr and self.pr >= self.bound:
            self.tr = True
        elif self.tr and self.pr == 0:
            self.tr = False
            self.nt += 1
        return self.tr

    def reset(self) -> None:
        """Back to the initial state (Pr = 0, Nt = 1, not in trouble): a new navigation problem."""
        self.pr, self.nt, self.tr = 0, 1, False


def choose_helper(in_trouble: bool, me_xy, teammates: Iterable[tuple[int, float, float, bool | None]]) -> int | None:
    """§5 rule 3: the teammate a robot in trouble heads to: the nearest one it sees that is not
    in trouble (ties: lowest id), or None.

    Parameters
    ----------
    in_trouble : bool
        This robot's Tr.
    me_xy : (x, y)
        This robot's position [m] (own frame).
    teammates : iterable of (robot_id, x, y, trouble)
        Teammates seen now, positions in own frame; ``trouble`` None when unknown (skipped).

    Examples
    --------
    >>> choose_helper(True, (0, 0), [(1, 3.0, 0.0, True), (2, 5.0, 0.0, False), (3, 4.0, 0.0, None)])
    2
    """
    if not in_trouble:
        return None
    best, best_d = None, math.inf
    for rid, x, y, trouble in sorted(teammates, key=lambda t: t[0]):
        if trouble is None or trouble:
            continue
        d = math.hypot(x - me_xy[0], y - me_xy[1])
        if d < best_d:
            best, best_d = int(rid), d
    return best
