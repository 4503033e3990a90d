"""The ARGoS peer's experiment is the arena of teamnav's swarm benchmark (benchmarks/peers/argos_peer.py).

A speed ratio against ARGoS means something only when both simulate the same world: N robots
in a walled square of side sqrt(N) m. These tests read the XML the peer hands to ``argos3``.
"""

from __future__ import annotations

import importlib.util
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given, settings, strategies as st

ROOT = Path(__file__).resolve().parents[1]


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


argos_peer = _load("argos_peer", ROOT / "benchmarks" / "peers" / "argos_peer.py")


def _floats(text: str) -> list[float]:
    return [float(v) for v in text.split(",")]


@settings(max_examples=30, deadline=None)
@given(n=st.integers(1, 20000), ticks=st.integers(1, 5000), threads=st.integers(0, 8))
def test_the_experiment_is_the_swarm_arena(n, ticks, threads):
    root = ET.fromstring(argos_peer.experiment_xml(n, ticks, threads, Path("/lib/x.so")))
    exp = root.find("framework/experiment")
    assert float(exp.get("length")) * int(exp.get("ticks_per_second")) == pytest.approx(ticks)
    assert int(root.find("framework/system").get("threads")) == threads
    assert int(root.find("arena/distribute/entity").get("quantity")) == n
    side = math.sqrt(n)
    faces = []
    for box in root.findall("arena/box"):
        size = _floats(box.get("size"))
        pos = _floats(box.find("body").get("position"))
        axis = 0 if size[0] < size[1] else 1  # the wall's thin axis
        faces.append(abs(pos[axis]) - size[axis] / 2)  # its inner face's distance from the centre
        assert max(size[:2]) >= side  # each wall spans the side
    assert faces == pytest.approx([side / 2] * 4, abs=2e-3)  # the free square is sqrt(N) m wide, as teamnav's arena
    lo = _floats(root.find("arena/distribute/position").get("min"))
    hi = _floats(root.find("arena/distribute/position").get("max"))
    radius = 0.085  # the foot-bot's body
    assert hi[0] + radius <= side / 2 + 1e-3 and lo[0] - radius >= -side / 2 - 1e-3  # robots start inside the walls


def test_a_bad_size_is_refused():
    with pytest.raises(ValueError, match="robots and ticks must be >= 1"):
        argos_peer.experiment_xml(0, 10, 0, Path("/lib/x.so"))


def test_a_missing_build_names_the_prefix(tmp_path):
    with pytest.raises(SystemExit, match=str(tmp_path)):
        argos_peer.run_once(tmp_path, 10, 10, 0, 10.0)
