"""One MCL update (motion + perception weighting + resampling), particle-beams per second.

Contenders, on the same map, scan and particle distribution in one run:

- teamnav ``MCL``, beam model with exact ray casting (Fox et al. §2.2 Fig. 1; ``teamnav.world.raycast``);
- the same, doing what nav2 AMCL's update also does: augmented recovery (w_slow / w_fast), the
  KLD bound over a histogram (``min = max = n``, as the peer is run) and the pose estimate;
- teamnav ``MCL``, likelihood field (Probabilistic Robotics §6.4);
- a straightforward NumPy MCL (written here): Table 5.6 motion, ray marching at half a cell,
  the exact beam mixture, ``searchsorted`` low-variance resampling;
- nav2's AMCL core through the ``amcl`` package from PyPI (GPL-3.0: only in the benchmark's
  own venv, never a teamnav dependency), ``min_particles = max_particles = n``, 60 beams. Its
  binding hard-wires nav2's ``BeamModel`` (``amcl-0.1.2/src/amcl.cpp`` builds
  ``std::make_unique<BeamModel>`` in the constructor and in ``setMap``; the likelihood-field
  sources are compiled but never constructed): Bresenham ray casting per beam
  (``map_calc_range``), ``exp`` of the mixture per beam, then ``pf_update_resample`` (KLD
  histogram, random-pose injection, cluster statistics; its draw is a linear search per
  sample, hence quadratic).

Every round re-initialises every contender from the same Gaussian ``N(pose, diag(1 m, 1 m,
0.5 rad)^2)`` around the pose the scan was taken from (untimed; amcl through
``set_initial_pose``, which draws the same Gaussian, in walls and unknown space too) and then
times one update: all contenders weigh the same kind of sample set, and the best of the
rounds is kept (after an init neither teamnav nor amcl injects random samples: w_slow = w_fast). (Uniform sampling over free space is not reachable through the binding, and
amcl's own global start, a Gaussian around the map centre, puts most samples in unknown
space where its rays end at once.) Contenders take turns within a round, so they share the
machine's load. The map is handed to amcl with its origin shifted by half a cell: amcl
indexes a cell by ``round`` of the world coordinate (its cells are centred on grid
corners), teamnav by ``floor``.

Plus density-tree build + query for 10 000 samples. Usage::

    python -m venv /tmp/amcl-venv && /tmp/amcl-venv/bin/pip install amcl numpy numba scipy pillow pyyaml pydantic
    /tmp/amcl-venv/bin/pip install -e . --no-deps
    /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py            # 1k, 10k, 100k particles
    /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py --quick    # 1k, 10k
"""

from __future__ import annotations

import argparse
import math
import os
import time
from pathlib import Path

import numba
import numpy as np

from teamnav.control.protocol import SensorInfo
from teamnav.localization import MCL, DensityTree, KLDParams, MCLParams, MotionParams
from teamnav.localization.beam_model import BeamModelParams, beam_probability
from teamnav.localization.density_tree import query_kernel
from teamnav.world import load_map
from teamnav.world.distance import distance_field
from teamnav.world.grid import FREE, UNKNOWN
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
AMCL_NAME = "nav2 AMCL beam model (amcl 0.1.2, C++)"
NUMPY_NAME = "NumPy (ray marching)"


class AmclPeer:
    """nav2 AMCL through the ``amcl`` binding, fed the same map, scan and odometry steps."""

    def __init__(self, amcl, grid, n, scan_m, angles):
        self.amcl = amcl
        occ = np.where(grid.cells == FREE, 0, 100).astype(int)
        occ[grid.cells == UNKNOWN] = -1  # amcl: unknown stops its rays, as "unknown" in SEES does here
        mp = amcl.MotionParameters(alpha1=0.05, alpha2=0.05, alpha3=0.05, alpha4=0.05, alpha5=0.05)
        lp = amcl.LaserParameters(z_hit=0.8, z_short=0.1, z_max=0.05, z_rand=0.05, sigma_hit=0.1, lambda_short=0.5,
                                  chi_outlier=0.0, max_beams=N_BEAMS)
        self.loc = amcl.AMCL(n, n, 0.001, 0.1, mp, lp, "differential")
        half = 0.5 * grid.resolution_m  # amcl's cell i spans (i - 1/2, i + 1/2) cells from its origin
        ox, oy = grid.origin_xy_m
        self.loc.set_map(amcl.create_occupancy_grid_from_list(occ.tolist(), grid.resolution_m, ox + half, oy + half))
        self.loc.set_laser_pose(amcl.Vector3D(0.0, 0.0, 0.0))
        self.scan = amcl.create_laser_scan_from_list([[float(r), float(a)] for r, a in zip(scan_m, angles)], MAX_RANGE)
        self.odom = np.zeros(3)

    def reset(self, mean, std):
        a = self.amcl
        cov = a.create_diagonal_covariance(*(float(v) ** 2 for v in std))
        self.loc.set_initial_pose(a.Vector3D(*map(float, mean)), cov)

    def step(self, delta):
        # the first update after set_initial_pose takes its odometry as the reference (a zero
        # step: amcl still draws the motion noise), then weighs the scan and resamples
        c, s = math.cos(self.odom[2]), math.sin(self.odom[2])
        self.odom = self.odom + [c * delta[0] - s * delta[1], s * delta[0] + c * delta[1], delta[2]]
        self.loc.update(self.scan, self.amcl.Vector3D(*self.odom))

    def pose(self):
        m = self.loc.get_pose_mean()
        return np.array([m.x, m.y, m.theta])


# ---------------------------------------------------------------------------- teamnav contenders
class TeamnavPeer:
    def __init__(self, grid, sensor, n, model, scan, as_amcl=False):
        extra = {}
        if as_amcl:
            extra = dict(recovery="augmented", adaptive=True, kld=KLDParams(min_particles=n, max_particles=n))
        else:
            extra = dict(recovery="none")
        self.f = MCL(MCLParams(n_particles=n, sensor_model=model, motion=MotionParams(), **extra), grid, sensor,
                     np.random.default_rng(0))
        self.scan = scan
        self.as_amcl = as_amcl

    def reset(self, mean, std):
        self.f.init_pose(mean, np.diag(np.asarray(std) ** 2))

    def step(self, delta):
        f = self.f
        f.predict(delta)
        f.update(self.scan)
        f.resample()
        if self.as_amcl:
            f.estimate()


class NumpyPeer:
    def __init__(self, grid, angles, n, scan):
        self.grid, self.angles, self.n, self.scan = grid, angles, n, scan
        self.rng = np.random.default_rng(3)
        self.m = None

    def reset(self, mean, std):
        p = np.asarray(mean) + self.rng.standard_normal((self.n, 3)) * np.asarray(std)
        p[:, 2] = np.angle(np.exp(1j * p[:, 2]))
        self.m = NumpyMCL(self.grid, p, self.angles, self.rng)

    def step(self, delta):
        self.m.update(delta, self.scan, (0.05,) * 4)


# ---------------------------------------------------------------------------- runs
DELTA = np.array([0.1, 0.0, 0.02])  # odometry step of every update (previous body frame) [m, m, rad]
INIT_STD = (1.0, 1.0, 0.5)  # spread of the sample set every round starts from [m, m, rad]


def best_of_rounds(peers, mean, rounds, once=()):
    """Best wall and best CPU time of one update per contender (contenders take turns within
    a round, so they share the machine's load); those named in ``once`` run one round only."""
    wall = {k: math.inf for k in peers}
    cpu = {k: math.inf for k in peers}
    for r in range(rounds):
        for name, peer in peers.items():
            if r and name in once:
                continue
            peer.reset(mean, INIT_STD)
            c = time.process_time()
            t = time.perf_counter()
            peer.step(DELTA)
            wall[name] = min(wall[name], time.perf_counter() - t)
            cpu[name] = min(cpu[name], time.process_time() - c)
    return wall, cpu


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="1k and 10k particles only, fewer rounds")
    ap.add_argument("--sizes", type=int, nargs="+", help="particle counts (default 1000 10000 100000)")
    ap.add_argument("--rounds", type=int, help="timed rounds per size (default 7, 5 with --quick)")
    ap.add_argument("--no-numpy-at", type=int, default=100_000, help="skip the NumPy peer from this many particles")
    args = ap.parse_args()
    sizes = args.sizes or ([1000, 10_000] if args.quick else [1000, 10_000, 100_000])
    rounds = args.rounds or (5 if args.quick else 7)
    grid = load_map(MAP)
    angles = np.linspace(-np.pi / 2, np.pi / 2, N_BEAMS)
    sensor = SensorInfo("laser", "laser", angles, MAX_RANGE, 0.02)
    caster = RayCaster(grid, SEES, MAX_RANGE)
    rng = np.random.default_rng(1)
    free = np.argwhere(distance_field(grid) >= 0.5)
    rc = free[rng.integers(len(free))]
    here = np.array([(rc[1] + 0.5) * grid.resolution_m, (rc[0] + 0.5) * grid.resolution_m, 0.3])
    scan = caster.cast(here[None], angles)[0]
    try:
        import amcl
    except ImportError:
        amcl = None
    # the ray lengths the contenders meet: the samples of one round's start
    probe = MCL(MCLParams(n_particles=10_000), grid, sensor, np.random.default_rng(5))
    probe.init_pose(here, np.diag(np.asarray(INIT_STD) ** 2))
    pr = caster.cast(np.array(probe.particles), angles)
    print(f"map {grid.name} {grid.shape[1]}x{grid.shape[0]} cells, {N_BEAMS} beams over 180 deg, {MAX_RANGE:g} m; "
          f"every round starts from N(pose of the scan, diag{INIT_STD}^2) [m, m, rad]: "
          f"{(pr[:, 0] == 0).mean():.0%} of the samples in walls or unknown space, mean expected range "
          f"{pr.mean():.2f} m; one update = predict + weigh + resample; best of {rounds} rounds; "
          f"numba threads {numba.get_num_threads()}, load average {os.getloadavg()[0]:.1f}; NumPy: one round "
          f"from 10 000 samples", flush=True)
    print()
    print("| particles | method | ms / update | M particle-beams/s | vs amcl | CPU ms / update | vs amcl (CPU) "
          "| vs NumPy |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    summary = {}  # particles -> (CPU ratio, wall ratio) of the plain beam model against amcl
    for n in sizes:
        pb = n * N_BEAMS
        peers = {
            "teamnav beam (exact ray casting)": TeamnavPeer(grid, sensor, n, "beam", scan),
            "teamnav beam + KLD + augmented + estimate": TeamnavPeer(grid, sensor, n, "beam", scan, as_amcl=True),
            "teamnav likelihood field": TeamnavPeer(grid, sensor, n, "likelihood_field", scan),
        }
        if n < args.no_numpy_at:
            peers[NUMPY_NAME] = NumpyPeer(grid, angles, n, scan)
        if amcl is not None:
            peers[AMCL_NAME] = AmclPeer(amcl, grid, n, scan, angles)
        for name, peer in peers.items():  # compile, warm caches (the slow peers need no warming)
            if name not in (NUMPY_NAME, AMCL_NAME) or n <= 1000:
                peer.reset(here, INIT_STD)
                peer.step(DELTA)
        slow = (NUMPY_NAME,) if n >= 10_000 else ()
        wall, cpu = best_of_rounds(peers, here, rounds if n < 100_000 else max(3, rounds // 2), once=slow)
        ref_a, ref_ac = wall.get(AMCL_NAME), cpu.get(AMCL_NAME)
        ref_n = wall.get(NUMPY_NAME)
        for name, t in wall.items():
            va = f"{ref_a / t:.2f}x" if ref_a else "-"
            va = f"**{va}**" if ref_a and name.startswith("teamnav beam") else va
            vc = f"{ref_ac / cpu[name]:.2f}x" if ref_ac else "-"
            vn = f"{ref_n / t:.1f}x" if ref_n else "-"
            print(f"| {n:,} | {name} | {t * 1e3:.2f} | {pb / t / 1e6:.2f} | {va} | {cpu[name] * 1e3:.2f} | {vc} "
                  f"| {vn} |", flush=True)
            if ref_ac and name == "teamnav beam (exact ray casting)":
                summary[n] = (ref_ac / cpu[name], ref_a / t)
    if amcl is None:
        print("\namcl is not installed in this interpreter; for the AMCL column run:\n"
              "  python -m venv /tmp/amcl-venv && /tmp/amcl-venv/bin/pip install amcl numpy numba scipy pillow "
              "pyyaml pydantic\n  /tmp/amcl-venv/bin/pip install -e . --no-deps\n"
              "  /tmp/amcl-venv/bin/python benchmarks/bench_mcl.py")
    # density tree: build + query for 10 000 samples (the query runs the serial twin below
    # density_tree._PARALLEL_MIN_POINTS points; the threaded kernel is timed beside it)
    x = np.c_[rng.normal(20.0, 2.0, (10_000, 2)), rng.uniform(-np.pi, np.pi, 10_000)]
    xy = np.ascontiguousarray(x[:, :2])
    DensityTree.fit(xy)(xy)
    best = {"build": math.inf, "query": math.inf, "query threaded": math.inf}
    cpu_ = {k: math.inf for k in best}
    for _ in range(20):
        t, c = time.perf_counter(), time.process_time()
        tree = DensityTree.fit(xy, min_samples=20)
        t1, c1 = time.perf_counter(), time.process_time()
        tree(xy)
        t2, c2 = time.perf_counter(), time.process_time()
        query_kernel(xy, tree.lo, tree.hi, tree.circular, tree.split_dim, tree.split_val, tree.child,
                     tree.density, np.empty(len(xy)))
        t3, c3 = time.perf_counter(), time.process_time()
        for k, dw, dc in (("build", t1 - t, c1 - c), ("query", t2 - t1, c2 - c1), ("query threaded", t3 - t2, c3 - c2)):
            best[k], cpu_[k] = min(best[k], dw), min(cpu_[k], dc)
    print(f"\ndensity tree, 10 000 samples (x, y), {tree.n_nodes} nodes, {tree.nbytes} bytes; best of 20, "
          f"wall / CPU: build {best['build'] * 1e3:.2f} / {cpu_['build'] * 1e3:.2f} ms, query 10 000 points "
          f"{best['query'] * 1e3:.2f} / {cpu_['query'] * 1e3:.2f} ms (threaded kernel "
          f"{best['query threaded'] * 1e3:.2f} / {cpu_['query threaded'] * 1e3:.2f} ms)")
    # last, one line per size a script can read (1k last: the goal is >= 5x there, on one thread)
    print()
    for n in sorted(summary, key=lambda k: (k == 1000, k)):
        c, w = summary[n]
        goal = f"; goal >= 5x {'met' if c >= 5.0 else 'not met'}" if n == 1000 else ""
        print(f"MCL {n / 1000:g}k particles: teamnav / amcl = {c:.2f}x (CPU), {w:.2f}x (wall){goal}")

if __name__ == "__main__":
    main()
