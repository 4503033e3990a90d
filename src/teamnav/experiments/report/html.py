"""The report as one self-contained HTML file (no scripts, no external links or images).

Layout: a header (what, when, quick or full), a table of contents with each section's status
and how many of its claims hold, then per section: the title, the paper file, a summary table
of every :class:`~teamnav.experiments.report.model.Comparison` (claim | paper | ours | holds
✓ ✗ — | where we differ), then the other blocks in order: tables, figures (PNG embedded as
``data:image/png;base64`` URIs, drawn by :mod:`teamnav.viz.report_figures`), paragraphs, and
missing blocks as grey boxes "not measured: WHAT — WHY", never as numbers. A footer gives
the teamnav version, the git commit when the package runs from a checkout, the date, the mode
and, per section, its wall time and how many trials it ran and reused.

All text from sections is escaped (``html.escape``, quotes included: names of scenarios, robot
groups, places and events may hold anything), and the page's Content-Security-Policy
(:data:`CSP`) allows no script at all and nothing from outside, only ``data:`` images. A
figure that cannot be drawn becomes a missing block naming the error, so one bad figure never
loses the report.
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import math
import subprocess
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from teamnav.experiments.report.model import COLUMNS, Comparison, Ledger, MapView, Missing, Plot, Precondition, Table, Text

__all__ = ["CSP", "git_commit", "render_report"]

_CSS = """
body { font-family: system-ui, -apple-system, 'Segoe UI', Roboto, sans-serif; margin: 0 auto; max-width: 1100px;
       padding: 1.2em 1.6em; color: #1f2328; line-height: 1.45; }
h1 { margin-bottom: 0.2em; } h2 { border-bottom: 2px solid #d0d7de; padding-bottom: 0.2em; margin-top: 2.2em; }
h3 { margin-bottom: 0.3em; }
.sub { color: #59636e; margin-top: 0; }
table { border-collapse: collapse; margin: 0.6em 0 1.2em; font-size: 0.92em; }
th, td { border: 1px solid #d0d7de; padding: 0.3em 0.6em; vertical-align: top; text-align: left; }
th { background: #f6f8fa; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
td.holds { text-align: center; font-weight: bold; font-size: 1.1em; }
.yes { color: #1a7f37; } .no { color: #cf222e; } .na { color: #8c959f; }
.missing { background: #eaeef2; border: 1px dashed #8c959f; color: #424a53; padding: 0.6em 0.9em;
           margin: 0.8em 0; border-radius: 4px; }
.missing b { color: #24292f; }
.error { border-color: #cf222e; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #eaeef2; }
figcaption, .note { color: #59636e; font-size: 0.9em; }
.status-ok { color: #1a7f37; } .status-missing { color: #8c959f; } .status-error { color: #cf222e; } .status-pending { color: #9a6700; }
footer { margin-top: 3em; border-top: 1px solid #d0d7de; color: #59636e; font-size: 0.88em; }
nav ol { padding-left: 1.4em; }
"""

#: the report's Content-Security-Policy: no scripts, nothing fetched, images only as data: URIs
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; base-uri 'none'; form-action 'none'"

_HOLDS = {True: ("✓", "yes", "holds"), False: ("✗", "no", "does not hold"), None: ("—", "na", "not measured")}


def _e(text: Any) -> str:
    return html.escape(str(text), quote=True)


def git_commit() -> str | None:
    """The short commit of the checkout teamnav runs from (``+dirty`` when modified), or None."""
    here = Path(__file__).resolve().parent
    try:
        top = subprocess.run(["git", "rev-parse", "--show-toplevel"], cwd=here, capture_output=True, text=True, timeout=5)
        # only teamnav's own checkout (an installed copy may sit inside some other repository)
        if top.returncode != 0 or not here.is_relative_to(Path(top.stdout.strip()).resolve() / "src" / "teamnav"):
            return None
        sha = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=here, capture_output=True, text=True, timeout=5)
        if sha.returncode != 0:
            return None
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--untracked-files=no"], cwd=here, capture_output=True, text=True, timeout=10
        )
        return sha.stdout.strip() + ("+dirty" if dirty.returncode == 0 and dirty.stdout.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return None


def _cell(value: Any) -> tuple[str, bool]:
    """A table cell as text, and whether it is a number (right-aligned)."""
    if value is None:
        return "—", False
    if isinstance(value, bool):
        return ("✓" if value else "✗"), False
    if isinstance(value, int):
        return f"{value:d}", True
    if isinstance(value, float):
        if math.isnan(value):
            return "—", False
        return f"{value:.4g}", True
    if isinstance(value, np.integer):  # numpy scalars
        return f"{int(value):d}", True
    if isinstance(value, np.floating):
        return _cell(float(value))
    return str(value), False


def _missing(what: str, why: str, error: bool = False) -> str:
    cls = "missing error" if error else "missing"
    return f'<div class="{cls}"><b>not measured:</b> {_e(what)} — {_e(why)}</div>'


def _table(block: Table) -> str:
    out = []
    if block.title:
        out.append(f"<h3>{_e(block.title)}</h3>")
    out.append("<table><thead><tr>" + "".join(f"<th>{_e(c)}</th>" for c in block.columns) + "</tr></thead><tbody>")
    for row in block.rows:
        cells = []
        for v in row:
            text, num = _cell(v)
            cells.append(f'<td class="num">{_e(text)}</td>' if num else f"<td>{_e(text)}</td>")
        out.append("<tr>" + "".join(cells) + "</tr>")
    out.append("</tbody></table>")
    if block.note:
        out.append(f'<p class="note">{_e(block.note)}</p>')
    return "\n".join(out)


def _figure(png: bytes, title: str, caption: str) -> str:
    data = base64.b64encode(png).decode("ascii")
    cap = f"<figcaption>{_e(caption)}</figcaption>" if caption else ""
    return f'<figure><img alt="{_e(title)}" src="data:image/png;base64,{data}">{cap}</figure>'


def _draw(block: Plot | MapView) -> str:
    from teamnav.viz.report_figures import mapview_png, plot_png

    try:
        png = plot_png(block) if isinstance(block, Plot) else mapview_png(block)
    except Exception as exc:  # noqa: BLE001 - one bad figure must not lose the report
        return _missing(f"figure {block.title!r}", f"it could not be drawn: {type(exc).__name__}: {exc}", error=True)
    return _figure(png, block.title, block.caption)


def _comparisons(comps: Sequence[Comparison]) -> str:
    if not comps:
        return ""
    with_column = any(c.column for c in comps)
    rows = []
    for c in comps:
        mark, cls, word = _HOLDS.get(c.holds, _HOLDS[None])
        column = f"<td>{_e(COLUMNS.get(c.column, ''))}</td>" if with_column else ""
        rows.append(
            f"<tr><td>{_e(c.claim)}</td>{column}<td>{_e(c.paper)}</td><td>{_e(c.ours)}</td>"
            f'<td class="holds {cls}" title="{word}">{mark}</td><td>{_e(c.differs)}</td></tr>'
        )
    column_head = "<th>column</th>" if with_column else ""
    head = f"<tr><th>claim</th>{column_head}<th>paper</th><th>ours</th><th>holds</th><th>where we differ</th></tr>"
    return f'<table class="comparisons"><thead>{head}</thead><tbody>{"".join(rows)}</tbody></table>'


def _ledger(block: Ledger) -> str:
    rows = [[COLUMNS[r.column], r.name, r.value, r.source, r.ref] for r in block.rows]
    return _table(Table(title=block.title, columns=["column", "parameter", "value", "source", "where from"],
                        rows=rows, note=block.note))


def _precondition(block: Precondition) -> str:
    mark, cls, word = _HOLDS.get(block.holds, _HOLDS[None])
    needs = f" (needed by {', '.join(block.claims)})" if block.claims else ""
    return (f'<p class="precondition"><b>precondition</b>{_e(needs)}: {_e(block.what)} — checked on {_e(block.seeds)}: '
            f'{_e(block.result)} <span class="holds {cls}" title="{word}">{mark}</span></p>')


def _verdicts(comps: Sequence[Comparison]) -> str:
    if not comps:
        return "no claims compared"
    yes = sum(c.holds is True for c in comps)
    no = sum(c.holds is False for c in comps)
    na = sum(c.holds is None for c in comps)
    parts = [f"{yes}/{len(comps)} claims hold"]
    if no:
        parts.append(f"{no} do not")
    if na:
        parts.append(f"{na} not measured")
    return ", ".join(parts)


def _section(s: Any) -> str:
    """A section's HTML, drawn once per outcome (cached on it: the report is rewritten after
    every section, and figures are the slow part)."""
    cached = getattr(s, "html_cache", None)
    if cached:
        return cached
    text = _section_html(s)
    if hasattr(s, "html_cache") and s.status != "pending":
        s.html_cache = text
    return text


def _section_html(s: Any) -> str:
    out = [f'<section id="sec-{_e(s.key)}">', f"<h2>{_e(s.title)}</h2>"]
    paper = f"paper: <code>{_e(s.paper)}</code>" if s.paper else "paper: —"
    out.append(f'<p class="sub">{paper} · section <code>{_e(s.key)}</code> · '
               f'<span class="status-{_e(s.status)}">{_e(s.status)}</span> · {s.wall_s:.1f} s</p>')
    if s.summary:
        out.append(f"<p>{_e(s.summary)}</p>")
    out.append(_comparisons(s.comparisons))
    for block in s.blocks:
        if isinstance(block, Comparison):
            continue  # shown in the summary table above
        if isinstance(block, Missing):
            out.append(_missing(block.what, block.why, error=s.status == "error"))
        elif isinstance(block, Table):
            out.append(_table(block))
        elif isinstance(block, Ledger):
            out.append(_ledger(block))
        elif isinstance(block, Precondition):
            out.append(_precondition(block))
        elif isinstance(block, (Plot, MapView)):
            out.append(_draw(block))
        elif isinstance(block, Text):
            out.append("".join(f"<p>{_e(p.strip())}</p>" for p in str(block.text).split("\n\n") if p.strip()))
    if s.status == "error" and s.traceback:
        out.append(f"<details><summary>traceback</summary><pre>{_e(s.traceback)}</pre></details>")
    out.append("</section>")
    return "\n".join(x for x in out if x)


def render_report(sections: Sequence[Any], meta: dict[str, Any]) -> str:
    """The report's HTML text.

    Parameters
    ----------
    sections : list of SectionOutcome
        From :func:`teamnav.experiments.report.run_report`, in order.
    meta : dict
        ``quick`` (bool), ``executor``, ``workers``, ``address``, ``wall_s``.

    Returns
    -------
    str
        One HTML document; images are data URIs, so the file stands alone.
    """
    from teamnav import __version__

    mode = "quick (CI: few seeds, short runs)" if meta.get("quick") else "full reproduction"
    now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    toc = []
    for s in sections:
        toc.append(
            f'<li><a href="#sec-{_e(s.key)}">{_e(s.title)}</a> — <span class="status-{_e(s.status)}">{_e(s.status)}</span>'
            f"; {_e(_verdicts(s.comparisons))}</li>"
        )
    body = "\n".join(_section(s) for s in sections)
    commit = git_commit()
    workers = meta.get("workers") or "all CPUs"
    executor = meta.get("executor", "local") + (f" at {meta['address']}" if meta.get("address") else "")
    times = "".join(
        f"<tr><td>{_e(s.key)}</td><td>{_e(s.status)}</td><td class='num'>{s.wall_s:.1f}</td>"
        f"<td class='num'>{sum(w.get('run', 0) for w in s.sweeps)}</td><td class='num'>{sum(w.get('reused', 0) for w in s.sweeps)}</td></tr>"
        for s in sections
    )
    footer = (
        f"<footer><p>teamnav {_e(__version__)}" + (f" · git {_e(commit)}" if commit else "") + f" · {_e(now)} · {_e(mode)} · "
        f"executor {_e(executor)}, workers {_e(workers)} · total {float(meta.get('wall_s', 0.0)):.1f} s</p>"
        f"<table><thead><tr><th>section</th><th>status</th><th>wall time [s]</th><th>trials run</th><th>trials reused</th></tr></thead><tbody>{times}</tbody></table>"
        "</footer>"
    )
    return (
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
        f"<meta http-equiv=\"Content-Security-Policy\" content=\"{_e(CSP)}\">"
        "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
        f"<title>teamnav report ({'quick' if meta.get('quick') else 'full'})</title><style>{_CSS}</style></head><body>\n"
        f"<h1>teamnav: the four papers, reproduced</h1><p class=\"sub\">{_e(mode)} · {_e(now)}</p>\n"
        "<p>Each section puts a paper's claims beside our measurements. We reproduce trends and ratios, not the "
        "authors' exact numbers; a claim we did not measure is marked — and shown as missing, never as a number.</p>\n"
        f"<nav><h3>Contents</h3><ol>{''.join(toc)}</ol></nav>\n{body}\n{footer}\n</body></html>\n"
    )
