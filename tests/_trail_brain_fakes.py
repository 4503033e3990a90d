"""Test doubles shared by the trail brains' tests (test_crumbs.py, test_trails.py)."""

from __future__ import annotations

import numpy as np

from teamnav.control.check import synthetic_infos
from teamnav.control.types import Observation, RangeScan


class RecordingNav:
    """Stands in for Navigate: records the preferred headings, reversal vetoes and turn-arounds
    it is handed."""

    def __init__(self, params, rng, info, laser="laser"):
        self.headings = []
        self.allow_reverse = []
        self.ignore_memory = []  # reverse_ignore_memory of each step
        self.turn_arounds = []  # leave_m of each turn_around call
        self.mode = "fake"
        self.leaving = False  # never in a turn_around's drive-off

    def step(self, obs, preferred_heading_rad=None, *, allow_reverse=True, reverse_ignore_memory=False):
        self.headings.append(preferred_heading_rad)
        self.allow_reverse.append(allow_reverse)
        self.ignore_memory.append(reverse_ignore_memory)
        return 0.3, 0.0

    def turn_around(self, leave_m=0.0):
        self.turn_arounds.append((len(self.headings), leave_m))


def make_obs(robot_id, step, pose, events=(), inbox=()):
    """An observation with a clear 8 m laser scan at odometry ``pose``."""
    angles = np.linspace(-np.pi / 2, np.pi / 2, 181)
    scan = RangeScan(np.full(181, 8.0), angles, 8.0)
    return Observation(robot_id, step, step * 0.1, np.asarray(pose, float), np.zeros(3), scans={"laser": scan},
                       events=tuple(events), inbox=tuple(inbox))


def make_brains(monkeypatch, module, cls, n=2, **params):
    """``n`` brains of class ``cls`` (defined in ``module``) driving a :class:`RecordingNav`."""
    monkeypatch.setattr(module, "Navigate", RecordingNav)
    infos = synthetic_infos(n)
    p = cls.Params(**params)
    return [cls(p, np.random.default_rng(i), infos[i]) for i in range(n)]
