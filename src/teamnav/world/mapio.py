"""Map files: ROS map_server YAML + image, plain PNG/PGM/BMP images, and a material layer.

teamnav reads and writes maps in the format of ROS 2's ``nav2_map_server``
(``nav2_map_server/src/map_io.cpp``, ``loadMapYaml`` and ``loadMapFromFile``): every map that
nav2's map_server loads, teamnav loads the same way, cell for cell (``tests/test_mapio.py``
holds nav2's own loader test cases). A map is a YAML file next to an image::

    image: depot.pgm          # relative to the YAML file's folder (or absolute)
    resolution: 0.05          # metres per pixel, positive
    origin: [0.0, 0.0, 0.0]   # x [m], y [m], yaw [rad] of the lower-left pixel (any yaw)
    negate: 0                 # 0/1 (any integer: non-zero is true) or false/true (default 0)
    occupied_thresh: 0.65     # in [0, 1]                        (default 0.65)
    free_thresh: 0.196        # in [0, 1], below occupied_thresh (default 0.196)
    mode: trinary             # trinary | scale | raw            (default trinary)

Keys the loader does not know (``map_type: occupancy``, written by common map tools) are
ignored, as map_server ignores them, with one warning line naming the file and the keys.
nav2 requires the two thresholds; teamnav takes map_saver's values when they are missing.

A yaw turns the map about its origin: the grid keeps its cells axis-aligned in its own local
frame and every consumer (ray casting, collisions, spawning, plots, replay, MCAP) goes
through :class:`~teamnav.world.grid.OccupancyGrid`'s world <-> cell transform.

teamnav extension (ignored by ROS, which skips unknown keys)::

    materials: depot_materials.png   # a second 8-bit greyscale image, same size as ``image``
    material_values: {3: glass, 4: foam}

Pixels of the material layer whose value is listed in ``material_values`` set that cell to
the named material (any name: ``glass``, ``foam`` and ``unknown`` are built in, new names
are appended to the grid's materials in increasing pixel value order; ``free`` carves free
space). Pixels with unlisted values (conventionally 0) keep what the occupancy image says.
The layer is applied after the occupancy image is thresholded.

Pixel rule (nav2 ``loadMapFromFile``, per pixel)
------------------------------------------------
1. The channels averaged are red, green and blue (a greyscale pixel is its grey value three
   times); in *trinary* mode an image with an alpha channel averages the alpha in as a fourth
   channel (nav2's "preserve existing behaviour" quirk; for grey + alpha that is
   ``(3 grey + alpha) / 4``). ``shade = average / max`` where ``max`` is 255 for 8-bit images
   and 65535 for 16-bit ones (16-bit greyscale PNG and PGM keep their precision; a PGM with
   another ``maxval`` is scaled to 8 or 16 bits on reading). Palette images are expanded to
   RGB(A), 1-bit images to 0/255 greyscale.
2. ``occ = shade`` if ``negate`` else ``1 - shade``.
3. *trinary*: occupied (100) if ``occupied_thresh < occ``, free (0) if ``occ < free_thresh``,
   unknown (-1) otherwise.
   *scale*: unknown (-1) where alpha is not opaque; else occupied / free as in trinary, and in
   between ``rint((occ - free_thresh) / (occupied_thresh - free_thresh) * 100)``.
4. *raw*: ``v = round(shade * 255)`` (``negate`` is not applied); ``v`` if ``0 <= v <= 100``,
   else unknown (-1).

ROS 1's ``map_server`` (``image_loader.cpp``) differs from nav2 only in modes scale and raw:
its scale band is ``1 + 99 * ratio`` truncated (never 0 or 100), and raw takes the negated
average truncated. teamnav follows nav2.

teamnav's grid has no graded occupancy, so the occupancy value is reduced to materials the
way ``amcl`` reads a map (``amcl_node.cpp``, ``convertMap``): exactly 0 is ``free``, exactly
100 is ``wall`` and every other value (-1 and the graded 1..99) is ``unknown``. In trinary
mode this is exactly the three-way threshold rule above; in scale mode the graded band
between the two thresholds becomes ``unknown`` (except where nav2's rounding gives 0 or 100);
in raw mode only pixel values 0 and 100 are free and wall.

The image's top row is the map's highest y, so the pixel array is flipped vertically
(row 0 of :attr:`OccupancyGrid.cells` is the bottom of the image).

A plain ``.png``/``.pgm``/``.bmp`` file (no YAML) is read with map_saver's thresholds
(``occupied_thresh=0.65``, ``free_thresh=0.196``, ``negate=0``, trinary) and needs
``resolution_m``.

Every malformed input raises :class:`MapError`, whose message names the file, the field,
what was expected and what was found. An image larger than :data:`MAX_MAP_CELLS` pixels is
refused from its header, before any pixel is decoded, with the memory it would need.
"""

from __future__ import annotations

import difflib
import logging
import math
import os
import tempfile
import threading
import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from PIL import Image, UnidentifiedImageError

from teamnav.files import file_mode
from teamnav.safe_yaml import YamlLimitError, safe_load, show_value
from teamnav.world.grid import DEFAULT_MATERIALS, MAX_MAP_CELLS, OccupancyGrid, check_map_size

_log = logging.getLogger(__name__)

__all__ = [
    "MapError",
    "MapMetadata",
    "load_map",
    "load_occupancy",
    "save_map",
    "read_map_yaml",
    "occupancy_values",
    "occupancy_to_cells",
    "DEFAULT_OCCUPIED_THRESH",
    "DEFAULT_FREE_THRESH",
    "IMAGE_SUFFIXES",
    "YAML_SUFFIXES",
]

#: map_server's customary thresholds (the values ``map_saver`` writes).
DEFAULT_OCCUPIED_THRESH: float = 0.65
DEFAULT_FREE_THRESH: float = 0.196
MODES: tuple[str, ...] = ("trinary", "scale", "raw")
YAML_SUFFIXES: tuple[str, ...] = (".yaml", ".yml")
IMAGE_SUFFIXES: tuple[str, ...] = (".png", ".pgm", ".bmp")
YAML_FIELDS: tuple[str, ...] = (
    "image",
    "resolution",
    "origin",
    "negate",
    "occupied_thresh",
    "free_thresh",
    "mode",
    "materials",
    "material_values",
)

#: Pixel values ``save_map`` writes (those of ROS ``map_saver``).
PIXEL_OCCUPIED: int = 0
PIXEL_UNKNOWN: int = 205
PIXEL_FREE: int = 254

#: occupancy values of ``nav_msgs/OccupancyGrid``
OCC_FREE: int = 0
OCC_OCCUPIED: int = 100
OCC_UNKNOWN: int = -1


class MapError(ValueError):
    """A map file is missing or malformed.

    Parameters
    ----------
    file : str or Path
        The file at fault.
    field : str
        The YAML field (or ``"image"``, ``"<file>"``, ``"<yaml>"`` for the file itself).
    expected : str
        What a valid value looks like.
    found : object
        What was found (shown with ``repr`` unless already a string description).

    Examples
    --------
    >>> str(MapError("m.yaml", "resolution", "a positive number", -1.0))
    "m.yaml: field 'resolution': expected a positive number, found -1.0"
    """

    def __init__(self, file: str | os.PathLike, field: str, expected: str, found: Any) -> None:
        self.file = str(file)
        self.field = field
        self.expected = expected
        self.found = found
        shown = found if isinstance(found, _Described) else show_value(found)  # bounded, however big
        super().__init__(f"{self.file}: field {field!r}: expected {expected}, found {shown}")


class _Described(str):
    """A description of what was found, printed without quotes."""


@dataclass(frozen=True)
class MapMetadata:
    """Validated contents of a map YAML file.

    Attributes
    ----------
    image : Path
        Occupancy image, resolved against the YAML file's folder.
    resolution_m : float
        Cell side [m], positive and finite.
    origin_xy_m : tuple of float
        World (x, y) [m] of the lower-left corner of the lower-left pixel.
    yaw_rad : float
        Rotation of the image's axes in the world [rad] (``origin[2]``).
    negate : bool
        Swap the meaning of black and white.
    occupied_thresh, free_thresh : float
        map_server thresholds on ``p`` in [0, 1], ``free_thresh < occupied_thresh``.
    mode : str
        ``"trinary"``, ``"scale"`` or ``"raw"``.
    materials_image : Path or None
        teamnav material layer, same size as ``image``.
    material_values : dict of int to str
        Pixel value of the material layer -> material name.
    """

    image: Path
    resolution_m: float
    origin_xy_m: tuple[float, float]
    negate: bool = False
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH
    free_thresh: float = DEFAULT_FREE_THRESH
    mode: str = "trinary"
    materials_image: Path | None = None
    material_values: dict[int, str] | None = None
    yaw_rad: float = 0.0
    #: keys of the YAML file that map_server and teamnav ignore (warned about once)
    ignored_keys: tuple[str, ...] = ()


# ---------------------------------------------------------------------------- public API
def load_map(
    path: str | os.PathLike,
    *,
    resolution_m: float | None = None,
    origin_xy_m: tuple[float, float] | None = None,
) -> OccupancyGrid:
    """Load a map file into an :class:`OccupancyGrid`.

    Parameters
    ----------
    path : str or Path
        ``.yaml``/``.yml`` (ROS map_server YAML, see the module docstring) or a plain
        ``.png``/``.pgm`` image.
    resolution_m : float, optional
        Cell side [m]. Required for a plain image; for a YAML file it replaces the file's
        ``resolution``.
    origin_xy_m : (float, float), optional
        World (x, y) [m] of the lower-left corner. Default (0, 0) for a plain image; for a
        YAML file it replaces the file's ``origin``.

    Returns
    -------
    OccupancyGrid
        ``cells`` of shape (image height, image width), row 0 = bottom of the image;
        ``name`` is the path.

    Raises
    ------
    MapError
        Missing file, unreadable image, wrong field type or value (see the module docstring).

    Examples
    --------
    >>> g = load_map("/work/shared/data/nav2/tb3_sandbox.yaml")  # doctest: +SKIP
    >>> g.shape, g.resolution_m, g.origin_xy_m  # doctest: +SKIP
    ((384, 384), 0.05, (-10.0, -10.0))
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if path.is_dir():
        raise MapError(path, "<file>", "a map file", _Described("a directory"))
    if suffix not in YAML_SUFFIXES + IMAGE_SUFFIXES:
        raise MapError(path, "<file>", f"a file ending in one of {YAML_SUFFIXES + IMAGE_SUFFIXES}", _Described(repr(path.suffix)))
    if not path.is_file():
        raise MapError(path, "<file>", "an existing map file", _Described("no such file"))
    if resolution_m is not None:
        resolution_m = _check_resolution(path, "resolution_m", resolution_m)
    if origin_xy_m is not None:
        origin_xy_m = _check_origin_xy(path, "origin_xy_m", origin_xy_m)

    if suffix in IMAGE_SUFFIXES:
        if resolution_m is None:
            raise MapError(path, "resolution_m", "a resolution in metres per pixel for a plain image (no YAML)", None)
        meta = MapMetadata(image=path, resolution_m=resolution_m, origin_xy_m=origin_xy_m or (0.0, 0.0))
    else:
        meta = read_map_yaml(path)
        if resolution_m is not None or origin_xy_m is not None:
            meta = dataclasses.replace(
                meta,
                resolution_m=meta.resolution_m if resolution_m is None else resolution_m,
                origin_xy_m=meta.origin_xy_m if origin_xy_m is None else origin_xy_m,
            )

    pixels = _read_image(meta.image, "image", source=path)
    values = occupancy_values(pixels, meta.negate, meta.occupied_thresh, meta.free_thresh, meta.mode)
    cells = occupancy_to_cells(values)
    materials = DEFAULT_MATERIALS
    if meta.materials_image is not None:
        cells, materials = _apply_material_layer(path, meta, cells)
    # image row 0 is the top (highest y); grid row 0 is the bottom
    cells = np.ascontiguousarray(cells[::-1])
    return OccupancyGrid(cells, meta.resolution_m, meta.origin_xy_m, materials, str(path), meta.yaw_rad)


def load_occupancy(path: str | os.PathLike) -> tuple[np.ndarray, MapMetadata]:
    """The ``nav_msgs/OccupancyGrid`` nav2's map_server would publish for a map YAML.

    Parameters
    ----------
    path : str or Path
        A map_server YAML file.

    Returns
    -------
    values : ndarray of shape (height, width), int8
        ``OccupancyGrid.data`` reshaped: row 0 is the image's bottom row (nav2 stores
        ``data[width * (height - y - 1) + x]`` for image row ``y``); 100 occupied, 0 free,
        -1 unknown, graded values in scale and raw modes.
    meta : MapMetadata
        The YAML's validated fields (resolution, origin, yaw, thresholds, mode, negate).

    Raises
    ------
    MapError
        As :func:`load_map`.
    """
    path = Path(path)
    if path.is_dir():
        raise MapError(path, "<file>", "a map YAML file", _Described("a directory"))
    meta = read_map_yaml(path)
    pixels = _read_image(meta.image, "image", source=path)
    values = occupancy_values(pixels, meta.negate, meta.occupied_thresh, meta.free_thresh, meta.mode)
    return np.ascontiguousarray(values[::-1]), meta


def read_map_yaml(path: str | os.PathLike) -> MapMetadata:
    """Read and validate a map_server YAML file (without reading the images).

    Parameters
    ----------
    path : str or Path
        The YAML file.

    Returns
    -------
    MapMetadata

    Raises
    ------
    MapError
        On a missing file, invalid YAML, a missing required field (``image``,
        ``resolution``, ``origin``), a value of the wrong type or range.

    Keys teamnav does not know are ignored, as map_server ignores them; one warning line
    (logger ``teamnav.world.mapio``) names the file and the keys, once per file per process.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MapError(path, "<file>", "an existing map YAML file", _Described("no such file")) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MapError(path, "<file>", "a readable UTF-8 YAML file", _Described(f"{type(exc).__name__}: {exc}")) from None
    try:
        doc = safe_load(text)  # safe constructors only; nesting, alias expansion, duplicate keys bounded
    except YamlLimitError as exc:
        raise MapError(path, exc.field or "<yaml>", "YAML within teamnav's limits", _Described(str(exc))) from None
    except yaml.YAMLError as exc:
        raise MapError(path, "<yaml>", "valid YAML", _Described(f"a syntax error: {str(exc).splitlines()[0]}")) from None
    except RecursionError:
        raise MapError(path, "<yaml>", "YAML nested at most 100 levels deep", _Described("a document nested too deeply")) from None
    if not isinstance(doc, dict):
        raise MapError(path, "<yaml>", "a mapping of map fields (image, resolution, origin, ...)", _Described(type(doc).__name__))
    ignored = tuple(str(key) for key in doc if key not in YAML_FIELDS)
    if ignored:
        _warn_ignored_keys(path, ignored)
    for key in ("image", "resolution", "origin"):
        if key not in doc:
            close = [k for k in ignored if difflib.get_close_matches(k, [key], n=1)]
            hint = f" (is {close[0]!r} a misspelling of it?)" if close else ""
            raise MapError(path, key, f"a required field{hint}", _Described("nothing (field missing)"))

    image = _check_relpath(path, "image", doc["image"])
    resolution = _check_resolution(path, "resolution", doc["resolution"])
    origin, yaw = _check_origin(path, doc["origin"])
    negate = _check_negate(path, doc.get("negate", 0))
    occ = _check_thresh(path, "occupied_thresh", doc.get("occupied_thresh", DEFAULT_OCCUPIED_THRESH))
    free = _check_thresh(path, "free_thresh", doc.get("free_thresh", DEFAULT_FREE_THRESH))
    if not occ > free:
        raise MapError(path, "occupied_thresh", f"a value greater than free_thresh={free!r}", occ)
    mode = doc.get("mode", "trinary")
    if not isinstance(mode, str) or mode not in MODES:
        raise MapError(path, "mode", f"one of {MODES}", mode)

    materials_image = None
    material_values = None
    if "materials" in doc or "material_values" in doc:
        if "materials" not in doc:
            raise MapError(path, "materials", "an image path when 'material_values' is given", _Described("nothing (field missing)"))
        if "material_values" not in doc:
            raise MapError(path, "material_values", "a mapping {pixel value: material name} when 'materials' is given", _Described("nothing (field missing)"))
        materials_image = _check_relpath(path, "materials", doc["materials"])
        material_values = _check_material_values(path, doc["material_values"])

    return MapMetadata(
        image=image,
        resolution_m=resolution,
        origin_xy_m=origin,
        negate=negate,
        occupied_thresh=occ,
        free_thresh=free,
        mode=mode,
        materials_image=materials_image,
        material_values=material_values,
        yaw_rad=yaw,
        ignored_keys=ignored,
    )


_WARNED: set[tuple[str, tuple[str, ...]]] = set()


def _warn_ignored_keys(path: Path, keys: tuple[str, ...]) -> None:
    """One warning line per (file, keys) per process: map_server ignores unknown keys too."""
    token = (str(path), keys)
    if token in _WARNED:
        return
    _WARNED.add(token)
    hints = []
    for k in keys:
        close = difflib.get_close_matches(k, YAML_FIELDS, n=1)
        hints.append(f"{k!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
    _log.warning("warning: %s: ignoring key%s %s, which map_server ignores too (known keys: %s)",
                 path, "s" if len(keys) > 1 else "", ", ".join(hints), ", ".join(YAML_FIELDS))


def occupancy_values(
    pixels: np.ndarray,
    negate: bool = False,
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH,
    free_thresh: float = DEFAULT_FREE_THRESH,
    mode: str = "trinary",
    max_value: int | None = None,
) -> np.ndarray:
    """map_server's per-pixel occupancy values (``nav_msgs/OccupancyGrid.data``).

    Implements nav2's ``loadMapFromFile`` (``nav2_map_server/src/map_io.cpp``) step by step,
    see the module docstring. The image is *not* flipped here.

    Parameters
    ----------
    pixels : ndarray of shape (H, W) or (H, W, C), uint8 or uint16
        Image; C = 2 (grey + alpha), 3 (RGB) or 4 (RGBA). The last channel of a 2- or
        4-channel image is alpha.
    negate : bool, default False
    occupied_thresh, free_thresh : float, defaults 0.65, 0.196
    mode : {"trinary", "scale", "raw"}, default "trinary"
    max_value : int, optional
        Full scale of a channel: 255 for uint8 pixels, 65535 for uint16 (the default).

    Returns
    -------
    ndarray of shape (H, W), int8
        100 occupied, 0 free, -1 unknown; scale mode also 1..99 (0 and 100 where nav2's
        rounding reaches them); raw mode 0..100 or -1.

    Examples
    --------
    >>> occupancy_values(np.array([[0, 205, 254]], np.uint8)).tolist()
    [[100, -1, 0]]
    >>> occupancy_values(np.array([[0, 100, 101, 255]], np.uint8), mode="raw").tolist()
    [[0, 100, -1, -1]]
    """
    if mode not in MODES:
        raise ValueError(f"mode must be one of {MODES}, got {mode!r}")
    px = np.asarray(pixels)
    if max_value is None:
        max_value = 65535 if px.dtype == np.uint16 else 255
    full = float(max_value)
    if px.ndim == 2:
        px = px[..., None]
    n_channels = px.shape[-1]
    has_alpha = n_channels in (2, 4)
    colour = px[..., : n_channels - 1 if has_alpha else n_channels].astype(np.float64)
    # nav2 reads red, green and blue quantums: a grey pixel counts three times
    total = colour.sum(axis=-1) * (3.0 if colour.shape[-1] == 1 else 1.0)
    count = 3
    if mode == "trinary" and has_alpha:
        # "To preserve existing behavior, average in alpha with color channels in Trinary mode."
        total = total + px[..., -1].astype(np.float64)
        count = 4
    shade = (total / count) / full  # Magick::ColorGray::scaleQuantumToDouble(sum / n)
    if mode == "raw":
        occ_percent = np.floor(shade * 255.0 + 0.5)  # std::round: halves away from zero
        out = np.full(shade.shape, OCC_UNKNOWN, dtype=np.int8)
        ok = (occ_percent >= OCC_FREE) & (occ_percent <= OCC_OCCUPIED)
        out[ok] = occ_percent[ok].astype(np.int8)
        return out
    occ = shade if negate else 1.0 - shade
    out = np.full(occ.shape, OCC_UNKNOWN, dtype=np.int8)
    if mode == "scale":
        opaque = (px[..., -1] == max_value) if has_alpha else np.ones(occ.shape, dtype=bool)
        band = opaque & (occ <= occupied_thresh) & (occ >= free_thresh)
        ratio = (occ[band] - free_thresh) / (occupied_thresh - free_thresh)
        out[band] = np.rint(ratio * 100.0).astype(np.int8)  # std::rint, round half to even
        out[opaque & (occ > occupied_thresh)] = OCC_OCCUPIED
        out[opaque & (occ < free_thresh)] = OCC_FREE
        return out
    out[occ > occupied_thresh] = OCC_OCCUPIED
    out[occ < free_thresh] = OCC_FREE
    return out


def occupancy_to_cells(values: np.ndarray) -> np.ndarray:
    """Reduce occupancy values to material ids as ``amcl`` reads a map.

    Parameters
    ----------
    values : ndarray of int8
        ``nav_msgs/OccupancyGrid`` values.

    Returns
    -------
    ndarray of uint8, same shape
        ``free`` (0) where the value is 0, ``wall`` (1) where it is 100, ``unknown`` (2)
        elsewhere (amcl ``convertMap``: 0 free, 100 occupied, anything else unknown).

    Examples
    --------
    >>> occupancy_to_cells(np.array([0, 100, -1, 50], np.int8)).tolist()
    [0, 1, 2, 2]
    """
    values = np.asarray(values)
    cells = np.full(values.shape, DEFAULT_MATERIALS.index("unknown"), dtype=np.uint8)
    cells[values == OCC_FREE] = DEFAULT_MATERIALS.index("free")
    cells[values == OCC_OCCUPIED] = DEFAULT_MATERIALS.index("wall")
    return cells


def save_map(
    grid: OccupancyGrid,
    yaml_path: str | os.PathLike,
    *,
    occupied_thresh: float = DEFAULT_OCCUPIED_THRESH,
    free_thresh: float = DEFAULT_FREE_THRESH,
) -> Path:
    """Write ``grid`` as a map_server YAML + PGM (+ a material layer PGM if needed).

    The YAML holds the grid's origin *and yaw* and the given thresholds (pass those a map was
    read with to write them back as read). The occupancy image (``<stem>.pgm``) uses
    ``map_saver``'s pixel values, 254 free, 205 unknown, 0 for every other material (a ROS
    consumer sees glass and foam as obstacles, as a robot bumps into them), except where the
    thresholds would read one of them otherwise: then the nearest pixel value that reads back
    as that class is used (a ``MapError`` if the thresholds leave none). Cells whose material is neither ``free``,
    ``wall`` nor ``unknown`` also go to ``<stem>_materials.pgm``, pixel value = material id,
    with ``material_values`` naming every id >= 3 of ``grid.materials``. All files are
    written to temporary names in the target folder and moved in place with
    :func:`os.replace`, the YAML last, so a reader never sees a half-written map.

    ``load_map(save_map(g, p))`` gives the same cells as ``g`` (and the same materials
    tuple when ``g.materials`` starts with :data:`DEFAULT_MATERIALS`), resolution and origin.

    Parameters
    ----------
    grid : OccupancyGrid
    yaml_path : str or Path
        Target ``.yaml``/``.yml`` path; images go next to it.

    Returns
    -------
    Path
        ``yaml_path``.

    Examples
    --------
    >>> import tempfile, os
    >>> g = OccupancyGrid(np.array([[0, 1], [2, 3]], np.uint8), 0.1)
    >>> d = tempfile.mkdtemp()
    >>> g2 = load_map(save_map(g, os.path.join(d, "m.yaml")))
    >>> g2.cells.tolist(), g2.resolution_m
    ([[0, 1], [2, 3]], 0.1)
    """
    yaml_path = Path(yaml_path)
    if yaml_path.suffix.lower() not in YAML_SUFFIXES:
        raise MapError(yaml_path, "<file>", f"a path ending in one of {YAML_SUFFIXES}", _Described(repr(yaml_path.suffix)))
    if not isinstance(grid, OccupancyGrid):
        raise TypeError(f"save_map: grid must be an OccupancyGrid, got {type(grid).__name__}")
    occupied_thresh = _check_thresh(yaml_path, "occupied_thresh", occupied_thresh)
    free_thresh = _check_thresh(yaml_path, "free_thresh", free_thresh)
    if not occupied_thresh > free_thresh:
        raise MapError(yaml_path, "occupied_thresh", f"a value greater than free_thresh={free_thresh!r}", occupied_thresh)
    px_free, px_unknown, px_occupied = _pixels_for(yaml_path, occupied_thresh, free_thresh)
    folder = yaml_path.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise MapError(yaml_path, "<file>", "a path in a folder that can be created and written",
                       _Described(f"{type(exc).__name__}: {exc.strerror or exc}")) from None
    # per material id, then one lookup per cell (not a string per cell: 0.2 s on 1200 x 1200)
    lut = np.array([px_free if m == "free" else px_unknown if m == "unknown" else px_occupied for m in grid.materials],
                   dtype=np.uint8)
    is_special = np.array([m not in ("free", "wall", "unknown") for m in grid.materials], dtype=bool)
    image = lut[grid.cells]
    special = is_special[grid.cells]

    image_name = yaml_path.stem + ".pgm"
    doc: dict[str, Any] = {
        "image": image_name,
        "mode": "trinary",
        "resolution": float(grid.resolution_m),
        "origin": [float(grid.origin_xy_m[0]), float(grid.origin_xy_m[1]), float(grid.yaw_rad)],
        "negate": 0,
        "occupied_thresh": occupied_thresh,
        "free_thresh": free_thresh,
    }
    files: list[tuple[Path, Any]] = [(folder / image_name, image[::-1])]
    if special.any():
        layer = np.where(special, grid.cells, 0).astype(np.uint8)
        layer_name = yaml_path.stem + "_materials.pgm"
        doc["materials"] = layer_name
        doc["material_values"] = {
            k: name for k, name in enumerate(grid.materials) if name not in ("free", "wall", "unknown")
        }
        files.append((folder / layer_name, layer[::-1]))
    files.append((yaml_path, yaml.safe_dump(doc, sort_keys=False)))

    temps: list[tuple[str, Path]] = []
    mode = file_mode()
    try:
        for target, content in files:
            fd, tmp = tempfile.mkstemp(prefix="." + target.name + ".", suffix=".tmp" + target.suffix, dir=folder)
            os.close(fd)
            temps.append((tmp, target))
            os.chmod(tmp, mode)  # the user's umask, as any tool's files (mkstemp makes 0600)
            if isinstance(content, str):
                Path(tmp).write_text(content, encoding="utf-8")
            else:
                Image.fromarray(np.ascontiguousarray(content), mode="L").save(tmp, format="PPM")
        for tmp, target in temps:
            os.replace(tmp, target)
    except OSError as exc:
        raise MapError(yaml_path, "<file>", "a path in a folder that can be written",
                       _Described(f"{type(exc).__name__}: {exc.strerror or exc}")) from None
    finally:
        for tmp, _ in temps:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return yaml_path


# ---------------------------------------------------------------------------- helpers
def _pixels_for(path: Path, occupied_thresh: float, free_thresh: float) -> tuple[int, int, int]:
    """8-bit pixel values (free, unknown, occupied) that nav2's trinary rule reads back as
    free, unknown and occupied under these thresholds: map_saver's 254 / 205 / 0 where they
    do, else the nearest value that does."""
    values = occupancy_values(np.arange(256, dtype=np.uint8)[None, :], False, occupied_thresh, free_thresh)[0]
    out = []
    for want, preferred, what in ((OCC_FREE, PIXEL_FREE, "free"), (OCC_UNKNOWN, PIXEL_UNKNOWN, "unknown"),
                                  (OCC_OCCUPIED, PIXEL_OCCUPIED, "occupied")):
        ok = np.flatnonzero(values == want)
        if ok.size == 0:
            raise MapError(path, "occupied_thresh", f"thresholds under which some 8-bit pixel reads as {what}",
                           _Described(f"occupied_thresh={occupied_thresh!r}, free_thresh={free_thresh!r}"))
        out.append(int(ok[np.argmin(np.abs(ok - preferred))]))
    return out[0], out[1], out[2]


def _read_image(image_path: Path, field: str, *, source: Path) -> np.ndarray:
    """Pixels of ``image_path`` as uint8 or uint16 (H, W) or (H, W, C); errors name ``source``'s ``field``.

    The size is read from the header and checked against :data:`MAX_MAP_CELLS` before any
    pixel is decoded (a hostile header cannot make teamnav allocate the image).
    """
    where = source if source == image_path else f"{source} -> {image_path}"
    if image_path.is_dir():
        raise MapError(where, field, "an image file", _Described("a directory"))
    if not image_path.is_file():
        raise MapError(where, field, "an existing image file", _Described("no such file"))
    try:
        with _open_header_only(image_path) as im:
            w, h = im.size
            try:
                check_map_size(w, h, f"an image of {w} x {h} px")
            except ValueError as exc:
                raise MapError(where, field, f"an image of at most {MAX_MAP_CELLS:,} pixels", _Described(str(exc))) from None
            im.load()
            if im.mode == "P":
                im = im.convert("RGBA" if "transparency" in im.info else "RGB")
            elif im.mode == "1":
                im = im.convert("L")
            elif im.mode == "PA":
                im = im.convert("RGBA")
            if im.mode in ("I;16", "I;16B", "I;16L", "I"):
                # 16-bit greyscale (PNG, PGM with maxval > 255): keep the precision, as nav2 does
                wide = np.array(im, dtype=np.int64)
                if wide.size and (wide.min() < 0 or wide.max() > 65535):
                    raise MapError(where, field, "16-bit greyscale values in 0..65535",
                                   _Described(f"values in {wide.min()}..{wide.max()}"))
                pixels = wide.astype(np.uint16)
            elif im.mode in ("L", "LA", "RGB", "RGBA"):
                pixels = np.array(im, dtype=np.uint8)
            else:
                raise MapError(where, field, "an 8- or 16-bit greyscale, grey+alpha, RGB or RGBA image",
                               _Described(f"image mode {im.mode!r}"))
    except MapError:
        raise
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError, EOFError, Image.DecompressionBombError) as exc:
        raise MapError(where, field, "a readable PNG, PGM or BMP image", _Described(f"{type(exc).__name__}: {exc}")) from None
    if pixels.ndim < 2 or pixels.shape[0] < 1 or pixels.shape[1] < 1:
        raise MapError(where, field, "a non-empty image", _Described(f"shape {pixels.shape}"))
    return pixels


_PIL_LIMIT_LOCK = threading.Lock()


def _open_header_only(image_path: Path) -> Image.Image:
    """``Image.open`` (which reads only the header) without PIL's own decompression-bomb
    refusal, so that the caller can refuse an oversized image with teamnav's figure and limit
    (:data:`MAX_MAP_CELLS`, below PIL's)."""
    with _PIL_LIMIT_LOCK:
        saved = Image.MAX_IMAGE_PIXELS
        Image.MAX_IMAGE_PIXELS = None
        try:
            return Image.open(image_path)
        finally:
            Image.MAX_IMAGE_PIXELS = saved


def _apply_material_layer(path: Path, meta: MapMetadata, cells: np.ndarray) -> tuple[np.ndarray, tuple[str, ...]]:
    assert meta.materials_image is not None and meta.material_values is not None
    layer = _read_image(meta.materials_image, "materials", source=path)
    if layer.dtype != np.uint8:
        raise MapError(path, "materials", "an 8-bit greyscale image", _Described("a 16-bit image"))
    if layer.ndim != 2:
        raise MapError(path, "materials", "a single-channel 8-bit greyscale image", _Described(f"an image with {layer.shape[2]} channels"))
    if layer.shape != cells.shape:
        raise MapError(path, "materials", f"an image of the same size as 'image' ({cells.shape[1]}x{cells.shape[0]} px)", _Described(f"{layer.shape[1]}x{layer.shape[0]} px"))
    materials = list(DEFAULT_MATERIALS)
    for value in sorted(meta.material_values):
        name = meta.material_values[value]
        if name not in materials:
            materials.append(name)
    if len(materials) > 256:
        raise MapError(path, "material_values", "at most 256 materials in all", len(materials))
    out = cells.copy()
    for value, name in meta.material_values.items():
        out[layer == value] = materials.index(name)
    return out, tuple(materials)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _check_resolution(path: Path, field: str, v: Any) -> float:
    if not _is_number(v) or not math.isfinite(v) or v <= 0:
        raise MapError(path, field, "a positive finite number of metres per pixel", v)
    return float(v)


def _check_origin_xy(path: Path, field: str, v: Any) -> tuple[float, float]:
    if (
        not isinstance(v, (list, tuple))
        or len(v) != 2
        or not all(_is_number(x) and math.isfinite(x) for x in v)
    ):
        raise MapError(path, field, "a pair of finite numbers (x, y) in metres", v)
    return (float(v[0]), float(v[1]))


def _check_origin(path: Path, v: Any) -> tuple[tuple[float, float], float]:
    if (
        not isinstance(v, list)
        or len(v) != 3
        or not all(_is_number(x) and math.isfinite(x) for x in v)
    ):
        raise MapError(path, "origin", "a list of three finite numbers [x_m, y_m, yaw_rad]", v)
    return (float(v[0]), float(v[1])), float(v[2])


def _check_negate(path: Path, v: Any) -> bool:
    # nav2 reads negate as an int, else as a bool: any integer, non-zero meaning true
    if isinstance(v, (bool, int)):
        return bool(v)
    raise MapError(path, "negate", "0, 1, true or false", v)


def _check_thresh(path: Path, field: str, v: Any) -> float:
    if not _is_number(v) or not math.isfinite(v) or not 0.0 <= v <= 1.0:
        raise MapError(path, field, "a number in [0, 1]", v)
    return float(v)


def _check_relpath(path: Path, field: str, v: Any) -> Path:
    if not isinstance(v, str) or not v.strip():
        raise MapError(path, field, "an image file name (relative to the YAML's folder, or absolute)", v)
    p = Path(v)
    return p if p.is_absolute() else path.parent / p


def _check_material_values(path: Path, v: Any) -> dict[int, str]:
    if not isinstance(v, dict) or not v:
        raise MapError(path, "material_values", "a non-empty mapping {pixel value 0..255: material name}", v)
    out: dict[int, str] = {}
    for key, name in v.items():
        if isinstance(key, bool) or not isinstance(key, int) or not 0 <= key <= 255:
            raise MapError(path, "material_values", "pixel values that are integers in 0..255", key)
        if not isinstance(name, str) or not name:
            raise MapError(path, f"material_values[{key}]", "a material name (non-empty string)", name)
        out[key] = name
    return out
