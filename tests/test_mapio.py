"""Map loading and saving: real ROS maps, map_server's pixel rule, round trips, errors."""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

import teamnav.world
from teamnav.world.grid import DEFAULT_MATERIALS, OccupancyGrid
from teamnav.world.mapio import MapError, load_map, load_occupancy, occupancy_values, read_map_yaml, save_map

# the real maps ship with the package (identical to /work/shared/data), so a clean checkout finds them
DATA = Path(teamnav.world.__file__).parent / "maps"
FREE, WALL, UNKNOWN, GLASS, FOAM = range(5)


def _pixels(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path))


# ---------------------------------------------------------------------------- real maps
@pytest.mark.parametrize(
    "yaml_name, image_name, shape, origin, free_values, unknown_values",
    [
        # basement: 0 occupied, 205 unknown (p = 50/255 > 0.196), 254/255 free
        ("mit/basement_hallways_5cm.yaml", "mit/basement_hallways_5cm.png", (1200, 1200), (0.0, 0.0), (254, 255), (205,)),
        # depot has free_thresh 0.25, so its grey 205 (p = 0.196) is *free* under map_server's rule
        ("nav2/depot.yaml", "nav2/depot.pgm", (307, 604), (0.0, 0.0), (205, 254), ()),
        ("nav2/tb3_sandbox.yaml", "nav2/tb3_sandbox.pgm", (384, 384), (-10.0, -10.0), (254,), (205,)),
    ],
)
def test_real_maps_load_with_expected_geometry_and_cell_counts(yaml_name, image_name, shape, origin, free_values, unknown_values):
    g = load_map(DATA / yaml_name)
    px = _pixels(DATA / image_name)
    assert g.shape == shape == px.shape
    assert g.resolution_m == pytest.approx(0.05)
    assert g.origin_xy_m == origin
    assert g.materials == DEFAULT_MATERIALS
    assert g.name == str(DATA / yaml_name)
    n_free = int(np.isin(px, free_values).sum())
    n_unknown = int(np.isin(px, unknown_values).sum())
    n_occ = int((px == 0).sum())
    assert n_free + n_unknown + n_occ == px.size  # every pixel value accounted for
    counts = np.bincount(g.cells.ravel(), minlength=3)
    assert counts[FREE] == n_free
    assert counts[UNKNOWN] == n_unknown
    assert counts[WALL] == n_occ
    # the image is flipped: grid row 0 is the bottom image row
    np.testing.assert_array_equal(g.cells[0] == WALL, px[-1] == 0)
    np.testing.assert_array_equal(g.cells[-1] == WALL, px[0] == 0)


def test_real_map_round_trips_through_save(tmp_path):
    g = load_map(DATA / "nav2" / "tb3_sandbox.yaml")
    out = save_map(g, tmp_path / "sandbox.yaml")
    g2 = load_map(out)
    np.testing.assert_array_equal(g2.cells, g.cells)
    assert g2.origin_xy_m == g.origin_xy_m and g2.resolution_m == g.resolution_m
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sandbox.pgm", "sandbox.yaml"]  # no temp files left


def test_plain_image_needs_resolution_and_uses_map_server_defaults(tmp_path):
    px = np.array([[0, 100, 205, 254]], np.uint8)  # p = 1, 0.61, 0.196, 0.004
    Image.fromarray(px).save(tmp_path / "m.png")
    with pytest.raises(MapError, match=r"m\.png.*'resolution_m'"):
        load_map(tmp_path / "m.png")
    g = load_map(tmp_path / "m.png", resolution_m=0.1, origin_xy_m=(1.0, -2.0))
    assert g.cells.tolist() == [[WALL, UNKNOWN, UNKNOWN, FREE]]
    assert g.origin_xy_m == (1.0, -2.0) and g.resolution_m == 0.1


def test_yaml_overrides(tmp_path):
    g = load_map(DATA / "nav2" / "tb3_sandbox.yaml", resolution_m=0.1, origin_xy_m=(0.0, 0.0))
    assert g.resolution_m == 0.1 and g.origin_xy_m == (0.0, 0.0)


# ---------------------------------------------------------------------------- pixel rule
def _reference(px: np.ndarray, negate: bool, occ_th: float, free_th: float, mode: str) -> np.ndarray:
    """nav2's loadMapFromFile + amcl's reading, per pixel, in Python loops (map_io.cpp).

    Magick gives red, green and blue quantums (a grey pixel's grey value three times); in
    trinary mode an image with alpha adds the alpha as a fourth channel.
    """
    full = 65535.0 if px.dtype == np.uint16 else 255.0
    h, w = px.shape[:2]
    out = np.empty((h, w), np.uint8)
    for i in range(h):
        for j in range(w):
            p = [int(v) for v in (px[i, j] if px.ndim == 3 else [px[i, j]])]
            has_alpha = len(p) in (2, 4)
            colour = p[:-1] if has_alpha else p
            channels = colour * 3 if len(colour) == 1 else colour
            alpha = p[-1] if has_alpha else int(full)
            if mode == "trinary" and has_alpha:
                channels = channels + [alpha]
            shade = (sum(channels) / len(channels)) / full
            occ = shade if negate else 1.0 - shade
            if mode == "trinary":
                v = 100 if occ_th < occ else 0 if occ < free_th else -1
            elif mode == "scale":
                if alpha != full:
                    v = -1
                elif occ_th < occ:
                    v = 100
                elif occ < free_th:
                    v = 0
                else:
                    v = int(np.rint((occ - free_th) / (occ_th - free_th) * 100.0))
            else:
                r = math.floor(shade * 255 + 0.5)
                v = r if 0 <= r <= 100 else -1
            out[i, j] = FREE if v == 0 else WALL if v == 100 else UNKNOWN
    return out[::-1]


thresholds = st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)).filter(lambda t: t[0] > t[1] + 1e-6)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    data=st.data(),
    th=thresholds,
    negate=st.booleans(),
    mode=st.sampled_from(["trinary", "scale", "raw"]),
    fmt=st.sampled_from([("pgm", "L"), ("png", "L"), ("bmp", "L"), ("png", "LA"), ("png", "RGB"), ("bmp", "RGB"),
                         ("png", "RGBA"), ("png", "I;16"), ("pgm", "I;16")]),
)
def test_loader_matches_map_server_rule(tmp_path, data, th, negate, mode, fmt):
    occ_th, free_th = th
    suffix, pil_mode = fmt
    h = data.draw(st.integers(1, 6))
    w = data.draw(st.integers(1, 6))
    channels = {"L": 1, "LA": 2, "RGB": 3, "RGBA": 4, "I;16": 1}[pil_mode]
    if pil_mode == "I;16":  # 16-bit greyscale: nav2 keeps the precision
        value = st.one_of(st.sampled_from([0, 100 * 257, 205 * 257, 254 * 257, 65535]), st.integers(0, 65535))
        dtype = np.uint16
    else:  # favour the values maps use, plus anything
        value = st.one_of(st.sampled_from([0, 100, 155, 205, 254, 255]), st.integers(0, 255))
        dtype = np.uint8
    flat = data.draw(st.lists(value, min_size=h * w * channels, max_size=h * w * channels))
    px = np.array(flat, dtype).reshape((h, w, channels) if channels > 1 else (h, w))
    img = tmp_path / f"m.{suffix}"
    if suffix == "pgm" and dtype == np.uint16:  # a 16-bit binary PGM (maxval 65535), written by hand
        img.write_bytes(f"P5\n{w} {h}\n65535\n".encode() + px.astype(">u2").tobytes())
    else:
        Image.fromarray(px, mode=None if dtype == np.uint16 else pil_mode).save(img)
    doc = {
        "image": img.name,
        "resolution": 0.05,
        "origin": [0.0, 0.0, 0.0],
        "negate": int(negate),
        "occupied_thresh": occ_th,
        "free_thresh": free_th,
        "mode": mode,
    }
    (tmp_path / "m.yaml").write_text(yaml.safe_dump(doc))
    g = load_map(tmp_path / "m.yaml")
    np.testing.assert_array_equal(g.cells, _reference(px, negate, occ_th, free_th, mode))


def test_scale_mode_grades_between_thresholds_and_trinary_does_not():
    px = np.array([[128]], np.uint8)  # occ = 0.498, between 0.196 and 0.65
    assert occupancy_values(px, mode="trinary").item() == -1
    graded = occupancy_values(px, mode="scale").item()
    assert graded == round((1 - 128 / 255 - 0.196) / (0.65 - 0.196) * 100) == 67  # nav2: rint(ratio * 100)
    transparent = np.array([[[128, 0]]], np.uint8)  # grey + alpha 0
    assert occupancy_values(transparent, mode="scale").item() == -1


def test_raw_mode_keeps_0_to_100_and_ignores_negate_like_nav2():
    px = np.array([[0, 100, 37, 101, 255]], np.uint8)
    assert occupancy_values(px, mode="raw").tolist() == [[0, 100, 37, -1, -1]]
    # nav2 applies negate to occ, which raw mode never reads
    assert occupancy_values(px, negate=True, mode="raw").tolist() == [[0, 100, 37, -1, -1]]
    # RGB: the mean of the three channels, rounded half away from zero (std::round)
    assert occupancy_values(np.array([[[1, 1, 2], [0, 0, 1]]], np.uint8), mode="raw").tolist() == [[1, 0]]


def test_trinary_averages_alpha_in_like_nav2():
    # grey + alpha: red, green, blue and alpha -> (3 * 0 + 0) / 4 = 0 -> occupied
    assert occupancy_values(np.array([[[0, 0]]], np.uint8), mode="trinary").item() == 100
    # white, transparent: (3 * 255 + 0) / 4 -> occ = 0.25 -> unknown between 0.196 and 0.65
    px = np.array([[[255, 0]]], np.uint8)
    assert occupancy_values(px, mode="trinary").item() == -1
    # scale mode: any pixel that is not opaque is unknown
    assert occupancy_values(px, mode="scale").item() == -1
    assert occupancy_values(np.array([[[255, 255]]], np.uint8), mode="scale").item() == 0


# ---------------------------------------------------------------------------- round trips and materials
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    cells=st.integers(1, 8).flatmap(
        lambda h: st.integers(1, 8).flatmap(
            lambda w: st.lists(st.integers(0, 4), min_size=h * w, max_size=h * w).map(lambda v: np.array(v, np.uint8).reshape(h, w))
        )
    ),
    res=st.floats(0.01, 1.0),
    ox=st.floats(-100, 100),
    oy=st.floats(-100, 100),
)
def test_save_load_round_trip(tmp_path, cells, res, ox, oy):
    g = OccupancyGrid(cells, res, (ox, oy))
    g2 = load_map(save_map(g, tmp_path / "rt.yaml"))
    np.testing.assert_array_equal(g2.cells, g.cells)
    assert g2.materials == g.materials
    assert g2.resolution_m == res and g2.origin_xy_m == (ox, oy)


def test_round_trip_custom_material_and_layer_semantics(tmp_path):
    mats = DEFAULT_MATERIALS + ("curtain",)
    cells = np.array([[0, 1, 5], [3, 4, 2]], np.uint8)
    g = OccupancyGrid(cells, 0.5, (0.0, 0.0), mats)
    save_map(g, tmp_path / "c.yaml")
    doc = yaml.safe_load((tmp_path / "c.yaml").read_text())
    assert doc["materials"] == "c_materials.pgm"
    assert doc["material_values"] == {3: "glass", 4: "foam", 5: "curtain"}
    # a ROS consumer sees every special material as occupied
    occ = np.asarray(Image.open(tmp_path / "c.pgm"))[::-1]
    assert occ.tolist() == [[254, 0, 0], [0, 0, 205]]
    g2 = load_map(tmp_path / "c.yaml")
    assert g2.materials == mats
    np.testing.assert_array_equal(g2.cells, cells)


def test_material_layer_free_carves_and_unlisted_values_keep_occupancy(tmp_path):
    Image.fromarray(np.array([[0, 0, 254]], np.uint8)).save(tmp_path / "o.pgm")
    Image.fromarray(np.array([[7, 9, 9]], np.uint8)).save(tmp_path / "l.pgm")
    doc = {"image": "o.pgm", "resolution": 1.0, "origin": [0, 0, 0], "materials": "l.pgm", "material_values": {7: "free", 3: "glass"}}
    (tmp_path / "m.yaml").write_text(yaml.safe_dump(doc))
    g = load_map(tmp_path / "m.yaml")
    assert g.cells.tolist() == [[FREE, WALL, FREE]]


# ---------------------------------------------------------------------------- errors
def _write_map(tmp_path: Path, **fields) -> Path:
    Image.fromarray(np.full((3, 4), 254, np.uint8)).save(tmp_path / "ok.pgm")
    doc = {"image": "ok.pgm", "resolution": 0.05, "origin": [0.0, 0.0, 0.0], "negate": 0,
           "occupied_thresh": 0.65, "free_thresh": 0.196}
    for k, v in fields.items():
        if v is _DELETE:
            doc.pop(k)
        else:
            doc[k] = v
    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(doc))
    return p


_DELETE = object()


@pytest.mark.parametrize(
    "fields, field, expect",
    [
        ({"resolution": -0.05}, "resolution", "positive finite"),
        ({"resolution": float("nan")}, "resolution", "positive finite"),
        ({"resolution": "0.05"}, "resolution", "positive finite"),
        ({"resolution": True}, "resolution", "positive finite"),
        ({"resolution": _DELETE}, "resolution", "required"),
        ({"image": _DELETE}, "image", "required"),
        ({"image": 3}, "image", "image file name"),
        ({"image": "missing.pgm"}, "image", "existing image"),
        ({"origin": [0.0, 0.0, float("inf")]}, "origin", "three finite numbers"),
        ({"origin": [0.0, 0.0]}, "origin", "three finite numbers"),
        ({"origin": "0 0 0"}, "origin", "three finite numbers"),
        ({"negate": "yes"}, "negate", "0, 1"),
        ({"occupied_thresh": 1.5}, "occupied_thresh", r"\[0, 1\]"),
        ({"free_thresh": -0.1}, "free_thresh", r"\[0, 1\]"),
        ({"occupied_thresh": 0.1, "free_thresh": 0.2}, "occupied_thresh", "greater than free_thresh"),
        ({"occupied_thresh": 0.2, "free_thresh": 0.2}, "occupied_thresh", "greater than free_thresh"),
        ({"mode": "ternary"}, "mode", "trinary"),
        ({"resolutoin": 0.05, "resolution": _DELETE}, "resolution", "'resolutoin' a misspelling"),
        ({"materials": "ok.pgm"}, "material_values", "mapping"),
        ({"materials": "ok.pgm", "material_values": {300: "glass"}}, "material_values", "0..255"),
        ({"materials": "ok.pgm", "material_values": {3: 4}}, "material_values[3]", "material name"),
    ],
)
def test_bad_yaml_fields_name_file_field_and_expectation(tmp_path, fields, field, expect):
    p = _write_map(tmp_path, **fields)
    with pytest.raises(MapError, match=expect) as info:
        load_map(p)
    msg = str(info.value)
    assert "bad.yaml" in msg
    assert f"field {field!r}" in msg
    assert info.value.field == field


def test_missing_file_and_bad_suffix(tmp_path):
    with pytest.raises(MapError, match=r"nope\.yaml.*no such file"):
        load_map(tmp_path / "nope.yaml")
    (tmp_path / "m.txt").write_text("x")
    with pytest.raises(MapError, match=r"m\.txt.*'\.txt'"):
        load_map(tmp_path / "m.txt")


def test_unreadable_image_and_bad_yaml_syntax(tmp_path):
    (tmp_path / "junk.pgm").write_bytes(b"not an image at all")
    p = _write_map(tmp_path, image="junk.pgm")
    with pytest.raises(MapError, match=r"bad\.yaml -> .*junk\.pgm: field 'image': expected a readable PNG, PGM or BMP"):
        load_map(p)
    (tmp_path / "s.yaml").write_text("image: [unclosed\n")
    with pytest.raises(MapError, match=r"s\.yaml: field '<yaml>': expected valid YAML"):
        load_map(tmp_path / "s.yaml")
    (tmp_path / "l.yaml").write_text("- a\n- b\n")
    with pytest.raises(MapError, match=r"l\.yaml.*mapping"):
        load_map(tmp_path / "l.yaml")


def test_material_layer_size_mismatch(tmp_path):
    Image.fromarray(np.zeros((2, 2), np.uint8)).save(tmp_path / "small.pgm")
    p = _write_map(tmp_path, materials="small.pgm", material_values={3: "glass"})
    with pytest.raises(MapError, match=r"bad\.yaml: field 'materials': expected an image of the same size as 'image' \(4x3 px\), found 2x2 px"):
        load_map(p)


def test_bad_override_arguments(tmp_path):
    p = _write_map(tmp_path)
    with pytest.raises(MapError, match="'resolution_m'"):
        load_map(p, resolution_m=0.0)
    with pytest.raises(MapError, match="'origin_xy_m'"):
        load_map(p, origin_xy_m=(float("inf"), 0.0))


def test_sixteen_bit_image_and_palette_image(tmp_path):
    # 16-bit greyscale keeps its precision: 1000/65535 is black (occupied), 65000/65535 white
    Image.fromarray(np.array([[1000, 65000]], np.uint16)).save(tmp_path / "deep.png")
    assert load_map(tmp_path / "deep.png", resolution_m=0.1).cells.tolist() == [[WALL, FREE]]
    Image.fromarray(np.zeros((2, 2), np.float32), mode="F").save(tmp_path / "float.tiff")
    (tmp_path / "f.yaml").write_text("image: float.tiff\nresolution: 0.1\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"float\.tiff: field 'image': expected an 8- or 16-bit greyscale.*found image mode 'F'"):
        load_map(tmp_path / "f.yaml")
    pal = Image.fromarray(np.array([[0, 1]], np.uint8), mode="P")
    pal.putpalette([0, 0, 0, 255, 255, 255] + [0] * 762)  # index 0 black, 1 white
    pal.save(tmp_path / "pal.png")
    assert load_map(tmp_path / "pal.png", resolution_m=0.1).cells.tolist() == [[WALL, FREE]]


def test_save_map_refuses_a_non_yaml_target(tmp_path):
    g = OccupancyGrid(np.zeros((2, 2), np.uint8), 0.1)
    with pytest.raises(MapError, match=r"m\.pgm: field '<file>': expected a path ending in one of"):
        save_map(g, tmp_path / "m.pgm")
    assert not any(tmp_path.iterdir())


# ---------------------------------------------------------------------------- nav2 map_server's own loader tests
# Ported from navigation2's nav2_map_server/test/unit/test_map_io.cpp and test_constants.cpp:
# a 10 x 10 map at 0.1 m with origin [2, 3, 1] (a yaw of 1 rad), whose OccupancyGrid.data is
# g_valid_image_content, given bottom row first. The reference image (testmap.png/.pgm/.bmp)
# is rebuilt from that content: 100 -> black (0), 0 -> white (255).
NAV2_CONTENT = np.array([
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    100, 100, 100, 100, 0, 0, 100, 100, 100, 0,
    100, 100, 100, 100, 0, 0, 100, 100, 100, 0,
    100, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    100, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    100, 0, 0, 0, 0, 0, 100, 100, 0, 0,
    100, 0, 0, 0, 0, 0, 100, 100, 0, 0,
    100, 0, 0, 0, 0, 0, 100, 100, 0, 0,
    100, 0, 0, 0, 0, 0, 100, 100, 0, 0,
    100, 0, 0, 0, 0, 0, 0, 0, 0, 0,
], np.int8).reshape(10, 10)  # row 0 = the map's bottom row
NAV2_RES, NAV2_ORIGIN = 0.1, [2.0, 3.0, 1.0]
NAV2_YAML = ("image: \"testmap.{ext}\"\nresolution: 0.1\norigin: [2.0, 3.0, 1.0]\noccupied_thresh: 0.65\n"
             "free_thresh: 0.196\nnegate: 0\nmode: \"trinary\"\n")


def _nav2_testmap(folder: Path, ext: str) -> Path:
    image = np.where(NAV2_CONTENT[::-1] == 100, 0, 255).astype(np.uint8)  # the image's top row first
    Image.fromarray(image, mode="L").save(folder / f"testmap.{ext}")
    (folder / "testmap.yaml").write_text(NAV2_YAML.format(ext=ext))
    return folder / "testmap.yaml"


def _nav2_save(values: np.ndarray, folder: Path, mode: str) -> Path:
    """Write ``values`` (row 0 = bottom) as nav2's saveMapToFile does (tryWriteMapToFile), in ``mode``."""
    top_first = values[::-1].astype(int)
    unknown = (top_first < 0) | (top_first > 100)
    if mode == "trinary":  # thresholds 0.196 / 0.65 -> rint(100 t) = 20 / 65
        px = np.where(top_first <= 20, 254, np.where(top_first >= 65, 0, 205))
        px = np.where(unknown, 205, px).astype(np.uint8)
        Image.fromarray(px, mode="L").save(folder / "saved.pgm")
        ext = "pgm"
    elif mode == "scale":  # RGBA; unknown grey 0.5 and transparent, else grey (100 - v) / 100
        grey = np.rint((100.0 - top_first) / 100.0 * 255.0)
        rgba = np.stack([grey, grey, grey, np.full(grey.shape, 255.0)], axis=-1)
        rgba[unknown] = (128, 128, 128, 0)
        Image.fromarray(rgba.astype(np.uint8), mode="RGBA").save(folder / "saved.png")
        ext = "png"
    else:  # raw: the value itself as the grey level, unknown as MaxRGB
        px = np.where(unknown, 255, top_first).astype(np.uint8)
        Image.fromarray(px, mode="L").save(folder / "saved.png")
        ext = "png"
    (folder / "saved.yaml").write_text(
        f"image: saved.{ext}\nmode: {mode}\nresolution: 0.1\norigin: [2, 3, 1]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n")
    return folder / "saved.yaml"


@pytest.mark.parametrize("ext", ["pgm", "png", "bmp"])
def test_nav2_load_save_valid_image(tmp_path, ext):
    """loadSaveValidPGM / loadSaveValidPNG / loadSaveValidBMP: the content cell for cell, then
    saved (by nav2's saver and by teamnav's) and loaded back unchanged."""
    values, meta = load_occupancy(_nav2_testmap(tmp_path, ext))
    assert meta.resolution_m == NAV2_RES and values.shape == (10, 10)
    np.testing.assert_array_equal(values, NAV2_CONTENT)
    again, _ = load_occupancy(_nav2_save(values, tmp_path, "trinary"))
    np.testing.assert_array_equal(again, NAV2_CONTENT)
    grid = load_map(tmp_path / "testmap.yaml")
    np.testing.assert_array_equal(grid.cells == WALL, NAV2_CONTENT == 100)
    np.testing.assert_array_equal(grid.cells == FREE, NAV2_CONTENT == 0)
    back, _ = load_occupancy(save_map(grid, tmp_path / "ours" / "testmap.yaml"))
    np.testing.assert_array_equal(back, NAV2_CONTENT)


@pytest.mark.parametrize("mode", ["scale", "raw"])
def test_nav2_load_save_map_modes(tmp_path, mode):
    """loadSaveMapModes: a map saved by nav2 in scale and in raw mode loads back to the same data."""
    values, _ = load_occupancy(_nav2_testmap(tmp_path, "png"))
    again, meta = load_occupancy(_nav2_save(values, tmp_path, mode))
    assert meta.mode == mode
    np.testing.assert_array_equal(again, NAV2_CONTENT)


def test_nav2_load_valid_yaml(tmp_path):
    """loadValidYAML: every field as nav2 reads it, the yaw included."""
    meta = read_map_yaml(_nav2_testmap(tmp_path, "png"))
    assert meta.image == tmp_path / "testmap.png"
    assert meta.resolution_m == NAV2_RES
    assert [*meta.origin_xy_m, meta.yaw_rad] == NAV2_ORIGIN
    assert (meta.free_thresh, meta.occupied_thresh, meta.mode, meta.negate) == (0.196, 0.65, "trinary", False)


def test_nav2_load_invalid_file_and_yaml(tmp_path):
    """loadInvalidFile / loadInvalidYAML: a missing image, an empty name, a missing YAML."""
    (tmp_path / "foo.yaml").write_text(NAV2_YAML.replace("testmap.{ext}", "foo"))
    with pytest.raises(MapError, match=r"foo\.yaml -> .*foo: field 'image': expected an existing image file"):
        load_map(tmp_path / "foo.yaml")
    with pytest.raises(MapError, match="field '<file>'"):
        load_map("")
    with pytest.raises(MapError, match=r"invalid_file\.yaml: field '<file>': expected an existing map file, found no such file"):
        load_map(tmp_path / "invalid_file.yaml")


def test_nav2_invalid_image_yaml_is_refused_for_its_image_not_its_map_type(tmp_path, caplog):
    """nav2's invalid_image.yaml: ``map_type: "occupancy"`` is ignored (one warning line
    naming the file and the key) and the missing image is what fails."""
    (tmp_path / "invalid_image.yaml").write_text("map_type: \"occupancy\"\n" + NAV2_YAML.replace("testmap.{ext}", "invalid.png"))
    with caplog.at_level(logging.WARNING, logger="teamnav.world.mapio"):
        with pytest.raises(MapError, match=r"field 'image': expected an existing image file"):
            load_map(tmp_path / "invalid_image.yaml")
        with pytest.raises(MapError):
            load_map(tmp_path / "invalid_image.yaml")
    warned = [r.getMessage() for r in caplog.records if "map_type" in r.getMessage()]
    assert len(warned) == 1 and "invalid_image.yaml" in warned[0] and "ignoring key 'map_type'" in warned[0]


@pytest.mark.parametrize("occ, free, field", [(2.0, 2.0, "occupied_thresh"), (-2.0, -2.0, "occupied_thresh"),
                                              (0.2, 0.7, "occupied_thresh")])
def test_nav2_save_invalid_parameters(tmp_path, occ, free, field):
    """saveInvalidParameters: thresholds out of [0, 1] or free above occupied are refused and
    nothing is written; so is a folder that cannot be made."""
    grid = load_map(_nav2_testmap(tmp_path, "png"))
    with pytest.raises(MapError, match=f"field '{field}'"):
        save_map(grid, tmp_path / "out" / "m.yaml", occupied_thresh=occ, free_thresh=free)
    assert not (tmp_path / "out").exists()
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(MapError, match=r"a_file/sub/m\.yaml: field '<file>': expected a path in a folder"):
        save_map(grid, tmp_path / "a_file" / "sub" / "m.yaml")


def test_saved_map_keeps_origin_yaw_and_thresholds_and_reads_back_in_a_map_server_reader(tmp_path):
    """A run folder's map.yaml: origin, yaw and thresholds written as read, and an independent
    reader of nav2's rule (``_reference``) finds the same cells in the saved image."""
    src = load_map(DATA / "nav2" / "depot.yaml")  # free_thresh 0.25: map_saver's 205 would read free
    rotated = src.with_pose((2.0, 3.0), 1.0)
    meta = read_map_yaml(DATA / "nav2" / "depot.yaml")
    out = save_map(rotated, tmp_path / "map.yaml", occupied_thresh=meta.occupied_thresh, free_thresh=meta.free_thresh)
    doc = yaml.safe_load(out.read_text())
    assert doc["origin"] == [2.0, 3.0, 1.0]
    assert (doc["occupied_thresh"], doc["free_thresh"]) == (meta.occupied_thresh, meta.free_thresh)
    back = load_map(out)
    np.testing.assert_array_equal(back.cells, src.cells)
    assert back.yaw_rad == 1.0 and back.origin_xy_m == (2.0, 3.0)
    px = np.asarray(Image.open(tmp_path / doc["image"]))
    np.testing.assert_array_equal(_reference(px, bool(doc["negate"]), doc["occupied_thresh"], doc["free_thresh"], doc["mode"]),
                                  src.cells)


def test_hostile_image_header_is_refused_before_decoding(tmp_path):
    """A PGM header claiming 1e5 x 1e5 pixels: refused from the header with the figure."""
    (tmp_path / "bomb.pgm").write_bytes(b"P5\n100000 100000\n255\n" + b"\0" * 64)
    (tmp_path / "bomb.yaml").write_text("image: bomb.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"bomb\.pgm: field 'image': expected an image of at most 53,687,091 pixels, "
                                       r"found an image of 100000 x 100000 px has 10,000,000,000 cells, which needs about "
                                       r"372\.5 GiB .*MAX_MAP_BYTES"):
        load_map(tmp_path / "bomb.yaml")


def test_map_yaml_with_an_alias_bomb_or_a_duplicate_key_is_refused_quickly(tmp_path):
    """A "billion laughs" under ``resolution`` and a key given twice: one bounded message each
    (the loader counts values as aliases expand, so nothing is built or printed in full)."""
    rows = ['a: &a ["x","x","x","x","x","x","x","x","x","x"]']
    for prev, name in zip("abcdefgh", "bcdefghi"):
        rows.append(f"{name}: &{name} [" + ",".join([f"*{prev}"] * 10) + "]")
    (tmp_path / "lol.yaml").write_text("\n".join(rows) + "\nimage: x.pgm\nresolution: *i\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"lol\.yaml: field '\w': expected YAML within teamnav's limits, found .*1,000,000 values") as info:
        load_map(tmp_path / "lol.yaml")
    assert len(str(info.value)) < 400
    (tmp_path / "dup.yaml").write_text("image: x.pgm\nresolution: 0.1\nresolution: 0.2\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"dup\.yaml: field 'resolution': .*duplicate key 'resolution' \(first given at line 2\)"):
        load_map(tmp_path / "dup.yaml")
    (tmp_path / "deep.yaml").write_text("image: x.pgm\nresolution: " + "[" * 20000 + "]" * 20000 + "\norigin: [0, 0, 0]\n")
    with pytest.raises(MapError, match=r"deep\.yaml: field .*nested"):
        load_map(tmp_path / "deep.yaml")
