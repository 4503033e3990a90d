"""The collision metric counts the same overlapping pairs with its two methods: every pair
at once (small teams, no scipy.spatial import) and the k-d tree (larger teams)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from teamnav.experiments import metrics as M
from teamnav.world.grid import OccupancyGrid


@pytest.mark.parametrize("n", [2, 7, 30])
def test_all_pairs_and_the_kd_tree_count_the_same_overlaps(n, monkeypatch):
    rng = np.random.default_rng(n)
    T = 300
    xy = rng.uniform(2.0, 2.0 + 0.6 * np.sqrt(n), (T, n, 2))  # crowded: many overlaps, many near misses
    data = SimpleNamespace(grid=OccupancyGrid.empty(20.0, 20.0, 0.1), true_pose=np.concatenate([xy, np.zeros((T, n, 1))], axis=2),
                           radius_m=rng.uniform(0.1, 0.4, n), n_robots=n)
    all_pairs = M.collisions(data)
    monkeypatch.setattr(M, "_ALL_PAIRS_MAX", 1)
    kd_tree = M.collisions(data)
    assert all_pairs == kd_tree
    assert all_pairs["collisions_robot"] > 0
