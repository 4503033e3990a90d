"""The disk cache of distance fields: a cached field is the computed one bit for bit, and a
broken, unwritable or turned-off cache never changes a result or raises."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from teamnav.world import distance, field_cache


@pytest.fixture
def mask() -> np.ndarray:
    rng = np.random.default_rng(5)
    m = np.zeros((500, 520), np.uint8)  # 260 000 cells: above MIN_CELLS
    m[rng.integers(0, 500, 300), rng.integers(0, 520, 300)] = 1
    m[:, 0] = 1
    return m


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("TEAMNAV_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(distance, "_LAST", [None])  # no in-process memo between calls
    return tmp_path / "cache" / "distance-fields"


def _exact(mask, res):
    return ndimage.distance_transform_edt(mask == 0, sampling=res)


def test_a_cached_field_is_the_computed_one_bit_for_bit(mask, cache, monkeypatch):
    first = distance.distance_field(mask, 0.05)
    files = list(cache.glob("*.npy"))
    assert len(files) == 1 and not list(cache.glob(".tmp-*"))
    monkeypatch.setattr(distance, "_LAST", [None])
    calls = []
    real = field_cache.load
    monkeypatch.setattr(field_cache, "load", lambda *a: calls.append(1) or real(*a))
    second = distance.distance_field(mask, 0.05)
    assert calls and np.array_equal(second, first) and second.tobytes() == _exact(mask, 0.05).tobytes()


def test_the_key_tells_apart_masks_and_cell_sizes(mask, cache, monkeypatch):
    distance.distance_field(mask, 0.05)
    monkeypatch.setattr(distance, "_LAST", [None])
    coarse = distance.distance_field(mask, 0.1)
    other = mask.copy()
    other[250, 260] = 1
    monkeypatch.setattr(distance, "_LAST", [None])
    moved = distance.distance_field(other, 0.05)
    assert len(list(cache.glob("*.npy"))) == 3
    assert np.array_equal(coarse, _exact(mask, 0.1)) and np.array_equal(moved, _exact(other, 0.05))


@pytest.mark.parametrize("damage", [b"not an array", b""])
def test_a_damaged_file_is_recomputed(mask, cache, monkeypatch, damage):
    distance.distance_field(mask, 0.05)
    (path,) = cache.glob("*.npy")
    path.write_bytes(damage)
    monkeypatch.setattr(distance, "_LAST", [None])
    assert np.array_equal(distance.distance_field(mask, 0.05), _exact(mask, 0.05))


def test_a_field_of_another_shape_in_the_file_is_not_used(mask, cache, monkeypatch):
    distance.distance_field(mask, 0.05)
    (path,) = cache.glob("*.npy")
    np.save(path, np.zeros((3, 3)))
    monkeypatch.setattr(distance, "_LAST", [None])
    assert np.array_equal(distance.distance_field(mask, 0.05), _exact(mask, 0.05))


def test_an_unwritable_cache_is_no_error(mask, tmp_path, monkeypatch):
    blocker = tmp_path / "a-file"
    blocker.write_text("x")
    monkeypatch.setenv("TEAMNAV_CACHE_DIR", str(blocker))  # a file where the folder should be
    monkeypatch.setattr(distance, "_LAST", [None])
    assert np.array_equal(distance.distance_field(mask, 0.05), _exact(mask, 0.05))
    assert not field_cache.store(mask, 0.05, _exact(mask, 0.05))


@pytest.mark.parametrize("value", ["off", ""])
def test_the_cache_can_be_turned_off(mask, tmp_path, monkeypatch, value):
    monkeypatch.setenv("TEAMNAV_CACHE_DIR", value)
    monkeypatch.setattr(distance, "_LAST", [None])
    assert field_cache.cache_dir() is None
    distance.distance_field(mask, 0.05)
    assert field_cache.load(mask, 0.05) is None


def test_small_masks_are_not_cached(cache):
    small = np.zeros((40, 40), np.uint8)
    small[0] = 1
    distance.distance_field(small, 0.1)
    assert not cache.exists() or not list(cache.glob("*.npy"))


def test_the_default_place_follows_xdg(monkeypatch, tmp_path):
    monkeypatch.delenv("TEAMNAV_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert field_cache.cache_dir() == tmp_path / "teamnav" / "distance-fields"
