"""Ray-casting throughput and exactness on the MIT basement map, against peers, in one run.

    python benchmarks/bench_raycast.py            # 100 000 poses x 180 beams, reference on 1000 poses
    python benchmarks/bench_raycast.py --quick    # 10 000 poses, reference on 100 poses (< 1 min)

Queries: random poses uniformly inside free cells of ``basement_hallways_5cm.png`` (0.05 m,
1200 x 1200; unknown grey counts as blocking), random headings, 180 beams spread over 180°,
10 m maximum range. Every method answers the same queries:

- ``teamnav``: :class:`teamnav.world.RayCaster` (clearance-map jumping + exact DDA), one
  thread (``parallel=False``) and all numba threads.
- ``numba DDA``: a plain Amanatides–Woo traversal, the textbook exact method, written here
  with the same care (precomputed sin/cos, integer cell indices, prange over poses).
- ``raycast2D`` (PyPI, C, Bresenham, single-threaded): only if installed. It is GPL and
  never a dependency of teamnav; install it in a separate venv, see ``benchmarks/README.md``.

Agreement is measured against :func:`teamnav.world.raycast.brute_force_reference` (steps of
0.001 cell) on the first ``--ref-poses`` poses: the share of rays within one cell (0.05 m) and
the worst error. Timings exclude JIT compilation (a warm-up call first) and take the best of
``--repeat`` rounds, the methods taking turns within a round (the machine may be shared).
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np
from numba import njit, prange

from teamnav.world.grid import OccupancyGrid
from teamnav.world.raycast import RayCaster, brute_force_reference, clearance_map

MAP_PNG = Path(os.environ.get("TEAMNAV_DATA", "/work/shared/data")) / "mit" / "basement_hallways_5cm.png"
RES_M = 0.05
MAX_RANGE_M = 10.0


# ---------------------------------------------------------------------------- data
def load_basement(path: Path = MAP_PNG) -> np.ndarray:
    """uint8 (H, W) blocking mask, row 0 = bottom: pixel 0 occupied, 205 unknown (blocks), >= 254 free."""
    from PIL import Image

    img = np.asarray(Image.open(path).convert("L"))[::-1]
    blk = np.ascontiguousarray((img < 254).astype(np.uint8))
    blk.setflags(write=False)
    return blk


def random_free_poses(blocking: np.ndarray, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    free = np.argwhere(blocking == 0)
    pick = free[rng.integers(0, len(free), n)]
    xs = (pick[:, 1] + rng.random(n)) * RES_M
    ys = (pick[:, 0] + rng.random(n)) * RES_M
    th = rng.uniform(-math.pi, math.pi, n)
    return xs, ys, th


# ---------------------------------------------------------------------------- peer: plain DDA
@njit(cache=True, inline="always")
def _dda_one(blk, fx, fy, dx, dy, tmax):
    h = blk.shape[0]
    w = blk.shape[1]
    c = int(math.floor(fx))
    r = int(math.floor(fy))
    if r < 0 or r >= h or c < 0 or c >= w or blk[r, c] != 0:
        return 0.0
    if dx > 0.0:
        sx = 1
        tdx = 1.0 / dx
        tmx = (c + 1 - fx) * tdx
    elif dx < 0.0:
        sx = -1
        tdx = -1.0 / dx
        tmx = (fx - c) * tdx
    else:
        sx = 0
        tdx = np.inf
        tmx = np.inf
    if dy > 0.0:
        sy = 1
        tdy = 1.0 / dy
        tmy = (r + 1 - fy) * tdy
    elif dy < 0.0:
        sy = -1
        tdy = -1.0 / dy
        tmy = (fy - r) * tdy
    else:
        sy = 0
        tdy = np.inf
        tmy = np.inf
    while True:
        if tmx < tmy:
            t = tmx
            c += sx
            tmx += tdx
        else:
            t = tmy
            r += sy
            tmy += tdy
        if t >= tmax:
            return tmax
        if r < 0 or r >= h or c < 0 or c >= w or blk[r, c] != 0:
            return t


@njit(cache=True, parallel=True)
def dda_cast(blk, res, xs, ys, ths, beams, tmax, out):
    """Plain Amanatides–Woo DDA, all poses x beams (the internal peer)."""
    nb = beams.shape[0]
    cb = np.cos(beams)
    sb = np.sin(beams)
    for p in prange(xs.shape[0]):
        fx = xs[p] / res
        fy = ys[p] / res
        ct = math.cos(ths[p])
        st = math.sin(ths[p])
        for b in range(nb):
            dx = ct * cb[b] - st * sb[b]
            dy = st * cb[b] + ct * sb[b]
            out[p, b] = _dda_one(blk, fx, fy, dx, dy, tmax) * res


# ---------------------------------------------------------------------------- peer: raycast2D
def raycast2d_module():
    try:
        from raycast2D import raycaster  # type: ignore[import-not-found]
    except ImportError:
        return None
    return raycaster


def raycast2d_prepare(blocking, xs, ys, ths, beams):
    """raycast2D's own inputs: image (0 = occupied), integer pixel poses, (P, B, 3) uint32 endpoints."""
    img = np.ascontiguousarray((blocking == 0).astype(np.uint8))
    px = np.floor(xs / RES_M).astype(np.int64)
    py = np.floor(ys / RES_M).astype(np.int64)
    length_px = MAX_RANGE_M / RES_M
    ang = ths[:, None] + beams[None, :]
    ex = np.round(px[:, None] + length_px * np.cos(ang)).astype(np.int64)
    ey = np.round(py[:, None] + length_px * np.sin(ang)).astype(np.int64)
    rays = np.zeros(ang.shape + (3,), np.int64)
    rays[..., 0] = ex
    rays[..., 1] = ey
    return img, px, py, rays.astype(np.uint32)  # negative ends wrap like the C int cast expects


def raycast2d_run(mod, img, px, py, rays):
    for p in range(px.shape[0]):
        mod.raycast(img, rays[p], int(px[p]), int(py[p]))


def raycast2d_ranges(rays, xs, ys, ths, beams):
    """Ranges [m] from raycast2D's hit cells: where our exact beam enters that cell (slab test),
    or the distance to its centre if the beam misses it; max range when nothing was hit."""
    hit = rays[..., 2] == 1
    cx = rays[..., 0].astype(np.int64).astype(np.float64)
    cy = rays[..., 1].astype(np.int64).astype(np.float64)
    fx = (xs / RES_M)[:, None]
    fy = (ys / RES_M)[:, None]
    ang = ths[:, None] + beams[None, :]
    dx, dy = np.cos(ang), np.sin(ang)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1x, t2x = (cx - fx) / dx, (cx + 1 - fx) / dx
        t1y, t2y = (cy - fy) / dy, (cy + 1 - fy) / dy
        tin = np.maximum(np.minimum(t1x, t2x), np.minimum(t1y, t2y))
        tout = np.minimum(np.maximum(t1x, t2x), np.maximum(t1y, t2y))
    through = np.isfinite(tin) & (tin <= tout) & (tout >= 0)
    centre = np.hypot(cx + 0.5 - fx, cy + 0.5 - fy)
    t = np.where(through, np.maximum(tin, 0.0), centre) * RES_M
    return np.where(hit, np.minimum(t, MAX_RANGE_M), MAX_RANGE_M)


# ---------------------------------------------------------------------------- harness
def best_time(fn, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def agreement(ranges: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    err = np.abs(ranges - ref)
    return float((err <= RES_M).mean() * 100.0), float(err.max())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="10k poses, reference on 100 poses")
    ap.add_argument("--poses", type=int, default=None, help="number of poses (default 100000, quick 10000)")
    ap.add_argument("--beams", type=int, default=180)
    ap.add_argument("--ref-poses", type=int, default=None, help="poses checked against the reference (default 1000, quick 100)")
    ap.add_argument("--repeat", type=int, default=None, help="timing rounds, best kept (default 5, quick 3)")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    n = args.poses or (10_000 if args.quick else 100_000)
    n_ref = min(n, args.ref_poses or (100 if args.quick else 1000))
    repeat = args.repeat or (3 if args.quick else 5)
    if n < 1 or args.beams < 1 or n_ref < 1 or repeat < 1:
        raise SystemExit(f"--poses, --beams, --ref-poses and --repeat must be >= 1, got {n}, {args.beams}, {n_ref}, {repeat}")
    all_threads = numba.config.NUMBA_NUM_THREADS

    blocking = load_basement()
    grid = OccupancyGrid(blocking, RES_M, (0.0, 0.0), name=str(MAP_PNG))
    xs, ys, ths = random_free_poses(blocking, n, args.seed)
    beams = np.linspace(-math.pi / 2, math.pi / 2, args.beams)
    nrays = n * args.beams
    print(f"map {MAP_PNG.name} {blocking.shape[1]}x{blocking.shape[0]} @ {RES_M} m, {n} poses x {args.beams} beams "
          f"= {nrays / 1e6:.1f} M rays, max range {MAX_RANGE_M} m; {platform.processor() or platform.machine()}, "
          f"{all_threads} numba threads, numba {numba.__version__}")

    clearance_map(np.zeros((2, 2), np.uint8))  # first numba call of the process: loads numba
    t0 = time.perf_counter()
    caster = RayCaster(grid, max_range_m=MAX_RANGE_M)
    setup_s = time.perf_counter() - t0
    tmax = MAX_RANGE_M / RES_M

    # contenders: (name, threads, prepare(), timed run(), ranges())
    contenders = []
    for threads in sorted({1, all_threads}):
        ours = np.empty((n, args.beams))
        contenders.append((
            "teamnav RayCaster", threads, lambda: None,
            lambda o=ours, t=threads: caster.cast_xyt(xs, ys, ths, beams, out=o, parallel=t > 1),
            lambda o=ours: o,
        ))
        dda = np.empty((n, args.beams))
        contenders.append((
            "numba plain DDA", threads, lambda: None,
            lambda o=dda: dda_cast(blocking, RES_M, xs, ys, ths, beams, tmax, o),
            lambda o=dda: o,
        ))
    mod = raycast2d_module()
    if mod is not None:
        img, px, py, rays = raycast2d_prepare(blocking, xs, ys, ths, beams)
        work = [rays.copy()]

        def rc_prepare():
            work[0] = rays.copy()  # raycast2D writes its hits into its input

        contenders.append((
            "raycast2D (C, Bresenham)", 1, rc_prepare,
            lambda: raycast2d_run(mod, img, px, py, work[0]),
            lambda: raycast2d_ranges(work[0], xs, ys, ths, beams),
        ))
    else:
        print("raycast2D not installed: its row is skipped. To compare, in a separate venv:\n"
              "  python -m venv /tmp/benchenv && /tmp/benchenv/bin/pip install -r benchmarks/requirements-peers.txt\n"
              "  /tmp/benchenv/bin/pip install -e . --no-deps && /tmp/benchenv/bin/python benchmarks/bench_raycast.py")

    # warm up (JIT), then time round-robin so that every method sees the same machine load
    for name, threads, prep, run, _ in contenders:
        numba.set_num_threads(threads)
        prep()
        run()
    best = [math.inf] * len(contenders)
    busy = [0.0] * len(contenders)  # CPU time / (wall time x threads) of the best round
    for _ in range(repeat):
        for i, (name, threads, prep, run, _) in enumerate(contenders):
            numba.set_num_threads(threads)
            prep()
            c0 = time.process_time()
            t0 = time.perf_counter()
            run()
            dt = time.perf_counter() - t0
            if dt < best[i]:
                best[i] = dt
                busy[i] = (time.process_time() - c0) / (dt * threads)
    rows = [(c[0], c[1], dt, c[4](), b) for c, dt, b in zip(contenders, best, busy)]

    numba.set_num_threads(all_threads)
    t0 = time.perf_counter()
    ref = brute_force_reference(blocking, 0.0, 0.0, RES_M, xs[:n_ref], ys[:n_ref], ths[:n_ref], beams, MAX_RANGE_M)
    ref_s = time.perf_counter() - t0
    hit_share = float((ref < MAX_RANGE_M).mean() * 100)

    base = next((r[2] for r in rows if r[0].startswith("raycast2D")), None)
    print(f"\nclearance maps built in {setup_s * 1e3:.0f} ms; reference: {n_ref} poses ({n_ref * args.beams} rays, "
          f"{hit_share:.0f} % hit something) in {ref_s:.1f} s")
    head = (f"{'method':<26}{'threads':>8}{'M rays/s':>10}{'vs raycast2D':>14}{'within 1 cell':>15}"
            f"{'worst err m':>13}{'cpu busy':>10}")
    print(head)
    print("-" * len(head))
    for name, threads, dt, ranges, cpu in rows:
        pct, worst = agreement(ranges[:n_ref], ref)
        ratio = f"{base / dt:.2f}x" if base else "n/a"
        print(f"{name:<26}{threads:>8}{nrays / dt / 1e6:>10.2f}{ratio:>14}{pct:>14.3f}%{worst:>13.4f}{cpu:>9.0%}")
    print("(vs raycast2D: against its single thread; cpu busy well under 100 % on a multi-thread row means\n"
          " the cores were shared with other work during that run, so its figure is low)")
    ours = {r[1]: r for r in rows if r[0].startswith("teamnav")}
    for threads, (_, _, _, ranges, _) in ours.items():
        if not np.array_equal(ranges, ours[1][3]):
            print(f"WARNING: teamnav ranges differ between 1 and {threads} threads")
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
