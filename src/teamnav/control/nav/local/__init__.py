"""Local navigation algorithms: the set A of Sgorbissa & Arkin §2 and §6.

Sgorbissa & Arkin §2: robot R_i "is provided with a local navigation algorithm A which
returns, at each computation step t, what is considered as the best choice for reaching the
goal G_icurr"; §6 compares three: a standard potential field, the potential field plus
Balch & Arkin's Avoid-Past schema, and Lumelsky & Skewis's VisBug-21. This package gives each
as a :class:`LocalNavigator` that a brain drives one step at a time:

>>> import numpy as np
>>> from teamnav.control.types import RangeScan
>>> nav = make_navigator("visbug21", None, rng=np.random.default_rng(0), step_length_m=0.1, radius_m=0.25)
>>> nav.set_goal(np.array([2.0, 0.0]))                       # own odometry frame
>>> scan = RangeScan(np.full(72, 4.0), np.linspace(-np.pi, np.pi, 72, endpoint=False), 4.0)
>>> round(nav.direction(np.array([0.0, 0.0, 0.0]), scan), 6), nav.progressing
(0.0, True)

The brain (not the navigator) applies §2's rule 4 ("whenever R_i can see its current goal it
starts heading towards it, suppressing the output of algorithm A") and the ε test for having
reached the goal; :func:`goal_in_sight` is the visibility test it can use.
"""

from __future__ import annotations

import difflib
import math

import numpy as np
from pydantic import BaseModel, ValidationError

from teamnav.control.nav.local.avoid_past import AvoidPast, AvoidPastParams
from teamnav.control.nav.local.base import (
    LocalNavigator,
    ProgressMonitor,
    check_goal,
    check_pose,
    check_scan,
    safe_heading,
    scan_points,
    segment_clearance,
)
from teamnav.control.nav.local.potential_field import PotentialField, PotentialFieldParams
from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams
from teamnav.control.types import RangeScan

__all__ = [
    "NAVIGATORS", "AvoidPast", "AvoidPastParams", "LocalNavigator", "PotentialField", "PotentialFieldParams",
    "ProgressMonitor", "VisBug21", "VisBugParams", "goal_in_sight", "make_navigator", "safe_heading",
    "scan_points",
]

#: Registry of the set A: name -> navigator class (each has a ``Params`` pydantic model).
NAVIGATORS: dict[str, type] = {
    "potential_field": PotentialField,
    "avoid_past": AvoidPast,
    "visbug21": VisBug21,
}


def make_navigator(name: str, params: dict | BaseModel | None, *, rng: np.random.Generator,
                   step_length_m: float, radius_m: float) -> LocalNavigator:
    """Build the local navigator ``name`` from its parameters.

    Parameters
    ----------
    name : str
        A key of :data:`NAVIGATORS`.
    params : dict, the navigator's Params model, or None
        None or ``{}``: the defaults. A dict is validated by the navigator's Params model.
    rng : numpy.random.Generator
        The robot's own stream.
    step_length_m : float
        Length of one motion step [m] (> 0).
    radius_m : float
        Robot radius [m] (> 0).

    Raises
    ------
    ValueError
        Unknown name (with a "did you mean" hint), parameters the model refuses (naming the
        field), or a bad step length / radius / rng.
    """
    try:
        cls = NAVIGATORS[name]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(name), list(NAVIGATORS), n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"unknown local navigator {name!r} (known: {', '.join(NAVIGATORS)}){hint}") from None
    model = cls.Params
    if params is None:
        p = model()
    elif isinstance(params, model) and type(params) is model:
        p = params
    elif isinstance(params, BaseModel):
        raise ValueError(f"params for {name!r} must be a {model.__name__} or a dict, got {type(params).__name__}")
    elif isinstance(params, dict):
        try:
            p = model(**params)
        except ValidationError as e:
            parts = [f"{'.'.join(str(x) for x in err['loc']) or '<params>'}: {err['msg']} (got {err.get('input')!r})"
                     for err in e.errors()]
            raise ValueError(f"bad parameters for local navigator {name!r}: " + "; ".join(parts)) from None
    else:
        raise ValueError(f"params for {name!r} must be a dict, a {model.__name__} or None, got {type(params).__name__}")
    for label, v in (("step_length_m", step_length_m), ("radius_m", radius_m)):
        if not (isinstance(v, (int, float, np.floating, np.integer)) and math.isfinite(v) and v > 0):
            raise ValueError(f"{label} must be a finite number of metres > 0, got {v!r}")
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    return cls(p, rng, float(step_length_m), float(radius_m))


def goal_in_sight(pose: np.ndarray, scan: RangeScan, goal_xy: np.ndarray, clearance_m: float = 0.0) -> bool:
    """Is the goal visible (Sgorbissa & Arkin §2, V(R_i)) from ``pose`` in this scan?

    True when the goal is within the scan's maximum range, every beam within one beam spacing
    (``2π / n_beams``) of the goal's bearing reaches past it (line of sight as far as the beams
    tell), and every
    sensed point is more than ``clearance_m`` from the segment robot -> goal (with a robot
    radius: the robot can also drive straight there).

    Examples
    --------
    >>> s = RangeScan(np.array([1.0, 4, 4, 4, 4, 4, 4, 4]), np.linspace(0, 2 * np.pi, 8, endpoint=False), 4.0)
    >>> goal_in_sight(np.zeros(3), s, np.array([2.0, 0.0])), goal_in_sight(np.zeros(3), s, np.array([0.0, 2.0]))
    (False, True)
    """
    pose = check_pose(pose)
    scan = check_scan(scan)
    g = check_goal(goal_xy)
    to_goal = g - pose[:2]
    dist = math.hypot(to_goal[0], to_goal[1])
    if dist > float(scan.max_range_m):
        return False
    ranges = np.asarray(scan.ranges_m, dtype=np.float64)
    if ranges.size == 0:
        return False
    rel = (np.asarray(scan.angles_rad, dtype=np.float64) + pose[2] - math.atan2(to_goal[1], to_goal[0]) + math.pi) % (2 * math.pi) - math.pi
    near = np.abs(rel) <= 2.0 * math.pi / ranges.size + 1e-12
    if not near.any() or np.any(ranges[near] < dist):
        return False
    if clearance_m > 0.0:
        pts = scan_points(pose, scan)
        if pts.shape[0] and segment_clearance(pts, pose[:2], g[None, :])[0] < clearance_m:
            return False
    return True
