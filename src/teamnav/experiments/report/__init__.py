"""Paper reports: run (or reuse) each paper's sweeps and write one self-contained HTML file.

``teamnav report EXPERIMENT|all --out DIR [--quick]`` and :func:`build_report` do the same:

1. find the sections: every section an installed paper declares
   (:attr:`teamnav.plugins.Paper.sections`, a module that defines ``SECTION``, a
   :class:`~teamnav.experiments.report.model.SectionSpec`), plus sections added with
   :func:`register_section` (tests);
2. for each chosen section, call ``SECTION.build(ctx)`` with a
   :class:`~teamnav.experiments.report.context.SweepContext`; its ``ctx.sweep(...)`` runs the
   section's sweeps into ``DIR/sweeps/<sweep name>/results.sqlite`` or reuses the trials
   already there (the store is resumable, so a report killed half-way resumes too);
3. render the blocks into ``DIR/index.html`` (:mod:`teamnav.experiments.report.html`), written
   under a temporary name and renamed, plus ``DIR/report.json`` (what each section returned:
   status, wall time, comparisons, sweeps run and reused). Both are rewritten after every
   section, the sections still to come shown as pending, so a long full run can be read
   while it goes and a killed one leaves a truthful report of what it finished.

Every section an installed paper declares is always in ``all`` (:func:`expected_sections`):
while its module does not exist, the report shows it as missing ("system not built yet"),
never as numbers. A section whose ``build`` raises is shown as missing with the error,
the other sections still run, and :attr:`ReportResult.ok` is False (the CLI exits 1 after
writing the report).

Examples
--------
::

    from teamnav.experiments.report import build_report
    index = build_report("all", "reports/quick", quick=True)          # -> reports/quick/index.html
    index = build_report(["collab-mcl"], "reports/full", workers=16)  # the full reproduction
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import difflib
import importlib
import json
import os
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from teamnav.experiments.report.model import (
    Comparison,
    Ledger,
    MapView,
    Missing,
    Plot,
    Precondition,
    SectionSpec,
    Table,
    Text,
)

__all__ = [
    "expected_sections",
    "MARKER_NAME",
    "ReportError",
    "ReportResult",
    "SectionOutcome",
    "available_sections",
    "build_report",
    "discover_sections",
    "register_section",
    "resolve_names",
    "run_report",
    "unregister_section",
]

#: File that marks a folder as a teamnav report (so ``--out`` can be reused, and nothing else is).
MARKER_NAME = "teamnav-report.json"

def expected_sections() -> dict[str, tuple[str, str, int]]:
    """Every section the installed papers declare: key -> (title, paper file, order). ``report
    all`` always has them, as results or as missing."""
    from teamnav import plugins

    out: dict[str, tuple[str, str, int]] = {}
    for paper in plugins.papers().values():
        for s in paper.sections:
            out.setdefault(s.key, (s.title or s.key, s.paper, s.order))
    return dict(sorted(out.items(), key=lambda kv: (kv[1][2], kv[0])))


def _declared_modules() -> dict[str, str]:
    """Section key -> the module that defines its ``SECTION``, for every installed paper."""
    from teamnav import plugins

    out: dict[str, str] = {}
    for paper in plugins.papers().values():
        for s in paper.sections:
            out.setdefault(s.key, s.module)
    return out


_BLOCK_TYPES = (Text, Table, Plot, MapView, Comparison, Missing, Ledger, Precondition)
_registered: dict[str, SectionSpec] = {}


class ReportError(ValueError):
    """Bad report input: an unknown section name, an output folder that is not a report's,
    a bad executor option. The CLI prints the message and exits with status 2."""


# ---------------------------------------------------------------------------- sections
def register_section(spec: SectionSpec, *, replace: bool = False) -> None:
    """Add a section that is not a module of ``report.sections`` (tests, plug-ins).

    Raises
    ------
    ReportError
        ``spec`` is not a SectionSpec, or its key is registered already (unless ``replace``).
    """
    if not isinstance(spec, SectionSpec):
        raise ReportError(f"register_section: expected a SectionSpec, received {type(spec).__name__}")
    if spec.key in _registered and not replace:
        raise ReportError(f"register_section: section {spec.key!r} is registered already; pass replace=True to replace it")
    _registered[spec.key] = spec


def unregister_section(key: str) -> None:
    """Remove a section added with :func:`register_section` (no error when absent)."""
    _registered.pop(key, None)


def _broken_section(key: str, module: str, error: str) -> SectionSpec:
    """A stand-in for a section module that cannot be imported: its build raises the error."""
    title, paper, order = expected_sections().get(key, (key, "", 100))

    def build(ctx: Any) -> list:
        raise ImportError(f"section module {module} could not be imported: {error}")

    return SectionSpec(key=key, title=title, paper=paper, build=build, order=order)


def discover_sections() -> dict[str, SectionSpec]:
    """Every ``SECTION`` of the modules the installed papers declare (:func:`_declared_modules`).

    A module that fails to import, or has no valid ``SECTION``, becomes a section whose build
    raises that error (so the report shows it instead of losing it); a module that does not
    exist is left out (:func:`available_sections` shows its section as missing).

    Returns
    -------
    dict of str to SectionSpec
        By section key.
    """
    found: dict[str, SectionSpec] = {}
    for key, module in _declared_modules().items():
        try:
            mod = importlib.import_module(module)
        except ModuleNotFoundError as exc:
            if exc.name is not None and module.startswith(exc.name):
                continue  # the paper's section is not written yet: missing, not broken
            found[key] = _broken_section(key, module, f"{type(exc).__name__}: {exc}")
            continue
        except Exception as exc:  # noqa: BLE001 - a broken section must not break the others
            found[key] = _broken_section(key, module, f"{type(exc).__name__}: {exc}")
            continue
        spec = getattr(mod, "SECTION", None)
        if not isinstance(spec, SectionSpec):
            found[key] = _broken_section(key, module, f"expected SECTION = SectionSpec(...), found {type(spec).__name__}")
            continue
        found[spec.key] = spec
    return found


def available_sections() -> dict[str, SectionSpec | None]:
    """Every known section key, in report order: discovered or registered sections, and the
    expected paper sections whose module does not exist yet (value None)."""
    found = {**discover_sections(), **_registered}
    expected = expected_sections()
    keys = set(found) | set(expected)

    def order(key: str) -> tuple[int, str]:
        spec = found.get(key)
        if key in expected:
            return (expected[key][2], key)
        return (spec.order if spec is not None else 100, key)

    return {k: found.get(k) for k in sorted(keys, key=order)}


def resolve_names(names: str | Sequence[str], known: Iterable[str]) -> list[str]:
    """The section keys to build: ``"all"`` (every known key) or the given keys, checked.

    Raises
    ------
    ReportError
        An unknown name, with "did you mean" and the known names; or no name at all.
    """
    known = list(known)
    if isinstance(names, str):
        names = [names]
    names = [n.strip() for item in names for n in str(item).split(",") if n.strip()]
    if not names:
        raise ReportError(f"report: expected a section name or 'all', received none (known: {', '.join(known)})")
    if "all" in names:
        return known
    out: list[str] = []
    for name in names:
        if name not in known:
            close = difflib.get_close_matches(name, known, n=1, cutoff=0.5)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise ReportError(f"report: unknown section {name!r}{hint} (known: all, {', '.join(known)})")
        if name not in out:
            out.append(name)
    return out


# ---------------------------------------------------------------------------- results
@dataclass
class SectionOutcome:
    """What one section produced.

    Attributes
    ----------
    key, title, paper : str
        From the SectionSpec (or :func:`expected_sections` for a paper not built yet).
    status : {"ok", "missing", "error", "pending"}
        ``missing``: no section module yet; ``error``: its build raised (the blocks then hold
        one Missing block with the error); ``pending``: not built yet in a report that is
        still running (only in the index.html written between sections).
    blocks : list
        The blocks to render, in order.
    wall_s : float
        Wall time of the section's build [s].
    error : str
        ``"Type: message"`` when ``status == "error"``.
    traceback : str
    sweeps : list of dict
        One entry per ``ctx.sweep`` call: name, folder, total, run (done + failed), reused.
    """

    key: str
    title: str
    paper: str
    status: str
    blocks: list = field(default_factory=list)
    wall_s: float = 0.0
    error: str = ""
    traceback: str = ""
    summary: str = ""
    sweeps: list[dict[str, Any]] = field(default_factory=list)
    html_cache: str = field(default="", repr=False)

    @property
    def comparisons(self) -> list[Comparison]:
        return [b for b in self.blocks if isinstance(b, Comparison)]


@dataclass
class ReportResult:
    """What :func:`run_report` returns: the index file and each section's outcome."""

    index: Path
    sections: list[SectionOutcome]
    quick: bool
    wall_s: float

    @property
    def ok(self) -> bool:
        """False when some section raised (the report still holds every other section)."""
        return not any(s.status == "error" for s in self.sections)

    @property
    def errors(self) -> list[SectionOutcome]:
        return [s for s in self.sections if s.status == "error"]


# ---------------------------------------------------------------------------- output folder
def _check_out_dir(out_dir: Path) -> None:
    """``out_dir`` must be missing, empty, or a folder an earlier report wrote (it has the marker),
    and writable: not a symbolic link, not below a file or a read-only folder."""
    from teamnav.files import destination_problem

    problem = destination_problem(out_dir, folder=True)
    if problem is None and out_dir.is_dir() and not os.access(out_dir, os.W_OK | os.X_OK):
        problem = f"{out_dir} is read-only"
    if problem is not None:
        raise ReportError(f"--out {out_dir}: cannot be written ({problem}); choose another --out")
    if out_dir.exists() and not out_dir.is_dir():
        raise ReportError(f"--out {out_dir}: expected a folder for the report, received an existing file")
    if out_dir.is_dir() and any(out_dir.iterdir()) and not (out_dir / MARKER_NAME).is_file():
        raise ReportError(
            f"--out {out_dir}: expected a new or empty folder, or one an earlier `teamnav report` wrote "
            f"(it holds {MARKER_NAME}); received a non-empty folder that is not a report"
        )


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _write_marker(out_dir: Path, quick: bool) -> None:
    from teamnav import __version__

    marker = out_dir / MARKER_NAME
    data: dict[str, Any] = {}
    if marker.is_file():
        try:
            data = json.loads(marker.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            data = {}
    now = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    data.setdefault("created_at", now)
    data.update({"tool": "teamnav report", "teamnav_version": __version__, "last_started_at": now, "last_quick": quick})
    _write_atomic(marker, json.dumps(data, indent=2) + "\n")


# ---------------------------------------------------------------------------- building
def _check_blocks(blocks: Any, key: str) -> list:
    if not isinstance(blocks, (list, tuple)):
        raise TypeError(f"section {key}: build(ctx) must return a list of blocks, returned {type(blocks).__name__}")
    for i, block in enumerate(blocks):
        if not isinstance(block, _BLOCK_TYPES):
            names = ", ".join(t.__name__ for t in _BLOCK_TYPES)
            raise TypeError(f"section {key}: block {i} is a {type(block).__name__}; expected one of {names}")
    return list(blocks)


def _build_one(key: str, spec: SectionSpec | None, make_ctx: Callable[[str], Any], say: Callable[[str], None]) -> SectionOutcome:
    if spec is None:
        title, paper, _ = expected_sections()[key]
        return SectionOutcome(
            key, title, paper, "missing", [Missing(what="this paper's reproduction", why="system not built yet (no section module)")]
        )
    ctx = make_ctx(key)
    out = SectionOutcome(spec.key, spec.title, spec.paper, "ok", summary=spec.summary)
    say(f"section {key}: building ({'quick' if ctx.quick else 'full'})")
    t0 = time.perf_counter()
    try:
        out.blocks = _check_blocks(spec.build(ctx), key)
    except Exception as exc:  # noqa: BLE001 - one section's failure must not lose the others
        out.status = "error"
        out.error = f"{type(exc).__name__}: {exc}"
        out.traceback = traceback.format_exc()
        out.blocks = [Missing(what=f"section {key}", why=f"its build raised {out.error}")]
    out.wall_s = time.perf_counter() - t0
    out.sweeps = list(ctx.sweeps)
    say(f"section {key}: {out.status} in {out.wall_s:.1f} s" + (f" ({out.error})" if out.error else ""))
    return out


def _outcome_json(s: SectionOutcome) -> dict[str, Any]:
    return {
        "key": s.key,
        "title": s.title,
        "paper": s.paper,
        "status": s.status,
        "wall_s": round(s.wall_s, 3),
        "error": s.error or None,
        "traceback": s.traceback or None,
        "comparisons": [
            {"claim": c.claim, "column": c.column, "paper": c.paper, "ours": c.ours, "holds": c.holds,
             "differs": c.differs} for c in s.comparisons
        ],
        "ledger": [row.record() for b in s.blocks if isinstance(b, Ledger) for row in b.rows],
        "precondition": [b.record() for b in s.blocks if isinstance(b, Precondition)],
        "missing": [{"what": b.what, "why": b.why} for b in s.blocks if isinstance(b, Missing)],
        "sweeps": s.sweeps,
    }


def run_report(
    names: str | Sequence[str],
    out_dir: str | os.PathLike,
    *,
    quick: bool = False,
    executor: str = "local",
    workers: int | None = None,
    address: str | None = None,
    progress: bool = True,
    wait: bool = False,
    group_brains: bool = False,
) -> ReportResult:
    """Build the report and say how each section went (see :func:`build_report`).

    The report folder is claimed for the whole build (:func:`teamnav.files.claim`): a second
    report into the same folder refuses (:class:`~teamnav.files.ClaimError`), or waits with
    ``wait``; the claim goes on every way out (Ctrl-C and SIGTERM included).

    ``group_brains``: every run of the report steps teams through their compiled group brains
    where they have one (``docs/concepts/group-brains.md``): the same runs bit for bit, so it
    enters no trial id or configuration hash and stored trials are reused either way.

    Returns
    -------
    ReportResult
        ``.index`` is ``out_dir/index.html``; ``.ok`` is False when some section raised.

    Raises
    ------
    ReportError
        Unknown section name, an output folder that is not a report's, a bad executor option;
        raised before anything is written.
    """
    from teamnav.experiments.executors import make_executor
    from teamnav.experiments.signals import sigterm_raises
    from teamnav.experiments.sweep import SweepError
    from teamnav.files import claim

    t_start = time.perf_counter()
    if out_dir is None or not os.fspath(out_dir):
        raise ReportError("--out: expected a folder for the report, received nothing")
    out = Path(out_dir)
    try:
        make_executor(executor, workers=workers, address=address)  # checks the options, starts nothing
    except SweepError as exc:
        raise ReportError(str(exc)) from None
    sections = available_sections()
    keys = resolve_names(names, sections)
    _check_out_dir(out)
    with contextlib.ExitStack() as held:
        held.enter_context(sigterm_raises())  # SIGTERM: the claim goes, then the process ends
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            held.enter_context(claim(out, "report folder", command="teamnav report", wait=wait,
                                     say=lambda line: print(line, file=sys.stderr, flush=True)))
            _check_out_dir(out)  # what a report that held it before us left there
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ReportError(f"--out {out}: cannot be written ({exc.strerror or exc}); choose another --out") from None
        from teamnav.experiments.runner import group_brains_default

        with group_brains_default(group_brains):  # the runs a section makes itself, outside its sweeps
            return _run_report_claimed(out, keys, sections, quick, executor, workers, address, progress, t_start,
                                       group_brains)


def _run_report_claimed(out: Path, keys: list[str], sections: dict, quick: bool, executor: str, workers: int | None,
                        address: str | None, progress: bool, t_start: float,
                        group_brains: bool = False) -> ReportResult:
    """:func:`run_report` once the report folder is claimed."""
    from teamnav.experiments.executors import LocalExecutor
    from teamnav.experiments.report.context import SweepContext

    _write_marker(out, quick)

    def say(msg: str) -> None:
        if progress:
            print(msg, file=sys.stderr, flush=True)

    # local workers start once for the whole report, not once per sweep: a quick report is dozens
    # of sweeps of a few short trials, where the workers' start-up (imports, numba cache loads)
    # would otherwise cost more than the trials
    shared = LocalExecutor(workers, keep_pool=True) if executor == "local" else None

    def make_ctx(key: str) -> SweepContext:
        return SweepContext(out, quick=quick, executor=executor, workers=workers, address=address, progress=progress,
                            section=key, runner=shared, group_brains=group_brains)

    index = out / "index.html"
    outcomes: list[SectionOutcome] = []
    # off a terminal, a plain line every 10 s while a section works outside its sweeps (which
    # print their own lines; this one keeps quiet while they do)
    heartbeat = None
    if progress:
        from teamnav.experiments.progress import PlainProgress, stderr_is_terminal

        if not stderr_is_terminal():
            current = [""]
            heartbeat = PlainProgress("teamnav report", len(keys), "sections", quiet_if_recent=True,
                                      details=lambda: f"building {current[0]}").start()
    try:
        for i, key in enumerate(keys):
            if heartbeat is not None:
                current[0] = key
                heartbeat.update(i)
            outcomes.append(_build_one(key, sections[key], make_ctx, say))
            # rewrite the report after every section: a long full run shows what it has so far,
            # and the sections still to come are marked as pending, not left out
            pending = [_pending(k, sections[k]) for k in keys[i + 1 :]]
            _write_outputs(out, index, outcomes + pending, quick, executor, workers, address, time.perf_counter() - t_start)
    finally:
        if heartbeat is not None:
            heartbeat.close()
        if shared is not None:
            shared.close()
    if not keys:  # pragma: no cover - resolve_names never returns an empty list
        _write_outputs(out, index, [], quick, executor, workers, address, time.perf_counter() - t_start)
    return ReportResult(index=index, sections=outcomes, quick=quick, wall_s=time.perf_counter() - t_start)


def _pending(key: str, spec: SectionSpec | None) -> SectionOutcome:
    title, paper = (spec.title, spec.paper) if spec is not None else expected_sections()[key][:2]
    return SectionOutcome(key, title, paper, "pending", [Missing(what="this section", why="not built yet: the report is still running")])


def _write_outputs(out: Path, index: Path, outcomes: list[SectionOutcome], quick: bool, executor: str,
                   workers: int | None, address: str | None, wall_s: float) -> None:
    """Write index.html and report.json (each atomically)."""
    from teamnav import __version__
    from teamnav.experiments.report.html import render_report

    meta = {"quick": quick, "executor": executor, "workers": workers, "address": address, "wall_s": wall_s}
    _write_atomic(index, render_report(outcomes, meta))
    summary = {
        "teamnav_version": __version__,
        "written_at": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        **meta,
        "sections": [_outcome_json(s) for s in outcomes],
    }
    _write_atomic(out / "report.json", json.dumps(summary, indent=2, default=str) + "\n")


def build_report(
    names: str | Sequence[str],
    out_dir: str | os.PathLike,
    quick: bool = False,
    executor: str = "local",
    workers: int | None = None,
    address: str | None = None,
    progress: bool = True,
    wait: bool = False,
) -> Path:
    """Run (or reuse) the sweeps of the named sections and write ``out_dir/index.html``.

    Parameters
    ----------
    names : "all", str or list of str
        Section keys (``"collab-mcl"``), comma-separated keys, or ``"all"``.
    out_dir : str or Path
        The report folder: new, empty, or an earlier report's (then its sweeps are reused and
        only missing trials run). Holds ``index.html``, ``report.json``, ``sweeps/<name>/``.
    quick : bool
        The short version (few seeds, short runs; what CI runs). Default: the full reproduction.
    executor : {"local", "ray"}
        Where the trials run (see :func:`teamnav.experiments.sweep.sweep`).
    workers : int, optional
        Trials at once (default: all CPUs / the Ray cluster's).
    address : str, optional
        Ray cluster address, with ``executor="ray"``.
    progress : bool
        Progress bars and one line per section on stderr.
    wait : bool
        When another process is writing ``out_dir`` (it holds its claim, ``.NAME.lock`` beside
        it), wait for it instead of refusing.

    Returns
    -------
    Path
        ``out_dir/index.html``. A section that raised is shown in it as missing with its error;
        use :func:`run_report` to learn whether that happened.

    Raises
    ------
    ReportError
        See :func:`run_report`.
    """
    return run_report(names, out_dir, quick=quick, executor=executor, workers=workers, address=address, progress=progress,
                      wait=wait).index
