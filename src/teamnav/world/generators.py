"""The registry of built-in maps: every installed paper's maps, found by name.

The maps themselves are drawn where their paper lives (``teamnav.papers.<paper>.maps``, with
:class:`~teamnav.world.map_builder.MapBuilder`) and registered through the ``teamnav.papers``
entry-point group (:attr:`teamnav.plugins.Paper.maps`); this module builds one by name. The
papers show their environments only as figures, so each map is faithful to what the text and
figures say (sizes, topology, what makes it hard) and is otherwise plain office geometry;
every choice is written in its generator's docstring and in :attr:`EnvironmentMap.notes`.

All lengths are metres; all maps default to 0.1 m cells. Nothing here is random.
"""

from __future__ import annotations

import difflib
import functools
import warnings
from collections.abc import Mapping
from typing import Any, Callable, Iterator

from teamnav.world.map_builder import EnvironmentMap, MapBuilder

__all__ = ["MapBuilder", "EnvironmentMap", "BUILTIN_MAPS", "builtin_map"]


class _BuiltinMaps(Mapping):
    """``{name: factory}`` (called with no argument, or a resolution) of every installed paper's maps, read on first use."""

    @functools.cached_property
    def _table(self) -> dict[str, Callable[[], EnvironmentMap]]:
        from teamnav import plugins

        table: dict[str, Callable[[], EnvironmentMap]] = {}
        for paper in plugins.papers().values():
            for name, entry in paper.maps.items():
                if name in table:
                    warnings.warn(f"teamnav: paper {paper.key!r} registers map {name!r}, which is taken; skipped",
                                  stacklevel=2)
                    continue
                table[name] = functools.partial(_build, entry)
        return table

    def __getitem__(self, name: str) -> Callable[[], EnvironmentMap]:
        return self._table[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._table)

    def __len__(self) -> int:
        return len(self._table)

    def __repr__(self) -> str:
        return f"BUILTIN_MAPS({sorted(self._table)})"


def _build(entry: Any, *args: Any, **kwargs: Any) -> EnvironmentMap:
    """Build a paper's map entry (arguments, such as ``resolution_m``, go to its factory)."""
    from teamnav import plugins

    return plugins.map_factory(entry)(*args, **kwargs)


#: Every built-in map by name: ``BUILTIN_MAPS[name]()`` builds it (``BUILTIN_MAPS[name](0.05)`` at 5 cm).
BUILTIN_MAPS: Mapping[str, Callable[[], EnvironmentMap]] = _BuiltinMaps()


def builtin_map(name: str) -> EnvironmentMap:
    """Build the built-in environment ``name`` (a key of :data:`BUILTIN_MAPS`).

    Raises
    ------
    ValueError
        For an unknown name, with a "did you mean" hint and the known names.

    Examples
    --------
    >>> builtin_map("hexagon").grid.shape
    (150, 170)
    """
    try:
        factory = BUILTIN_MAPS[name]
    except (KeyError, TypeError):
        close = difflib.get_close_matches(str(name), list(BUILTIN_MAPS), n=1)
        hint = f" Did you mean {close[0]!r}?" if close else ""
        raise ValueError(f"unknown built-in map {name!r}.{hint} Known maps: {', '.join(sorted(BUILTIN_MAPS))}") from None
    return factory()


def __getattr__(name: str) -> Any:
    """The map factories this module used to define (``office_simple``, ``hexagon``, ...), now
    in their paper's ``maps`` module: found there, with a deprecation warning (kept one release)."""
    from teamnav import plugins

    for paper in plugins.papers().values():
        for entry in paper.maps.values():
            target = entry[0] if isinstance(entry, tuple) else entry
            module, _, attr = target.partition(":")
            if attr == name:
                warnings.warn(f"teamnav.world.generators.{name} moved to {module}.{name}", DeprecationWarning,
                              stacklevel=2)
                return plugins.resolve(target)
    raise AttributeError(f"module 'teamnav.world.generators' has no attribute {name!r}")
