"""The ``teamnav`` command: list, run, validate and sweep scenarios; write paper reports.

The CLI only parses, loads the scenario and calls the library (STYLE habit 17). Every bad
input (a scenario, a map, an override, an output folder) ends in one message on stderr and
exit status 2, never a traceback; an unexpected exception (a bug) still shows its traceback.

Examples
--------
::

    teamnav list
    teamnav run demo
    teamnav run demo --seed 3 --set robots.0.count=4 --set radio.p_loss=0.1 --duration 20
    teamnav run my_scenario.yaml --out runs/mine --gif
    teamnav run runs/mine/scenario.yaml --out runs/again      # reproduces runs/mine
    teamnav validate my_scenario.yaml
    teamnav run demo --set record_scans=true --html             # + runs/demo-*/replay.html
    teamnav replay runs/mine --out mine.html --every 2
    teamnav export runs/mine --mcap mine.mcap                   # open in Foxglove
    teamnav report all --quick --out reports/quick              # paper report (teamnav.experiments.report)
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import math
import os
from pathlib import Path
from typing import Iterator, List, Optional

import typer
from rich.console import Console
from rich.table import Table

from teamnav import __version__

app = typer.Typer(
    name="teamnav",
    help="Simulator and experiments for robot teams that help each other navigate.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_show_locals=False,
)

#: exit status for bad input (as click uses for usage errors)
EXIT_BAD_INPUT = 2


def _out() -> Console:
    return Console(highlight=False, soft_wrap=True)


def _err() -> Console:
    return Console(stderr=True, highlight=False, soft_wrap=True)


@contextlib.contextmanager
def _bad_input_exits() -> Iterator[None]:
    """Turn bad-input exceptions into one message on stderr and exit status 2."""
    from teamnav.experiments.errors import ScenarioError
    from teamnav.experiments.runner import OutputDirError
    from teamnav.world.mapio import MapError

    try:
        yield
    except (ScenarioError, MapError, OutputDirError) as exc:
        _err().print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except ValueError as exc:
        if os.environ.get("TEAMNAV_DEBUG"):
            raise
        _err().print(f"error: {exc}", markup=False)
        _err().print("(set TEAMNAV_DEBUG=1 to see where this came from)", markup=False, style="dim")
        raise typer.Exit(EXIT_BAD_INPUT) from None


def _version(value: bool) -> None:
    if value:
        _out().print(f"teamnav {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(False, "--version", callback=_version, is_eager=True, help="Print the version and exit."),
) -> None:
    """teamnav: run the four papers' robot-team experiments, or your own scenarios."""


# ---------------------------------------------------------------------------- list
@app.command("list")
def list_() -> None:
    """List built-in scenarios (with one-line descriptions), controllers and maps."""
    from teamnav.control import registry as controllers
    from teamnav.experiments import registry as scenarios
    from teamnav.experiments.spec import package_maps
    from teamnav.world.generators import BUILTIN_MAPS

    con = _out()
    table = Table(title="Scenarios (teamnav run NAME)", title_justify="left")
    table.add_column("name", style="bold")
    table.add_column("description")
    for name in scenarios.names():
        table.add_row(name, scenarios.describe(name))
    con.print(table)
    con.print("[bold]Controllers[/bold] (robots\\[i].controller): " + ", ".join(controllers.names()))
    con.print("[bold]Built-in maps[/bold] (map: {builtin: NAME}): " + ", ".join(sorted(BUILTIN_MAPS)))
    con.print("[bold]Packaged maps[/bold] (map: {package: NAME}): " + ", ".join(package_maps()))


# ---------------------------------------------------------------------------- run
def _default_out(name: str) -> Path:
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    out = Path("runs") / f"{name}-{stamp}"
    k = 2
    while out.exists():
        out = Path("runs") / f"{name}-{stamp}-{k}"
        k += 1
    return out


def _fmt(v) -> str:
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, int):
        return f"{v:d}"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else f"{v:.4g}"
    return str(v)


def metrics_table(values: dict, title: str) -> Table:
    """A two-column rich table of metric values."""
    table = Table(title=title, title_justify="left")
    table.add_column("metric")
    table.add_column("value", justify="right")
    for k, v in values.items():
        table.add_row(k, _fmt(v))
    return table


@app.command()
def run(
    scenario: str = typer.Argument(..., help="Built-in scenario name (see `teamnav list`) or a scenario YAML file."),
    seed: Optional[int] = typer.Option(None, "--seed", help="Random seed (replaces the scenario's)."),
    set_: Optional[List[str]] = typer.Option(
        None, "--set", help="Override a field: KEY=VALUE with a dotted KEY (robots.0.count=10, radio.p_loss=0.1). Repeatable."
    ),
    duration: Optional[float] = typer.Option(None, "--duration", help="Simulated time [s] (replaces duration_s)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Run folder to write (default runs/NAME-TIMESTAMP)."),
    gif: bool = typer.Option(False, "--gif", help="Also write run.gif."),
    force: bool = typer.Option(False, "--force", help="Replace --out if it exists and is not empty."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no table; print only the run folder."),
    html: bool = typer.Option(False, "--html", help="Also write replay.html (see `teamnav replay`)."),
) -> None:
    """Run a scenario, write its run folder and print its metrics."""
    from teamnav.experiments.runner import run as run_scenario
    from teamnav.experiments.spec import load_scenario

    with _bad_input_exits():
        scn = load_scenario(scenario, overrides=set_ or None, seed=seed, duration_s=duration)
        target = out if out is not None else _default_out(scn.name)
        result = run_scenario(scn, out_dir=target, progress=False if quiet else None, gif=gif, force=force)
        if html:
            from teamnav.viz.replay import build_replay

            build_replay(result.run_dir)
    con = _out()
    if quiet:
        con.print(str(result.run_dir), markup=False)
        return
    title = f"{scn.name}: {scn.n_robots} robots, {scn.duration_s:g} s simulated, seed {scn.seed}"
    con.print(metrics_table(result.metrics, title))
    con.print(f"run folder: {result.run_dir}", markup=False)


# ---------------------------------------------------------------------------- validate
@app.command()
def validate(
    scenario: str = typer.Argument(..., help="Scenario YAML file (or built-in name) to check."),
    set_: Optional[List[str]] = typer.Option(None, "--set", help="Override a field: KEY=VALUE (repeatable)."),
) -> None:
    """Load and check a scenario (fields, map, controllers and their parameters) without running it."""
    from teamnav.experiments.spec import build_grid, load_scenario

    with _bad_input_exits():
        scn = load_scenario(scenario, overrides=set_ or None)
        grid = build_grid(scn)
    groups = ", ".join(f"{g.count} x {g.controller}" for g in scn.robots)
    h, w = grid.shape
    _out().print(
        f"ok: {scn.source}\n  {scn.name}: {scn.n_robots} robots ({groups}), map {scn.map.describe()} "
        f"({w} x {h} cells at {grid.resolution_m:g} m), {scn.duration_s:g} s = {scn.n_steps} steps of {scn.dt_s:g} s, "
        f"seed {scn.seed}",
        markup=False,
    )


# ---------------------------------------------------------------------------- replay / export
@app.command()
def replay(
    run_dir: Path = typer.Argument(..., help="A run folder (written by `teamnav run`)."),
    out: Optional[Path] = typer.Option(None, "--out", help="HTML file to write (default RUN_DIR/replay.html)."),
    every: int = typer.Option(1, "--every", help="Keep every K-th recorded sample as a frame."),
    max_frames: int = typer.Option(5000, "--max-frames", help="At most this many frames (--every grows to fit)."),
    max_points: int = typer.Option(300, "--max-points", help="At most this many points per sample of a points layer."),
    no_scans: bool = typer.Option(False, "--no-scans", help="Leave recorded range scans out (smaller file)."),
) -> None:
    """Write a self-contained HTML replay of a run (open it from disk in any browser)."""
    from teamnav.viz.replay import build_replay

    with _bad_input_exits():
        stats = build_replay(run_dir, out, every=every, max_frames=max_frames, max_points=max_points, scans=not no_scans)
    _out().print(f"{stats.path}  ({stats.bytes / 1e6:.2f} MB, {stats.n_frames} frames of {stats.n_robots} robots; "
                 f"layers: {', '.join(stats.layers)})", markup=False)


@app.command()
def export(
    run_dir: Path = typer.Argument(..., help="A run folder (written by `teamnav run`)."),
    mcap: Path = typer.Option(..., "--mcap", help="MCAP file to write (opens in Foxglove)."),
    force: bool = typer.Option(False, "--force", help="Replace the MCAP file if it exists."),
) -> None:
    """Export a run to MCAP with Foxglove's well-known schemas (map, poses, scans, frames, markers)."""
    from teamnav.viz.mcap_export import export_mcap

    with _bad_input_exits():
        stats = export_mcap(run_dir, mcap, force=force)
    _out().print(f"{stats.path}  ({stats.bytes / 1e6:.2f} MB, {stats.messages} messages on {stats.channels} channels)",
                 markup=False)


from teamnav.experiments.sweep_cli import sweep_command  # noqa: E402  (after the app exists)

app.command("sweep")(sweep_command)

from teamnav.experiments.report.cli import report_command  # noqa: E402

app.command("report")(report_command)


def main() -> None:  # pragma: no cover - console entry for `python -m teamnav`
    app(prog_name="teamnav")


if __name__ == "__main__":  # pragma: no cover
    main()
