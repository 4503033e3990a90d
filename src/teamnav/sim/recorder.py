"""What a run leaves behind: trajectories (truth and belief), stalls, events, radio traffic, logs.

The :class:`Recorder` keeps one sample every ``record_every`` steps (step 0 included) in
preallocated arrays that double when full, so recording costs one row copy per sample.
Poses are stored as float32 (≈ 10 µm at 100 m from the origin, far below any sensor noise),
which halves the memory of long swarm runs.

:meth:`Recorder.save` writes a run folder's recorder files, each atomically (written under
a temporary name in the same folder, then ``os.replace``-d), so a reader never sees a
half-written file:

``trajectories.npz``
    ``t_s`` (T,) float64, ``step`` (T,) int64, ``true_pose`` (T, N, 3) float32 (world frame),
    ``odom_pose`` (T, N, 3) float32 (each robot's own odometry frame), ``stalled`` (T, N) bool.
``events.json``
    ``{"events": [{"step", "t_s", "robot", "place", "event"}, ...]}``.
``comm.json``
    Radio totals (``messages_sent``, ``bytes_sent``, ``messages_delivered``,
    ``bytes_delivered``, ``deliveries_lost``, ``sent_by_kind``) and ``per_robot`` lists.
``logs.json``
    ``{"logs": [{"step", "t_s", "robot", "values": {...}}, ...]}``: the non-empty dicts of
    per-robot controllers' ``log()``, one entry per robot and recorded step.

:func:`load` reads a folder back into a :class:`RunRecord`.
"""

from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

__all__ = ["Recorder", "RunRecord", "load"]


def _jsonable(v: Any) -> Any:
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (np.bool_,)):
        return bool(v)
    if isinstance(v, np.integer):
        return int(v)
    if isinstance(v, np.floating):
        return float(v)
    if isinstance(v, (set, frozenset)):
        return sorted(v, key=repr)
    return repr(v)


def _write_atomic(path: Path, write) -> None:
    """Call ``write(file_object)`` on a temporary file next to ``path``, then rename it into place."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _write_json(path: Path, obj: Any) -> None:
    data = json.dumps(obj, default=_jsonable, allow_nan=True).encode("utf-8")
    _write_atomic(path, lambda f: f.write(data))


@dataclass
class RunRecord:
    """A recorded run read back by :func:`load` (shapes as in the module docstring)."""

    t_s: np.ndarray
    step: np.ndarray
    true_pose: np.ndarray
    odom_pose: np.ndarray
    stalled: np.ndarray
    events: list[dict] = field(default_factory=list)
    comm: dict = field(default_factory=dict)
    logs: list[dict] = field(default_factory=list)


class Recorder:
    """Samples of a running simulation.

    Parameters
    ----------
    n_robots : int
    record_every : int
        Keep steps ``0, record_every, 2 * record_every, ...``.
    capacity : int, default 256
        Initial number of samples; doubles when full.

    Examples
    --------
    >>> rec = Recorder(2, record_every=1)
    >>> rec.record(0, 0.0, np.zeros((2, 3)), np.zeros((2, 3)), np.zeros(2, bool))
    >>> rec.true_pose.shape
    (1, 2, 3)
    """

    def __init__(self, n_robots: int, record_every: int = 1, capacity: int = 256) -> None:
        if int(n_robots) < 1:
            raise ValueError(f"n_robots must be >= 1, got {n_robots!r}")
        if int(record_every) < 1:
            raise ValueError(f"record_every must be >= 1, got {record_every!r}")
        self.n = int(n_robots)
        self.record_every = int(record_every)
        cap = max(1, int(capacity))
        self._t = np.zeros(cap)
        self._step = np.zeros(cap, np.int64)
        self._true = np.zeros((cap, self.n, 3), np.float32)
        self._odom = np.zeros((cap, self.n, 3), np.float32)
        self._stalled = np.zeros((cap, self.n), np.bool_)
        self.size = 0
        #: Place events, each a dict (step, t_s, robot, place, event); the engine shares its list.
        self.events: list[dict] = []
        self.logs: list[dict] = []
        #: Returns the radio's traffic counts when asked (set by the engine); None: no radio.
        self.comm_counts: Callable[[], dict] | None = None

    @property
    def comm(self) -> dict:
        """Radio traffic so far (zeros when the run has no radio)."""
        if self.comm_counts is not None:
            return self.comm_counts()
        return {"mode": None, "messages_sent": 0, "bytes_sent": 0, "messages_delivered": 0, "bytes_delivered": 0,
                "deliveries_lost": 0, "sent_by_kind": {}, "per_robot": {}}

    def wants(self, step: int) -> bool:
        """Whether step ``step`` is sampled."""
        return step % self.record_every == 0

    def _grow(self) -> None:
        cap = 2 * self._t.shape[0]
        for name in ("_t", "_step", "_true", "_odom", "_stalled"):
            old = getattr(self, name)
            new = np.zeros((cap,) + old.shape[1:], old.dtype)
            new[: self.size] = old[: self.size]
            setattr(self, name, new)

    def record(self, step: int, time_s: float, true_pose: np.ndarray, odom_pose: np.ndarray, stalled: np.ndarray,
               logs: dict[int, dict] | None = None) -> None:
        """Append one sample: poses (N, 3), stall flags (N,), and per-robot controller logs."""
        if self.size == self._t.shape[0]:
            self._grow()
        k = self.size
        self._t[k] = time_s
        self._step[k] = step
        self._true[k] = true_pose
        self._odom[k] = odom_pose
        self._stalled[k] = stalled
        self.size += 1
        if logs:
            for robot, values in logs.items():
                if values:
                    self.logs.append({"step": int(step), "t_s": float(time_s), "robot": int(robot), "values": values})

    # ------------------------------------------------------------------ views
    @property
    def t_s(self) -> np.ndarray:
        return self._t[: self.size]

    @property
    def steps(self) -> np.ndarray:
        return self._step[: self.size]

    @property
    def true_pose(self) -> np.ndarray:
        return self._true[: self.size]

    @property
    def odom_pose(self) -> np.ndarray:
        return self._odom[: self.size]

    @property
    def stalled(self) -> np.ndarray:
        return self._stalled[: self.size]

    # ------------------------------------------------------------------ files
    def save(self, run_dir: str | os.PathLike) -> Path:
        """Write the recorder files into ``run_dir`` (created if needed), each atomically."""
        run_dir = Path(run_dir)
        run_dir.mkdir(parents=True, exist_ok=True)
        arrays = {"t_s": self.t_s, "step": self.steps, "true_pose": self.true_pose, "odom_pose": self.odom_pose,
                  "stalled": self.stalled}
        _write_atomic(run_dir / "trajectories.npz", lambda f: np.savez_compressed(f, **arrays))
        _write_json(run_dir / "events.json", {"events": self.events})
        _write_json(run_dir / "comm.json", self.comm)
        _write_json(run_dir / "logs.json", {"logs": self.logs})
        return run_dir


def load(run_dir: str | os.PathLike) -> RunRecord:
    """Read the recorder files of ``run_dir`` back.

    Raises
    ------
    ValueError
        ``run_dir`` has no ``trajectories.npz``.
    """
    run_dir = Path(run_dir)
    traj = run_dir / "trajectories.npz"
    if not traj.is_file():
        raise ValueError(f"run_dir must hold a recorded run (trajectories.npz), got {str(run_dir)!r}")
    with np.load(traj) as z:
        arrays = {k: np.asarray(z[k]) for k in z.files}

    def read(name: str, key: str | None, default):
        p = run_dir / name
        if not p.is_file():
            return default
        obj = json.loads(p.read_text(encoding="utf-8"))
        return obj.get(key, default) if key is not None else obj

    n_t = arrays["t_s"].shape[0]
    return RunRecord(
        t_s=arrays["t_s"],
        step=arrays.get("step", np.arange(n_t)),
        true_pose=arrays["true_pose"],
        odom_pose=arrays["odom_pose"],
        stalled=arrays.get("stalled", np.zeros(arrays["true_pose"].shape[:2], bool)),
        events=read("events.json", "events", []),
        comm=read("comm.json", None, {}),
        logs=read("logs.json", "logs", []),
    )
