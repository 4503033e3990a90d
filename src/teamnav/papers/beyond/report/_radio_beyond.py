"""The ``beyond`` section's block on a restricted radio for every system (ours).

Each of the four systems runs on its own scenario with the radio restricted, one case per
restriction (the named sweeps ``beyond-radio-los``, ``-collab-mcl``, ``-blazing``, ``-try``):

- **loss**: each delivery lost with ``p_loss`` 0 (the papers' radio), 0.3, 0.6, 0.9 and 1
  (no radio at all: the floor each system falls to);
- **range**: the radio reaches only robots within ``range_m`` (the LOS system: its own line of
  sight radio at 2 and 4 m instead of the scenario's 8 m, and a radio that reaches everyone,
  which the paper forbids, §1);
- **bandwidth**: one cap per system (:class:`~teamnav.sim.config.RadioConfig`'s
  ``bandwidth_bps``: a token bucket per sender, over-cap messages dropped at the sender), half
  the bytes per second each robot offers on tuning seeds 1000-1001, with a burst that holds the
  system's largest message (the sweep files give the numbers).

Headline metrics (lower or higher is better as marked):

=============================  ==============================================  ===============
system (scenario)              headline                                        better
=============================  ==============================================  ===============
LOS help (los-help-simple)     R1's motion steps per target, VisBug-21,        lower
                               R1..R4, the first 30 targets of task 1
Collaborative MCL              mean over the 8 robots of the time to localize  lower
(collab-mcl-hallway)           (error < 1.5 m), censored at the run's 300 s
Blazing a trail                units delivered per hour, 30-min runs           higher
(blazing-a-trail)
Try to see it my way           units delivered per hour, 30-min runs           higher
(try-to-see-it-my-way)
=============================  ==============================================  ===============

Claims (``claims/beyond.yaml``: ``radio-los``, ``radio-collab-mcl``, ``radio-blazing``,
``radio-try``), the same two rules per system, ours (no paper measures a degraded radio):
the headline at p_loss 0.3 keeps >= 90 % of the lossless one (``<m>_p03_mean`` against
``<m>_p0_mean``; for a lower-is-better metric, at most 1.111 x), and ``loss_reversals`` = 0:
along p_loss 0, 0.3, 0.6, 0.9, 1 no more lossy case is better than the one before it by more
than 2 standard errors of the per-seed paired difference (:func:`loss_reversals`).

Quick mode (CI): cases p0 and p0.9 of each system, seed 0, 3 LOS targets, 60-s MCL and 5-min
trail runs (eight short runs, about 1 CPU-min): the pipeline works; no verdict. Full mode: the
sweep files, seeds 0-9, 350 runs: about 1500 CPU-s on a 2-core EPYC (try 401, blazing 390,
collab-mcl 562, los 169; docs/report/beyond.md has the numbers, commit e8cee29, 2026-11-27).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Plot, Series, Table, Text
from teamnav.papers.trails.report import _trails as T

#: the loss cases, in order of p_loss
LOSS_CASES = (("p0", 0.0), ("p0.3", 0.3), ("p0.6", 0.6), ("p0.9", 0.9), ("p1", 1.0))
QUICK_CASES = ("p0", "p0.9")
#: a paired difference counts as a reversal beyond this many standard errors
REVERSAL_SE = 2.0


@dataclass(frozen=True)
class RadioSystem:
    """One system's sweep and headline.

    ``metric``: the store column; ``per_hour``: divide by the run's simulated hours (units);
    ``prefix``: the claim's metric prefix (``<prefix>_p0_mean``); ``ranges``: (case, range [m],
    label) of its range cases, the unrestricted one last with the x it is drawn at;
    ``quick_set``: quick-mode overrides; ``quick_s``: quick-mode duration [s] (None: the file's).
    """

    key: str
    title: str
    sweep: str
    claim: str
    metric: str
    label: str
    higher_is_better: bool
    per_hour: bool
    prefix: str
    ranges: tuple[tuple[str, float, str], ...]
    extra: tuple[str, ...]
    quick_s: float | None
    quick_set: tuple[tuple[str, object], ...] = ()
    fmt: str = "{:.1f}"


def _los_quick_targets() -> list:
    from teamnav.papers.los_help import tasks as L

    return L.task_targets_xy("simple", 1, 3)


SYSTEMS = (
    RadioSystem("los", "LOS help (Sgorbissa & Arkin; VisBug-21, R1..R4, 30 targets of task 1)", "beyond-radio-los",
                "radio-los", "los_steps_per_target", "steps per target", False, False, "spt",
                (("range-2m", 2.0, "LOS 2 m"), ("range-4m", 4.0, "LOS 4 m"), ("p0", 8.0, "LOS 8 m (the scenario's)")),
                ("broadcast", "bw-1000"), None, fmt="{:.0f}"),
    RadioSystem("collab-mcl", "Collaborative MCL (Fox et al.; 8 sonar robots, hallway, 300 s)",
                "beyond-radio-collab-mcl", "radio-collab-mcl", "loc_time_to_localize_s", "time to localize [s]", False,
                False, "ttl", (("range-2m", 2.0, "2 m"), ("range-4m", 4.0, "4 m"), ("p0", 6.0, "unlimited (drawn at 6 m)")),
                ("bw-64",), 60.0, fmt="{:.0f}"),
    RadioSystem("blazing", "Blazing a trail (Vaughan et al. 2000; blazing-trail-v1, 30 min)", "beyond-radio-blazing",
                "radio-blazing", "units_total", "units per hour", True, True, "units",
                (("range-2m", 2.0, "2 m"), ("range-5m", 5.0, "5 m"), ("range-10m", 10.0, "10 m"),
                 ("p0", 40.0, "unlimited (drawn at 40 m)")), ("bw-10",), 300.0),
    RadioSystem("try", "Try to see it my way (Vaughan et al. 2002; trail-share-v1, 30 min)", "beyond-radio-try",
                "radio-try", "units_total", "units per hour", True, True, "units",
                (("range-2m", 2.0, "2 m"), ("range-5m", 5.0, "5 m"), ("range-10m", 10.0, "10 m"),
                 ("p0", 40.0, "unlimited (drawn at 40 m)")), ("bw-30",), 300.0),
)


def headline(rows: list[dict], system: RadioSystem) -> dict[int, float]:
    """Seed -> the system's headline value of each finished row (units per hour for the trail
    systems: ``units_total`` over the run's simulated hours)."""
    out: dict[int, float] = {}
    for r in rows:
        v = T.values([r], system.metric)
        if not v.size:
            continue
        x = float(v[0])
        if system.per_hour:
            t = T.values([r], "sim_time_s")
            if not t.size or t[0] <= 0:
                continue
            x *= 3600.0 / float(t[0])
        out[int(r.get("seed"))] = x
    return out


def loss_reversals(by_case: dict[str, dict[int, float]], higher_is_better: bool,
                   cases: tuple[str, ...] = tuple(c for c, _ in LOSS_CASES)) -> int:
    """Consecutive pairs of ``cases`` (ordered by p_loss) where the lossier one is *better* by
    more than :data:`REVERSAL_SE` standard errors of the per-seed paired difference (seeds run
    in both; a pair with fewer than 2 common seeds counts nothing).

    >>> loss_reversals({"p0": {0: 10.0, 1: 11.0, 2: 12.0}, "p0.3": {0: 14.0, 1: 15.0, 2: 16.5}}, True, ("p0", "p0.3"))
    1
    >>> loss_reversals({"p0": {0: 10.0, 1: 11.0, 2: 12.0}, "p0.3": {0: 14.0, 1: 15.0, 2: 16.5}}, False, ("p0", "p0.3"))
    0
    """
    n = 0
    for a, b in zip(cases, cases[1:]):
        A, B = by_case.get(a, {}), by_case.get(b, {})
        common = sorted(set(A) & set(B))
        if len(common) < 2:
            continue
        d = np.array([B[s] - A[s] for s in common])  # lossier minus less lossy
        if not higher_is_better:
            d = -d
        se = float(d.std(ddof=1) / np.sqrt(d.size))
        if d.mean() > REVERSAL_SE * se and d.mean() > 0:
            n += 1
    return n


def claim_values(by_case: dict[str, dict[int, float]], system: RadioSystem) -> dict[str, float]:
    """The claim's metrics: ``<prefix>_p0_mean``, ``<prefix>_p03_mean`` (NaN when not run) and
    ``loss_reversals``."""
    def m(case):
        v = list(by_case.get(case, {}).values())
        return float(np.mean(v)) if v else float("nan")

    return {f"{system.prefix}_p0_mean": m("p0"), f"{system.prefix}_p03_mean": m("p0.3"),
            "loss_reversals": float(loss_reversals(by_case, system.higher_is_better))}


def _spread(v: np.ndarray, fmt: str) -> str:
    if v.size == 0:
        return "n/a"
    q1, med, q3 = np.percentile(v, [25, 50, 75])
    return f"{T.msd(v, fmt)}; median {fmt.format(med)} [{fmt.format(q1)}, {fmt.format(q3)}]"


def _radio_text(case: str, system: RadioSystem) -> str:
    if case.startswith("p"):
        base = "LOS 8 m" if system.key == "los" else "all robots"
        return f"{base}, p_loss {case[1:]}" + (" (no radio)" if case == "p1" else " (the paper's)" if case == "p0" else "")
    if case.startswith("range-"):
        return ("LOS " if system.key == "los" else "") + f"range {case[6:]}"
    if case.startswith("bw-"):
        return f"cap {case[3:]} B/s per sender"
    if case == "broadcast":
        return "reaches everyone (beyond the paper's LOS rule)"
    return case


def _system_block(ctx, system: RadioSystem) -> list:
    from teamnav.experiments.claims import history_text, judge, load_claims, rule_text
    from teamnav.experiments.sweep import load_sweep

    quick = bool(ctx.quick)
    spec = load_sweep(system.sweep)
    if quick:
        kw: dict = {"seeds": [0]}
        if system.quick_s is not None:
            kw["duration_s"] = system.quick_s
        if system.key == "los":
            kw["set"] = {"robots.0.params.targets_xy": _los_quick_targets()}
        res = ctx.sweep(T.case_spec(system.sweep, QUICK_CASES), **kw)
        labels = list(QUICK_CASES)
    else:
        res = ctx.sweep(system.sweep)
        labels = [str(c.get("case")) for c in spec.cases]
    rows = T.by_case(T.ok(res))
    if not rows:
        return [Missing(f"{system.title}: restricted-radio runs", f"sweep {res.name} finished none of {res.total} trials")]
    by_case = {lab: headline(rows.get(lab, []), system) for lab in labels}
    base = np.array(list(by_case.get("p0", {}).values()))
    table = []
    for lab in labels:
        v = np.array(list(by_case[lab].values()))
        r = rows.get(lab, [])
        ratio = (float(v.mean() / base.mean()) if v.size and base.size and base.mean() != 0 else float("nan"))
        sent, deliv = T.values(r, "messages_sent"), T.values(r, "messages_delivered")
        table.append([lab, _radio_text(lab, system), _spread(v, system.fmt),
                      "—" if lab == "p0" or not np.isfinite(ratio) else f"{ratio:.2f}",
                      f"{sent.mean():.0f}" if sent.size else "n/a", f"{deliv.mean():.0f}" if deliv.size else "n/a"])
    extra = ""
    if system.key == "collab-mcl":
        fin = {lab: T.values(rows.get(lab, []), "loc_final_localized_fraction") for lab in labels}
        extra = " Robots localized at the end (share, mean over runs): " + ", ".join(
            f"{lab} {fin[lab].mean():.2f}" for lab in labels if fin[lab].size) + "."
    if system.key == "los":
        fin = {lab: T.values(rows.get(lab, []), "los_finished") for lab in labels}
        extra = " Tasks finished: " + ", ".join(f"{lab} {int(fin[lab].sum())}/{fin[lab].size}" for lab in labels
                                                 if fin[lab].size) + "."
    seeds = sorted({int(r.get("seed")) for rs in rows.values() for r in rs})
    blocks: list = [Table(
        f"{system.title}: {system.label} under a restricted radio",
        ["case", "radio", f"{system.label}: mean ± sd (n); median [IQR]", "ratio of means to p0",
         "messages sent (mean per run)", "deliveries (mean per run)"], table,
        note=f"sweep {system.sweep}" + (" (quick: two cases, one seed, short runs; not the result)" if quick else "")
             + f", seeds {', '.join(map(str, seeds)) if len(seeds) < 4 else f'{seeds[0]}-{seeds[-1]}'}; "
             + ("higher" if system.higher_is_better else "lower") + " is better." + extra)]
    pts = [(p, by_case[c]) for c, p in LOSS_CASES if by_case.get(c)]
    series = []
    if len(pts) > 1:
        series.append(_curve("against p_loss", pts))
    rpts = [(x, by_case[c]) for c, x, _ in system.ranges if by_case.get(c)]
    plots = []
    if series:
        plots.append(Plot(f"{system.title}: {system.label} against p_loss", "p_loss (1: no radio)", system.label, series,
                          caption="mean over seeds, band 25-75 %; p_loss 0 is the paper's radio."))
    if len(rpts) > 1:
        plots.append(Plot(f"{system.title}: {system.label} against radio range", "radio range [m]", system.label,
                          [_curve("against range", rpts)],
                          caption="mean over seeds, band 25-75 %; " + "; ".join(f"{x:g} m: {t}" for _, x, t in system.ranges)
                                  + "."))
    blocks += plots
    claim = load_claims("beyond")[system.claim]
    vals = claim_values(by_case, system)
    if quick:
        holds, how = None, "not judged in quick mode (one seed, short runs)"
    else:
        holds, how = judge(claim, vals, float(spec.duration_s or 0.0) if system.key != "los" else None)
    blocks.append(Comparison(
        f"{claim.title} ({rule_text(claim)})",
        f"{claim.paper_number} ({claim.statement.section}: \u201c{claim.statement.quote}\u201d)",
        how + f"; radio off (p_loss 1): {_mean_text(by_case.get('p1'), system.fmt)} against "
              f"{_mean_text(by_case.get('p0'), system.fmt)} lossless",
        holds, "our rule (no paper measures a degraded radio). History of the rule: " + history_text(claim)))
    return blocks


def _mean_text(d: dict[int, float] | None, fmt: str) -> str:
    return "n/a" if not d else fmt.format(float(np.mean(list(d.values()))))


def _curve(label: str, pts: list[tuple[float, dict[int, float]]]) -> Series:
    pts = sorted(pts, key=lambda p: p[0])
    vs = [np.array(list(d.values())) for _, d in pts]
    return Series(label, [p for p, _ in pts], [float(v.mean()) for v in vs], [float(np.percentile(v, 25)) for v in vs],
                  [float(np.percentile(v, 75)) for v in vs], style="line+points")


def restricted_radio(ctx) -> list:
    """The block: one table, curves and a verdict per system (module docstring)."""
    missing = T.brains_missing(["los-explorer-v1", "los-helper-v1", "mcl-wander-v1", "blazing-trail-v1",
                                "trail-share-v1"])
    if missing is not None:
        return [missing]
    blocks: list = [Text(
        "The papers' future work, a restricted radio for every system (Blazing §6 names \u201crestricting "
        "the communication range\u201d): each system's headline metric as deliveries are lost (p_loss 0-1, where 1 "
        "is no radio), as the radio's range shrinks, and under one bandwidth cap per system (ours: a token bucket "
        "per sender, over-cap messages dropped, RadioConfig.bandwidth_bps; half of what each robot offers, measured "
        "on tuning seeds). Shorter tasks than the papers' (30 LOS targets, 300-s MCL runs, 30-min trail runs) keep "
        "the full block cheap; the verdict rules are ours, fixed before the runs.")]
    for system in SYSTEMS:
        blocks += _system_block(ctx, system)
    return blocks
