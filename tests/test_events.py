"""Place events: "enter" fires once per entry, "inside" every step, markers fire nothing."""

from __future__ import annotations

import numpy as np

from teamnav.sim.config import PlaceConfig
from teamnav.sim.events import Places

HOME = PlaceConfig(name="home", x_m=0.0, y_m=0.0, radius_m=1.0, event="took_resource")
SOURCE = PlaceConfig(name="source", x_m=10.0, y_m=0.0, radius_m=1.0, event="given_resource", on="inside")
MARK = PlaceConfig(name="mark", x_m=5.0, y_m=0.0, radius_m=1.0)


def _path(places, xs_per_step, start_x):
    p = Places(places, np.array(start_x, float), np.zeros(len(start_x)))
    out = []
    for k, xs in enumerate(xs_per_step, start=1):
        xs = np.array(xs, float)
        out.append(p.update(k, 0.1 * k, xs, np.zeros(len(xs))))
    return p, out


def test_enter_fires_once_and_again_only_after_leaving():
    xs = [[2.0], [1.0], [0.5], [0.0], [1.5], [0.9], [0.9]]
    p, out = _path([HOME], xs, [3.0])
    fired = [o[0] for o in out]
    assert fired == [(), ("took_resource",), (), (), (), ("took_resource",), ()]  # 1.0 m is inside (inclusive)
    assert [(e["step"], e["robot"], e["place"], e["event"]) for e in p.log] == [
        (2, 0, "home", "took_resource"), (6, 0, "home", "took_resource")
    ]


def test_robot_starting_inside_fires_after_reentering():
    p, out = _path([HOME], [[0.2], [2.0], [0.2]], [0.0])
    assert [o[0] for o in out] == [(), (), ("took_resource",)]


def test_inside_fires_every_step_and_markers_never():
    p, out = _path([SOURCE, MARK], [[10.0], [10.5], [5.0], [12.0]], [8.0])
    assert [o[0] for o in out] == [("given_resource",), ("given_resource",), (), ()]
    assert not any(e["place"] == "mark" for e in p.log)


def test_several_robots_and_places_in_one_step():
    p = Places([HOME, SOURCE], np.array([5.0, 5.0, 5.0]), np.zeros(3))
    out = p.update(1, 0.1, np.array([0.0, 10.0, 5.0]), np.zeros(3))
    assert out == [("took_resource",), ("given_resource",), ()]
    assert [e["robot"] for e in p.log] == [0, 1]


def test_no_places_is_inactive():
    p = Places([MARK], np.zeros(2), np.zeros(2))
    assert not p.active and p.update(1, 0.1, np.zeros(2), np.zeros(2)) == [(), ()]
