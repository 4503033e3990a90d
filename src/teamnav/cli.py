"""The ``teamnav`` command: list, run, validate and sweep scenarios; write paper reports.

The CLI only parses, loads the scenario and calls the library (STYLE habit 17). Every bad
input (a scenario, a map, an override, an output folder) ends in one message on stderr and
exit status 2, never a traceback; an unexpected exception (a bug) still shows its traceback.

Help pages are plain text (``rich_markup_mode=None``): a help string is printed as written, so
a unit in brackets ("[s]") survives, and a pipe gets no box drawing. Every option that takes a
value names it with a metavar (``KEY=VALUE``, ``SECONDS``, ``DIR``, ``N``); flags show none.

Examples
--------
::

    teamnav list
    teamnav list --names                                        # one scenario name per line, for scripts
    teamnav list --json
    teamnav run demo
    teamnav run demo --seed 3 --set robots.0.count=4 --set radio.p_loss=0.1 --duration 20
    teamnav run my_scenario.yaml --out runs/mine --gif
    teamnav run runs/mine/scenario.yaml --out runs/again      # reproduces runs/mine
    teamnav run demo --controller my_brain:MyBrain            # your own Controller class (my_brain.py)
    teamnav validate my_scenario.yaml
    teamnav run demo --set record_scans=true --html             # + runs/demo-*/replay.html
    teamnav replay runs/mine --out mine.html --every 2
    teamnav export runs/mine --mcap mine.mcap                   # open in Foxglove
    teamnav report all --quick --out reports/quick              # paper report (teamnav.experiments.report)
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import json
import math
import os
from collections.abc import MutableMapping
from pathlib import Path
from typing import Any, Iterator, List, Optional

import typer
import typer.core
from rich.console import Console
from rich.table import Table

from teamnav import __version__


def _no_type(ctx: Any = None) -> None:
    return None


class _Group(typer.core.TyperGroup):
    """The ``teamnav`` group: its commands' arguments show their metavar only.

    Newer typer writes an argument's Python type after its name in help (``SCENARIO <str>``),
    whatever its metavar says; every command got from the group (so every command registered,
    now or later) has that type label removed from its arguments. Options are left alone: one
    that takes a value names it with its metavar, and flags show no type in plain help.
    """

    def resolve_command(self, ctx, args):  # type: ignore[override]
        # `teamnav --version true`: say that the flag takes no value, not "no such command 'true'"
        if ctx.params.get("version") and args and super().get_command(ctx, args[0]) is None:
            ctx.fail(f"--version takes no value (received {args[0]!r})")
        return super().resolve_command(ctx, args)

    def get_command(self, ctx, cmd_name):  # type: ignore[override]
        cmd = super().get_command(ctx, cmd_name)
        for param in getattr(cmd, "params", ()):
            if getattr(param, "param_type_name", "") == "argument" and hasattr(param, "display_type_rich"):
                param.display_type_rich = _no_type
        return cmd

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.commands = _Commands(self.commands)

    def list_commands(self, ctx):  # type: ignore[override]
        return list(self.commands)  # the names only: loads nothing

    def format_commands(self, ctx, formatter):  # type: ignore[override]
        # As click's, except that a command not loaded yet shows its one-line help from
        # _LAZY_COMMANDS: `teamnav --help` imports none of them.
        rows = []
        for name in self.list_commands(ctx):
            if not self.commands.loaded(name):
                rows.append((name, _LAZY_COMMANDS[name][2]))
                continue
            cmd = self.get_command(ctx, name)
            if cmd is not None and not cmd.hidden:
                rows.append((name, cmd))
        if rows:
            limit = formatter.width - 6 - max(len(name) for name, _ in rows)
            with formatter.section("Commands"):
                formatter.write_dl([(name, c if isinstance(c, str) else c.get_short_help_str(limit)) for name, c in rows])


#: Commands whose module is imported only when the command runs (or shows its own help), so
#: `teamnav --help`, `list` and `run` never import the report machinery:
#: name -> (module, function, the one-line help `teamnav --help` shows; a test checks that it
#: is the command's own).
_LAZY_COMMANDS: dict[str, tuple[str, str, str]] = {
    "report": ("teamnav.experiments.report.cli", "report_command",
               "Write an HTML report: each paper's claims beside our numbers."),
}


class _Commands(MutableMapping):
    """The group's commands by name: the registered ones, then those of :data:`_LAZY_COMMANDS`,
    each built (its module imported) the first time it is looked up."""

    def __init__(self, commands: dict) -> None:
        self._loaded = dict(commands)

    def loaded(self, name: str) -> bool:
        return name in self._loaded

    def __getitem__(self, name: str) -> Any:
        if name not in self._loaded and name in _LAZY_COMMANDS:
            self._loaded[name] = _load_lazy_command(name)
        return self._loaded[name]

    def __setitem__(self, name: str, cmd: Any) -> None:
        self._loaded[name] = cmd

    def __delitem__(self, name: str) -> None:
        del self._loaded[name]

    def __iter__(self) -> Iterator[str]:
        yield from self._loaded
        yield from (n for n in _LAZY_COMMANDS if n not in self._loaded)

    def __len__(self) -> int:
        return len(set(self._loaded) | set(_LAZY_COMMANDS))


def _load_lazy_command(name: str) -> Any:
    """The click command of lazy command ``name``, built by typer as ``app.command`` would."""
    import importlib

    module, attr, _ = _LAZY_COMMANDS[name]
    one = typer.Typer(rich_markup_mode=None, add_completion=False)
    one.command(name)(getattr(importlib.import_module(module), attr))
    return typer.main.get_command(one)


app = typer.Typer(
    name="teamnav",
    cls=_Group,
    help="Simulator and experiments for robot teams that help each other navigate.",
    no_args_is_help=True,
    add_completion=False,
    rich_markup_mode=None,
    context_settings={"max_content_width": 120},
    pretty_exceptions_show_locals=False,
)

#: exit status for bad input (as click uses for usage errors); also a controller that cannot be
#: built (its module fails to import, its Params refuse the parameters, its constructor raises)
EXIT_BAD_INPUT = 2
#: exit status for a controller that fails mid-run (its step raises, returns no action, or
#: takes longer than --brain-timeout)
EXIT_BRAIN_FAILED = 3


def _out() -> Console:
    return Console(highlight=False, soft_wrap=True)


def _err() -> Console:
    return Console(stderr=True, highlight=False, soft_wrap=True)


@contextlib.contextmanager
def _bad_input_exits(debug: bool = False) -> Iterator[None]:
    """Turn bad-input exceptions into one message on stderr and exit status 2; a controller
    that fails mid-run into one message naming it, the robot and the step, and exit status 3
    (with ``debug``, the controller's own traceback first)."""
    from teamnav.control.guard import BrainBuildError, BrainError
    from teamnav.experiments.errors import ScenarioError
    from teamnav.experiments.runner import OutputDirError
    from teamnav.files import ClaimError
    from teamnav.viz.run_folder import OutputPathError, RunFolderError
    from teamnav.world.mapio import MapError

    debug = debug or bool(os.environ.get("TEAMNAV_DEBUG"))
    try:
        yield
    except BrainError as exc:
        err = _err()
        if debug:
            err.print(exc.brain_traceback().rstrip(), markup=False, highlight=False)
        err.print(f"error: {exc}", markup=False)
        if not debug:
            err.print("(run with --debug to see the controller's traceback)", markup=False, style="dim")
        raise typer.Exit(EXIT_BAD_INPUT if isinstance(exc, BrainBuildError) else EXIT_BRAIN_FAILED) from None
    except (ScenarioError, MapError, OutputDirError, ClaimError, OutputPathError, RunFolderError) as exc:
        _err().print(f"error: {exc}", markup=False)
        raise typer.Exit(EXIT_BAD_INPUT) from None
    except ValueError as exc:
        if debug:
            raise
        _err().print(f"error: {exc}", markup=False)
        _err().print("(set TEAMNAV_DEBUG=1 to see where this came from)", markup=False, style="dim")
        raise typer.Exit(EXIT_BAD_INPUT) from None


@app.callback(invoke_without_command=True)
def _main(
    ctx: typer.Context,
    version: bool = typer.Option(False, "--version", help="Print the version and exit."),
) -> None:
    """teamnav: run the four papers' robot-team experiments, or your own scenarios."""
    # --version is a plain flag handled here, not an eager callback: an eager one exits while
    # parsing, before the words after it are looked at, so `teamnav --version true` passed.
    # Here the command name has been resolved first, and an unknown one is a usage error (2).
    if version:
        typer.echo(f"teamnav {__version__}")
        raise typer.Exit()
    if ctx.invoked_subcommand is None:
        ctx.fail("Missing command.")


# ---------------------------------------------------------------------------- list
def catalogue() -> dict[str, Any]:
    """What ``teamnav list --json`` prints: scenarios (name, description), controllers, maps."""
    from teamnav.control import registry as controllers
    from teamnav.experiments import registry as scenarios
    from teamnav.experiments.spec import package_maps
    from teamnav.world.generators import BUILTIN_MAPS

    return {
        "scenarios": [{"name": n, "description": scenarios.describe(n)} for n in scenarios.names()],
        "controllers": list(controllers.names()),
        "builtin_maps": sorted(BUILTIN_MAPS),
        "packaged_maps": list(package_maps()),
    }


@app.command("list")
def list_(
    names: bool = typer.Option(False, "--names", help="Print only the scenario names, one per line (for scripts)."),
    as_json: bool = typer.Option(
        False, "--json", help="Print one JSON document: scenarios (name, description), controllers, builtin_maps, packaged_maps."
    ),
) -> None:
    """List built-in scenarios, controllers and maps.

    A table for people; --names or --json for scripts.
    """
    if names and as_json:
        raise typer.BadParameter("give --names or --json, not both", param_hint="'--names' / '--json'")
    # --names and --json are plain writes, not rich: nothing wrapped, styled or cut to a width
    if names:
        from teamnav.experiments import registry as scenarios

        typer.echo("\n".join(scenarios.names()))
        return
    cat = catalogue()
    if as_json:
        typer.echo(json.dumps(cat, indent=2))
        return
    con = _out()
    table = Table(title="Scenarios (teamnav run NAME)", title_justify="left")
    table.add_column("name", style="bold")
    table.add_column("description")
    for s in cat["scenarios"]:
        table.add_row(s["name"], s["description"])
    con.print(table)
    con.print("[bold]Controllers[/bold] (robots\\[i].controller): " + ", ".join(cat["controllers"]))
    con.print("[bold]Built-in maps[/bold] (map: {builtin: NAME}): " + ", ".join(cat["builtin_maps"]))
    con.print("[bold]Packaged maps[/bold] (map: {package: NAME}): " + ", ".join(cat["packaged_maps"]))


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


#: at most this many rows in the metrics table after ``teamnav run``
MAX_TABLE_ROWS = 15

_STATS = ("mean", "median", "min", "max", "total", "std")
_SUFFIX_UNITS = {"s": "s", "m": "m", "mps": "m/s", "deg": "deg", "degps": "deg/s", "min": "min", "rad": "rad"}


def _is_scalar(key: str, value: Any) -> bool:
    """A number to print (not a series: no list, array, dict or JSON string)."""
    return isinstance(value, (bool, int, float)) and not key.endswith("_series")


def unit_from_key(key: str) -> str:
    """The unit a metric key's suffix names (``path_length_m_mean`` -> m, ``mean_speed_mps`` -> m/s), else ''."""
    parts = key.replace(".", "_").split("_")
    if len(parts) > 1 and parts[-1] in _STATS:
        parts = parts[:-1]
    return _SUFFIX_UNITS.get(parts[-1], "") if len(parts) > 1 else ""


def _declared_headlines() -> tuple[dict[str, tuple[tuple[str, str], ...]], dict[str, tuple[tuple[str, str], ...]]]:
    """``{metric name: ((key, unit), ...)}`` of the paper metric sets and of the general metrics,
    as :mod:`teamnav.experiments.metric_sets` declares them."""
    import importlib

    from teamnav.experiments import metric_sets
    from teamnav.experiments import metrics as _registry  # noqa: F401  (imports every metric set)

    paper: dict[str, tuple[tuple[str, str], ...]] = {}
    for module in metric_sets.metric_set_modules().values():
        paper.update(getattr(importlib.import_module(module), "HEADLINE", {}))
    return paper, dict(metric_sets.CORE_HEADLINE)


def headline_rows(metric_names, values: dict[str, Any], data: Any = None,
                  limit: int = MAX_TABLE_ROWS) -> list[tuple[str, Any, str]]:
    """The rows ``teamnav run`` prints: ``(key, value, unit)``, at most ``limit``, never a series.

    The headline keys each metric of ``metric_names`` declares (``HEADLINE`` in
    :mod:`teamnav.experiments.metric_sets`), the paper metric sets' first and the general
    metrics' after, each only where the run produced it. A metric declared nowhere shows its
    scalar keys (read from ``data`` by computing it again, or, without ``data`` or when no
    metric declares anything, every scalar of ``values``), units from the key's suffix.
    """
    from teamnav.experiments import metrics as registry

    paper, core = _declared_headlines()
    declared = {**paper, **core}
    names = list(metric_names)
    order = [n for n in names if n in paper] + [n for n in names if n in core]
    rows: list[tuple[str, Any, str]] = []
    seen: set[str] = set()

    def add(key: str, unit: str) -> None:
        if key not in seen and key in values and _is_scalar(key, values[key]):
            seen.add(key)
            rows.append((key, values[key], unit))

    undeclared = [n for n in names if n not in declared]
    if not any(n in declared for n in names) or (undeclared and data is None):
        fallback_keys = list(values)
    else:
        fallback_keys = []
        for n in undeclared:
            try:
                fallback_keys += list(registry.compute([n], data))
            except Exception:  # noqa: BLE001 - a table row is not worth failing a finished run
                continue
    for n in order:
        for key, unit in declared[n]:
            add(key, unit)
    for key in fallback_keys:
        add(key, unit_from_key(key))
    return rows[:limit]


def metrics_table(rows, title: str) -> Table:
    """A rich table of metric rows: ``(key, value, unit)`` tuples, or a ``{key: value}`` dict (no units)."""
    if isinstance(rows, dict):
        rows = [(k, v, "") for k, v in rows.items()]
    table = Table(title=title, title_justify="left")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for k, v, unit in rows:
        table.add_row(k, _fmt(v), unit)
    return table


def _positive_seconds(value: Optional[float]) -> Optional[float]:
    if value is not None and not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"must be a number of seconds > 0, got {value:g}")
    return value


@app.command()
def run(
    scenario: str = typer.Argument(
        ..., metavar="SCENARIO", help="Built-in scenario name (see `teamnav list`) or a scenario YAML file."
    ),
    seed: Optional[int] = typer.Option(None, "--seed", metavar="N", help="Random seed (replaces the scenario's)."),
    set_: Optional[List[str]] = typer.Option(
        None, "--set", metavar="KEY=VALUE",
        help="Override a field, with a dotted KEY (robots.0.count=10, radio.p_loss=0.1). Repeatable.",
    ),
    duration: Optional[float] = typer.Option(
        None, "--duration", metavar="SECONDS", help="Simulated time [s] (replaces the scenario's duration_s)."
    ),
    out: Optional[Path] = typer.Option(None, "--out", metavar="DIR", help="Run folder to write (default runs/NAME-TIMESTAMP)."),
    gif: bool = typer.Option(False, "--gif", help="Also write run.gif."),
    force: bool = typer.Option(False, "--force", help="Replace --out if it exists and is not empty."),
    quiet: bool = typer.Option(False, "--quiet", "-q", help="No progress bar and no table; print only the run folder."),
    html: bool = typer.Option(False, "--html", help="Also write replay.html (see `teamnav replay`)."),
    wait: bool = typer.Option(False, "--wait", help="If another teamnav process is writing the same --out folder, wait for it instead of refusing."),
    controller: Optional[List[str]] = typer.Option(
        None, "--controller", metavar="MODULE:CLASS",
        help="Run your own Controller class for every group, or for one group as GROUP=MODULE:CLASS "
             "(a module on the path or in this folder, or path/to/file.py:CLASS). Repeatable.",
    ),
    brain_timeout: Optional[float] = typer.Option(
        None, "--brain-timeout", metavar="SECONDS", callback=_positive_seconds,
        help="Stop the run when one controller call (a robot's step) takes longer than SECONDS.",
    ),
    debug: bool = typer.Option(
        False, "--debug", help="On a failure, show the traceback (a controller's own, when it failed).",
    ),
    group_brains: bool = typer.Option(
        False, "--group-brains", help="Step teams through their compiled group brains where they have one (the same "
        "run, bit for bit).",
    ),
) -> None:
    """Run a scenario, write its run folder and print its metrics.

    Exit status: 0 done; 2 bad input, including a controller that cannot be built (its module
    fails to import or exits, its parameters are refused, its constructor raises); 3 a
    controller failed during the run (its step raised, returned no Action, or took longer than
    --brain-timeout). On a failure one error line names the controller, the robot and the
    step, and nothing is written to --out.
    """
    from teamnav.experiments.runner import run as run_scenario
    from teamnav.experiments.spec import load_scenario

    with _bad_input_exits(debug):
        if controller:  # the controllers first, so --set can give the new ones their parameters
            base = load_scenario(scenario, seed=seed, duration_s=duration)
            swap = [f"{k}={json.dumps(v)}" for k, v in controller_overrides(base, controller).items()]
            scn = load_scenario(scenario, overrides=swap + list(set_ or []), seed=seed, duration_s=duration)
        else:
            scn = load_scenario(scenario, overrides=set_ or None, seed=seed, duration_s=duration)
        target = out if out is not None else _default_out(scn.name)
        result = run_scenario(scn, out_dir=target, progress=False if quiet else None, gif=gif, force=force,
                              brain_timeout_s=brain_timeout, wait=wait, group_brains=group_brains)
        if html:
            from teamnav.viz.replay import build_replay

            build_replay(result.run_dir)
    con = _out()
    if quiet:
        con.print(str(result.run_dir), markup=False)
        return
    title = f"{scn.name}: {scn.n_robots} robots, {scn.duration_s:g} s simulated, seed {scn.seed}"
    rows = headline_rows(scn.metric_names, result.metrics, result.data)
    con.print(metrics_table(rows, title))
    con.print(f"all {len(result.metrics)} metrics: {result.run_dir / 'metrics.json'}", markup=False)
    con.print(f"run folder: {result.run_dir}", markup=False)


def controller_overrides(scn: Any, specs: List[str]) -> dict[str, Any]:
    """``--controller`` values as scenario overrides: ``MODULE:CLASS`` for every group, or
    ``GROUP=MODULE:CLASS`` (a group name or index) for one.

    A group keeps its ``params`` when the new controller's ``Params`` takes them; otherwise they
    are left out, with a note on stderr (``--set robots.N.params.KEY=VALUE``, applied after the
    swap, gives the new controller its own).
    """
    from teamnav.control import registry
    from teamnav.experiments.errors import ScenarioError

    names = [g.name for g in scn.robots]
    chosen: dict[int, str] = {}
    for spec in specs:
        head, sep, tail = spec.partition("=")
        if sep and head and ":" not in head and "/" not in head:
            group, entry = head.strip(), tail.strip()
            idx = [i for i, n in enumerate(names) if n == group]
            if not idx and group.isdigit() and int(group) < len(names):
                idx = [int(group)]
            if not idx:
                raise ScenarioError.one(scn.source, "--controller", f"expected GROUP=MODULE:CLASS with a group of the scenario "
                                        f"({', '.join(dict.fromkeys(names))}) or its index", group)
        else:
            idx, entry = list(range(len(names))), spec.strip()
        try:
            registry.lookup(entry)
        except KeyError as exc:
            raise ScenarioError.one(scn.source, "--controller", str(exc.args[0])) from None
        module, _, attr = entry.rpartition(":")
        if module.endswith(".py") or "/" in module or os.sep in module:  # a file: absolute, so scenario.yaml reruns anywhere
            entry = f"{Path(os.path.expanduser(module)).resolve()}:{attr}"
        for i in idx:
            chosen[i] = entry
    overrides: dict[str, Any] = {}
    for i, entry in sorted(chosen.items()):
        overrides[f"robots.{i}.controller"] = entry
        params = dict(scn.robots[i].params)
        if params:
            try:
                registry.lookup(entry).Params.model_validate(params)
            except Exception:  # noqa: BLE001 - any refusal: the parameters were the old controller's
                overrides[f"robots.{i}.params"] = {}
                _err().print(f"note: robots[{i}] ({names[i]!r}): params left out, {entry} does not take them "
                             f"({', '.join(params)})", markup=False)
    return overrides


# ---------------------------------------------------------------------------- validate
@app.command()
def validate(
    scenario: str = typer.Argument(..., metavar="SCENARIO", help="Scenario YAML file (or built-in name) to check."),
    set_: Optional[List[str]] = typer.Option(
        None, "--set", metavar="KEY=VALUE", help="Override a field, with a dotted KEY as in `teamnav run`. Repeatable."
    ),
) -> None:
    """Check a scenario (fields, map, controllers) without running it.

    Loads the scenario and its map and checks every field, controller and controller parameter.
    """
    from teamnav.experiments.spec import build_grid, load_scenario

    with _bad_input_exits():
        scn = load_scenario(scenario, overrides=set_ or None)
        grid = build_grid(scn)
    groups = ", ".join(f"{g.count} x {g.controller}" for g in scn.robots)
    simulated = scn.n_steps * scn.dt_s  # whole steps: what a run simulates when dt_s does not divide duration_s
    exact = "" if abs(simulated - scn.duration_s) <= 1e-9 * scn.duration_s else f" (simulates {simulated:g} s)"
    h, w = grid.shape
    _out().print(
        f"ok: {scn.source}\n  {scn.name}: {scn.n_robots} robots ({groups}), map {scn.map.describe()} "
        f"({w} x {h} cells at {grid.resolution_m:g} m), {scn.duration_s:g} s = {scn.n_steps} steps of {scn.dt_s:g} s{exact}, "
        f"seed {scn.seed}",
        markup=False,
    )


# ---------------------------------------------------------------------------- replay / export
@app.command()
def replay(
    run_dir: Path = typer.Argument(..., metavar="RUN_DIR", help="A run folder (written by `teamnav run`)."),
    out: Optional[Path] = typer.Option(None, "--out", metavar="FILE", help="HTML file to write (default RUN_DIR/replay.html)."),
    every: int = typer.Option(1, "--every", metavar="K", help="Keep every K-th recorded sample as a frame."),
    max_frames: int = typer.Option(5000, "--max-frames", metavar="N", help="At most N frames (--every grows to fit)."),
    max_points: int = typer.Option(300, "--max-points", metavar="N", help="At most N points per sample of a points layer."),
    no_scans: bool = typer.Option(False, "--no-scans", help="Leave recorded range scans out (smaller file)."),
    wait: bool = typer.Option(False, "--wait", help="If another teamnav process is writing the same HTML file, wait for it instead of refusing."),
) -> None:
    """Write a self-contained HTML replay of a run.

    Open it from disk in any browser.
    """
    from teamnav.viz.replay import build_replay

    with _bad_input_exits():
        stats = build_replay(run_dir, out, every=every, max_frames=max_frames, max_points=max_points, scans=not no_scans,
                             wait=wait)
    _out().print(f"{stats.path}  ({stats.bytes / 1e6:.2f} MB, {stats.n_frames} frames of {stats.n_robots} robots; "
                 f"layers: {', '.join(stats.layers)})", markup=False)


@app.command()
def export(
    run_dir: Path = typer.Argument(..., metavar="RUN_DIR", help="A run folder (written by `teamnav run`)."),
    mcap: Path = typer.Option(..., "--mcap", metavar="FILE", help="MCAP file to write (opens in Foxglove)."),
    force: bool = typer.Option(False, "--force", help="Replace the MCAP file if it exists."),
    wait: bool = typer.Option(False, "--wait", help="If another teamnav process is writing the same MCAP file, wait for it instead of refusing."),
) -> None:
    """Export a run to MCAP, to open in Foxglove.

    Uses Foxglove's well-known schemas: map, poses, scans, frames, markers.
    """
    from teamnav.viz.mcap_export import export_mcap

    with _bad_input_exits():
        stats = export_mcap(run_dir, mcap, force=force, wait=wait)
    _out().print(f"{stats.path}  ({stats.bytes / 1e6:.2f} MB, {stats.messages} messages on {stats.channels} channels)",
                 markup=False)


from teamnav.experiments.sweep_cli import sweep_command  # noqa: E402  (after the app exists)

app.command("sweep")(sweep_command)

# `report` is registered lazily: see _LAZY_COMMANDS


def main() -> None:  # pragma: no cover - console entry for `python -m teamnav`
    app(prog_name="teamnav")


if __name__ == "__main__":  # pragma: no cover
    main()
