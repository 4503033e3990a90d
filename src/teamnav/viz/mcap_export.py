"""Export a recorded run to MCAP with Foxglove's well-known schemas (opens in Foxglove as is).

:func:`export_mcap` reads a run folder only (see :mod:`teamnav.sim.recorder`) and writes,
through the official ``foxglove-sdk`` writer (protobuf encoding, zstd chunks), with message log
and header times equal to the simulated time (from the Unix epoch):

=============================  =========================  ==========================================
topic                          schema                     what
=============================  =========================  ==========================================
``/map``                       ``foxglove.Grid``          the true map, one message at t = 0, field
                                                          ``occupancy`` (uint8: 0 free, 100 blocking
                                                          material, 255 unknown), frame ``world``
``/tf``                        ``foxglove.FrameTransforms``  per recorded step, for every robot i:
                                                          ``world → robot_i/odom`` (``T_t · O_t⁻¹``:
                                                          the drift of its odometry frame) and
                                                          ``robot_i/odom → robot_i/base`` (``O_t``)
``/robot_i/pose``              ``foxglove.PoseInFrame``   true pose in ``world``, one per recorded step
``/robot_i/believed_pose``     ``foxglove.PoseInFrame``   odometry anchored at the start pose (as the
                                                          HTML replay and the figures draw it), ``world``
``/robot_i/scan/SENSOR``       ``foxglove.LaserScan``     one per recorded scan (``record_scans``),
                                                          frame ``robot_i/base``; sensors whose beams
                                                          are not evenly spaced go to ``/robot_i/rays/SENSOR``
                                                          as ``foxglove.SceneUpdate`` line lists
``/layers/NAME``               ``foxglove.SceneUpdate``   each recorder layer per step it has samples:
                                                          ``points`` as spheres, ``segments`` as line
                                                          lists, ``markers`` as arrows, ``state`` as text
                                                          over the robot; one entity per robot
                                                          (``NAME/i``), in ``world`` or the robot's
                                                          ``robot_i/odom`` frame (so odometric crumbs
                                                          move with the drift, as the robot believes
                                                          them); held layers stay until replaced
=============================  =========================  ==========================================
"""

from __future__ import annotations

import colorsys
import contextlib
import errno
import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import numpy as np

from teamnav.files import destination_problem, write_cause
from teamnav.viz.replay import odom_anchor, read_run
from teamnav.viz.run_folder import OutputPathError, atomic_output

__all__ = ["McapStats", "export_mcap"]


@dataclass(frozen=True)
class McapStats:
    """What :func:`export_mcap` wrote: ``path``, ``bytes``, ``messages``, ``channels`` and
    ``counts`` (messages per topic)."""

    path: Path
    bytes: int
    messages: int
    channels: int
    counts: dict


def _quat(yaw: float):
    from foxglove.messages import Quaternion

    return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0))


def _pose(x: float, y: float, yaw: float):
    from foxglove.messages import Pose, Vector3

    return Pose(position=Vector3(x=float(x), y=float(y), z=0.0), orientation=_quat(float(yaw)))


def _rgb(i: int, n: int):
    from foxglove.messages import Color

    if i < 0:
        return Color(r=0.1, g=0.1, b=0.1, a=1.0)
    r, g, b = colorsys.hsv_to_rgb((i * 0.618034) % 1.0 if n > 10 else i / max(n, 1), 0.75, 0.85)
    return Color(r=r, g=g, b=b, a=0.9)


def _uniform(angles: np.ndarray) -> bool:
    if angles.shape[0] < 2:
        return True
    d = np.diff(angles)
    return bool(np.allclose(d, d[0], atol=1e-6) and d[0] > 0)


@contextlib.contextmanager
def _writer_io_errors(tmp: str | os.PathLike) -> Iterator[None]:
    """The MCAP writer reports a failed write (a full disk) as a RuntimeError; make it the OSError
    :func:`~teamnav.viz.run_folder.atomic_output` turns into one line, naming the cause."""
    try:
        yield
    except RuntimeError as exc:
        if "I/O error" not in str(exc):
            raise
        raise OSError(errno.EIO, write_cause(exc, tmp)) from None


def export_mcap(run_dir: str | os.PathLike, path: str | os.PathLike, *, force: bool = False, wait: bool = False) -> McapStats:
    """Write ``path`` (an MCAP file) from the run folder ``run_dir`` (topics in the module docstring).

    Parameters
    ----------
    run_dir : str or Path
    path : str or Path
    force : bool, default False
        Replace ``path`` if it exists.
    wait : bool, default False
        When another process is writing ``path`` (it holds its claim: :func:`teamnav.files.claim`),
        wait for it instead of refusing.

    Returns
    -------
    McapStats

    Raises
    ------
    ValueError
        Not a run folder, or ``path`` exists and ``force`` is False, or cannot be written
        (:class:`~teamnav.viz.run_folder.OutputPathError`), or another process is writing it
        (:class:`~teamnav.files.ClaimError`).
    """
    import foxglove
    from foxglove.channels import FrameTransformsChannel, GridChannel, LaserScanChannel, PoseInFrameChannel, SceneUpdateChannel
    from foxglove.messages import (
        ArrowPrimitive,
        Duration,
        FrameTransform,
        FrameTransforms,
        Grid,
        LaserScan,
        LinePrimitive,
        LinePrimitiveLineType,
        PackedElementField,
        PackedElementFieldNumericType,
        Point3,
        PoseInFrame,
        SceneEntity,
        SceneUpdate,
        SpherePrimitive,
        TextPrimitive,
        Timestamp,
        Vector2,
        Vector3,
    )

    rec, grid, _robots = read_run(run_dir)
    path = Path(path)
    if path.is_dir():
        raise OutputPathError(f"MCAP file {path}: expected a file path, found a folder; choose another --mcap")
    problem = destination_problem(path, folder=False)
    if problem is not None:
        raise OutputPathError(f"MCAP file {path}: cannot be written ({problem}); choose another --mcap")
    if (path.exists() or path.is_symlink()) and not force:
        raise OutputPathError(f"MCAP file {str(path)!r} exists; choose another --mcap or pass --force")
    T, N = rec.true_pose.shape[:2]
    true = np.asarray(rec.true_pose, float)
    odom = np.asarray(rec.odom_pose, float)
    steps = np.asarray(rec.step, np.int64)
    t_ns = np.rint(np.asarray(rec.t_s, float) * 1e9).astype(np.int64)
    frame_dt_s = float(np.median(np.diff(rec.t_s))) if T > 1 else 0.1
    anchor = odom_anchor(true[0], odom[0])
    ca, sa = np.cos(anchor[:, 2]), np.sin(anchor[:, 2])
    belief = np.stack([ca * odom[..., 0] - sa * odom[..., 1] + anchor[:, 0],
                       sa * odom[..., 0] + ca * odom[..., 1] + anchor[:, 1], odom[..., 2] + anchor[:, 2]], axis=-1)
    # world -> odom_t = T_t · O_t^-1
    d = true[..., 2] - odom[..., 2]
    cd, sd = np.cos(d), np.sin(d)
    wo = np.stack([true[..., 0] - (cd * odom[..., 0] - sd * odom[..., 1]),
                   true[..., 1] - (sd * odom[..., 0] + cd * odom[..., 1]), d], axis=-1)

    def stamp(ns: int):
        return Timestamp(sec=int(ns // 1_000_000_000), nsec=int(ns % 1_000_000_000))

    counts: dict[str, int] = {}
    ctx = foxglove.Context()
    # written under a temporary name in the target folder, renamed once complete; a path that
    # cannot be written is an OutputPathError naming it, and nothing is left behind
    # (claimed: a second export into ``path`` refuses or waits; SIGTERM removes the temporary file)
    with atomic_output(path, "MCAP file", "--mcap", run_dir=run_dir, force=force, wait=wait, command="teamnav export") as tmp, \
            _writer_io_errors(tmp):
        with foxglove.open_mcap(tmp, allow_overwrite=True, context=ctx):
            def log(ch, msg, ns):
                ch.log(msg, log_time=int(ns))
                topic = ch.topic()
                counts[topic] = counts.get(topic, 0) + 1

            if grid is not None:
                ch = GridChannel("/map", context=ctx)
                blocking = grid.blocking(None)
                occ = np.where(blocking, 100, 0).astype(np.uint8)
                if "unknown" in grid.materials:
                    occ[grid.cells == grid.materials.index("unknown")] = 255
                h, w = occ.shape
                log(ch, Grid(timestamp=stamp(int(t_ns[0])), frame_id="world",
                             pose=_pose(grid.origin_xy_m[0], grid.origin_xy_m[1], grid.yaw_rad), column_count=int(w),
                             cell_size=Vector2(x=grid.resolution_m, y=grid.resolution_m), row_stride=int(w), cell_stride=1,
                             fields=[PackedElementField(name="occupancy", offset=0, type=PackedElementFieldNumericType.Uint8)],
                             data=occ.tobytes()), t_ns[0])

            tf = FrameTransformsChannel("/tf", context=ctx)
            pose_ch = [PoseInFrameChannel(f"/robot_{i}/pose", context=ctx) for i in range(N)]
            belief_ch = [PoseInFrameChannel(f"/robot_{i}/believed_pose", context=ctx) for i in range(N)]
            for k in range(T):
                ts = stamp(int(t_ns[k]))
                tfs = []
                for i in range(N):
                    tfs.append(FrameTransform(timestamp=ts, parent_frame_id="world", child_frame_id=f"robot_{i}/odom",
                                              translation=Vector3(x=float(wo[k, i, 0]), y=float(wo[k, i, 1]), z=0.0),
                                              rotation=_quat(float(wo[k, i, 2]))))
                    tfs.append(FrameTransform(timestamp=ts, parent_frame_id=f"robot_{i}/odom", child_frame_id=f"robot_{i}/base",
                                              translation=Vector3(x=float(odom[k, i, 0]), y=float(odom[k, i, 1]), z=0.0),
                                              rotation=_quat(float(odom[k, i, 2]))))
                log(tf, FrameTransforms(transforms=tfs), t_ns[k])
                for i in range(N):
                    log(pose_ch[i], PoseInFrame(timestamp=ts, frame_id="world", pose=_pose(*true[k, i])), t_ns[k])
                    log(belief_ch[i], PoseInFrame(timestamp=ts, frame_id="world", pose=_pose(*belief[k, i])), t_ns[k])

            for key, sc in sorted(rec.scans.items()):
                sensor = sc.sensor or key
                ang = np.asarray(sc.angles_rad, float)
                uniform = _uniform(ang)
                ts_ns = t_ns[np.clip(np.searchsorted(steps, sc.step), 0, T - 1)]
                for j, i in enumerate(sc.robots.tolist()):
                    frame = f"robot_{i}/base"
                    if uniform:
                        ch = LaserScanChannel(f"/robot_{i}/scan/{sensor}", context=ctx)
                        for s in range(sc.step.shape[0]):
                            log(ch, LaserScan(timestamp=stamp(int(ts_ns[s])), frame_id=frame, pose=_pose(0.0, 0.0, 0.0),
                                              start_angle=float(ang[0]), end_angle=float(ang[-1]),
                                              ranges=sc.ranges[s, j].astype(float).tolist()), ts_ns[s])
                    else:
                        ch = SceneUpdateChannel(f"/robot_{i}/rays/{sensor}", context=ctx)
                        for s in range(sc.step.shape[0]):
                            r = sc.ranges[s, j].astype(float)
                            pts = []
                            for a, rr in zip(ang, r):
                                pts += [Point3(x=0.0, y=0.0, z=0.0), Point3(x=rr * math.cos(a), y=rr * math.sin(a), z=0.0)]
                            ent = SceneEntity(timestamp=stamp(int(ts_ns[s])), frame_id=frame, id=f"{sensor}/{i}",
                                              lifetime=Duration.from_secs(frame_dt_s),
                                              lines=[LinePrimitive(type=LinePrimitiveLineType.LineList, thickness=0.01,
                                                                   points=pts, color=_rgb(i, N))])
                            log(ch, SceneUpdate(entities=[ent]), ts_ns[s])

            for name, lay in sorted(rec.layers.items()):
                ch = SceneUpdateChannel(f"/layers/{name}", context=ctx)
                lay_ns = t_ns[np.clip(np.searchsorted(steps, lay.step), 0, T - 1)]
                lifetime = None if lay.hold else Duration.from_secs(frame_dt_s)
                order = np.argsort(lay_ns, kind="stable")
                for s in order.tolist():
                    i = int(lay.robot[s])
                    rows = lay.rows(s).astype(float)
                    ts = stamp(int(lay_ns[s]))
                    frame = f"robot_{i}/odom" if lay.frame == "odom" and i >= 0 else "world"
                    colour = _rgb(i, N)
                    ent = dict(timestamp=ts, frame_id=frame, id=f"{name}/{i}", lifetime=lifetime)
                    if lay.kind == "points":
                        ent["spheres"] = [SpherePrimitive(pose=_pose(r[0], r[1], 0.0), size=Vector3(x=0.08, y=0.08, z=0.08),
                                                          color=colour) for r in rows]
                    elif lay.kind == "segments":
                        pts = []
                        for r in rows:
                            pts += [Point3(x=r[0], y=r[1], z=0.05), Point3(x=r[2], y=r[3], z=0.05)]
                        ent["lines"] = [LinePrimitive(type=LinePrimitiveLineType.LineList, thickness=0.03, points=pts,
                                                      color=colour)] if pts else []
                    elif lay.kind == "markers":
                        ent["arrows"] = [ArrowPrimitive(pose=_pose(r[0], r[1], r[2] if rows.shape[1] > 2 else 0.0),
                                                        shaft_length=0.3, shaft_diameter=0.06, head_length=0.15,
                                                        head_diameter=0.15, color=colour) for r in rows]
                    else:  # state: text over the robot's base
                        label = lay.labels[int(rows[0, 0])] if rows.shape[0] and int(rows[0, 0]) < len(lay.labels) else ""
                        ent["frame_id"] = f"robot_{i}/base" if i >= 0 else "world"
                        ent["texts"] = [TextPrimitive(pose=_pose(0.0, 0.0, 0.0), billboard=True, font_size=14.0,
                                                      scale_invariant=True, color=colour, text=label)]
                    log(ch, SceneUpdate(entities=[SceneEntity(**{k: v for k, v in ent.items() if v is not None})]), lay_ns[s])
    return McapStats(path=path, bytes=path.stat().st_size, messages=sum(counts.values()), channels=len(counts),
                     counts=dict(sorted(counts.items())))
