"""What the environments refuse, each with one error that says what to change.

- :func:`batch_memory_problem`: a :class:`~teamnav.env.BatchedEnv` whose copies would need more
  memory than :data:`teamnav.env.batched.MAX_BATCH_BYTES` is refused before any copy is allocated (as scenario files
  refuse maps past :data:`teamnav.world.grid.MAX_MAP_BYTES`).
- :func:`as_action`: an agent's action must be a real number array of two values; complex,
  object and text values are refused (numpy would drop an imaginary part silently), and so
  are wrong shapes, each error naming the agent (and the copy of a batch) and the expected shape.
- :func:`first_not_finite`: which (copy, agent) of a batch has a NaN or infinite action, so
  that a batch is refused before any copy steps.
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

#: Default of :data:`teamnav.env.batched.MAX_BATCH_BYTES` (16 GiB).
MAX_BATCH_BYTES: int = 16 * 1024**3
#: Bytes each copy needs per map cell: its simulation's float64 distance field and the
#: ray-casting tables (measured ~8-18 B/cell on the built-in maps).
BATCH_BYTES_PER_CELL: int = 16
#: Bytes each copy needs per robot (state, scans, brain or proxy, observation objects).
BATCH_BYTES_PER_ROBOT: int = 64 * 1024
#: Bytes each copy needs besides (its simulation, recorder and episode bookkeeping).
BATCH_BYTES_PER_COPY: int = 256 * 1024

#: numpy dtype kinds an action may have: bool, signed and unsigned integers, floats
_REAL_KINDS = frozenset("biuf")


def _gib(n: float) -> str:
    return f"{n / 1024**3:.1f} GiB" if n >= 0.1 * 1024**3 else f"{n / 1024**2:.1f} MiB"


def batch_bytes(n_cells: int, n_robots: int, obs_bytes: int, num_envs: int) -> tuple[float, float]:
    """(bytes per copy, bytes for ``num_envs`` copies) of a batch: a copy's map cells and robots
    at :data:`BATCH_BYTES_PER_CELL` and :data:`BATCH_BYTES_PER_ROBOT`, plus four times its
    observation (the space's bounds, the step's buffer and the copy's own arrays)."""
    per_copy = float(n_cells) * BATCH_BYTES_PER_CELL + float(n_robots) * BATCH_BYTES_PER_ROBOT \
        + 4.0 * float(obs_bytes) + BATCH_BYTES_PER_COPY
    return per_copy, per_copy * float(num_envs)


def batch_memory_problem(n_cells: int, n_robots: int, obs_bytes: int, num_envs: int,
                         limit: int = MAX_BATCH_BYTES) -> str | None:
    """Why ``num_envs`` copies are refused (None when they fit in ``limit`` bytes).

    Examples
    --------
    >>> batch_memory_problem(1_440_000, 1, 1000, 8) is None
    True
    >>> print(batch_memory_problem(1_440_000, 1, 1000, 1_000_000))
    num_envs=1,000,000 copies need about 21.3 TiB of memory (about 22.3 MiB per copy: 1,440,000 map cells at 16 bytes, 1 robot at 65536 bytes; 1,000,000 robots in all); expected at most 16.0 GiB (teamnav.env.batched.MAX_BATCH_BYTES): use fewer copies (at most 735 here), a coarser map or fewer robots
    """
    per_copy, need = batch_bytes(n_cells, n_robots, obs_bytes, num_envs)
    if need <= limit:
        return None
    total = f"{need / 1024**4:.1f} TiB" if need >= 1024**4 else _gib(need)
    fits = int(limit // per_copy)
    return (
        f"num_envs={num_envs:,} copies need about {total} of memory (about {_gib(per_copy)} per copy: "
        f"{n_cells:,} map cells at {BATCH_BYTES_PER_CELL} bytes, {n_robots} robot{'s' if n_robots != 1 else ''} at {BATCH_BYTES_PER_ROBOT} bytes; "
        f"{n_robots * num_envs:,} robots in all); expected at most {_gib(limit)} "
        f"(teamnav.env.batched.MAX_BATCH_BYTES): use fewer copies (at most {fits:,} here), a coarser map or fewer robots"
    )


def _where(agent: str, copy: int | None) -> str:
    return f"agent {agent!r}" if copy is None else f"copy {copy}, agent {agent!r}"


def action_meaning(holonomic: bool) -> str:
    return "(vx, vy) [m/s]" if holonomic else "(v [m/s], omega [rad/s])"


def as_action(value: Any, agent: str, meaning: str, copy: int | None = None, strict: bool = False) -> np.ndarray:
    """``value`` as a float64 array of shape (2,), or ValueError naming the agent (and the copy)
    and the expected shape: complex, object and text values are refused, not cast, and any
    shape with other than two values too (a (1, 2) row is taken, a scalar is not spread;
    ``strict``: only shape (2,))."""
    expected = f"expected a real number array of shape (2,) {meaning}"
    where = _where(agent, copy)
    if isinstance(value, (str, bytes)):
        raise ValueError(f"{where}: action is text {value!r}; {expected}")
    try:
        arr = np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged nesting
        raise ValueError(f"{where}: action {value!r} is not an array ({exc}); {expected}") from None
    if arr.dtype.kind not in _REAL_KINDS:
        raise ValueError(f"{where}: action has dtype {arr.dtype} ({_kind(arr)}), got {_short(value)}; {expected} "
                         "(float64 or any real dtype; complex, object and text are not cast)")
    if arr.size != 2 or (strict and arr.shape != (2,)):
        raise ValueError(f"{where}: action has shape {arr.shape} ({arr.size} values), got {_short(value)}; {expected}")
    return arr.astype(np.float64, copy=False).reshape(2)


def _kind(arr: np.ndarray) -> str:
    return {"c": "complex", "O": "Python objects", "U": "text", "S": "bytes", "V": "records",
            "M": "datetimes", "m": "time spans"}.get(arr.dtype.kind, "not real numbers")


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def check_batch(actions: Any, num_envs: int, agents: Sequence[str], meanings: Sequence[str]) -> np.ndarray:
    """A batch's actions as a float64 array (num_envs, n_agents, 2), or ValueError naming the
    first copy and agent whose action is not real or not of shape (2,), or the axis that
    has the wrong length (with the expected shape)."""
    n = len(agents)
    meaning = meanings[0] if len(set(meanings)) == 1 else "(v, omega) or (vx, vy) per agent"
    expected = f"expected shape ({num_envs}, {n}, 2): copies x agents ({', '.join(agents[:4])}{' ...' if n > 4 else ''}) x 2 {meaning}"
    if isinstance(actions, (str, bytes)):
        raise ValueError(f"actions are text {_short(actions)}; {expected}")
    try:
        a = np.asarray(actions)
        ragged = False
    except (ValueError, TypeError):
        a, ragged = None, True
    if not ragged and a.dtype.kind in _REAL_KINDS:
        if a.shape == (num_envs, n, 2):
            return a.astype(np.float64, copy=False)
        if a.ndim == 3 and a.shape[0] == num_envs and a.shape[1] == n:
            raise ValueError(f"copy 0, agent {agents[0]!r}: action has shape {a.shape[2:]}; {expected} (got {a.shape})")
    # find the first copy / agent that is off
    try:
        copies = list(actions) if not isinstance(actions, dict) else None
    except TypeError:
        copies = None
    if copies is None or (not ragged and a.ndim == 0):
        raise ValueError(f"actions {_short(actions)} are not an array of one action per copy and agent; {expected}")
    if len(copies) != num_envs:
        raise ValueError(f"actions have {len(copies)} copies, got shape {getattr(a, 'shape', '(ragged)')}; {expected}")
    for e, rows in enumerate(copies):
        try:
            rows = list(rows) if not isinstance(rows, (str, bytes, dict)) else None
        except TypeError:
            rows = None
        if rows is None or len(rows) != n:
            got = "not a list of agents' actions" if rows is None else f"{len(rows)} actions"
            raise ValueError(f"copy {e}: {got} for its {n} agents; {expected}")
        for j, v in enumerate(rows):
            as_action(v, agents[j], meanings[j], copy=e, strict=True)
    raise ValueError(f"actions of shape {getattr(a, 'shape', '(ragged)')} and dtype {getattr(a, 'dtype', '?')}; {expected}")


def first_not_finite(a: np.ndarray, check: np.ndarray) -> tuple[int, int] | None:
    """(copy, agent) of the first row of ``a`` (num_envs, n_agents, 2) under the mask ``check``
    (num_envs, n_agents) holding NaN or infinity; None when every checked row is finite."""
    if len(a) * a.shape[1] <= 16:
        if all(map(math.isfinite, a.ravel().tolist())):
            return None
    bad = ~np.isfinite(a).all(axis=2) & check
    if not bad.any():
        return None
    e, j = np.argwhere(bad)[0]
    return int(e), int(j)
