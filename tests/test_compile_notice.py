"""`teamnav run` says when numba really compiles (numba's compile events), not when it loads
its cache: the plain progress lines show it while it lasts, a terminal gets one line."""

from __future__ import annotations

import io
from types import SimpleNamespace

import numba
import pytest

from teamnav.experiments import runner

SCN = SimpleNamespace(name="demo", n_robots=2)


def _fresh_kernel():
    # a new function each call, no cache: calling it compiles for real
    @numba.njit(cache=False)
    def add_one(x):
        return x + 1

    return add_one


def test_plain_lines_say_compiling_while_numba_compiles(monkeypatch):
    monkeypatch.setattr("teamnav.experiments.progress.stderr_is_terminal", lambda: False)
    rep = runner._Progress(None, 10, SCN)
    phases = []
    monkeypatch.setattr(rep.plain, "phase", phases.append)
    try:
        with rep.watching_compiles():
            assert _fresh_kernel()(1) == 2
    finally:
        rep.close()
    assert phases[0] == runner.COMPILING and phases[-1] != runner.COMPILING
    assert "first run only" in runner.COMPILING


def test_a_cache_load_or_a_compiled_kernel_says_nothing(monkeypatch):
    monkeypatch.setattr("teamnav.experiments.progress.stderr_is_terminal", lambda: False)
    kernel = _fresh_kernel()
    kernel(1)  # compiled before the watch
    rep = runner._Progress(None, 10, SCN)
    phases = []
    monkeypatch.setattr(rep.plain, "phase", phases.append)
    try:
        with rep.watching_compiles():
            kernel(2)
    finally:
        rep.close()
    assert phases == []


def test_a_terminal_gets_one_line(monkeypatch):
    monkeypatch.setattr("teamnav.experiments.progress.stderr_is_terminal", lambda: True)
    err = io.StringIO()
    monkeypatch.setattr(runner.sys, "stderr", err)
    rep = runner._Progress(None, 10, SCN)
    try:
        with rep.watching_compiles():
            _fresh_kernel()(1)
            _fresh_kernel()(1)
    finally:
        rep.close()
    assert err.getvalue().count("compiling numba kernels") == 1
    assert err.getvalue().startswith("demo (2 robots): compiling numba kernels (first run only")


@pytest.mark.parametrize("progress", [False, lambda k: None])
def test_no_progress_no_listener(progress, capsys):
    """Without a progress display (quiet, or the caller's own callback) a compile says nothing."""
    rep = runner._Progress(progress, 10, SCN)
    with rep.watching_compiles():
        assert _fresh_kernel()(1) == 2
    rep.close()
    assert rep.bar is None and rep.plain is None and not rep.told_compiling
    assert "compiling" not in capsys.readouterr().err
