"""The sweep description: :class:`SweepSpec`, its options and the named sweeps.

A sweep is a scenario, a grid of ``--set``-style overrides and a number (or list) of seeds
(:mod:`teamnav.experiments.sweep` runs it). This module holds what describes one: the
validated :class:`SweepSpec`, the parsers of the ``--grid`` / ``--set`` / ``--seeds`` options,
and the loading of sweep files and named sweeps into a spec (:func:`resolve_spec`).

A sweep can be written as YAML; the files shipped in ``teamnav/experiments/sweeps/`` are
*named sweeps* (``demo-robots.yaml`` is ``demo-robots``), one per paper experiment::

    name: demo-robots                 # the sweep's name in the results table (default: file stem)
    description: one line
    scenario: demo                    # a built-in scenario name, or a file relative to this one
    grid:                             # dotted override keys, as `teamnav run --set`
      robots.0.count: [2, 4, 8]
      radio.p_loss: [0.0, 0.2]
    seeds: 5                          # seeds 0..4, or an explicit list [3, 7, 11]
    set:                              # fixed overrides for every trial
      robots.0.params.cruise_speed_mps: 0.4
    duration_s: 30                    # optional, replaces the scenario's
    cases:                            # optional: named bundles of overrides that go together
      - {case: pf, robots.0.params.navigator: potential_field, robots.0.params.state_sharing: true}
      - {case: visbug, robots.0.params.navigator: visbug21}

``cases`` is an axis of its own (slowest, before the grid): each case is a label ``case`` and
overrides applied together, for keys that a grid cannot tie (a navigator and the sharing flags
that go with it; a per-robot drift pattern). Trials are cases x grid x seeds; a trial's
``params`` carry the case label under ``case`` and its overrides.

One key, one place
------------------
Keys are compared in their canonical spelling (:func:`~teamnav.experiments.spec.canonical_key`:
``robots.00.count`` and `` robots.0.count`` are ``robots.0.count``) and stored that way. A trial
applies ``set``, then its case, then the grid axes in order, so a key given in two places
would run the later value while the earlier one still labelled the trial. That is refused,
naming both spellings: two spellings of one key in one layer, a key in two layers, and a key
that replaces what another one set (``robots.0`` and ``robots.0.count``). One exception,
said in the file: ``cases_replace_set: [KEY, ...]`` lists ``set`` keys that a case may
replace (``set`` then gives the value of the cases that do not)::

    set: {robots.0.params: {cruise_speed_mps: 0.4}}
    cases_replace_set: [robots.0.params]
    cases:
      - {case: slow}
      - {case: fast, robots.0.params: {cruise_speed_mps: 0.8}}

Grid values that run the same scenario (``2`` and ``2.0``) and cases with the same overrides
run once, under the first, with a :class:`SweepWarning` (:func:`~teamnav.experiments.sweep_trials.expand`).
"""

from __future__ import annotations

import difflib
import json
import os
from importlib import resources
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

__all__ = [
    "MAX_TRIALS_PER_SWEEP",
    "SWEEP_DIR",
    "SweepError",
    "SweepSpec",
    "SweepWarning",
    "describe_sweep",
    "load_sweep",
    "parse_grid",
    "parse_seeds",
    "parse_set",
    "resolve_spec",
    "sweep_names",
]

#: Folder of the core's named sweeps (each paper's are in its own package folder).
SWEEP_DIR: Path = Path(str(resources.files("teamnav.experiments"))) / "sweeps"

#: Most trials a sweep may have (cases x grid combinations x seeds), 10^5; also the most seeds
#: one ``seeds`` / ``--seeds`` may name. Counted from the lengths before anything is made, so
#: a grid of 10^6 combinations or a seed range up to 10^11 is refused at once (one message)
#: instead of hanging in expansion or dying of MemoryError. A bigger study is several sweeps
#: (into one store if you like: each keeps its own name).
MAX_TRIALS_PER_SWEEP: int = 100_000

#: Override keys that a grid or ``set`` may not use, and what to use instead.
_RESERVED_KEYS = {"seed": "use seeds (a count N for seeds 0..N-1, or a list)"}

_NAME_CHARS = "A-Za-z0-9_.-"


class SweepWarning(UserWarning):
    """A sweep runs, but not quite as written: two grid values or two cases run the same
    scenario, so the later one is left out. ``teamnav sweep`` prints it as ``warning: ...``."""


class SweepError(ValueError):
    """A sweep description, grid, seed list or option is invalid.

    The message is one paragraph that names the parameter, what was expected and the value
    received; the CLI prints it and exits with status 2.
    """


# ---------------------------------------------------------------------------- the description
class SweepSpec(BaseModel):
    """What to sweep: a scenario, a grid of overrides, seeds, fixed overrides.

    Attributes
    ----------
    scenario : str
        A built-in scenario name (``"demo"``) or a scenario YAML file.
    grid : dict of str to list
        Dotted override key (``robots.0.count``, same syntax as ``--set``) to the values to try,
        in order. Every value list is non-empty; a value that runs the same scenario as an
        earlier one (``2`` after ``2``, ``2.0`` after ``2``) runs once, with a warning. Default:
        no grid (one combination).
    seeds : int or list of int
        ``N`` runs seeds ``0..N-1``; a list runs exactly those seeds. Default 1 (seed 0).
    set : dict of str to value
        Fixed overrides applied to every trial (before the grid's).
    duration_s : float, optional
        Simulated time [s] of every trial, replacing the scenario's. > 0.
    name : str, optional
        The sweep's name in the results table; default: the sweep file's stem or the scenario.
    description : str
        One line for humans.
    cases : list of dict
        Named bundles of overrides (``{"case": label, key: value, ...}``), an axis before
        the grid; labels are distinct and a case may not use a grid key. Default: none.
    cases_replace_set : list of str
        Keys of ``set`` that a case may replace (see "One key, one place" in the module
        docstring); without it a case setting a ``set`` key is refused. Default: none.

    Every key of ``grid``, ``set``, ``cases`` and ``cases_replace_set`` is stored in its
    canonical spelling (:func:`~teamnav.experiments.spec.canonical_key`).
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    scenario: str = Field(min_length=1)
    grid: dict[str, list[Any]] = Field(default_factory=dict)
    seeds: int | list[int] = 1
    set: dict[str, Any] = Field(default_factory=dict)
    duration_s: float | None = Field(None, gt=0.0, le=1e7, allow_inf_nan=False)
    name: str | None = Field(None, min_length=1, max_length=100, pattern=rf"^[{_NAME_CHARS}]+$")
    description: str = ""
    cases: list[dict[str, Any]] = Field(default_factory=list)
    cases_replace_set: list[str] = Field(default_factory=list)

    @model_validator(mode="before")
    @classmethod
    def _one_spelling_one_place(cls, data: Any) -> Any:
        return _canonical_layers(data) if isinstance(data, Mapping) else data

    @field_validator("cases")
    @classmethod
    def _check_cases(cls, cases: list[dict[str, Any]]) -> list[dict[str, Any]]:
        labels: set[str] = set()
        for k, case in enumerate(cases):
            label = case.get("case")
            if not isinstance(label, str) or not label:
                raise ValueError(f"cases[{k}]: expected a non-empty string label under 'case', received {label!r}")
            if label in labels:
                raise ValueError(f"cases[{k}]: expected distinct labels, received {label!r} twice")
            labels.add(label)
            keys = [key for key in case if key != "case"]
            if not keys:
                raise ValueError(f"cases[{k}] ({label!r}): expected at least one override besides 'case'")
            for key in keys:
                _check_key(key, f"cases[{k}]")
        return cases

    @field_validator("grid")
    @classmethod
    def _check_grid(cls, grid: dict[str, list[Any]]) -> dict[str, list[Any]]:
        for key, values in grid.items():
            _check_key(key, "grid")
            if not values:
                raise ValueError(f"grid {key}: expected a non-empty list of values, received []")
        return grid

    @field_validator("set")
    @classmethod
    def _check_set(cls, fixed: dict[str, Any]) -> dict[str, Any]:
        for key in fixed:
            _check_key(key, "set")
        return fixed

    @field_validator("seeds")
    @classmethod
    def _check_seeds(cls, seeds: int | list[int]) -> int | list[int]:
        if isinstance(seeds, bool):
            raise ValueError(f"seeds: expected a count >= 1 or a list of seeds, received {seeds!r}")
        if isinstance(seeds, int):
            if not 1 <= seeds <= MAX_TRIALS_PER_SWEEP:
                raise ValueError(f"seeds: expected a count in [1, {MAX_TRIALS_PER_SWEEP}] (MAX_TRIALS_PER_SWEEP) or a list "
                                 f"of seeds, received {seeds}")
            return seeds
        if not seeds:
            raise ValueError("seeds: expected a count >= 1 or a non-empty list of seeds, received []")
        if len(seeds) > MAX_TRIALS_PER_SWEEP:
            raise ValueError(f"seeds: expected at most {MAX_TRIALS_PER_SWEEP} seeds (MAX_TRIALS_PER_SWEEP), received "
                             f"a list of {len(seeds)}")
        for s in seeds:
            if not 0 <= s <= 2**63 - 1:
                raise ValueError(f"seeds: expected every seed in [0, 2**63 - 1], received {s}")
        seen: set[int] = set()
        dup = sorted({s for s in seeds if s in seen or seen.add(s)})
        if dup:
            raise ValueError(f"seeds: expected distinct seeds, received {dup[0]} more than once")
        return seeds

    @model_validator(mode="after")
    def _duration_once(self) -> "SweepSpec":
        if self.duration_s is not None:
            where = ["grid"] * ("duration_s" in self.grid) + ["set"] * ("duration_s" in self.set)
            where += [f"case {c['case']!r}" for c in self.cases if "duration_s" in c]
            if where:
                raise ValueError(f"duration_s: expected either duration_s or the key duration_s in {where[0]}, received both")
        for key in self.cases_replace_set:
            if key not in self.set:
                raise ValueError(f"cases_replace_set: expected keys of set (that a case may replace), received {key!r}, "
                                 f"which set does not give")
        return self

    @property
    def seed_list(self) -> list[int]:
        """The seeds to run, in order."""
        return list(range(self.seeds)) if isinstance(self.seeds, int) else list(self.seeds)

    @property
    def sweep_name(self) -> str:
        """``name``, or the scenario's file stem / name when the sweep has none."""
        if self.name:
            return self.name
        return Path(self.scenario).stem if _looks_like_path(self.scenario) else self.scenario

    @property
    def n_trials(self) -> int:
        """Cases x grid combinations x seeds, counted (nothing is made)."""
        return _count_trials(len(self.cases), self.grid, self.seeds)


def _check_key(key: str, where: str) -> None:
    parts = key.split(".")
    if not key or any(not p.strip() for p in parts) or key != key.strip():
        raise ValueError(f"{where}: expected a dotted key such as robots.0.count, received {key!r}")
    if key in _RESERVED_KEYS:
        raise ValueError(f"{where}: key {key!r} cannot be swept here; {_RESERVED_KEYS[key]}")


def _canonical_layers(data: Mapping[str, Any]) -> dict[str, Any]:
    """``data`` with every key of grid, set, cases and cases_replace_set in its canonical
    spelling, refusing a key given twice (two spellings of it, or in two layers that a trial
    applies one after the other) unless ``cases_replace_set`` lets a case replace a set key.

    What is not a mapping of string keys is left as it is, for the field validators to report.
    """
    from teamnav.experiments.spec import canonical_key

    data = dict(data)
    too_many = _too_many(data)
    if too_many:
        raise ValueError(too_many)

    def one_layer(layer: Any, where: str, skip: tuple[str, ...] = ()) -> tuple[Any, dict[str, str]]:
        if not isinstance(layer, Mapping) or not all(isinstance(k, str) for k in layer):
            return layer, {}
        out: dict[str, Any] = {}
        spelt: dict[str, str] = {}
        for key, value in layer.items():
            canon = key if key in skip else canonical_key(key)
            if canon in out:
                raise ValueError(f"{where}: {_twice(spelt[canon], key, canon)}")
            out[canon], spelt[canon] = value, key
        return out, spelt

    grid, grid_spelt = one_layer(data.get("grid"), "grid")
    fixed, set_spelt = one_layer(data.get("set"), "set")
    if "grid" in data:
        data["grid"] = grid
    if "set" in data:
        data["set"] = fixed
    cases_in = data.get("cases")
    cases: list[tuple[str, Mapping[str, Any], dict[str, str]]] = []
    if isinstance(cases_in, list):
        out_cases = []
        for k, case in enumerate(cases_in):
            label = case.get("case") if isinstance(case, Mapping) else None
            where = f"cases[{k}]" + (f" ({label!r})" if isinstance(label, str) else "")
            canon, spelt = one_layer(case, where, skip=("case",))
            out_cases.append(canon)
            if isinstance(canon, Mapping):
                cases.append((where, canon, spelt))
        data["cases"] = out_cases
    replace = data.get("cases_replace_set")
    if isinstance(replace, list) and all(isinstance(k, str) for k in replace):
        replace = [canonical_key(k) for k in replace]
        data["cases_replace_set"] = replace
    replaceable = set(replace) if isinstance(replace, list) else set()

    # what one trial applies, in order: set, its case, the grid axes (each grid axis: any of its values)
    def entries(layer: Any, spelt: dict[str, str], where: str, many: bool = False) -> list[tuple[str, str, list[str], list]]:
        if not isinstance(layer, Mapping):
            return []
        out = []
        for key, value in layer.items():
            if key == "case" and where.startswith("cases["):
                continue
            values = list(value) if many and isinstance(value, list) else [value]
            out.append((where, spelt.get(key, key), key.split("."), values))
        return out

    head = entries(fixed, set_spelt, "set")
    tail = entries(grid, grid_spelt, "grid", many=True)
    for case in cases or [("", {}, {})]:
        order = head + entries(case[1], case[2], case[0]) + tail
        for j, later in enumerate(order):
            for earlier in order[:j]:
                problem = _overlap(earlier, later, replaceable)
                if problem:
                    raise ValueError(problem)
    return data


def _count_trials(n_cases: int, grid: Mapping[str, Sequence[Any]], seeds: int | Sequence[int]) -> int:
    n = max(1, n_cases) * (seeds if isinstance(seeds, int) else len(seeds))
    for values in grid.values():
        n *= len(values)
    return n


def _too_many(data: Mapping[str, Any]) -> str | None:
    """Why the raw sweep ``data`` has too many trials (:data:`MAX_TRIALS_PER_SWEEP`), or None;
    what is malformed is left for the field validators."""
    grid, cases, seeds = data.get("grid", {}), data.get("cases", []), data.get("seeds", 1)
    if not (isinstance(grid, Mapping) and all(isinstance(v, (list, tuple)) for v in grid.values())
            and isinstance(cases, (list, tuple)) and (isinstance(seeds, (list, tuple)) or type(seeds) is int)):
        return None
    if type(seeds) is int and not 1 <= seeds <= MAX_TRIALS_PER_SWEEP:
        return None  # the seeds validator says why
    n = _count_trials(len(cases), grid, seeds)
    if n <= MAX_TRIALS_PER_SWEEP:
        return None
    sizes = [f"{len(cases)} cases"] * bool(cases) + [f"{len(v)} {k}" for k, v in grid.items()]
    sizes.append(f"{seeds if isinstance(seeds, int) else len(seeds)} seeds")
    return (f"expected at most {MAX_TRIALS_PER_SWEEP} trials in a sweep (MAX_TRIALS_PER_SWEEP), received "
            f"{' x '.join(sizes)} = {n} trials; use fewer values or seeds, or split the study into several sweeps")


def _twice(first: str, second: str, canon: str) -> str:
    """The message for a key given twice, in one spelling or two."""
    what = f"key {first!r} is given twice" if first == second else f"keys {first!r} and {second!r} are two spellings of {canon}"
    return f"{what}; expected each key once (a trial would run the last one's value): remove one"


def _reaches(value: Any, parts: Sequence[str]) -> bool:
    """Whether ``value`` (an override's value) holds something at the path ``parts``."""
    for p in parts:
        if isinstance(value, Mapping) and p in value:
            value = value[p]
        elif isinstance(value, list) and p.isdecimal() and int(p) < len(value):
            value = value[int(p)]
        else:
            return False
    return True


def _overlap(earlier: tuple, later: tuple, replaceable: set[str]) -> str | None:
    """Why ``later`` (applied after ``earlier`` in one trial) throws away what ``earlier`` set, or None."""
    where_a, spell_a, parts_a, values_a = earlier
    where_b, spell_b, parts_b, _ = later
    n = min(len(parts_a), len(parts_b))
    if parts_a[:n] != parts_b[:n]:
        return None
    if len(parts_a) < len(parts_b) and not any(_reaches(v, parts_b[n:]) for v in values_a):
        return None  # the later key only adds inside what the earlier one set
    if len(parts_a) < len(parts_b) and where_a == "set":
        # set: is the base every trial starts from; a later set: key, a grid axis or a case naming
        # a field inside one of its dicts refines it, and its own column stores what ran (the
        # report's paper-rules sweeps give the brain's params in set: and set or vary one of them)
        return None
    if where_a == "set" and where_b.startswith("cases[") and ".".join(parts_a) in replaceable:
        return None  # the file says that cases replace it
    canon_a, canon_b = ".".join(parts_a), ".".join(parts_b)
    if canon_a == canon_b:
        what = f"both set {canon_a}"
    elif len(parts_b) < len(parts_a):
        what = f"{canon_b} replaces all of {canon_a}"
    else:
        what = f"{canon_a} holds a value for {canon_b}"
    layer_a, layer_b = (w.split(" ")[0].split("[")[0] for w in (where_a, where_b))
    if layer_a == "set" and layer_b == "cases":
        fix = (f"list {canon_a} under cases_replace_set: in the sweep file to let the cases' values win, "
               f"or remove it from set or from the case")
    elif layer_b == "grid" and layer_a != "grid":
        fix = f"remove it from {layer_a} (the grid gives it in every trial) or from the grid"
    else:
        fix = "remove one of them"
    once = "once" if layer_a == layer_b else f"in only one of {' and '.join(sorted((layer_a, layer_b), key=lambda x: x != 'grid'))}"
    if layer_b == "grid" and layer_a != "grid":
        head = f"{where_a}: key {spell_a!r} is also a grid key ({spell_b!r}; {what})"
    else:
        head = f"{where_b}: key {spell_b!r} overrides {where_a} key {spell_a!r} ({what})"
    return f"{head}, so a trial would silently drop what {where_a} gives; expected each key {once}: {fix}"


def _looks_like_path(s: str) -> bool:
    return s.lower().endswith((".yaml", ".yml")) or "/" in s or os.sep in s


def _canonical(value: Any) -> str:
    """Canonical JSON text (sorted keys, no spaces) used for hashing and comparing values.

    Trial ids and config hashes are hashes of this text (:mod:`teamnav.experiments.sweep_trials`);
    changing it changes every id, and stored results are found by id.
    """
    return json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=True, default=str)


def _spec_error(exc: ValidationError, where: str) -> SweepError:
    lines = []
    for err in exc.errors(include_url=False):
        loc = ".".join(str(p) for p in err.get("loc", ()) if not str(p).startswith(("int", "list[")))
        msg = str(err.get("msg", "invalid value"))
        msg = msg.removeprefix("Value error, ")
        if err.get("type") == "extra_forbidden":
            close = difflib.get_close_matches(str(loc), SweepSpec.model_fields, n=1)
            msg = "unknown key" + (f"; did you mean {close[0]!r}?" if close else "") + f" (known: {', '.join(SweepSpec.model_fields)})"
            lines.append(f"{loc}: {msg}")
            continue
        msg = msg.replace("Input should be", "expected")
        if msg.split(":", 1)[0].strip() in SweepSpec.model_fields or msg.startswith("grid "):
            text = msg  # the validator named the field itself
        else:
            text = f"{loc}: {msg}" if loc else msg
        if "input" in err and not isinstance(err["input"], (dict, list)) and "received" not in text:
            text += f" (received {err['input']!r})"
        if text not in lines:
            lines.append(text)
    if len(lines) == 1:
        return SweepError(f"sweep {where}: {lines[0]}")
    return SweepError(f"sweep {where} has {len(lines)} problems:\n" + "\n".join(f"  {line}" for line in lines))


def _validate_spec(data: Mapping[str, Any], where: str) -> SweepSpec:
    try:
        return SweepSpec.model_validate(dict(data))
    except ValidationError as exc:
        raise _spec_error(exc, where) from None


# ---------------------------------------------------------------------------- parsing options
def _read_value(text: str, what: str, key: str, shown: str | None = None) -> Any:
    from teamnav.experiments.spec import read_yaml

    try:
        return read_yaml(text)
    except yaml.YAMLError as exc:
        first = str(exc).splitlines()[0]
        shown = text if shown is None else shown
        raise SweepError(f"{what} {key}: expected YAML values, comma-separated ({first}), received {shown!r}") from None


def parse_grid(items: Sequence[str] | Mapping[str, Sequence[Any]] | None) -> dict[str, list[Any]]:
    """Parse ``--grid`` options into a grid.

    Parameters
    ----------
    items : list of str, or dict
        ``"KEY=V1,V2,..."`` strings; the values are read as a YAML flow sequence, so they are
        YAML scalars (``0.1``, ``true``, ``fast``) or quoted strings / flow lists when they
        hold commas (``'a,b'``, ``[1, 2]``). A dict is checked and returned as lists.

    Returns
    -------
    dict of str to list
        In the order given, keys in their canonical spelling
        (:func:`~teamnav.experiments.spec.canonical_key`).

    Raises
    ------
    SweepError
        An item without ``=``, an empty key or value list, an empty value, or a key given twice
        (in any two spellings: ``robots.0.count`` and ``robots.00.count`` are one key).

    Examples
    --------
    >>> parse_grid(["robots.0.count=2,4,8", "radio.mode=range,los"])
    {'robots.0.count': [2, 4, 8], 'radio.mode': ['range', 'los']}
    """
    from teamnav.experiments.spec import canonical_key

    if items is None:
        return {}
    spelt: dict[str, str] = {}

    def once(key: str, where: str) -> str:
        canon = canonical_key(key)
        if canon in spelt:
            raise SweepError(f"{where} {canon}: {_twice(spelt[canon], key, canon)}")
        spelt[canon] = key
        return canon

    if isinstance(items, Mapping):
        out: dict[str, list[Any]] = {}
        for key, values in items.items():
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                raise SweepError(f"grid {key}: expected a list of values, received {values!r}")
            out[once(str(key), "grid")] = list(values)
        return out
    if isinstance(items, str):
        items = [items]
    grid: dict[str, list[Any]] = {}
    for item in items:
        if not isinstance(item, str) or "=" not in item:
            raise SweepError(f"--grid: expected KEY=V1,V2,... (e.g. robots.0.count=2,4,8), received {item!r}")
        key, _, text = item.partition("=")
        key = key.strip()
        if not key:
            raise SweepError(f"--grid: expected a dotted key before '=', received {item!r}")
        if not text.strip():
            raise SweepError(f"--grid {key}: expected one or more comma-separated values, received {text!r}")
        values = _read_value(f"[{text}]", "--grid", key, text)
        if any(v is None for v in values) or not values:
            raise SweepError(f"--grid {key}: expected no empty values between commas, received {text!r}")
        grid[once(key, "--grid")] = values
    return grid


def parse_set(items: Sequence[str] | Mapping[str, Any] | None) -> dict[str, Any]:
    """Parse ``--set KEY=VALUE`` options (values read as YAML) into a dict of fixed overrides,
    keys in their canonical spelling; a key given twice (in any two spellings) is refused."""
    from teamnav.experiments.spec import canonical_key

    if items is None:
        return {}
    if isinstance(items, Mapping):
        pairs = [(str(k), v) for k, v in items.items()]
    else:
        if isinstance(items, str):
            items = [items]
        pairs = []
        for item in items:
            if not isinstance(item, str) or "=" not in item:
                raise SweepError(f"--set: expected KEY=VALUE (e.g. radio.p_loss=0.1), received {item!r}")
            key, _, text = item.partition("=")
            key = key.strip()
            pairs.append((key, _read_value(text, "--set", key) if text.strip() else None))
    out: dict[str, Any] = {}
    spelt: dict[str, str] = {}
    for key, value in pairs:
        canon = canonical_key(key)
        if canon in out:
            raise SweepError(f"--set {canon}: {_twice(spelt[canon], key, canon)}")
        out[canon], spelt[canon] = value, key
    return out


def parse_seeds(value: int | str | Sequence[int] | None) -> int | list[int] | None:
    """``5`` or ``"5"`` -> 5 (seeds 0..4); ``"1,4,9"`` or ``[1, 4, 9]`` -> that list; ranges
    ``"1000-1009"`` (inclusive) and mixes ``"1,4,10-12"`` -> the list; None -> None.

    A single number is a *count* (``"1000"`` runs seeds 0..999); one seed alone is ``"1000-1000"``.

    >>> parse_seeds("3"), parse_seeds("1000-1002"), parse_seeds("1,4,10-11")
    (3, [1000, 1001, 1002], [1, 4, 10, 11])
    """
    if value is None or isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, str):
        text = value.strip()
        try:
            if "," in text or "-" in text.lstrip("-"):
                spans: list[range] = []
                for part in (t.strip() for t in text.split(",")):
                    a, sep, b = part.partition("-") if not part.startswith("-") else (part, "", "")
                    if sep:
                        lo, hi = int(a), int(b)
                        if hi < lo:
                            raise ValueError
                        spans.append(range(lo, hi + 1))
                    else:
                        spans.append(range(int(part), int(part) + 1))
                count = sum(len(r) for r in spans)  # counted before any list is made
                if count > MAX_TRIALS_PER_SWEEP:
                    raise SweepError(f"--seeds: expected at most {MAX_TRIALS_PER_SWEEP} seeds (MAX_TRIALS_PER_SWEEP), "
                                     f"received {value!r}, which names {count} seeds")
                return [s for r in spans for s in r]
            return int(text)
        except SweepError:
            raise
        except ValueError:
            raise SweepError(f"--seeds: expected a count N (seeds 0..N-1), a list such as 1,4,9 or a range such as "
                             f"1000-1009, received {value!r}") from None
    if isinstance(value, Iterable):
        out = list(value)
        if all(isinstance(s, int) and not isinstance(s, bool) for s in out):
            return out
    raise SweepError(f"seeds: expected a count N or a list of integers, received {value!r}")


# ---------------------------------------------------------------------------- named sweeps
def sweep_files() -> dict[str, Path]:
    """``{name: file}`` of the named sweeps: the core's (``teamnav/experiments/sweeps/``), then
    every installed paper's ``sweeps/`` folder (:mod:`teamnav.plugins`); a name shipped twice
    keeps the first."""
    from teamnav import plugins

    found = {p.stem: p for p in sorted(SWEEP_DIR.glob("*.yaml"))} if SWEEP_DIR.is_dir() else {}
    for paper in plugins.papers().values():
        for p in paper.files("sweeps"):
            found.setdefault(p.stem, p)
    return found


def sweep_names() -> list[str]:
    """Names of the named sweeps (:func:`sweep_files`), sorted."""
    return sorted(sweep_files())


def describe_sweep(name: str) -> str:
    """First line of the named sweep's description."""
    try:
        text = str(load_sweep(name).description)
    except SweepError:
        return "(invalid)"
    return text.strip().splitlines()[0] if text.strip() else ""


def load_sweep(name_or_path: str | os.PathLike) -> SweepSpec:
    """Read a named sweep (``"demo-robots"``) or a sweep YAML file.

    A relative ``scenario`` path in the file is taken relative to the file's folder, and
    ``name`` defaults to the file's stem.

    Raises
    ------
    SweepError
        Unknown name (with "did you mean"), unreadable file, bad YAML, or an invalid field.
    """
    text = os.fspath(name_or_path)
    if _looks_like_path(text) or Path(text).is_file():
        path = Path(text)
    else:
        files = sweep_files()
        if text not in files:
            names = sorted(files)
            close = difflib.get_close_matches(text, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise SweepError(f"sweep: unknown named sweep {text!r}{hint} (known: {', '.join(names) or 'none'})")
        path = files[text]
    data = _read_sweep_file(path)
    scenario = data.get("scenario")
    if isinstance(scenario, str) and _looks_like_path(scenario):
        p = Path(os.path.expanduser(scenario))
        data["scenario"] = str(p if p.is_absolute() else (path.resolve().parent / p))
    data.setdefault("name", path.stem)
    return _validate_spec(data, f"file {path}")


def _read_sweep_file(path: Path) -> dict[str, Any]:
    from teamnav.experiments.spec import read_yaml

    if not path.is_file():
        raise SweepError(f"sweep file {path}: expected an existing file, received a missing path")
    try:
        data = read_yaml(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise SweepError(f"sweep file {path}: expected a readable UTF-8 file ({exc})") from None
    except yaml.YAMLError as exc:
        raise SweepError(f"sweep file {path}: expected valid YAML ({str(exc).splitlines()[0]})") from None
    if not isinstance(data, dict):
        raise SweepError(f"sweep file {path}: expected a mapping of sweep fields, received {type(data).__name__}")
    return data


def _is_sweep_file(text: str) -> bool:
    path = Path(text)
    if not (path.is_file() and _looks_like_path(text)):
        return False
    try:
        data = _read_sweep_file(path)
    except SweepError:
        return False
    return "scenario" in data


def resolve_spec(
    name_or_spec: "SweepSpec | str | os.PathLike",
    *,
    grid: Sequence[str] | Mapping[str, Sequence[Any]] | None = None,
    seeds: int | str | Sequence[int] | None = None,
    set: Sequence[str] | Mapping[str, Any] | None = None,  # noqa: A002 - mirrors --set
    duration_s: float | None = None,
    name: str | None = None,
) -> SweepSpec:
    """The sweep to run: a spec, a named sweep, a sweep file or a scenario, plus options.

    ``name_or_spec`` is looked up in this order: a :class:`SweepSpec`; a named sweep; a YAML
    file with a top-level ``scenario`` key (a sweep file); otherwise a scenario name or file.
    ``grid`` entries are added to (or replace, key by key) the spec's grid, ``set`` entries
    to its fixed overrides (keys compared in their canonical spelling; a key may not be in both
    ``grid`` and ``set``); ``seeds``, ``duration_s`` and ``name`` replace the spec's.
    """
    if isinstance(name_or_spec, SweepSpec):
        base = name_or_spec
    else:
        text = os.fspath(name_or_spec)
        if not text:
            raise SweepError("sweep: expected a sweep or scenario name or file, received ''")
        if text in sweep_names() or _is_sweep_file(text):
            base = load_sweep(text)
        else:
            if _looks_like_path(text) and Path(text).exists():
                text = str(Path(text).resolve())  # workers may run elsewhere (another cwd, a Ray node)
            base = _validate_spec({"scenario": text}, f"of scenario {text!r}")
    data = base.model_dump()
    extra_grid = parse_grid(grid)
    extra_set = parse_set(set)
    both = [key for key in extra_grid if key in extra_set]
    if both:
        raise SweepError(f"--set {both[0]}: the key is also a --grid axis; expected it in only one of --grid and --set")
    if extra_grid:
        data["grid"] = {**data["grid"], **extra_grid}
        for key in extra_grid:
            data["set"].pop(key, None)
            if key in data["cases_replace_set"]:
                data["cases_replace_set"].remove(key)
    if extra_set:
        data["set"] = {**data["set"], **extra_set}
        for key in extra_set:
            data["grid"].pop(key, None)
    parsed = parse_seeds(seeds)
    if parsed is not None:
        data["seeds"] = parsed
    if duration_s is not None:
        data["duration_s"] = duration_s
    if name is not None:
        data["name"] = name
    return _validate_spec(data, repr(data.get("name") or data["scenario"]))
