"""The paper column's set-up checks on tuning seeds (Fox, Burgard, Kruppa & Thrun; FIDELITY §1).

Three parts, each by a rule of docs/report/collab-mcl.md ("2026-11-29: rules written before the
runs"):

- ``calibrate`` (rule 2): a tracking filter's per-beam log mean likelihood, per scenario group: one
  robot of the group started at a known pose with its filter initialised there (``init_pose``),
  paper column, alone; the median of its logged ``loglik_per_beam`` over the records after 5 s
  where its error is below 0.5 m. That median is the group's ``adapt_ref_loglik_per_beam``.
- ``precondition`` (rule 3): §5.1, paper column, Robin alone; at the first record where Robin's
  true x reaches the lab door, the heaviest mode of its 64 logged samples
  (:func:`teamnav.papers.collab_mcl.metrics.heaviest_mode`).
- ``modes`` (rule 4): the hexagon, one sonar and one laser robot, alone, paper column; the modes of
  each belief at the end (:func:`teamnav.papers.collab_mcl.metrics.belief_modes`).

Tuning seeds only (>= 1000). Usage::

    nice -n 10 python scripts/collab_mcl_fidelity.py calibrate --seeds 1000-1004
    nice -n 10 python scripts/collab_mcl_fidelity.py precondition --seeds 1000-1009 --workers 2
    nice -n 10 python scripts/collab_mcl_fidelity.py modes --seeds 1000-1002

Each run is printed as one JSON line (with its CPU seconds); ``--out`` appends them to a file.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

TUNING_SEED_MIN = 1000

#: scenario group -> (scenario, group index, start pose (x, y, theta_deg) for calibration)
CALIBRATE = {
    "detection/robin": ("collab-mcl-detection", 1, (6.0, 9.6, 0.0)),
    "hexagon/sonar": ("collab-mcl-hexagon", 0, (8.5, 4.5, 90.0)),
    "hexagon/laser": ("collab-mcl-hexagon", 1, (8.5, 12.0, -90.0)),
    "hallway/sonar": ("collab-mcl-hallway", 0, (14.5, 26.5, 0.0)),
}


def parse_seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out += list(range(int(a), int(b or a) + 1))
    if min(out) < TUNING_SEED_MIN:
        raise SystemExit(f"tuning seeds only (>= {TUNING_SEED_MIN})")
    return out


def _paper_params(scen: str) -> dict[int, dict]:
    from teamnav.papers.trails.report._trails import paper_rules_spec

    return {int(k.split(".")[1]): dict(v) for k, v in paper_rules_spec(scen).set.items() if k.endswith(".params")}


def _records(data, robot: int):
    rec_t = np.asarray(data.t_s, dtype=float)
    for r in sorted((r for r in data.logs if r["robot"] == robot and "pts" in r["values"]), key=lambda r: r["t_s"]):
        j = int(np.argmin(np.abs(rec_t - float(r["t_s"]))))
        pts = np.asarray(r["values"]["pts"], dtype=float).reshape(-1, 2)
        yield float(r["t_s"]), data.true_pose[j, robot], pts, r["values"]


def calibrate_run(job) -> dict:
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario

    key, seed = job
    scen, gi, start = CALIBRATE[key]
    params = _paper_params(scen)
    groups = load_scenario(scen).robots
    ov: dict = {}
    for i, g in enumerate(groups):
        p = dict(params.get(i, g.params or {}))
        p["collaborate"] = False
        p["adapt_ref_loglik_per_beam"] = -1000.0  # inert here: the count stays at its floor
        if i == gi:
            p["init_pose"] = list(start)
            ov[f"robots.{i}.start"] = {"poses": [list(start)]}
        ov[f"robots.{i}.params"] = p
        ov[f"robots.{i}.count"] = 1
    t0 = time.process_time()
    try:
        res = run(load_scenario(scen, overrides=ov, seed=seed, duration_s=60.0), progress=False)
    except Exception as exc:  # noqa: BLE001 - reported as a row (e.g. a random start on the fixed one)
        return {"part": "calibrate", "group": key, "seed": seed, "n": 0, "median_loglik_per_beam": None,
                "error": str(exc)[:300], "cpu_s": round(time.process_time() - t0, 1)}
    vals = []
    for t, truth, pts, v in _records(res.data, gi):
        err = float(np.mean(np.hypot(pts[:, 0] - truth[0], pts[:, 1] - truth[1])))
        if t >= 5.0 and err < 0.5 and v.get("loglik_per_beam") is not None:
            vals.append(v["loglik_per_beam"])
    return {"part": "calibrate", "group": key, "seed": seed, "n": len(vals),
            "median_loglik_per_beam": float(np.median(vals)) if vals else None,
            "cpu_s": round(time.process_time() - t0, 1)}


def _with_update(ov: dict, update: tuple[float, float] | None) -> dict:
    """Every group's filter updates every ``update`` = (metres, degrees) of motion (rule 11's set-up
    fix; the scenarios' 0.2 m / 15 deg otherwise)."""
    if update is not None:
        for k in [k for k in ov if k.endswith(".params")]:
            ov[k] = {**ov[k], "min_update_m": update[0], "min_update_deg": update[1]}
    return ov


def precondition_run(seed: int, robin_min: int | None = None, update: tuple[float, float] | None = None) -> dict:
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario
    from teamnav.papers.collab_mcl.maps import LAB_DOOR_X
    from teamnav.papers.collab_mcl.metrics import heaviest_mode

    scen = "collab-mcl-detection"
    params = _paper_params(scen)
    ov = {f"robots.{i}.params": {**p, "collaborate": False} if i == 1 else p for i, p in params.items()}
    if robin_min is not None:
        ov["robots.1.params"]["min_particles"] = robin_min
    ov = _with_update(ov, update)
    t0 = time.process_time()
    res = run(load_scenario(scen, overrides=ov, seed=seed, duration_s=110.0), progress=False)
    out = {"part": "precondition", "seed": seed, "robin_min": robin_min, "update": update, "t_s": None,
           "heaviest_mode": None, "error_m": None}
    for t, truth, pts, v in _records(res.data, 1):
        if truth[0] >= LAB_DOOR_X:
            out.update({"t_s": t, "heaviest_mode": heaviest_mode(pts), "n_particles": v.get("n_particles"),
                        "error_m": float(np.mean(np.hypot(pts[:, 0] - truth[0], pts[:, 1] - truth[1])))})
            break
    out["cpu_s"] = round(time.process_time() - t0, 1)
    return out


def modes_run(seed: int, column: str = "paper", update: tuple[float, float] | None = None) -> dict:
    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario
    from teamnav.papers.collab_mcl.metrics import belief_modes

    scen = "collab-mcl-hexagon"
    params = _paper_params(scen) if column == "paper" else {
        i: dict(g.params or {}) for i, g in enumerate(load_scenario(scen).robots)}
    ov = {}
    for i, p in params.items():
        ov[f"robots.{i}.params"] = {**p, "collaborate": False}
        ov[f"robots.{i}.count"] = 1
    ov = _with_update(ov, update)
    t0 = time.process_time()
    res = run(load_scenario(scen, overrides=ov, seed=seed, duration_s=200.0), progress=False)
    out = {"part": "modes", "column": column, "seed": seed, "update": update}
    for robot, kind in ((0, "sonar"), (1, "laser")):
        recs = list(_records(res.data, robot))
        t, truth, pts, v = recs[-1]
        out[kind] = belief_modes(pts)
        out[f"{kind}_n_particles"] = v.get("n_particles")
    out["cpu_s"] = round(time.process_time() - t0, 1)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("part", choices=["calibrate", "precondition", "modes"])
    ap.add_argument("--seeds", default="1000-1004")
    ap.add_argument("--groups", default=",".join(CALIBRATE))
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--column", choices=["paper", "teamnav"], default="paper", help="modes: which column")
    ap.add_argument("--robin-min", type=int, default=None, help="precondition: Robin's min_particles (rule 6)")
    def _interval(text: str) -> tuple[float, float]:
        try:
            m, deg = (float(x) for x in text.split(","))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected 'METRES,DEGREES' (e.g. 1.0,45), got {text!r}") from None
        if not (m > 0 and deg > 0):
            raise argparse.ArgumentTypeError(f"expected two numbers > 0, got {text!r}")
        return m, deg

    ap.add_argument("--update", type=_interval, default=None, help="precondition / modes: 'M,DEG', every group's filter update "
                                                    "interval (rule 11); default the scenarios' 0.2 m / 15 deg")
    ap.add_argument("--out", default=None)
    a = ap.parse_args(argv)
    update = a.update
    seeds = parse_seeds(a.seeds)
    if a.part == "calibrate":
        fn, jobs = calibrate_run, [(g, s) for g in a.groups.split(",") for s in seeds]
    else:
        import functools

        fn = (functools.partial(precondition_run, robin_min=a.robin_min, update=update) if a.part == "precondition"
              else functools.partial(modes_run, column=a.column, update=update))
        jobs = seeds
    t0 = time.time()
    rows = []
    with ProcessPoolExecutor(a.workers) if a.workers > 1 else _Serial() as ex:
        for row in ex.map(fn, jobs):
            rows.append(row)
            print(json.dumps(row), flush=True)
            if a.out:
                with open(a.out, "a") as f:
                    f.write(json.dumps(row) + "\n")
    if a.part == "calibrate":
        for g in a.groups.split(","):
            v = [r["median_loglik_per_beam"] for r in rows if r["group"] == g and r["median_loglik_per_beam"] is not None]
            print(f"{g}: median over {len(v)} seeds {np.median(v) if v else float('nan'):.4f} (per seed {v})")
    elif a.part == "precondition":
        hm = [r["heaviest_mode"] for r in rows]
        ok = sum(1 for h in hm if h is not None and h <= 0.5)
        print(f"heaviest mode at the lab door: {hm}; <= 0.5 in {ok} of {len(hm)} runs: "
              f"{'holds' if ok >= math.ceil(0.8 * len(hm)) else 'does not hold'}")
    print(f"CPU {sum(r['cpu_s'] for r in rows):.0f} s, wall {time.time() - t0:.0f} s", file=sys.stderr)
    return 0


class _Serial:
    def __enter__(self):
        return self

    def __exit__(self, *a):
        return False

    def map(self, fn, jobs):
        return map(fn, jobs)


if __name__ == "__main__":
    raise SystemExit(main())
