"""numba's on-disk caches are renewed when a module a cached kernel calls has changed.

numba checks only the compiled function's own file: a cached kernel that inlines a numba
function of another module goes on running its old code after that module is edited. The test
shows the staleness on a small package, then that ``teamnav._kernel_caches.renew`` fixes it and
renews only the kernels whose callees changed.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from teamnav import _kernel_caches as kc


def _write(path: Path, text: str, bump_s: int = 0) -> None:
    path.write_text(textwrap.dedent(text))
    if bump_s:  # a later mtime, as an editor's save gives (numba and the stamp both read it)
        st = path.stat()
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + bump_s * 1_000_000_000))


def _package(tmp_path: Path) -> Path:
    root = tmp_path / "kpkg"
    root.mkdir()
    _write(root / "__init__.py", "")
    _write(root / "callee.py", """
        from numba import njit

        @njit
        def value():
            return 1
    """)
    _write(root / "kernel.py", """
        from numba import njit

        from kpkg.callee import value

        @njit(cache=True)
        def run():
            return value() * 10
    """)
    _write(root / "other.py", """
        from numba import njit

        @njit(cache=True)
        def run():
            return 7
    """)
    return root


def _call(root: Path, module: str, env_extra: dict | None = None) -> int:
    env = {**os.environ, "PYTHONPATH": str(root.parent), **(env_extra or {})}
    out = subprocess.run([sys.executable, "-c", f"import kpkg.{module} as m; print(m.run())"],
                         capture_output=True, text=True, env=env, timeout=120, check=True)
    return int(out.stdout.strip())


def test_the_package_kernels_and_their_callees_are_found():
    deps = kc.module_deps()
    names = {str(p.relative_to(kc.PACKAGE_ROOT)) for p in deps}
    assert "world/raycast.py" in names and "sim/collisions.py" in names
    assert "_kernel_caches.py" not in names and "control/group.py" not in names  # cache=True in prose only
    rel = {str(m.relative_to(kc.PACKAGE_ROOT)): {str(d.relative_to(kc.PACKAGE_ROOT)) for d in ds}
           for m, ds in deps.items()}
    # the compiled LOS brain inlines the navigators' kernels, which inline the geometry's
    assert {"control/nav/local/compiled.py", "control/nav/local/base.py"} <= rel["papers/los_help/brains/compiled.py"]
    assert "world/raycast.py" in rel["localization/mcl.py"]
    # plain Python modules are not stamps: a kernel can call only numba code
    assert not any(d.startswith("experiments/") for ds in rel.values() for d in ds)


def test_cache_dir_is_numbas_own(monkeypatch, tmp_path):
    from numba.core.caching import UserProvidedCacheLocator

    from teamnav.world import raycast

    kernel = next(v for v in vars(raycast).values() if getattr(getattr(v, "_cache", None), "cache_path", None))
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert kc.cache_dir_of(Path(raycast.__file__)) == Path(kernel._cache.cache_path)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    sub = UserProvidedCacheLocator.get_suitable_cache_subpath(raycast.__file__)
    assert kc.cache_dir_of(Path(raycast.__file__)) == tmp_path / sub


@pytest.mark.parametrize("user_cache_dir", [False, True], ids=["in-tree", "NUMBA_CACHE_DIR"])
def test_an_edited_callee_renews_only_its_callers(tmp_path, monkeypatch, user_cache_dir):
    root = _package(tmp_path)
    env = {}
    if user_cache_dir:
        env["NUMBA_CACHE_DIR"] = str(tmp_path / "numba-cache")
        monkeypatch.setenv("NUMBA_CACHE_DIR", env["NUMBA_CACHE_DIR"])
    else:
        monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    assert _call(root, "kernel", env) == 10 and _call(root, "other", env) == 7
    first = kc.renew(root, force=True)  # no record yet: every kernel module once
    assert {p.name for p in first} == {"kernel.py", "other.py"}
    assert _call(root, "kernel", env) == 10 and _call(root, "other", env) == 7
    assert kc.renew(root, force=True) == []  # nothing changed: the fast path
    other_index = sorted(kc.cache_dir_of(root / "other.py").glob("other.*.nbi"))
    assert other_index

    _write(root / "callee.py", """
        from numba import njit

        @njit
        def value():
            return 2
    """, bump_s=5)
    assert _call(root, "kernel", env) == 10  # numba alone: the old callee, from the cache
    renewed = kc.renew(root, force=True)
    assert [p.name for p in renewed] == ["kernel.py"]
    assert sorted(kc.cache_dir_of(root / "other.py").glob("other.*.nbi")) == other_index  # kept
    assert _call(root, "kernel", env) == 20


def test_a_broken_record_renews_everything_once(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    root = _package(tmp_path)
    kc.renew(root, force=True)
    record = kc.cache_dir_of(root / "__init__.py") / kc.RECORD_NAME
    record.write_text("{not json")
    assert {p.name for p in kc.renew(root, force=True)} == {"kernel.py", "other.py"}
    assert set(json.loads(record.read_text())["modules"]) == {"kernel.py", "other.py"}
    assert kc.renew(root, force=True) == []


def test_a_cache_folder_that_cannot_be_written_is_left_alone(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    root = _package(tmp_path)
    (root / "__pycache__").write_text("a file where the cache folder would be")
    renewed = kc.renew(root, force=True)  # must not raise
    assert {p.name for p in renewed} <= {"kernel.py", "other.py"}
    assert not (root / "__pycache__").is_dir()
