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

__all__ = ["EXIT_BAD_INPUT", "EXIT_SECTION_FAILED", "report_command"]

#: exit status for bad input
EXIT_BAD_INPUT = 2
#: exit status when the report was written but some section raised
EXIT_SECTION_FAILED = 1


def report_command(
    experiments: List[str] = typer.Argument(
        ..., metavar="EXPERIMENT|all", help="Section keys (los-help, collab-mcl, blazing-a-trail, try-to-see-it-my-way) or 'all'."
    ),
    out: Path = typer.Option(..., "--out", help="Report folder (index.html, report.json, sweeps/); an earlier report's folder is reused."),
    quick: bool = typer.Option(False, "--quick", help="The short version (few seeds, short runs): what CI runs."),
    executor: str = typer.Option("local", "--executor", help="'local' worker processes, or 'ray' (needs the ray extra of teamnav)."),
    address: Optional[str] = typer.Option(None, "--address", help="Ray cluster address (auto, ray://host:10001); default: a local Ray."),
    workers: Optional[int] = typer.Option(None, "--workers", "-j", help="Trials at once (default: all CPUs)."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bars or section lines; print only the report's path."),
) -> None:
    """Write a self-contained HTML report: each paper's claims beside our measurements."""
    from teamnav.experiments.report import ReportError, run_report
    from teamnav.experiments.sweep import SweepError

    err = Console(stderr=True, highlight=False, soft_wrap=True)
    try:
        result = run_report(experiments, out, quick=quick, executor=executor, workers=workers, address=address, progress=not quiet)
    except (ReportError, SweepError) as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    con = Console(highlight=False, soft_wrap=True)
    if not quiet:
        for s in result.sections:
            holds = sum(c.holds is True for c in s.comparisons)
            line = f"  {s.key:<22} {s.status:<8} {s.wall_s:7.1f} s  {holds}/{len(s.comparisons)} claims hold"
            con.print(line + (f"  ({s.error})" if s.error else ""), markup=False)
    con.print(str(result.index), markup=False)
    if not result.ok:
        for s in result.errors:
            err.print(f"error: section {s.key} raised {s.error} (shown as missing in the report)", markup=False)
        raise typer.Exit(EXIT_SECTION_FAILED)
