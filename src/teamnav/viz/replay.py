"""A self-contained HTML replay of a recorded run: one file, data and script inlined.

:func:`build_replay` reads a run folder (only the folder: ``trajectories.npz``, ``map.yaml``,
and when present ``robots.json``, ``events.json``, ``layers.json`` + ``layers.npz``,
``scenario.yaml``; see :mod:`teamnav.sim.recorder`) and writes an HTML page that plays it on a
canvas over the map, from disk, with no server and no network. It works for any run folder,
including ones from other people's scenarios.

What the page draws (each a layer the viewer can toggle):

- true poses (discs with a heading tick) and a short trail of recent true positions;
- believed poses: each robot's odometry, which lives in the robot's own frame, drawn anchored
  at its start pose (``T0 · O0⁻¹ · O_t``, as :func:`teamnav.viz.plots.odom_in_world`), so the
  gap to the true disc is the odometry error;
- range scans (``record_scans``), rays from the true pose;
- every recorder layer: ``points`` (crumbs, trails, particle clouds, subsampled to
  ``max_points`` per sample), ``segments`` (detections, messages), ``markers`` (goals, ghost
  robots), ``state`` (text next to each robot and in the per-robot table). Layers in a robot's
  ``odom`` frame are anchored like the believed poses;
- task events (a ring around the robot for a moment, and the list of recent events).

Controls: timeline scrubber, play/pause, speed, single steps, follow a robot, zoom (wheel) and
pan (drag), a legend, the time and each robot's state at the current step.

Hostile strings
---------------
Names and labels come from scenario files and run folders that anyone may hand over (robot
groups, sensors, places, events, layer descriptions and labels, the scenario name). The page
never runs them: the title is HTML-escaped, the metadata is JSON with ``<``, ``>``, ``&``,
U+2028 and U+2029 written as ``\\u003c`` etc. (so it cannot close its ``<script>`` element),
the page puts strings into the DOM only through ``textContent`` or its ``esc()``, and its
Content-Security-Policy runs no script but its own (allowed by hash) and loads nothing from
outside.

Size
----
Frames are every ``every``-th recorded sample, further thinned so that there are at most
``max_frames``. Positions are quantised to int16 over the map's bounds (a few mm on a 100 m
map), headings to int8 (1.4°), scan ranges to uint8 of the sensor's range, delta-coded over
time, zlib-compressed and base64-encoded; the page inflates them with the browser's own
``DecompressionStream``. The page exposes ``window.teamnavReplay`` (current frame and step,
robot screen positions, layer switches, timings) for tests and scripting.
"""

from __future__ import annotations

import base64
import hashlib
import html
import io
import json
import math
import os
import re
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from teamnav.sim.recorder import RunRecord
from teamnav.viz.run_folder import atomic_output, read_map, read_run_folder
from teamnav.viz.run_folder import scenario_name as run_scenario_name
from teamnav.world.grid import OccupancyGrid

__all__ = ["ReplayStats", "build_replay", "odom_anchor", "read_run"]

_TEMPLATE = Path(__file__).with_name("replay_template.html")
#: map images wider or taller than this are downsampled [px]
MAX_MAP_PX = 4096
#: map colours (RGB) per material name, as in the matplotlib figures; others purple
_MATERIAL_RGB = {"free": (255, 255, 255), "wall": (0, 0, 0), "unknown": (158, 158, 158), "glass": (59, 130, 246),
                 "foam": (245, 158, 11)}
_OTHER_RGB = (142, 68, 173)


@dataclass(frozen=True)
class ReplayStats:
    """What :func:`build_replay` wrote: ``path``, ``n_frames``, ``every`` (recorded samples per
    frame), ``n_robots``, ``bytes`` (file size) and ``layers`` (names of the toggleable layers)."""

    path: Path
    n_frames: int
    every: int
    n_robots: int
    bytes: int
    layers: tuple[str, ...]


def read_run(run_dir: str | os.PathLike) -> tuple[RunRecord, OccupancyGrid | None, dict]:
    """The recorder files, the map (None when the folder has no ``map.yaml``) and ``robots.json``,
    every array and field checked (:func:`teamnav.viz.run_folder.read_run_folder`).

    Raises
    ------
    RunFolderError
        ``run_dir`` is not a run folder, or a file in it is damaged or malformed (the message
        names the file and the field).
    MapError
        ``map.yaml`` or its image is invalid.
    """
    rec, robots = read_run_folder(run_dir)
    return rec, read_map(run_dir), robots


def odom_anchor(true_pose0: np.ndarray, odom_pose0: np.ndarray) -> np.ndarray:
    """Per robot, the rigid transform from its odometry frame to the world that puts its first
    odometry pose on its first true pose: ``A = T0 · O0⁻¹``.

    Parameters
    ----------
    true_pose0, odom_pose0 : ndarray of shape (N, 3)

    Returns
    -------
    ndarray of shape (N, 3)
        ``(tx, ty, dtheta)``: a point ``p`` in robot i's odometry frame is drawn at
        ``R(dtheta_i) p + t_i``.

    Examples
    --------
    >>> a = odom_anchor(np.array([[1.0, 2.0, 0.0]]), np.array([[0.0, 0.0, 0.0]]))
    >>> a.tolist()
    [[1.0, 2.0, 0.0]]
    """
    T0 = np.asarray(true_pose0, float)
    O0 = np.asarray(odom_pose0, float)
    d = T0[:, 2] - O0[:, 2]
    c, s = np.cos(d), np.sin(d)
    tx = T0[:, 0] - (c * O0[:, 0] - s * O0[:, 1])
    ty = T0[:, 1] - (s * O0[:, 0] + c * O0[:, 1])
    return np.stack([tx, ty, d], axis=1)


def _apply_anchor(anchor: np.ndarray, robot: np.ndarray, xy: np.ndarray, heading: np.ndarray | None = None):
    """Rows ``xy`` (k, 2) in the odometry frames of ``robot`` (k,) to the world."""
    a = anchor[robot]
    c, s = np.cos(a[:, 2]), np.sin(a[:, 2])
    x = c * xy[:, 0] - s * xy[:, 1] + a[:, 0]
    y = s * xy[:, 0] + c * xy[:, 1] + a[:, 1]
    out = np.stack([x, y], axis=1)
    if heading is not None:
        out = np.concatenate([out, (heading + a[:, 2])[:, None]], axis=1)
    return out


# ---------------------------------------------------------------------------- packing
class _Pack:
    """Typed arrays laid end to end (8-byte aligned), described by name, dtype, offset, shape."""

    _JS = {np.dtype(np.int8): "i8", np.dtype(np.uint8): "u8", np.dtype(np.int16): "i16", np.dtype(np.uint16): "u16",
           np.dtype(np.int32): "i32", np.dtype(np.float32): "f32", np.dtype(np.float64): "f64"}

    def __init__(self) -> None:
        self.buf = io.BytesIO()
        self.index: dict[str, list] = {}

    def add(self, name: str, a: np.ndarray) -> str:
        a = np.ascontiguousarray(a)
        if a.dtype not in self._JS:
            raise TypeError(f"cannot pack {a.dtype}")
        pad = (-self.buf.tell()) % 8
        self.buf.write(b"\0" * pad)
        self.index[name] = [self._JS[a.dtype], self.buf.tell(), int(a.size), list(a.shape)]
        self.buf.write(a.astype(a.dtype.newbyteorder("<"), copy=False).tobytes())
        return name

    def encoded(self, level: int) -> str:
        return base64.b64encode(zlib.compress(self.buf.getvalue(), level)).decode("ascii")


class _Quant:
    """World coordinates to int16 over the drawing bounds, and back: ``x = x0 + q * scale``."""

    def __init__(self, x0: float, y0: float, x1: float, y1: float) -> None:
        self.x0, self.y0 = float(x0), float(y0)
        self.scale = max(x1 - x0, y1 - y0, 1e-6) / 65000.0

    def q(self, v: np.ndarray, origin: float) -> np.ndarray:
        return np.clip(np.rint((np.asarray(v, float) - origin) / self.scale) - 32500, -32768, 32767).astype(np.int16)

    def qx(self, v):
        return self.q(v, self.x0)

    def qy(self, v):
        return self.q(v, self.y0)

    def json(self) -> dict:
        return {"x0": self.x0, "y0": self.y0, "scale": self.scale, "bias": 32500}


def _q_angle(a: np.ndarray) -> np.ndarray:
    """Angles [rad] to int8 (256 levels per turn)."""
    return (np.rint(np.asarray(a, float) * (128.0 / math.pi)).astype(np.int64) % 256).astype(np.uint8).view(np.int8)


def _delta_time(a: np.ndarray) -> np.ndarray:
    """Differences along axis 0 with wrap-around integer arithmetic (undone by a running sum)."""
    out = a.copy()
    out[1:] = a[1:] - a[:-1]  # numpy integer arithmetic wraps, as the page's typed arrays do
    return out


def _map_png(grid: OccupancyGrid) -> tuple[str, int]:
    """The map as a PNG data URI (row 0 at the top = highest y) and its downsampling factor."""
    from PIL import Image

    lut = np.array([_MATERIAL_RGB.get(m, _OTHER_RGB) for m in grid.materials] + [_OTHER_RGB] * (256 - len(grid.materials)),
                   np.uint8)
    cells = grid.cells[::-1]
    f = max(1, math.ceil(max(cells.shape) / MAX_MAP_PX))
    rgb = lut[cells[::f, ::f]]
    out = io.BytesIO()
    Image.fromarray(rgb, "RGB").save(out, format="PNG", optimize=True)
    return "data:image/png;base64," + base64.b64encode(out.getvalue()).decode("ascii"), f


def _frame_samples(n_samples: int, every: int, max_frames: int) -> tuple[np.ndarray, int]:
    """Indices of the recorded samples shown as frames (the last one always) and the stride."""
    every = max(1, int(every))
    if n_samples > 0 and math.ceil(n_samples / every) > max_frames:
        every = math.ceil(n_samples / max_frames)
    idx = np.arange(0, n_samples, every)
    if idx.size == 0 or idx[-1] != n_samples - 1:
        idx = np.append(idx, n_samples - 1)
    return idx.astype(np.int64), every


def _bounds(grid: OccupancyGrid | None, xy: np.ndarray) -> tuple[float, float, float, float]:
    pts = xy.reshape(-1, 2)
    pts = pts[np.isfinite(pts).all(axis=1)]
    if grid is not None:
        x0, x1, y0, y1 = grid.bounds_m
        if "unknown" in grid.materials:  # frame the explored part of a SLAM map, not its grey margin
            rows, cols = np.nonzero(grid.cells != grid.materials.index("unknown"))
            if rows.size and grid.rotated:
                x0, x1, y0, y1 = grid.block_bounds_m(rows.min(), rows.max(), cols.min(), cols.max())
            elif rows.size:
                (x0, y0), (x1, y1) = grid.cell_centers(rows.min(), cols.min()), grid.cell_centers(rows.max(), cols.max())
    else:
        x0, x1, y0, y1 = float(pts[:, 0].min()), float(pts[:, 0].max()), float(pts[:, 1].min()), float(pts[:, 1].max())
    if pts.size:
        x0, x1 = min(x0, float(pts[:, 0].min())), max(x1, float(pts[:, 0].max()))
        y0, y1 = min(y0, float(pts[:, 1].min())), max(y1, float(pts[:, 1].max()))
    m = 0.02 * max(x1 - x0, y1 - y0, 1.0)
    return x0 - m, y0 - m, x1 + m, y1 + m


#: characters that JSON inside a ``<script>`` element must not hold literally: ``<`` (``</script>``,
#: ``<!--``), ``>``, ``&``, and the line separators that some JavaScript parsers end a line at
_SCRIPT_JSON_ESCAPES = {"<": "\\u003c", ">": "\\u003e", "&": "\\u0026", "\u2028": "\\u2028", "\u2029": "\\u2029"}


def _script_json(value: Any) -> str:
    """``value`` as JSON that is safe inside an HTML ``<script>`` element: ``<``, ``>``, ``&``,
    U+2028 and U+2029 are written as ``\\u003c`` etc., so no string (a scenario's robot group
    or place name, a layer label) can close the element or open a comment in it; ``JSON.parse``
    and :func:`json.loads` read the same value back.

    Examples
    --------
    >>> _script_json({"name": "</script><b>&"})
    '{"name":"\\\\u003c/script\\\\u003e\\\\u003cb\\\\u003e\\\\u0026"}'
    >>> json.loads(_script_json(["</script>"]))
    ['</script>']
    """
    text = json.dumps(value, separators=(",", ":"))
    return re.sub("[<>&\u2028\u2029]", lambda m: _SCRIPT_JSON_ESCAPES[m.group(0)], text)


def _script_csp(page: str) -> str:
    """The page's Content-Security-Policy: nothing from outside, images only as ``data:`` URIs,
    and no script element or inline event handler but the page's own script (its last
    ``<script>`` element, allowed by its SHA-256), so even a string that slipped through escaping
    could not run. ``'unsafe-eval'`` lets drivers such as Playwright's ``wait_for_function``
    evaluate expressions in the page (the page itself never evaluates strings)."""
    start = page.rindex("<script>") + len("<script>")
    body = page[start: page.index("</script>", start)]
    digest = base64.b64encode(hashlib.sha256(body.encode("utf-8")).digest()).decode("ascii")
    return (f"default-src 'none'; img-src data:; style-src 'unsafe-inline'; script-src 'sha256-{digest}' 'unsafe-eval'; "
            "base-uri 'none'; form-action 'none'")


def _colours(n: int) -> list[str]:
    """One distinct colour per robot (evenly spaced hues, golden-ratio order past 10)."""
    base = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"]
    if n <= len(base):
        return base[:n]
    return [f"hsl({(i * 137.508) % 360:.1f},70%,45%)" for i in range(n)]


# ---------------------------------------------------------------------------- build
def build_replay(
    run_dir: str | os.PathLike,
    out: str | os.PathLike | None = None,
    *,
    every: int = 1,
    max_frames: int = 5000,
    max_points: int = 300,
    max_beams: int = 90,
    scans: bool = True,
    title: str | None = None,
    compress_level: int = 6,
    wait: bool = False,
) -> ReplayStats:
    """Write the HTML replay of the run folder ``run_dir``.

    Parameters
    ----------
    run_dir : str or Path
        A run folder (see :mod:`teamnav.experiments.runner`).
    out : str or Path, optional
        The HTML file (default ``run_dir/replay.html``).
    every : int, default 1
        Keep every ``every``-th recorded sample as a frame.
    max_frames : int, default 5000
        At most this many frames (``every`` grows to fit); the last sample is always a frame.
    max_points : int, default 300
        At most this many rows per sample of a ``points`` layer (evenly subsampled: particle
        clouds).
    max_beams : int, default 90
        At most this many beams per scan (evenly subsampled).
    scans : bool, default True
        Include recorded range scans.
    title : str, optional
        Page title (default: the scenario name and the folder name).
    compress_level : int, default 6
        zlib level of the inlined data.
    wait : bool, default False
        When another process is writing ``out`` (it holds its claim: :func:`teamnav.files.claim`),
        wait for it instead of refusing (:class:`~teamnav.files.ClaimError`).

    Returns
    -------
    ReplayStats

    Raises
    ------
    ValueError
        Not a run folder, or a bad option (naming it).
    """
    for name, v, lo in (("every", every, 1), ("max_frames", max_frames, 2), ("max_points", max_points, 1),
                        ("max_beams", max_beams, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise ValueError(f"{name} must be an int >= {lo}, got {v!r}")
    run_dir = Path(run_dir)
    rec, grid, robots = read_run(run_dir)
    out = Path(out) if out is not None else run_dir / "replay.html"
    T, N = rec.true_pose.shape[:2]
    if T == 0:
        raise ValueError(f"{str(run_dir)!r}: trajectories.npz holds no samples")
    fidx, every = _frame_samples(T, every, max_frames)
    F = fidx.size
    steps = np.asarray(rec.step, np.int64)
    fsteps = steps[fidx]
    true = np.asarray(rec.true_pose, float)[fidx]
    anchor = odom_anchor(rec.true_pose[0], rec.odom_pose[0])
    odom = np.asarray(rec.odom_pose, float)[fidx]
    belief = _apply_anchor(anchor, np.tile(np.arange(N), F), odom[..., :2].reshape(-1, 2),
                           odom[..., 2].reshape(-1)).reshape(F, N, 3)
    x0, y0, x1, y1 = _bounds(grid, np.concatenate([true[..., :2], belief[..., :2]]))
    qt = _Quant(x0, y0, x1, y1)
    pack = _Pack()
    pack.add("fstep", fsteps.astype(np.int32))
    pack.add("ft", np.asarray(rec.t_s, float)[fidx].astype(np.float32))
    for key, p in (("true", true), ("belief", belief)):
        pack.add(f"{key}.x", _delta_time(qt.qx(p[..., 0])))
        pack.add(f"{key}.y", _delta_time(qt.qy(p[..., 1])))
        pack.add(f"{key}.th", _delta_time(_q_angle(p[..., 2])))
    stalled = np.asarray(rec.stalled, bool)[fidx]
    pack.add("stalled", stalled.astype(np.uint8))

    def frame_of(step_arr: np.ndarray) -> np.ndarray:
        return np.searchsorted(fsteps, np.asarray(step_arr, np.int64), side="left")

    layers_meta = []
    for name in sorted(rec.layers):
        lay = rec.layers[name]
        S = lay.step.shape[0]
        if S == 0:  # declared but never written (e.g. no radio in a swarm run): nothing to toggle
            continue
        f = frame_of(lay.step)
        keep = f < F
        counts = np.diff(lay.offset)
        rows_sel, new_counts = [], np.zeros(S, np.int64)
        for s in np.flatnonzero(keep):
            k = int(counts[s])
            sel = np.arange(lay.offset[s], lay.offset[s + 1])
            if lay.kind == "points" and k > max_points:
                sel = sel[np.linspace(0, k - 1, max_points).round().astype(np.int64)]
            rows_sel.append(sel)
            new_counts[s] = sel.size
        sel = np.concatenate(rows_sel) if rows_sel else np.zeros(0, np.int64)
        data = lay.data[sel].astype(float)
        robot_of_row = np.repeat(lay.robot.astype(np.int64), new_counts)
        samples = np.flatnonzero(keep)
        # sort samples by (robot, frame) for per-robot binary search in the page
        rob = lay.robot.astype(np.int64)[samples]
        rob_key = np.where(rob < 0, N, rob)
        order = np.lexsort((f[samples], rob_key))
        samples = samples[order]
        starts = np.concatenate([[0], np.cumsum(new_counts)])  # row start per original sample in `data`
        perm = np.concatenate([np.arange(starts[s], starts[s + 1]) for s in samples]) if samples.size else np.zeros(0, np.int64)
        data, robot_of_row = data[perm], robot_of_row[perm]
        cnt = new_counts[samples]
        entry = {"name": name, "kind": lay.kind, "frame": lay.frame, "hold": lay.hold, "description": lay.description,
                 "labels": lay.labels, "width": int(lay.data.shape[1])}
        pack.add(f"L.{name}.frame", f[samples].astype(np.int32))
        pack.add(f"L.{name}.off", np.concatenate([[0], np.cumsum(cnt)]).astype(np.int32))
        rstart = np.searchsorted(rob_key[order], np.arange(N + 2), side="left").astype(np.int32)
        pack.add(f"L.{name}.rstart", rstart)  # samples of robot r: rstart[r]..rstart[r+1]; team-wide: index N
        if lay.kind == "state":
            pack.add(f"L.{name}.v", data[:, 0].astype(np.int16))
        else:
            if lay.frame == "odom" and data.shape[0]:
                own = np.clip(robot_of_row, 0, N - 1)
                if lay.kind == "segments":
                    a = _apply_anchor(anchor, own, data[:, 0:2])
                    b = _apply_anchor(anchor, own, data[:, 2:4])
                    data = np.concatenate([a, b], axis=1)
                else:
                    data = _apply_anchor(anchor, own, data[:, :2], data[:, 2] if data.shape[1] == 3 else None)
            cols = [qt.qx(data[:, 0]) if data.size else np.zeros(0, np.int16),
                    qt.qy(data[:, 1]) if data.size else np.zeros(0, np.int16)]
            if lay.kind == "segments":
                cols += [qt.qx(data[:, 2]), qt.qy(data[:, 3])] if data.size else [np.zeros(0, np.int16)] * 2
            pack.add(f"L.{name}.xy", np.stack(cols, axis=1).astype(np.int16) if data.size else np.zeros((0, len(cols)), np.int16))
            if lay.kind != "segments" and lay.data.shape[1] == 3:
                pack.add(f"L.{name}.th", _q_angle(data[:, 2]) if data.size else np.zeros(0, np.int8))
                entry["heading"] = True
        layers_meta.append(entry)

    scans_meta = []
    if scans:
        for key in sorted(rec.scans):
            sc = rec.scans[key]
            if sc.step.shape[0] == 0:
                continue
            pos = np.searchsorted(sc.step, fsteps, side="left")
            ok = (pos < sc.step.shape[0]) & (sc.step[np.minimum(pos, sc.step.shape[0] - 1)] == fsteps)
            B = sc.angles_rad.shape[0]
            bsel = np.arange(B) if B <= max_beams else np.linspace(0, B - 1, max_beams).round().astype(np.int64)
            rng = np.zeros((F, sc.robots.shape[0], bsel.size), np.uint8)
            if ok.any():
                r = sc.ranges[pos[ok]][:, :, bsel]
                rng[ok] = np.clip(np.rint(r / max(sc.max_range_m, 1e-9) * 254), 0, 254).astype(np.uint8)
            rng[~ok] = 255  # 255: no scan at this frame
            pack.add(f"S.{key}.r", rng)
            pack.add(f"S.{key}.robots", sc.robots.astype(np.int32))
            pack.add(f"S.{key}.ang", sc.angles_rad[bsel].astype(np.float32))
            scans_meta.append({"key": key, "group": sc.group, "sensor": sc.sensor, "kind": sc.kind,
                               "max_range_m": sc.max_range_m, "beams": int(bsel.size)})

    events = []
    for e in rec.events:
        try:
            fr = int(frame_of([int(e["step"])])[0])
        except (KeyError, TypeError, ValueError):
            continue
        if fr < F:
            # a fault (teamnav.sim.faults) is recorded with event None and its kind under "fault"
            # a robot's start (a scenario's launch: robots started one at a time) under "launched"
            label = e.get("event") if e.get("event") is not None else (
                f"fault: {e['fault']}" if e.get("fault") else "started" if e.get("launched") else "")
            events.append({"f": fr, "t": float(e.get("t_s", 0.0)), "robot": int(e.get("robot", -1)),
                           "event": str(label), "place": str(e.get("place") or "")})

    map_meta = None
    if grid is not None:
        uri, f = _map_png(grid)
        # the image's own rectangle (origin + size) and the yaw it is turned by about its origin
        (gx0, gy0), (gw, gh) = grid.origin_xy_m, grid.size_m
        map_meta = {"png": uri, "x0": gx0, "y0": gy0, "x1": gx0 + gw, "y1": gy0 + gh, "yaw": grid.yaw_rad,
                    "downsample": f, "name": grid.name}

    scenario_name = run_scenario_name(run_dir)
    radius = robots.get("radius_m") if isinstance(robots.get("radius_m"), list) and len(robots["radius_m"]) == N else [0.2] * N
    group = robots.get("group") if isinstance(robots.get("group"), list) and len(robots["group"]) == N else [""] * N
    meta = {
        "format": 1,
        "title": title or (f"{scenario_name} — {run_dir.resolve().name}" if scenario_name else run_dir.resolve().name),
        "n_robots": N, "n_frames": F, "every": every, "n_samples": T,
        "bounds": [x0, y0, x1, y1], "quant": qt.json(),
        "robots": {"radius_m": [float(r) for r in radius], "group": [str(g) for g in group], "colour": _colours(N)},
        "map": map_meta, "layers": layers_meta, "scans": scans_meta, "events": events,
        "arrays": pack.index,
    }
    payload = pack.encoded(compress_level)
    page = _TEMPLATE.read_text(encoding="utf-8")
    # every string from the run folder goes in escaped: the title as HTML text, the metadata as
    # JSON that cannot close its <script> element (the page puts strings into the DOM escaped)
    fill = {"TITLE": html.escape(meta["title"]), "META": _script_json(meta), "DATA": payload,
            "CSP": html.escape(_script_csp(page))}
    page = re.sub(r"\{\{(TITLE|META|DATA|CSP)\}\}", lambda m: fill[m.group(1)], page)  # one pass: data never re-scanned
    with atomic_output(out, "HTML file", "--out", run_dir=run_dir, wait=wait, command="teamnav replay") as tmp:  # nothing half-written, even on /proc or a full disk
        tmp.write_text(page, encoding="utf-8")
    names = ["map", "true", "trails", "belief"] + (["scans"] if scans_meta else []) + [m["name"] for m in layers_meta]
    names += ["events"] if events else []
    return ReplayStats(path=out, n_frames=F, every=every, n_robots=N, bytes=out.stat().st_size, layers=tuple(names))


def _decode(html_text: str) -> tuple[dict, dict[str, Any]]:
    """Read back the metadata and the arrays (quantised, delta-coded) of a replay page (for tests)."""
    start = html_text.index('id="teamnav-meta">') + len('id="teamnav-meta">')
    meta = json.loads(html_text[start: html_text.index("</script>", start)])
    start = html_text.index('id="teamnav-data">') + len('id="teamnav-data">')
    raw = zlib.decompress(base64.b64decode(html_text[start: html_text.index("</script>", start)].strip()))
    dt = {"i8": np.int8, "u8": np.uint8, "i16": np.int16, "u16": np.uint16, "i32": np.int32, "f32": np.float32,
          "f64": np.float64}
    arrays = {name: np.frombuffer(raw, dt[t], count=n, offset=off).reshape(shape)
              for name, (t, off, n, shape) in meta["arrays"].items()}
    return meta, arrays
