"""The ``collab-mcl`` section's §7.2 "delayed integration" comparison (Fox, Burgard, Kruppa & Thrun 2000):
unsure detections integrated at once (§3.2, the paper's rule), dropped, or delayed until the observer's
belief is concentrated, on the co-travel case of the symmetric hallway (sweep ``collab-mcl-cotravel``:
4 sonar robots start together in hallway C heading north). Teamnav column only: ``paper_rules``
keeps the paper's "integrate at once" and refuses the other two.

Claims ``delayed-integration`` (delay against integrate) and ``delayed-vs-drop`` (delay against drop)
in ``claims/collab-mcl.yaml``; metrics by :func:`cotravel_values`. Full mode only (4 cases x 20
seeds of 400 s, about 7 CPU min); quick mode says so.
"""

from __future__ import annotations

import math

import numpy as np

from teamnav.experiments.report.model import Comparison, Missing, Table
from teamnav.papers.collab_mcl.report._collab_common import _metric, _ms

#: the sweep's cases, in table order: (case label, what the observer does with an unsure detection)
CASES = (("alone", "no detections used (collaborate off)"),
         ("integrate", "sent at once (§3.2, the paper's rule)"),
         ("drop", "dropped (heaviest cluster below 0.6 or wider than 1 m)"),
         ("delay", "kept, sent once concentrated (>= 0.6, <= 1 m), applied at its time (§7.2)"))

SWEEP = "collab-mcl-cotravel"


def _case(row: dict) -> str | None:
    return row["params"].get("case")


def _paired(a: dict[int, float], b: dict[int, float]) -> tuple[float, float, int, int]:
    """Per-seed ``a - b``: mean, standard error, pairs, pairs where ``a`` is lower."""
    d = np.array([a[s] - b[s] for s in sorted(set(a) & set(b))], dtype=float)
    if d.size == 0:
        return float("nan"), float("nan"), 0, 0
    se = float(d.std(ddof=1) / math.sqrt(d.size)) if d.size > 1 else float("nan")
    return float(d.mean()), se, int(d.size), int((d < 0).sum())


def cotravel_values(rows: list[dict]) -> dict[str, float]:
    """Claim metrics from the co-travel runs (ok rows of every case).

    Per case ``c``: ``{c}_ttl_mean_s`` (mean over runs of the per-run mean time to localize,
    censored at the duration), ``{c}_final_localized`` (mean share of robots localized at the end),
    ``{c}_runs``. Paired by seed (same start poses): ``delay_paired_mean_s`` / ``_se_s`` /
    ``_upper_s`` (mean + 2 s.e.) of delay - integrate, ``delay_faster_pairs``, ``n_pairs``; the
    same against drop (``delay_vs_drop_*``) and integrate - alone (``integrate_vs_alone_*``).
    """
    nan = float("nan")
    ttl: dict[str, dict[int, float]] = {c: {} for c, _ in CASES}
    loc: dict[str, dict[int, float]] = {c: {} for c, _ in CASES}
    for r in rows:
        c, m = _case(r), r.get("metrics") or {}
        if c in ttl and isinstance(m.get("loc_time_to_localize_s"), (int, float)):
            ttl[c][r["seed"]] = float(m["loc_time_to_localize_s"])
            loc[c][r["seed"]] = float(m.get("loc_final_localized_fraction", nan))
    out: dict[str, float] = {}
    for c, _ in CASES:
        out[f"{c}_ttl_mean_s"] = float(np.mean(list(ttl[c].values()))) if ttl[c] else nan
        out[f"{c}_final_localized"] = float(np.nanmean(list(loc[c].values()))) if loc[c] else nan
        out[f"{c}_runs"] = float(len(ttl[c]))
    for key, a, b in (("delay", "delay", "integrate"), ("delay_vs_drop", "delay", "drop"),
                      ("drop_vs_integrate", "drop", "integrate"), ("integrate_vs_alone", "integrate", "alone")):
        mean, se, n, lower = _paired(ttl[a], ttl[b])
        out.update({f"{key}_paired_mean_s": mean, f"{key}_paired_se_s": se, f"{key}_paired_upper_s": mean + 2.0 * se,
                    f"{key}_faster_pairs": float(lower), f"{key}_n_pairs": float(n)})
    return out


def _delayed(ctx, out: dict | None = None) -> list:
    """Blocks of claims ``delayed-integration`` and ``delayed-vs-drop`` (teamnav column); their metrics
    go into ``out["teamnav"][id]`` and an empty dict into ``out["paper_rules"][id]`` (not run there)."""
    from teamnav.experiments.claims import judge, load_claims, rule_text
    from teamnav.papers.collab_mcl.report._collab_common import _ok

    if ctx.quick:
        return [Missing("§7.2 delayed integration (co-travel hallway)", "measured in the full report only "
                        "(4 cases x 20 runs of 400 s, about 7 CPU min)")]
    claims = load_claims("collab-mcl")
    seeds = claims["delayed-integration"].seed_list
    rows = _ok(ctx.sweep(SWEEP, seeds=seeds))
    vals = cotravel_values(rows)
    for col in (out or {}):
        for cid in ("delayed-integration", "delayed-vs-drop"):
            out[col][cid] = vals if col == "teamnav" else {}
    table = []
    for c, what in CASES:
        rs = [r for r in rows if _case(r) == c]
        table.append([c, what, len(rs), _ms(_metric(rs, "loc_time_to_localize_s")),
                      _ms(_metric(rs, "loc_final_localized_fraction")), _ms(_metric(rs, "loc_censored")),
                      _ms(_metric(rs, "loc_syncs"))])

    def paired(key: str, a: str, b: str) -> str:
        return (f"{a} - {b}: {vals[f'{key}_paired_mean_s']:+.0f} ± {vals[f'{key}_paired_se_s']:.0f} s (s.e.), "
                f"{a} faster in {int(vals[f'{key}_faster_pairs'])}/{int(vals[f'{key}_n_pairs'])} seeds")

    blocks: list = [Table("§7.2 delayed integration, co-travel hallway (4 sonar robots start together in hallway C; "
                          "mean ± std over runs)",
                          ["case", "unsure detections", "runs", "time to localize [s]", "localized at the end",
                           "robots never localized", "syncs"], table,
                          note=f"Seeds {seeds[0]}-{seeds[-1]}, 400 s, teamnav's hallway settings otherwise. Paired by "
                               f"seed: {paired('delay', 'delay', 'integrate')}; "
                               f"{paired('delay_vs_drop', 'delay', 'drop')}; "
                               f"{paired('drop_vs_integrate', 'drop', 'integrate')}; "
                               f"{paired('integrate_vs_alone', 'integrate', 'alone')}.")]
    for cid, title in (("delayed-integration", "§7.2: delayed integration against integrating at once"),
                       ("delayed-vs-drop", "§7.2: delayed integration against dropping unsure detections")):
        c = claims[cid]
        ok, how = judge(c, vals)
        blocks.append(Comparison(title, "stated, not measured (\"can be much better if it is done retrospectively\")",
                                 f"time to localize: integrate {vals['integrate_ttl_mean_s']:.0f} s, drop "
                                 f"{vals['drop_ttl_mean_s']:.0f} s, delay {vals['delay_ttl_mean_s']:.0f} s; localized "
                                 f"at the end {vals['integrate_final_localized']:.0%} / "
                                 f"{vals['drop_final_localized']:.0%} / {vals['delay_final_localized']:.0%}",
                                 ok, f"Teamnav column only (paper_rules integrates at once). Rule (claims/collab-mcl.yaml, "
                                     f"{cid}, judged on teamnav): {rule_text(c)}; {how}. Seeds {seeds[0]}-{seeds[-1]}.",
                                 column="teamnav"))
    return blocks
