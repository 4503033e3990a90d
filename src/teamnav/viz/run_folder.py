"""Read a run folder that may be damaged or hostile; write an output file without leaving half of it.

``teamnav replay`` and ``teamnav export`` read run folders that anyone may hand them: a copy
cut short, a file from another program, an edited JSON. :func:`read_run_folder` reads the
files :mod:`teamnav.sim.recorder` and :mod:`teamnav.experiments.runner` write and checks every
array and field that the viewers use before they use it, so anything wrong ends in one
:class:`RunFolderError` (a ``ValueError``; the CLI prints it and exits with status 2) that
names the folder, the file, the field and what was expected, for example::

    run folder runs/a: trajectories.npz: true_pose: expected finite poses, found nan at sample 3 (robot 1)

Arrays are always loaded with ``allow_pickle=False``: a file holding Python objects is refused
as such, and no message ever suggests loading pickles. The arrays of a folder may not expand
to more than :data:`MAX_RUN_BYTES` in memory (read from the zip directory before anything is
decompressed).

:func:`atomic_output` writes an output file (the replay page, the MCAP file) under a
temporary name in the target folder and renames it into place only once it is complete; a path
that cannot be written (``/proc/x.mcap``, a folder) is a :class:`OutputPathError` naming the
path, and nothing is left behind: neither the temporary file nor folders made for it.

Examples
--------
::

    rec, robots = read_run_folder("runs/demo-20250101-120000")
    with atomic_output("out/replay.html", "HTML file", "--out") as tmp:
        tmp.write_text(page, encoding="utf-8")
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import re
import secrets
import stat
import sys
import zipfile
import zlib
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from teamnav.files import HOST, claim, destination_problem, file_mode
from teamnav.sim.recorder import LAYER_KINDS, Layer, RunRecord, Scan

#: Files a run folder holds (``teamnav run``); an output path must not be one of them.
RUN_FILES: frozenset[str] = frozenset({
    "trajectories.npz", "layers.npz", "layers.json", "logs.json", "events.json", "comm.json", "robots.json",
    "metrics.json", "scenario.yaml", "map.yaml", "map.pgm", "map_materials.pgm", "trajectories.png", "run.gif",
})

__all__ = ["MAX_JSON_BYTES", "MAX_RUN_BYTES", "MAX_TEXT_BYTES", "RUN_FILES", "OutputPathError", "RunFolderError", "atomic_output", "clean_stale_tmp", "read_map", "read_run_folder", "scenario_name"]

#: Most memory [bytes] the arrays of a run folder (trajectories.npz + layers.npz) may take once
#: decompressed (2 GiB); larger folders are refused before anything is decompressed.
MAX_RUN_BYTES = 2 * 1024**3

#: Largest JSON file of a run folder [bytes] (logs.json of a long run is a few MiB); larger
#: ones are refused before they are read.
MAX_JSON_BYTES = 256 * 1024**2
#: Largest scenario.yaml or map.yaml read from a run folder [bytes].
MAX_TEXT_BYTES = 16 * 1024**2

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_-]{0,63}$")  # layer and scan names (as the recorder allows)
_FRAMES = ("world", "odom")
_ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06")


class RunFolderError(ValueError):
    """A run folder that cannot be read: names the folder, the file, the field (when there is
    one), what was expected and what was found.

    Examples
    --------
    >>> print(RunFolderError("runs/a", "robots.json", "radius_m", "a list of 2 numbers", "'big'"))
    run folder runs/a: robots.json: radius_m: expected a list of 2 numbers, found 'big'
    """

    def __init__(self, run_dir: str | os.PathLike, file: str, field: str, expected: str, found: str | None = None) -> None:
        self.run_dir, self.file, self.field = str(run_dir), file, field
        where = (f"{file}: " if file else "") + (f"{field}: " if field else "")
        got = f", found {found}" if found is not None else ""
        super().__init__(f"run folder {self.run_dir}: {where}expected {expected}{got}")


class OutputPathError(ValueError):
    """An output file that cannot be written where asked; names the path and the option."""


# ---------------------------------------------------------------------------- helpers
def _short(text: Any, limit: int = 120) -> str:
    text = str(text)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def _describe_bytes(head: bytes) -> str:
    if not head:
        return "an empty file"
    try:
        head.decode("utf-8")
    except UnicodeDecodeError:
        return "data that is not a zip archive"
    return "a text file"


def _dtype_word(a: np.ndarray) -> str:
    return f"{a.dtype} array of shape {tuple(a.shape)}"


_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a named pipe (FIFO)"), (stat.S_ISSOCK, "a socket"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"))


def checked_file(run_dir: str | os.PathLike, path: str | os.PathLike, limit: int, *, file: str | None = None) -> Path | None:
    """``path`` (relative to ``run_dir``, or absolute) if it is safe to read as a file of the run
    folder, None when it does not exist.

    Refused, before a byte is read: a symbolic link (or a path) that leads out of ``run_dir``
    (a run folder handed over must not make teamnav read ``~/.ssh/id_rsa`` into a page),
    anything but a regular file (a named pipe would hang the read, a device never ends), and a
    file larger than ``limit`` bytes (a huge or sparse file would exhaust memory).

    Raises
    ------
    RunFolderError
        Naming the file and what it is.
    """
    run_dir = Path(run_dir)
    full = run_dir / path
    label = file or str(path)
    try:
        st = os.lstat(full)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise RunFolderError(run_dir, label, "", "a readable file", _short(exc.strerror or exc)) from None
    if not full.resolve().is_relative_to(run_dir.resolve()):  # a link (or a link above it) out of the folder
        where = os.readlink(full) if stat.S_ISLNK(st.st_mode) else str(full.resolve())
        raise RunFolderError(run_dir, label, "", "a file inside the run folder",
                             f"a path leading out of it, to {_short(where)} (teamnav does not follow it)")
    try:
        st = os.stat(full)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise RunFolderError(run_dir, label, "", "a readable file", _short(exc.strerror or exc)) from None
    if not stat.S_ISREG(st.st_mode):
        kind = next((word for test, word in _KINDS if test(st.st_mode)), "not a regular file")
        raise RunFolderError(run_dir, label, "", "a regular file", kind)
    if st.st_size > limit:
        raise RunFolderError(run_dir, label, "", f"a file of at most {limit / 1024**2:.0f} MiB",
                             f"{st.st_size / 1024**2:.0f} MiB")
    return full


class _Folder:
    """The run folder being read, for messages."""

    def __init__(self, run_dir: Path) -> None:
        self.dir = run_dir

    def error(self, file: str, field: str, expected: str, found: str | None = None) -> RunFolderError:
        return RunFolderError(self.dir, file, field, expected, found)

    # ------------------------------------------------------------------ arrays
    def npz(self, name: str, budget: list[int]) -> dict[str, np.ndarray]:
        """Every array of ``name`` (an .npz), numbers only, with ``allow_pickle=False``."""
        expected = "a NumPy .npz archive as `teamnav run` writes it"
        path = checked_file(self.dir, name, MAX_RUN_BYTES)
        if path is None:
            raise self.error(name, "", "a readable file", "nothing: it does not exist")
        try:
            with open(path, "rb") as fh:
                head = fh.read(4)
        except OSError as exc:
            raise self.error(name, "", "a readable file", _short(exc.strerror or exc)) from None
        if head not in _ZIP_MAGIC:
            raise self.error(name, "", expected, _describe_bytes(head))
        arrays: dict[str, np.ndarray] = {}
        key = ""
        try:
            with zipfile.ZipFile(path) as zf:
                size = sum(info.file_size for info in zf.infolist())
            budget[0] += size
            if budget[0] > MAX_RUN_BYTES:
                raise self.error(
                    name, "", f"arrays of at most {MAX_RUN_BYTES / 1024**3:.0f} GiB in all (teamnav.viz.run_folder.MAX_RUN_BYTES)",
                    f"{budget[0] / 1024**3:.1f} GiB once decompressed",
                )
            with np.load(path, allow_pickle=False) as z:
                if not hasattr(z, "files"):
                    raise self.error(name, "", expected, "a single array, not an archive of named arrays")
                for key in z.files:
                    a = z[key]
                    if not isinstance(a, np.ndarray):
                        raise self.error(name, key, "a NumPy array (.npy) in the archive", "other data")
                    arrays[key] = a
        except RunFolderError:
            raise
        except ValueError as exc:
            if "pickle" in str(exc).lower() or "object arrays" in str(exc).lower():
                # never pass on numpy's advice to load with allow_pickle=True
                raise self.error(name, key, "an array of numbers", "an array of Python objects, which teamnav never loads") from None
            raise self.error(name, key, expected, f"a damaged archive ({_short(exc)})") from None
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError, KeyError, NotImplementedError, RuntimeError) as exc:
            raise self.error(name, key, expected, f"a truncated or damaged archive ({type(exc).__name__}: {_short(exc)})") from None
        return arrays

    def array(
        self,
        arrays: dict[str, np.ndarray],
        file: str,
        key: str,
        shape: tuple,
        kinds: str,
        what: str,
        *,
        finite: bool = False,
    ) -> np.ndarray:
        """``arrays[key]`` checked: its shape (None in ``shape``: any length; ints: that
        length), its dtype kind (``"iu"``, ``"fiu"``, ``"b"``...) and, if ``finite``, no NaN/inf."""
        if key not in arrays:
            have = ", ".join(sorted(arrays)) or "none"
            raise self.error(file, key, what, f"no such array (arrays: {_short(have)})")
        a = arrays[key]
        if a.ndim != len(shape) or any(n is not None and a.shape[i] != n for i, n in enumerate(shape)) or a.dtype.kind not in kinds:
            raise self.error(file, key, what, _dtype_word(a))
        if finite and a.dtype.kind == "f" and a.size and not np.isfinite(a).all():
            bad = tuple(int(i) for i in np.argwhere(~np.isfinite(a))[0])
            raise self.error(file, key, f"{what} with finite values", f"{a[bad]} at index {list(bad)}")
        return a

    # ------------------------------------------------------------------ JSON
    def json(self, name: str) -> Any:
        """The parsed JSON of ``name`` (None when the file is absent)."""
        path = checked_file(self.dir, name, MAX_JSON_BYTES)
        if path is None:
            return None
        try:
            text = path.read_text(encoding="utf-8")
        except UnicodeDecodeError:
            raise self.error(name, "", "UTF-8 JSON text", "bytes that are not UTF-8") from None
        except OSError as exc:
            raise self.error(name, "", "a readable JSON file", _short(exc.strerror or exc)) from None
        try:
            return json.loads(text)
        except json.JSONDecodeError as exc:
            raise self.error(name, "", "valid JSON", f"a syntax error at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
        except RecursionError:
            raise self.error(name, "", "JSON nested a few levels deep", "a document nested too deeply") from None


def _is_int(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def _is_num(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def _show(v: Any) -> str:
    from teamnav.experiments.errors import show_value

    return show_value(v, 60)


# ---------------------------------------------------------------------------- reading
def read_run_folder(run_dir: str | os.PathLike) -> tuple[RunRecord, dict]:
    """The recorder files of ``run_dir`` as a :class:`~teamnav.sim.recorder.RunRecord`, and
    ``robots.json`` (``{}`` when absent), every field checked.

    Raises
    ------
    RunFolderError
        ``run_dir`` is not a run folder, or a file in it is damaged, of another program, or
        holds a value the viewers cannot draw (a NaN pose, an array of the wrong shape, a
        robot index out of range, ...).
    """
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        what = "a file, not a folder" if run_dir.exists() else "nothing: it does not exist"
        raise RunFolderError(run_dir, "", "", "a run folder written by `teamnav run`", what)
    if not (run_dir / "trajectories.npz").is_file():
        raise RunFolderError(run_dir, "", "", "a run folder written by `teamnav run` (with trajectories.npz)",
                             "no trajectories.npz: this is not a run folder")
    fo = _Folder(run_dir)
    budget = [0]
    tf = "trajectories.npz"
    z = fo.npz(tf, budget)
    t_s = fo.array(z, tf, "t_s", (None,), "fiu", "the sample times [s], shape (T,)", finite=True)
    T = t_s.shape[0]
    if T == 0:
        raise fo.error(tf, "t_s", "at least one recorded sample", "none")
    true = fo.array(z, tf, "true_pose", (T, None, 3), "fiu", f"poses (x, y, heading) of shape (T={T}, N, 3)")
    N = true.shape[1]
    if N == 0:
        raise fo.error(tf, "true_pose", "at least one robot", "none")
    odom = fo.array(z, tf, "odom_pose", (T, N, 3), "fiu", f"odometry poses of shape (T={T}, N={N}, 3)")
    for key, a in (("true_pose", true), ("odom_pose", odom)):
        if a.dtype.kind == "f" and not np.isfinite(a).all():
            k, i, c = (int(v) for v in np.argwhere(~np.isfinite(a))[0])
            raise fo.error(tf, key, "finite poses", f"{a[k, i, c]} at sample {k} (t = {float(t_s[k]):g} s), robot {i}, "
                           f"{('x', 'y', 'heading')[c]}")
    if "step" in z:
        step = fo.array(z, tf, "step", (T,), "iu", f"the step numbers, integers of shape (T={T},)").astype(np.int64)
        if T > 1 and (np.diff(step) < 0).any():
            raise fo.error(tf, "step", "step numbers that never decrease", f"step {int(step[np.argmax(np.diff(step) < 0) + 1])} "
                           "after a larger one")
    else:
        step = np.arange(T, dtype=np.int64)
    if "stalled" in z:
        stalled = fo.array(z, tf, "stalled", (T, N), "biu", f"stall flags of shape (T={T}, N={N})").astype(bool)
    else:
        stalled = np.zeros((T, N), bool)

    events = _events(fo, N)
    comm = fo.json("comm.json")
    if comm is None:
        comm = {}
    elif not isinstance(comm, dict):
        raise fo.error("comm.json", "", "a JSON object of radio totals", type(comm).__name__)
    logs = fo.json("logs.json")
    if logs is None:
        logs = []
    else:
        if not isinstance(logs, dict) or not isinstance(logs.get("logs", []), list):
            raise fo.error("logs.json", "logs" if isinstance(logs, dict) else "", 'a JSON object {"logs": [...]}',
                           _show(logs.get("logs") if isinstance(logs, dict) else logs))
        logs = logs.get("logs", [])
    layers, scans = _layers(fo, N, budget)
    robots = _robots(fo, N)
    rec = RunRecord(t_s=t_s.astype(np.float64), step=step, true_pose=_floats(true), odom_pose=_floats(odom), stalled=stalled,
                    events=events, comm=comm, logs=logs, layers=layers, scans=scans)
    return rec, robots


def _floats(a: np.ndarray) -> np.ndarray:
    return a if a.dtype.kind == "f" else a.astype(np.float64)


def _events(fo: _Folder, N: int) -> list[dict]:
    doc = fo.json("events.json")
    if doc is None:
        return []
    name = "events.json"
    if not isinstance(doc, dict) or not isinstance(doc.get("events", []), list):
        raise fo.error(name, "events" if isinstance(doc, dict) else "", 'a JSON object {"events": [...]}',
                       _show(doc.get("events") if isinstance(doc, dict) else doc))
    events = doc.get("events", [])
    for j, e in enumerate(events):
        if not isinstance(e, dict):
            raise fo.error(name, f"events[{j}]", "an object with step, t_s, robot, event", _show(e))
        if "step" in e and not _is_int(e["step"]):
            raise fo.error(name, f"events[{j}].step", "an integer step", _show(e["step"]))
        if "t_s" in e and not _is_num(e["t_s"]):
            raise fo.error(name, f"events[{j}].t_s", "a finite number of seconds", _show(e["t_s"]))
        if "robot" in e and not (_is_int(e["robot"]) and -1 <= e["robot"] < N):
            raise fo.error(name, f"events[{j}].robot", f"a robot index in -1..{N - 1}", _show(e["robot"]))
    return events


def _robots(fo: _Folder, N: int) -> dict:
    doc = fo.json("robots.json")
    if doc is None:
        return {}
    name = "robots.json"
    if not isinstance(doc, dict):
        raise fo.error(name, "", 'a JSON object {"group": [...], "controller": [...], "radius_m": [...]}', type(doc).__name__)
    if "radius_m" in doc:
        r = doc["radius_m"]
        if not (isinstance(r, list) and len(r) == N and all(_is_num(v) and v > 0 for v in r)):
            raise fo.error(name, "radius_m", f"a list of {N} positive numbers (one per robot)", _show(r))
    for key in ("group", "controller"):
        if key in doc:
            v = doc[key]
            if not (isinstance(v, list) and len(v) == N and all(x is None or isinstance(x, str) for x in v)):
                raise fo.error(name, key, f"a list of {N} names (one per robot)", _show(v))
    return doc


def _layers(fo: _Folder, N: int, budget: list[int]) -> tuple[dict[str, Layer], dict[str, Scan]]:
    """Layers and scans, as :func:`teamnav.sim.recorder.load` reads them, checked."""
    layers: dict[str, Layer] = {}
    scans: dict[str, Scan] = {}
    meta = fo.json("layers.json")
    if meta is None or not (fo.dir / "layers.npz").is_file():
        return layers, scans
    mj, nz = "layers.json", "layers.npz"
    if not isinstance(meta, dict):
        raise fo.error(mj, "", 'a JSON object {"layers": {...}, "scans": {...}}', type(meta).__name__)
    lm, sm = meta.get("layers", {}), meta.get("scans", {})
    for key, v in (("layers", lm), ("scans", sm)):
        if not isinstance(v, dict):
            raise fo.error(mj, key, "a JSON object of name -> description", _show(v))
    la = fo.npz(nz, budget)
    for name, m in lm.items():
        where = f"layers.{name}"
        if not _NAME.match(name):
            raise fo.error(mj, where, "a layer name of letters, digits, '_' and '-' (starting with a letter)", _show(name))
        if not isinstance(m, dict):
            raise fo.error(mj, where, "a JSON object (kind, frame, hold, ...)", _show(m))
        kind, frame = m.get("kind"), m.get("frame", "world")
        if kind not in LAYER_KINDS:
            raise fo.error(mj, f"{where}.kind", f"one of {', '.join(LAYER_KINDS)}", _show(kind))
        if frame not in _FRAMES:
            raise fo.error(mj, f"{where}.frame", f"one of {', '.join(_FRAMES)}", _show(frame))
        labels = m.get("labels", [])
        if not (isinstance(labels, list) and all(isinstance(x, str) for x in labels)):
            raise fo.error(mj, f"{where}.labels", "a list of strings", _show(labels))
        columns, description = m.get("columns", []), m.get("description", "")
        if not isinstance(columns, list) or not isinstance(description, str):
            raise fo.error(mj, where, "columns as a list and description as a string", _show(m))
        step = fo.array(la, nz, f"{name}.step", (None,), "iu", "the sample steps, integers of shape (S,)").astype(np.int64)
        S = step.shape[0]
        robot = fo.array(la, nz, f"{name}.robot", (S,), "iu", f"robot indices of shape (S={S},)").astype(np.int64)
        if S and (robot.min() < -1 or robot.max() >= N):
            raise fo.error(nz, f"{name}.robot", f"robot indices in -1..{N - 1}", str(int(robot.min() if robot.min() < -1 else robot.max())))
        offset = fo.array(la, nz, f"{name}.offset", (S + 1,), "iu", f"row offsets of shape (S+1={S + 1},)").astype(np.int64)
        widths = LAYER_KINDS[kind]
        data = fo.array(la, nz, f"{name}.data", (None, None), "fiu", f"rows of shape (K, {' or '.join(map(str, widths))})",
                        finite=True)
        if data.shape[1] not in widths:
            raise fo.error(nz, f"{name}.data", f"rows of width {' or '.join(map(str, widths))} for a {kind} layer", _dtype_word(data))
        if offset[0] != 0 or offset[-1] != data.shape[0] or (np.diff(offset) < 0).any():
            raise fo.error(nz, f"{name}.offset", f"offsets rising from 0 to the {data.shape[0]} rows of {name}.data",
                           f"{offset[0]} .. {offset[-1]}")
        if kind == "state" and data.size and (data.min() < 0 or data.max() >= max(len(labels), 1) or (data != np.round(data)).any()):
            raise fo.error(nz, f"{name}.data", f"label indices in 0..{len(labels) - 1} for a state layer", _short(data[:, 0][:5]))
        layers[name] = Layer(name=name, kind=kind, frame=frame, hold=bool(m.get("hold", False)), columns=list(columns),
                             description=description, labels=list(labels), step=step, robot=robot.astype(np.int32),
                             offset=offset, data=data.astype(np.float32, copy=False))
    for key, m in sm.items():
        where = f"scans.{key}"
        if not _NAME.match(key):
            raise fo.error(mj, where, "a scan name of letters, digits, '_' and '-' (starting with a letter)", _show(key))
        if not isinstance(m, dict):
            raise fo.error(mj, where, "a JSON object (group, sensor, kind, max_range_m)", _show(m))
        mr = m.get("max_range_m")
        if not (_is_num(mr) and mr > 0):
            raise fo.error(mj, f"{where}.max_range_m", "a positive number of metres", _show(mr))
        texts = {k: m.get(k, "") for k in ("group", "sensor", "kind")}
        for k, v in texts.items():
            if not isinstance(v, str):
                raise fo.error(mj, f"{where}.{k}", "a string", _show(v))
        p = f"scan.{key}"
        step = fo.array(la, nz, f"{p}.step", (None,), "iu", "the scan steps, integers of shape (S,)").astype(np.int64)
        if step.shape[0] > 1 and (np.diff(step) < 0).any():
            raise fo.error(nz, f"{p}.step", "scan steps that never decrease", "a decreasing step")
        robots = fo.array(la, nz, f"{p}.robots", (None,), "iu", "robot indices of shape (R,)").astype(np.int64)
        if robots.size and (robots.min() < 0 or robots.max() >= N):
            raise fo.error(nz, f"{p}.robots", f"robot indices in 0..{N - 1}", _short(robots[:8].tolist()))
        angles = fo.array(la, nz, f"{p}.angles_rad", (None,), "fiu", "beam angles [rad] of shape (B,)", finite=True)
        ranges = fo.array(la, nz, f"{p}.ranges", (step.shape[0], robots.shape[0], angles.shape[0]), "fiu",
                          f"ranges of shape (S={step.shape[0]}, R={robots.shape[0]}, B={angles.shape[0]})")
        if ranges.dtype.kind == "f" and np.isnan(ranges).any():
            raise fo.error(nz, f"{p}.ranges", "ranges in metres (no NaN)", "nan")
        scans[key] = Scan(key=key, max_range_m=float(mr), step=step, robots=robots.astype(np.int32),
                          angles_rad=angles.astype(np.float64), ranges=ranges, **texts)
    return layers, scans


def scenario_name(run_dir: str | os.PathLike) -> str:
    """The ``name`` field of the folder's ``scenario.yaml`` ("" when absent or unreadable: it
    only titles a page). Read with the scenario loader's limits (depth, alias expansion)."""
    import yaml

    from teamnav.experiments.spec import read_yaml

    try:
        path = checked_file(run_dir, "scenario.yaml", MAX_TEXT_BYTES)
    except RunFolderError:
        return ""  # a link out, a pipe, a huge file: no title from it
    if path is None:
        return ""
    try:
        doc = read_yaml(path.read_text(encoding="utf-8"))
    except (yaml.YAMLError, OSError, UnicodeDecodeError, RecursionError):
        return ""
    name = doc.get("name", "") if isinstance(doc, dict) else ""
    return name if isinstance(name, str) else ""


def read_map(run_dir: str | os.PathLike):
    """The folder's ``map.yaml`` as an :class:`~teamnav.world.grid.OccupancyGrid`, or None.

    Raises
    ------
    MapError
        The map files are invalid (the message names them).
    RunFolderError
        The map image is larger than a scenario may use
        (:data:`teamnav.experiments.spec.MAX_MAP_BYTES`).
    """
    from teamnav.experiments.spec import map_file_problem
    from teamnav.world.mapio import load_map

    from teamnav.world.mapio import read_map_yaml

    if (Path(run_dir) / "map.yaml").is_dir():
        return None
    path = checked_file(run_dir, "map.yaml", MAX_TEXT_BYTES)
    if path is None:
        return None
    meta = read_map_yaml(path)
    for image in (meta.image, meta.materials_image):  # the images it names: inside the folder, regular files
        if image is not None:
            checked_file(run_dir, Path(os.path.abspath(image)), MAX_RUN_BYTES, file=f"map.yaml's image {Path(image).name}")
    problem = map_file_problem(path)
    if problem:
        raise RunFolderError(run_dir, "map.yaml", "", "a map small enough to load", problem)
    return load_map(path)


# ---------------------------------------------------------------------------- writing
#: ``.NAME.HOST-PID.XXXXXXXX.tmp``: the temporary file of :func:`atomic_output`
_TMP = re.compile(r"^\.(?P<name>.+)\.(?P<host>[A-Za-z0-9-]{1,32})-(?P<pid>\d+)\.[0-9a-f]{8}\.tmp$")


def clean_stale_tmp(path: str | os.PathLike) -> list[Path]:
    """Remove the temporary files of :func:`atomic_output` for ``path`` that processes of this
    host left behind when they were killed outright (SIGKILL, a power cut): their pid is gone."""
    from teamnav.experiments.signals import pid_alive

    path = Path(path)
    removed: list[Path] = []
    try:
        entries = list(os.scandir(path.parent))
    except OSError:
        return removed
    for entry in entries:
        m = _TMP.match(entry.name)
        if m is None or m["name"] != path.name or m["host"] != HOST or pid_alive(int(m["pid"])):
            continue
        with contextlib.suppress(OSError):
            if entry.is_file(follow_symlinks=False) or entry.is_symlink():
                os.unlink(entry.path)
                removed.append(Path(entry.path))
    return removed


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, what: str, option: str, *, run_dir: str | os.PathLike | None = None,
                  force: bool | None = None, wait: bool = False, command: str = "") -> Iterator[Path]:
    """Yield a temporary path in ``path``'s folder; on success rename it to ``path``.

    Folders missing above ``path`` are made; on any failure the temporary file and the folders
    made are removed, and an ``OSError`` becomes an :class:`OutputPathError` naming ``path``
    (``what``: "HTML file", "MCAP file"; ``option``: the CLI option to change). With
    ``run_dir``, a ``path`` that is one of that run folder's own files (:data:`RUN_FILES`) is
    refused: writing the replay over ``trajectories.npz`` would destroy the run it shows.

    ``path`` is claimed for the whole write (:func:`teamnav.files.claim`): a second writer of
    the same ``path`` raises :class:`~teamnav.files.ClaimError` (or waits, with ``wait``).
    With ``force=False``, an existing ``path`` is refused, checked again once the claim is
    held (another writer may have just finished it). Temporary files of writers of ``path``
    that were killed outright are removed; SIGTERM removes this one's as Ctrl-C does. A
    ``path`` that is a symbolic link, or below a file, a dangling link or a read-only folder,
    is refused before anything is made.
    """
    from teamnav.experiments.signals import sigterm_deferred, sigterm_raises

    path = Path(path)
    todo = f"choose another {option}"
    if path.is_dir() and not path.is_symlink():
        raise OutputPathError(f"{what} {path}: expected a file path, found a folder; {todo}")
    problem = destination_problem(path, folder=False)
    if problem is not None:
        raise OutputPathError(f"{what} {path}: cannot be written ({problem}); {todo}")
    if run_dir is not None and path.name in RUN_FILES and path.exists() and path.parent.resolve() == Path(run_dir).resolve():
        raise OutputPathError(f"{what} {path}: expected a new file, found the run folder's own {path.name}; {todo}")

    def refuse_existing() -> None:
        if force is False and (path.exists() or path.is_symlink()):
            raise OutputPathError(f"{what} {path}: exists; {todo} or pass --force")

    refuse_existing()
    parent = path.parent
    made: list[Path] = []
    p = parent
    while not p.exists() and p != p.parent:
        made.append(p)
        p = p.parent
    tmp: Path | None = None

    def undo() -> None:
        if tmp is not None:
            with contextlib.suppress(OSError):
                tmp.unlink()
        for d in made:  # deepest first
            with contextlib.suppress(OSError):
                d.rmdir()

    with sigterm_raises(), contextlib.ExitStack() as held:  # SIGTERM: as Ctrl-C, then the process ends

        @contextlib.contextmanager
        def undone_on_failure():
            """On any failure: release the claim, remove the temporary; an OSError becomes one line."""
            try:
                yield
            except OSError as exc:
                held.close()
                undo()
                raise OutputPathError(f"{what} {path}: cannot be written ({exc.strerror or exc}); {todo}") from None
            except BaseException:
                held.close()
                undo()
                raise

        with undone_on_failure():
            parent.mkdir(parents=True, exist_ok=True)
            held.enter_context(claim(path, what, command=command, wait=wait,
                                     say=lambda line: print(line, file=sys.stderr, flush=True)))
            refuse_existing()
            clean_stale_tmp(path)
            name = parent / f".{path.name}.{HOST}-{os.getpid()}.{secrets.token_hex(4)}.tmp"
            with sigterm_deferred():  # no SIGTERM between creating the file and knowing its name
                os.close(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_EXCL, file_mode()))
                tmp = name
        with undone_on_failure():
            yield tmp
            os.replace(tmp, path)
