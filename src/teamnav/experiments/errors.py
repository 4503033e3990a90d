"""One clear message for every bad scenario input.

Everything a user can get wrong before a run starts (a YAML typo, an unknown key, a NaN, an
out-of-range number, a missing or malformed map, an unknown controller, bad controller
parameters, a bad ``--set`` override) ends in a :class:`ScenarioError`: a ``ValueError``
whose message is one paragraph naming the file, then one line per problem with the field
path (``robots[0].sensors[1].max_range_m``), what was expected and what was received. The
CLI prints it and exits with status 2; no traceback from deep inside (DESIGN "Conventions").
"""

from __future__ import annotations

import difflib
import math
import re
from dataclasses import dataclass
from typing import Any, Iterable, Sequence

import yaml
from pydantic import BaseModel, ValidationError

__all__ = [
    "Problem",
    "ScenarioError",
    "YamlLimitError",
    "bounded_repr",
    "format_loc",
    "from_validation_error",
    "from_yaml_error",
    "show_value",
]


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a scenario.

    Attributes
    ----------
    field : str
        Field path, e.g. ``"robots[0].count"``; ``""`` for the file as a whole.
    message : str
        What was expected, in words (``"expected an integer >= 1"``).
    received : str or None
        What was found, already formatted for display; None when there is nothing to show.
    note : str or None
        Where the value came from, e.g. ``"from --set robots.0.count=abc"``.
    """

    field: str
    message: str
    received: str | None = None
    note: str | None = None

    def line(self) -> str:
        where = f"{self.field}: " if self.field else ""
        got = f" (received {self.received})" if self.received is not None else ""
        note = f" [{self.note}]" if self.note else ""
        return f"{where}{self.message}{got}{note}"


class ScenarioError(ValueError):
    """A scenario (file, name or override) is invalid.

    Parameters
    ----------
    file : str
        The scenario file (or ``"<scenario name>"`` / ``"<code>"``) at fault.
    problems : sequence of Problem
        At least one problem.

    Attributes
    ----------
    file : str
    problems : tuple of Problem

    Examples
    --------
    >>> err = ScenarioError("demo.yaml", [Problem("robots[0].count", "expected an integer >= 1", "0")])
    >>> print(err)
    scenario demo.yaml: robots[0].count: expected an integer >= 1 (received 0)
    """

    def __init__(self, file: str, problems: Sequence[Problem]) -> None:
        if not problems:
            raise ValueError("ScenarioError needs at least one problem")
        self.file = str(file)
        self.problems = tuple(problems)
        if len(self.problems) == 1:
            text = f"scenario {self.file}: {self.problems[0].line()}"
        else:
            lines = "\n".join(f"  {p.line()}" for p in self.problems)
            text = f"scenario {self.file} has {len(self.problems)} problems:\n{lines}"
        super().__init__(text)

    @classmethod
    def one(cls, file: str, field: str, message: str, received: Any = None, *, raw: bool = False) -> "ScenarioError":
        """A single-problem error; ``received`` is shown with :func:`show_value` unless ``raw``."""
        shown = None if received is None else (str(received) if raw else show_value(received))
        return cls(file, [Problem(field, message, shown)])


# ---------------------------------------------------------------------------- formatting
# show_value, bounded_repr and YamlLimitError live in teamnav.safe_yaml (the map loader uses
# them too) and are re-exported here.
from teamnav.safe_yaml import YamlLimitError, bounded_repr, show_value  # noqa: E402,F401


def format_loc(loc: Iterable[Any], data: Any = None) -> str:
    """Field path from a pydantic ``loc``: ``('robots', 0, 'sensors', 1, 'laser', 'max_range_m')``
    becomes ``robots[0].sensors[1].max_range_m``.

    pydantic puts discriminated-union tags (``'laser'``) and union member names in the
    location; walking the input ``data`` alongside tells them apart from real keys.
    """
    out = ""
    node = data
    for key in loc:
        if isinstance(key, int):
            out += f"[{key}]"
            node = node[key] if isinstance(node, (list, tuple)) and -len(node) <= key < len(node) else None
            continue
        key = str(key)
        if _is_tag(key, node):
            continue
        out += f".{key}" if out else key
        node = node.get(key) if isinstance(node, dict) else None
    return out


#: words pydantic uses for union members in error locations
_TYPE_WORDS = frozenset(
    {"float", "int", "str", "bool", "none", "list", "tuple", "dict", "set", "frozenset", "bytes", "is-instance",
     "lax-or-strict", "json-or-python", "union", "nullable", "default"}
)


def _is_tag(key: str, node: Any) -> bool:
    """Whether ``key`` in an error location names a union member rather than a field."""
    if isinstance(node, dict):
        if key in node:
            return False
        if node.get("kind") == key:  # discriminated union ('laser', 'sonar', ...)
            return True
    return "[" in key or key in _TYPE_WORDS or key[:1].isupper()


_LEADING_PATH = re.compile(r"^([A-Za-z_][\w.\[\]]*): (.*)$", re.S)

_PYDANTIC_MESSAGES = {
    "extra_forbidden": "unknown key",
    "missing": "required field is missing",
    "finite_number": "expected a finite number (NaN and infinity are not allowed)",
}


def _known_keys(model: type[BaseModel] | None) -> set[str]:
    """Every field name of ``model`` and of the models nested in it (for "did you mean")."""
    seen: set[type] = set()
    keys: set[str] = set()

    def visit(tp: Any) -> None:
        if isinstance(tp, type) and issubclass(tp, BaseModel):
            if tp in seen:
                return
            seen.add(tp)
            for name, f in tp.model_fields.items():
                keys.add(name)
                visit(f.annotation)
        for arg in getattr(tp, "__args__", ()) or ():
            visit(arg)
        for meta in getattr(tp, "__metadata__", ()) or ():
            visit(meta)
        origin = getattr(tp, "__origin__", None)
        if origin is not None and origin is not tp:
            visit(origin)

    if model is not None:
        visit(model)
    return keys


def from_validation_error(
    exc: ValidationError,
    file: str,
    data: Any = None,
    *,
    model: type[BaseModel] | None = None,
    prefix: str = "",
    notes: dict[str, str] | None = None,
) -> ScenarioError:
    """Turn every error of a pydantic ``ValidationError`` into a :class:`Problem`.

    Parameters
    ----------
    exc : ValidationError
    file : str
        The scenario file, for the message.
    data : object, optional
        The validated input, to tell union tags from keys in locations.
    model : pydantic model class, optional
        Its field names feed the "did you mean" hint for unknown keys.
    prefix : str
        Prepended to every field path (``"robots[0].params"`` for controller parameters).
    notes : dict of str to str, optional
        Extra text for problems whose path starts with a key (e.g. which ``--set`` made it).
    """
    known = _known_keys(model)
    problems = []
    for err in exc.errors(include_url=False):
        path = format_loc(err.get("loc", ()), data)
        if prefix:
            path = f"{prefix}.{path}" if path else prefix
        kind = err.get("type", "")
        msg = _PYDANTIC_MESSAGES.get(kind, err.get("msg", "invalid value"))
        if msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        # a validator that names the field itself ("map.builtin: unknown ...") sets the path
        m = _LEADING_PATH.match(msg)
        if m and (not path or _nested(m.group(1), path)):
            path, msg = m.group(1), m.group(2)
        if kind.startswith("greater") or kind.startswith("less") or kind in {"finite_number"}:
            msg = msg.replace("Input should be", "expected a number")
        msg = msg.replace("Input should be", "expected")
        received: str | None
        if kind == "missing":
            received = None
        elif kind == "extra_forbidden":
            leaf = path.rsplit(".", 1)[-1]
            close = difflib.get_close_matches(leaf, known, n=1)
            if close:
                msg += f"; did you mean {close[0]!r}?"
            received = None
        elif "input" in err and not isinstance(err["input"], dict):
            received = show_value(err["input"])
        else:
            received = None
        note = next((n for key, n in (notes or {}).items() if _nested(path, key) or _nested(key, path)), None)
        problems.append(Problem(path, msg, received, note))
    return ScenarioError(file, problems)


def _nested(inner: str, outer: str) -> bool:
    """Whether field path ``inner`` is ``outer`` or lies under it."""
    return bool(outer) and (inner == outer or inner.startswith(outer + ".") or inner.startswith(outer + "["))


def from_yaml_error(exc: yaml.YAMLError, file: str) -> ScenarioError:
    """A YAML syntax error, with its line and column (1-based); a :class:`YamlLimitError`
    names its field."""
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    where = f"line {mark.line + 1}, column {mark.column + 1}" if mark is not None else "unknown position"
    if isinstance(exc, YamlLimitError):
        return ScenarioError(file, [Problem(exc.field, f"{exc.problem} (at {where})")])
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    context = getattr(exc, "context", None)
    text = f"{context}, {problem}" if context else str(problem)
    return ScenarioError(file, [Problem("", f"YAML syntax error at {where}: expected valid YAML, {text}")])
