"""Papers plug into the core through one path: the ``teamnav.papers`` entry-point group.

The core (``geometry``, ``world``, ``localization``, ``control``, ``sim``, ``env``,
``experiments``, ``viz``, ``cli``) names no paper. A paper system is a package that declares a
:class:`Paper` and registers it in its ``pyproject.toml``, the way teamnav registers its own
five (``teamnav.papers.los_help`` and the others)::

    [project.entry-points."teamnav.papers"]
    my_paper = "my_pkg.paper:PAPER"

Once the package is installed, ``teamnav list`` shows its scenarios, brains and maps,
``teamnav sweep`` runs its sweeps, ``teamnav run`` computes its metric sets, and ``teamnav
report`` builds its sections and judges its claims. Everything in a :class:`Paper` is a
string (a module path or ``"module:attr"``), so discovering papers imports nothing heavy;
the brain, map, metric set or section is imported when it is first used.

Files live in the paper's package folder (``package``): ``scenarios/*.yaml`` (built-in
scenarios named by their stem), ``sweeps/*.yaml`` (named sweeps), ``claims/<section>.yaml``
(the claims a section judges, :mod:`teamnav.experiments.claims`).
"""

from __future__ import annotations

import functools
import importlib
import warnings
from dataclasses import dataclass, field
from importlib import metadata, resources
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

__all__ = ["ENTRY_POINT_GROUP", "Paper", "PaperError", "PaperSection", "papers", "resolve"]

#: The entry-point group papers register under.
ENTRY_POINT_GROUP = "teamnav.papers"


class PaperError(ValueError):
    """A paper's declaration is malformed (names the entry point and the field)."""


@dataclass(frozen=True)
class PaperSection:
    """A report section a paper contributes.

    Attributes
    ----------
    key : str
        Section name (``teamnav report KEY``), e.g. ``"los-help"``.
    module : str
        Module defining ``SECTION`` (a :class:`~teamnav.experiments.report.model.SectionSpec`).
    title, paper : str
        Shown when the module cannot be imported (the report then lists the section as an
        error instead of losing it); ``paper`` is the paper's file name in ``shared/papers/``.
    order : int
        Place in the report (smaller first).
    """

    key: str
    module: str
    title: str = ""
    paper: str = ""
    order: int = 100


@dataclass(frozen=True)
class Paper:
    """What one paper system contributes to the core. Every entry is a string; nothing is
    imported until used.

    Attributes
    ----------
    key : str
        Short name (``"los_help"``), unique among installed papers.
    title : str
        One line for people.
    package : str
        The paper's package; its folder holds ``scenarios/``, ``sweeps/`` and ``claims/``.
    brains : mapping of str to str
        Controller name (``"los-explorer-v1"``) to ``"module:Class"``.
    maps : mapping of str to str or (str, mapping)
        Built-in map name to ``"module:factory"``, or ``("module:factory", {keyword: value})``
        for a variant of one factory.
    metric_sets : mapping of str to str
        Metric set name to the module that registers its metrics on import (and may declare
        ``HEADLINE``, see :mod:`teamnav.experiments.metric_sets`). The core imports every
        paper's sets in the order of their names.
    sections : sequence of PaperSection
        Report sections.
    """

    key: str
    title: str
    package: str
    brains: Mapping[str, str] = field(default_factory=dict)
    maps: Mapping[str, Any] = field(default_factory=dict)
    metric_sets: Mapping[str, str] = field(default_factory=dict)
    sections: Sequence[PaperSection] = ()

    def folder(self) -> Path | None:
        """The package's folder on disk (None when it is not a plain folder)."""
        try:
            root = resources.files(self.package)
        except (ModuleNotFoundError, TypeError):
            return None
        path = Path(str(root))
        return path if path.is_dir() else None

    def files(self, sub: str, pattern: str = "*.yaml") -> list[Path]:
        """The files ``pattern`` in the package's ``sub`` folder, sorted."""
        folder = self.folder()
        if folder is None or not (folder / sub).is_dir():
            return []
        return sorted((folder / sub).glob(pattern))


def _check(paper: Any, where: str) -> Paper:
    if not isinstance(paper, Paper):
        raise PaperError(f"{where}: expected a teamnav.plugins.Paper, found {type(paper).__name__}")
    for name, entry in paper.brains.items():
        if not isinstance(entry, str) or ":" not in entry:
            raise PaperError(f"{where}: brains[{name!r}] must be 'module:Class', got {entry!r}")
    for name, entry in paper.maps.items():
        target = entry[0] if isinstance(entry, tuple) else entry
        if not isinstance(target, str) or ":" not in target:
            raise PaperError(f"{where}: maps[{name!r}] must be 'module:factory' or ('module:factory', kwargs), got {entry!r}")
    for s in paper.sections:
        if not isinstance(s, PaperSection):
            raise PaperError(f"{where}: sections must hold PaperSection, found {type(s).__name__}")
    return paper


@functools.cache
def papers() -> dict[str, Paper]:
    """Every installed paper, by key, sorted by key.

    A registration that cannot be loaded or is malformed is skipped with a warning naming the
    entry point (one broken plug-in must not take the others down); two papers with one key
    keep the first.
    """
    found: dict[str, Paper] = {}
    eps = sorted(metadata.entry_points(group=ENTRY_POINT_GROUP), key=lambda e: (e.name, e.value))
    seen: set[tuple[str, str]] = set()
    for ep in eps:
        if (ep.name, ep.value) in seen:  # the same distribution found twice on the path
            continue
        seen.add((ep.name, ep.value))
        where = f"entry point {ep.name} = {ep.value} (group {ENTRY_POINT_GROUP})"
        try:
            paper = _check(ep.load(), where)
        except Exception as exc:  # noqa: BLE001 - a broken plug-in is reported, not fatal
            warnings.warn(f"teamnav: skipped paper {where}: {type(exc).__name__}: {exc}", stacklevel=2)
            continue
        if paper.key in found:
            warnings.warn(f"teamnav: paper key {paper.key!r} of {where} is taken by "
                          f"{found[paper.key].package}; skipped", stacklevel=2)
            continue
        found[paper.key] = paper
    return dict(sorted(found.items()))


def resolve(entry: str) -> Any:
    """The object named by ``"module:attr"``."""
    module, _, attr = entry.partition(":")
    return getattr(importlib.import_module(module), attr)


def map_factory(entry: Any) -> Callable[[], Any]:
    """A zero-argument factory for a :attr:`Paper.maps` entry."""
    if isinstance(entry, tuple):
        target, kwargs = entry
        return functools.partial(resolve(target), **dict(kwargs))
    return resolve(entry)
