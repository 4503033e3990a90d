"""Places, Crumbs and Trails shared between unrelated frames through task-level landmarks.

Vaughan, Støy, Sukhatme & Matarić, "Try to see it my way: using task-level features to
transform between reference frames in robot teams" (2002), §2:

- §2.1.1 a **Place** ``[P x y]``: the name of a task event and where it happened, in the
  robot's own (drifting) odometry frame; one Place per event name (§2.1.4,
  :meth:`Trail.set_place`).
- §2.1.2 a **Crumb** ``[P x y s t]``: "A was s seconds away from (x, y) at time t"
  (:meth:`Trail.add_crumbs`).
- §2.1.3 a **Trail**: a set of Crumbs and Places (:class:`Trail`; on the wire a
  :class:`TrailMessage`).
- §2.1.5 *Combining trails* (:func:`place_transform`, :meth:`Trail.combine`): with two Places
  in common, the received trail is mapped through the unique similarity ``T`` (translation,
  rotation, scale) that takes the received Places onto the local ones
  (:func:`teamnav.geometry.similarity.similarity_from_two_pairs`); every Crumb and every Place
  the local trail lacks is copied through ``T``; common Places are not copied. With fewer common
  Places, a *pessimistic* policy refuses, an *optimistic* one copies as-is (none in common) or
  translates by the one common Place.
- §2.2 step 2 the **temporary trail** (:func:`temporary_trail`): copies of all Places plus one
  Crumb (last Place visited, time since, now), broadcast every S seconds.
- §2.3 the **trail-using rule** (:meth:`Trail.best_crumb`): among the Crumbs for the current
  goal Place within a radius, head for the one with the lowest time-to-Place; step 2, Crumbs
  older than a threshold (4 min) are destroyed (:meth:`Trail.expire`).

Choices where the paper is silent:

- With more than two common Places (N places, §2.1), ``T`` is fixed by the pair of common
  Places farthest apart in the local trail (the best-conditioned pair); the others are
  "assumed to be consistent" and not copied (§2.1.5).
- Two common Places that coincide (closer than 1e-6 m) cannot fix a rotation; the pair then
  counts as one common Place.
- A Crumb's time-to-place ``s`` is a time and is not scaled by ``T``.

Crumbs are stored as numpy columns (place code, x, y, s, t) in a buffer that doubles when
full; expiry and queries are vectorised (trails hold thousands of crumbs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, Mapping, Sequence

import numpy as np

from teamnav.geometry.similarity import Similarity, similarity_from_two_pairs

__all__ = ["Policy", "Trail", "TrailMessage", "place_transform", "temporary_trail"]

Policy = Literal["pessimistic", "optimistic"]
_POLICIES = ("pessimistic", "optimistic")
#: Two Places closer than this [m] cannot define a rotation (treated as one common Place).
_DEGENERATE_M = 1e-6


@dataclass(frozen=True)
class TrailMessage:
    """A Trail on the wire (Try-to-see §2.1.3; the §2.2 temporary trail is a 1-crumb one).

    Attributes
    ----------
    place_names : tuple of str, length p
        Place names P (task event names).
    place_xy_m : ndarray of shape (p, 2), float64
        Place positions in the sender's frame [m].
    crumb_place : tuple of str, length k
        Each Crumb's Place name.
    crumb_xy_m : ndarray of shape (k, 2), float64
        Crumb positions in the sender's frame [m].
    crumb_s : ndarray of shape (k,), float64
        Time-to-place estimates [s].
    crumb_t : ndarray of shape (k,), float64
        Creation times [s] (robots' clocks agree).
    """

    place_names: tuple[str, ...]
    place_xy_m: np.ndarray
    crumb_place: tuple[str, ...]
    crumb_xy_m: np.ndarray
    crumb_s: np.ndarray
    crumb_t: np.ndarray

    def __post_init__(self) -> None:
        pxy = np.asarray(self.place_xy_m, dtype=np.float64).reshape(-1, 2)
        cxy = np.asarray(self.crumb_xy_m, dtype=np.float64).reshape(-1, 2)
        s = np.asarray(self.crumb_s, dtype=np.float64).reshape(-1)
        t = np.asarray(self.crumb_t, dtype=np.float64).reshape(-1)
        if len(self.place_names) != pxy.shape[0] or len(set(self.place_names)) != len(self.place_names):
            raise ValueError(f"TrailMessage: place_names {self.place_names!r} must be unique and match "
                             f"place_xy_m's {pxy.shape[0]} rows")
        if not (len(self.crumb_place) == cxy.shape[0] == s.shape[0] == t.shape[0]):
            raise ValueError(f"TrailMessage: crumb_place ({len(self.crumb_place)}), crumb_xy_m ({cxy.shape[0]}), "
                             f"crumb_s ({s.shape[0]}) and crumb_t ({t.shape[0]}) must have one length")
        object.__setattr__(self, "place_names", tuple(self.place_names))
        object.__setattr__(self, "crumb_place", tuple(self.crumb_place))
        object.__setattr__(self, "place_xy_m", pxy)
        object.__setattr__(self, "crumb_xy_m", cxy)
        object.__setattr__(self, "crumb_s", s)
        object.__setattr__(self, "crumb_t", t)

    @property
    def places(self) -> dict[str, np.ndarray]:
        """Place name -> position (2,) [m]."""
        return {n: self.place_xy_m[i] for i, n in enumerate(self.place_names)}


def place_transform(local_places: Mapping[str, np.ndarray], received_places: Mapping[str, np.ndarray],
                    policy: Policy) -> Similarity | None:
    """The map from a received trail's frame into the local one, or None to refuse (§2.1.5).

    Parameters
    ----------
    local_places, received_places : mapping of str to array_like (2,)
        Places by name in each frame [m].
    policy : {"pessimistic", "optimistic"}
        What to do with fewer than two common Places.

    Returns
    -------
    Similarity or None
        Two or more common Places: the similarity taking the received pair onto the local pair
        (the pair farthest apart locally). One common Place: pessimistic None, optimistic the
        translation taking it onto the local one. None in common: pessimistic None, optimistic
        the identity.

    Examples
    --------
    >>> T = place_transform({"A": [0, 0], "B": [10, 0]}, {"A": [1, 1], "B": [1, 6]}, "pessimistic")
    >>> round(T.scale, 12), round(T.rotation_rad, 12)
    (2.0, -1.570796326795)
    >>> place_transform({"A": [0, 0]}, {"A": [1, 1]}, "pessimistic") is None
    True
    >>> place_transform({"A": [0, 0]}, {"A": [1, 1]}, "optimistic").tx
    -1.0
    """
    if policy not in _POLICIES:
        raise ValueError(f"policy must be one of {_POLICIES}, got {policy!r}")
    common = [n for n in local_places if n in received_places]
    if len(common) >= 2:
        loc = np.array([np.asarray(local_places[n], dtype=np.float64) for n in common])
        rec = np.array([np.asarray(received_places[n], dtype=np.float64) for n in common])
        d_loc = np.linalg.norm(loc[:, None, :] - loc[None, :, :], axis=-1)
        d_rec = np.linalg.norm(rec[:, None, :] - rec[None, :, :], axis=-1)
        usable = (d_loc > _DEGENERATE_M) & (d_rec > _DEGENERATE_M)
        if usable.any():
            score = np.where(usable, d_loc, -1.0)
            i, j = np.unravel_index(int(np.argmax(score)), score.shape)
            return similarity_from_two_pairs(rec[i], rec[j], loc[i], loc[j], tol_m=_DEGENERATE_M)
        common = common[:1]
    if policy == "pessimistic":
        return None
    if len(common) == 1:
        d = np.asarray(local_places[common[0]], dtype=np.float64) - np.asarray(received_places[common[0]],
                                                                                 dtype=np.float64)
        return Similarity(1.0, 0.0, float(d[0]), float(d[1]))
    return Similarity.identity()


class Trail:
    """One robot's Trail: its Places and the Crumbs it knows, in its own frame (§2.1.3).

    Parameters
    ----------
    capacity : int, default 256
        Initial crumb buffer size (it grows as needed).

    Examples
    --------
    >>> tr = Trail()
    >>> tr.set_place("A", 0.0, 0.0); tr.set_place("B", 10.0, 5.0)
    >>> tr.add_crumbs(["A"], [[3.0, 4.0]], [20.0], [201.0])
    >>> len(tr), tr.best_crumb("A", 3.5, 4.0, radius_m=1.0)[1]
    (1, 20.0)
    """

    def __init__(self, capacity: int = 256) -> None:
        if not isinstance(capacity, int) or capacity < 1:
            raise ValueError(f"capacity must be an int >= 1, got {capacity!r}")
        self.places: dict[str, np.ndarray] = {}
        self._codes: dict[str, int] = {}
        self._names: list[str] = []
        self._p = np.empty(capacity, dtype=np.int32)
        self._xys = np.empty((capacity, 4), dtype=np.float64)  # x, y, s, t
        self._n = 0
        self._t_min = math.inf  # oldest crumb's time: expire() is O(1) while nothing is due

    # ------------------------------------------------------------------ storage
    def __len__(self) -> int:
        return self._n

    def _code(self, name: str) -> int:
        code = self._codes.get(name)
        if code is None:
            code = self._codes[name] = len(self._names)
            self._names.append(name)
        return code

    @property
    def crumb_xy_m(self) -> np.ndarray:
        """Crumb positions (n, 2) [m] (a view)."""
        return self._xys[: self._n, :2]

    @property
    def crumb_s(self) -> np.ndarray:
        """Time-to-place estimates (n,) [s] (a view)."""
        return self._xys[: self._n, 2]

    @property
    def crumb_t(self) -> np.ndarray:
        """Creation times (n,) [s] (a view)."""
        return self._xys[: self._n, 3]

    @property
    def crumb_place(self) -> list[str]:
        """Each crumb's Place name (a new list)."""
        return [self._names[c] for c in self._p[: self._n]]

    def place_mask(self, name: str) -> np.ndarray:
        """Bool (n,): crumbs that refer to Place ``name``."""
        code = self._codes.get(name)
        if code is None:
            return np.zeros(self._n, dtype=bool)
        return self._p[: self._n] == code

    def _reserve(self, extra: int) -> None:
        need = self._n + extra
        if need > self._p.shape[0]:
            cap = max(need, 2 * self._p.shape[0])
            p = np.empty(cap, dtype=np.int32)
            xys = np.empty((cap, 4), dtype=np.float64)
            p[: self._n] = self._p[: self._n]
            xys[: self._n] = self._xys[: self._n]
            self._p, self._xys = p, xys

    # ------------------------------------------------------------------ rules
    def set_place(self, name: str, x_odom_m: float, y_odom_m: float) -> None:
        """Create Place ``name`` or move it to the current position (§2.1.4, §2.2 step 1)."""
        if not isinstance(name, str) or not name:
            raise ValueError(f"a Place name must be a non-empty string, got {name!r}")
        self.places[name] = np.array([x_odom_m, y_odom_m], dtype=np.float64)

    def add_crumbs(self, places: Sequence[str], xy_m, s, t) -> None:
        """Append Crumbs ``[P x y s t]`` (§2.1.2); ``xy_m`` (k, 2), ``s`` and ``t`` (k,)."""
        xy = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
        s_arr = np.asarray(s, dtype=np.float64).reshape(-1)
        t_arr = np.asarray(t, dtype=np.float64).reshape(-1)
        k = xy.shape[0]
        if not (len(places) == k == s_arr.shape[0] == t_arr.shape[0]):
            raise ValueError(f"add_crumbs: places ({len(places)}), xy_m ({k}), s ({s_arr.shape[0]}) and "
                             f"t ({t_arr.shape[0]}) must have one length")
        if k == 0:
            return
        self._reserve(k)
        sl = slice(self._n, self._n + k)
        self._p[sl] = [self._code(p) for p in places]
        self._xys[sl, :2] = xy
        self._xys[sl, 2] = s_arr
        self._xys[sl, 3] = t_arr
        self._n += k
        self._t_min = min(self._t_min, float(t_arr.min()))

    def combine(self, msg: TrailMessage, policy: Policy, *, use_transforms: bool = True) -> Similarity | None:
        """Combine a received trail into this one (§2.1.5, §2.2 step 3).

        Parameters
        ----------
        msg : TrailMessage
            The received trail, in the sender's frame.
        policy : {"pessimistic", "optimistic"}
            See :func:`place_transform`.
        use_transforms : bool, default True
            False: copy as-is whatever the Places say, as if every frame agreed (the ablation
            "same drift, without Place transforms").

        Returns
        -------
        Similarity or None
            The transform applied, or None when the policy refused the trail (nothing copied).
        """
        rec_places = msg.places
        if use_transforms:
            T = place_transform(self.places, rec_places, policy)
            if T is None:
                return None
        else:
            T = Similarity.identity()
        new = [n for n in msg.place_names if n not in self.places]
        if new:
            moved = T.apply(np.array([rec_places[n] for n in new]))
            for n, xy in zip(new, moved):
                self.places[n] = xy
        if msg.crumb_xy_m.shape[0]:
            self.add_crumbs(msg.crumb_place, T.apply(msg.crumb_xy_m), msg.crumb_s, msg.crumb_t)
        return T

    def expire(self, now_s: float, max_age_s: float) -> int:
        """Destroy Crumbs older than ``max_age_s`` (§2.3 step 2, "we used 4 minutes").

        Returns
        -------
        int
            How many were removed.
        """
        cutoff = now_s - max_age_s
        if self._n == 0 or self._t_min >= cutoff:
            return 0
        keep = self._xys[: self._n, 3] >= cutoff
        k = int(keep.sum())
        removed = self._n - k
        self._p[:k] = self._p[: self._n][keep]
        self._xys[:k] = self._xys[: self._n][keep]
        self._n = k
        self._t_min = float(self._xys[:k, 3].min()) if k else math.inf
        return removed

    def best_crumb(self, goal: str, x_odom_m: float, y_odom_m: float, radius_m: float, *,
                   below_s: float = math.inf) -> tuple[int, float] | None:
        """The trail-using rule (§2.3 step 1).

        "finds those Crumbs which reference its current goal ... and have a position within a
        fixed radius of the current position. The preferred direction of movement is towards
        the Crumb with the lowest time-to-Place estimate."

        Parameters
        ----------
        below_s : float, default inf
            Consider only crumbs with a time-to-place below this [s] (see :class:`TrailShare
            <teamnav.papers.trails.brains.trail_share.TrailShare>`'s ``descend_only``).

        Returns
        -------
        (index, s) or None
            Index of that crumb (into :attr:`crumb_xy_m`) and its time-to-place [s]; None when
            no crumb for ``goal`` is within ``radius_m`` (inclusive). Ties go to the earliest.
        """
        near = self._goal_offsets(goal, x_odom_m, y_odom_m)
        if near is None:
            return None
        xys, is_goal, d2 = near
        ok = is_goal & (d2 <= radius_m * radius_m)
        if below_s != math.inf:
            ok &= xys[:, 2] < below_s
        if not ok.any():
            return None
        s = np.where(ok, xys[:, 2], np.inf)
        i = int(np.argmin(s))
        return i, float(s[i])

    def _goal_offsets(self, goal: str, x_odom_m: float, y_odom_m: float
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The held crumbs ``(x, y, s)``, which of them are for ``goal``, and their squared
        distances to (x, y) [m^2]; None when there is no crumb for ``goal``'s Place at all."""
        code = self._codes.get(goal)
        if code is None or self._n == 0:
            return None
        xys = self._xys[: self._n]
        dx = xys[:, 0] - x_odom_m
        dy = xys[:, 1] - y_odom_m
        return xys, self._p[: self._n] == code, dx * dx + dy * dy

    def nearest_crumb(self, goal: str, x_odom_m: float, y_odom_m: float, radius_m: float, *,
                      below_s: float = math.inf) -> tuple[float, float] | None:
        """Position (x, y) [m] of the crumb for ``goal`` nearest to (x, y) within ``radius_m``
        (inclusive) with a time-to-place below ``below_s``, or None.

        Not a rule of the paper: :class:`TrailShare <teamnav.papers.trails.brains.trail_share.TrailShare>`
        heads for it when the trail-using rule finds no crumb (``recover_radius_m``).

        Examples
        --------
        >>> tr = Trail()
        >>> tr.add_crumbs(["A", "A", "B"], [[0.0, 0.0], [4.0, 0.0], [2.0, 0.0]], [5.0, 9.0, 1.0], [0.0, 0.0, 0.0])
        >>> tr.nearest_crumb("A", 2.5, 0.0, 3.0), tr.nearest_crumb("A", 2.5, 0.0, 3.0, below_s=6.0)
        ((4.0, 0.0), (0.0, 0.0))
        """
        near = self._goal_offsets(goal, x_odom_m, y_odom_m)
        if near is None:
            return None
        xys, is_goal, d2 = near
        d2 = np.where(is_goal, d2, np.inf)
        if below_s != math.inf:
            d2 = np.where(xys[:, 2] < below_s, d2, np.inf)
        i = int(np.argmin(d2))
        if not d2[i] <= radius_m * radius_m:
            return None
        return float(xys[i, 0]), float(xys[i, 1])

    def heading_to_best(self, goal: str, x_odom_m: float, y_odom_m: float, radius_m: float, *,
                        below_s: float = math.inf, from_xy: tuple[float, float] | None = None) -> float | None:
        """Direction [rad] towards :meth:`best_crumb` around (x, y), or None (no crumb, or on it).

        The direction is taken from ``from_xy`` (the robot's position, when the crumbs were
        searched around a point ahead of it), by default from (x, y).
        """
        best = self.best_crumb(goal, x_odom_m, y_odom_m, radius_m, below_s=below_s)
        if best is None:
            return None
        fx, fy = (x_odom_m, y_odom_m) if from_xy is None else from_xy
        cx, cy = self._xys[best[0], :2]
        dx, dy = cx - fx, cy - fy
        if dx * dx + dy * dy < 1e-12:
            return None
        return math.atan2(dy, dx)

    def to_message(self) -> TrailMessage:
        """A copy of the whole trail as a message body."""
        names = tuple(self.places)
        return TrailMessage(names, np.array([self.places[n] for n in names]).reshape(-1, 2), tuple(self.crumb_place),
                            self.crumb_xy_m.copy(), self.crumb_s.copy(), self.crumb_t.copy())


def temporary_trail(trail: Trail, last_place: str, x_odom_m: float, y_odom_m: float, since_place_s: float,
                    now_s: float) -> TrailMessage:
    """The §2.2 step 2 temporary trail: copies of all Places plus one Crumb.

    "a single Crumb filled in with the current location, the name of the last Place visited,
    the time elapsed since visiting the Place, and the current time."

    Examples
    --------
    >>> tr = Trail(); tr.set_place("A", 0.0, 0.0)
    >>> m = temporary_trail(tr, "A", 2.0, 1.0, 12.0, 30.0)
    >>> m.place_names, m.crumb_place, m.crumb_s.tolist()
    (('A',), ('A',), [12.0])
    """
    names = tuple(trail.places)
    pxy = np.array([trail.places[n] for n in names], dtype=np.float64).reshape(-1, 2)
    return TrailMessage(names, pxy, (last_place,), np.array([[x_odom_m, y_odom_m]]), np.array([since_place_s]),
                        np.array([now_s]))
