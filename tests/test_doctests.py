"""The numpydoc Examples in every teamnav module run and give what they show (STYLE habit 13).

Run through :mod:`doctest` over the *installed* package, so CI checks the same files users get.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

import teamnav

MODULES = sorted(
    m.name for m in pkgutil.walk_packages(teamnav.__path__, prefix="teamnav.")
    if not m.name.endswith("__main__")
)


@pytest.mark.parametrize("name", MODULES)
def test_module_examples(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} doctest examples failed (see output)"


def test_examples_exist():
    """Guard against the walk finding nothing (the check above would pass vacuously)."""
    attempted = 0
    for name in ("teamnav.geometry.angles", "teamnav.world.los", "teamnav.papers.los_help.brains.goal_sharing"):
        attempted += doctest.testmod(importlib.import_module(name), verbose=False).attempted
    assert attempted >= 5
