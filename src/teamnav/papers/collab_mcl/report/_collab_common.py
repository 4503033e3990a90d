"""Row helpers of the ``collab-mcl`` section: rows that ran, mean ± std, and error curves with a
95 % band over runs (Fox, Burgard, Kruppa & Thrun 2000); and its two columns ("paper as written",
"teamnav"): a sweep's rows per column, a claim's seeds, verdicts and rule text.

Split from :mod:`.section` (no behaviour change).
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from teamnav.experiments.report.model import Series


def _ok(result) -> list[dict[str, Any]]:
    return [r for r in result.rows() if r.get("status") == "ok" and r.get("metrics")]


def _param(row: dict, key: str, default=None):
    return row["params"].get(key, default)


def _ms(values) -> str:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        return "n/a"
    sd = float(v.std(ddof=1)) if v.size > 1 else 0.0
    return f"{v.mean():.1f} ± {sd:.1f}"


def _band(rows: list[dict], pick) -> tuple[list[float], list[float], list[float], list[float]] | None:
    """Mean and 95 % confidence band over runs of a per-run error series on a common time grid."""
    curves = []
    for r in rows:
        s = r["metrics"].get("loc_error_series")
        if not s:
            continue
        d = json.loads(s)
        y = pick(d)
        if y is None:
            continue
        t = np.asarray(d["t_s"], dtype=float)
        y = np.asarray([np.nan if v is None else v for v in y], dtype=float)
        curves.append((t, y))
    if not curves:
        return None
    t_end = min(c[0][-1] for c in curves)
    grid = np.linspace(0.0, t_end, min(120, max(2, len(curves[0][0]))))
    ys = np.array([np.interp(grid, t, y) for t, y in curves])
    n = ys.shape[0]
    mean = np.nanmean(ys, axis=0)
    if n > 1:
        from scipy.stats import t as student

        half = student.ppf(0.975, n - 1) * np.nanstd(ys, axis=0, ddof=1) / math.sqrt(n)
    else:
        half = np.zeros_like(mean)
    return grid.tolist(), mean.tolist(), (mean - half).tolist(), (mean + half).tolist()


def _series(label: str, rows: list[dict], pick) -> list[Series]:
    b = _band(rows, pick)
    return [] if b is None else [Series(label, b[0], b[1], lo=b[2], hi=b[3])]


def _metric(rows: list[dict], key: str) -> list[float]:
    return [r["metrics"][key] for r in rows if isinstance(r["metrics"].get(key), (int, float))]


# ---------------------------------------------------------------------------- columns and claims
#: the two columns: (key, heading)
COLUMNS = (("paper_rules", "paper as written"), ("teamnav", "teamnav"))
HEAD = dict(COLUMNS)


def _seeds(ctx, claim) -> list[int]:
    """The claim's report seeds (its quick seeds in quick mode)."""
    from teamnav.experiments.claims import _parse_seeds

    return _parse_seeds(claim.quick_seeds) if ctx.quick and claim.quick_seeds else claim.seed_list


def _col_sweep(ctx, col: str, sweep_name: str, **kw) -> list[dict]:
    """Finished rows of sweep ``sweep_name`` in column ``col``: ``"teamnav"`` as the scenario is,
    ``"paper_rules"`` with every mcl-wander-v1 group at ``paper_rules: true`` (the params those
    rules set dropped from the scenario; :func:`teamnav.papers.trails.report._trails.paper_rules_spec`), in its own folder."""
    if col == "paper_rules":
        from teamnav.papers.trails.report._trails import paper_rules_spec

        if kw.get("name"):
            kw["name"] = f"{kw['name']}-paper-rules"
        return _ok(ctx.sweep(paper_rules_spec(sweep_name), **kw))
    return _ok(ctx.sweep(sweep_name, **kw))


def _verdicts(claim, vals: dict[str, dict], out: dict | None = None) -> dict[str, tuple]:
    """``{column: judge(claim, that column's values)}``; each column of ``out`` (the section's
    ``{column: {claim id: metrics}}``) also gets its values as ``out[column][claim.id]``."""
    from teamnav.papers.collab_mcl.report._collab_fidelity import gated_judge

    verdicts = {col: gated_judge(claim, vals[col]) for col, _ in COLUMNS}
    for col in (out or {}):
        out[col][claim.id] = vals[col]
    return verdicts


def judged_column(claim) -> str:
    """The report model's column key (``"paper"`` / ``"teamnav"``) of the column a claim is judged on."""
    return "paper" if claim.judged == "paper_rules" else "teamnav"


def _rule_text(claim, verdicts: dict[str, tuple], n_text: str) -> str:
    """The rule, its reading on the judged column and on the other one, and the runs judged."""
    from teamnav.experiments.claims import rule_text

    other = "teamnav" if claim.judged == "paper_rules" else "paper_rules"
    return (f" Rule (claims/collab-mcl.yaml, {claim.id}, judged on {HEAD[claim.judged]}): {rule_text(claim)}; "
            f"{verdicts[claim.judged][1]}. {HEAD[other]}: {verdicts[other][1]}. {n_text}")
