"""What each detection tree does to its receiver in the paper column (Fox, Burgard, Kruppa & Thrun 2000).

Traces the ``paper_rules: true`` column of ``collab-mcl-hallway`` (§5.2.1) or ``collab-mcl-hexagon``
(§5.2.2) on tuning seeds, every detection (and its §2.3 reply, the "inverse" tree) at the moment
eq. 14 is applied. For each received tree it records, from the receiver's *full* sample set just
before and just after the update (not the 64 logged samples):

- ``err0`` / ``err1``: the weighted mean distance of the samples to the receiver's true position
  (the report's error) before / after;
- ``mass0`` / ``mass1``: the weight within 1.5 m of the true position before / after, and ``cnt0``:
  how many samples lie there before (eq. 14 can only reweight samples that exist, §3.2);
- ``serr``: the sender's error at that time (its logged samples), so the tree is "right" (< 1.5 m)
  or "wrong".

It also runs the same seed alone (same start poses) and gives, per robot, the first time its error
is below 1.5 m alone and together, and how many trees it received before it localized alone.

Tuning seeds only (>= 1000). One process, at nice 10. Usage::

    PYTHONPATH=src nice -n 10 python scripts/collab_mcl_why.py hexagon --seeds 1000-1002 --out /tmp/why-hex.jsonl
    PYTHONPATH=src nice -n 10 python scripts/collab_mcl_why.py hallway --seeds 1000 --duration 300 --out /tmp/why-hall.jsonl
    python scripts/collab_mcl_why.py summary --out /tmp/why-hex.jsonl
    PYTHONPATH=src nice -n 10 python scripts/collab_mcl_why.py modes-hexagon --seeds 1000-1002 --out /tmp/why-modes.jsonl
    PYTHONPATH=src nice -n 10 python scripts/collab_mcl_why.py modes-hallway --seeds 1000-1009 --times 1,5,10,30,60 \
        --factor sigma+beams --out /tmp/why-modes.jsonl

What was measured with it: docs/report/collab-mcl.md ("2026-11-29: why the paper column fails on the
judged seeds").
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

NEAR_M = 1.5
CAPT: list[dict] = []


def patch() -> None:
    """Wrap the brain's message handler to keep the receiver's samples before and after each tree."""
    from teamnav.papers.collab_mcl.brains import localizing as L

    orig = L.MCLWander._handle

    def wrapped(self, msg, obs):
        body = msg.body
        kind = None
        if msg.kind == L.SYNC_KIND and isinstance(body, L.SyncMessage):
            if body.kind == "detection" and body.target == self.robot_id:
                kind, sender = "detection", body.observer
            elif body.kind == "inverse" and body.observer == self.robot_id:
                kind, sender = "inverse", body.target
        if kind is None:
            return orig(self, msg, obs)
        p0 = self.mcl.particles[:, :2].astype(np.float32).copy()
        w0 = np.asarray(self.mcl.weights, dtype=float).copy()
        before = sum(self.sync.applied.values())
        out = orig(self, msg, obs)
        CAPT.append({"robot": int(self.robot_id), "t": float(obs.time_s), "kind": kind, "sender": int(sender),
                     "applied": bool(sum(self.sync.applied.values()) > before),
                     "p0": p0, "w0": w0, "p1": self.mcl.particles[:, :2].astype(np.float32).copy(),
                     "w1": np.asarray(self.mcl.weights, dtype=float).copy(),
                     "tree": body.tree if kind == "detection" else None})
        return out

    L.MCLWander._handle = wrapped


def _truth(data, robot: int, t: float) -> np.ndarray:
    rec_t = np.asarray(data.t_s, dtype=float)
    return data.true_pose[int(np.argmin(np.abs(rec_t - t))), robot]


def _stats(p: np.ndarray, w: np.ndarray, xy: np.ndarray) -> tuple[float, float, int]:
    w = w / w.sum()
    d = np.hypot(p[:, 0] - xy[0], p[:, 1] - xy[1])
    return float((w * d).sum()), float(w[d < NEAR_M].sum()), int((d < NEAR_M).sum())


def first_loc(t: np.ndarray, err: np.ndarray) -> list[float | None]:
    out = []
    for j in range(err.shape[1]):
        ok = np.where(err[:, j] < NEAR_M)[0]
        out.append(float(t[ok[0]]) if ok.size else None)
    return out


def one(part: str, seed: int, collaborate: bool, duration: float | None) -> tuple[dict, list[dict]]:
    from collab_mcl_collapse import PART_DURATION, PART_SCENARIO, overrides

    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario
    from teamnav.papers.collab_mcl.metrics import error_matrix

    CAPT.clear()
    duration = duration or PART_DURATION[part]
    t0 = time.process_time()
    res = run(load_scenario(PART_SCENARIO[part], overrides=overrides(part, "paper", collaborate), seed=seed,
                            duration_s=duration), progress=False)
    cpu = time.process_time() - t0
    t, err, kinds, _ = error_matrix(res.data)
    run_row = {"part": part, "seed": seed, "collaborate": collaborate, "duration_s": duration, "cpu_s": round(cpu, 1),
               "kinds": kinds, "t_loc": first_loc(t, err),
               "final_err": [float(e[~np.isnan(e)][-1]) for e in err.T]}
    dets = []
    for c in CAPT:
        xy = _truth(res.data, c["robot"], c["t"])[:2]
        e0, m0, n0 = _stats(c["p0"], c["w0"], xy)
        e1, m1, _ = _stats(c["p1"], c["w1"], xy)
        k = int(np.argmin(np.abs(t - c["t"])))
        tree_ratio = None
        if c["tree"] is not None:
            # eq. 14's factor at the true position over its weighted mean over the receiver's samples
            f_truth = float(c["tree"](np.asarray([xy], dtype=float))[0])
            w = c["w0"] / c["w0"].sum()
            f_mean = float((w * c["tree"](c["p0"].astype(float))).sum())
            tree_ratio = round(f_truth / f_mean, 2) if f_mean > 0 else (math.inf if f_truth > 0 else None)
        dets.append({"seed": seed, "robot": c["robot"], "t": round(c["t"], 1), "kind": c["kind"], "sender": c["sender"],
                     "applied": c["applied"], "n0": int(c["w0"].size), "err0": round(e0, 2), "err1": round(e1, 2),
                     "mass0": round(m0, 4), "mass1": round(m1, 4), "cnt0": n0, "tree_ratio": tree_ratio,
                     "serr": round(float(err[k, c["sender"]]), 2)})
    CAPT.clear()
    return run_row, dets


def modes(part: str, seed: int, duration: float, times: list[float], factor: str = "paper") -> list[dict]:
    """Alone, paper column, first ``duration`` s: per robot and time, the modes of its 64 logged
    samples (:func:`teamnav.papers.collab_mcl.metrics.belief_modes`: single linkage 1.5 m, >= 10 %)
    and the share of them within 1.5 m of the truth. ``factor``: one of
    ``collab_mcl_collapse.FACTORS`` on top of the paper column (a diagnosis, not a fill choice)."""
    from collab_mcl_collapse import PART_SCENARIO, overrides

    from teamnav.experiments.runner import run
    from teamnav.experiments.spec import load_scenario
    from teamnav.papers.collab_mcl.metrics import belief_modes

    t0 = time.process_time()
    res = run(load_scenario(PART_SCENARIO[part], overrides=overrides(part, factor, False), seed=seed,
                            duration_s=duration), progress=False)
    data = res.data
    out = []
    for r in data.logs:
        if "pts" not in r["values"]:
            continue
        tt = float(r["t_s"])
        if not any(abs(tt - x) < 0.05 for x in times):
            continue
        pts = np.asarray(r["values"]["pts"], dtype=float).reshape(-1, 2)
        xy = _truth(data, int(r["robot"]), tt)[:2]
        near = float(np.mean(np.hypot(pts[:, 0] - xy[0], pts[:, 1] - xy[1]) < NEAR_M))
        x0, y0 = (float(v) for v in data.true_pose[0, int(r["robot"])][:2])
        out.append({"type": "modes", "part": part, "factor": factor, "seed": seed, "robot": int(r["robot"]), "t": tt,
                    "start_xy": [round(x0, 2), round(y0, 2)],
                    "modes": belief_modes(pts), "near": round(near, 3), "n": r["values"]["n_particles"],
                    "cpu_s": round(time.process_time() - t0, 1)})
    return out


def summary(rows: list[dict]) -> None:
    runs = [r for r in rows if r.get("type") == "run"]
    dets = [r for r in rows if r.get("type") == "det"]
    for part in sorted({r["part"] for r in runs}):
        pr = [r for r in runs if r["part"] == part]
        cpu = sum(r["cpu_s"] for r in pr)
        print(f"== {part}: {len(pr)} runs, {cpu / 60:.1f} CPU min")
        alone = {r["seed"]: r for r in pr if not r["collaborate"]}
        team = {r["seed"]: r for r in pr if r["collaborate"]}
        for s in sorted(team):
            d = [x for x in dets if x["seed"] == s and x.get("part", part) == part]
            a = alone.get(s)
            print(f"seed {s}: kinds {team[s]['kinds']}")
            print("  t_loc alone ", a["t_loc"] if a else None)
            print("  t_loc team  ", team[s]["t_loc"])
            print("  final alone ", [round(x, 1) for x in a["final_err"]] if a else None)
            print("  final team  ", [round(x, 1) for x in team[s]["final_err"]])
            for rb in range(len(team[s]["kinds"])):
                mine = [x for x in d if x["robot"] == rb and x["applied"]]
                ta = a["t_loc"][rb] if a else None
                pre = [x for x in mine if ta is None or x["t"] < ta]
                print(f"  robot {rb} ({team[s]['kinds'][rb]}): trees {len(mine)}, first at "
                      f"{mine[0]['t'] if mine else None}; before alone-loc ({ta}): {len(pre)}")
        # classes over all trees received (applied or not: eq. 14 is skipped when the tree is 0 on
        # every sample, MCL.multiply_weights)
        allt = [x for x in dets if x.get("part", part) == part]
        n = len(allt)
        if not n:
            continue

        def cls(x):
            r = "R" if x["err0"] < NEAR_M else "W"
            s = "r" if x["serr"] < NEAR_M else "w"
            return f"receiver {r} / sender {s}"

        print(f"  trees received: {n} (detections {sum(x['kind'] == 'detection' for x in allt)}, "
              f"replies {sum(x['kind'] == 'inverse' for x in allt)}); applied {sum(x['applied'] for x in allt)}")
        und = [x for x in allt if 0.05 < x["mass0"] < 0.95]
        print(f"  receiver undecided (0.05 < weight within 1.5 m of truth < 0.95) at {len(und)} of {n} trees; "
              f"weight near truth < 0.05 at {sum(x['mass0'] <= 0.05 for x in allt)}, > 0.95 at "
              f"{sum(x['mass0'] >= 0.95 for x in allt)}")
        for c in sorted({cls(x) for x in allt}):
            g = [x for x in allt if cls(x) == c]
            ap = [x for x in g if x["applied"]]
            tr = [x["tree_ratio"] for x in g if x.get("tree_ratio") is not None and x["cnt0"] > 0]
            print(f"  {c}: {len(g)} ({len(g) / n:.0%}), applied {len(ap)}; no sample within 1.5 m of truth "
                  f"before: {sum(x['cnt0'] == 0 for x in g)}; mass near truth (applied) "
                  f"{np.mean([x['mass0'] for x in ap]) if ap else float('nan'):.3f} -> "
                  f"{np.mean([x['mass1'] for x in ap]) if ap else float('nan'):.3f}; error < 1.5 m after: "
                  f"{sum(x['err1'] < NEAR_M for x in ap)}; samples {np.median([x['n0'] for x in g]):.0f} (median); "
                  f"tree at truth / mean over samples (detections, samples near truth): "
                  f"median {np.median(tr) if tr else float('nan'):.2f} (n {len(tr)})")


def parse_seeds(text: str) -> list[int]:
    """Seeds "1000-1009,1012" (tuning seeds only): the fidelity script's parser, beside this one."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from collab_mcl_fidelity import parse_seeds as parse

    return parse(text)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("part", choices=["hallway", "hexagon", "summary", "modes-hallway", "modes-hexagon"])
    ap.add_argument("--times", default="1,2,5,10,30", help="modes-*: record times [s]")
    ap.add_argument("--factor", default="paper", help="modes-*: a factor of collab_mcl_collapse.FACTORS")
    ap.add_argument("--seeds", default="1000")
    ap.add_argument("--duration", type=float, default=None)
    ap.add_argument("--conditions", default="alone,team")
    ap.add_argument("--out", required=True)
    a = ap.parse_args(argv)
    if a.part == "summary":
        summary([json.loads(line) for line in Path(a.out).read_text().splitlines() if line.strip()])
        return 0
    if a.part.startswith("modes-"):
        times = [float(x) for x in a.times.split(",")]
        for seed in parse_seeds(a.seeds):
            rows = modes(a.part[6:], seed, a.duration or max(times) + 1, times, a.factor)
            with open(a.out, "a") as f:
                f.writelines(json.dumps(r) + "\n" for r in rows)
            for tt in times:
                g = [r for r in rows if abs(r["t"] - tt) < 0.05]
                print(f"{a.part} {a.factor} seed {seed} t {tt:.0f} s: modes {[r['modes'] for r in g]} "
                      f"share near truth {[r['near'] for r in g]} samples {[r['n'] for r in g]}", flush=True)
        return 0
    patch()
    for seed in parse_seeds(a.seeds):
        for cond in a.conditions.split(","):
            run_row, dets = one(a.part, seed, cond == "team", a.duration)
            with open(a.out, "a") as f:
                f.write(json.dumps({"type": "run", **run_row}) + "\n")
                f.writelines(json.dumps({"type": "det", "part": a.part, **d}) + "\n" for d in dets)
            print(f"{a.part} seed {seed} {cond}: cpu {run_row['cpu_s']} s, trees {len(dets)}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
