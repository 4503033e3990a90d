"""Import paths of the papers' modules before each paper got its folder still work for one
release: each gives the module at its new path (the same object, never a second copy) and warns
with a DeprecationWarning naming the new path."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from teamnav._moved_paths import MOVED

_PROBE = r"""
import importlib, json, sys, warnings
from teamnav._moved_paths import MOVED
out = {}
for old in sorted(MOVED):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mod = importlib.import_module(old)
    new = importlib.import_module(MOVED[old])
    out[old] = {"same": mod is new, "name": mod.__name__,
                "warned": [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]}
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def imported() -> dict:
    res = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1])


def test_the_table_covers_the_paths_users_saw():
    for old in ("teamnav.control.coop.los_help", "teamnav.control.coop.los_help.explorer",
                "teamnav.control.localizing", "teamnav.control.coop.blazing_trail", "teamnav.control.beyond.localized",
                "teamnav.experiments.los_tasks", "teamnav.experiments.report.sections.los_help",
                "teamnav.experiments.metric_sets.trails", "teamnav.world.maps_trails"):
        assert old in MOVED, old
    assert all(new.startswith("teamnav.papers.") for new in MOVED.values())


def test_every_old_path_gives_the_new_module_with_a_warning(imported):
    assert set(imported) == set(MOVED)
    for old, got in imported.items():
        assert got["same"] and got["name"] == MOVED[old], (old, got)
    # a path is warned about once, when first imported (a package warns for itself, not again for its modules)
    warned = [w for got in imported.values() for w in got["warned"]]
    assert "teamnav.control.coop.los_help.explorer moved to teamnav.papers.los_help.brains.explorer" in " ".join(warned)
    assert all("the old path works for one release" in w for w in warned if "moved to" in w)


def test_old_map_factories_on_generators_warn_and_build():
    import teamnav.world.generators as gen

    with pytest.warns(DeprecationWarning, match="moved to teamnav.papers.collab_mcl.maps.hexagon"):
        hexagon = gen.hexagon
    assert hexagon().grid.shape == (150, 170)
    with pytest.raises(AttributeError, match="no attribute 'no_such_map'"):
        gen.no_such_map  # noqa: B018
