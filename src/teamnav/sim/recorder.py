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
    per-robot controllers' ``log()``, one entry per robot and recorded step (without their
    ``"layers"`` entry, which goes to the layer files).
``layers.json`` + ``layers.npz`` (only when a run has layers or scans)
    Extra things to draw, for the HTML replay, the MCAP export and figures (see below).

Layers
------
A *layer* is a named, typed stream of drawable things, written by the engine (detections,
radio messages), by experiment code, or by a brain through its ``log()``. Each layer has

``kind``
    ``"points"``: per sample, a variable list of ``(x, y)`` or ``(x, y, heading)`` rows
    (crumbs, trails, particle clouds, density-tree leaves as centres);
    ``"segments"``: rows ``(x0, y0, x1, y1)`` (detections, messages between robots);
    ``"markers"``: rows ``(x, y)`` or ``(x, y, heading)`` drawn as larger symbols (shared
    goals, ghost robots, MCL estimates);
    ``"state"``: one string per sample (``"carrying"``, ``"in trouble"``, ``"localized"``).
``frame``
    ``"world"`` (the true map frame) or ``"odom"``: the owning robot's own odometry frame,
    the only frame a brain knows. Viewers anchor ``odom`` coordinates at the robot's start
    pose, as :func:`teamnav.viz.plots.odom_in_world` does for believed poses.
``hold``
    False: a sample is shown at its step only. True: a robot's latest sample stays on show
    until that robot's next sample of the layer (so a brain logs its crumbs or its state
    only when they change; an empty sample clears).

A *sample* is ``(step, robot, rows)``; ``robot`` is -1 for team-wide things. Samples are
stored in CSR form in ``layers.npz``: ``NAME.step`` (S,) int64, ``NAME.robot`` (S,) int32,
``NAME.offset`` (S + 1,) int64 and ``NAME.data`` (K, D) float32 (rows of sample ``s`` are
``data[offset[s]:offset[s + 1]]``; for ``state`` layers ``D = 1`` and the value is an index
into the layer's ``labels``). ``layers.json`` holds ``{"format": 1, "layers": {NAME: {"kind",
"frame", "hold", "columns", "description", "labels"}}, "scans": {...}}``.

Range scans (``SimConfig.record_scans``) go to ``layers.npz`` as ``scan.KEY.step`` (S,),
``scan.KEY.robots`` (R,) int32, ``scan.KEY.angles_rad`` (B,) and ``scan.KEY.ranges``
(S, R, B) float32 [m], where ``KEY`` names the group's sensor (``g0_laser``); ``layers.json``
``"scans"`` gives each ``KEY``'s ``group``, ``sensor``, ``kind`` and ``max_range_m``. Ranges
are the noisy readings the brains got, measured from each robot's true pose.

Brains write layers through ``log()``: a ``"layers"`` entry maps layer names to an array
``(k, 2 | 3)`` (a ``points`` layer in the robot's ``odom`` frame, held), a string (a
``state`` layer, held) or a dict ``{"data": ..., "kind": ..., "frame": ..., "hold": ...,
"description": ...}`` for anything else. For example ``{"layers": {"crumbs": xy,
"state": "carrying"}}``.

:func:`load` reads a folder back into a :class:`RunRecord`.
"""

from __future__ import annotations

import contextlib

import json
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from teamnav.files import file_mode

__all__ = ["LAYER_KINDS", "Layer", "Recorder", "RunRecord", "Scan", "load"]

#: layer kind -> allowed row widths (``state``: one label index per sample)
LAYER_KINDS: dict[str, tuple[int, ...]] = {"points": (2, 3), "segments": (4,), "markers": (2, 3), "state": (1,)}
_COLUMNS = {2: ["x_m", "y_m"], 3: ["x_m", "y_m", "heading_rad"], 4: ["x0_m", "y0_m", "x1_m", "y1_m"]}
_FRAMES = ("world", "odom")
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,63}$")


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
    """Call ``write(file_object)`` on a temporary file next to ``path``, then rename it into
    place, with the mode an ordinary file gets (``0o666 & ~umask``; mkstemp's is 0600)."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        if hasattr(os, "fchmod"):
            os.fchmod(fd, file_mode())
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):  # the temp file may not exist yet
            os.unlink(tmp)
        raise


def _write_json(path: Path, obj: Any) -> None:
    data = json.dumps(obj, default=_jsonable, allow_nan=True).encode("utf-8")
    _write_atomic(path, lambda f: f.write(data))


@dataclass
class Layer:
    """One layer read back (see "Layers" in the module docstring).

    Attributes
    ----------
    name, kind, frame : str
    hold : bool
    columns : list of str
        Names of the ``data`` columns (``["label"]`` for ``state``).
    description : str
    labels : list of str
        ``state`` values (``data`` holds indices into it); empty for other kinds.
    step : ndarray of shape (S,), int64
    robot : ndarray of shape (S,), int32 (-1: not one robot's)
    offset : ndarray of shape (S + 1,), int64
    data : ndarray of shape (K, D), float32
    """

    name: str
    kind: str
    frame: str
    hold: bool
    columns: list
    description: str
    labels: list
    step: np.ndarray
    robot: np.ndarray
    offset: np.ndarray
    data: np.ndarray

    def rows(self, s: int) -> np.ndarray:
        """The rows of sample ``s``, shape (k, D)."""
        return self.data[self.offset[s]: self.offset[s + 1]]


@dataclass
class Scan:
    """The range scans of one group's sensor: ``ranges[s, r, b]`` [m] of robot ``robots[r]``,
    beam ``angles_rad[b]`` (body frame), at step ``step[s]``."""

    key: str
    group: str
    sensor: str
    kind: str
    max_range_m: float
    step: np.ndarray
    robots: np.ndarray
    angles_rad: np.ndarray
    ranges: np.ndarray


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
    layers: dict[str, Layer] = field(default_factory=dict)
    scans: dict[str, Scan] = field(default_factory=dict)


class _LayerBuffer:
    """Samples of one layer while the run goes on (rows appended as small arrays)."""

    def __init__(self, name: str, kind: str, frame: str, hold: bool, description: str) -> None:
        self.meta = {"kind": kind, "frame": frame, "hold": bool(hold), "description": description}
        self.name = name
        self.width: int | None = 1 if kind == "state" else None
        self.labels: dict[str, int] = {}
        self.step: list[int] = []
        self.robot: list[int] = []
        self.count: list[int] = []
        self.chunks: list[np.ndarray] = []

    def add(self, step: int, robot: int, data: Any) -> None:
        kind = self.meta["kind"]
        if kind == "state":
            if not isinstance(data, str):
                raise ValueError(f"layer {self.name!r} (state): a sample must be a str, got {type(data).__name__}")
            rows = np.array([[self.labels.setdefault(data, len(self.labels))]], np.float32)
        else:
            rows = np.asarray(data, dtype=np.float32)
            if rows.ndim == 1 and rows.size == 0:
                rows = rows.reshape(0, self.width or LAYER_KINDS[kind][0])
            widths = LAYER_KINDS[kind] if self.width is None else (self.width,)
            if rows.ndim != 2 or rows.shape[1] not in widths:
                raise ValueError(f"layer {self.name!r} ({kind}): a sample must have shape (k, {' or '.join(map(str, widths))}), "
                                 f"got {rows.shape}")
            if not np.isfinite(rows).all():
                raise ValueError(f"layer {self.name!r}: sample of robot {robot} at step {step} has non-finite values")
            self.width = rows.shape[1]
        self.step.append(int(step))
        self.robot.append(int(robot))
        self.count.append(rows.shape[0])
        self.chunks.append(rows)

    def arrays(self) -> dict[str, np.ndarray]:
        width = self.width or LAYER_KINDS[self.meta["kind"]][0]
        data = np.concatenate(self.chunks) if self.chunks else np.zeros((0, width), np.float32)
        return {"step": np.asarray(self.step, np.int64), "robot": np.asarray(self.robot, np.int32),
                "offset": np.concatenate([[0], np.cumsum(self.count, dtype=np.int64)]).astype(np.int64),
                "data": data.reshape(-1, width).astype(np.float32, copy=False)}

    def json(self) -> dict:
        width = self.width or LAYER_KINDS[self.meta["kind"]][0]
        cols = ["label"] if self.meta["kind"] == "state" else _COLUMNS[width]
        return {**self.meta, "columns": cols, "labels": sorted(self.labels, key=self.labels.get)}


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
        self._layers: dict[str, _LayerBuffer] = {}
        self._scans: dict[str, dict] = {}

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
                self.record_log(step, time_s, robot, values)

    def record_log(self, step: int, time_s: float, robot: int, values: dict | None) -> None:
        """Store one brain's ``log()`` entry: its ``"layers"`` entry into layers (module
        docstring), the rest into :attr:`logs` (a brain driven from outside, :mod:`teamnav.env`,
        logs through this too)."""
        if values and "layers" in values:
            values = dict(values)
            self._log_layers(int(step), int(robot), values.pop("layers"))
        if values:
            self.logs.append({"step": int(step), "t_s": float(time_s), "robot": int(robot), "values": values})

    # ------------------------------------------------------------------ layers
    def declare_layer(self, name: str, kind: str, *, frame: str = "world", hold: bool = False,
                      description: str = "") -> None:
        """Create layer ``name`` (see "Layers" in the module docstring); again with the same
        kind and frame is a no-op.

        Raises
        ------
        ValueError
            A bad name, kind or frame, or ``name`` exists with another kind or frame.
        """
        if not isinstance(name, str) or not _NAME.match(name):
            raise ValueError(f"layer name must match {_NAME.pattern} (a letter, then letters, digits, _ or -), got {name!r}")
        if kind not in LAYER_KINDS:
            raise ValueError(f"layer {name!r}: kind must be one of {sorted(LAYER_KINDS)}, got {kind!r}")
        if frame not in _FRAMES:
            raise ValueError(f"layer {name!r}: frame must be one of {list(_FRAMES)}, got {frame!r}")
        old = self._layers.get(name)
        if old is not None:
            if (old.meta["kind"], old.meta["frame"]) != (kind, frame):
                raise ValueError(f"layer {name!r} is a {old.meta['kind']} layer in frame {old.meta['frame']!r}; "
                                 f"got kind {kind!r} in frame {frame!r}")
            return
        self._layers[name] = _LayerBuffer(name, kind, frame, hold, str(description))

    def add_layer_sample(self, name: str, step: int, robot: int, data: Any) -> None:
        """Append one sample to the declared layer ``name``.

        Parameters
        ----------
        name : str
        step : int
            The engine step it belongs to (viewers show it at the first recorded step >= it).
        robot : int
            The owning robot (its colour; its odometry frame for ``frame="odom"``), or -1.
        data : array_like of shape (k, D), or str for ``state`` layers
            Rows as in "Layers" (module docstring); k may be 0.

        Examples
        --------
        >>> rec = Recorder(2)
        >>> rec.declare_layer("goals", "markers", hold=True)
        >>> rec.add_layer_sample("goals", 0, 1, [[1.0, 2.0]])
        >>> rec.layer_names
        ['goals']
        """
        buf = self._layers.get(name)
        if buf is None:
            raise ValueError(f"layer {name!r} is not declared; call declare_layer first (declared: {sorted(self._layers)})")
        if not -1 <= int(robot) < self.n:
            raise ValueError(f"layer {name!r}: robot must be -1 or in [0, {self.n}), got {robot!r}")
        buf.add(step, robot, data)

    @property
    def layer_names(self) -> list[str]:
        return sorted(self._layers)

    def _log_layers(self, step: int, robot: int, layers: Any) -> None:
        """Store the ``"layers"`` entry of a brain's ``log()`` (see the module docstring)."""
        if not isinstance(layers, dict):
            raise ValueError(f"robot {robot}: log()['layers'] must be a dict of layer name to data, got "
                             f"{type(layers).__name__}")
        for name, value in layers.items():
            if isinstance(value, str):
                spec = {"kind": "state", "data": value}
            elif isinstance(value, dict):
                if "data" not in value:
                    raise ValueError(f"robot {robot}: log()['layers'][{name!r}] needs a 'data' entry")
                spec = value
            else:
                spec = {"kind": "points", "data": value}
            kind = spec.get("kind", "points")
            default_hold = kind != "segments"
            self.declare_layer(name, kind, frame=spec.get("frame", "world" if kind == "state" else "odom"), hold=bool(spec.get("hold", default_hold)),
                               description=spec.get("description", ""))
            self.add_layer_sample(name, step, robot, spec["data"])

    def add_scan(self, key: str, step: int, robots: np.ndarray, ranges: np.ndarray, *, angles_rad: np.ndarray,
                 max_range_m: float, group: str = "", sensor: str = "", kind: str = "") -> None:
        """Append the scans ``ranges`` (R, B) [m] of ``robots`` (R,) taken at ``step``, under ``key``."""
        if not isinstance(key, str) or not _NAME.match(key):
            raise ValueError(f"scan key must match {_NAME.pattern}, got {key!r}")
        ranges = np.asarray(ranges, dtype=np.float32)
        entry = self._scans.get(key)
        if entry is None:
            entry = self._scans[key] = {
                "meta": {"group": group, "sensor": sensor, "kind": kind, "max_range_m": float(max_range_m)},
                "robots": np.asarray(robots, np.int32).copy(), "angles_rad": np.asarray(angles_rad, float).copy(),
                "step": [], "ranges": [],
            }
        if ranges.shape != (entry["robots"].shape[0], entry["angles_rad"].shape[0]):
            raise ValueError(f"scan {key!r}: ranges must have shape {(entry['robots'].shape[0], entry['angles_rad'].shape[0])}, "
                             f"got {ranges.shape}")
        entry["step"].append(int(step))
        entry["ranges"].append(ranges.copy())

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
        if self._layers or self._scans:
            arrays = {}
            for name, buf in self._layers.items():
                for k, v in buf.arrays().items():
                    arrays[f"{name}.{k}"] = v
            for key, e in self._scans.items():
                arrays[f"scan.{key}.step"] = np.asarray(e["step"], np.int64)
                arrays[f"scan.{key}.robots"] = e["robots"]
                arrays[f"scan.{key}.angles_rad"] = e["angles_rad"]
                arrays[f"scan.{key}.ranges"] = np.stack(e["ranges"]) if e["ranges"] else np.zeros(
                    (0, e["robots"].shape[0], e["angles_rad"].shape[0]), np.float32)
            _write_atomic(run_dir / "layers.npz", lambda f: np.savez_compressed(f, **arrays))
            _write_json(run_dir / "layers.json", {
                "format": 1,
                "layers": {name: buf.json() for name, buf in self._layers.items()},
                "scans": {key: e["meta"] for key, e in self._scans.items()},
            })
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
    with np.load(traj, allow_pickle=False) as z:
        arrays = {k: np.asarray(z[k]) for k in z.files}

    def read(name: str, key: str | None, default):
        p = run_dir / name
        if not p.is_file():
            return default
        obj = json.loads(p.read_text(encoding="utf-8"))
        return obj.get(key, default) if key is not None else obj

    n_t = arrays["t_s"].shape[0]
    layers: dict[str, Layer] = {}
    scans: dict[str, Scan] = {}
    meta = read("layers.json", None, None)
    if meta is not None and (run_dir / "layers.npz").is_file():
        with np.load(run_dir / "layers.npz", allow_pickle=False) as z:
            la = {k: np.asarray(z[k]) for k in z.files}
        for name, m in meta.get("layers", {}).items():
            layers[name] = Layer(name=name, kind=m["kind"], frame=m["frame"], hold=bool(m["hold"]),
                                 columns=list(m.get("columns", [])), description=m.get("description", ""),
                                 labels=list(m.get("labels", [])), step=la[f"{name}.step"], robot=la[f"{name}.robot"],
                                 offset=la[f"{name}.offset"], data=la[f"{name}.data"])
        for key, m in meta.get("scans", {}).items():
            scans[key] = Scan(key=key, group=m.get("group", ""), sensor=m.get("sensor", ""), kind=m.get("kind", ""),
                              max_range_m=float(m["max_range_m"]), step=la[f"scan.{key}.step"],
                              robots=la[f"scan.{key}.robots"], angles_rad=la[f"scan.{key}.angles_rad"],
                              ranges=la[f"scan.{key}.ranges"])
    return RunRecord(
        t_s=arrays["t_s"],
        step=arrays.get("step", np.arange(n_t)),
        true_pose=arrays["true_pose"],
        odom_pose=arrays["odom_pose"],
        stalled=arrays.get("stalled", np.zeros(arrays["true_pose"].shape[:2], bool)),
        events=read("events.json", "events", []),
        comm=read("comm.json", None, {}),
        logs=read("logs.json", "logs", []),
        layers=layers,
        scans=scans,
    )
