"""Fingerprints of the line-of-sight help runs: a speed-up must not move a single bit.

Runs ``los-help-simple`` and ``los-help-complex`` (Sgorbissa & Arkin §6) with each algorithm
of Tables 1–2 (the cases of ``los-table1.yaml``: potential field with state + goal sharing,
Avoid-Past and VisBug-21 with goal sharing), R1 alone and R1..R4, ``err_max`` 0 and 0.4 (every
robot's detector, eqs. 1-2), for ``--steps`` steps each, recording every step, and prints one
SHA-256 per run over

- the true poses and the odometry of every robot at every step (bytes of the float64 arrays),
- every brain's log at every step (modes, Tr/Pr/Nt, message and byte counts, targets reached),
- the events, and per brain at the end: steps per target (``target_steps``), targets
  reached, messages sent / received, bytes sent, moves.

Usage::

    python benchmarks/los_fingerprint.py                      # all 24 runs, ~1500 steps each
    python benchmarks/los_fingerprint.py --save base.json     # record
    python benchmarks/los_fingerprint.py --check base.json    # compare (exit 1 on a difference)
    python benchmarks/los_fingerprint.py --steps 300 --only simple

Recorded in ``benchmarks/los_fingerprints.json`` (1500 steps) at 4641d4c, the brains of
2026-11-23 (trouble_helper_towards_goal, via_in_sight, visbug_reverse_walk_factor); the
speed-ups merged after it (56777c6) reproduce every hash. The speed branch itself was checked
against its base f9d6cb5 after every commit. Re-recorded in 22f62f5 (2026-11-26) with NumPy 2.4.6 and numba
0.68.1 (the file now names them; ``--check`` warns when they differ): the commit
f9f4cf8 (2026-11-24) run with NumPy 2.4.6 already differed in 21 of 24 runs, the complex ones by 513792e's
map and budget, the simple potential-field and Avoid-Past ones by NumPy (2.4's own hypot and
arctan2 differ from libm in the last bit; VisBug-21 alone, all in numba kernels, held).
Re-recorded in e013e31 after ``see_past_teammates`` (fc95e88): the 12 runs of R1 alone
reproduced 22f62f5's hashes (the rule acts only on steps with a teammate in sight), the 12
team runs moved, as they must; a re-check reproduces the new file.

``los_fingerprints_epyc.json``: the same 24 runs at defbca7 on a 2-core AMD EPYC with AVX-512
(same NumPy and numba), where 16 of the hashes above (every potential-field and Avoid-Past run)
come out differently already at the commit that recorded them: check against the file recorded
on your kind of machine (the speed-ups of 2026-11-27 held both: the file above's 8 VisBug-21 runs and all 24 of
this one).

Re-recorded (``los_fingerprints_epyc.json`` only) after two changes of behaviour meant to move
runs: Avoid-Past's lifelong memory as the default (bdfa8a8, ``memory_scope="robot"``: all
8 Avoid-Past runs moved, R1 alone included) and perfect sensing at ``err_max = 0`` (7915eb8, the
occlusion model returns exact range and bearing there: the 4 potential-field and VisBug-21
team runs at err_max 0 moved). The other 12 (R1 alone and err_max 0.4 for those two
algorithms) reproduced their hashes. ``los_fingerprints.json`` still holds the hashes of
before these changes and needs re-recording on the machine that recorded it (not this one).

``--paper-rules`` (8e3551b, 2026-11-27): the same 24 runs with both brains at
``paper_rules: true``, as the report's "paper as written" column runs them (VisBug-21's
``boundary_shortcut`` and ``turn="left"``, the lifelong Avoid-Past memory, no gap-fills), whose
code paths the default runs do not reach; ``los_fingerprints_paper_epyc.json`` holds them as
recorded at 2abec5c on the EPYC machine::

    python benchmarks/los_fingerprint.py --paper-rules --check benchmarks/los_fingerprints_paper_epyc.json

2026-11-29, at 37d70e6, on a 2-core Intel Xeon (NumPy 2.4.6, numba 0.68.1): ``los_fingerprints.json``
(default) and ``los_fingerprints_paper.json`` (``--paper-rules``) re-recorded, 24 runs each; on
this machine every one of the 48 hashes differs from the EPYC files' (recorded at earlier commits
on another CPU), and a second run reproduced all 48. Check on this kind of machine with::

    python benchmarks/los_fingerprint.py --check benchmarks/los_fingerprints.json
    python benchmarks/los_fingerprint.py --paper-rules --check benchmarks/los_fingerprints_paper.json

``--group-brains`` runs the compiled group brains wherever they exist
(``docs/concepts/group-brains.md``) and must match the same files. Since 2026-11-29 every run
of each file steps compiled robots (the summary's ``compiled robots``): the 12 runs of R1 alone,
VisBug-21's 4 included, and the 12 team runs with all 4 robots in one group call. Both files
matched, 24 of 24 runs each.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import sys
import time

#: case -> overrides (as los-table1.yaml's cases)
CASES = {
    "pot-field": {"robots.0.params.navigator": "potential_field", "robots.0.params.state_sharing": True},
    "avoid-past": {"robots.0.params.navigator": "avoid_past", "robots.0.params.state_sharing": False},
    "visbug21": {"robots.0.params.navigator": "visbug21", "robots.0.params.state_sharing": False},
}
MAPS = {"simple": "los-help-simple", "complex": "los-help-complex"}
TEAMS = {"R1": 0, "R1-R4": 1}
ERR_MAX = (0.0, 0.4)


def _default(o):
    import numpy as np

    if isinstance(o, np.ndarray):
        return {"nd": o.dtype.str, "shape": list(o.shape), "hex": hashlib.sha256(o.tobytes()).hexdigest()}
    if isinstance(o, (np.floating,)):
        return float(o).hex()
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, float):
        return o.hex()
    raise TypeError(type(o).__name__)


def _paper_rules_set(map_key: str) -> dict:
    """Every robot group's params at ``paper_rules: true``, as the report's paper-as-written
    column sets them (``_trails.paper_rules_spec`` of the map's table sweep)."""
    from teamnav.papers.trails.report._trails import paper_rules_spec
    from teamnav.experiments.sweep import resolve_spec

    return dict(paper_rules_spec(resolve_spec({"simple": "los-table1", "complex": "los-table2"}[map_key])).set)


def run_one(map_key: str, case: str, team: str, err_max: float, steps: int, paper_rules: bool = False,
            group_brains: bool = False) -> tuple[str, dict]:
    """(sha256, readable summary) of one run; ``paper_rules``: both brains as the paper wrote them
    (the report's "paper as written" column), the case's navigator and sharing flag on top;
    ``group_brains``: the compiled group brains where they exist (the summary says how many robots
    they ran), which must give the same hash."""
    import numpy as np

    from teamnav import load_scenario
    from teamnav.experiments.runner import run

    ov = {**(_paper_rules_set(map_key) if paper_rules else {}), **CASES[case]}
    present = TEAMS[team]
    for k in (1, 2, 3):
        ov[f"robots.{k}.count"] = present
    for k in (0, 1, 2, 3):
        ov[f"robots.{k}.detector.err_max"] = err_max
    ov["record_every"] = 1
    scn = load_scenario(MAPS[map_key], overrides=ov, duration_s=steps * 0.1, seed=0)
    res = run(scn, progress=False, group_brains=group_brains)
    d = res.data
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(d.true_pose, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(d.odom_pose, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(d.stalled).astype(np.uint8).tobytes())
    h.update(json.dumps(d.logs, sort_keys=True, default=_default).encode())
    h.update(json.dumps(d.event_log, sort_keys=True, default=_default).encode())
    summary = {}
    brains = [b for g in res.sim.brains for b in (g if isinstance(g, list) else [g])]
    for i, b in enumerate(brains):
        s = {
            "target_steps": list(getattr(b, "target_steps", [])),
            "targets_reached": int(getattr(b, "targets_reached", getattr(b, "waypoints_reached", 0))),
            "msgs_sent": int(b.msgs_sent), "msgs_received": int(b.msgs_received),
            "bytes_sent": int(b.bytes_sent), "moves": int(b.moves),
        }
        summary[f"robot{i}"] = s
        h.update(json.dumps(s, sort_keys=True).encode())
    summary["steps"] = int(res.sim.step_index)
    h.update(str(summary["steps"]).encode())
    # not hashed; a team's group brain may run a row on its reference brain (``compiled_robots``)
    summary["compiled_robots"] = sum(getattr(team, "compiled_robots", stop - start)
                                     for team, start, stop, _ in res.sim.group_teams)
    return h.hexdigest(), summary


def _versions() -> dict[str, str]:
    """The numeric libraries a run's last bits depend on."""
    import numba
    import numpy

    return {"numpy": numpy.__version__, "numba": numba.__version__}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--steps", type=int, default=1500)
    ap.add_argument("--only", action="append", help="substring filter on the run key (repeatable: any)")
    ap.add_argument("--save", help="write the fingerprints to this JSON file")
    ap.add_argument("--check", help="compare with the fingerprints in this JSON file")
    ap.add_argument("--paper-rules", action="store_true",
                    help="the same 24 runs with both brains at paper_rules: true (the report's paper-as-written "
                         "column; its own reference files, los_fingerprints_paper.json and los_fingerprints_paper_epyc.json)")
    ap.add_argument("--group-brains", action="store_true",
                    help="run with the compiled group brains where they exist (docs/concepts/group-brains.md): "
                         "the same files must match")
    args = ap.parse_args(argv)
    import teamnav

    print(f"teamnav from {teamnav.__file__}", flush=True)
    ref = {}
    if args.check:
        with open(args.check) as f:
            ref = json.load(f)
        if ref.get("steps") != args.steps:
            print(f"reference has steps={ref.get('steps')}, running {args.steps}", file=sys.stderr)
        for lib, have in _versions().items():
            want = ref.get("versions", {}).get(lib)
            if want != have:
                print(f"reference recorded with {lib} {want or '(not recorded)'}, running {have}: hashes may "
                      "differ without any change of ours (NumPy 2.4's hypot/arctan2 differ from libm's in the "
                      "last bit, and the potential field's and Avoid-Past's numpy lines use them)", file=sys.stderr)
    out = {"steps": args.steps, "versions": _versions(), "paper_rules": bool(args.paper_rules), "runs": {}}
    if ref and bool(ref.get("paper_rules", False)) != bool(args.paper_rules):
        print(f"reference has paper_rules={ref.get('paper_rules', False)}, running paper_rules={args.paper_rules}",
              file=sys.stderr)
    bad = 0
    t_all = time.process_time()
    for map_key, case, team, err in itertools.product(MAPS, CASES, TEAMS, ERR_MAX):
        key = f"{map_key}/{case}/{team}/err{err}"
        if args.only and not any(s in key for s in args.only):
            continue
        t0 = time.process_time()
        digest, summary = run_one(map_key, case, team, err, args.steps, args.paper_rules, args.group_brains)
        cpu = time.process_time() - t0
        out["runs"][key] = {"sha256": digest, "summary": summary}
        status = ""
        if ref:
            want = ref.get("runs", {}).get(key, {}).get("sha256")
            status = "  (no reference)" if want is None else ("  OK" if want == digest else "  DIFFERS")
            bad += want is not None and want != digest
        r1 = summary["robot0"]
        print(f"{key:36s} {digest[:16]} reached {r1['targets_reached']:3d} msgs {r1['msgs_sent']:5d} "
              f"cpu {cpu:6.1f}s{status}" + (f"  compiled robots {summary['compiled_robots']}" if args.group_brains else ""),
              flush=True)
    print(f"total CPU {time.process_time() - t_all:.1f} s; {len(out['runs'])} runs; {bad} differ")
    if args.save:
        with open(args.save, "w") as f:
            json.dump(out, f, indent=1, sort_keys=True)
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())
