"""Keep numba's on-disk kernel caches honest when a module a kernel calls has changed.

numba's cache (``@njit(cache=True)``) checks only the source file of the function it compiled.
A kernel that calls (and inlines) a numba function of another module goes on running that
module's *old* code from the cache after the other module is edited: a silent, wrong result,
until someone deletes ``__pycache__/*.nbi`` by hand. :func:`renew` closes that hole for the
whole package, once per process, at ``import teamnav``:

- The package's kernel modules are the ``.py`` files with a ``cache=True`` numba decorator. For
  each, its *dependencies* are the teamnav modules it imports, transitively, that can hold code
  a kernel calls: modules that use numba, and package ``__init__`` files that may re-export
  one (read from the source with :mod:`ast`, never imported). Their sizes and modification
  times are its stamp.
- A record of the stamps is kept beside the caches (``numba-deps.json``). When it matches, the
  check costs one ``stat`` per listed file. When a dependency of a kernel module has changed,
  that module's cache index files are deleted, so its kernels compile afresh, once; modules
  whose dependencies did not change keep their caches. With no record (a fresh tree, or one
  cached before this check existed) every kernel module's index is renewed once.
- Caches are found where numba puts them: ``__pycache__`` beside the source, or under
  ``NUMBA_CACHE_DIR`` when that is set (numba's ``<folder>_<sha1 of the folder>`` layout, which
  ``tests/test_kernel_caches.py`` checks against numba's own locator). A cache folder that
  cannot be written (an installed package owned by another user) is left alone: installed
  sources do not change in place.

``control/group.py: renew_stale_caches`` does the same per dispatcher for the compiled group
brains; this module makes the per-dispatcher stamps a second line of defence, not the only one.
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
import re
from pathlib import Path

__all__ = ["cache_dir_of", "kernel_modules", "module_deps", "renew"]

PACKAGE_ROOT = Path(__file__).resolve().parent
RECORD_NAME = "numba-deps.json"
#: a decorator that compiles with numba's on-disk cache: ``@njit(cache=True)``, ``@nb.njit(..., cache=True)``
_CACHED_KERNEL = re.compile(r"@[\w.]*(?:njit|jit|vectorize|guvectorize)\([^)]*\bcache\s*=\s*True")
_renewed_in_this_process = False


def cache_dir_of(py_file: Path) -> Path:
    """The folder where numba caches the kernels of ``py_file``.

    ``__pycache__`` beside the file, or, when the environment sets ``NUMBA_CACHE_DIR``, numba's
    ``UserProvidedCacheLocator`` path: ``NUMBA_CACHE_DIR/<parent folder>_<sha1 of the folder>``.
    """
    folder = os.path.dirname(os.path.abspath(py_file))
    user_dir = os.environ.get("NUMBA_CACHE_DIR")
    if user_dir:
        sub = "_".join([os.path.split(folder)[-1], hashlib.sha1(folder.encode()).hexdigest()])
        return Path(user_dir) / sub
    return Path(folder) / "__pycache__"


def kernel_modules(root: Path = PACKAGE_ROOT) -> list[Path]:
    """The package's ``.py`` files that hold a cached numba kernel (``cache=True``), sorted."""
    out = []
    for p in sorted(root.rglob("*.py")):
        if "__pycache__" in p.parts or p == Path(__file__).resolve():
            continue
        try:
            if _CACHED_KERNEL.search(p.read_text(encoding="utf-8")):
                out.append(p)
        except (OSError, UnicodeDecodeError):
            continue
    return out


def _module_file(name: str, root: Path) -> Path | None:
    """The source file of teamnav module ``name`` under ``root`` (a package's ``__init__.py``)."""
    parts = name.split(".")
    if not parts or parts[0] != root.name:
        return None
    base = root.joinpath(*parts[1:])
    if base.with_suffix(".py").is_file():
        return base.with_suffix(".py")
    if (base / "__init__.py").is_file():
        return base / "__init__.py"
    return None


def _module_name(py_file: Path, root: Path) -> str:
    rel = py_file.relative_to(root).with_suffix("")
    parts = [root.name, *rel.parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _direct_imports(py_file: Path, root: Path) -> set[Path]:
    """The teamnav source files that ``py_file`` imports (absolute and relative imports).

    Only files that can hold what a kernel calls are followed: modules that use numba, and
    package ``__init__`` files (which may re-export a numba function). A compiled kernel can
    call nothing else, so the stamp of plain Python modules would only renew caches for nothing.
    """
    try:
        text = py_file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return set()
    if "numba" not in text and py_file.name != "__init__.py":
        return set()
    try:
        tree = ast.parse(text, filename=str(py_file))
    except SyntaxError:
        return set()
    me = _module_name(py_file, root)
    package = me if py_file.name == "__init__.py" else me.rpartition(".")[0]
    out: set[Path] = set()
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                anchor = package.split(".")
                anchor = anchor[: len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            names = [base] + [f"{base}.{a.name}" for a in node.names]
        for name in names:
            f = _module_file(name, root)
            if f is not None and f != py_file:
                out.add(f)
    return out


def _can_hold_kernel_code(py_file: Path) -> bool:
    try:
        text = py_file.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return False
    return "numba" in text or py_file.name == "__init__.py"


def module_deps(root: Path = PACKAGE_ROOT) -> dict[Path, set[Path]]:
    """Each kernel module's teamnav dependencies, transitively (itself excluded)."""
    direct: dict[Path, set[Path]] = {}

    def imports_of(f: Path) -> set[Path]:
        if f not in direct:
            direct[f] = _direct_imports(f, root)
        return direct[f]

    out = {}
    for mod in kernel_modules(root):
        seen: set[Path] = set()
        todo = [mod]
        while todo:
            for dep in imports_of(todo.pop()):
                if dep not in seen and dep != mod and _can_hold_kernel_code(dep):
                    seen.add(dep)
                    todo.append(dep)
        out[mod] = seen
    return out


def _stat(p: Path) -> list[int] | None:
    try:
        st = p.stat()
    except OSError:
        return None
    return [st.st_size, st.st_mtime_ns]


def _record_path(root: Path) -> Path:
    return cache_dir_of(root / "__init__.py") / RECORD_NAME


def renew(root: Path = PACKAGE_ROOT, *, force: bool = False) -> list[Path]:
    """Delete the cache indexes of the kernel modules whose dependencies changed.

    Returns the kernel modules renewed (empty on the fast path: nothing listed has changed).
    Runs once per process unless ``force``. Never raises for a cache folder that cannot be read
    or written: it leaves that folder alone.
    """
    global _renewed_in_this_process
    if _renewed_in_this_process and not force:
        return []
    _renewed_in_this_process = True
    record_path = _record_path(root)
    try:
        record = json.loads(record_path.read_text())
        stats = record["stats"]
        if all(_stat(root / rel) == st for rel, st in stats.items()):
            return []
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        record = None
    deps = module_deps(root)
    listed = set(deps) | {d for ds in deps.values() for d in ds}
    stats = {str(p.relative_to(root)): _stat(p) for p in sorted(listed)}
    old_stats = record["stats"] if record else {}
    old_mods = set(record["modules"]) if record else set()
    renewed = []
    for mod, ds in deps.items():
        rel = str(mod.relative_to(root))
        changed = record is None or rel not in old_mods or any(
            old_stats.get(str(d.relative_to(root))) != stats[str(d.relative_to(root))] for d in ds)
        if not changed:
            continue
        folder = cache_dir_of(mod)
        try:
            for index in folder.glob(f"{mod.stem}.*.nbi"):
                index.unlink(missing_ok=True)
        except OSError:
            continue
        renewed.append(mod)
    try:
        record_path.parent.mkdir(parents=True, exist_ok=True)
        tmp = record_path.with_name(f"{RECORD_NAME}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"modules": sorted(str(m.relative_to(root)) for m in deps), "stats": stats}))
        os.replace(tmp, record_path)
    except OSError:  # a cache folder that cannot be written: renewed again next time, never an error
        return renewed
    return renewed
