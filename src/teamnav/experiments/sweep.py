"""Sweeps: one scenario run over a grid of parameter values x seeds, resumably.

A sweep is a scenario, a grid of ``--set``-style overrides and a number (or list) of seeds.
Its trials are the Cartesian product of the grid's values times the seeds; each trial is one
run of the scenario with those overrides and that seed. Trials run in worker processes (or on
a Ray cluster, :mod:`teamnav.experiments.executors`); the parent process writes one row per
finished trial into ``OUT/results.sqlite`` (:mod:`teamnav.experiments.store`), committed
before the next trial starts in that worker slot. Running the same sweep into the same folder
again skips the trials already done, so a sweep killed at any moment (SIGKILL included) resumes
and loses only the trials that were running (DESIGN "Determinism and data").

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

Trial identity
--------------
``trial_id`` is the first 16 hex digits of the SHA-256 of the canonical JSON (sorted keys,
no spaces) of ``{"scenario": <scenario name>, "params": <every override of the trial, fixed
ones and grid values, plus duration_s when given>, "seed": <seed>}``. It depends only on what
the user asked for, so it is the same in every process and on every machine, and a rerun
recognises the trials it already has. Values count as written: ``2`` and ``2.0`` are different
trials. ``config_hash`` is the hash of the fully resolved scenario without its seed, name and
description: trials that simulate the same configuration share it, whatever the seed.

Examples
--------
>>> from teamnav.experiments.sweep import SweepSpec, expand
>>> spec = SweepSpec(scenario="demo", grid={"robots.0.count": [2, 4]}, seeds=3, duration_s=2)
>>> trials = expand(spec)
>>> len(trials), trials[0].params, trials[0].seed
(6, {'robots.0.count': 2, 'duration_s': 2.0}, 0)
"""

from __future__ import annotations

import difflib
import hashlib
import itertools
import json
import math
import os
import pickle
import time
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

__all__ = [
    "SWEEP_DIR",
    "SweepError",
    "SweepResult",
    "SweepSpec",
    "Trial",
    "describe_sweep",
    "expand",
    "load_sweep",
    "parse_grid",
    "parse_seeds",
    "parse_set",
    "resolve_spec",
    "sweep",
    "sweep_names",
]

#: Folder of the named sweeps shipped with the package.
SWEEP_DIR: Path = Path(str(resources.files("teamnav.experiments"))) / "sweeps"

#: Override keys that a grid or ``set`` may not use, and what to use instead.
_RESERVED_KEYS = {"seed": "use seeds (a count N for seeds 0..N-1, or a list)"}

_NAME_CHARS = "A-Za-z0-9_.-"


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
        in order. Every value list is non-empty and has no repeated value. Default: no grid
        (one combination).
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

    @field_validator("cases")
    @classmethod
    def _check_cases(cls, cases: list[dict[str, Any]]) -> list[dict[str, Any]]:
        labels: list[str] = []
        for k, case in enumerate(cases):
            label = case.get("case")
            if not isinstance(label, str) or not label:
                raise ValueError(f"cases[{k}]: expected a non-empty string label under 'case', received {label!r}")
            if label in labels:
                raise ValueError(f"cases[{k}]: expected distinct labels, received {label!r} twice")
            labels.append(label)
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
            seen: list[str] = []
            for v in values:
                text = _canonical(v)
                if text in seen:
                    raise ValueError(f"grid {key}: expected distinct values, received {v!r} twice")
                seen.append(text)
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
            if not 1 <= seeds <= 1_000_000:
                raise ValueError(f"seeds: expected a count in [1, 1000000] or a list of seeds, received {seeds}")
            return seeds
        if not seeds:
            raise ValueError("seeds: expected a count >= 1 or a non-empty list of seeds, received []")
        for s in seeds:
            if not 0 <= s <= 2**63 - 1:
                raise ValueError(f"seeds: expected every seed in [0, 2**63 - 1], received {s}")
        dup = sorted({s for s in seeds if seeds.count(s) > 1})
        if dup:
            raise ValueError(f"seeds: expected distinct seeds, received {dup[0]} more than once")
        return seeds

    @model_validator(mode="after")
    def _grid_and_set_apart(self) -> "SweepSpec":
        both = sorted(set(self.grid) & set(self.set))
        if both:
            raise ValueError(f"set: key {both[0]!r} is also a grid key; expected each key in only one of grid and set")
        in_cases = sorted({key for case in self.cases for key in case} & set(self.grid))
        if in_cases:
            raise ValueError(f"cases: key {in_cases[0]!r} is also a grid key; expected each key in only one of cases and grid")
        if "duration_s" in self.grid and self.duration_s is not None:
            raise ValueError("duration_s: expected either duration_s or a grid over duration_s, received both")
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
        n = len(self.seed_list) * max(1, len(self.cases))
        for values in self.grid.values():
            n *= len(values)
        return n


def _check_key(key: str, where: str) -> None:
    parts = key.split(".")
    if not key or any(not p.strip() for p in parts) or key != key.strip():
        raise ValueError(f"{where}: expected a dotted key such as robots.0.count, received {key!r}")
    if key in _RESERVED_KEYS:
        raise ValueError(f"{where}: key {key!r} cannot be swept here; {_RESERVED_KEYS[key]}")


def _looks_like_path(s: str) -> bool:
    return s.lower().endswith((".yaml", ".yml")) or "/" in s or os.sep in s


def _canonical(value: Any) -> str:
    """Canonical JSON text (sorted keys, no spaces) used for hashing and comparing values."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True, allow_nan=True, default=str)


def _hash(value: Any) -> str:
    return hashlib.sha256(_canonical(value).encode("utf-8")).hexdigest()[:16]


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
        In the order given.

    Raises
    ------
    SweepError
        An item without ``=``, an empty key or value list, an empty value, or a key given twice.

    Examples
    --------
    >>> parse_grid(["robots.0.count=2,4,8", "radio.mode=range,los"])
    {'robots.0.count': [2, 4, 8], 'radio.mode': ['range', 'los']}
    """
    if items is None:
        return {}
    if isinstance(items, Mapping):
        out: dict[str, list[Any]] = {}
        for key, values in items.items():
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                raise SweepError(f"grid {key}: expected a list of values, received {values!r}")
            out[str(key)] = list(values)
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
        if key in grid:
            raise SweepError(f"--grid {key}: expected each key once, received it twice")
        grid[key] = values
    return grid


def parse_set(items: Sequence[str] | Mapping[str, Any] | None) -> dict[str, Any]:
    """Parse ``--set KEY=VALUE`` options (values read as YAML) into a dict of fixed overrides."""
    if items is None:
        return {}
    if isinstance(items, Mapping):
        return {str(k): v for k, v in items.items()}
    if isinstance(items, str):
        items = [items]
    out: dict[str, Any] = {}
    for item in items:
        if not isinstance(item, str) or "=" not in item:
            raise SweepError(f"--set: expected KEY=VALUE (e.g. radio.p_loss=0.1), received {item!r}")
        key, _, text = item.partition("=")
        key = key.strip()
        out[key] = _read_value(text, "--set", key) if text.strip() else None
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
                out: list[int] = []
                for part in (t.strip() for t in text.split(",")):
                    a, sep, b = part.partition("-") if not part.startswith("-") else (part, "", "")
                    if sep:
                        lo, hi = int(a), int(b)
                        if hi < lo:
                            raise ValueError
                        out.extend(range(lo, hi + 1))
                    else:
                        out.append(int(part))
                return out
            return int(text)
        except ValueError:
            raise SweepError(f"--seeds: expected a count N (seeds 0..N-1), a list such as 1,4,9 or a range such as "
                             f"1000-1009, received {value!r}") from None
    if isinstance(value, Iterable):
        out = list(value)
        if all(isinstance(s, int) and not isinstance(s, bool) for s in out):
            return out
    raise SweepError(f"seeds: expected a count N or a list of integers, received {value!r}")


# ---------------------------------------------------------------------------- named sweeps
def sweep_names() -> list[str]:
    """Names of the sweeps shipped in ``teamnav/experiments/sweeps/``, sorted."""
    return sorted(p.stem for p in SWEEP_DIR.glob("*.yaml")) if SWEEP_DIR.is_dir() else []


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
        names = sweep_names()
        if text not in names:
            close = difflib.get_close_matches(text, names, n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise SweepError(f"sweep: unknown named sweep {text!r}{hint} (known: {', '.join(names) or 'none'})")
        path = SWEEP_DIR / f"{text}.yaml"
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
    to its fixed overrides; ``seeds``, ``duration_s`` and ``name`` replace the spec's.
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
    if extra_grid:
        data["grid"] = {**data["grid"], **extra_grid}
        for key in extra_grid:
            data["set"].pop(key, None)
    extra_set = parse_set(set)
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


# ---------------------------------------------------------------------------- trials
@dataclass(frozen=True)
class Trial:
    """One run of a sweep.

    Attributes
    ----------
    trial_id : str
        16 hex digits, stable (see the module docstring).
    sweep : str
        The sweep's name.
    scenario : str
        The scenario as the sweep names it (built-in name or absolute file path).
    scenario_name : str
        The resolved scenario's ``name``.
    params : dict of str to value
        Every override of this trial: the fixed ``set``, this combination of grid values,
        and ``duration_s`` when the sweep sets it.
    seed : int
    config_hash : str
        16 hex digits: hash of the resolved scenario without seed, name and description.
    grid_keys : tuple of str
        Which keys of ``params`` vary across the sweep.
    """

    trial_id: str
    sweep: str
    scenario: str
    scenario_name: str
    params: dict[str, Any]
    seed: int
    config_hash: str
    grid_keys: tuple[str, ...] = ()
    #: robot-steps of the resolved scenario (robots x steps): the schedule's size estimate
    work: float = 0.0

    @property
    def overrides(self) -> dict[str, Any]:
        """``params`` without ``duration_s`` and the ``case`` label (what ``load_scenario(overrides=...)`` gets)."""
        return {k: v for k, v in self.params.items() if k not in ("duration_s", "case")}

    @property
    def duration_s(self) -> float | None:
        return self.params.get("duration_s")

    def load(self):
        """The trial's validated :class:`~teamnav.experiments.spec.Scenario`."""
        from teamnav.experiments.spec import load_scenario

        return load_scenario(self.scenario, overrides=self.overrides or None, seed=self.seed, duration_s=self.duration_s)

    def label(self) -> str:
        """``robots.0.count=4 seed=2`` (grid values and seed)."""
        shown = " ".join(f"{k}={self.params[k]!r}" for k in self.grid_keys)
        if "case" in self.params:
            shown = f"case={self.params['case']} {shown}"
        return f"{shown} seed={self.seed}".strip()


def trial_id(scenario_name: str, params: Mapping[str, Any], seed: int) -> str:
    """The stable id of a trial (see the module docstring)."""
    return _hash({"scenario": scenario_name, "params": dict(params), "seed": int(seed)})


def config_hash(scenario) -> str:
    """Hash of a resolved scenario without its seed, name and description."""
    data = scenario.model_dump(mode="json")
    for key in ("seed", "name", "description"):
        data.pop(key, None)
    return _hash(data)


def _blame(exc, grid_keys: Sequence[str]) -> str | None:
    """Which grid key a ScenarioError is about (from its field path or its --set note)."""
    from teamnav.experiments.spec import _pretty

    for problem in getattr(exc, "problems", ()):
        for key in grid_keys:
            pretty = _pretty(key.split("."))
            if problem.field in (f"--set {key}", pretty) or problem.field.startswith((pretty + ".", pretty + "[")):
                return key
            if problem.note and problem.note.startswith(f"from --set {key}="):
                return key
    return None


def _problem_text(exc) -> str:
    problems = getattr(exc, "problems", None)
    if not problems:
        return str(exc)
    return "; ".join(f"{p.field}: {p.message}" + (f" (received {p.received})" if p.received is not None else "") for p in problems)


def expand(spec: SweepSpec) -> list[Trial]:
    """Every trial of ``spec``: cases (slowest) x grid combinations (first key slowest) x seeds (fastest).

    Each combination is loaded and validated with :func:`~teamnav.experiments.spec.load_scenario`
    first, so a bad value fails here, before any trial runs.

    Returns
    -------
    list of Trial
        ``spec.n_trials`` trials with distinct ``trial_id``.

    Raises
    ------
    SweepError
        One message listing every grid value that makes the scenario invalid (key, what was
        expected, value), or the scenario's own error when it is invalid whatever the grid.
    """
    from teamnav.experiments.errors import ScenarioError
    from teamnav.experiments.spec import load_scenario

    keys = list(spec.grid)
    seeds = spec.seed_list
    fixed = dict(spec.set)
    trials: list[Trial] = []
    bad: dict[tuple[str, str], str] = {}
    cases = spec.cases or [{}]
    for case, combo in itertools.product(cases, itertools.product(*(spec.grid[k] for k in keys))):
        values = dict(zip(keys, combo))
        bundle = {k: v for k, v in case.items() if k != "case"}
        params = {**fixed, **bundle, **values}
        duration = spec.duration_s
        if "duration_s" in params:
            duration = params.pop("duration_s")
        try:
            scn = load_scenario(spec.scenario, overrides=params or None, seed=seeds[0], duration_s=duration)
        except ScenarioError as exc:
            culprit = _blame(exc, keys) if keys else None
            if culprit is None:
                where = f" with set {fixed}" if fixed else ""
                where += f" in case {case['case']!r}" if case else ""
                raise SweepError(f"sweep {spec.sweep_name!r}: the scenario is invalid{where}: {exc}") from None
            bad.setdefault((culprit, _canonical(values[culprit])), f"grid {culprit}={values[culprit]!r}: {_problem_text(exc)}")
            continue
        if duration is not None:
            params["duration_s"] = float(duration)
        if case:
            params["case"] = case["case"]
        chash = config_hash(scn)
        for seed in seeds:
            trials.append(
                Trial(
                    trial_id=trial_id(scn.name, params, seed),
                    sweep=spec.sweep_name,
                    scenario=spec.scenario,
                    scenario_name=scn.name,
                    params=dict(params),
                    seed=seed,
                    config_hash=chash,
                    grid_keys=tuple(keys),
                    work=float(scn.n_robots * scn.n_steps),
                )
            )
    if bad:
        lines = list(bad.values())
        if len(lines) == 1:
            raise SweepError(f"sweep {spec.sweep_name!r}: {lines[0]}")
        raise SweepError(f"sweep {spec.sweep_name!r} has {len(lines)} invalid grid values:\n" + "\n".join(f"  {x}" for x in lines))
    ids = [t.trial_id for t in trials]
    if len(set(ids)) != len(ids):  # pragma: no cover - distinct values make distinct ids
        raise SweepError(f"sweep {spec.sweep_name!r}: two trials share an id; expected distinct grid values")
    return trials


# ---------------------------------------------------------------------------- running
@dataclass
class SweepResult:
    """What :func:`sweep` returns.

    Attributes
    ----------
    name : str
        The sweep's name.
    store_path : Path
        ``OUT/results.sqlite``.
    total : int
        Trials in the sweep.
    done : int
        Trials that ran and succeeded in this call.
    failed : int
        Trials that ran and failed in this call.
    skipped : int
        Trials not run because the store already had them (``'ok'``, or ``'failed'`` with
        ``retry_failed=False``).
    elapsed_s : float
        Wall time of this call [s].
    failures : list of dict
        ``{"trial_id", "label", "error"}`` for each trial that failed in this call.
    """

    name: str
    store_path: Path
    total: int
    done: int = 0
    failed: int = 0
    skipped: int = 0
    elapsed_s: float = 0.0
    failures: list[dict[str, str]] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no trial failed in this call."""
        return self.failed == 0

    def summary(self) -> str:
        """One line: counts, time and the store."""
        return (
            f"sweep {self.name}: {self.done} ok, {self.failed} failed, {self.skipped} skipped (already in the store) "
            f"of {self.total} trials in {self.elapsed_s:.1f} s -> {self.store_path}"
        )

    def rows(self, *, all_sweeps: bool = False) -> list[dict[str, Any]]:
        """The store's rows for this sweep (every sweep in the store with ``all_sweeps``)."""
        from teamnav.experiments.store import load_rows

        return load_rows(self.store_path, sweep=None if all_sweeps else self.name)

    def dataframe(self, *, all_sweeps: bool = False):
        """The rows as a pandas DataFrame (needs pandas)."""
        from teamnav.experiments.store import load_dataframe

        return load_dataframe(self.store_path, sweep=None if all_sweeps else self.name)


def sweep(
    name_or_spec: "SweepSpec | str | os.PathLike",
    *,
    out_dir: str | os.PathLike,
    grid: Sequence[str] | Mapping[str, Sequence[Any]] | None = None,
    seeds: int | str | Sequence[int] | None = None,
    set: Sequence[str] | Mapping[str, Any] | None = None,  # noqa: A002 - mirrors --set
    duration_s: float | None = None,
    name: str | None = None,
    executor: str = "local",
    workers: int | None = None,
    address: str | None = None,
    progress: bool = True,
    retry_failed: bool = True,
    artifacts: bool = False,
    trial_fn: Callable[..., Mapping[str, Any]] | None = None,
) -> SweepResult:
    """Run a sweep into ``out_dir``, resuming what an earlier call left.

    Parameters
    ----------
    name_or_spec : SweepSpec, str or Path
        A spec, a named sweep (:func:`sweep_names`), a sweep YAML file, or a scenario name or
        file (then ``grid`` and ``seeds`` say what to sweep).
    out_dir : str or Path
        Folder of the results store ``results.sqlite`` (created if missing).
    grid : list of "KEY=V1,V2" or dict of key to list, optional
        Grid axes, added to the spec's.
    seeds : int, "1,4,9" or list of int, optional
        Replaces the spec's seeds.
    set : list of "KEY=VALUE" or dict, optional
        Fixed overrides, added to the spec's.
    duration_s : float, optional
        Simulated time of every trial [s].
    name : str, optional
        Replaces the sweep's name.
    executor : {"local", "ray"}
        ``"local"``: worker processes on this machine (default); ``"ray"``: Ray tasks on the
        cluster at ``address``, or on a local Ray started for this sweep.
    workers : int, optional
        Trials running at once; default ``os.cpu_count()`` (local) or the cluster's CPUs (Ray).
    address : str, optional
        Ray cluster address (``"auto"``, ``"ray://host:10001"``); only with ``executor="ray"``.
    progress : bool
        Show a progress bar on stderr (done / failed / remaining, ETA).
    retry_failed : bool
        Run again the trials stored as ``'failed'`` (default); False skips them too.
    artifacts : bool
        Also write each trial's run folder to ``out_dir/trials/<trial_id>/``.
    trial_fn : callable, optional
        ``trial_fn(scenario, out_dir) -> {metric: number}`` replaces the default (a full
        :func:`~teamnav.experiments.runner.run`); it must be picklable (a module-level
        function) and runs in the workers.

    Returns
    -------
    SweepResult

    Raises
    ------
    SweepError
        Bad sweep, grid, seeds, option, or a store holding other results under the same ids;
        raised before any trial runs.
    """
    from teamnav.experiments.executors import TrialTask, make_executor
    from teamnav.experiments.store import STORE_NAME, ResultsStore, check_store

    t0 = time.perf_counter()
    if out_dir is None or not os.fspath(out_dir):
        raise SweepError("out_dir: expected a folder for results.sqlite, received None")
    spec = resolve_spec(name_or_spec, grid=grid, seeds=seeds, set=set, duration_s=duration_s, name=name)
    runner = make_executor(executor, workers=workers, address=address)  # checks options, starts nothing
    if trial_fn is not None and not callable(trial_fn):
        raise SweepError(f"trial_fn: expected a callable or None, received {trial_fn!r}")
    if trial_fn is not None and executor == "local":
        try:
            pickle.dumps(trial_fn)
        except Exception:  # noqa: BLE001 - any pickling failure means the workers cannot get it
            raise SweepError(
                f"trial_fn: expected a module-level function (spawned worker processes import it by name), "
                f"received {trial_fn!r}, which cannot be pickled"
            ) from None
    trials = expand(spec)
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise SweepError(f"out_dir: expected a folder, received the file {out}")
    check_store(out / STORE_NAME)  # a results.sqlite that is not a teamnav store: refused before any trial
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepError(f"out_dir: cannot create or write the folder {out} ({exc.strerror or exc}); "
                         "use --out with another folder") from None
    result = SweepResult(spec.sweep_name, out / STORE_NAME, len(trials))
    from teamnav.experiments.signals import sigterm_raises

    # SIGTERM as Ctrl-C: the workers are stopped and the store closed before the process ends
    with sigterm_raises(), ResultsStore(out / STORE_NAME) as store:
        previous = store.existing()
        clash = [t for t in trials if t.trial_id in previous and previous[t.trial_id][1] != t.config_hash]
        if clash:
            t = clash[0]
            raise SweepError(
                f"out_dir {out}: trial {t.trial_id} ({t.label()}) is stored with config hash "
                f"{previous[t.trial_id][1]} but the scenario now resolves to {t.config_hash} (the scenario file or "
                f"teamnav changed); expected the same configuration, so write this sweep to a new folder"
            )
        skip_status = {"ok"} if retry_failed else {"ok", "failed"}
        todo = [t for t in trials if previous.get(t.trial_id, ("",))[0] not in skip_status]
        result.skipped = len(trials) - len(todo)
        store.register_sweep(spec.sweep_name, spec.model_dump(mode="json"))
        art = out / "trials" if artifacts else None
        todo = longest_first(todo, trials, store.rows())  # both cores busy to the end (issue 27 §2)
        tasks = [TrialTask(t, trial_fn, str(art / t.trial_id) if art is not None else None) for t in todo]
        by_id = {t.trial_id: t for t in todo}
        bar = _Bar(spec.sweep_name, len(todo), result.skipped, show=progress and bool(todo))

        def on_result(res) -> None:
            trial = by_id[res.trial_id]
            store.record(trial, res)
            if res.status == "ok":
                result.done += 1
            else:
                result.failed += 1
                result.failures.append({"trial_id": trial.trial_id, "label": trial.label(), "error": res.error or ""})
            bar.advance(res.status == "ok")

        try:
            if tasks:
                runner.run(tasks, on_result)
        finally:
            bar.close()
            result.elapsed_s = time.perf_counter() - t0
    return result


def longest_first(todo: list[Trial], trials: list[Trial], rows: list[dict[str, Any]]) -> list[Trial]:
    """``todo`` ordered by expected wall time, longest first, so that the last trials to start
    are short ones and no worker idles while one long trial finishes.

    The expected time of a trial is the mean ``wall_time_s`` the store holds for its
    configuration (same ``config_hash``: the same scenario, another seed or an earlier try);
    a configuration never run yet is estimated from its robot-steps (``Trial.work``) at the
    median seconds per robot-step of the measured ones, or ranked by robot-steps alone when
    nothing is measured. Ties keep the sweep's own order.
    """
    measured: dict[str, list[float]] = {}
    for r in rows:
        w = r.get("wall_time_s")
        if isinstance(w, (int, float)) and math.isfinite(w) and w > 0:
            measured.setdefault(r.get("config_hash"), []).append(float(w))
    work = {t.config_hash: t.work for t in trials}
    rates = sorted(sum(v) / len(v) / work[h] for h, v in measured.items() if work.get(h, 0) > 0)
    rate = rates[len(rates) // 2] if rates else 1.0

    def expected(t: Trial) -> float:
        times = measured.get(t.config_hash)
        return sum(times) / len(times) if times else t.work * rate

    order = sorted(range(len(todo)), key=lambda i: (-expected(todo[i]), i))
    return [todo[i] for i in order]


class _Bar:
    """Sweep progress on stderr: a rich bar (done / total, ok and failed counts, elapsed and
    ETA) on a terminal; elsewhere (CI, nohup, a pipe) a plain line every
    :func:`~teamnav.experiments.progress.period_s` seconds and one at the end."""

    def __init__(self, name: str, total: int, skipped: int, show: bool) -> None:
        self._progress = None
        self._plain = None
        self._total, self._ok, self._failed = total, 0, 0
        if not show:
            return
        from teamnav.experiments.progress import PlainProgress, stderr_is_terminal

        note = f" ({skipped} already done)" if skipped else ""
        if not stderr_is_terminal():
            self._plain = PlainProgress(f"teamnav sweep {name}{note}", total, "trials", details=self._counts).start()
            return
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TextColumn("[green]{task.fields[ok]} ok[/] [red]{task.fields[failed]} failed[/] {task.fields[left]} left"),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=False,
        )
        from rich.markup import escape

        self._task = self._progress.add_task(escape(f"sweep {name}{note}"), total=total, ok=0, failed=0, left=total)
        self._progress.start()

    def _counts(self) -> str:
        left = self._total - self._ok - self._failed
        return f"{self._ok} ok, {self._failed} failed, {left} left"

    def advance(self, ok: bool) -> None:
        self._ok += ok
        self._failed += not ok
        if self._plain is not None:
            self._plain.update(self._ok + self._failed)
        if self._progress is None:
            return
        left = self._total - self._ok - self._failed
        self._progress.update(self._task, advance=1, ok=self._ok, failed=self._failed, left=left)

    def close(self) -> None:
        if self._plain is not None:
            self._plain.close(final="{line}")
            self._plain = None
        if self._progress is not None:
            self._progress.stop()
            self._progress = None
