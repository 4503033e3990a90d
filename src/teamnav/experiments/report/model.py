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


@dataclass(frozen=True)
class Comparison:
    """One claim of the paper beside our measurement.

    ``paper``: the paper's number or statement ("379 ± 37 s → 153 ± 17 s (−60 %)").
    ``ours``: ours, with spread and count ("212 ± 40 s → 95 ± 22 s (−55 %), n = 8").
    ``holds``: whether the EXPERIMENTS.md "must show" criterion holds in our data (None: not
    measured). ``differs``: one sentence on where and why we differ.
    """

    claim: str
    paper: str
    ours: str
    holds: bool | None
    differs: str = ""


@dataclass(frozen=True)
class Missing:
    what: str
    why: str


Block = Union[Text, Table, Plot, MapView, Comparison, Missing]


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
