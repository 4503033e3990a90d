"""One MCL update (motion + perception weighting + resampling), particle-beams per second.

Contenders, on the same map, particles and scan in one run:

- teamnav ``MCL``, beam model with exact ray casting (Fox et al. §2.2 Fig. 1; ``teamnav.world.raycast``);
- teamnav ``MCL``, likelihood field (Probabilistic Robotics §6.4);
- a straightforward NumPy MCL (written here): Table 5.6 motion, ray marching at half a cell,
  the exact beam mixture, ``searchsorted`` low-variance resampling;
- nav2's AMCL core through the ``amcl`` package from PyPI (GPL-3.0: only in the benchmark's
  own venv, never a teamnav dependency), ``min_particles = max_particles = n``, 60 beams.

Plus density-tree build + query for 10 000 samples. Usage::

    python -m venv /tmp/amcl-venv && /tmp/amcl-venv/bin/pip install amcl numpy numba scipy pillow pyyaml pydantic
    /tmp/amcl-venv/bin/pip install -e . --no-deps
    /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py            # 1k, 10k, 100k particles
    /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py --quick    # 1k, 10k
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from teamnav.control.protocol import SensorInfo
from teamnav.localization import MCL, DensityTree, MCLParams, MotionParams
from teamnav.localization.beam_model import BeamModelParams, beam_probability
from teamnav.world import load_map
from teamnav.world.raycast import RayCaster

MAP = Path(__file__).resolve().parents[1] / "src/teamnav/world/maps/mit/basement_hallways_5cm.yaml"
N_BEAMS = 60
MAX_RANGE = 10.0
SEES = ("wall", "unknown", "foam")


# ---------------------------------------------------------------------------- NumPy peer
class NumpyMCL:
    """The textbook loop written with NumPy arrays (no numba): what a first implementation is."""

    def __init__(self, grid, particles, angles, rng):
        self.block = grid.blocking(SEES).astype(bool)
        self.res = grid.resolution_m
        self.ox, self.oy = grid.origin_xy_m
        self.p = particles.copy()
        self.w = np.full(len(particles), 1.0 / len(particles))
        self.angles = angles
        self.rng = rng
        self.beam = BeamModelParams()

    def raymarch(self, p):
        h, w = self.block.shape
        step = 0.5 * self.res
        ts = np.arange(0.0, MAX_RANGE + step, step)
        out = np.empty((len(p), len(self.angles)))
        for a in range(0, len(p), 256):  # chunks bound the (chunk, beams, steps) temporaries
            q = p[a:a + 256]
            th = q[:, 2:3] + self.angles[None, :]
            xs = q[:, 0:1, None] + np.cos(th)[:, :, None] * ts
            ys = q[:, 1:2, None] + np.sin(th)[:, :, None] * ts
            c = np.floor((xs - self.ox) / self.res).astype(np.int64)
            r = np.floor((ys - self.oy) / self.res).astype(np.int64)
            inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
            hit = ~inside | self.block[np.clip(r, 0, h - 1), np.clip(c, 0, w - 1)]
            first = np.where(hit.any(axis=2), hit.argmax(axis=2), len(ts) - 1)
            out[a:a + 256] = np.minimum(ts[first], MAX_RANGE)
        return out

    def update(self, delta, z, alpha):
        n = len(self.p)
        rot1 = math.atan2(delta[1], delta[0])
        trans = math.hypot(delta[0], delta[1])
        rot2 = delta[2] - rot1
        e = self.rng.standard_normal((n, 3))
        r1 = rot1 - e[:, 0] * math.sqrt(alpha[0] * rot1**2 + alpha[1] * trans**2)
        t = trans - e[:, 1] * math.sqrt(alpha[2] * trans**2 + alpha[3] * (rot1**2 + rot2**2))
        r2 = rot2 - e[:, 2] * math.sqrt(alpha[0] * rot2**2 + alpha[1] * trans**2)
        self.p[:, 0] += t * np.cos(self.p[:, 2] + r1)
        self.p[:, 1] += t * np.sin(self.p[:, 2] + r1)
        self.p[:, 2] = np.angle(np.exp(1j * (self.p[:, 2] + r1 + r2)))
        expected = self.raymarch(self.p)
        ll = np.log(beam_probability(z[None, :], expected, self.beam, MAX_RANGE)).sum(axis=1)
        lw = np.log(self.w) + ll
        w = np.exp(lw - lw.max())
        c = np.cumsum(w)
        u = (self.rng.random() + np.arange(n)) * (c[-1] / n)
        self.p = self.p[np.minimum(np.searchsorted(c, u), n - 1)]
        self.w = np.full(n, 1.0 / n)


# ---------------------------------------------------------------------------- amcl peer
def make_amcl(grid, n, angles):
    try:
        import amcl
    except ImportError:
        return None
    occ = np.where(grid.cells == 0, 0, 100).astype(int)
    occ[grid.cells == 2] = -1
    mp = amcl.MotionParameters(alpha1=0.05, alpha2=0.05, alpha3=0.05, alpha4=0.05, alpha5=0.05)
    lp = amcl.LaserParameters(z_hit=0.8, z_short=0.1, z_max=0.05, z_rand=0.05, sigma_hit=0.1, lambda_short=0.5,
                              chi_outlier=0.0, max_beams=N_BEAMS)
    loc = amcl.AMCL(n, n, 0.001, 0.1, mp, lp, "differential")
    loc.set_map(amcl.create_occupancy_grid_from_list(occ.tolist(), grid.resolution_m, *grid.origin_xy_m))
    loc.set_laser_pose(amcl.Vector3D(0.0, 0.0, 0.0))
    xmin, xmax, ymin, ymax = grid.bounds_m
    loc.set_initial_pose(amcl.Vector3D(0.5 * (xmin + xmax), 0.5 * (ymin + ymax), 0.0),
                         amcl.create_diagonal_covariance(25.0, 25.0, 3.0))
    return loc, amcl


def time_amcl(peer, scan_m, angles, rounds):
    loc, amcl = peer
    scan = amcl.create_laser_scan_from_list([[float(r), float(a)] for r, a in zip(scan_m, angles)], MAX_RANGE)
    x = 0.0
    loc.update(scan, amcl.Vector3D(x, 0.0, 0.0))
    best = math.inf
    for _ in range(rounds):
        x += 0.3  # beyond AMCL's update thresholds, so every call runs the filter
        t = time.perf_counter()
        loc.update(scan, amcl.Vector3D(x, 0.0, 0.0))
        best = min(best, time.perf_counter() - t)
    return best


# ---------------------------------------------------------------------------- runs
def time_teamnav(grid, sensor, n, model, scan, rounds):
    params = MCLParams(n_particles=n, sensor_model=model, recovery="none", motion=MotionParams())
    f = MCL(params, grid, sensor, np.random.default_rng(0))
    f.init_global()
    d = np.array([0.1, 0.0, 0.02])
    f.predict(d), f.update(scan), f.resample()  # compile / warm caches
    best = math.inf
    for _ in range(rounds):
        t = time.perf_counter()
        f.predict(d)
        f.update(scan)
        f.resample()
        best = min(best, time.perf_counter() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1k and 10k particles only, fewer rounds")
    ap.add_argument("--no-numpy-at", type=int, default=100_000, help="skip the NumPy peer from this many particles")
    args = ap.parse_args()
    sizes = [1000, 10_000] if args.quick else [1000, 10_000, 100_000]
    rounds = 3 if args.quick else 5
    grid = load_map(MAP)
    angles = np.linspace(-np.pi / 2, np.pi / 2, N_BEAMS)
    sensor = SensorInfo("laser", "laser", angles, MAX_RANGE, 0.02)
    caster = RayCaster(grid, SEES, MAX_RANGE)
    rng = np.random.default_rng(1)
    free = np.argwhere(grid.cells == 0)
    rc = free[rng.integers(len(free))]
    here = np.array([[(rc[1] + 0.5) * grid.resolution_m, (rc[0] + 0.5) * grid.resolution_m, 0.3]])
    scan = caster.cast(here, angles)[0]
    print(f"map {grid.name} {grid.shape[1]}x{grid.shape[0]} cells, {N_BEAMS} beams over 180 deg, "
          f"{MAX_RANGE:g} m; particles uniform over free space; best of {rounds}")
    print()
    print(f"| particles | method | ms / update | M particle-beams/s | vs amcl | vs NumPy |")
    print(f"| ---: | --- | ---: | ---: | ---: | ---: |")
    amcl_missing = False
    for n in sizes:
        pb = n * N_BEAMS
        res = {}
        res["teamnav beam (exact ray casting)"] = time_teamnav(grid, sensor, n, "beam", scan, rounds)
        res["teamnav likelihood field"] = time_teamnav(grid, sensor, n, "likelihood_field", scan, rounds)
        if n < args.no_numpy_at:
            init = MCL(MCLParams(n_particles=n), grid, sensor, np.random.default_rng(2))
            init.init_global()
            peer = NumpyMCL(grid, np.array(init.particles), angles, np.random.default_rng(3))
            best = math.inf
            for _ in range(max(1, rounds // 2)):
                t = time.perf_counter()
                peer.update([0.1, 0.0, 0.02], scan, (0.05,) * 4)
                best = min(best, time.perf_counter() - t)
            res["NumPy (ray marching)"] = best
        peer = make_amcl(grid, n, angles)
        if peer is None:
            amcl_missing = True
        else:
            res["nav2 AMCL (amcl 0.1.2, C++)"] = time_amcl(peer, scan, angles, rounds)
        ref_a = res.get("nav2 AMCL (amcl 0.1.2, C++)")
        ref_n = res.get("NumPy (ray marching)")
        for name, t in res.items():
            va = f"{ref_a / t:.2f}x" if ref_a else "-"
            vn = f"{ref_n / t:.1f}x" if ref_n else "-"
            print(f"| {n:,} | {name} | {t * 1e3:.2f} | {pb / t / 1e6:.2f} | {va} | {vn} |")
    if amcl_missing:
        print("\namcl is not installed in this interpreter; for the AMCL column run:\n"
              "  python -m venv /tmp/amcl-venv && /tmp/amcl-venv/bin/pip install amcl numpy numba scipy pillow "
              "pyyaml pydantic\n  /tmp/amcl-venv/bin/pip install -e . --no-deps\n"
              "  /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py")
    # density tree: build + query for 10 000 samples
    x = np.c_[rng.normal(20.0, 2.0, (10_000, 2)), rng.uniform(-np.pi, np.pi, 10_000)]
    DensityTree.fit(x[:, :2])(x[:, :2])
    best_b, best_q = math.inf, math.inf
    for _ in range(5):
        t = time.perf_counter()
        tree = DensityTree.fit(x[:, :2], min_samples=20)
        t1 = time.perf_counter()
        tree(x[:, :2])
        t2 = time.perf_counter()
        best_b, best_q = min(best_b, t1 - t), min(best_q, t2 - t1)
    print(f"\ndensity tree, 10 000 samples (x, y): build {best_b * 1e3:.2f} ms, query 10 000 points "
          f"{best_q * 1e3:.2f} ms, {tree.n_nodes} nodes, {tree.nbytes} bytes")


if __name__ == "__main__":
    main()
