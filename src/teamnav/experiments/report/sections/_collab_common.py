"""Row helpers of the ``collab-mcl`` section: rows that ran, mean ± std, and error curves with a
95 % band over runs (Fox, Burgard, Kruppa & Thrun 2000).

Split from :mod:`.collab_mcl` (no behaviour change).
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
