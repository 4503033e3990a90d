"""Figures of a paper report: draw a ``Plot`` or a ``MapView`` (``experiments.report.model``)
to PNG bytes with matplotlib's Agg backend (STYLE habit 15: only ``viz`` imports matplotlib).

A ``Plot`` holds curves as data: each :class:`~teamnav.experiments.report.model.Series` is
drawn by its ``style`` ("line", "points", "line+points", "bar", "step") with its ``lo``..``hi``
band as a shaded area (lines, steps) or error bars (points, bars). ``x`` values may be numbers
or category labels (strings; then the categories are spaced evenly in first-seen order, and
several bar series stand side by side). NaN values leave gaps. ``hlines`` are dashed reference
lines with their labels in the legend; ``logy`` plots y on a log scale.

A ``MapView`` draws the occupancy grid (same colours as :mod:`teamnav.viz.plots`), each point
cloud as small dots and each marker as a labelled cross.

Examples
--------
>>> from teamnav.experiments.report.model import Plot, Series
>>> png = plot_png(Plot("t", "x", "y", [Series("a", [0, 1, 2], [1, 2, 1.5], lo=[0.5, 1.5, 1], hi=[1.5, 2.5, 2])]))
>>> png[:8] == b"\\x89PNG\\r\\n\\x1a\\n"
True
"""

from __future__ import annotations

import io
import math
from typing import Any, Sequence

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

__all__ = ["SERIES_STYLES", "mapview_png", "plot_png"]

#: the ``Series.style`` values this module draws
SERIES_STYLES = ("line", "points", "line+points", "bar", "step")

_DPI = 110


def _floats(values: Sequence[Any] | None, what: str) -> np.ndarray | None:
    if values is None:
        return None
    try:
        return np.array([np.nan if v is None else float(v) for v in values], dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected numbers (or None for a gap), received {list(values)[:5]!r}") from None


def _is_category(v: Any) -> bool:
    return isinstance(v, str)


def _x_positions(series: Sequence[Any]) -> tuple[list[np.ndarray], list[str] | None]:
    """Numeric x per series, and the category labels when any x is a string."""
    if any(_is_category(v) for s in series for v in s.x):
        cats: list[str] = []
        for s in series:
            for v in s.x:
                if str(v) not in cats:
                    cats.append(str(v))
        return [np.array([cats.index(str(v)) for v in s.x], dtype=float) for s in series], cats
    return [_floats(s.x, f"series {s.label!r}: x") for s in series], None


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI, bbox_inches="tight")
    plt.close(fig)
    return buf.getvalue()


def plot_png(plot: Any, *, size_in: tuple[float, float] = (6.4, 3.9)) -> bytes:
    """Draw a ``Plot`` to PNG bytes.

    Parameters
    ----------
    plot : teamnav.experiments.report.model.Plot
    size_in : (float, float)
        Figure width and height [inch].

    Returns
    -------
    bytes
        A PNG file.

    Raises
    ------
    ValueError
        A series whose x, y, lo, hi lengths differ, an unknown style, or non-numeric y.
    """
    series = list(plot.series)
    for s in series:
        if s.style not in SERIES_STYLES:
            raise ValueError(f"series {s.label!r}: style expected one of {', '.join(SERIES_STYLES)}, received {s.style!r}")
        n = len(s.x)
        for name in ("y", "lo", "hi"):
            v = getattr(s, name)
            if v is not None and len(v) != n:
                raise ValueError(f"series {s.label!r}: {name} has {len(v)} values; expected {n} (one per x)")
    xs, cats = _x_positions(series)
    n_bars = sum(s.style == "bar" for s in series)
    if cats is not None:
        bar_w = 0.8 / max(n_bars, 1)
    else:
        steps = [np.diff(np.unique(x[np.isfinite(x)])) for x, s in zip(xs, series) if s.style == "bar"]
        steps = [d.min() for d in steps if d.size]
        bar_w = 0.8 * (min(steps) if steps else 1.0) / max(n_bars, 1)
    fig, ax = plt.subplots(figsize=size_in)
    colours = plt.get_cmap("tab10")
    k_bar = 0
    for i, (s, x) in enumerate(zip(series, xs)):
        colour = colours(i % 10)
        y = _floats(s.y, f"series {s.label!r}: y")
        lo = _floats(s.lo, f"series {s.label!r}: lo")
        hi = _floats(s.hi, f"series {s.label!r}: hi")
        band = lo is not None and hi is not None
        if s.style == "bar":
            offset = (k_bar - (n_bars - 1) / 2) * bar_w
            k_bar += 1
            yerr = np.abs(np.vstack([y - lo, hi - y])) if band else None
            ax.bar(x + offset, y, width=bar_w, color=colour, alpha=0.85, label=s.label, yerr=yerr, capsize=3, ecolor="#333333")
            continue
        if s.style == "points":
            if band:
                ax.errorbar(x, y, yerr=np.abs(np.vstack([y - lo, hi - y])), fmt="o", color=colour, capsize=3, label=s.label)
            else:
                ax.plot(x, y, "o", color=colour, label=s.label)
            continue
        drawstyle = "steps-post" if s.style == "step" else "default"
        marker = "o" if s.style == "line+points" else None
        ax.plot(x, y, color=colour, drawstyle=drawstyle, marker=marker, markersize=4, label=s.label)
        if band:
            step = "post" if s.style == "step" else None
            ax.fill_between(x, lo, hi, color=colour, alpha=0.22, linewidth=0, step=step)
    for j, (yv, label) in enumerate(plot.hlines):
        ax.axhline(float(yv), color="#555555", linestyle=("--", ":", "-.")[j % 3], linewidth=1.0, label=label)
    if cats is not None:
        ax.set_xticks(range(len(cats)))
        ax.set_xticklabels(cats, rotation=0 if sum(len(c) for c in cats) < 60 else 30, ha="center" if sum(len(c) for c in cats) < 60 else "right")
    if plot.logy:
        ax.set_yscale("log")
    ax.set_title(plot.title)
    ax.set_xlabel(plot.xlabel)
    ax.set_ylabel(plot.ylabel)
    ax.grid(True, alpha=0.3)
    if series or plot.hlines:
        ax.legend(fontsize="small", loc="best")
    return _png(fig)


def mapview_png(view: Any, *, size_in: float = 6.0, max_points: int = 20000) -> bytes:
    """Draw a ``MapView`` (map, point clouds, markers) to PNG bytes.

    Parameters
    ----------
    view : teamnav.experiments.report.model.MapView
        ``grid`` may be None (then only points and markers, on equal axes) or an
        EnvironmentMap (its ``grid`` is drawn).
    size_in : float
        The longer side of the figure [inch].
    max_points : int
        At most this many points per cloud are drawn (an even subsample of the rest).

    Returns
    -------
    bytes
        A PNG file.

    Raises
    ------
    ValueError
        A point cloud that is not of shape (n, 2) or more columns.
    """
    grid = view.grid
    if grid is not None and not hasattr(grid, "bounds_m") and hasattr(grid, "grid"):
        grid = grid.grid  # an EnvironmentMap (builtin_map(...)) instead of its OccupancyGrid
    if grid is not None:
        xmin, xmax, ymin, ymax = grid.bounds_m
        w, h = max(xmax - xmin, 1e-6), max(ymax - ymin, 1e-6)
        aspect = h / w
    else:
        aspect = 1.0
    figsize = (size_in, max(2.0, min(size_in * aspect, 2 * size_in))) if aspect <= 1 else (max(2.0, size_in / aspect) + 1.0, size_in)
    fig, ax = plt.subplots(figsize=figsize)
    if grid is not None:
        from teamnav.viz.plots import _draw_map

        _draw_map(ax, grid)
    ax.set_aspect("equal")
    colours = plt.get_cmap("tab10")
    for i, (label, pts) in enumerate(view.points):
        arr = np.asarray(pts, dtype=float)
        if arr.size == 0:
            arr = arr.reshape(0, 2)
        if arr.ndim != 2 or arr.shape[1] < 2:
            raise ValueError(f"map view {view.title!r}: points {label!r} expected shape (n, 2), received {arr.shape}")
        if len(arr) > max_points:
            arr = arr[np.linspace(0, len(arr) - 1, max_points).astype(int)]
        size = 4.0 if len(arr) > 500 else 9.0
        ax.scatter(arr[:, 0], arr[:, 1], s=size, color=colours(i % 10), alpha=0.6, linewidths=0, label=f"{label} ({len(pts)})", zorder=3)
    for j, (label, x, y) in enumerate(view.markers):
        colour = colours((len(view.points) + j) % 10)
        ax.plot([x], [y], marker="X", markersize=10, color=colour, markeredgecolor="black", linestyle="none", label=label, zorder=5)
        if math.isfinite(float(x)) and math.isfinite(float(y)):
            ax.annotate(label, (x, y), xytext=(5, 5), textcoords="offset points", fontsize="small", zorder=6)
    ax.set_title(view.title)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    if len(view.points) or len(view.markers):
        ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    return _png(fig)
