"""Robot detector: which teammates a robot sees, and where (in its body frame).

Implements the sensing of teammates used by two of the papers:

- Sgorbissa & Arkin, "Local navigation strategies for a team of robots", §3 and §6.1: robots
  see each other only in line of sight, within a visibility radius; with sensing noise the
  perceived distance and angle follow eqs. 1–2 (the *occlusion* model below).
- Fox, Burgard, Kruppa & Thrun, "Collaborative multi-robot localization", §4: a detection
  reports the seen robot's identity and its relative position in polar coordinates (range,
  bearing); §4.2 models its error as a zero-mean Gaussian with independent distance and
  angle components (Fig. 7; the *gaussian* model below) and counts false negatives and
  false positives (Table 2: 6.7 % and 3.5 %).

Simulator side (truth): it reads every robot's true pose and the map and returns, per
observer, what that observer perceives. Rules, from :class:`~teamnav.sim.config.DetectorConfig`:

1. *Range*: centre-to-centre distance ``d_r <= max_range_m``.
2. *Field of view*: ``|alpha_r| <= fov/2`` where the bearing in the observer's body frame is
   ``alpha_r = wrap(atan2(dy, dx) - theta)`` (every target passes when ``fov_deg = 360``).
3. *Line of sight* (if ``line_of_sight``): the segment between the two centres crosses no
   cell the detector ``sees`` (:func:`teamnav.world.los.line_of_sight`, symmetric bit for
   bit, so with a 360° field of view A sees B exactly when B sees A before noise).
4. *Noise* on range and bearing:

   - ``gaussian`` (Fox et al. §4.2): ``d_p = max(0, d_r + N(0, range_noise_std_m))``,
     ``alpha_p = alpha_r + N(0, bearing_noise_std_deg)``;
   - ``occlusion`` (Sgorbissa & Arkin §6.1, eqs. 1–2): ``d_p = d_r + d_r d_noise``,
     ``alpha_p = alpha_r + atan(robotsize / 2 d_r) alpha_noise``, ``robotsize`` the seen
     robot's diameter, ``d_noise ~ U[-err_max, err_max]`` and ``alpha_noise ~ U[-1, 1]``:
     the paper draws the angle factor on ``[-1, 1]``, not on ``[-err_max, err_max]``
     (the occlusion of a robot cannot move its perceived centre beyond its silhouette), so
     ``|d_p - d_r| <= err_max d_r`` and ``|alpha_p - alpha_r| <= atan(robotsize / 2 d_r)``.
     ``err_max = 0`` is perfect sensing: exact range *and* bearing (Sgorbissa & Arkin §6.1
     call Tables 1-2 "perfect sensing"; eqs. 1-2 apply only in the noise figures 16-17, and
     their err_max = 0 point is the tables' configuration). The draws are still taken, so
     the detector's random stream is the same at every err_max. Before commit 7915eb8
     (2026-11-27) the bearing carried eq. 2's error at ``err_max = 0`` too.
5. *False negatives*: each true detection is dropped with ``p_false_negative``.
6. *False positives*: with ``p_false_positive`` per observer per step, one phantom at a
   range uniform in ``(0, max_range_m]`` and a bearing uniform over the field of view.
7. *Identity*: ``robot_id`` is the seen robot's id when ``report_identity``, else None. A
   phantom carries None, or, when identities are reported, the id of a uniformly drawn
   *other* robot (a misrecognised marker: Fox et al.'s detector always names a robot).

Bearings are wrapped to ``(-pi, pi]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from teamnav.control.types import Detection
from teamnav.geometry.angles import wrap_angle
from teamnav.sim.config import DetectorConfig
from teamnav.world.grid import OccupancyGrid
from teamnav.world.los import _segment_visible, line_of_sight, pairs_within

__all__ = ["DetectionArrays", "RobotDetector"]

_FULL_CIRCLE_EPS_RAD = 1e-9


@dataclass(frozen=True)
class DetectionArrays:
    """All detections of one step as flat arrays, ordered by observer row, then true
    detections by target index, then the observer's false positive (if any).

    Attributes
    ----------
    row : ndarray (M,) int64
        Position of the observer in the ``observers`` argument.
    observer : ndarray (M,) int64
        Index of the observer into the pose arrays (``observers[row]``).
    target : ndarray (M,) int64
        Index of the seen robot into the pose arrays; -1 for a false positive.
    robot_id : ndarray (M,) int64
        Reported identity (``ids[target]`` or a phantom's id); -1 for "no identity".
    range_m : ndarray (M,) float64
        Perceived centre-to-centre distance [m].
    bearing_rad : ndarray (M,) float64
        Perceived direction in the observer's body frame [rad], in ``(-pi, pi]``.
    """

    row: np.ndarray
    observer: np.ndarray
    target: np.ndarray
    robot_id: np.ndarray
    range_m: np.ndarray
    bearing_rad: np.ndarray

    def __len__(self) -> int:
        return int(self.row.shape[0])


class RobotDetector:
    """Sees teammates: range, field of view, line of sight, noise, false detections.

    Parameters
    ----------
    cfg : DetectorConfig
        The detector's parameters (validated).
    grid : OccupancyGrid
        The map; cells of the materials ``cfg.sees`` hide robots behind them.

    Examples
    --------
    >>> from teamnav.world.grid import OccupancyGrid
    >>> det = RobotDetector(DetectorConfig(max_range_m=5.0), OccupancyGrid.empty(10, 10, 0.5))
    >>> xs, ys, th = np.array([1.0, 3.0, 9.0]), np.array([1.0, 1.0, 9.0]), np.array([0.0, np.pi, 0.0])
    >>> out = det.detect(xs, ys, th, np.full(3, 0.2), np.array([0, 1]), np.random.default_rng(0), np.arange(3))
    >>> [[(d.robot_id, round(d.range_m, 6), round(d.bearing_rad, 6)) for d in row] for row in out]
    [[(1, 2.0, 0.0)], [(0, 2.0, 0.0)]]
    """

    def __init__(self, cfg: DetectorConfig, grid: OccupancyGrid):
        if not isinstance(cfg, DetectorConfig):
            raise ValueError(f"cfg must be a DetectorConfig, got {type(cfg).__name__}")
        if not isinstance(grid, OccupancyGrid):
            raise ValueError(f"grid must be an OccupancyGrid, got {type(grid).__name__}")
        self.cfg = cfg
        self.grid = grid
        self.max_range_m = float(cfg.max_range_m)
        self.fov_rad = math.radians(cfg.fov_deg)
        self.full_circle = self.fov_rad >= 2 * math.pi - _FULL_CIRCLE_EPS_RAD
        self.blocking = grid.blocking(cfg.sees)
        # a rotated map: line of sight is tested in the grid's local frame (origin (0, 0))
        self._ox, self._oy = grid.kernel_frame(np.zeros(0), np.zeros(0))[2:]
        self._res = grid.resolution_m

    # ------------------------------------------------------------------ validation
    @staticmethod
    def _check(xs, ys, thetas, radii, observers, rng, ids):
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
        xs = np.ascontiguousarray(xs, dtype=np.float64)
        if xs.ndim != 1:
            raise ValueError(f"xs must be a 1-D array (N,), got shape {xs.shape}")
        n_all = xs.shape[0]
        out = [xs]
        for name, v in (("ys", ys), ("thetas", thetas), ("radii", radii)):
            arr = np.ascontiguousarray(v, dtype=np.float64)
            if arr.shape != (n_all,):
                raise ValueError(f"{name} must have shape ({n_all},) like xs, got {arr.shape}")
            out.append(arr)
        for name, arr in zip(("xs", "ys", "thetas", "radii"), out):
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{name} must be finite, got {arr[~np.isfinite(arr)][:3].tolist()}")
        if np.any(out[3] < 0):
            raise ValueError(f"radii must be >= 0 [m], got min {float(out[3].min())}")
        obs = np.asarray(observers)
        if obs.ndim != 1 or (obs.size and not np.issubdtype(obs.dtype, np.integer)):
            raise ValueError(f"observers must be a 1-D integer array of robot indices, got {obs.dtype} {obs.shape}")
        obs = obs.astype(np.int64)
        if obs.size and (obs.min() < 0 or obs.max() >= n_all):
            raise ValueError(f"observers must be indices in [0, {n_all}), got {obs[(obs < 0) | (obs >= n_all)][:3].tolist()}")
        if np.unique(obs).shape[0] != obs.shape[0]:
            raise ValueError("observers must not repeat a robot index")
        id_arr = np.asarray(ids)
        if id_arr.shape != (n_all,) or (id_arr.size and not np.issubdtype(id_arr.dtype, np.integer)):
            raise ValueError(f"ids must be an integer array of shape ({n_all},), got {id_arr.dtype} {id_arr.shape}")
        return (*out, obs, id_arr.astype(np.int64))

    # ------------------------------------------------------------------ truth
    def _visible(self, xs, ys, thetas, obs):
        """Noise-free (row, observer, target, range, bearing) of every rule-1–3 pair,
        ordered by row, then target.

        Up to ``_BRUTE_MAX_ROBOTS`` robots the candidate pairs come from one kernel that
        tests every observer against every robot (range, then line of sight); larger teams
        use the spatial hash of :func:`~teamnav.world.los.pairs_within`. Both keep the pairs
        with ``dx*dx + dy*dy <= max_range_m**2`` and the same line-of-sight kernel (symmetric
        bit for bit), so they return the same detections.
        """
        n_all = xs.shape[0]
        if n_all <= _BRUTE_MAX_ROBOTS:
            return self._visible_brute(xs, ys, thetas, obs)
        row_of = np.full(n_all, -1, dtype=np.int64)
        row_of[obs] = np.arange(obs.shape[0], dtype=np.int64)
        i, j = pairs_within(xs, ys, self.max_range_m)
        a = np.concatenate([i, j])  # directed pairs a sees b
        b = np.concatenate([j, i])
        keep = row_of[a] >= 0
        a, b = a[keep], b[keep]
        # the same kernel as the small-team path (libm's hypot and atan2, element by element):
        # NumPy >= 2.4 has its own SIMD hypot/arctan2 that can differ from libm in the last bit,
        # and the two paths must return the same detections bit for bit
        if a.size:
            rng_m, bearing = _range_bearing(xs, ys, thetas, a, b)  # int64 from pairs_within
        else:
            rng_m, bearing = np.empty(0), np.empty(0)
        if not self.full_circle and a.size:
            keep = np.abs(bearing) <= self.fov_rad / 2
            a, b, rng_m, bearing = a[keep], b[keep], rng_m[keep], bearing[keep]
        if self.cfg.line_of_sight and a.size:
            # one line-of-sight test per unordered pair (the test is symmetric bit for bit)
            key = np.minimum(a, b) * n_all + np.maximum(a, b)
            ukey, inv = np.unique(key, return_inverse=True)
            lo, hi = ukey // n_all, ukey % n_all
            lx, ly = self.grid.kernel_frame(xs, ys)[:2]
            seen = line_of_sight(self.blocking, self._ox, self._oy, self._res, lx[lo], ly[lo], lx[hi], ly[hi])[inv]
            a, b, rng_m, bearing = a[seen], b[seen], rng_m[seen], bearing[seen]
        row = row_of[a]
        order = np.lexsort((b, row))
        return row[order], a[order], b[order], rng_m[order], np.asarray(bearing)[order]

    def _visible_brute(self, xs, ys, thetas, obs):
        """:meth:`_visible` for a small team: one kernel finds the pairs in range and in line
        of sight (already ordered by row, then target); range and bearing come from the kernel
        the hashed path uses too, so both agree to the last bit."""
        n_all = xs.shape[0]
        cap = obs.shape[0] * max(n_all - 1, 0)
        out = np.empty((3, cap), dtype=np.int64)
        lx, ly = self.grid.kernel_frame(xs, ys)[:2]  # range and line of sight: frame-free / local
        m = _pairs_in_sight(lx, ly, obs, self.max_range_m * self.max_range_m, self.cfg.line_of_sight,
                            self.blocking, self._ox, self._oy, 1.0 / self._res, out)
        row, a, b = out[0, :m], out[1, :m], out[2, :m]
        if not m:
            empty = np.empty(0)
            return row, a, b, empty, empty
        # speed (H7a): hypot, atan2 and the wrap in one kernel (_range_bearing: libm's calls,
        # element by element)
        rng_m, bearing = _range_bearing(xs, ys, thetas, a, b)
        if not self.full_circle and m:
            keep = np.abs(bearing) <= self.fov_rad / 2
            row, a, b, rng_m, bearing = row[keep], a[keep], b[keep], rng_m[keep], bearing[keep]
        return row, a, b, rng_m, bearing

    # ------------------------------------------------------------------ noise
    def _noisy(self, d_r, a_r, size_m, rng):
        """Perceived range and bearing of true detections (rule 4)."""
        return self._apply_noise(d_r, a_r, size_m, self._draw_noise(d_r.shape[0], rng))

    def _draw_noise(self, m, rng):
        """The draws of rule 4 for ``m`` true detections: (2, m) uniforms (occlusion) or
        standard normals (gaussian), or None when the model is noise-free."""
        cfg = self.cfg
        if cfg.noise_model == "occlusion":
            return rng.random((2, m))
        if cfg.range_noise_std_m == 0.0 and cfg.bearing_noise_std_deg == 0.0:
            return None
        return rng.standard_normal((2, m))

    def _apply_noise(self, d_r, a_r, size_m, u):
        """Rule 4 with the draws ``u`` of :meth:`_draw_noise` (element by element, so the
        detections of several groups can be corrupted in one call)."""
        cfg = self.cfg
        m = d_r.shape[0]
        if cfg.noise_model == "occlusion":
            if cfg.err_max == 0.0:
                # perfect sensing (Tables 1-2, §6.1): exact range and bearing; the
                # draws of _draw_noise were taken all the same (the same random stream)
                return d_r, a_r
            # Sgorbissa & Arkin §6.1 eqs. 1-2: d_p = d_r + d_r d_noise, alpha_p = alpha_r +
            # atan(robotsize / 2 d_r) alpha_noise, d_noise ~ U[-err_max, err_max] and, as the paper
            # states, alpha_noise ~ U[-1, 1] (the bearing error of a partial occlusion is bounded
            # by the half-angle the seen robot subtends, whatever err_max is).
            # speed (H7a): in one kernel, the same operations element by element as
            #   d_p = d_r + d_r * (err_max * (2 u0 - 1)),
            #   a_p = wrap(a_r + arctan(size / (2 d_r)) * (2 u1 - 1))   (d_r = 0 -> pi/2)
            return _occlusion_noise(np.ascontiguousarray(d_r, dtype=np.float64),
                                    np.ascontiguousarray(a_r, dtype=np.float64),
                                    np.ascontiguousarray(size_m, dtype=np.float64), u[0], u[1], float(cfg.err_max))
        # Fox et al. §4.2, Fig. 7: zero-mean Gaussian errors, independent in distance and
        # angle; a perceived range is kept >= 0.
        if u is None:
            return d_r, a_r
        s_r = cfg.range_noise_std_m
        s_b = math.radians(cfg.bearing_noise_std_deg)
        d_p = np.maximum(d_r + s_r * u[0], 0.0)
        a_p = a_r + s_b * u[1]
        return d_p, _wrap(a_p) if m else a_p

    # ------------------------------------------------------------------ API
    def detect_arrays(self, xs, ys, thetas, radii, observers, rng: np.random.Generator, ids) -> DetectionArrays:
        """Every observer's detections at one step, as flat arrays.

        Parameters
        ----------
        xs, ys, thetas : ndarray of shape (N,)
            True poses of *all* robots [m, m, rad].
        radii : ndarray of shape (N,)
            Body radii [m]; the occlusion model's ``robotsize`` is the seen robot's diameter.
        observers : ndarray of shape (n,), int
            Indices (into the pose arrays) of the robots that look, without repeats.
        rng : numpy.random.Generator
            The detector's stream. Draws, in this order: the noise of the M true detections
            (occlusion: ``random((2, M))``; gaussian: ``standard_normal((2, M))`` unless both
            standard deviations are 0), false negatives ``random(M)`` (if
            ``p_false_negative > 0``), false positives ``random(n)`` then ``random((2, K))``
            for the K phantoms, then their ids ``integers(0, N - 1, K)`` when identities are
            reported (all only if ``p_false_positive > 0``).
        ids : ndarray of shape (N,), int
            The identity each robot is reported under.

        Returns
        -------
        DetectionArrays
            Ordered by observer row, then target index, phantoms last.
        """
        xs, ys, thetas, radii, obs, ids = self._check(xs, ys, thetas, radii, observers, rng, ids)
        return self._finish(self._visible(xs, ys, thetas, obs), xs.shape[0], radii, obs, rng, ids)

    def _finish(self, truth, n_all, radii, obs, rng, ids) -> DetectionArrays:
        """Rules 4–7 on the noise-free ``truth`` of :meth:`_visible` (all draws from ``rng``)."""
        cfg = self.cfg
        row, a, b, d_r, a_r = truth
        d_p, a_p = self._noisy(d_r, a_r, 2.0 * radii[b], rng)
        if cfg.p_false_negative > 0.0:
            kept = rng.random(row.shape[0]) >= cfg.p_false_negative
            row, a, b, d_p, a_p = row[kept], a[kept], b[kept], d_p[kept], a_p[kept]
        rid = ids[b] if cfg.report_identity else np.full(b.shape[0], -1, dtype=np.int64)
        if cfg.p_false_positive > 0.0 and obs.shape[0]:
            fp_rows = np.flatnonzero(rng.random(obs.shape[0]) < cfg.p_false_positive)
            k = fp_rows.shape[0]
            u = rng.random((2, k))
            fp_range = self.max_range_m * (1.0 - u[0])  # (0, max_range]
            if self.full_circle:
                fp_bearing = math.pi - 2.0 * math.pi * u[1]  # (-pi, pi]
            else:
                fp_bearing = self.fov_rad * (u[1] - 0.5)
            fp_obs = obs[fp_rows]
            if cfg.report_identity and n_all >= 2:
                other = rng.integers(0, n_all - 1, k)
                other += other >= fp_obs  # any robot but the observer
                fp_id = ids[other]
            else:
                fp_id = np.full(k, -1, dtype=np.int64)
            row = np.concatenate([row, fp_rows])
            a = np.concatenate([a, fp_obs])
            b = np.concatenate([b, np.full(k, -1, dtype=np.int64)])
            rid = np.concatenate([rid, fp_id])
            d_p = np.concatenate([d_p, fp_range])
            a_p = np.concatenate([a_p, fp_bearing])
            order = np.argsort(row, kind="stable")
            row, a, b, rid, d_p, a_p = row[order], a[order], b[order], rid[order], d_p[order], a_p[order]
        return DetectionArrays(
            row=row.astype(np.int64), observer=a.astype(np.int64), target=b.astype(np.int64),
            robot_id=rid.astype(np.int64), range_m=np.asarray(d_p, np.float64), bearing_rad=np.asarray(a_p, np.float64),
        )

    def detect(self, xs, ys, thetas, radii, observers, rng: np.random.Generator, ids) -> list[tuple[Detection, ...]]:
        """Every observer's detections at one step, as :class:`Detection` tuples.

        Same parameters as :meth:`detect_arrays`, which it wraps (same draws).

        Returns
        -------
        list of tuple of Detection
            ``result[k]`` holds what ``observers[k]`` perceives, in its body frame.
        """
        arr = self.detect_arrays(xs, ys, thetas, radii, observers, rng, ids)
        return _as_tuples(arr, np.asarray(observers).shape[0])

    def _detect_groups(self, xs, ys, thetas, radii, observers, rngs, ids) -> list[list[tuple[Detection, ...]]]:
        """:meth:`detect` for several groups of observers at once, without input checks (the
        engine's per-step path).

        The noise-free part (range, field of view, line of sight) is computed once for all
        observers; then each group draws its noise, false negatives and false positives from
        its own stream, exactly as :meth:`detect` would with that group alone: the result and
        every stream's state equal those of one :meth:`detect` call per group, in any order.

        Parameters
        ----------
        xs, ys, thetas, radii : ndarray of shape (N,)
            Contiguous float64, finite (true poses and radii of all robots).
        observers : list of ndarray (n_g,), int64
            Each group's observers; no robot in two groups.
        rngs : list of numpy.random.Generator
            Each group's detector stream.
        ids : ndarray (N,), int64

        Returns
        -------
        list of (list of tuple of Detection)
            Per group, what :meth:`detect` returns.
        """
        # speed (H7a): the engine passes the same observer arrays every step; their
        # concatenation and offsets are kept while they are the same objects
        key = tuple(map(id, observers))
        memo = getattr(self, "_groups_memo", None)
        if memo is None or memo[0] != key or any(x is not y for x, y in zip(memo[1], observers)):
            obs = observers[0] if len(observers) == 1 else np.concatenate(observers)
            sizes = [o.shape[0] for o in observers]
            offs = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            self._groups_memo = memo = (key, list(observers), obs, sizes, offs, offs.tolist())
        obs, sizes, offs = memo[2], memo[3], memo[4]
        row, a, b, d_r, a_r = self._visible(xs, ys, thetas, obs)
        n_all = xs.shape[0]
        cfg = self.cfg
        if row.shape[0] == 0 and cfg.p_false_negative == 0.0 and cfg.p_false_positive == 0.0:
            # nobody sees anybody: the same draws (none are used), no detections
            for rng in rngs:
                self._draw_noise(0, rng)
            return [[()] * n for n in sizes]
        cut = np.searchsorted(row, offs).tolist()
        if cfg.p_false_negative == 0.0 and cfg.p_false_positive == 0.0:
            # rule 4 only: each group's draws from its own stream, the arithmetic in one pass
            draws = [self._draw_noise(cut[g + 1] - cut[g], rng) for g, rng in enumerate(rngs)]
            u = None if draws[0] is None else draws[0] if len(draws) == 1 else np.concatenate(draws, axis=1)
            d_p, a_p = self._apply_noise(d_r, a_r, 2.0 * radii[b], u)
            rid = ids[b] if cfg.report_identity else np.full(b.shape[0], -1, dtype=np.int64)
            rids = [None if v < 0 else v for v in rid.tolist()]
            dets = [Detection(r, br, i) for r, br, i in zip(d_p.tolist(), a_p.tolist(), rids)]
            bl = np.searchsorted(row, np.arange(obs.shape[0] + 1)).tolist()
            per_row = [tuple(dets[bl[k]:bl[k + 1]]) for k in range(obs.shape[0])]
            return [per_row[offs[g]:offs[g + 1]] for g in range(len(observers))]
        out = []
        for g, (o, rng) in enumerate(zip(observers, rngs)):
            s0, s1 = cut[g], cut[g + 1]
            truth = (row[s0:s1] - offs[g], a[s0:s1], b[s0:s1], d_r[s0:s1], a_r[s0:s1])
            out.append(_as_tuples(self._finish(truth, n_all, radii, o, rng, ids), sizes[g]))
        return out

    def _detect_groups_padded(self, xs, ys, thetas, radii, observers, rngs, ids):
        """:meth:`_detect_groups` for a detector with rule 4 only (no false negatives or
        positives), its result already in the padded form of a group brain's observation
        (:func:`teamnav.control.group.pad_detections` of the concatenated groups' tuples):
        ``(count (n,), id (n, k), range_m (n, k), bearing_rad (n, k))`` over every observer of
        ``observers`` in order, ``k`` the most detections of one observer, empty slots -1 and
        NaN. The same draws from each group's stream and the same values bit for bit as the
        tuples (which only carried these float64 values as Python floats); no
        :class:`Detection` object is built. Returns None (nothing drawn) for a detector with
        false negatives or positives: the caller takes :meth:`_detect_groups` then.
        """
        cfg = self.cfg
        if cfg.p_false_negative != 0.0 or cfg.p_false_positive != 0.0:
            return None
        key = tuple(map(id, observers))
        memo = getattr(self, "_groups_memo", None)
        if memo is None or memo[0] != key or any(x is not y for x, y in zip(memo[1], observers)):
            obs = observers[0] if len(observers) == 1 else np.concatenate(observers)
            sizes = [o.shape[0] for o in observers]
            offs = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
            self._groups_memo = memo = (key, list(observers), obs, sizes, offs, offs.tolist())
        obs, offs = memo[2], memo[4]
        n = obs.shape[0]
        row, a, b, d_r, a_r = self._visible(xs, ys, thetas, obs)
        m = row.shape[0]
        if m == 0:
            for rng in rngs:
                self._draw_noise(0, rng)
            return np.zeros(n, dtype=np.int64), np.empty((n, 0), dtype=np.int64), np.empty((n, 0)), np.empty((n, 0))
        cut = np.searchsorted(row, offs).tolist()
        draws = [self._draw_noise(cut[g + 1] - cut[g], rng) for g, rng in enumerate(rngs)]
        u = None if draws[0] is None else draws[0] if len(draws) == 1 else np.concatenate(draws, axis=1)
        d_p, a_p = self._apply_noise(d_r, a_r, 2.0 * radii[b], u)
        return _pad_rows(row, b, ids, cfg.report_identity, np.asarray(d_p, np.float64), np.asarray(a_p, np.float64), n)


# ---------------------------------------------------------------------------- helpers
@njit(cache=True)
def _pad_rows(row, b, ids, report_identity, d_p, a_p, n):
    """The padded arrays of :meth:`Detector._detect_groups_padded` from the sorted detections
    (``row`` ascending; each row's detections in order): per row its count, and its
    detections' ids (``ids[b]``, -1 without identities or for a negative id), ranges and
    bearings in slots 0..count-1, the rest -1 / NaN (as ``pad_detections`` fills them)."""
    m = row.shape[0]
    count = np.zeros(n, dtype=np.int64)
    for j in range(m):
        count[row[j]] += 1
    k = 0
    for r in range(n):
        if count[r] > k:
            k = count[r]
    det_id = np.full((n, k), -1, dtype=np.int64)
    rng_m = np.full((n, k), np.nan)
    brg = np.full((n, k), np.nan)
    col = 0
    for j in range(m):
        r = row[j]
        if j > 0 and row[j - 1] == r:
            col += 1
        else:
            col = 0
        if report_identity:
            v = ids[b[j]]
            det_id[r, col] = v if v >= 0 else -1
        rng_m[r, col] = d_p[j]
        brg[r, col] = a_p[j]
    return count, det_id, rng_m, brg


#: Teams up to this size find their visible pairs by testing every pair in one kernel;
#: larger ones use the spatial hash (:func:`teamnav.world.los.pairs_within`).
_BRUTE_MAX_ROBOTS = 64


@njit(cache=True)
def _pairs_in_sight(xs, ys, obs, r2, los, blocking, ox, oy, inv, out):
    """Directed pairs (row, observer, target) with the target within ``sqrt(r2)`` of the
    observer and, if ``los``, in line of sight; ordered by row, then target. Returns the
    count written to ``out`` (3, cap)."""
    n = xs.shape[0]
    m = 0
    for k in range(obs.shape[0]):
        i = obs[k]
        for j in range(n):
            if j == i:
                continue
            ddx = xs[i] - xs[j]
            ddy = ys[i] - ys[j]
            if ddx * ddx + ddy * ddy <= r2:
                lo = min(i, j)
                hi = max(i, j)
                if los and not _segment_visible(blocking, (xs[lo] - ox) * inv, (ys[lo] - oy) * inv,
                                                (xs[hi] - ox) * inv, (ys[hi] - oy) * inv):
                    continue
                out[0, m] = k
                out[1, m] = i
                out[2, m] = j
                m += 1
    return m


_TWO_PI = 2.0 * math.pi


@njit(cache=True, inline="always")
def _wrap1(a):
    """:func:`~teamnav.geometry.angles.wrap_angle` of one float (its operations: np.mod is
    fmod with the sign of the divisor)."""
    if (a > -math.pi and a <= math.pi) or a != a:
        return a
    w = np.fmod(a + math.pi, _TWO_PI)
    if w != 0.0:
        if w < 0.0:
            w += _TWO_PI
    else:
        w = 0.0
    w = w - math.pi
    if w <= -math.pi:
        w += _TWO_PI
    if w > math.pi:
        w = math.pi
    return w


@njit(cache=True)
def _range_bearing(xs, ys, thetas, a, b):
    """Range ``hypot(dx, dy)`` and wrapped bearing ``arctan2(dy, dx) − θ_a`` of each pair a -> b."""
    m = a.shape[0]
    rng_m = np.empty(m)
    bearing = np.empty(m)
    for k in range(m):
        dx = xs[b[k]] - xs[a[k]]
        dy = ys[b[k]] - ys[a[k]]
        rng_m[k] = math.hypot(dx, dy)
        bearing[k] = _wrap1(math.atan2(dy, dx) - thetas[a[k]])
    return rng_m, bearing


@njit(cache=True, error_model="numpy")
def _occlusion_noise(d_r, a_r, size_m, u0, u1, err_max):
    """Sgorbissa & Arkin eqs. 1-2 with the draws (u0, u1) (see :meth:`RobotDetector._apply_noise`)."""
    m = d_r.shape[0]
    d_p = np.empty(m)
    a_p = np.empty(m)
    for k in range(m):
        d_noise = err_max * (2.0 * u0[k] - 1.0)
        a_noise = 2.0 * u1[k] - 1.0
        d_p[k] = d_r[k] + d_r[k] * d_noise
        half_angle = math.atan(size_m[k] / (2.0 * d_r[k]))
        a_p[k] = _wrap1(a_r[k] + half_angle * a_noise)
    return d_p, a_p


def _wrap(a: np.ndarray) -> np.ndarray:
    """:func:`~teamnav.geometry.angles.wrap_angle` of an array, returned as is when every angle
    is already in ``(-pi, pi]`` (which is what ``wrap_angle`` returns then, bit for bit)."""
    if a.shape[0] and bool(((a > -math.pi) & (a <= math.pi)).all()):
        return a
    return wrap_angle(a)


def _as_tuples(arr: DetectionArrays, n: int) -> list[tuple[Detection, ...]]:
    """Per observer row, its detections as :class:`Detection` tuples."""
    if arr.row.shape[0] == 0:
        return [()] * n
    bounds = np.searchsorted(arr.row, np.arange(n + 1))
    rids = [None if v < 0 else v for v in arr.robot_id.tolist()]
    dets = [Detection(r, br, i) for r, br, i in zip(arr.range_m.tolist(), arr.bearing_rad.tolist(), rids)]
    bl = bounds.tolist()
    return [tuple(dets[bl[k]:bl[k + 1]]) for k in range(n)]
