"""The beam model's fill (Fox et al. §2.2, §4.1): ``beam_stride`` and ``sigma_hit_m`` by the rule of
:mod:`teamnav.papers.collab_mcl.beam_fill`, on tuning seeds, the §5.1 corridor and the hexagon.

Usage::

    nice -n 10 python scripts/collab_mcl_beam_fill.py --seeds 1000-1009 --out /tmp/beam-fill.json

Prints the table (sigma, stride, beams, mean m_s, mean m_g, mean |m_s - m_g|, admissible) and the
choice; writes every case to ``--out``. What it gave: docs/report/collab-mcl.md.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from teamnav.localization import BeamModelParams
from teamnav.papers.collab_mcl.beam_fill import Criterion, choose
from teamnav.sim.config import LaserConfig
from teamnav.sim.sensors.range_sensors import build_range_sensor
from teamnav.world.generators import builtin_map

SIGMAS = (0.05, 0.1, 0.2, 0.4, 0.8, 1.6)
STRIDES = (1, 2, 3, 5, 9, 18, 36)
#: map -> K (the column's global-localization count)
MAPS = {"lab_and_corridor": 10000, "hexagon": 8000}
BEAM = BeamModelParams(z_hit=0.7, z_short=0.1, z_max=0.1, z_rand=0.1, sigma_hit_m=0.2)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", default="1000-1009")
    ap.add_argument("--sigmas", default=",".join(map(str, SIGMAS)))
    ap.add_argument("--strides", default=",".join(map(str, STRIDES)))
    ap.add_argument("--out", default="/tmp/beam-fill.json")
    a = ap.parse_args()
    lo, _, hi = a.seeds.partition("-")
    seeds = list(range(int(lo), int(hi or lo) + 1))
    if min(seeds) < 1000:
        raise SystemExit("tuning seeds only (>= 1000)")
    sigmas = [float(s) for s in a.sigmas.split(",")]
    strides = [int(s) for s in a.strides.split(",")]
    cases, rows = [], []
    t0 = time.process_time()
    for name, k in MAPS.items():
        grid = builtin_map(name).grid
        sensor = build_range_sensor(LaserConfig(n_beams=180, fov_deg=179, max_range_m=8.0, noise_std_m=0.05), grid)
        crit = Criterion(grid, sensor, BEAM, sigmas, strides, k)
        print(f"{name}: {crit.poses.shape[0]} grid poses, cast in {time.process_time() - t0:.0f} CPU s", flush=True)
        for s in seeds:
            c = crit.case(s)
            cases.append(c)
            rows.append({"map": name, "seed": s, "pose": c.pose, "m_s": c.m_s.tolist(), "m_g": c.m_g.tolist()})
            print(f"  seed {s}: pose {np.round(c.pose, 2).tolist()} done ({time.process_time() - t0:.0f} CPU s)",
                  flush=True)
    r = choose(cases, sigmas, strides, 180)
    print("sigma  stride beams  m_s    m_g    gap   ok")
    for row in r["table"]:
        print("{:5.2f} {:6d} {:5d} {:6.3f} {:6.3f} {:6.3f} {}".format(*row))
    print({k: v for k, v in r.items() if k != "table"})
    print(f"CPU {time.process_time() - t0:.0f} s")
    with open(a.out, "w") as f:
        json.dump({"sigmas": sigmas, "strides": strides, "cases": rows, "choice": {k: v for k, v in r.items()}}, f)


if __name__ == "__main__":
    main()
