"""``teamnav report``: run (or reuse) the papers' sweeps and write a self-contained HTML report.

The command only parses its options and calls :func:`teamnav.experiments.report.run_report`
(STYLE habit 17); ``teamnav.cli`` registers it as ``report``.

Exit status: 0 when every section built; 1 when some section raised (the report is written
anyway, with that section shown as missing and its error); 2 for bad input (unknown section,
with "did you mean"; an ``--out`` folder that is not a report's; a bad executor option), with
one message and no traceback.

Examples
--------
::

    teamnav report all --quick --out reports/quick          # what CI runs (minutes)
    teamnav report all --out reports/full                   # the full reproduction
    teamnav report collab-mcl --out reports/full --workers 16
    teamnav report all --out reports/full --executor ray --address auto
"""

from __future__ import annotations

from pathlib import Path
from typing import List, Optional

import typer
from rich.console import Console

__all__ = ["EXIT_BAD_INPUT", "EXIT_SECTION_FAILED", "QUICK_NOTE", "report_command", "section_line"]

#: exit status for bad input
EXIT_BAD_INPUT = 2
#: exit status when the report was written but some section raised
EXIT_SECTION_FAILED = 1
#: said beside a quick report's claim count: its sweeps are too small for verdicts
QUICK_NOTE = "quick mode: indicative only, small sample; run without --quick for the verdicts"


def section_line(section, quick: bool) -> str:
    """One section's line: key, status, wall time, claims that hold (and how many were not
    judged: a rule that needs full-length runs, a metric not measured); a quick report says so on it."""
    # a section with two columns (FIDELITY §1) is judged on its paper column; teamnav's are beside it
    judged = [c for c in section.comparisons if c.column != "teamnav"]
    holds = sum(c.holds is True for c in judged)
    unjudged = sum(c.holds is None for c in judged)
    line = f"  {section.key:<22} {section.status:<8} {section.wall_s:7.1f} s  {holds}/{len(judged)} claims hold"
    if unjudged:
        line += f", {unjudged} not judged"
    if quick:
        line += f" ({QUICK_NOTE})"
    return line + (f"  ({section.error})" if section.error else "")


def report_command(
    experiments: List[str] = typer.Argument(
        ..., metavar="EXPERIMENT|all", help="Section keys (los-help, collab-mcl, blazing-a-trail, try-to-see-it-my-way) or 'all'."
    ),
    out: Path = typer.Option(
        ..., "--out", metavar="DIR", help="Report folder (index.html, report.json, sweeps/); an earlier report's folder is reused."
    ),
    quick: bool = typer.Option(
        False, "--quick", help="The short version (few seeds, short runs): what CI runs. Its verdicts are indicative only."
    ),
    executor: str = typer.Option(
        "local", "--executor", metavar="local|ray", help="'local' worker processes, or 'ray' (needs the ray extra of teamnav)."
    ),
    address: Optional[str] = typer.Option(
        None, "--address", metavar="ADDRESS", help="Ray cluster address (auto, ray://host:10001); default: a local Ray."
    ),
    workers: Optional[int] = typer.Option(None, "--workers", "-j", metavar="N", help="Trials at once (default: all CPUs)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bars or section lines; print only the report's path."),
    wait: bool = typer.Option(False, "--wait", help="If another teamnav report is writing the same --out folder, wait for it instead of refusing."),
    group_brains: bool = typer.Option(
        False, "--group-brains", help="Step teams through their compiled group brains where they have one (the same "
        "runs, bit for bit; stored trials are reused either way)."),
) -> None:
    """Write an HTML report: each paper's claims beside our numbers.

    One self-contained file, OUT/index.html. --quick gives indicative verdicts only.
    """
    from teamnav.experiments.report import ReportError, run_report
    from teamnav.experiments.sweep import SweepError
    from teamnav.files import ClaimError

    err = Console(stderr=True, highlight=False, soft_wrap=True)
    try:
        result = run_report(experiments, out, quick=quick, executor=executor, workers=workers, address=address, progress=not quiet,
                            wait=wait, group_brains=group_brains)
    except (ReportError, SweepError, ClaimError) as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    con = Console(highlight=False, soft_wrap=True)
    if not quiet:
        for s in result.sections:
            con.print(section_line(s, result.quick), markup=False)
    con.print(str(result.index), markup=False)
    if not result.ok:
        for s in result.errors:
            err.print(f"error: section {s.key} raised {s.error} (shown as missing in the report)", markup=False)
        raise typer.Exit(EXIT_SECTION_FAILED)
