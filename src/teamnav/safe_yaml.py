"""YAML that cannot hurt: safe loading with bounded nesting, alias expansion and duplicate
keys refused, and bounded display of received values.

Scenario, sweep and ``--set`` YAML (:mod:`teamnav.experiments.spec`) and map YAML
(:mod:`teamnav.world.mapio`) are read with :class:`LimitedSafeLoader`: only PyYAML's safe
constructors (no Python objects), and a "billion laughs" or 20 000 nested brackets is refused
before anything walks it. Error messages show received values with :func:`show_value`, whose
work is bounded however large the value.
"""

from __future__ import annotations

import math
from typing import Any

import yaml

__all__ = ["YAML_MAX_DEPTH", "YAML_MAX_NODES", "LimitedSafeLoader", "YamlLimitError", "bounded_repr", "safe_load",
           "show_value"]

_MERGE_TAG = "tag:yaml.org,2002:merge"


class YamlLimitError(yaml.MarkedYAMLError):
    """YAML that parses but that teamnav refuses: a duplicate key, nesting deeper than a limit,
    aliases that expand past a limit, a self-referencing alias.

    Parameters
    ----------
    field : str
        Field path of the offending node (``robots[0].count``; ``""`` for the document).
    problem : str
        What is wrong and what was expected, in words.
    mark : yaml.Mark or None
        Where in the text (line and column).
    """

    def __init__(self, field: str, problem: str, mark: Any = None) -> None:
        super().__init__(problem=problem, problem_mark=mark)
        self.field = field

    def __str__(self) -> str:
        where = f" at line {self.problem_mark.line + 1}, column {self.problem_mark.column + 1}" if self.problem_mark else ""
        return f"{self.field + ': ' if self.field else ''}{self.problem}{where}"



def show_value(v: Any, limit: int = 80) -> str:
    """A short display of a received value: ``repr`` for scalars, ``.nan``-style for NaN/inf.

    The work is bounded by ``limit`` (see :func:`bounded_repr`), so a value that would print
    as gigabytes (a YAML "billion laughs", a huge list) costs no more than a small one.
    """
    if isinstance(v, float) and not math.isfinite(v):
        text = "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf")
    else:
        text = bounded_repr(v, limit)
    return text if len(text) <= limit else text[: limit - 3] + "..."


class _Full(Exception):
    """Raised inside :func:`bounded_repr` once enough text has been produced."""


def bounded_repr(v: Any, limit: int = 80, *, max_depth: int = 20) -> str:
    """``repr(v)`` cut to ``limit`` characters (ending in ``...``), computed lazily.

    Dicts, lists and tuples are walked item by item and the walk stops as soon as ``limit``
    characters exist, so the cost is bounded by ``limit`` whatever the size of ``v`` (shared
    sub-structures, as YAML aliases make, are never expanded in full); deeper than
    ``max_depth`` shows ``...``, so a self-referencing value terminates. For values that fit,
    the text equals ``repr(v)``.

    Examples
    --------
    >>> bounded_repr([1, "a", {"b": (2,)}])
    "[1, 'a', {'b': (2,)}]"
    >>> x = [0] * 10
    >>> for _ in range(30):
    ...     x = [x] * 10  # 10**31 items if printed in full
    >>> bounded_repr(x, 20)
    '[[[[[[[[[[[[[[[[[...'
    """
    parts: list[str] = []
    size = 0

    def emit(text: str) -> None:
        nonlocal size
        parts.append(text)
        size += len(text)
        if size > limit:
            raise _Full

    def walk(x: Any, depth: int) -> None:
        if depth > max_depth:
            emit("...")
        elif type(x) is dict:
            emit("{")
            for i, (k, val) in enumerate(x.items()):
                emit(", " if i else "")
                walk(k, depth + 1)
                emit(": ")
                walk(val, depth + 1)
            emit("}")
        elif type(x) in (list, tuple):
            emit("[" if type(x) is list else "(")
            for i, item in enumerate(x):
                emit(", " if i else "")
                walk(item, depth + 1)
            emit("]" if type(x) is list else ("," if len(x) == 1 else "") + ")")
        elif isinstance(x, (str, bytes)):
            emit(repr(x[: limit + 1]) if len(x) > limit else repr(x))
        else:
            emit(repr(x))

    try:
        walk(v, 0)
    except _Full:
        pass
    text = "".join(parts)
    return text if len(text) <= limit else text[: max(limit - 3, 0)] + "..."



#: Deepest nesting of mappings and lists a scenario, sweep or ``--set`` YAML may have (a
#: scenario needs about 6; deeper documents are refused before Python's recursion limit).
YAML_MAX_DEPTH = 100
#: Most values (scalars, lists, mappings) a YAML document may hold once every alias
#: (``*name``) is expanded: refuses a "billion laughs" before anything walks it.
YAML_MAX_NODES = 1_000_000


class LimitedSafeLoader(yaml.SafeLoader):
    """PyYAML's safe loader that refuses, with a :class:`YamlLimitError` naming the field and
    the line: a key given twice in one mapping (plain YAML keeps the last one
    silently), nesting deeper than :data:`YAML_MAX_DEPTH`, more than :data:`YAML_MAX_NODES`
    values once aliases are expanded, and an alias inside the node it refers to.
    """

    def __init__(self, stream) -> None:
        super().__init__(stream)
        self._path: list[str] = []
        self._size: dict[int, int] = {}  # id(node) -> values under it, aliases expanded

    def _field(self, extra: str = "") -> str:
        text = "".join(self._path) + extra
        text = text[1:] if text.startswith(".") else text
        return text if len(text) <= 80 else text[:60] + "..." + text[-17:]

    def compose_node(self, parent, index):  # noqa: D102 - PyYAML hook
        event = self.peek_event()
        if isinstance(index, yaml.ScalarNode):
            seg = f".{index.value}"
        elif isinstance(index, int):
            seg = f"[{index}]"
        else:
            seg = ""  # the document, or a mapping key
        if len(self._path) >= YAML_MAX_DEPTH:
            raise YamlLimitError(
                self._field(),
                f"nested more than {YAML_MAX_DEPTH} levels deep; expected at most {YAML_MAX_DEPTH} levels of mappings and lists",
                event.start_mark,
            )
        self._path.append(seg)
        try:
            node = super().compose_node(parent, index)
        finally:
            self._path.pop()
        size = self._size.get(id(node))
        if size is None:
            if isinstance(event, yaml.AliasEvent):
                raise YamlLimitError(
                    self._field(seg),
                    f"alias *{event.anchor} is used inside the node it names (a self-referencing structure); "
                    "expected aliases to refer to complete nodes",
                    event.start_mark,
                )
            if isinstance(node, yaml.MappingNode):
                seen: dict[tuple[str, str], Any] = {}
                for key, _ in node.value:
                    if isinstance(key, yaml.ScalarNode) and key.tag != _MERGE_TAG:
                        first = seen.setdefault((key.tag, key.value), key)
                        if first is not key:
                            raise YamlLimitError(
                                self._field(seg + f".{key.value}"),
                                f"duplicate key {show_value(key.value)} (first given at line {first.start_mark.line + 1}); "
                                "expected each key once in a mapping",
                                key.start_mark,
                            )
                size = 1 + sum(self._size[id(k)] + self._size[id(v)] for k, v in node.value)
            elif isinstance(node, yaml.SequenceNode):
                size = 1 + sum(self._size[id(v)] for v in node.value)
            else:
                size = 1
            self._size[id(node)] = size
        if size > YAML_MAX_NODES:
            raise YamlLimitError(
                self._field(seg),
                f"expands to more than {YAML_MAX_NODES:,} values through aliases (*name) or sheer size; "
                f"expected at most {YAML_MAX_NODES:,} (teamnav.safe_yaml.YAML_MAX_NODES)",
                event.start_mark,
            )
        return node



def safe_load(text: str) -> Any:
    """Parse YAML text with :class:`LimitedSafeLoader` (YAML 1.1 scalars, as ``yaml.safe_load``)."""
    return yaml.load(text, Loader=LimitedSafeLoader)  # noqa: S506 - a SafeLoader subclass
