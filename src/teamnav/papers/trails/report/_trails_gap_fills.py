"""What each gap-fill of ``blazing-trail-v1`` (and of ``trail-share-v1``) buys, and what keeps the 2000
team from breaking down: the runs of ``scripts/trail_gap_fill_study.py``, shown as
measured, not re-run by the report.

Vaughan, Støy, Sukhatme & Matarić (2000) §5.1: 28 units in 30 min, then "the unbounded odometry
error causes the system to break down completely at around 27 minutes". The study pairs seeds
(same start spots, drift and noise draws in every configuration) on seeds 100-107, which are
neither the report's (0-9) nor used to choose any value (nothing is tuned with them):

- part ``gapfills``: the 30-min ``blazing-a-trail`` trial, ``paper`` (every gap-fill at the
  paper's value, 0.25 m/s), ``teamnav`` (ours, 0.4 m/s), ``paper+G`` (the paper's rules with G
  alone at our value) and ``teamnav-G`` (ours with G alone at the paper's value);
- part ``drift``: 1 h at the ``blazing-drift`` cases (k x the 2002 paper's per-robot heading drift;
  wheel slip, a heading random walk; wheel-scale errors) for ``paper``,
  ``paper+reverse_carried_crumbs``, ``teamnav@0.25`` (our gap-fills at the paper's speed) and
  ``teamnav``.

The runs are package data, ``papers/trails/report/data/blazing-gap-fill-study.json`` (one dict per
run, as the script writes them; ``docs/report/blazing-gap-fill-study.jsonl`` and
``blazing-drift-study.jsonl`` hold the same lines; a test checks that they agree). The ``breakdown`` part
(the 2000 paper column as judged since 2026-11-29, 1 h at the papers' drift with and without a
heading random walk, tuning seeds 1000-1019) is stored in the same file. The same
``gapfills`` part for the 2002 brain (``--system try``: trail-share-v1 on ``try-to-see-it-my-way``)
is ``try-gap-fill-study.json`` / ``docs/report/try-gap-fill-study.jsonl``, shown in the
try-to-see-it-my-way section: 30-min runs on paired seeds 100-107 with the 180° rule's turns
counted, on the set-up of 2026-11-29 (2da9eba: 361 beams, the one-at-a-time start, crumb radius
4 m; 176 runs, 28 CPU-min). Its first version (1-h runs, seeds 100-103, on 2026-11-27's set-up,
turns not counted) is kept as ``docs/report/try-gap-fill-study-2026-11-27.jsonl``, history only.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from teamnav.experiments.report.model import Missing, Table, Text

__all__ = ["BREAKDOWN_HEADER", "DATA_FILES", "HEADER", "STUDY_RUNS", "blocks", "breakdown_in_window", "breakdown_rows",
           "cases", "study_runs", "table_rows"]

_DATA = Path(__file__).resolve().parent / "data"
#: system -> its package-data file of study runs (``--system`` of the script)
DATA_FILES = {"blazing": "blazing-gap-fill-study.json", "try": "try-gap-fill-study.json"}
#: system -> (brain, scenario) as the tables name them
SYSTEM_NAMES = {"blazing": ("blazing-trail-v1", "blazing-a-trail"), "try": ("trail-share-v1", "try-to-see-it-my-way")}


def study_runs(system: str = "blazing") -> tuple[dict, ...]:
    """The stored runs of ``system`` (empty when the file is absent)."""
    path = _DATA / DATA_FILES[system]
    return tuple(json.loads(path.read_text(encoding="utf-8"))) if path.is_file() else ()


#: the study's runs of blazing-trail-v1 (see the module docstring)
STUDY_RUNS: tuple[dict, ...] = study_runs("blazing")

#: what the paired column compares with: the first of these that the case ran
REFERENCES = ("paper", "paper+reverse_carried_crumbs")

HEADER = ["configuration", "units (mean ± std)",
          "paired vs the reference; teamnav-G vs teamnav (mean ± s.e., seeds with more)",
          "units in the 2nd half", "broke down", "median breakdown [min]", "180° turns per hour (team)",
          "CPU s / run"]


#: a run "never worked" when it delivered fewer than this many units in its first 30 min (one optimal
#: robot delivers ~10, the paper's team 28): reported apart, not counted as a breakdown
NEVER_WORKED_UNITS_30MIN = 3
#: breakdowns are counted within the paper's 30 min: the last delivery before 30 min - 180 s
#: followed by none until 30 min (the report's 180-s rule applied to the first 30 min)
BREAKDOWN_WINDOW_S = 1800.0


def breakdown_in_window(times_s: list[float], window_s: float = BREAKDOWN_WINDOW_S) -> bool:
    """The report's breakdown rule on the first ``window_s`` of a run: deliveries before it, the last
    one at least 180 s (:data:`~teamnav.papers.trails.metrics.BREAKDOWN_GAP_S`) before its end.

    >>> breakdown_in_window([100.0, 900.0]), breakdown_in_window([100.0, 1700.0]), breakdown_in_window([])
    (True, False, False)
    """
    from teamnav.papers.trails.metrics import BREAKDOWN_GAP_S

    inside = [t for t in times_s if t <= window_s]
    return bool(inside) and window_s - inside[-1] >= BREAKDOWN_GAP_S


def breakdown_rows(rows: list[dict]) -> list[list[str]]:
    """The breakdown study's table: per configuration and case, the runs that never worked (fewer than
    :data:`NEVER_WORKED_UNITS_30MIN` units in the first 30 min) apart, and of the runs that worked, how
    many broke down within 30 min and within the hour, with units and the 180° rule's turns."""
    out = []
    for key in sorted({(r["config"], r["case"]) for r in rows if r["part"] == "breakdown"}):
        g = [r for r in rows if r["part"] == "breakdown" and (r["config"], r["case"]) == key]
        t30 = [[t for t in r.get("delivery_times_s") or [] if t <= BREAKDOWN_WINDOW_S] for r in g]
        never = [r for r, t in zip(g, t30) if len(t) < NEVER_WORKED_UNITS_30MIN]
        worked = [(r, t) for r, t in zip(g, t30) if len(t) >= NEVER_WORKED_UNITS_30MIN]
        b30 = sum(breakdown_in_window(r.get("delivery_times_s") or []) for r, _ in worked)
        b60 = sum(not r["breakdown_censored"] for r, _ in worked)
        rev = [r["reversals"] / (r["duration_s"] / 3600.0) for r in g if r.get("reversals") is not None]
        out.append([key[0], key[1], str(len(g)), f"{len(never)} (seeds {','.join(str(r['seed']) for r in never) or '-'})",
                    f"{b30}/{len(worked)}", f"{b60}/{len(worked)}",
                    f"{np.mean([r['units'] for r in g]):.1f}" if g else "-",
                    f"{np.mean(rev):.0f}" if rev else "-"])
    return out


BREAKDOWN_HEADER = ["configuration", "case", "runs", "never worked (< 3 units in 30 min)",
                    "of the runs that worked: broke down within 30 min", "within the hour", "units (mean)",
                    "180° turns per hour (team)"]



def _ms(v: list[float]) -> str:
    if len(v) > 1:
        return f"{np.mean(v):.1f} ± {np.std(v, ddof=1):.1f}"
    return f"{v[0]:.1f}" if v else "-"


def _paired(rows: list[dict], base: dict[int, dict], key: str) -> str:
    d = [r[key] - base[r["seed"]][key] for r in rows if r["seed"] in base]
    if len(d) < 2:
        return "-"
    se = float(np.std(d, ddof=1)) / math.sqrt(len(d))
    return f"{np.mean(d):+.1f} ± {se:.1f} ({sum(x > 0 for x in d)}/{len(d)})"


def _order(config: str) -> tuple:
    return (config != "paper", config != "paper+reverse_carried_crumbs", config != "teamnav",
            config.startswith("teamnav"), config)


def table_rows(runs, part: str, case: str) -> list[list[str]]:
    """One row per configuration of ``part`` at drift ``case`` ("" for the scenario's own drift):
    :data:`HEADER`'s columns; the paired difference is against the reference (the first of
    :data:`REFERENCES` that ran at this case, marked "reference") on the same seed, and for a
    ``teamnav-G`` row against ``teamnav`` (what leaving G out of ours costs)."""
    rs = [r for r in runs if r["part"] == part and r["case"] == case]
    ref = next((c for c in REFERENCES if any(r["config"] == c for r in rs)), None)
    bases = {name: {r["seed"]: r for r in rs if r["config"] == name} for name in (ref, "teamnav")}
    out = []
    for c in sorted({r["config"] for r in rs}, key=_order):
        g = [r for r in rs if r["config"] == c]
        base = bases["teamnav" if c.startswith("teamnav-") else ref]
        dur = g[0]["duration_s"]
        broke = [r for r in g if not r["breakdown_censored"]]
        med = float(np.median([r["duration_s"] if r["breakdown_censored"] else r["breakdown_s"] for r in g]))
        rev = [r["reversals"] / (r["duration_s"] / 3600.0) for r in g if r.get("reversals") is not None]
        out.append([c, _ms([r["units"] for r in g]), "reference" if c == ref else _paired(g, base, "units"),
                    _ms([r["units_second_half"] for r in g]), f"{len(broke)}/{len(g)}",
                    f"{med / 60:.0f}" + ("+" if med >= dur else ""),
                    _ms(rev) if rev else "not logged", f"{np.mean([r['cpu_s'] for r in g]):.1f}"])
    return out


def cases(runs, part: str) -> list[str]:
    """The drift cases of ``part`` in the study, in the order x0, x1, x4, x1-slip, x1-scale5."""
    return sorted({r["case"] for r in runs if r["part"] == part}, key=lambda c: (len(c), c))


def _seeds(runs) -> str:
    s = sorted({r["seed"] for r in runs})
    return f"{s[0]}-{s[-1]}" if s else "-"


def blocks(runs=None, system: str = "blazing") -> list:
    """The study's tables of ``system`` for its report section (both parts), or a Missing block."""
    runs = list(study_runs(system) if runs is None else runs)
    brain, scenario = SYSTEM_NAMES[system]
    if not runs:
        return [Missing(f"gap-fill study of {brain}", "no runs of scripts/trail_gap_fill_study.py stored")]
    out: list = [Text(
        f"Why the two columns of {brain} differ, taken apart (scripts/trail_gap_fill_study.py "
        f"--system {system}, paired seeds "
        f"{_seeds([r for r in runs if r['part'] in ('gapfills', 'drift')] or runs)}, which are neither the report's "
        "nor used to choose anything; measured once and shown "
        "as measured, not re-run here). 'paper+G': the paper's rules with gap-fill G alone at teamnav's value "
        "(what G buys on its own); 'teamnav-G': ours with G alone at the paper's value (what G is worth among "
        "the others); 'teamnav@0.25': every gap-fill of ours at the paper's cruise speed.")]
    for case in cases(runs, "gapfills"):
        rs = [r for r in runs if r["part"] == "gapfills" and r["case"] == case]
        out.append(Table(f"Each gap-fill alone: {scenario}, {rs[0]['duration_s'] / 60:g} min, the scenario's drift",
                         HEADER, table_rows(runs, "gapfills", case)))
    for case in cases(runs, "drift"):
        rs = [r for r in runs if r["part"] == "drift" and r["case"] == case]
        out.append(Table(f"Drift case {case}: {rs[0]['duration_s'] / 60:g} min, paper / paper with homebound crumbs "
                         "reversed / our gap-fills at 0.25 m/s / ours", HEADER, table_rows(runs, "drift", case)))
    rv = [r for r in runs if r["part"] == "reversals"]
    if rv:
        out.append(Table(f"The 180° rule's turns counted: {brain} on {scenario}, {rv[0]['duration_s'] / 60:g} min, the "
                         f"scenario's drift, the paper's rules with each reversal-damping gap-fill alone, seeds "
                         f"{_seeds(rv)}", HEADER, table_rows(runs, "reversals", ""),
                         note="the same configurations as the table above on more seeds (tuning seeds), with "
                              "Navigate's count of the 180° rule's turns: whether each gap-fill damps the "
                              "flip-flopping is read from the runs, not inferred"))
    bd = [r for r in runs if r["part"] == "breakdown"]
    if bd:
        out.append(Table(f"Breakdown study: the 2000 paper column as judged (paper-2000: the trail followed backwards, "
                         f"0.4 m/s) at the papers' drift (k = 1), without and with a heading random walk of h "
                         f"deg/sqrt(m) (x1-slip<h>; x1-slip: h = 1), 1 h, seeds {_seeds(bd)}", BREAKDOWN_HEADER,
                         breakdown_rows(bd),
                         note=f"a run that delivered fewer than {NEVER_WORKED_UNITS_30MIN} units in its first 30 min "
                              "never worked: listed apart, not a breakdown; breakdowns of the runs that worked are "
                              "counted within the paper's 30 min (the 180-s rule on the first 30 min) and within "
                              "the hour. The slip size is ours (no paper gives the trail robots' figure): swept"))
    elif system == "blazing":
        out.append(Missing("breakdown study (>= 20 seeds, runs that never worked apart, breakdowns within 30 min)",
                           "not run yet: nice -n 10 python scripts/trail_gap_fill_study.py breakdown --seeds 1000-1019 "
                           "--out F.jsonl, then store F in papers/trails/report/data/"))
    return out


# ------------------------------------------------------------------ probes on tuning seeds
#: the probes on tuning seeds (``scripts/trail_gap_fill_study.py`` runs, seeds >= 1000), package data:
#: ``probe`` "precondition-2000" (the 2000 paper column, 30 min, k = 0 and the scenario's drift, with
#: its literal reading beside it) and "speed-0.25" (trail-share-v1's teamnav column at 0.4 and 0.25 m/s,
#: 30 min, k = 0 and the scenario's drift); docs/report/trails-probes.jsonl holds the same lines
PROBES_FILE = "trails-probes.json"
#: the 2000 precondition (Blazing §5.1: "Until 20 minutes all robots made consistently correct turning
#: decisions"; 28 units in 30 min): without drift the paper column's team delivers at least half the
#: paper's 28 units in 30 min on average and at most one run of the probe breaks down (the 180-s rule);
#: written before the probe's k = 0 runs. Needed by claim drift-breakdown (a breakdown from drift needs
#: a team that works without it)
PRE_MIN_UNITS_30MIN, PRE_MAX_BROKE = 14.0, 1


def probe_runs() -> tuple[dict, ...]:
    """The stored probe runs (empty when the file is absent)."""
    path = _DATA / PROBES_FILE
    return tuple(json.loads(path.read_text(encoding="utf-8"))) if path.is_file() else ()


def precondition_2000(runs=None):
    """The 2000 paper column's precondition (:data:`PRE_MIN_UNITS_30MIN`, :data:`PRE_MAX_BROKE`), checked on
    the stored probe runs of ``paper-2000`` at k = 0: a :class:`Precondition` (holds None: not run)."""
    from teamnav.experiments.report.model import Precondition

    runs = [r for r in (probe_runs() if runs is None else runs)
            if r.get("probe") == "precondition-2000" and r["config"] == "paper-2000" and r["case"] == "x0"]
    what = ("Blazing §5.1: the team works before drift does (\"Until 20 minutes all robots made consistently "
            "correct turning decisions\", 28 units in 30 min). Check: the 2000 paper column without drift, 30 min, "
            f"delivers >= {PRE_MIN_UNITS_30MIN:g} units on average and at most {PRE_MAX_BROKE} run breaks down")
    if not runs:
        return Precondition(what, "-", "not run (scripts/trail_gap_fill_study.py drift --configs paper-2000 "
                                        "--cases x0 --seeds 1000-1004 --duration 1800)", None, ("drift-breakdown",))
    units = [r["units"] for r in runs]
    broke = sum(not r["breakdown_censored"] for r in runs)
    holds = bool(np.mean(units) >= PRE_MIN_UNITS_30MIN and broke <= PRE_MAX_BROKE)
    rev = [r["reversals"] / (r["duration_s"] / 3600.0) for r in runs if r.get("reversals") is not None]
    return Precondition(what, _seeds(runs),
                        f"units {_ms(units)} (paper 28), {broke}/{len(runs)} broke down, the 180° rule's turns "
                        f"{_ms(rev)} per hour (team)" + ("" if holds else ": does not hold, so claim drift-breakdown "
                                                                          "reads 'precondition not met' on this column"),
                        holds, ("drift-breakdown",))


def probe_table(probe: str, runs=None) -> Table | Missing:
    """One probe's runs per configuration and drift case: units, a work rate (units x 2 x 31.5 m per robot
    and second, over the cruise speed), first delivery, breakdowns, the 180° rule's turns per hour and
    per km driven at cruise."""
    runs = [r for r in (probe_runs() if runs is None else runs) if r.get("probe") == probe]
    if not runs:
        return Missing(f"probe {probe}", "not run")
    rows = []
    for key in sorted({(r["config"], r["case"]) for r in runs}, key=lambda k: (k[1], k[0])):
        g = [r for r in runs if (r["config"], r["case"]) == key]
        cr = g[0].get("cruise_mps", 0.25)
        hours = g[0]["duration_s"] / 3600.0
        work = [r["units"] * 2 * 31.5 / (4 * r["duration_s"] * cr) for r in g]
        rev_h = [r["reversals"] / hours for r in g if r.get("reversals") is not None]
        rows.append([key[0], key[1] or "scenario drift", f"{cr:g}", _ms([r["units"] for r in g]),
                     f"{np.mean(work):.2f} ± {np.std(work, ddof=1) if len(work) > 1 else 0.0:.2f}",
                     _ms([r["first_delivery_s"] / 60 for r in g if r.get("first_delivery_s") is not None]),
                     f"{sum(not r['breakdown_censored'] for r in g)}/{len(g)}", _ms(rev_h),
                     _ms([x / (4 * cr * 3.6) for x in rev_h])])
    return Table(f"Probe {probe} on tuning seeds {_seeds(runs)} ({runs[0]['duration_s'] / 60:g} min)",
                 ["configuration", "drift", "cruise [m/s]", "units", "work rate (route m delivered per robot-m "
                  "at cruise)", "first delivery [min]", "broke down", "180° turns per hour (team)",
                  "180° turns per km at cruise (team)"], rows,
                 note="tuning seeds, not the report's; the work rate is units x 2 x 31.5 m / (4 robots x duration x "
                      "cruise): the share of the team's time spent carrying work at cruise")
