"""Controllers found by name, so a scenario file can name them (STYLE habit 9).

Entries are versioned names mapped to lazy ``"module:attr"`` entry points, as Gymnasium's
registry does. Unknown names get a "did you mean" hint; a second registration of a name
raises.

A controller that is not registered can be named by its entry point directly, as
``robots[i].controller: "my_pkg.brains:MyBrain"`` in a scenario or ``teamnav run
--controller my_pkg.brains:MyBrain``: :func:`lookup` imports ``my_pkg.brains`` and takes its
``MyBrain``. The module is looked for on the Python path and then in the current folder (so
``my_brain.py`` next to where ``teamnav`` is run works, as ``python -m`` would find it); a
path to a file works too (``./brains/my_brain.py:MyBrain``). The class must look like a
controller: a ``Params`` pydantic model and a ``step`` method (``step_batch`` for a batched
one), see :mod:`teamnav.control.protocol`.
"""

from __future__ import annotations

import difflib
import hashlib
import importlib
import importlib.util
import os
import re
import sys
from pathlib import Path
from typing import Any

_REGISTRY: dict[str, str] = {}

#: ``module.path:Attr`` or ``path/to/file.py:Attr`` (the part after the last ':' is the attribute)
_ENTRY = re.compile(r"^(?P<module>[^:]+|[A-Za-z]:[\\/][^:]*):(?P<attr>[A-Za-z_][A-Za-z0-9_]*)$")
_MODULE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")


def register(name: str, entry_point: str) -> None:
    """Register controller ``name`` (e.g. ``"wander-v1"``) at ``"package.module:Class"``."""
    if name in _REGISTRY:
        raise ValueError(f"controller {name!r} is already registered (at {_REGISTRY[name]})")
    if ":" not in entry_point:
        raise ValueError(f"entry point for {name!r} must look like 'module:attr', got {entry_point!r}")
    _REGISTRY[name] = entry_point


def names() -> list[str]:
    """All registered controller names, sorted."""
    return sorted(_REGISTRY)


def is_entry_point(name: str) -> bool:
    """Whether ``name`` reads as ``module:Class`` (or ``file.py:Class``) rather than a registered name.

    Examples
    --------
    >>> is_entry_point("my_pkg.brains:MyBrain"), is_entry_point("wander-v1")
    (True, False)
    """
    return isinstance(name, str) and name not in _REGISTRY and _ENTRY.match(name) is not None


def lookup(name: str) -> Any:
    """The controller class registered as ``name``, or named by the entry point ``name``.

    Raises
    ------
    KeyError
        With a "did you mean" hint when ``name`` is unknown; for an entry point, what could
        not be imported or found, or why the attribute is not a controller.
    """
    entry = _REGISTRY.get(name)
    if entry is not None:
        module, attr = entry.split(":")
        return getattr(importlib.import_module(module), attr)
    if is_entry_point(name):
        return _resolve_entry_point(name)
    close = difflib.get_close_matches(name, _REGISTRY, n=3)
    hint = f"; did you mean {' or '.join(repr(c) for c in close)}?" if close else ""
    raise KeyError(
        f"unknown controller {name!r}{hint} (known: {', '.join(names())}; or give your own class as "
        "'module:Class' or 'path/to/file.py:Class')"
    ) from None


def _import_file(path: Path) -> Any:
    """Import the Python file ``path`` once per path, as a module of its own."""
    path = path.resolve()
    tag = hashlib.sha1(str(path).encode()).hexdigest()[:10]
    mod_name = f"_teamnav_user_{re.sub(r'[^A-Za-z0-9_]', '_', path.stem)}_{tag}"
    if mod_name in sys.modules:
        return sys.modules[mod_name]
    spec = importlib.util.spec_from_file_location(mod_name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load {path} as a Python module")
    module = importlib.util.module_from_spec(spec)
    sys.modules[mod_name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        sys.modules.pop(mod_name, None)
        raise
    return module


def _import_module(module: str) -> Any:
    """``importlib.import_module``, then again with the current folder on the path when the
    module is not found and the folder is not on it (a console script's path lacks it)."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as exc:
        top = module.split(".")[0]
        cwd = os.getcwd()
        on_path = cwd in sys.path or "" in sys.path
        here = Path(cwd, top + ".py").is_file() or Path(cwd, top).is_dir()
        if exc.name != top or on_path or not here:
            raise
        sys.path.append(cwd)
        return importlib.import_module(module)


def _resolve_entry_point(name: str) -> Any:
    m = _ENTRY.match(name)
    assert m is not None
    module, attr = m["module"], m["attr"]
    as_file = module.endswith(".py") or "/" in module or os.sep in module
    try:
        if as_file:
            path = Path(os.path.expanduser(module))
            if not path.is_file():
                raise KeyError(f"controller {name!r}: no such Python file {module!r}")
            mod = _import_file(path)
        else:
            if not _MODULE.match(module):
                raise KeyError(f"controller {name!r}: {module!r} is not a module name (expected 'package.module:Class' "
                               "or 'path/to/file.py:Class')")
            mod = _import_module(module)
    except KeyError:
        raise
    except ModuleNotFoundError as exc:
        raise KeyError(f"controller {name!r}: cannot import module {module!r} ({exc}); put it on the Python path "
                       "(PYTHONPATH), in the current folder, or give a file as 'path/to/file.py:Class'") from None
    except BaseException as exc:  # noqa: BLE001 - the user's module failed while importing: say so in one line
        # even sys.exit() or a KeyboardInterrupt raised by the module itself (they used to end
        # the run with nothing written, sys.exit(0) with exit status 0); SIGTERM stays SIGTERM
        if isinstance(exc, KeyboardInterrupt) and type(exc) is not KeyboardInterrupt:
            raise
        from teamnav.control.guard import describe

        raise KeyError(f"controller {name!r}: importing {module!r} failed: {describe(exc)}") from None
    cls = getattr(mod, attr, None)
    if cls is None:
        public = sorted(n for n, v in vars(mod).items() if isinstance(v, type) and not n.startswith("_"))
        close = difflib.get_close_matches(attr, public, n=1)
        hint = f"; did you mean {close[0]!r}?" if close else ""
        raise KeyError(f"controller {name!r}: module {module!r} has no attribute {attr!r}{hint}")
    problem = _not_a_controller(cls)
    if problem:
        raise KeyError(f"controller {name!r}: {attr} is not a controller: {problem} (see teamnav.control.protocol)")
    return cls


def _not_a_controller(cls: Any) -> str | None:
    """Why ``cls`` cannot be built and stepped by the engine (None when it can)."""
    if not isinstance(cls, type):
        return f"expected a class, got {type(cls).__name__}"
    params = getattr(cls, "Params", None)
    if not (isinstance(params, type) and callable(getattr(params, "model_validate", None))):
        return "it needs a pydantic model 'Params' (use teamnav.control.NoParams for none)"
    method = "step_batch" if getattr(cls, "batched", False) else "step"
    if not callable(getattr(cls, method, None)):
        return f"it needs a method {method}(obs)"
    return None


# Built-in controllers of the core. Paper systems register theirs through the
# ``teamnav.papers`` entry-point group (:mod:`teamnav.plugins`), loaded below.
register("idle-v1", "teamnav.control.idle:Idle")
register("wander-v1", "teamnav.control.nav.wander:Wander")
register("wander-batched-v1", "teamnav.control.nav.wander:WanderBatched")
# the single optimal robot that follows a planned route (the trail papers' baseline, a generic brain)
register("route-follow-v1", "teamnav.control.nav.route_follow:RouteFollow")
# low-level Navigate + Panic with random exploration (Vaughan et al.'s, a generic brain)
register("explore-v1", "teamnav.control.nav.explore:Explore")


def _register_papers() -> None:
    """Register every installed paper's brains (:attr:`teamnav.plugins.Paper.brains`)."""
    from teamnav import plugins

    for paper in plugins.papers().values():
        for name, entry in paper.brains.items():
            if name in _REGISTRY:
                import warnings

                warnings.warn(f"teamnav: paper {paper.key!r} registers controller {name!r}, which is taken "
                              f"(at {_REGISTRY[name]}); skipped", stacklevel=2)
                continue
            register(name, entry)


_register_papers()
