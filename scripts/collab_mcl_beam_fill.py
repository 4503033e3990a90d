"""The beam model's fill (Fox et al. §2.2, §4.1, §5.2): ``beam_stride`` and ``sigma_hit_m`` by the rule
of :mod:`teamnav.papers.collab_mcl.beam_fill`, on tuning seeds: the laser on the §5.1 corridor and
the hexagon (rule 1), the sonar on the symmetric hallway and the hexagon (rule 8).

Usage::

    nice -n 10 python scripts/collab_mcl_beam_fill.py --seeds 1000-1009 --out /tmp/beam-fill.json
    nice -n 10 python scripts/collab_mcl_beam_fill.py --sensor sonar --seeds 1000-1009 --out /tmp/sonar-fill.json

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
from teamnav.sim.config import LaserConfig, SonarConfig
from teamnav.sim.sensors.range_sensors import build_range_sensor
from teamnav.world.generators import builtin_map

BEAM = BeamModelParams(z_hit=0.7, z_short=0.1, z_max=0.1, z_rand=0.1, sigma_hit_m=0.2)
#: per sensor: the written candidates, map -> K (the column's global-localization count), the
#: simulated sensor (the scenarios' own), the filter's cone (degrees, rays; the brain's defaults)
SENSORS = {
    "laser": {"sigmas": (0.05, 0.1, 0.2, 0.4, 0.8, 1.6), "strides": (1, 2, 3, 5, 9, 18, 36),
              "maps": {"lab_and_corridor": 10000, "hexagon": 8000},
              "config": LaserConfig(n_beams=180, fov_deg=179, max_range_m=8.0, noise_std_m=0.05),
              "cone": (0.0, 1)},
    "sonar": {"sigmas": (0.1, 0.2, 0.3, 0.5, 0.8, 1.2, 2.0), "strides": (1, 2, 4, 8),
              "maps": {"symmetric_hallway": 10000, "hexagon": 8000},
              "config": SonarConfig(n_transducers=16, fov_deg=360, cone_deg=15, rays_per_cone=5,
                                    max_range_m=5.0, noise_std_m=0.05, p_specular=0.02),
              "cone": (15.0, 3)},
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--sensor", choices=sorted(SENSORS), default="laser")
    ap.add_argument("--seeds", default="1000-1009")
    ap.add_argument("--sigmas", default=None, help="comma-separated; default: the sensor's written grid")
    ap.add_argument("--strides", default=None, help="comma-separated; default: the sensor's written grid")
    ap.add_argument("--out", default="/tmp/beam-fill.json")
    a = ap.parse_args()
    spec = SENSORS[a.sensor]
    lo, _, hi = a.seeds.partition("-")
    seeds = list(range(int(lo), int(hi or lo) + 1))
    if min(seeds) < 1000:
        raise SystemExit("tuning seeds only (>= 1000)")
    sigmas = [float(s) for s in a.sigmas.split(",")] if a.sigmas else list(spec["sigmas"])
    strides = [int(s) for s in a.strides.split(",")] if a.strides else list(spec["strides"])
    cases, rows = [], []
    t0 = time.process_time()
    for name, k in spec["maps"].items():
        grid = builtin_map(name).grid
        sensor = build_range_sensor(spec["config"], grid)
        cone_deg, rays = spec["cone"]
        crit = Criterion(grid, sensor, BEAM, sigmas, strides, k, cone_deg=cone_deg, rays_per_cone=rays)
        print(f"{name}: {crit.poses.shape[0]} grid poses, cast in {time.process_time() - t0:.0f} CPU s", flush=True)
        for s in seeds:
            c = crit.case(s)
            cases.append(c)
            rows.append({"map": name, "seed": s, "pose": c.pose, "m_s": c.m_s.tolist(), "m_g": c.m_g.tolist()})
            print(f"  seed {s}: pose {np.round(c.pose, 2).tolist()} done ({time.process_time() - t0:.0f} CPU s)",
                  flush=True)
    r = choose(cases, sigmas, strides, sensor.angles_rad.shape[0])
    print("sigma  stride beams  m_s    m_g    gap   ok")
    for row in r["table"]:
        print("{:5.2f} {:6d} {:5d} {:6.3f} {:6.3f} {:6.3f} {}".format(*row))
    print({k: v for k, v in r.items() if k != "table"})
    print(f"CPU {time.process_time() - t0:.0f} s")
    with open(a.out, "w") as f:
        json.dump({"sensor": a.sensor, "sigmas": sigmas, "strides": strides, "cases": rows, "choice": {k: v for k, v in r.items()}}, f)


if __name__ == "__main__":
    main()
