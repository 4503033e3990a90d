"""Figures of a recorded run: the map, true trajectories, believed odometry and final poses.

Everything here reads recorded data only (STYLE habit 15): arrays, or a run folder written by
:func:`teamnav.experiments.runner.run` (``trajectories.npz`` with ``t_s``, ``true_pose``
(T, N, 3), ``odom_pose`` (T, N, 3); ``map.yaml``; optionally ``robots.json`` with the body
radii). Only this package imports matplotlib, always with the non-interactive Agg backend.

Colours of the map: free white, wall black, unknown grey, glass blue, foam orange, any other
material purple.
"""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection, PatchCollection  # noqa: E402
from matplotlib.colors import ListedColormap  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from matplotlib.transforms import Affine2D  # noqa: E402

from teamnav.world.grid import OccupancyGrid  # noqa: E402
from teamnav.world.mapio import load_map  # noqa: E402

__all__ = ["MATERIAL_COLOURS", "load_run_arrays", "odom_in_world", "plot_run", "plot_trajectories", "save_gif"]

#: RGB colour of each material name; unlisted materials are drawn purple.
MATERIAL_COLOURS: dict[str, str] = {
    "free": "#ffffff",
    "wall": "#000000",
    "unknown": "#9e9e9e",
    "glass": "#3b82f6",
    "foam": "#f59e0b",
}
_OTHER = "#8e44ad"
#: at most this many frames in a GIF; longer runs are decimated
MAX_GIF_FRAMES = 200


def _map_cmap(grid: OccupancyGrid) -> ListedColormap:
    return ListedColormap([MATERIAL_COLOURS.get(m, _OTHER) for m in grid.materials])


def _robot_colours(n: int) -> np.ndarray:
    cmap = plt.get_cmap("tab10" if n <= 10 else "tab20" if n <= 20 else "hsv")
    return np.array([cmap(i % cmap.N if n <= 20 else i / max(n, 1)) for i in range(n)])


def odom_in_world(true_pose: np.ndarray, odom_pose: np.ndarray) -> np.ndarray:
    """Odometry trajectories drawn in the world frame, anchored at each robot's first true pose.

    Parameters
    ----------
    true_pose, odom_pose : ndarray of shape (T, N, 3)

    Returns
    -------
    ndarray of shape (T, N, 3)
        ``T0 · O0⁻¹ · O_t`` per robot: where the robot believes it is, if it knew its start.
    """
    T0, O0 = true_pose[0], odom_pose[0]
    dx = odom_pose[..., 0] - O0[:, 0]
    dy = odom_pose[..., 1] - O0[:, 1]
    c0, s0 = np.cos(O0[:, 2]), np.sin(O0[:, 2])
    lx, ly = c0 * dx + s0 * dy, -s0 * dx + c0 * dy
    c, s = np.cos(T0[:, 2]), np.sin(T0[:, 2])
    out = np.empty_like(odom_pose, dtype=float)
    out[..., 0] = T0[:, 0] + c * lx - s * ly
    out[..., 1] = T0[:, 1] + s * lx + c * ly
    out[..., 2] = T0[:, 2] + odom_pose[..., 2] - O0[:, 2]
    return out


def _view_box(grid: OccupancyGrid, xy: np.ndarray, margin_m: float = 1.0) -> tuple[float, float, float, float]:
    """Bounds around the known (non-unknown) part of the map and the trajectories."""
    xmin, xmax, ymin, ymax = grid.bounds_m
    known = grid.cells != grid.materials.index("unknown") if "unknown" in grid.materials else np.ones(grid.shape, bool)
    rows, cols = np.nonzero(known)
    if rows.size and grid.rotated:
        x0, x1, y0, y1 = grid.block_bounds_m(rows.min(), rows.max(), cols.min(), cols.max())
        bx, by = [x0, x1], [y0, y1]
    elif rows.size:
        lo = grid.cell_centers(rows.min(), cols.min())
        hi = grid.cell_centers(rows.max(), cols.max())
        bx = [lo[0], hi[0]]
        by = [lo[1], hi[1]]
    else:
        bx, by = [xmin, xmax], [ymin, ymax]
    if xy.size:
        bx += [float(np.nanmin(xy[..., 0])), float(np.nanmax(xy[..., 0]))]
        by += [float(np.nanmin(xy[..., 1])), float(np.nanmax(xy[..., 1]))]
    return (max(xmin, min(bx) - margin_m), min(xmax, max(bx) + margin_m), max(ymin, min(by) - margin_m), min(ymax, max(by) + margin_m))


def _draw_map(ax, grid: OccupancyGrid) -> None:
    """The map's cells; a rotated map is drawn turned about its origin by its yaw."""
    ox, oy = grid.origin_xy_m
    w, h = grid.size_m
    image = ax.imshow(
        grid.cells,
        cmap=_map_cmap(grid),
        vmin=-0.5,
        vmax=len(grid.materials) - 0.5,
        origin="lower",
        extent=(ox, ox + w, oy, oy + h),
        interpolation="nearest",
    )
    if grid.rotated:
        image.set_transform(Affine2D().rotate_around(ox, oy, grid.yaw_rad) + ax.transData)
        xmin, xmax, ymin, ymax = grid.bounds_m
        ax.set_xlim(xmin, xmax)
        ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def _tight_layout_once(fig, **kwargs) -> None:
    """``fig.tight_layout(**kwargs)``, then no layout engine: matplotlib would otherwise keep a
    placeholder engine, and every ``savefig`` (every GIF frame) would draw the whole figure
    once more, map image included, before drawing it for real. The picture is the same."""
    fig.tight_layout(**kwargs)
    fig.set_layout_engine(None)


def _poses(ax, pose: np.ndarray, radius_m: np.ndarray, colours: np.ndarray) -> None:
    """Final poses as discs with a heading tick."""
    discs = [Circle((x, y), r) for (x, y, _), r in zip(pose, radius_m)]
    ax.add_collection(PatchCollection(discs, facecolors=colours, edgecolors="black", linewidths=0.5, alpha=0.9, zorder=4))
    tips = pose[:, :2] + radius_m[:, None] * np.stack([np.cos(pose[:, 2]), np.sin(pose[:, 2])], axis=1)
    ax.add_collection(LineCollection(np.stack([pose[:, :2], tips], axis=1), colors="black", linewidths=0.8, zorder=5))


def plot_trajectories(
    grid: OccupancyGrid,
    true_pose: np.ndarray,
    path: str | Path,
    *,
    odom_pose: np.ndarray | None = None,
    radius_m: np.ndarray | float = 0.2,
    title: str | None = None,
    dpi: int = 120,
) -> Path:
    """Save a PNG of the map, each robot's true trajectory, its odometry (dashed) and final pose.

    Parameters
    ----------
    grid : OccupancyGrid
    true_pose : ndarray of shape (T, N, 3)
        True poses [m, m, rad].
    path : str or Path
        Where to write the PNG.
    odom_pose : ndarray of shape (T, N, 3), optional
        Odometry poses in each robot's own frame, drawn dashed after anchoring at the first
        true pose (:func:`odom_in_world`); skipped for more than 20 robots.
    radius_m : float or ndarray of shape (N,)
        Body radii for the final-pose discs [m].
    title : str, optional
    dpi : int

    Returns
    -------
    Path
        ``path``.
    """
    true_pose = np.asarray(true_pose, dtype=float)
    if true_pose.ndim != 3 or true_pose.shape[2] != 3 or true_pose.shape[0] < 1:
        raise ValueError(f"true_pose must have shape (T >= 1, N, 3), got {true_pose.shape}")
    n = true_pose.shape[1]
    radius = np.broadcast_to(np.asarray(radius_m, dtype=float), (n,))
    colours = _robot_colours(n)
    box = _view_box(grid, true_pose[..., :2])
    w, h = box[1] - box[0], box[3] - box[2]
    fig_w = 8.0
    fig, ax = plt.subplots(figsize=(fig_w, max(3.0, min(12.0, fig_w * h / max(w, 1e-9)))))
    try:
        _draw_map(ax, grid)
        lw = 1.2 if n <= 20 else 0.5
        ax.add_collection(LineCollection(list(true_pose[:, :, :2].transpose(1, 0, 2)), colors=colours, linewidths=lw, zorder=2))
        if odom_pose is not None and n <= 20:
            believed = odom_in_world(true_pose, np.asarray(odom_pose, dtype=float))
            ax.add_collection(
                LineCollection(list(believed[:, :, :2].transpose(1, 0, 2)), colors=colours, linewidths=0.8, linestyles="--", alpha=0.8, zorder=3)
            )
        _poses(ax, true_pose[-1], radius, colours)
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
        if title:
            ax.set_title(title)
        if odom_pose is not None and n <= 20:
            ax.plot([], [], "k-", lw=1.2, label="true path")
            ax.plot([], [], "k--", lw=0.8, label="odometry (anchored at start)")
            ax.legend(loc="best", fontsize=8, framealpha=0.8)
        _tight_layout_once(fig)
        path = Path(path)
        fig.savefig(path, dpi=dpi)
    finally:
        plt.close(fig)
    return path


# ---------------------------------------------------------------------------- run folders
def load_run_arrays(run_dir: str | Path) -> tuple[OccupancyGrid, dict[str, np.ndarray], np.ndarray]:
    """Read a run folder's map, trajectories and robot radii.

    Returns
    -------
    grid : OccupancyGrid
        From ``map.yaml``.
    arrays : dict of str to ndarray
        ``t_s`` (T,), ``true_pose`` (T, N, 3), ``odom_pose`` (T, N, 3).
    radius_m : ndarray of shape (N,)
        From ``robots.json`` (0.2 m each when absent).
    """
    run_dir = Path(run_dir)
    grid = load_map(run_dir / "map.yaml")
    with np.load(run_dir / "trajectories.npz", allow_pickle=False) as z:
        arrays = {k: np.asarray(z[k]) for k in ("t_s", "true_pose", "odom_pose") if k in z.files}
    n = arrays["true_pose"].shape[1]
    robots = run_dir / "robots.json"
    radius = np.asarray(json.loads(robots.read_text())["radius_m"], float) if robots.is_file() else np.full(n, 0.2)
    return grid, arrays, radius


def plot_run(run_dir: str | Path, path: str | Path | None = None, *, title: str | None = None) -> Path:
    """:func:`plot_trajectories` of a run folder, written to ``run_dir/trajectories.png`` by default."""
    run_dir = Path(run_dir)
    grid, arrays, radius = load_run_arrays(run_dir)
    return plot_trajectories(
        grid,
        arrays["true_pose"],
        path if path is not None else run_dir / "trajectories.png",
        odom_pose=arrays.get("odom_pose"),
        radius_m=radius,
        title=title,
    )


def save_gif(run_dir: str | Path, path: str | Path | None = None, *, fps: int = 15, trail: int = 30, dpi: int = 80) -> Path:
    """Animate a run folder into ``run_dir/run.gif`` (at most :data:`MAX_GIF_FRAMES` frames).

    Parameters
    ----------
    run_dir : str or Path
        A run folder (see the module docstring).
    path : str or Path, optional
        Output file, default ``run_dir/run.gif``.
    fps : int
        Frames per second of the GIF.
    trail : int
        Each robot drags its last ``trail`` frames' positions behind it.
    dpi : int

    Returns
    -------
    Path
    """
    from matplotlib.animation import PillowWriter

    run_dir = Path(run_dir)
    grid, arrays, radius = load_run_arrays(run_dir)
    pose, t_s = arrays["true_pose"], arrays["t_s"]
    frames = np.unique(np.linspace(0, pose.shape[0] - 1, min(MAX_GIF_FRAMES, pose.shape[0])).round().astype(int))
    n = pose.shape[1]
    colours = _robot_colours(n)
    box = _view_box(grid, pose[..., :2])
    w, h = box[1] - box[0], box[3] - box[2]
    fig, ax = plt.subplots(figsize=(6.0, max(2.5, min(9.0, 6.0 * h / max(w, 1e-9)))))
    try:
        _draw_map(ax, grid)
        ax.set_xlim(box[0], box[1])
        ax.set_ylim(box[2], box[3])
        ax.set_axis_off()  # tick labels would cost most of each frame's drawing time
        trails = LineCollection([], colors=colours, linewidths=0.8 if n <= 20 else 0.4, zorder=2)
        ax.add_collection(trails)
        # marker size in points^2 from the body radius in data units
        px_per_m = fig.get_figwidth() * dpi / max(w, 1e-9)
        size = (2 * radius * px_per_m * 72.0 / dpi) ** 2
        dots = ax.scatter(pose[0, :, 0], pose[0, :, 1], s=np.maximum(size, 4.0), c=colours, edgecolors="black", linewidths=0.3, zorder=4)
        label = ax.text(0.01, 0.99, "", transform=ax.transAxes, va="top", ha="left", fontsize=9,
                        bbox={"facecolor": "white", "alpha": 0.8, "edgecolor": "none"}, zorder=6)
        _tight_layout_once(fig, pad=0.2)
        out = Path(path) if path is not None else run_dir / "run.gif"
        writer = PillowWriter(fps=fps)
        # the writer loop directly (not FuncAnimation, which draws every frame twice)
        with writer.saving(fig, str(out), dpi):
            for k, i in enumerate(frames):
                lo = frames[max(0, k - trail)]
                trails.set_segments(list(pose[lo : i + 1, :, :2].transpose(1, 0, 2)))
                dots.set_offsets(pose[i, :, :2])
                label.set_text(f"t = {float(t_s[i]):.1f} s")
                writer.grab_frame()
    finally:
        plt.close(fig)
    return out
