"""What a paper's report section is made of (the contract between paper modules and the
HTML writer).

Every section module a paper declares (:attr:`teamnav.plugins.Paper.sections`) defines ``SECTION``, a
:class:`SectionSpec`: a key (``los-help``, ``collab-mcl``, ``blazing-a-trail``,
``try-to-see-it-my-way``), a title, the paper file, and ``build(ctx) -> list[Block]``. The
report runs (or reuses, through the resumable sweep store) the named sweeps a section asks
``ctx`` for and renders the blocks. A section whose system is not built yet returns a
:class:`Missing` block saying so: a report never shows numbers that were not measured.

Blocks
------
- :class:`Comparison`: one paper claim (a table cell, a figure's trend) beside ours, with a
  verdict (``holds`` true/false/None for not measured) and one sentence on where we differ.
- :class:`Table`: rows of cells (strings or numbers), typically "mean ± std (n)".
- :class:`Plot` / :class:`MapView`: figures described as data (curves with confidence bands;
  a map with point clouds), drawn by ``teamnav.viz`` into PNGs embedded in the report.
- :class:`Text`: a paragraph (plain text, escaped by the writer).
- :class:`Missing`: what is not there and why.
- :class:`Ledger`: where every parameter of a column comes from (``shared/FIDELITY.md`` §2):
  :class:`LedgerRow` s of ``name``, ``value``, ``source`` (:data:`LEDGER_SOURCES`), ``ref``.
- :class:`Precondition`: a behaviour the paper reports and its verdict needs, checked on
  tuning seeds before the judged run (FIDELITY §1); when it does not hold, the claims that
  need it read "precondition not met", never "fails".

The two columns (FIDELITY §1): :data:`COLUMNS`. A :class:`Comparison`, a :class:`LedgerRow`
names its ``column`` (``"paper"``: the paper as its authors ran it, judged; ``"teamnav"``: our
gap-fills beside it). ``report.json`` carries, per section, ``comparisons`` (each with its
``column``), ``ledger`` (rows with their ``column``) and ``precondition`` (every
:class:`Precondition` the section checked): one shape for every section.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Protocol, Sequence, Union


@dataclass(frozen=True)
class Text:
    text: str


@dataclass(frozen=True)
class Table:
    title: str
    columns: Sequence[str]
    rows: Sequence[Sequence[Any]]
    note: str = ""


@dataclass(frozen=True)
class Series:
    """One curve of a :class:`Plot`: ``y`` over ``x``, with an optional band ``lo``..``hi``
    (e.g. a 95 % confidence interval). ``style``: "line", "points", "line+points", "bar"
    or "step"."""

    label: str
    x: Sequence[float]
    y: Sequence[float]
    lo: Sequence[float] | None = None
    hi: Sequence[float] | None = None
    style: str = "line"


@dataclass(frozen=True)
class Plot:
    """A figure described as data; ``teamnav.viz`` draws it (only ``viz`` imports matplotlib,
    STYLE habit 15). ``hlines``: horizontal reference lines ``(y, label)`` (a paper's level,
    a threshold)."""

    title: str
    xlabel: str
    ylabel: str
    series: Sequence[Series]
    hlines: Sequence[tuple[float, str]] = ()
    logy: bool = False
    caption: str = ""


@dataclass(frozen=True)
class MapView:
    """A map with point clouds and markers on it (e.g. a belief before and after a detection).

    ``grid``: an :class:`~teamnav.world.grid.OccupancyGrid`; ``points``: ``(label, ndarray of
    shape (n, 2))`` in world metres; ``markers``: ``(label, x_m, y_m)``."""

    title: str
    grid: Any
    points: Sequence[tuple[str, Any]] = ()
    markers: Sequence[tuple[str, float, float]] = ()
    caption: str = ""


#: The report's columns: key -> what the reader sees. ``paper``: the paper as its authors ran
#: it (the judged column; brains run with ``paper_rules: true``); ``teamnav``: our gap-fills.
COLUMNS: dict[str, str] = {"paper": "paper as written", "teamnav": "teamnav"}

#: Where a parameter's value comes from (FIDELITY §2): ``stated`` by the paper; ``implied`` by
#: its numbers (the arithmetic in ``ref``); a ``fill`` of a silence, chosen by a rule written
#: before any run on tuning seeds; an ``artifact-fix`` of a behaviour of our simulator the paper
#: does not have; a ``literal-ablation``: a literal reading the authors' own text contradicts
#: (an ablation row, never the judged one).
LEDGER_SOURCES: tuple[str, ...] = ("stated", "implied", "fill", "artifact-fix", "literal-ablation")


def _check_column(column: str | None, where: str, *, optional: bool) -> None:
    if column is None and optional:
        return
    if column not in COLUMNS:
        raise ValueError(f"{where}: column must be one of {', '.join(map(repr, COLUMNS))}, got {column!r}")


@dataclass(frozen=True)
class Comparison:
    """One claim of the paper beside our measurement.

    ``paper``: the paper's number or statement ("379 ± 37 s → 153 ± 17 s (−60 %)").
    ``ours``: ours, with spread and count ("212 ± 40 s → 95 ± 22 s (−55 %), n = 8").
    ``holds``: whether the EXPERIMENTS.md "must show" criterion holds in our data (None: not
    measured). ``differs``: one sentence on where and why we differ. ``column``: which column
    of :data:`COLUMNS` measured ``ours`` (None: a comparison that is not per column).
    """

    claim: str
    paper: str
    ours: str
    holds: bool | None
    differs: str = ""
    column: str | None = None

    def __post_init__(self) -> None:
        _check_column(self.column, f"Comparison {self.claim!r}", optional=True)


@dataclass(frozen=True)
class LedgerRow:
    """One parameter of a column that is not the library default, and where its value comes from.

    ``ref``: the paper's section and sentence (quoted) for ``stated`` / ``implied`` (with the
    arithmetic) / ``literal-ablation``; for a ``fill``, the rule, the criterion and the tuning
    seeds it was chosen on; for an ``artifact-fix``, the simulator behaviour it removes.

    Examples
    --------
    >>> LedgerRow("paper", "cruise_speed_mps", 0.4, "implied", "§5: a 33 m route, round trip ~3 min").source
    'implied'
    >>> LedgerRow("paper", "sigma_hit_m", 0.2, "guessed", "")
    Traceback (most recent call last):
    ...
    ValueError: ledger row 'sigma_hit_m': source must be one of stated, implied, fill, artifact-fix, literal-ablation, got 'guessed'
    """

    column: str
    name: str
    value: Any
    source: str
    ref: str

    def __post_init__(self) -> None:
        _check_column(self.column, f"ledger row {self.name!r}", optional=False)
        if self.source not in LEDGER_SOURCES:
            raise ValueError(f"ledger row {self.name!r}: source must be one of {', '.join(LEDGER_SOURCES)}, "
                             f"got {self.source!r}")
        if not str(self.ref).strip():
            raise ValueError(f"ledger row {self.name!r}: ref must say where the value comes from (the paper's "
                             "section and sentence, or the fill's rule, criterion and tuning seeds)")

    def record(self) -> dict[str, Any]:
        """The row as ``report.json`` carries it."""
        value = self.value if isinstance(self.value, (bool, int, float, str, type(None))) else repr(self.value)
        return {"column": self.column, "name": self.name, "value": value, "source": self.source, "ref": self.ref}


@dataclass(frozen=True)
class Ledger:
    """A column's ledger (FIDELITY §2), printed after the section's verdict table."""

    rows: Sequence[LedgerRow]
    title: str = "Ledger: where each parameter comes from"
    note: str = ""


@dataclass(frozen=True)
class Precondition:
    """A behaviour the paper reports that its verdicts need, checked on tuning seeds first.

    ``what``: the behaviour ("Robin alone is still ambiguous when it passes the lab").
    ``seeds``: the tuning seeds or tasks it was checked on ("1000-1009"). ``result``: what was
    measured. ``holds``: True / False / None (not checked). ``claims``: the claim ids that need it.
    """

    what: str
    seeds: str
    result: str
    holds: bool | None
    claims: Sequence[str] = ()

    def record(self) -> dict[str, Any]:
        """The precondition as ``report.json`` carries it."""
        return {"what": self.what, "seeds": self.seeds, "result": self.result, "holds": self.holds,
                "claims": list(self.claims)}


@dataclass(frozen=True)
class Missing:
    what: str
    why: str


Block = Union[Text, Table, Plot, MapView, Comparison, Missing, Ledger, Precondition]


class ReportContext(Protocol):
    """What a section's ``build`` gets.

    ``quick``: the short version (CI: few seeds, short durations; minutes for the whole report).
    ``out_dir``: the report folder (sections may write extra files under ``out_dir/<key>/``).
    ``sweep(spec_or_name, **overrides)``: run or reuse a sweep into
    ``out_dir/sweeps/<sweep name>/`` with the report's executor and workers; returns the
    :class:`~teamnav.experiments.sweep.SweepResult` (``.rows()`` / ``.dataframe()``). Rerunning
    the report reuses finished trials (the store is resumable).
    ``progress``: whether to show progress bars.
    """

    quick: bool
    out_dir: Path
    progress: bool

    def sweep(self, name_or_spec: Any, **kwargs: Any) -> Any: ...


@dataclass(frozen=True)
class SectionSpec:
    key: str
    title: str
    paper: str  # file name under shared/papers, e.g. "sgorbissa-arkin-local-navigation-...txt"
    build: Callable[[ReportContext], list[Block]]
    summary: str = ""
    order: int = 100
    tags: tuple[str, ...] = field(default_factory=tuple)
