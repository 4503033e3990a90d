"""``paper_rules: true``: a brain's parameters as the paper wrote them, and the table of our gap-fills.

Each brain fills gaps its paper leaves open (a look-ahead point, a cool-down, a recovery rule...).
Where such a gap-fill has a value that *is* the paper's rule (0 m of look-ahead, no cool-down,
the flag off), the brain's pydantic Params model declares it in

``PAPER_RULES: ClassVar[dict[str, Any]]``
    {field name: the paper's value}; a dotted name (``"navigate.reverse_cooldown_m"``) names a
    field of a nested params model. Each entry carries a comment citing the paper section whose
    rule it restores, and ``PAPER_RULE_NOTES`` (same keys) says it in one line for the report.
``PAPER_RULES_NESTED: ClassVar[dict[str, tuple[type, dict]]]``
    {field holding a nested params dict: (its model, the brain's defaults over that model's)}.
    The nested model declares its own ``PAPER_RULES``; ``paper_rules`` is passed down to it.

and a field ``paper_rules: bool = False``. :func:`apply_paper_rules`, called from the model's
``model_validator(mode="before")``, gives every listed field the paper's value when
``paper_rules`` is true. Setting a listed field to another value as well is a validation error
naming the field: a run is either the paper as written or ours, never a silent mix.

:func:`gap_fills` lists the gap-fills of a params model with both values, for the reports'
"paper as written" / "teamnav" tables.

>>> from pydantic import BaseModel
>>> from typing import ClassVar
>>> class P(BaseModel):
...     PAPER_RULES: ClassVar[dict] = {"lookahead_m": 0.0}  # §2.3: around the position estimate
...     PAPER_RULE_NOTES: ClassVar[dict] = {"lookahead_m": "§2.3: crumbs around the position estimate"}
...     lookahead_m: float = 1.0
...     paper_rules: bool = False
...     _rules = paper_rules_validator()
>>> P(paper_rules=True).lookahead_m, P().lookahead_m
(0.0, 1.0)
>>> gap_fills(P)
[GapFill(field='lookahead_m', teamnav_value=1.0, paper_value=0.0, note='§2.3: crumbs around the position estimate')]
"""

from __future__ import annotations

from typing import Any, NamedTuple

from pydantic import model_validator

__all__ = ["GapFill", "apply_paper_rules", "gap_fills", "paper_rules_validator"]


class GapFill(NamedTuple):
    """One gap-fill of a brain: the field, our default, the paper's value, and where the paper says so."""

    field: str
    teamnav_value: Any
    paper_value: Any
    note: str


_UNSET = object()


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, bool) or isinstance(b, bool):
        return a is b or (isinstance(a, bool) and isinstance(b, bool) and a == b)
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return float(a) == float(b)
    return a == b


def apply_paper_rules(cls: type, data: Any) -> Any:
    """The input of ``cls`` (a params model) with its ``PAPER_RULES`` applied when ``paper_rules``
    is true; unchanged otherwise (also when it is not a mapping: pydantic reports that).

    Nested params dicts named in ``PAPER_RULES_NESTED`` receive ``paper_rules: true`` (their model
    applies its own rules); dotted ``PAPER_RULES`` entries are set in the nested dict here.

    Raises
    ------
    ValueError
        A listed field is also set to a value other than the paper's (the message names it).
    """
    if not isinstance(data, dict) or data.get("paper_rules") is not True:
        return data
    out = dict(data)
    rules: dict[str, Any] = getattr(cls, "PAPER_RULES", {})
    nested: dict[str, tuple[type, dict]] = getattr(cls, "PAPER_RULES_NESTED", {})
    for name, (model, _) in nested.items():
        sub = out.get(name, {})
        if isinstance(sub, dict):
            if sub.get("paper_rules", True) is not True:
                raise ValueError(f"paper_rules: true also applies to {name}; {name}.paper_rules must not be false")
            for key, value in getattr(model, "PAPER_RULES", {}).items():  # named here with its prefix
                if key in sub and not _same(sub[key], value):
                    raise ValueError(
                        f"{name}.{key}: paper_rules: true sets it to the paper's value {value!r}, but it is also "
                        f"set to {sub[key]!r}; drop one of the two (a run is the paper as written or ours, not a mix)")
            out[name] = {**sub, "paper_rules": True}
    for key, value in rules.items():
        head, _, tail = key.partition(".")
        target = out
        field = head
        if tail:
            sub = out.get(head, {})
            if not isinstance(sub, dict):
                continue  # pydantic reports the bad type
            target = out[head] = dict(sub)
            field = tail
        given = target.get(field, _UNSET)
        if given is not _UNSET and not _same(given, value):
            raise ValueError(
                f"{key}: paper_rules: true sets it to the paper's value {value!r}, but it is also set to "
                f"{given!r}; drop one of the two (a run is the paper as written or ours, not a mix)")
        target[field] = value
    return out


def paper_rules_validator():
    """A ``model_validator(mode="before")`` applying :func:`apply_paper_rules`; assign it in the
    model's body (``_paper_rules = paper_rules_validator()``)."""

    def _apply(cls, data: Any) -> Any:
        return apply_paper_rules(cls, data)

    return model_validator(mode="before")(classmethod(_apply))


def _default(model: type, name: str) -> Any:
    f = model.model_fields[name]
    return f.get_default(call_default_factory=True)


def gap_fills(params_cls: type, ours: dict[str, Any] | None = None) -> list[GapFill]:
    """Every gap-fill of ``params_cls`` with our value and the paper's, nested models' included
    (dotted names; their "teamnav" value is the brain's default over the nested model's).

    ``ours``: the params a scenario gives the brain (e.g. ``cruise_speed_mps: 0.4``, a
    ``navigate`` dict); their values replace the defaults in the "teamnav" column.

    Raises
    ------
    KeyError
        A ``PAPER_RULES`` entry names no field (a typo in the declaration).
    """
    out: list[GapFill] = []
    given = ours or {}
    notes: dict[str, str] = getattr(params_cls, "PAPER_RULE_NOTES", {})
    nested: dict[str, tuple[type, dict]] = getattr(params_cls, "PAPER_RULES_NESTED", {})
    for key, value in getattr(params_cls, "PAPER_RULES", {}).items():
        head, _, tail = key.partition(".")
        if tail:
            model, defaults = nested[head]
            ours = defaults.get(tail, _default(model, tail))
        else:
            if head not in params_cls.model_fields:
                raise KeyError(f"{params_cls.__name__}.PAPER_RULES names {head!r}, which is not a field")
            ours = _default(params_cls, head)
        out.append(GapFill(key, _given(given, key, ours), value, notes.get(key, "")))
    for head, (model, defaults) in nested.items():
        for g in gap_fills(model):
            key = f"{head}.{g.field}"
            out.append(GapFill(key, _given(given, key, defaults.get(g.field, g.teamnav_value)), g.paper_value, g.note))
    return out


def _given(given: dict[str, Any], key: str, default: Any) -> Any:
    head, _, tail = key.partition(".")
    if not tail:
        return given.get(head, default)
    sub = given.get(head)
    return sub.get(tail, default) if isinstance(sub, dict) else default
