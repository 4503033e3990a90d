"""A sweep's trials: :func:`expand` turns a :class:`~teamnav.experiments.sweep_spec.SweepSpec`
into :class:`Trial` objects, each with its stable ``trial_id`` and its ``config_hash``.

Trials are cases (slowest) x grid combinations x seeds (fastest); each combination is
validated before any trial runs (:mod:`teamnav.experiments.sweep` runs them).

Trial identity
--------------
``trial_id`` is the first 16 hex digits of the SHA-256 of the canonical JSON (sorted keys,
no spaces) of ``{"scenario": <scenario name>, "params": <every override of the trial, fixed
ones and grid values, plus duration_s when given>, "seed": <seed>}``. It depends only on what
the user asked for, so it is the same in every process and on every machine, and a rerun
recognises the trials it already has. Keys count in their canonical spelling
(:func:`~teamnav.experiments.spec.canonical_key`), values as written. ``config_hash`` is the
hash of the fully resolved scenario without its seed, name and description: trials that
simulate the same configuration share it, whatever the seed.

Duplicates
----------
Two combinations that resolve to the same scenario (grid values ``2`` and ``2.0``, two cases
with the same overrides) would run the same trials twice under two labels; :func:`expand`
keeps the first and leaves the later one out, with one :class:`~teamnav.experiments.sweep_spec.SweepWarning`
naming them.
"""

from __future__ import annotations

import hashlib
import itertools
import warnings
from typing import Any, Mapping, Sequence

from teamnav.experiments.sweep_spec import SweepError, SweepSpec, SweepWarning, _canonical
from teamnav.experiments.trial import Trial

__all__ = ["Trial", "config_hash", "expand", "trial_id"]


# ---------------------------------------------------------------------------- trials
def _hash(value: Any) -> str:
    return hashlib.sha256(_canonical(value).encode("utf-8")).hexdigest()[:16]


def trial_id(scenario_name: str, params: Mapping[str, Any], seed: int) -> str:
    """The stable id of a trial (see the module docstring)."""
    return _hash({"scenario": scenario_name, "params": dict(params), "seed": int(seed)})


def config_hash(scenario) -> str:
    """Hash of a resolved scenario without its seed, name and description, with every robot
    group's brain parameters as its brain resolves them (defaults included).

    A scenario usually names only the parameters it changes; the rest are the brain's defaults,
    which belong to teamnav's code. Hashing the resolved parameters means that a trial stored
    before a default changed (e.g. a trail brain's crumb radius chosen anew) is not taken for the
    same configuration: a resumed sweep refuses the folder, and no run reuses the stale row.
    """
    data = scenario.model_dump(mode="json")
    for key in ("seed", "name", "description"):
        data.pop(key, None)
    groups = data.get("robots")
    if isinstance(groups, list):
        for dumped, resolved in zip(groups, _resolved_brain_params(scenario)):
            if resolved is not None and isinstance(dumped, dict):
                dumped["params"] = resolved  # a default spelled out is the same configuration
    return _hash(data)


def _resolved_brain_params(scenario) -> list:
    """Per robot group, its controller's ``Params`` with the group's ``params`` applied
    (``model_dump``); None where the controller or its parameters cannot be resolved here
    (the group's own ``params`` are hashed then; the run reports the problem itself)."""
    from teamnav.control import registry

    out = []
    for group in getattr(scenario, "robots", ()) or ():
        try:
            model = getattr(registry.lookup(group.controller), "Params", None)
            out.append(model.model_validate(dict(group.params or {})).model_dump(mode="json")
                       if model is not None else None)
        except Exception:  # noqa: BLE001 - unknown controller or bad params: the run names the problem
            out.append(None)
    return out


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

    A combination that resolves to the same scenario as an earlier one (see "Duplicates" in
    the module docstring) is left out, with a :class:`~teamnav.experiments.sweep_spec.SweepWarning`.

    Returns
    -------
    list of Trial
        ``spec.n_trials`` trials (fewer by the duplicates) with distinct ``trial_id``.

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
    first: dict[str, str] = {}  # config hash -> the combination that has it
    repeats: list[str] = []
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
        shown = " ".join(([f"case {case['case']!r}"] if case else []) + [f"{k}={v!r}" for k, v in values.items()])
        if chash in first:
            repeats.append(f"{shown} runs the same scenario as {first[chash]}")
            continue
        first[chash] = shown
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
    if repeats:
        more = f" (and {len(repeats) - 5} more)" if len(repeats) > 5 else ""
        warnings.warn(f"sweep {spec.sweep_name!r}: {len(repeats)} combination(s) left out, each runs once under the first: "
                      + "; ".join(repeats[:5]) + more, SweepWarning, stacklevel=2)
    ids = [t.trial_id for t in trials]
    if len(set(ids)) != len(ids):  # pragma: no cover - distinct values make distinct ids
        raise SweepError(f"sweep {spec.sweep_name!r}: two trials share an id; expected distinct grid values")
    return trials
