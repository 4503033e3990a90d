"""The ``los-help`` section's trials that another of its sweeps already runs (cost; 14d5e61, 2026-11-27).

In full mode the section asked for 780 trials, of which 75 are the same simulation twice: the
noise figures' err_max = 0 points (Figs. 16-17, every algorithm, both columns: 60 trials) are
Tables 1-2's R1..R4 runs, and the ablation's column that matches the tables' setting of each
algorithm (potential field: ghosts + state sharing; Avoid-Past and VisBug-21: ghosts without state
sharing; 15 trials) is Table 1's R1..R4 run of the teamnav column. Two trials are the same
simulation when their resolved scenarios hash the same (``config_hash``: the scenario with every
override applied, without seed, name and description) and their seeds are equal: the engine is
deterministic (``benchmarks/los_fingerprint.py``), so they record the same numbers.

:func:`reused_rows` finds, for the trials of a sweep spec, the rows of another sweep with the same
``(config_hash, seed)``; the section then runs only the trials it does not find. It proves the
identity per trial from the hashes, so a change to one sweep's scenario that makes the two differ
makes the section run the trial again instead of reusing a row of another configuration. Quick
mode did this already for the noise figures' err_max = 0 (by construction, without the check).
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping


def trial_keys(spec: Any) -> list[tuple[str, int]]:
    """``(config_hash, seed)`` of every trial of ``spec`` (a resolved sweep spec), in its order."""
    from teamnav.experiments.sweep import expand

    return [(t.config_hash, int(t.seed)) for t in expand(spec)]


def reused_rows(spec: Any, rows: Iterable[Mapping[str, Any]], params: Mapping[str, Any]) -> list[dict] | None:
    """The rows of ``rows`` that are the trials of ``spec``, one per trial, with ``params``
    written into their ``params``; None unless every trial of ``spec`` has such a row.

    Parameters
    ----------
    spec : SweepSpec
        The trials that would run (resolved: its grid, cases and ``set`` as the section calls it).
    rows : iterable of dict
        Finished rows of another sweep (``config_hash``, ``seed`` and ``params`` as the store gives them).
    params : mapping
        What the reused rows' ``params`` must say so that the section reads them as ``spec``'s
        (e.g. the err_max of the noise figures, which the tables' rows do not carry).
    """
    by_key: dict[tuple[str, int], Mapping[str, Any]] = {}
    for r in rows:
        chash, seed = r.get("config_hash"), r.get("seed")
        if chash is None or seed is None:
            return None
        by_key.setdefault((str(chash), int(seed)), r)
    if not by_key:
        return None
    out = []
    for key in trial_keys(spec):
        r = by_key.get(key)
        if r is None:
            return None
        out.append({**r, "params": {**(r.get("params") or {}), **params}})
    return out
