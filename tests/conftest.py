"""Hypothesis profiles: ``ci`` (reproducible, bounded) and ``dev`` (random, remembers failures).

``ci``: every run draws the same examples (``derandomize``), a fixed ``max_examples``
(a test's own ``@settings(max_examples=...)`` still wins), no example database (nothing read
from or written to ``.hypothesis/``) and no deadline (a shared 2-core machine's timing is not a
test result). The README's test command and ``.ci/run`` pass ``--hypothesis-profile=ci``.

``dev``: random examples, the example database under ``.hypothesis/`` (a failure found once is
tried first next time), Hypothesis' default ``max_examples``; no deadline either.

Without ``--hypothesis-profile`` the profile is ``$HYPOTHESIS_PROFILE`` if set, else ``ci`` when
``$CI`` is set (as CI services do), else ``dev``.
"""

from __future__ import annotations

import os

import pytest
from hypothesis import settings

# parent: Hypothesis' own defaults (else a profile inherits from whichever profile is loaded)
_defaults = settings.get_profile("default")
settings.register_profile("ci", _defaults, derandomize=True, max_examples=50, database=None, deadline=None, print_blob=True)
settings.register_profile("dev", _defaults, deadline=None)


def _default_profile() -> str:
    chosen = os.environ.get("HYPOTHESIS_PROFILE")
    if chosen:
        return chosen
    return "ci" if os.environ.get("CI") else "dev"


settings.load_profile(_default_profile())


@pytest.fixture
def memo_scenario_yaml(monkeypatch):
    """Parse each scenario YAML text once per test (each caller gets its own deep copy).

    For tests that expand hundreds of trials of the same few scenario files (a report section's
    full build with faked sweeps): the pure-Python YAML parse of the same text is most of their
    time and none of what they check."""
    import copy
    import functools

    from teamnav.experiments import spec

    parse = functools.lru_cache(maxsize=None)(spec.read_yaml)
    monkeypatch.setattr(spec, "read_yaml", lambda text: copy.deepcopy(parse(text)))


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    """A real, tiny run folder (2 robots, 1 s) for the tests that read or probe one."""
    from typer.testing import CliRunner

    from teamnav.cli import app

    out = tmp_path_factory.mktemp("run") / "demo"
    res = CliRunner().invoke(app, ["run", "demo", "--duration", "1", "--set", "robots.0.count=2", "--out", str(out),
                                   "--quiet"])
    assert res.exit_code == 0, res.output
    return out
