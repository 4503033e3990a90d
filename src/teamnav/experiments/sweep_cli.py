"""``teamnav sweep``: run a scenario over a grid of parameters x seeds into a results store.

The command only parses its options and calls :func:`teamnav.experiments.sweep.sweep`
(STYLE habit 17). Register it on the ``teamnav`` app with::

    from teamnav.experiments.sweep_cli import sweep_command
    app.command("sweep")(sweep_command)

Exit status: 0 when every trial run is ``ok``; 1 when some trials failed (they are in the
store with their errors, and a rerun retries them); 2 for bad input (sweep, grid, scenario,
option), with one message and no traceback.

Examples
--------
::

    teamnav sweep demo --grid robots.0.count=2,4,8 --seeds 5 --duration 20 --out sweeps/demo
    teamnav sweep demo-robots --out sweeps/demo-robots            # a named sweep
    teamnav sweep my_sweep.yaml --out sweeps/mine --executor ray --address auto
    teamnav sweep demo-robots --out sweeps/demo-robots --quiet     # rerun: skips what is done
"""

from __future__ import annotations

import contextlib
import os
import warnings
from pathlib import Path
from typing import List, Optional

import typer
from rich.console import Console

__all__ = ["EXIT_BAD_INPUT", "EXIT_TRIALS_FAILED", "sweep_command"]

#: exit status for bad input (as click uses for usage errors)
EXIT_BAD_INPUT = 2
#: exit status when the sweep ran but some trials failed
EXIT_TRIALS_FAILED = 1


def sweep_command(
    name_or_file: str = typer.Argument(
        ..., metavar="SWEEP_OR_SCENARIO", help="Named sweep, sweep YAML file, or scenario name/file (then give --grid/--seeds)."
    ),
    grid: Optional[List[str]] = typer.Option(
        None, "--grid", metavar="KEY=V1,V2,...", help="Grid axis, with a dotted KEY as in --set (robots.0.count=2,4,8). Repeatable."
    ),
    seeds: Optional[str] = typer.Option(
        None, "--seeds", metavar="N|S1,S2,...|A-B", help="N runs seeds 0..N-1 (a count: 1000 runs 1000 seeds); or a "
        "list such as 1,4,9, or a range such as 1000-1009 (1000-1000: that seed alone). Default: the sweep's, else 1."
    ),
    set_: Optional[List[str]] = typer.Option(
        None, "--set", metavar="KEY=VALUE", help="Fixed override for every trial, with a dotted KEY. Repeatable."
    ),
    duration: Optional[float] = typer.Option(
        None, "--duration", metavar="SECONDS", help="Simulated time of every trial [s] (replaces the scenario's duration_s)."
    ),
    name: Optional[str] = typer.Option(
        None, "--name", metavar="NAME", help="The sweep's name in the results table (default: the sweep file's or scenario's)."
    ),
    out: Path = typer.Option(..., "--out", metavar="DIR", help="Folder of results.sqlite; rerunning into it resumes the sweep."),
    executor: str = typer.Option(
        "local", "--executor", metavar="local|ray", help="'local' worker processes, or 'ray' (needs the ray extra of teamnav)."
    ),
    address: Optional[str] = typer.Option(
        None, "--address", metavar="ADDRESS", help="Ray cluster address (auto, ray://host:10001); default: a local Ray."
    ),
    workers: Optional[int] = typer.Option(None, "--workers", "-j", metavar="N", help="Trials at once (default: all CPUs)."),
    retry_failed: bool = typer.Option(True, "--retry-failed/--skip-failed", help="Rerun trials stored as failed (default) or skip them."),
    artifacts: bool = typer.Option(False, "--artifacts", help="Also write each trial's run folder under OUT/trials/."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar; one summary line at the end."),
    group_brains: bool = typer.Option(
        False, "--group-brains", help="Step teams through their compiled group brains where they have one (the same "
        "runs, bit for bit; stored trials are reused either way)."),
) -> None:
    """Run a sweep (grid x seeds) into OUT/results.sqlite.

    A rerun into the same folder skips the trials already done.
    """
    from teamnav.experiments.errors import ScenarioError
    from teamnav.experiments.runner import OutputDirError
    from teamnav.experiments.store import StoreError
    from teamnav.experiments.sweep import SweepError, sweep
    from teamnav.world.mapio import MapError

    err = Console(stderr=True, highlight=False, soft_wrap=True)
    try:
        with _warnings_printed(err):
            result = sweep(
                name_or_file,
                out_dir=out,
                grid=grid or None,
                seeds=seeds,
                set=set_ or None,
                duration_s=duration,
                name=name,
                executor=executor,
                workers=workers,
                address=address,
                progress=not quiet,
                retry_failed=retry_failed,
                artifacts=artifacts,
                group_brains=group_brains,
            )
    except (SweepError, ScenarioError, StoreError, MapError, OutputDirError) as exc:
        err.print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except ValueError as exc:
        if os.environ.get("TEAMNAV_DEBUG"):
            raise
        err.print(f"error: {exc}", markup=False)
        err.print("(set TEAMNAV_DEBUG=1 to see where this came from)", markup=False, style="dim")
        raise typer.Exit(EXIT_BAD_INPUT) from None
    con = Console(highlight=False, soft_wrap=True)
    con.print(result.summary(), markup=False)
    if result.failed:
        if not quiet:
            for f in result.failures[:10]:
                err.print(f"  failed {f['trial_id']} ({f['label']}): {f['error']}", markup=False)
            if len(result.failures) > 10:
                err.print(f"  ... and {len(result.failures) - 10} more (see the error column of the store)", markup=False)
        raise typer.Exit(EXIT_TRIALS_FAILED)


@contextlib.contextmanager
def _warnings_printed(err: Console):
    """Print each :class:`~teamnav.experiments.sweep_spec.SweepWarning` raised inside as one
    ``warning: ...`` line on ``err`` (other warnings go their usual way)."""
    from teamnav.experiments.sweep_spec import SweepWarning

    with warnings.catch_warnings():
        warnings.simplefilter("always", SweepWarning)
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, SweepWarning):
                err.print(f"warning: {message}", markup=False)
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield
