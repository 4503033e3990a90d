"""What users rely on does not change when code moves: names, hashes, trial ids, ``teamnav list``.

``tests/data/user_surface.json`` was recorded before each paper moved into its own folder
(``teamnav/papers/<paper>/``). Every scenario's config hash and every named sweep's trial ids
and config hashes must stay equal, or stored results would no longer be reused; the names of
scenarios, controllers, maps, metrics (in registration order, which orders ``metrics.json``),
sweeps, report sections and claims, and ``teamnav list --json``, must stay as users know them.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

RECORDED = json.loads((Path(__file__).parent / "data" / "user_surface.json").read_text())


@pytest.fixture(scope="module")
def now() -> dict:
    """Gathered in a fresh process: other tests register controllers and sections in theirs."""
    out = subprocess.run([sys.executable, str(Path(__file__).with_name("_user_surface.py"))], capture_output=True,
                         text=True, timeout=900)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


@pytest.mark.parametrize("key", ["controllers", "metrics", "sections", "claims", "list_json"])
def test_names_users_know_are_unchanged(now, key):
    assert now[key] == RECORDED[key]


def test_every_scenario_config_hash_is_unchanged(now):
    changed = {n: (RECORDED["scenario_hashes"].get(n), h) for n, h in now["scenario_hashes"].items()
               if RECORDED["scenario_hashes"].get(n) != h}
    assert sorted(now["scenario_hashes"]) == sorted(RECORDED["scenario_hashes"])
    assert not changed, f"config hashes changed (stored results would not be reused): {changed}"


def test_every_named_sweep_keeps_its_trial_ids_and_hashes(now):
    assert sorted(now["sweeps"]) == sorted(RECORDED["sweeps"])
    changed = [n for n in now["sweeps"] if now["sweeps"][n] != RECORDED["sweeps"][n]]
    assert not changed, f"trial ids or config hashes changed in sweeps {changed}"
    assert sum(len(v) for v in now["sweeps"].values()) > 2000  # every trial of every sweep was expanded
