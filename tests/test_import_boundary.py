"""Two rules, by construction.

1. Brains never import the simulator nor read a true pose. DESIGN.md "truth and belief never
   mix": code under ``teamnav/control``, ``teamnav/localization`` and every paper's
   ``teamnav/papers/<paper>/brains`` imports neither ``teamnav.sim``, ``teamnav.experiments``,
   ``teamnav.viz`` nor ``teamnav.cli``, and names nothing that smells of ground truth.
2. The core names no paper: nothing outside ``teamnav/papers`` imports ``teamnav.papers``
   (papers plug in through the ``teamnav.papers`` entry-point group, :mod:`teamnav.plugins`).

Each checker is also run on a synthetic offending source, so a checker that stopped flagging
would fail here too.
"""

from __future__ import annotations

import ast
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import teamnav

PKG = Path(teamnav.__file__).resolve().parent
BRAIN_DIRS = ("control", "localization", *sorted(str(p.relative_to(PKG)) for p in PKG.glob("papers/*/brains")))
FORBIDDEN = ("teamnav.sim", "teamnav.experiments", "teamnav.viz", "teamnav.cli")
#: What the core may never import: any paper.
PAPERS = ("teamnav.papers",)
#: The one core module allowed to name papers' modules: the one-release table of moved import paths.
CORE_EXEMPT = ("_moved_paths.py",)
#: Names of truth: the simulator's state fields and anything called "true_…" / "ground_truth".
TRUTH_NAMES = ("x_m", "y_m", "theta_rad")
_TRUTHY = re.compile(r"(?:^|_)true_|ground_?truth")


def _module_name(path: Path) -> str:
    rel = path.relative_to(PKG.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _is_package(path: Path) -> bool:
    return path.name == "__init__.py"


def _resolve(node: ast.ImportFrom, module: str, is_package: bool) -> str:
    """Absolute module of a (possibly relative) ``from … import``."""
    if node.level == 0:
        return node.module or ""
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    base = base[: len(base) - (node.level - 1)] if node.level > 1 else base
    return ".".join(base + ([node.module] if node.module else []))


def forbidden_imports(source: str, module: str, is_package: bool = False,
                      forbidden: tuple[str, ...] = FORBIDDEN) -> list[str]:
    """Imported modules of ``source`` (as module ``module``) that are under a ``forbidden`` package."""
    hits = []
    for node in ast.walk(ast.parse(source)):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(node, module, is_package)
            targets = [base] + [f"{base}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", getattr(node.func, "id", "")) in (
            "import_module", "__import__"
        ):
            targets = [a.value for a in node.args[:1] if isinstance(a, ast.Constant) and isinstance(a.value, str)]
        for t in targets:
            if any(t == f or t.startswith(f + ".") for f in forbidden):
                hits.append(f"line {node.lineno}: {t}")
    return hits


def truth_reads(source: str) -> list[str]:
    """Names/attributes in ``source`` that smell of ground truth."""
    hits = []
    for node in ast.walk(ast.parse(source)):
        name = None
        if isinstance(node, ast.Attribute):
            name = node.attr
            if isinstance(node.value, ast.Attribute) and node.value.attr == "state" and name in TRUTH_NAMES:
                hits.append(f"line {node.lineno}: state.{name}")
                continue
        elif isinstance(node, ast.Name):
            name = node.id
        elif isinstance(node, ast.arg):
            name = node.arg
        elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            name = node.name
        elif isinstance(node, ast.keyword):
            name = node.arg
        if name and _TRUTHY.search(name.lower()):
            hits.append(f"line {getattr(node, 'lineno', '?')}: {name}")
    return hits


def _brain_files() -> list[Path]:
    files = sorted(p for d in BRAIN_DIRS for p in (PKG / d).rglob("*.py"))
    assert files, f"no sources found under {PKG}/{{{','.join(BRAIN_DIRS)}}}"
    return files


def _core_files() -> list[Path]:
    files = sorted(p for p in PKG.rglob("*.py") if "papers" not in p.relative_to(PKG).parts[:1]
                   and p.name not in CORE_EXEMPT)
    assert len(files) > 50, f"too few core sources found under {PKG}"
    return files


def test_every_paper_has_brains_under_the_boundary():
    papers = sorted(p.name for p in PKG.glob("papers/*/") if (p / "__init__.py").is_file())
    assert papers == ["beyond", "collab_mcl", "los_help", "robustness", "trails"]
    assert {f"papers/{p}/brains" for p in papers if p != "robustness"} <= set(BRAIN_DIRS)


@pytest.mark.parametrize("path", _core_files(), ids=lambda p: str(p.relative_to(PKG)))
def test_core_imports_no_paper(path):
    hits = forbidden_imports(path.read_text(), _module_name(path), _is_package(path), PAPERS)
    assert not hits, (f"{path.relative_to(PKG)} imports a paper: {hits}; the core finds papers only through "
                      "the teamnav.papers entry-point group (teamnav.plugins)")


@pytest.mark.parametrize(
    ("source", "module"),
    [("from teamnav.papers.los_help.brains import LosExplorer", "teamnav.experiments.runner"),
     ("import teamnav.papers.trails.metrics", "teamnav.cli"),
     ("from teamnav import papers", "teamnav.world.generators"),
     ("from ..papers.beyond import brains", "teamnav.control.registry"),
     ("import importlib\nimportlib.import_module('teamnav.papers.collab_mcl.maps')", "teamnav.world.x")],
)
def test_paper_checker_flags_core_offenders(source, module):
    assert forbidden_imports(source, module, False, PAPERS)


@pytest.mark.parametrize("path", _brain_files(), ids=lambda p: str(p.relative_to(PKG)))
def test_brain_sources_import_no_simulator(path):
    hits = forbidden_imports(path.read_text(), _module_name(path), _is_package(path))
    assert not hits, f"{path.relative_to(PKG)} imports the truth side: {hits}"


@pytest.mark.parametrize("path", _brain_files(), ids=lambda p: str(p.relative_to(PKG)))
def test_brain_sources_read_no_truth(path):
    hits = truth_reads(path.read_text())
    assert not hits, f"{path.relative_to(PKG)} reads something that looks like ground truth: {hits}"


@pytest.mark.parametrize(
    ("source", "module", "is_package"),
    [
        ("import teamnav.sim.engine", "teamnav.control.x", False),
        ("from teamnav.sim import engine", "teamnav.control.x", False),
        ("from teamnav import sim", "teamnav.control.x", False),
        ("from teamnav import cli as c", "teamnav.localization.mcl", False),
        ("from ..sim.engine import Simulation", "teamnav.control.x", False),
        ("from ...viz import plot", "teamnav.control.nav.x", False),
        ("from ... import experiments", "teamnav.control.nav", True),
        ("def f():\n    import importlib\n    return importlib.import_module('teamnav.sim')", "teamnav.control.x", False),
    ],
)
def test_import_checker_flags_offenders(source, module, is_package):
    assert forbidden_imports(source, module, is_package)


@pytest.mark.parametrize(
    "source",
    ["from teamnav.control import types", "from ..geometry import se2", "import teamnav.simulated_thing",
     "from . import wander_kernel"],
)
def test_import_checker_passes_allowed(source):
    assert forbidden_imports(source, "teamnav.control.nav.x") == []


@pytest.mark.parametrize(
    "source",
    ["x = sim.state.x_m[0]", "pose = robot.true_pose", "def f(true_xy):\n    return true_xy",
     "err = est - ground_truth", "f(true_theta=1.0)", "p = self._true_pose", "t = self.state.theta_rad"],
)
def test_truth_checker_flags_offenders(source):
    assert truth_reads(source)


def test_truth_checker_passes_belief():
    assert truth_reads("pose = obs.odom_pose\nx_m = pose[0]\nok = True\nconstrue_x = 1") == []


_PROBE = """
import importlib, json, pkgutil, sys
import teamnav.control, teamnav.localization
pkgs = [teamnav.control, teamnav.localization]
for name in ("los_help", "collab_mcl", "trails", "beyond"):
    pkgs.append(importlib.import_module(f"teamnav.papers.{name}.brains"))
for pkg in pkgs:
    for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
        importlib.import_module(info.name)
print(json.dumps(sorted(m for m in sys.modules if m.startswith("teamnav."))))
"""


def test_importing_every_brain_module_loads_no_simulator():
    out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    loaded = json.loads(out.stdout.strip().splitlines()[-1])
    assert "teamnav.control.nav.wander" in loaded  # the walk really imported the modules
    assert "teamnav.papers.los_help.brains.explorer" in loaded
    bad = [m for m in loaded if any(m == f or m.startswith(f + ".") for f in FORBIDDEN)]
    assert not bad, f"importing the brain packages loaded the truth side: {bad}"


_SWEEP_PARTS = ("teamnav.experiments.sweep", "teamnav.experiments.executors", "teamnav.experiments.store")


@pytest.mark.parametrize(("module", "may_import"), [
    ("teamnav.experiments.trial", ()),
    ("teamnav.experiments.store", ()),
    ("teamnav.experiments.executors", ()),
    ("teamnav.experiments.sweep", ("teamnav.experiments.executors", "teamnav.experiments.store")),
])
def test_sweep_executors_and_store_form_no_circle(module, may_import):
    """Trial, TrialTask and TrialResult live in experiments/trial.py, which all three import:
    the store and the executors need neither the sweep nor each other (not even for types)."""
    path = PKG.parent / (module.replace(".", "/") + ".py")
    banned = tuple(m for m in _SWEEP_PARTS if m != module and m not in may_import)
    hits = forbidden_imports(path.read_text(), module, False, banned)
    assert not hits, f"{module} imports {hits}"
