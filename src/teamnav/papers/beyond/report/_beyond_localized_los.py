"""The ``beyond`` section's block on combination 2, localized LOS help.

The LOS help system (Sgorbissa & Arkin; VisBug-21, R1 helped by R2..R4, goal sharing, the
line-of-sight radio) with every brain on an MCL pose (``localized-v1``, Fox et al. §3.1), and
the frame between sender and receiver taken three ways (the brains' ``frame_source``,
:mod:`teamnav.papers.beyond.brains.localized_los`): from the mutual bearings (§3.1, the paper's rule),
from the two robots' MCL poses, or both fused by inverse covariance. Each on both office maps,
with eqs. 1-2's detector noise err_max 0 and 0.4 (sweeps ``beyond-localized-los-simple`` and
``-complex``, made by :mod:`teamnav.papers.beyond.localized_los_scenarios`).

Shown per map: R1's steps per target (``los_steps_per_target``, lower is better) mean ± sd over
seeds, tasks finished, the per-seed paired difference against ``bearings`` at the same err_max
(mean ± sd, the t statistic mean / s.e., and on how many seeds the case was faster), and the
filters' mean error (``loc_mean_error_m``). Verdicts: claims ``localized-los-mcl`` and
``localized-los-fused`` (``claims/beyond.yaml``), judged on seeds 0-9 in full mode.

Quick mode (CI): ``bearings-e0.4`` and ``mcl-e0.4`` on office_simple, seed 0, R1's first 3
targets (two runs of a few seconds): the pipeline works; no verdict. Full mode: 2 maps x 6 cases
x seeds 0-9, 10 targets each (120 runs; the cost is in docs/report/beyond.md).
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Table, Text
from teamnav.papers.trails.report import _trails as T

QUICK_CASES = ("bearings-e0.4", "mcl-e0.4")
QUICK_TARGETS = 3
FULL_SEEDS = tuple(range(10))
METRIC = "los_steps_per_target"
MAP_TEXT = {"simple": "office_simple (Table 1's map)", "complex": "office_complex_closed (Table 2's map)"}
SOURCE_TEXT = {"bearings": "mutual bearings (§3.1, the paper)", "mcl": "MCL poses", "fused": "both, fused"}
#: a paired difference counts as measured beyond this many standard errors
T_LIMIT = 2.0


def claim_key(source: str, err_max: float) -> str:
    """``mcl_e04`` for (mcl, 0.4): the claims' metric infix."""
    return f"{source}_e{f'{err_max:g}'.replace('.', '')}"


def per_seed(rows: list[dict], key: str = METRIC) -> dict[int, float]:
    """Seed -> the metric of each finished row."""
    out = {}
    for r in rows:
        v = T.values([r], key)
        if v.size:
            out[int(r.get("seed"))] = float(v[0])
    return out


def paired(a: dict[int, float], b: dict[int, float]) -> tuple[np.ndarray, float]:
    """The per-seed differences a - b over the seeds both have, and their t statistic (mean over
    standard error; NaN with fewer than 2 pairs, ±inf when every difference is the same non-zero).

    >>> d, t = paired({0: 10.0, 1: 12.0, 2: 11.0}, {0: 12.0, 1: 13.0, 2: 14.0})
    >>> d.tolist(), round(t, 3)
    ([-2.0, -1.0, -3.0], -3.464)
    """
    common = sorted(set(a) & set(b))
    d = np.array([a[s] - b[s] for s in common], dtype=float)
    if d.size < 2:
        return d, float("nan")
    se = float(d.std(ddof=1)) / math.sqrt(d.size)
    if se == 0.0:
        return d, (0.0 if d.mean() == 0 else math.copysign(math.inf, float(d.mean())))
    return d, float(d.mean()) / se


def claim_values(data: dict[str, dict[str, dict[int, float]]]) -> dict[str, float]:
    """The claims' metrics from ``data[map][case label] = {seed: steps per target}``."""
    from teamnav.papers.beyond.localized_los_scenarios import CASES, case_label

    out: dict[str, float] = {}
    for m, by in data.items():
        for source, e in CASES:
            v = list(by.get(case_label(source, e), {}).values())
            out[f"spt_{claim_key(source, e)}_{m}_mean"] = float(np.mean(v)) if v else float("nan")
            if source != "bearings" and e == 0.4:
                _, t = paired(by.get(case_label(source, e), {}), by.get(case_label("bearings", e), {}))
                out[f"spt_t_{source}_vs_bearings_e04_{m}"] = t
    return out


def verdict_text(d: np.ndarray, t: float) -> str:
    """One word on a paired difference (lower is better)."""
    if d.size < 2 or math.isnan(t):
        return "not measured"
    if t <= -T_LIMIT:
        return "helps"
    if t >= T_LIMIT:
        return "hurts"
    return "no measurable difference"


def _map_block(m: str, rows_by_case: dict[str, list[dict]], labels: list[str], quick: bool) -> tuple[list, list[str]]:
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.papers.beyond.localized_los_scenarios import CASES, case_label

    table, notes = [], []
    for source, e in CASES:
        lab = case_label(source, e)
        if lab not in labels:
            continue
        rows = rows_by_case.get(lab, [])
        v = per_seed(rows)
        fin = T.values(rows, "los_finished")
        err = T.values(rows, "loc_mean_error_m")
        if source == "bearings":
            diff = "—"
        else:
            d, t = paired(v, per_seed(rows_by_case.get(case_label("bearings", e), [])))
            if d.size:
                wins = int((d < 0).sum())
                diff = (f"{d.mean():+.1f} ± {d.std(ddof=1) if d.size > 1 else 0.0:.1f} (t = {t:.1f}; faster on "
                        f"{wins}/{d.size} seeds)")
                word = verdict_text(d, t)
                notes.append(f"{MAP_TEXT[m].split(' ')[0]}, err_max {e:g}, frames from {SOURCE_TEXT[source]}: {word} "
                             f"({d.mean():+.1f} steps per target against bearings, n = {d.size})")
            else:
                diff = "n/a"
        table.append([lab, SOURCE_TEXT[source], f"{e:g}", T.msd(np.array(list(v.values())), "{:.0f}"),
                      f"{int(fin.sum())}/{fin.size}" if fin.size else "n/a", diff,
                      f"{err.mean():.3f}" if err.size else "n/a"])
    seeds = sorted({int(r.get("seed")) for rs in rows_by_case.values() for r in rs})
    seed_text = ", ".join(map(str, seeds)) if len(seeds) < 4 else f"{seeds[0]}-{seeds[-1]}"
    block = Table(
        f"Localized LOS help on {MAP_TEXT[m]}: R1's steps per target by frame source",
        ["case", "frame from", "err_max (eqs. 1-2)", "steps per target: mean ± sd (n)", "tasks finished",
         "paired vs bearings, same err_max: mean ± sd", "MCL mean error [m]"], table,
        note=f"sweep beyond-localized-los-{m}" + (" (quick: two cases, one seed, 3 targets; not the result)"
                                                  if quick else f", {B.N_TARGETS} targets of task 1") + f", seeds {seed_text}; "
             "every brain on localized-v1's MCL pose; lower is better.")
    return [block], notes


def localized_los(ctx) -> list:
    """The block: a table per map, what helps and what does not, and the two verdicts."""
    from teamnav.papers.beyond import localized_los_scenarios as B
    from teamnav.experiments.claims import history_text, judge, load_claims, rule_text
    from teamnav.experiments.sweep import load_sweep

    missing = T.brains_missing(["los-explorer-v1", "los-helper-v1", "localized-v1"])
    if missing is not None:
        return [missing]
    quick = bool(ctx.quick)
    blocks: list = [Text(
        "Combination 2, localized LOS help: the LOS help system with every brain on an MCL pose "
        "(localized-v1: Fox et al. §3.1, the laser through the likelihood field, the map given, tracking from the "
        "known start), and the frame between sender and receiver from the mutual bearings (Sgorbissa & Arkin §3.1, "
        "θ21 = 180° + α21 − α12), from the two robots' MCL poses (sent in each message; no sighting needed), or "
        "both fused by inverse covariance (the bearing frame's from eqs. 1-2's error bounds, the poses' from the "
        "filters' samples). All three drive on the same filter, so only the frame's source differs. The radio "
        "stays the paper's line of sight.")]
    maps = ["simple"] if quick else list(B.MAPS)
    data: dict[str, dict[str, dict[int, float]]] = {}
    notes: list[str] = []
    for m in maps:
        name = B.sweep_name(m)
        if quick:
            targets = B.scenario_data(m, n_targets=QUICK_TARGETS)["robots"][0]["params"]["brain_params"]["targets_xy"]
            res = ctx.sweep(T.case_spec(name, QUICK_CASES), seeds=[0], duration_s=None,
                            set={"robots.0.params.brain_params.targets_xy": targets})
            labels = list(QUICK_CASES)
        else:
            res = ctx.sweep(name, seeds=list(FULL_SEEDS), duration_s=None)
            labels = [str(c.get("case")) for c in load_sweep(name).cases]
        rows = T.by_case(T.ok(res))
        if not rows:
            blocks.append(Missing(f"localized LOS help on {MAP_TEXT[m]}", f"sweep {name} finished no trial"))
            continue
        data[m] = {lab: per_seed(rows.get(lab, [])) for lab in labels}
        b, n = _map_block(m, rows, labels, quick)
        blocks += b
        notes += n
    if notes:
        blocks.append(Text("Where each source helps, paired by seed against the bearings at the same err_max "
                           f"(|t| >= {T_LIMIT:g} counts as measured): " + "; ".join(notes) + "."))
    vals = claim_values(data)
    for cid in ("localized-los-mcl", "localized-los-fused"):
        claim = load_claims("beyond")[cid]
        if quick:
            holds, how = None, "not judged in quick mode (one seed, 3 targets, one map)"
        else:
            holds, how = judge(claim, vals)
        blocks.append(Comparison(
            f"{claim.title} ({rule_text(claim)})",
            f"{claim.paper_number} ({claim.statement.section}: \u201c{claim.statement.quote}\u201d)", how, holds,
            "our rule (no paper combines these). History of the rule: " + history_text(claim)))
    return blocks
