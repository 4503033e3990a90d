"""CPU per step of the line-of-sight help runs, this tree against an older one, in one session.

Sgorbissa & Arkin's Tables 1–2 (``los-table1`` / ``los-table2``) are 2 maps × 3 algorithms ×
8 teams × 5 tasks of up to 200 targets; their CPU is the CPU per simulated step of
``los-help-simple`` / ``los-help-complex`` times the steps. This script measures that, per
configuration (map × algorithm case of ``los-table1.yaml`` × R1 alone / R1..R4), for two
source trees: this one and a *base* (by default the branch base f9d6cb5, unpacked with
``git archive`` into a temporary folder). Each measurement runs in a fresh process with
``PYTHONPATH=<tree>/src`` (one numba thread), after a warm-up run that loads the numba
kernels; base and new alternate, ``--repeats`` times each, so that both see the same load. It
prints, per configuration, the median CPU [ms] per step, the brains' share of it (inside the
brains' ``step`` and ``log``), and the ratio base / new.

Usage::

    python benchmarks/bench_los_brains.py                        # 12 configurations, ~5 min CPU
    python benchmarks/bench_los_brains.py --quick                # 1 repeat, 600 steps
    python benchmarks/bench_los_brains.py --only simple/visbug21 --steps 3000
    python benchmarks/bench_los_brains.py --base-src /path/to/old/src
    python benchmarks/bench_los_brains.py --targets 10 --repeats 1   # CPU of a 10-target task
    python benchmarks/bench_los_brains.py --kernels                  # each fast path vs its numpy version
    python benchmarks/bench_los_brains.py --paper-rules --only visbug21   # the paper-as-written column
    python benchmarks/bench_los_brains.py --team-step --base-commit 37d70e6   # 4-robot team steps, both columns
    python benchmarks/bench_los_brains.py --group-brains             # compiled group brains vs the reference
    python benchmarks/bench_los_brains.py --scaling --quick          # only the scaling row, teams of 4-64

``--team-step``: CPU seconds per 1000 team steps of R1..R4 on office_simple (R1 on tuning task
1001, Table 1's helpers' routes), for each column (teamnav, paper as written) and navigator
of R1 (potential field, Avoid-Past, VisBug-21), base and this tree alternating ``--repeats``
rounds (medians; first one untimed run per tree, which fills numba's cache); each run's
outputs (true and odometry poses, every brain's log, events, radio totals) are hashed, and a
configuration whose hashes differ between the trees says so.
It prints, last, one line per configuration and one for their median, in the form
``LOS team step, 4 robots (teamnav, potential_field): base / this tree = 1.05x``.

``--group-brains``: CPU per team step of the compiled group brains (``Simulation(...,
group_brains=True)``, ``docs/concepts/group-brains.md``) against the Python reference brains, in
this tree, for every team the group brains compile so far: R1 alone (Tables 1-2's first row)
on office_simple, tuning task 1001, each column (teamnav, paper as written) and navigator
(potential field, Avoid-Past, VisBug-21), and R1..R4 as in Tables 1-2, the whole team compiled
(``team/visbug21``, ``team/potential_field``, ``team/avoid_past``; ``--only paper/visbug21`` keeps
the configurations whose ``COLUMN/NAVIGATOR`` holds one of the strings). Reference and compiled alternate ``--repeats`` rounds, each run
in a fresh process after an untimed warm-up; each run's outputs are hashed as ``--team-step``
does, and a configuration whose runs differ says DIFFER. It prints, last, one line per
configuration and then one per team size, in the form
``LOS team step, 1 robots: compiled / reference = 1.4x`` (reference CPU over compiled CPU,
median of the configurations); a team in which a robot ran its reference brain inside the
group brain gets a line ``4 robots (helpers compiled, R1 reference)``, not the issue's
``4 robots:``. ``--quick`` ends with these lines too (1000 steps, one round).
The scaling row (last in ``--group-brains`` and ``--quick``, alone with ``--scaling``; sizes with
``--sizes``): R1 and n - 1 helpers, n = 4, 8, 16, 32, 64, on ``office_simple_grid`` (21 wings, each
Fig. 11's office; helpers three per wing on R2..R4's routes; ``teamnav.papers.los_help.scaling``), R1
on VisBug-21 on tuning task 1001, reference and compiled brains alternating, each run in a fresh
process, timed after 100 untimed steps of the same run (the set-up of 64 start regions is not a
team step, and numba compiles VisBug-21's object-mode call in each process on first use); the end
states (poses, logs, radio totals) are hashed, and a row whose runs differ says DIFFER. The teamnav column (``--quick``:
300 steps, one round, about 35 CPU-s) or both columns (otherwise: ``--steps``, ``--repeats``; 1000
steps x 3 rounds cost about 5 CPU-min). Its lines come after the
4-robot line, one per team size, ``LOS team step, 8 robots: compiled / reference = 2.2x`` (whole
step; the table gives the brains' share too); its own 4-robot size is named ``4 robots
(office_simple_grid)``, so that the issue's 4-robot line stays the Tables' team on office_simple.
``--group-brains --group-tasks 1001,1002``: whole tasks instead (200 targets, the scenario's
own budget per target, ``stop_when_finished``), reference then compiled in one process per
task, saying whether every output, the run's metrics and the steps per target are the same
(``--only`` as above).

``--targets N``: instead of a fixed number of steps, each run is the first N targets of task 1
(the scenario's own step budget per target and ``stop_when_finished``), and the table gives
the CPU seconds of the whole task (the run, not the process start) and its steps: the unit of
FULL_CPU_NOTE in ``teamnav/papers/los_help/report/section.py``.

Otherwise the runs are those of the Tables (``record_every`` 10, no step budget reached: the targets'
step budget is lifted so a potential field trapped alone keeps running for the whole time).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
sys.path.insert(0, str(HERE))
from _common import timed_run  # noqa: E402  (benchmarks/_common.py)
from los_fingerprint import CASES, MAPS, TEAMS  # noqa: E402  (the same 12 configurations)

BASE_COMMIT = "f9d6cb5"


def _overrides(case: str, team: str, map_key: str = "", targets: int = 0) -> dict:
    ov = dict(CASES[case])
    if os.environ.get("TEAMNAV_BENCH_PAPER_RULES") == "1":  # --paper-rules: the paper-as-written column
        from los_fingerprint import _paper_rules_set

        ov = {**_paper_rules_set(map_key), **ov}
    for k in (1, 2, 3):
        ov[f"robots.{k}.count"] = TEAMS[team]
    if targets:
        from teamnav import load_scenario

        task = load_scenario(MAPS[map_key]).robots[0].params["targets_xy"]
        ov["robots.0.params.targets_xy"] = [list(t) for t in task[:targets]]
    else:
        ov["robots.0.params.max_steps_per_target"] = 100_000_000
    return ov


def _worker(map_key: str, case: str, team: str, steps: int, targets: int = 0) -> dict:
    """(in the measuring process) CPU of one warm run: total and inside the brains."""
    from teamnav import load_scenario
    from teamnav.experiments.runner import run

    ov = _overrides(case, team, map_key, targets)
    run(load_scenario(MAPS[map_key], overrides=ov, duration_s=40.0, seed=0), progress=False)  # warm-up: kernels loaded
    if targets:
        scn = load_scenario(MAPS[map_key], overrides=ov, seed=0)  # its own duration: stops when R1 is done
    else:
        scn = load_scenario(MAPS[map_key], overrides=ov, duration_s=steps * 0.1, seed=0)
    total, brain_s, res = timed_run(scn, ("step", "log"))
    import teamnav

    brain = res.sim.brains[0]
    brain = brain[0] if isinstance(brain, list) else brain
    return {"cpu_s": total, "brain_s": brain_s, "steps": int(res.sim.step_index), "tree": teamnav.__file__,
            "reached": int(getattr(brain, "targets_reached", -1))}


def _measure(src: Path, key: str, steps: int, targets: int = 0) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_NUM_THREADS="1")
    map_key, case, team = key.split("/")
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker", map_key, case, team, str(steps),
                          str(targets)], env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _base_src(commit: str) -> Path:
    dest = Path(tempfile.gettempdir()) / f"teamnav-base-{commit}"
    if not (dest / "src" / "teamnav").is_dir():
        dest.mkdir(parents=True, exist_ok=True)
        arch = subprocess.run(["git", "-C", str(REPO), "archive", commit, "src"], check=True, capture_output=True)
        subprocess.run(["tar", "-x", "-C", str(dest)], input=arch.stdout, check=True)
    return dest / "src"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--worker", nargs=5, metavar=("MAP", "CASE", "TEAM", "STEPS", "TARGETS"), help=argparse.SUPPRESS)
    ap.add_argument("--team-worker", nargs=3, metavar=("CASE", "PAPER", "STEPS"), help=argparse.SUPPRESS)
    ap.add_argument("--group-worker", nargs=4, metavar=("NAV", "PAPER", "COMPILED", "STEPS"), help=argparse.SUPPRESS)
    ap.add_argument("--group-brains", action="store_true",
                    help="CPU per team step, compiled group brains vs the Python reference (this tree)")
    ap.add_argument("--group-tasks", help="with --group-brains: whole tuning tasks (comma-separated), identity "
                                          "of outputs and metrics, reference vs compiled")
    ap.add_argument("--group-task-worker", nargs=3, metavar=("NAV", "PAPER", "TASK"), help=argparse.SUPPRESS)
    ap.add_argument("--scale-worker", nargs=4, metavar=("N", "PAPER", "COMPILED", "STEPS"), help=argparse.SUPPRESS)
    ap.add_argument("--scaling", action="store_true",
                    help="only the scaling row: teams of 4-64 on office_simple_grid, compiled vs reference")
    ap.add_argument("--sizes", default=",".join(str(n) for n in SCALE_SIZES),
                    help="team sizes of the scaling row (comma-separated; default %(default)s)")
    ap.add_argument("--team-step", action="store_true",
                    help="CPU per 1000 team steps at 4 robots, both columns x 3 navigators, base vs this tree")
    ap.add_argument("--targets", type=int, default=0, help="time whole tasks of the first N targets of task 1")
    ap.add_argument("--kernels", action="store_true", help="time each fast path against its numpy version")
    ap.add_argument("--steps", type=int, default=2000, help="simulated steps per timed run (default 2000)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="one repeat of 600 steps")
    ap.add_argument("--only", action="append", help="substring filter on MAP/CASE/TEAM (repeatable: any)")
    ap.add_argument("--base-src", help=f"the older tree's src folder (default: git archive {BASE_COMMIT})")
    ap.add_argument("--base-commit", default=BASE_COMMIT)
    ap.add_argument("--new-src", help="the newer tree's src folder (default: this checkout's)")
    ap.add_argument("--paper-rules", action="store_true",
                    help="both brains at paper_rules: true (the report's paper-as-written column)")
    args = ap.parse_args(argv)
    if args.paper_rules:
        os.environ["TEAMNAV_BENCH_PAPER_RULES"] = "1"  # read by the measuring processes
    if args.worker:
        m, c, t, n, k = args.worker
        print(json.dumps(_worker(m, c, t, int(n), int(k))))
        return
    if args.team_worker:
        c, paper, n = args.team_worker
        print(json.dumps(_team_worker(c, paper == "1", int(n))))
        return
    if args.group_worker:
        nav, paper, compiled, n = args.group_worker
        print(json.dumps(_group_worker(nav, paper == "1", compiled == "1", int(n))))
        return
    if args.kernels:
        _kernels()
        return
    if args.scale_worker:
        n, paper, compiled, k = args.scale_worker
        print(json.dumps(_scale_worker(int(n), paper == "1", compiled == "1", int(k))))
        return
    sizes = tuple(int(v) for v in args.sizes.split(","))
    if args.scaling:
        lines = _scaling(sizes, SCALE_QUICK_STEPS if args.quick else args.steps,
                         1 if args.quick else max(1, args.repeats), (False,) if args.quick else (False, True))
        print("\n".join(lines))
        return
    if args.group_task_worker:
        nav, paper, task = args.group_task_worker
        print(json.dumps(_group_task_worker(nav, paper == "1", int(task))))
        return
    if args.group_brains and args.group_tasks:
        return _group_tasks([int(t) for t in args.group_tasks.split(",")], args.only)
    if args.group_brains:
        return _group_brains(1000 if args.quick else args.steps, 1 if args.quick else max(1, args.repeats),
                             args.only, sizes, args.quick)
    steps = 600 if args.quick else args.steps
    repeats = 1 if args.quick else max(1, args.repeats)
    base = Path(args.base_src) if args.base_src else _base_src(args.base_commit)
    new = Path(args.new_src) if args.new_src else REPO / "src"
    if args.team_step:
        return _team_steps(base, new, 1000 if args.quick else args.steps, 1 if args.quick else max(1, args.repeats),
                           args.base_src or args.base_commit, args.only)
    what = f"tasks of {args.targets} targets" if args.targets else f"{steps} steps per run"
    print(f"base {base}\nnew  {new}\n{what}, {repeats} repeat(s), load {os.getloadavg()[0]:.1f}")
    if args.targets:
        return _tasks(base, new, args, repeats)
    print(f"{'configuration':26s} {'base ms/step':>12s} {'(brains)':>9s} {'new ms/step':>12s} {'(brains)':>9s} "
          f"{'ratio':>6s} {'brains':>7s}")
    ratios = []
    for key in ("/".join(k) for k in itertools.product(MAPS, CASES, TEAMS)):
        if args.only and not any(s in key for s in args.only):
            continue
        b, n = [], []
        for _ in range(repeats):  # alternate: both trees see the same load
            b.append(_measure(base, key, steps))
            n.append(_measure(new, key, steps))
        if b[0]["steps"] != n[0]["steps"]:
            print(f"{key}: steps differ ({b[0]['steps']} vs {n[0]['steps']})", file=sys.stderr)
        bt = statistics.median(r["cpu_s"] / r["steps"] for r in b)
        bb = statistics.median(r["brain_s"] / r["steps"] for r in b)
        nt = statistics.median(r["cpu_s"] / r["steps"] for r in n)
        nb = statistics.median(r["brain_s"] / r["steps"] for r in n)
        ratios.append(bt / nt)
        print(f"{key:26s} {1000 * bt:12.3f} {1000 * bb:9.3f} {1000 * nt:12.3f} {1000 * nb:9.3f} "
              f"{bt / nt:6.2f} {bb / nb:7.2f}", flush=True)
    if ratios:
        print(f"ratio base/new per step: min {min(ratios):.2f}, median {statistics.median(ratios):.2f}, "
              f"max {max(ratios):.2f} (CPU time.process_time, one numba thread)")
    if args.quick and not args.only:
        _group_brains(1000, 1, None, sizes, True)  # last: the compiled group brains' lines per team size


def _kernels() -> None:
    """µs per call of each fast path and of the numpy version it replaced (kept as ``_*_numpy``
    or, for code that was inline, written out in ``tests/test_los_speed_equivalence.py``), on a
    72-beam scan in an office corridor (this process, this tree)."""
    import math

    import numpy as np

    sys.path.insert(0, str(REPO / "tests"))
    import test_los_speed_equivalence as eq

    from teamnav.papers.los_help.brains.goal_sharing import beam_near_reaches, point_visible
    from teamnav.control.nav.local import base
    from teamnav.control.nav.local.potential_field import PotentialFieldParams, _field_vector_numpy, field_vector
    from teamnav.control.nav.local.visbug21 import VisBug21, VisBugParams, boundary_heading
    from teamnav.control.types import RangeScan

    angles = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    # a corridor 2 m wide along x, open ends beyond 8 m
    with np.errstate(divide="ignore"):
        r = np.minimum(np.abs(1.0 / np.sin(angles)), 8.0)
    scan = RangeScan(r, angles, 8.0)
    pose = np.array([0.3, 0.1, 0.2])
    pts = base.scan_points(pose, scan)
    xy = pose[:2].copy()
    ends = xy + np.column_stack((np.linspace(0.5, 6, 60), np.linspace(-1, 1, 60)))
    params = PotentialFieldParams()
    nav_new = VisBug21(VisBugParams(), np.random.default_rng(0), 0.2, 0.2)
    nav_old = VisBug21(VisBugParams(), np.random.default_rng(0), 0.2, 0.2)
    a64 = np.ascontiguousarray(angles)
    pairs = {
        "point_visible (brain._sees)": (lambda: point_visible((3.0, 0.5), r, angles, 8.0, 0.0, 0.1),
                                        lambda: eq._point_visible_numpy((3.0, 0.5), r, angles, 8.0, 0.0, 0.1)),
        "keep view (brain._keeps)": (lambda: beam_near_reaches(r, a64, 3.0, 0.2, 0.13),
                                     lambda: eq._keeps_numpy(scan, 3.0, 0.6, 0.087, 8.0)),
        "corridor (brain._corridor_clear)": (lambda: base.corridor_clear(r, a64, 8.0, 0.2, 0.1, 3.0, 0.21),
                                             lambda: eq._corridor_clear_numpy(scan, 0.2, 0.1, 3.0, 0.2)),
        "scan_points": (lambda: base.scan_points(pose, scan), lambda: base._scan_points_numpy(pose, scan)),
        "segment_clearance (60 segments)": (lambda: base.segment_clearance(pts, xy, ends),
                                            lambda: base._segment_clearance_numpy(pts, xy, ends)),
        "safe_heading (blocked ahead)": (lambda: base.safe_heading(1.5, xy, pts, 0.2, 0.9),
                                         lambda: base._safe_heading_numpy(1.5, xy, pts, 0.2, 0.9)),
        "field_vector": (lambda: field_vector(pose, np.array([5.0, 0.0]), pts, 72, params, 0.2),
                         lambda: _field_vector_numpy(pose, np.array([5.0, 0.0]), pts, 72, params, 0.2)),
        "VisBug _followed (+ ends)": (lambda: nav_new._followed(pose, scan), lambda: nav_old._followed_numpy(pose, scan)),
        "VisBug boundary_heading": (lambda: boundary_heading(xy, pts, 0.33, 1, 1.5),
                                    lambda: eq._boundary_heading_numpy(xy, pts, 0.33, 1, 1.5)),
    }
    pairs.update(_leave_pair(pose, scan, pts))
    pairs.update(_radio_pairs())
    print(f"{'fast path':34s} {'new us':>8s} {'numpy us':>9s} {'ratio':>6s}")
    for name, (new, old) in pairs.items():
        new(), old()  # compiled / loaded
        times = []
        for f in (new, old):
            n = 2000
            t0 = time.process_time()
            for _ in range(n):
                f()
            times.append(1e6 * (time.process_time() - t0) / n)
        print(f"{name:34s} {times[0]:8.1f} {times[1]:9.1f} {times[1] / times[0]:6.1f}", flush=True)


def _leave_pair(pose, scan, pts) -> dict:
    """VisBug-21's leave test (kernel) against its numpy version, following the
    corridor's wall with the goal 6 m ahead (every sample closer than d_H tested)."""
    import math

    import numpy as np

    from teamnav.control.nav.local.visbug21 import MODE_FOLLOW, VisBug21, VisBugParams

    navs = []
    for _ in range(2):
        nav = VisBug21(VisBugParams(), np.random.default_rng(0), 0.2, 0.2)
        nav.goal_xy = np.array([6.3, 0.6])
        nav.mline = (np.array([-3.0, 0.6]), nav.goal_xy.copy())
        nav.mode, nav.hit_dist_m, nav._slack = MODE_FOLLOW, 9.0, math.pi / 72
        navs.append(nav)
    return {"VisBug _leave_point": (lambda: navs[0]._leave_point(pose, scan, pts, 0.28, 7.75),
                                    lambda: navs[1]._leave_point_numpy(pose, scan, pts, 0.28, 7.75))}


def _radio_pairs() -> dict:
    """H7a-2: a los-help message's size (per-type sizers vs the generic walk) and one step of
    a 4-robot line-of-sight radio (kernel vs numpy; send + collect vs the numpy version written
    out in ``tests/test_radio_speed.py``)."""
    import numpy as np

    import test_radio_speed as rs

    from teamnav.papers.los_help.brains.messages import GoalShare, LosHelpMsg, Sighting, VisReport
    from teamnav.control.types import Message, _payload_size_bytes_generic, payload_size_bytes
    from teamnav.sim.config import RadioConfig
    from teamnav.sim.radio import Radio

    body = LosHelpMsg(812, tuple(Sighting(j, 0.1 * j, 2.0 + j) for j in range(3)),
                      tuple(GoalShare(j, 40 * j, 1.5, -2.0) for j in range(4)),
                      tuple(VisReport(j, 40 * j, 3.0, 1.0, 0.5, 2.0) for j in range(4)), False)
    radio = Radio(RadioConfig(mode="line_of_sight", range_m=1e9), rs._grid(1), 4, np.random.default_rng(0))
    ref = rs._Reference(radio, 4, 0.0, 0)
    xs, ys = np.array([0.5, 1.0, 2.5, 4.0]), np.array([1.0, 3.0, 2.0, 1.5])
    out = [(i, Message(i, 0.0, body, kind="los_help")) for i in range(4)]
    senders = np.arange(4)

    def new_radio():
        radio.send(out, xs, ys)
        radio.collect()

    def old_radio():
        ref.send(out, xs, ys)
        ref.collect()

    return {
        "size_bytes (los-help message)": (lambda: payload_size_bytes(body), lambda: _payload_size_bytes_generic(body)),
        "Radio._receivers_of (4 of 4)": (lambda: radio._receivers_of([0, 1, 2, 3], xs, ys),
                                         lambda: radio._receivers_of_numpy(senders, xs, ys)),
        "Radio send+collect (4 messages)": (new_radio, old_radio),
    }


def _tasks(base: Path, new: Path, args, repeats: int) -> None:
    """CPU seconds of whole tasks (``--targets``), base and new alternating."""
    print(f"{'configuration':26s} {'steps':>6s} {'reached':>7s} {'base CPU s':>10s} {'new CPU s':>10s} {'ratio':>6s}")
    for key in ("/".join(k) for k in itertools.product(MAPS, CASES, TEAMS)):
        if args.only and not any(s in key for s in args.only):
            continue
        b, n = [], []
        for _ in range(repeats):
            b.append(_measure(base, key, 0, args.targets))
            n.append(_measure(new, key, 0, args.targets))
        if (b[0]["steps"], b[0]["reached"]) != (n[0]["steps"], n[0]["reached"]):
            print(f"{key}: runs differ: base {b[0]['steps']} steps {b[0]['reached']} reached, new "
                  f"{n[0]['steps']} / {n[0]['reached']}", file=sys.stderr)
        bt = statistics.median(r["cpu_s"] for r in b)
        nt = statistics.median(r["cpu_s"] for r in n)
        print(f"{key:26s} {n[0]['steps']:6d} {n[0]['reached']:7d} {bt:10.2f} {nt:10.2f} {bt / nt:6.2f}", flush=True)


#: navigator of R1 per case of ``los-table1.yaml`` (the keys of :data:`CASES`)
TEAM_NAVIGATORS = {"pot-field": "potential_field", "avoid-past": "avoid_past", "visbug21": "visbug21"}
#: tuning task (FIDELITY: line-of-sight tuning tasks are >= 1001; the judged ones are never timed here)
TEAM_TASK = 1001


def _team_worker(case: str, paper: bool, steps: int) -> dict:
    """(in the measuring process) CPU of ``steps`` warm team steps of R1..R4 on office_simple and a
    digest of everything the run put out."""
    import hashlib

    import numpy as np

    from los_fingerprint import _default, _paper_rules_set
    from teamnav import load_scenario
    from teamnav.papers.los_help.tasks import task_targets_xy

    ov = {**(_paper_rules_set("simple") if paper else {}), **CASES[case]}
    for k in (1, 2, 3):
        ov[f"robots.{k}.count"] = 1
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", TEAM_TASK)
    ov["robots.0.params.max_steps_per_target"] = 100_000_000
    from teamnav.experiments.runner import run

    run(load_scenario(MAPS["simple"], overrides=ov, duration_s=20.0, seed=0), progress=False)  # warm-up
    total, brain_s, res = timed_run(load_scenario(MAPS["simple"], overrides=ov, duration_s=steps * 0.1, seed=0))
    d = res.data
    h = hashlib.sha256()
    for a in (d.true_pose, d.odom_pose):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(d.stalled).astype(np.uint8).tobytes())
    h.update(json.dumps([d.logs, d.event_log, d.messages_sent, d.bytes_sent, d.messages_delivered],
                        sort_keys=True, default=_default).encode())
    return {"cpu_s": total, "brain_s": brain_s, "steps": int(res.sim.step_index), "digest": h.hexdigest()}


def _team_measure(src: Path, case: str, paper: bool, steps: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--team-worker", case, "1" if paper else "0",
                          str(steps)], env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _team_steps(base: Path, new: Path, steps: int, repeats: int, base_name: str, only) -> None:
    """CPU s per 1000 team steps at 4 robots, base and this tree alternating (see ``--team-step``)."""
    print(f"R1..R4 on office_simple, R1 on tuning task {TEAM_TASK}, {steps} steps per run, {repeats} round(s), "
          f"medians of CPU (time.process_time, one numba thread)")
    print(f"{'column':8s} {'navigator':16s} {'base s/1000':>11s} {'(brains)':>9s} {'new s/1000':>11s} {'(brains)':>9s} "
          f"{'ratio':>6s}  outputs")
    lines, ratios = [], []
    for paper, case in itertools.product((False, True), CASES):
        col, nav = ("paper" if paper else "teamnav"), TEAM_NAVIGATORS[case]
        if only and not any(o in f"{col}/{case}/{nav}" for o in only):
            continue
        b, n = [], []
        for src in (base, new):  # not timed: fills numba's cache for the kernels this configuration reaches
            _team_measure(src, case, paper, min(steps, 1000))
        for _ in range(repeats):  # alternate: both trees see the same load
            b.append(_team_measure(base, case, paper, steps))
            n.append(_team_measure(new, case, paper, steps))
        same = {r["digest"] for r in b} == {r["digest"] for r in n} and len({r["digest"] for r in b + n}) == 1
        bt = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in b)
        bb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in b)
        nt = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in n)
        nb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in n)
        ratios.append(bt / nt)
        print(f"{col:8s} {nav:16s} {bt:11.3f} {bb:9.3f} {nt:11.3f} {nb:9.3f} {bt / nt:6.2f}  "
              f"{'identical' if same else 'DIFFER'}", flush=True)
        lines.append(f"LOS team step, 4 robots ({col}, {nav}): base / this tree = {bt / nt:.2f}x")
    if ratios:
        print(f"(base: {base_name}; brains: CPU inside the brains' step and log)")
        for line in lines:
            print(line)
        print(f"LOS team step, 4 robots: base / this tree = {statistics.median(ratios):.2f}x "
              f"(median of {len(ratios)} configurations)")



# ---------------------------------------------------------------------------- group brains
#: The teams the group brains compile so far: R1 alone (team size 1), per navigator of R1.
GROUP_NAVIGATORS = ("potential_field", "avoid_past", "visbug21")
#: ... and R1..R4 as in Tables 1-2 ("team/<navigator of R1>"; state sharing with the potential
#: field only), the whole team compiled (with VisBug-21 since 2026-11-29: its temporary goals
#: and start_again)
GROUP_TEAMS = ("team/visbug21", "team/potential_field", "team/avoid_past")


def _group_overrides(navigator: str, paper: bool, task: int) -> dict:
    from teamnav.papers.los_help.tasks import _alone, task_targets_xy, team_overrides

    if navigator.startswith("team/"):  # R1..R4; the paper column: every robot with paper_rules
        ov = dict(team_overrides("simple", 3))
        ov["robots.0.params.navigator"] = navigator[len("team/"):]
        # Tables 1-2's cases: state sharing with the potential field, not with the others
        ov["robots.0.params.state_sharing"] = navigator == "team/potential_field"
        if paper:
            for k in range(4):
                ov[f"robots.{k}.params.paper_rules"] = True
    elif paper:
        ov = dict(_alone(navigator))  # the paper column's settings, R1 alone (the tuning sweeps' cases)
    else:
        ov = {"robots.0.params.navigator": navigator, "robots.1.count": 0, "robots.2.count": 0, "robots.3.count": 0}
    ov["robots.0.params.targets_xy"] = task_targets_xy("simple", task)
    return ov


def _digest(res) -> str:
    """SHA-256 of a run's outputs (as ``--team-step``): poses, odometry, stalls, logs, events, radio totals."""
    import hashlib

    import numpy as np

    from los_fingerprint import _default

    d = res.data
    h = hashlib.sha256()
    for a in (d.true_pose, d.odom_pose):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(d.stalled).astype(np.uint8).tobytes())
    h.update(json.dumps([d.logs, d.event_log, d.messages_sent, d.bytes_sent, d.messages_delivered],
                        sort_keys=True, default=_default).encode())
    return h.hexdigest()


def _group_task_worker(navigator: str, paper: bool, task: int) -> dict:
    """(in the measuring process) one whole task of R1 alone, reference then compiled."""
    from teamnav import load_scenario
    from teamnav.experiments.runner import run

    out = {}
    for compiled in (False, True):
        scn = load_scenario(MAPS["simple"], overrides=_group_overrides(navigator, paper, task), seed=0)
        t0 = time.process_time()
        res = run(scn, progress=False, group_brains=compiled)
        cpu = time.process_time() - t0
        r1 = res.sim.brains[0][0]
        out["compiled" if compiled else "reference"] = {
            "digest": _digest(res), "metrics": json.dumps(res.metrics, sort_keys=True, default=str),
            "target_steps": list(r1.target_steps), "steps": int(res.sim.step_index), "cpu_s": cpu,
            "teams": len(res.sim.group_teams)}
    return out


def _group_tasks(tasks: list[int], only: list[str] | None = None) -> None:
    """Whole tasks, reference vs compiled: the same outputs, metrics and steps per target?"""
    print(f"R1 alone on office_simple, whole tasks {tasks} (200 targets, the scenario's budget per target); "
          f"load {os.getloadavg()[0]:.1f}")
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_NUM_THREADS="1")
    bad = ran = 0
    for paper, nav, task in itertools.product((False, True), GROUP_NAVIGATORS, tasks):
        if only and not any(o in f"{'paper' if paper else 'teamnav'}/{nav}" for o in only):
            continue
        ran += 1
        res = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--group-task-worker", nav,
                              "1" if paper else "0", str(task)], env=env, check=True, capture_output=True, text=True)
        r = json.loads(res.stdout.strip().splitlines()[-1])
        a, b = r["reference"], r["compiled"]
        same = {k: a[k] == b[k] for k in ("digest", "metrics", "target_steps", "steps")}
        bad += not all(same.values()) or b["teams"] != 1
        print(f"{'paper' if paper else 'teamnav':8s} {nav:16s} task {task}: {a['steps']:7d} steps, "
              f"{len(a['target_steps']):3d} targets; outputs, metrics, steps per target: "
              f"{'same' if all(same.values()) else 'DIFFER ' + str(same)}; CPU reference {a['cpu_s']:.1f} s, "
              f"compiled {b['cpu_s']:.1f} s", flush=True)
    print(f"{bad} of {ran} whole tasks differ")


def _group_worker(navigator: str, paper: bool, compiled: bool, steps: int) -> dict:
    """(in the measuring process) CPU of ``steps`` warm steps of R1 alone on office_simple
    (tuning task TEAM_TASK), with the Python brain or its compiled group brain, and a digest of
    everything the run put out (as ``_team_worker``)."""
    from teamnav import load_scenario

    ov = _group_overrides(navigator, paper, TEAM_TASK)
    ov["robots.0.params.max_steps_per_target"] = 100_000_000
    from teamnav.experiments.runner import run

    run(load_scenario(MAPS["simple"], overrides=ov, duration_s=20.0, seed=0), progress=False,
        group_brains=compiled)  # warm-up
    total, brain_s, res = timed_run(load_scenario(MAPS["simple"], overrides=ov, duration_s=steps * 0.1, seed=0),
                                    group_brains=compiled)
    if compiled and not res.sim.group_teams:
        raise SystemExit("the group brain did not run R1")
    # robots whose step is compiled (a team's group brain may run a row on its reference brain)
    robots = sum(getattr(team, "compiled_robots", stop - start) for team, start, stop, _ in res.sim.group_teams)
    return {"cpu_s": total, "brain_s": brain_s, "steps": int(res.sim.step_index), "digest": _digest(res),
            "compiled_robots": robots, "robots": int(res.sim.n_robots)}


def _group_measure(navigator: str, paper: bool, compiled: bool, steps: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--group-worker", navigator,
                          "1" if paper else "0", "1" if compiled else "0", str(steps)],
                         env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _group_brains(steps: int, repeats: int, only: list[str] | None = None, sizes: tuple[int, ...] = (),
                  quick: bool = False) -> None:
    """CPU per team step, compiled group brains vs the Python reference (see ``--group-brains``)."""
    load0 = os.getloadavg()[0]
    t0 = time.process_time()
    print(f"R1 alone, and R1..R4 (team/...: the team's group brain), on office_simple, tuning task {TEAM_TASK}, "
          f"{steps} steps per run, {repeats} round(s), medians "
          f"of CPU (time.process_time, one numba thread), this tree ({REPO}), load {load0:.1f}")
    print(f"{'column':8s} {'navigator':16s} {'ref ms/step':>11s} {'(brains)':>9s} {'compiled':>9s} {'(brains)':>9s} "
          f"{'ratio':>6s} {'brains':>7s}  outputs")
    lines, ratios, team_ratios, whole_ratios = [], [], [], []
    for paper, nav in itertools.product((False, True), GROUP_NAVIGATORS + GROUP_TEAMS):
        col = "paper" if paper else "teamnav"
        if only and not any(o in f"{col}/{nav}" for o in only):
            continue
        for compiled in (False, True):  # untimed: fills numba's cache for what this configuration reaches
            _group_measure(nav, paper, compiled, min(steps, 500))
        ref, cmp_ = [], []
        for _ in range(repeats):  # alternate: both see the same load
            ref.append(_group_measure(nav, paper, False, steps))
            cmp_.append(_group_measure(nav, paper, True, steps))
        same = len({r["digest"] for r in ref + cmp_}) == 1
        rt = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in ref)
        rb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in ref)
        ct = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in cmp_)
        cb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in cmp_)
        team = nav.startswith("team/")
        whole = team and all(r["compiled_robots"] == r["robots"] for r in cmp_)
        if same:  # a ratio only for identical runs
            (whole_ratios if whole else team_ratios if team else ratios).append(rt / ct)
        print(f"{col:8s} {nav:16s} {rt:11.4f} {rb:9.4f} {ct:9.4f} {cb:9.4f} {rt / ct:6.2f} {rb / cb:7.2f}  "
              f"{'identical' if same else 'DIFFER'}; compiled robots {cmp_[0]['compiled_robots']} of "
              f"{cmp_[0]['robots']}", flush=True)
        lines.append(f"LOS team step, {4 if team else 1} robots ({col}, {nav}): compiled / reference = {rt / ct:.2f}x")
    print(f"(brains: CPU inside the brains' step and log, or the group brain's step_group and the views' log; "
          f"load {load0:.1f} -> {os.getloadavg()[0]:.1f}; this script's own CPU {time.process_time() - t0:.1f} s, "
          f"the runs' in their processes)")
    for line in lines:
        print(line)
    if ratios:
        print(f"LOS team step, 1 robots: compiled / reference = {statistics.median(ratios):.2f}x")
    if team_ratios:  # R1 on its reference brain inside the team: named apart from the "4 robots:" line
        print(f"LOS team step, 4 robots (helpers compiled, R1 reference): compiled / reference = "
              f"{statistics.median(team_ratios):.2f}x")
    scale_lines = []
    if sizes and not only:  # the scaling row: its table here, its lines after the 4-robot line
        scale_lines = _scaling(sizes, SCALE_QUICK_STEPS if quick else steps, repeats,
                               (False,) if quick else (False, True))
    if whole_ratios:  # the whole team compiled (the line)
        print(f"LOS team step, 4 robots: compiled / reference = {statistics.median(whole_ratios):.1f}x")
    for line in scale_lines:  # last: one line per larger team size
        print(line)


# ---------------------------------------------------------------------------- scaling row
#: Team sizes of the scaling row (R1 and n - 1 helpers on office_simple_grid,
#: ``teamnav.papers.los_help.scaling``).
SCALE_SIZES = (4, 8, 16, 32, 64)
#: Steps per timed run of the scaling row with ``--quick`` (a few hundred: about 1.5 CPU-min
#: for the five sizes, reference and compiled, processes and warm-ups included).
SCALE_QUICK_STEPS = 300
#: Untimed steps before the timed ones, in the same run.
SCALE_WARM_STEPS = 100


def _scale_worker(n: int, paper: bool, compiled: bool, steps: int, warm: int = SCALE_WARM_STEPS) -> dict:
    """(in the measuring process) CPU of ``steps`` team steps of R1 and ``n - 1`` helpers on the
    larger office (R1 on VisBug-21, tuning task TEAM_TASK), reference or compiled brains, after
    ``warm`` untimed steps of the same run (kernels loaded, and compiled where numba cannot cache
    them: VisBug-21's object-mode call in the paper column is compiled in each process on first
    use); the part inside the brains; numba compilations during the timed steps (should be 0);
    and a digest of the end state (true and odometry poses, every brain's log, radio totals)."""
    import hashlib

    import numpy as np
    from numba.core import event

    from los_fingerprint import _default
    from teamnav.experiments.spec import build_grid
    from teamnav.papers.los_help import scaling
    from teamnav.sim.engine import Simulation

    scn = scaling.load(n, task=TEAM_TASK, paper=paper, duration_s=(warm + steps) * 0.1)
    sim = Simulation(build_grid(scn), scn, group_brains=compiled)
    if compiled and sum(getattr(t, "compiled_robots", 0) for t, *_ in sim.group_teams) != n:
        raise SystemExit(f"the group brain did not compile all {n} robots")
    brain_s = [0.0]
    clock = time.process_time
    teams = [team for team, *_ in sim.group_teams]
    for brain in [b for g in sim.brains for b in (g if isinstance(g, list) else [g])] + teams:
        for meth in ("step", "log", "step_group"):  # as benchmarks/_common.py's timed_run
            f = getattr(brain, meth, None)
            if callable(f):
                def timed(*args, f=f):
                    t = clock()
                    out = f(*args)
                    brain_s[0] += clock() - t
                    return out

                setattr(brain, meth, timed)
    sim.run(warm)
    brain_s[0] = 0.0
    with event.install_recorder("numba:compile") as rec:
        t0 = clock()
        sim.run(steps)
        loop_s = clock() - t0
    brains = [b for g in sim.brains for b in (g if isinstance(g, list) else [g])]
    h = hashlib.sha256()
    for a in (sim.state.poses(), sim.odometry.pose):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    r = sim.radio
    h.update(json.dumps([b.log() for b in brains] + [list(map(int, r._sent_messages)), list(map(int, r._sent_bytes))],
                        sort_keys=True, default=_default).encode())
    return {"cpu_s": loop_s, "brain_s": brain_s[0], "steps": int(sim.step_index) - warm, "digest": h.hexdigest(),
            "robots": int(sim.n_robots), "compiles": sum(1 for e in rec.buffer if e[1].is_start)}


def _scale_measure(n: int, paper: bool, compiled: bool, steps: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"), NUMBA_NUM_THREADS="1")
    out = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--scale-worker", str(n),
                          "1" if paper else "0", "1" if compiled else "0", str(steps)],
                         env=env, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _scaling(sizes: tuple[int, ...], steps: int, repeats: int, papers: tuple[bool, ...] = (False,)) -> list[str]:
    """The scaling row: CPU per team step of R1 and n - 1 helpers on office_simple_grid, compiled
    against reference, per team size (and column); prints its table and returns its last lines,
    ``LOS team step, N robots: compiled / reference = X.Xx`` (the whole step, median over the
    columns) for every size but 4, whose line is named ``4 robots (office_simple_grid)`` (the
    issue's 4-robot line is the Tables' team on office_simple, printed by ``--group-brains``)."""
    load0 = os.getloadavg()[0]
    t0 = time.process_time()
    print(f"scaling row: R1 (VisBug-21, tuning task {TEAM_TASK}) and n-1 helpers (three per wing, R2..R4's routes) "
          f"on office_simple_grid, {steps} steps per run, {repeats} round(s), medians of CPU in Simulation.run "
          f"after {SCALE_WARM_STEPS} untimed steps (time.process_time, one numba thread), load {load0:.1f}")
    print(f"{'column':8s} {'robots':>6s} {'ref ms/step':>11s} {'(brains)':>9s} {'compiled':>9s} {'(brains)':>9s} "
          f"{'ratio':>6s} {'brains':>7s}  outputs")
    ratios: dict[int, list[float]] = {n: [] for n in sizes}
    for paper, n in itertools.product(papers, sizes):
        ref, cmp_ = [], []
        for _ in range(repeats):  # alternate: both see the same load
            ref.append(_scale_measure(n, paper, False, steps))
            cmp_.append(_scale_measure(n, paper, True, steps))
        same = len({r["digest"] for r in ref + cmp_}) == 1
        rt = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in ref)
        rb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in ref)
        ct = statistics.median(1000 * r["cpu_s"] / r["steps"] for r in cmp_)
        cb = statistics.median(1000 * r["brain_s"] / r["steps"] for r in cmp_)
        compiles = sum(r["compiles"] for r in ref + cmp_)
        if same:  # a ratio only for identical runs
            ratios[n].append(rt / ct)
        print(f"{'paper' if paper else 'teamnav':8s} {n:6d} {rt:11.3f} {rb:9.3f} {ct:9.3f} {cb:9.3f} {rt / ct:6.2f} "
              f"{rb / cb:7.2f}  {'identical' if same else 'DIFFER'}"
              f"{f'; {compiles} numba compilations while timed' if compiles else ''}", flush=True)
    print(f"(brains: CPU inside the brains' step and log, or the group brain's step_group and the views' log; "
          f"load {load0:.1f} -> {os.getloadavg()[0]:.1f}; this script's own CPU {time.process_time() - t0:.1f} s, "
          f"the runs' in their processes)")
    return [f"LOS team step, {n} robots{' (office_simple_grid)' if n == 4 else ''}: compiled / reference = "
            f"{statistics.median(r):.1f}x" for n, r in ratios.items() if r]


if __name__ == "__main__":
    main()
