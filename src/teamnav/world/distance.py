"""Euclidean distance field of an occupancy grid, and the likelihood field built on it.

The distance field feeds the likelihood-field sensor model of MCL (Thrun, Burgard & Fox,
*Probabilistic Robotics* §6.4, the end-point model that Fox et al.'s beam model is usually
traded for when speed matters) and potential-field navigation (Sgorbissa & Arkin §2).
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.world import field_cache
from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import _check_blocking, _check_positive

__all__ = ["COARSE_BLOCK_CELLS", "COARSE_FIELD_CELLS", "clearance_bound", "distance_field", "likelihood_field"]

#: Maps of at least this many cells get :func:`clearance_bound` in the simulator instead of a
#: dense :func:`distance_field` (the swarm arena at 2 cm has 2.5 M cells for 1000 robots, 25 M
#: for 10 000). The largest built-in map (the MIT basement, 1200 x 1200, of the demo and the
#: papers' runs) has 1.44 M, so no built-in run takes this path.
COARSE_FIELD_CELLS: int = 2_000_000
#: Side [cells] of the blocks of :func:`clearance_bound` (a power of 2).
COARSE_BLOCK_CELLS: int = 16


def distance_field(grid_or_blocking, resolution_m: float | None = None) -> np.ndarray:
    """Distance [m] from each cell centre to the nearest blocking cell centre.

    Parameters
    ----------
    grid_or_blocking : OccupancyGrid or ndarray of shape (H, W)
        A grid (every obstacle blocks: ``grid.blocking()``) or a blocking mask (nonzero =
        blocking).
    resolution_m : float, optional
        Cell side [m]. Required for a mask; for a grid it defaults to the grid's and, when
        given, must equal it.

    Returns
    -------
    ndarray of shape (H, W), float64
        Exact Euclidean distance transform (``scipy.ndimage.distance_transform_edt``) in
        metres, 0 in blocking cells. Cells outside the grid do not count as obstacles;
        a grid without any blocking cell gives ``inf`` everywhere. **Read-only**: the field of
        the last mask asked for is kept and handed out again, not copied (a 10 000-robot
        arena's field is 200 MB); ``.copy()`` it to change it.

    Examples
    --------
    >>> b = np.zeros((1, 4), np.uint8); b[0, 0] = 1
    >>> distance_field(b, 0.5).tolist()
    [[0.0, 0.5, 1.0, 1.5]]
    """
    if isinstance(grid_or_blocking, OccupancyGrid):
        grid = grid_or_blocking
        if resolution_m is not None and float(resolution_m) != grid.resolution_m:
            raise ValueError(
                f"resolution_m must match the grid's resolution {grid.resolution_m} (or be None), got {resolution_m!r}"
            )
        blocking = grid.blocking()
        res = grid.resolution_m
    else:
        if resolution_m is None:
            raise ValueError("resolution_m must be a finite number > 0 when a blocking mask is given, got None")
        blocking = _check_blocking(grid_or_blocking)
        res = _check_positive("resolution_m", resolution_m)
    last = _LAST[0]
    if last is not None and last[1] == res and last[0].shape == blocking.shape and np.array_equal(last[0], blocking):
        return last[2]
    free = blocking == 0
    if free.all():
        field = np.full(blocking.shape, np.inf)
    else:
        field = field_cache.load(blocking, res)  # large maps: computed once per machine, kept on disk
        if field is None:
            field = _edt(free, res)
            field_cache.store(blocking, res, field)
    field.flags.writeable = False
    _LAST[0] = (np.array(blocking, copy=True), res, field)
    return field


#: the last blocking mask, resolution and field :func:`distance_field` computed: a run asks
#: for its map's field twice (start poses, then the collision metric), 0.15 s each on a
#: 1200 x 1200 map; the field is read-only, so every caller can share the one array
_LAST: list = [None]


def likelihood_field(distance_m: np.ndarray, sigma_m: float, max_distance_m: float | None = None) -> np.ndarray:
    """Likelihood-field table ``exp(-d² / 2σ²)`` for the end-point sensor model.

    Parameters
    ----------
    distance_m : ndarray
        Distance field [m] (from :func:`distance_field`).
    sigma_m : float
        Standard deviation of the measurement noise [m].
    max_distance_m : float, optional
        Distances are clipped to this value first, so far-from-anything cells keep a small
        non-zero likelihood (Probabilistic Robotics §6.4). None: no clipping.

    Returns
    -------
    ndarray, same shape as ``distance_m``, float64
        Unnormalised Gaussian likelihood in ``(0, 1]``; 1 on obstacles.

    Examples
    --------
    >>> likelihood_field(np.array([0.0, 0.1]), 0.1).round(4).tolist()
    [1.0, 0.6065]
    """
    d = np.asarray(distance_m, dtype=np.float64)
    sigma = _check_positive("sigma_m", sigma_m)
    if np.isnan(d).any() or (d < 0).any():
        raise ValueError("distance_m must hold distances >= 0 (inf allowed), got negative or NaN values")
    if max_distance_m is not None:
        dmax = _check_positive("max_distance_m", max_distance_m)
        d = np.minimum(d, dmax)
    return np.exp(-(d * d) / (2.0 * sigma * sigma))


#: Cells of the distance field computed at once from the feature transform (a block of rows;
#: about 16 MB of temporaries).
_EDT_BLOCK_CELLS = 1 << 20


def _edt(free: np.ndarray, res: float) -> np.ndarray:
    """``scipy.ndimage.distance_transform_edt(free, sampling=res)``, bit for bit, without its
    full-grid temporaries.

    scipy computes the nearest-feature indices (int32, two per cell), then the distances from
    them through an int32 and a float64 array of two values per cell: 24 bytes a cell beside
    the 8-byte result, 815 MB of temporaries on the 25 M cells of a 10 000-robot arena at 2 cm.
    Here the indices come from scipy (``return_indices``) and the distances are computed a
    block of rows at a time with scipy's own operations in its order (difference, to float64,
    times the cell side, squared, the two axes summed, square root), so every value is the
    same double (``tests/test_distance_memory.py`` checks it against scipy).
    """
    from scipy import ndimage  # here: scipy.ndimage alone takes ~0.3 s to import

    ft = ndimage.distance_transform_edt(free, sampling=res, return_distances=False, return_indices=True)
    h, w = free.shape
    out = np.empty((h, w), np.float64)
    cols = np.arange(w, dtype=np.int32)
    step = max(1, _EDT_BLOCK_CELLS // max(w, 1))
    res = float(res)
    for r0 in range(0, h, step):
        r1 = min(h, r0 + step)
        dy = (ft[0, r0:r1] - np.arange(r0, r1, dtype=np.int32)[:, None]).astype(np.float64)
        dx = (ft[1, r0:r1] - cols[None, :]).astype(np.float64)
        dy *= res
        dx *= res
        np.multiply(dy, dy, dy)
        np.multiply(dx, dx, dx)
        np.add(dy, dx, dy)
        np.sqrt(dy, out[r0:r1])
    return out


def clearance_bound(blocking: np.ndarray, resolution_m: float, block: int = COARSE_BLOCK_CELLS) -> np.ndarray:
    """A lower bound of :func:`distance_field` per block of ``block x block`` cells.

    Parameters
    ----------
    blocking : ndarray of shape (H, W), uint8
        Blocking mask (nonzero = blocking).
    resolution_m : float
        Cell side [m].
    block : int, default :data:`COARSE_BLOCK_CELLS`
        Block side [cells], a power of 2 (>= 2).

    Returns
    -------
    ndarray of shape (ceil(H / block), ceil(W / block)), float64, read-only
        ``out[I, J]`` is at most the distance field's value (as :func:`distance_field`
        computes it, rounding included) at every cell of block ``(I, J)``: from the distance
        ``D`` [blocks] between block ``(I, J)`` and the nearest block holding a blocking cell
        (an exact Euclidean transform of the coarse mask), ``res * (block * D - sqrt(2) *
        (block - 1))`` (two cell centres are within ``(block - 1) / sqrt(2)`` cells of their
        blocks' centres), floored at 0 and shrunk by a relative 1e-9 to stay below the fine
        field's rounding; ``inf`` everywhere when nothing blocks. 0 in a block that holds a
        blocking cell. It costs 8 bytes per block (1 MB for the 25 M cells of a 10 000-robot
        arena at 2 cm, instead of 200 MB) and one pass over the mask.

    The collision kernels (:mod:`teamnav.sim.collisions`) read it, as they read the fine field,
    only to skip the exact cell test of a disc far from every wall; :func:`teamnav.sim.start.
    start_poses` chooses the same start cells with it as with the fine field.

    Examples
    --------
    >>> b = np.zeros((64, 64), np.uint8); b[:, 0] = 1
    >>> lb = clearance_bound(b, 0.1, 16)
    >>> lb.shape, bool((lb[:, 0] == 0).all()), bool((lb[:, 3] <= distance_field(b, 0.1)[:, 48:].min()).all())
    ((4, 4), True, True)
    """
    blocking = _check_blocking(blocking)
    res = _check_positive("resolution_m", resolution_m)
    block = int(block)
    if block < 2 or block & (block - 1):
        raise ValueError(f"block must be a power of 2 >= 2, got {block!r}")
    h, w = blocking.shape
    hc, wc = -(-h // block), -(-w // block)
    starts = np.arange(0, w, block)
    occ = np.zeros((hc, wc), np.bool_)
    for i in range(hc):
        occ[i] = np.logical_or.reduceat(blocking[i * block:(i + 1) * block].any(axis=0), starts)
    if not occ.any():
        out = np.full((hc, wc), np.inf)
    else:
        from scipy import ndimage

        d = ndimage.distance_transform_edt(~occ)
        out = np.maximum(res * (block * d - math.sqrt(2.0) * (block - 1)), 0.0) * (1.0 - 1e-9)
    out.flags.writeable = False
    return out


def block_shift(field_shape: tuple[int, int], blocking_shape: tuple[int, int]) -> int:
    """``k`` such that a field of ``field_shape`` has one value per ``2**k x 2**k`` block of a
    ``blocking_shape`` grid (0 for a dense field); ValueError when there is none."""
    h, w = blocking_shape
    for k in range(31):
        b = 1 << k
        if (-(-h // b), -(-w // b)) == tuple(field_shape):
            return k
        if b > max(h, w):
            break
    raise ValueError(f"a clearance field of shape {tuple(field_shape)} does not fit a map of shape {tuple(blocking_shape)}")
