"""A disk cache for distance fields of large maps, so a run does not import scipy to recompute one.

:func:`teamnav.world.distance.distance_field` on a 1200 × 1200 map costs about 0.15 s, and the
first one in a process also imports ``scipy.ndimage`` (about 0.3 s): together a third of a
1-s demo run's start-up. The field depends only on the blocking mask and the cell size, so it
is kept on disk under a key made of both, in the same spirit as numba's ``cache=True``.

- Where: ``$TEAMNAV_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/teamnav``, else
  ``~/.cache/teamnav``; fields go into ``distance-fields/``. ``TEAMNAV_CACHE_DIR=off`` (or an
  empty value) turns the cache off.
- What: a field is exactly the array ``scipy.ndimage.distance_transform_edt`` gave (float64,
  bit for bit); the key is a BLAKE2b digest of the mask's shape, bytes and cell size, and of
  :data:`FORMAT` (bumped when the field's definition changes).
- Safety: files are written to a temporary name and renamed, so two processes computing the
  same field never leave a half-written one; a file that cannot be read, or that does not
  hold an array of the mask's shape, is ignored (and recomputed). A cache folder that cannot
  be written is never an error: the field is computed, as without a cache.
- Only masks of at least :data:`MIN_CELLS` cells are cached: below that, computing is as cheap
  as reading.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
from pathlib import Path

import numpy as np

from teamnav.files import file_mode

__all__ = ["FORMAT", "MIN_CELLS", "cache_dir", "load", "store"]

#: bump when what a cached field means changes (not for numpy or scipy upgrades: the EDT is exact)
FORMAT = 1
#: masks smaller than this are not cached: below it, the EDT costs about what reading a file does
MIN_CELLS = 250_000


def cache_dir() -> Path | None:
    """The folder distance fields are cached in, or None when the cache is turned off."""
    env = os.environ.get("TEAMNAV_CACHE_DIR")
    if env is not None:
        if env.strip() in ("", "off", "0"):
            return None
        root = Path(env).expanduser()
    else:
        xdg = os.environ.get("XDG_CACHE_HOME")
        root = (Path(xdg) if xdg else Path.home() / ".cache") / "teamnav"
    return root / "distance-fields"


def _key(blocking: np.ndarray, resolution_m: float) -> str:
    h = hashlib.blake2b(digest_size=20)
    h.update(f"distance-field v{FORMAT} {blocking.shape} {blocking.dtype.str} {float(resolution_m)!r}".encode())
    h.update(np.ascontiguousarray(blocking).tobytes())
    return h.hexdigest()


def _path(blocking: np.ndarray, resolution_m: float) -> Path | None:
    if blocking.size < MIN_CELLS:
        return None
    folder = cache_dir()
    if folder is None:
        return None
    return folder / f"{_key(blocking, resolution_m)}.npy"


def load(blocking: np.ndarray, resolution_m: float) -> np.ndarray | None:
    """The cached field of ``blocking`` at ``resolution_m``, or None (not cached, off, unreadable)."""
    path = _path(blocking, resolution_m)
    if path is None or not path.is_file():
        return None
    try:
        field = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError):
        return None
    if field.shape != blocking.shape or field.dtype != np.float64:
        return None
    return field


def store(blocking: np.ndarray, resolution_m: float, field: np.ndarray) -> bool:
    """Keep ``field`` for later runs; True if it was written. Never raises for a file-system
    problem (a read-only home, a full disk): the cache is an optimisation, not a result."""
    path = _path(blocking, resolution_m)
    if path is None:
        return False
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".npy", dir=path.parent)
        with os.fdopen(fd, "wb") as f:
            np.save(f, np.asarray(field, dtype=np.float64), allow_pickle=False)
        os.chmod(tmp, file_mode())  # mkstemp made it 0600; the user's umask, as for any file teamnav writes
        os.replace(tmp, path)
        return True
    except OSError:
        if tmp is not None:
            try:
                os.unlink(tmp)
            except OSError:
                pass
        return False
