"""The ``los-help`` section's verdicts: EXPERIMENTS.md's rows for Tables 1-2 and Figs. 16-17 as
:class:`~teamnav.experiments.report.model.Comparison` blocks, paired by task (Sgorbissa & Arkin §6).

Split from :mod:`.section` (no behaviour change). The rules are read from the claim file
``claims/los-help.yaml`` (:mod:`teamnav.experiments.claims`): each verdict computes the metrics
its claim names and calls :func:`~teamnav.experiments.claims.judge`; no threshold lives here.

Two columns: the verdicts are computed on each column's rows and merged by
:func:`column_comparisons`, which gives each claim a comparison per column (``column`` of the
report model): the paper-as-written one is the verdict (every claim is ``judged:
paper_rules``), the teamnav one stands beside it. Table 2's verdicts read the mean
over the route plans of :data:`._los_common.ROUTE_PLANS` (``plans`` of
:func:`table_comparisons`, :func:`_plan_means`).
"""

from __future__ import annotations

import json
import math
from typing import Sequence

import numpy as np

from teamnav.papers.los_help import tasks as L
from teamnav.experiments.claims import judge, load_claims
from teamnav.experiments.report.model import Comparison
from teamnav.papers.los_help.report._los_common import (
    ERR_KEY, NAV_KEY, NAV_LABEL, PAPER_TABLES, TARGETS_KEY, TEAM_LABEL, _metric, finished_of, group, stats, steps_of,
    strictly_falling,
)


def _paired_per_task(by_team: dict[int, list[dict]], nav: str,
                     hs: Sequence[int]) -> tuple[dict[int, dict[str, float]], list[str], int] | None:
    """Steps per target by team size and task over the tasks finished with *every* team size in
    ``hs``: ({team: {task: steps}}, the common tasks (sorted), tasks run), or None when the rows do
    not name their tasks."""
    per: dict[int, dict[str, float]] = {}
    tasks: set[str] = set()
    for h in hs:
        per[h] = {}
        for r in group(by_team.get(h, []), NAV_KEY).get(nav, []):
            t = (r.get("params") or {}).get(TARGETS_KEY)
            if t is None:
                return None
            key = json.dumps(t)
            tasks.add(key)
            if _metric(r, "los_finished") > 0.5:
                per[h][key] = _metric(r, "los_steps_per_target")
    if not tasks:
        return None
    common = sorted(set.intersection(*(set(v) for v in per.values()))) if per else []
    return per, common, len(tasks)


def paired_means(by_team: dict[int, list[dict]], nav: str, hs: Sequence[int]) -> tuple[list[float], int, int] | None:
    """Mean steps per target per team size over the tasks finished with *every* team size in
    ``hs`` (a task failed by one team would otherwise leave only the easy tasks in its mean);
    (means, tasks kept, tasks run), or None when the rows do not name their tasks."""
    got = _paired_per_task(by_team, nav, hs)
    if got is None:
        return None
    per, common, n = got
    ms = [float(np.mean([per[h][t] for t in common])) if common else float("nan") for h in hs]
    return ms, len(common), n


def paired_rises(by_team: dict[int, list[dict]], nav: str, hs: Sequence[int]) -> list[str]:
    """Each added helper that *raised* the paired mean, with its size against the task-to-task
    noise: "R1 → R1,2: +11 ± 4 (s.e. over 5 tasks; 5 of 5 worse)". A verdict that fails on a
    rise within its standard error fails on noise; one several s.e. out fails for real."""
    got = _paired_per_task(by_team, nav, hs)
    if got is None:
        return []
    per, common, _n = got
    out = []
    for a, b in zip(hs, hs[1:]):
        if not common:
            break
        d = np.array([per[b][t] - per[a][t] for t in common])
        if d.mean() <= 0:
            continue
        se = float(d.std(ddof=1) / np.sqrt(d.size)) if d.size > 1 else float("nan")
        out.append(f"{TEAM_LABEL[a]} → {TEAM_LABEL[b]}: +{d.mean():.0f} ± {se:.0f} (s.e. over {d.size} tasks; "
                   f"{int((d > 0).sum())} of {d.size} worse)")
    return out

#: ``max_rise`` when no two team sizes have a finished mean (no added helper to rise at)
NO_RISE = -1e9


def _claim(claim_id: str):
    return load_claims("los-help")[claim_id]


def _judged(claim_id: str, values: dict[str, float], record: dict | None = None) -> bool | None:
    """The claim's verdict on ``values`` (None: a metric not measured); with ``record``, the
    values and the judge's reading are kept there under the claim's id (the claim table).

    The callers apply the claim's ``min_pairs`` themselves (they know the pairs of each trend,
    per route plan and navigator), before calling this: the claim is judged here without it."""
    got = judge(_claim(claim_id).model_copy(update={"min_pairs": None}), values)
    if record is not None:
        record[claim_id] = (dict(values), got)
    return got[0]


def _failed(claim_id: str, why: str, record: dict | None = None) -> bool:
    """A verdict that fails before any metric can be read (its metric is not defined): False,
    recorded with a NaN metric and ``why`` so that the claim table says "does not hold" too."""
    if record is not None:
        record[claim_id] = ({_claim(claim_id).metric: float("nan")}, (False, f"{why}: does not hold"))
    return False


def _team_mean(by_team: dict[int, list[dict]], nav: str, h: int) -> float:
    """Mean steps per target of ``nav`` with team ``h`` over its finished tasks (NaN: none)."""
    rs = group(by_team.get(h, []), NAV_KEY).get(nav, [])
    st, fin = steps_of(rs), finished_of(rs)
    ok = fin > 0.5
    return stats(st[ok])[0] if ok.any() else float("nan")


def _plan_means(plans: Sequence[dict[int, list[dict]]], nav: str, hs: Sequence[int]) -> tuple[list[float], str]:
    """Claims/los-help.yaml's route-plan rule: per plan, the paired-by-task mean per
    team of ``hs`` (:func:`paired_means`; unpaired when the rows name no tasks); then the mean over
    the plans at each team, NaN where some plan has none. Also one line per plan for the text."""
    per_plan, text = [], []
    for k, p in enumerate(plans):
        got = paired_means(p, nav, hs)
        ms = got[0] if got is not None else [_team_mean(p, nav, h) for h in hs]
        per_plan.append(ms)
        kept = f", {got[1]} of {got[2]} tasks" if got is not None else ""
        text.append(f"{PLAN_LABELS[k] if k < len(PLAN_LABELS) else k}: "
                    + " → ".join("n/a" if not np.isfinite(m) else f"{m:.0f}" for m in ms) + kept)
    arr = np.asarray(per_plan, dtype=float).reshape(len(plans), len(hs))
    means = [float(arr[:, j].mean()) if np.isfinite(arr[:, j]).all() else float("nan") for j in range(len(hs))]
    return means, "; ".join(text)


def _fewest_pairs(plans: Sequence[dict[int, list[dict]]], nav: str, hs: Sequence[int]) -> int | None:
    """The fewest tasks paired across the teams ``hs`` in any route plan (None: rows name no tasks)."""
    ks = [got[1] for p in plans if (got := paired_means(p, nav, hs)) is not None]
    return min(ks) if ks else None


#: the route plans' labels, in the order the section passes them (plan A first: the table's own runs)
PLAN_LABELS = ("plan A", "plan B", "plan C")


def table_comparisons(map_key: str, means: dict[str, list[float]], by_team: dict[int, list[dict]],
                      plans: Sequence[dict[int, list[dict]]] | None = None,
                      record: dict | None = None) -> list[Comparison]:
    """Tables 1-2's verdicts on one column's rows (``by_team``, team size -> rows).

    ``plans``: the rows of each route plan (Table 2's robustness column; plan A, the
    table's own rows, first, each plan with the same R1-alone rows): the verdicts then read the mean
    over the plans, as claims/los-help.yaml's Table 2 rules say (:func:`_plan_means`); a team counts
    as failing when it finished no task in any plan. ``record``: collects each claim's values and
    reading (:func:`_judged`)."""
    tab = 1 if map_key == "simple" else 2
    multi = plans is not None and len(plans) > 1
    pooled = by_team if not multi else {h: [r for p in plans for r in p.get(h, [])] for h in sorted(
        {h for p in plans for h in p})}
    paper = PAPER_TABLES[map_key]
    out: list[Comparison] = []
    teams = sorted(by_team)
    for nav in L.NAVIGATORS:
        hs = [h for h in teams if not (nav == "potential_field" and h == 0)]
        # a team that finished no task is worse than any that did: the trend holds through it
        # when such teams come before (fewer helpers than) every team that finished tasks
        fin = {h: finished_of(group(pooled.get(h, []), NAV_KEY).get(nav, [])) for h in hs}
        failing = [h for h in hs if fin[h].size and not (fin[h] > 0.5).any()]
        ok_hs = [h for h in hs if h not in failing]
        ms = [means[nav][h] for h in ok_hs]
        paired = paired_means(by_team, nav, ok_hs) if ok_hs and not multi else None
        note = ""
        if multi and ok_hs:
            ms, per_plan = _plan_means(plans, nav, ok_hs)
            note = f" (mean over {len(plans)} route plans of the paired means; {per_plan})"
        elif paired is not None:
            ms, k, n = paired
            note = f" (paired: the {k} of {n} tasks finished with every team that finished one)"
        pairs = _fewest_pairs(plans, nav, ok_hs) if multi and ok_hs else (paired[1] if paired is not None else None)
        p = [paper[nav][h][0] for h in hs if paper[nav][h] is not None]
        fails_first = not failing or not ok_hs or max(failing) < min(ok_hs)
        cid = f"table{tab}-{nav.replace('_', '-')}-falls"
        plan_gap = multi and bool(ok_hs) and not all(np.isfinite(ms))
        no_common = False
        min_pairs = _claim(cid).min_pairs
        too_few = min_pairs is not None and pairs is not None and 0 < pairs < min_pairs and len(ms) >= 2
        if too_few:
            # FIDELITY §3: a paired verdict on fewer pairs than the claim file fixes is no verdict
            holds = None
            if record is not None:
                record[cid] = ({"pairs": float(pairs)}, (None, f"not judged (n = {pairs})"))
        elif plan_gap:
            # claims/los-help.yaml's plan rule: a plan without a paired mean at a team (it finished no
            # task common to the teams that finished one) makes the trend fail
            holds = _failed(cid, "a route plan has no paired mean at some team", record)
        elif len(ms) < 2:
            # one team size with results: a trend only if teams with fewer helpers failed outright
            # (no added helper with a finished mean on either side: no rise, NO_RISE)
            holds = None if not failing else (
                _failed(cid, "no team finished a task", record) if not ok_hs
                else _judged(cid, {"max_rise": NO_RISE, "fails_first": float(fails_first)}, record))
        elif all(np.isfinite(ms)):
            holds = _judged(cid, {"max_rise": float(np.diff(np.asarray(ms, dtype=float)).max()),
                                  "fails_first": float(fails_first)}, record)
        elif any(np.isfinite(ms)):
            # some team between others has no paired mean: the trend cannot hold
            holds = _failed(cid, "a team between others has no paired mean", record)
        else:
            # no task finished by every team that finished one: helpers lost tasks that fewer helpers
            # finished, so the trend fails (claims/los-help.yaml, rule change of 2026-11-27; was "not judged")
            no_common = True
            holds = _failed(cid, "no task finished by every team that finished one", record)
        ours = " → ".join([f"fails ({int(fin[h].sum())}/{fin[h].size})" for h in failing if h < min(ok_hs, default=9)]
                          + ["n/a" if not np.isfinite(m) else f"{m:.0f}" for m in ms]
                          + [f"fails ({int(fin[h].sum())}/{fin[h].size})" for h in failing if h > min(ok_hs, default=9)])
        ratio = (f"; last/first {ms[-1] / ms[0]:.2f} (paper {p[-1] / p[0]:.2f})"
                 if len(ms) >= 2 and np.isfinite(ms[0]) and np.isfinite(ms[-1]) and ms[0] > 0 and not failing else "")
        out.append(Comparison(
            f"Table {tab}: {NAV_LABEL[nav]} steps fall as helpers are added ({', '.join(TEAM_LABEL[h] for h in hs)})",
            " → ".join(f"{v:.1f}" for v in p), ours + ratio + note, holds,
            f"not judged (n = {pairs}): the claim file fixes at least {min_pairs} pairs" if too_few else
            "" if holds or holds is None else
            "a route plan has no paired mean at some team (no task finished by every team that finished one in "
            "that plan), which fails the trend (claims/los-help.yaml)" if plan_gap else
            "no task was finished by every team that finished one: added helpers lost tasks that fewer helpers "
            "finished, which fails the trend (claims/los-help.yaml)" if no_common else
            "not strictly falling at every added helper in our runs"
            + (f" (each rise paired by task, {'; '.join(rises)})" if not multi and (rises := paired_rises(by_team, nav, ok_hs))
               else " (see the table)")))
    pf = group(by_team.get(0, []), NAV_KEY).get("potential_field", [])

    def helped(bt: dict[int, list[dict]]) -> np.ndarray:
        return finished_of([r for h in sorted(bt) if h > 0 for r in group(bt[h], NAV_KEY).get("potential_field", [])])

    alone_fin, help_fin = finished_of(pf), helped(pooled)
    if alone_fin.size and help_fin.size:
        # over route plans: the mean of the plans' fractions (each plan's helped runs; claims file)
        fracs = [float(np.mean(f > 0.5)) for p in (plans if multi else [by_team]) if (f := helped(p)).size]
        holds = _judged(f"table{tab}-pf-alone-fails", {"pf_alone_finished": float(np.mean(alone_fin > 0.5)),
                                                       "pf_helped_finished": float(np.mean(fracs))}, record)
        per_team = ", ".join(f"{TEAM_LABEL[h]} {int(f.sum())}/{f.size}" for h in sorted(pooled) if h > 0
                             and (f := finished_of(group(pooled[h], NAV_KEY).get("potential_field", []))).size)
        ours = (f"alone: {int(alone_fin.sum())}/{alone_fin.size} finished; with helpers: "
                f"{int(help_fin.sum())}/{help_fin.size} finished ({per_team}"
                + (f"; over {len(plans)} route plans" if multi else "") + ")")
    else:
        holds, ours = None, "not run"
    out.append(Comparison(f"Table {tab}: the potential field alone fails, and finishes with helpers (state + goal sharing)",
                          "no result alone; " + " → ".join(f"{v[0]:.1f}" for v in paper["potential_field"][1:]),
                          ours, holds, "" if holds or holds is None else
                          "some potential-field runs did the opposite of the paper (see the table)"))
    if map_key == "complex" and 3 in by_team:
        if multi:  # each algorithm's R1..R4 mean: the mean over the plans of each plan's (claims file)
            m3 = {nav: v for nav in L.NAVIGATORS
                  if np.isfinite(v := float(np.mean([_team_mean(p, nav, 3) for p in plans])))}
        else:
            m3 = {nav: means[nav][3] for nav in L.NAVIGATORS if np.isfinite(means[nav][3])}
        if len(m3) >= 2:
            spread = max(m3.values()) / min(m3.values()) - 1.0
            holds = _judged("table2-algorithm-matters", {"best_to_worst_spread": spread}, record)
            ours = (", ".join(f"{NAV_LABEL[k]} {v:.0f}" for k, v in m3.items()) + f" (best to worst +{100 * spread:.0f} %"
                    + (f"; means over {len(plans)} route plans" if multi else "") + ")")
        else:
            holds, ours = None, "not measured"
        out.append(Comparison("Table 2: with 3 helpers the algorithm still matters (best and worst differ by > 10 %)",
                              "Av. Past 682.6, VisBug 373.4, Pot. Fields 913.6 (+145 %)", ours, holds,
                              "" if holds or holds is None else "with 3 helpers our algorithms end up close"))
    return out

def alone_levels(rows: list[dict]) -> dict[str, float]:
    """R1 alone's steps per target per algorithm, the reference line of Figs. 16-17: the mean
    over its tasks when every task finished; otherwise the mean steps per *reached* target over
    every task, the abandoned target's budget included (a failed task has no finished mean, and
    a mean over the finished tasks only would keep the easy ones); NaN when none reached any."""
    out: dict[str, float] = {}
    for nav in L.NAVIGATORS:
        rs = group(rows, NAV_KEY).get(nav, [])
        st, fin = steps_of(rs), finished_of(rs)
        if not rs:
            out[nav] = float("nan")
        elif (fin > 0.5).all():
            out[nav] = stats(st)[0]
        else:
            reached = np.array([_metric(r, "los_targets_reached") for r in rs])
            ok = reached > 0
            out[nav] = float(np.mean(st[ok])) if ok.any() and nav != "potential_field" else float("nan")
    return out

def paired_noise(rows: list[dict], nav: str, errs: Sequence[float]) -> tuple[list[float], int] | None:
    """Mean steps per target of ``nav`` at each err_max of ``errs`` over the tasks finished at
    every one of them (a task failed at one noise level would leave only the easy ones), and
    how many tasks that is; None when the rows do not name their tasks."""
    per: dict[float, dict[str, float]] = {float(e): {} for e in errs}
    for r in group(rows, NAV_KEY).get(nav, []):
        p = r.get("params") or {}
        e, t = p.get(ERR_KEY), p.get(TARGETS_KEY)
        if t is None:
            return None
        if e is not None and float(e) in per and _metric(r, "los_finished") > 0.5:
            per[float(e)][json.dumps(t)] = _metric(r, "los_steps_per_target")
    common = set.intersection(*(set(v) for v in per.values()))
    return [float(np.mean([per[float(e)][t] for t in common])) if common else float("nan") for e in errs], len(common)

def noise_comparisons(map_key: str, means: dict[str, dict[float, float]], alone: dict[str, float],
                      rows: list[dict] | None = None, record: dict | None = None) -> list[Comparison]:
    """Figs. 16-17's claims; with ``rows`` the err_max 0 vs 0.4 comparison is paired by task
    (:func:`paired_noise`); ``record`` as in :func:`table_comparisons`."""
    out: list[Comparison] = []
    fig = 16 if map_key == "simple" else 17
    grow, text, pairs = [], [], []
    for nav, per in means.items():
        if 0.0 in per and 0.4 in per and np.isfinite(per[0.0]) and np.isfinite(per[0.4]):
            pn = paired_noise(rows, nav, (0.0, 0.4)) if rows else None
            if pn is not None and pn[1] > 0:
                (a, b), k = pn
                pairs.append(k)
                grow.append(b - a)
                text.append(f"{NAV_LABEL[nav]} {a:.0f} → {b:.0f} (paired, {k} tasks)")
            else:
                grow.append(per[0.4] - per[0.0])
                text.append(f"{NAV_LABEL[nav]} {per[0.0]:.0f} → {per[0.4]:.0f}")
    min_pairs = _claim(f"fig{fig}-noise-grows").min_pairs
    few = min(pairs) if pairs and min_pairs is not None and min(pairs) < min_pairs else None
    if few is not None:
        # FIDELITY §3: fewer pairs than the claim file fixes is no verdict
        gholds = None
        if record is not None:
            record[f"fig{fig}-noise-grows"] = ({"pairs": float(few)}, (None, f"not judged (n = {few})"))
    else:
        gholds = _judged(f"fig{fig}-noise-grows", {"min_growth": min(grow) if grow else math.nan}, record) if grow else None
    out.append(Comparison(f"Fig. {fig}: steps grow with err_max (0 → 0.4), R2..R4 present",
                          "performance decreases for every algorithm as err_max grows",
                          "; ".join(text) or "not run", gholds,
                          f"not judged (n = {few}): the claim file fixes at least {min_pairs} pairs" if few is not None
                          else "" if (not grow or gholds) else "some algorithms did not get slower with noise"))
    navs = [n for n in means if n in alone and np.isfinite(alone[n]) and 0.4 in means[n]]
    if map_key == "simple":
        below = [means[n][0.4] / alone[n] for n in navs]
        ours = "; ".join(f"{NAV_LABEL[n]} {means[n][0.4]:.0f} vs alone {alone[n]:.0f}" for n in navs)
        bholds = _judged("fig16-below-alone", {"max_ratio_to_alone": max(below)}, record) if below else None
        out.append(Comparison("Fig. 16: at err_max = 0.4 the steps stay below R1 alone",
                              "still lower than with no supporting robot (every algorithm)", ours or "not run",
                              bholds,
                              "" if (not below or bholds) else "help is gone at err_max = 0.4 for some algorithm"))
    else:
        fade = []
        for n in navs:
            if 0.0 in means[n]:
                gain0, gain4 = alone[n] - means[n][0.0], alone[n] - means[n][0.4]
                fade.append((n, gain0, gain4))
        ratios = [g4 / g0 for _, g0, g4 in fade if g0 > 0]
        ours = "; ".join(f"{NAV_LABEL[n]} gain over alone {g0:.0f} → {g4:.0f} steps" for n, g0, g4 in fade)
        fholds = _judged("fig17-help-fades", {"max_gain_ratio": max(ratios)}, record) if ratios else None
        out.append(Comparison("Fig. 17: on the complex map help fades quickly with noise (gain at 0.4 < half the gain at 0)",
                              "support robots become almost useless; VisBug worse than R1 alone", ours or "not run",
                              fholds,
                              "" if (not ratios or fholds) else "our helpers keep more of their gain under noise"))
    return out


#: the section's two columns (key, heading), as in the trail and collab-mcl sections
COLUMNS = (("paper_rules", "paper as written"), ("teamnav", "teamnav"))


def column_comparisons(by_col: dict[str, list[Comparison]]) -> list[Comparison]:
    """Each claim judged on both columns' runs (``{"paper_rules": [...], "teamnav": [...]}``, in the
    same order, from the same calls): for every claim its paper-as-written comparison
    (``column="paper"``, the verdict: every claim of claims/los-help.yaml is ``judged:
    paper_rules``), then its teamnav comparison (``column="teamnav"``, what our gap-fills give;
    not a verdict). Report models and ``report.json`` carry the column of each (FIDELITY §2).

    Raises
    ------
    ValueError
        The two columns name different claims (they must come from the same calls).
    """
    pr, tn = by_col["paper_rules"], by_col["teamnav"]
    if [c.claim for c in pr] != [c.claim for c in tn]:
        raise ValueError("the two columns' verdicts name different claims")
    out = []
    for a, b in zip(pr, tn):
        out.append(Comparison(a.claim, a.paper, a.ours, a.holds,
                              "; ".join(x for x in (a.differs, "the verdict (claims/los-help.yaml)") if x),
                              column="paper"))
        out.append(Comparison(b.claim, b.paper, b.ours, b.holds,
                              "; ".join(x for x in (b.differs, "our gap-fills beside the verdict, not judged") if x),
                              column="teamnav"))
    return out
