"""Built-in scenarios found by name (STYLE habit 9).

Every ``*.yaml`` file shipped in ``teamnav/experiments/scenarios/`` (the core's: ``demo``,
``depot``, ``swarm``) or in an installed paper's ``scenarios/`` folder (:mod:`teamnav.plugins`)
is a built-in scenario named after its stem (``demo.yaml`` is ``demo``). :func:`register` adds a scenario file from
elsewhere under a new name; a second registration of a name raises, and an unknown name gets
a "did you mean" hint.
"""

from __future__ import annotations

import difflib
from importlib import resources
from pathlib import Path

import yaml

__all__ = ["SCENARIO_DIR", "describe", "names", "path", "register"]

#: Folder of the core's scenario files (each paper's are in its own package folder).
SCENARIO_DIR: Path = Path(str(resources.files("teamnav.experiments"))) / "scenarios"

_EXTRA: dict[str, Path] = {}

#: libyaml's safe loader when PyYAML has it (a safe loader either way): `teamnav list` reads
#: every scenario file, and the pure-Python one takes ~1 s for them all
_FAST_SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _shipped() -> dict[str, Path]:
    """The core's scenario files, then every installed paper's; a name shipped twice keeps
    the first."""
    from teamnav import plugins

    found = {p.stem: p for p in sorted(SCENARIO_DIR.glob("*.yaml"))} if SCENARIO_DIR.is_dir() else {}
    for paper in plugins.papers().values():
        for p in paper.files("scenarios"):
            found.setdefault(p.stem, p)
    return found


def register(name: str, file: str | Path) -> None:
    """Make scenario file ``file`` available as ``name``.

    Raises
    ------
    ValueError
        If ``name`` is taken or ``file`` does not exist.
    """
    if name in _shipped() or name in _EXTRA:
        raise ValueError(f"scenario {name!r} is already registered (at {path(name)})")
    file = Path(file)
    if not file.is_file():
        raise ValueError(f"scenario file for {name!r} must exist, got {str(file)!r}")
    _EXTRA[name] = file


def names() -> list[str]:
    """All built-in and registered scenario names, sorted."""
    return sorted({**_shipped(), **_EXTRA})


def path(name: str) -> Path:
    """The file of scenario ``name``.

    Raises
    ------
    KeyError
        With a "did you mean" hint and the known names when ``name`` is unknown.
    """
    table = {**_shipped(), **_EXTRA}
    try:
        return table[name]
    except KeyError:
        close = difflib.get_close_matches(name, table, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise KeyError(f"unknown scenario {name!r}{hint} (known: {', '.join(sorted(table))})") from None


def describe(name: str) -> str:
    """The first line of scenario ``name``'s ``description`` (``""`` if it has none)."""
    try:
        data = yaml.load(path(name).read_text(encoding="utf-8"), Loader=_FAST_SAFE_LOADER)
    except (OSError, yaml.YAMLError):
        return "(unreadable)"
    text = str(data.get("description", "")) if isinstance(data, dict) else ""
    return text.strip().splitlines()[0] if text.strip() else ""
