"""``--group-brains`` on ``teamnav run``, ``teamnav sweep`` and ``teamnav report``: the option
reaches every trial's run (and so the engine), and changes nothing a sweep stores: the same
trial ids, configuration hashes and metrics (``docs/concepts/group-brains.md``: a run with group
brains is the same run, bit for bit, so stored trials are shared).

The trials are R1 alone on office_simple with Avoid-Past (the first compiled piece), 300 steps.
"""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import typer
from typer.testing import CliRunner

from teamnav.experiments.executors import LocalExecutor
from teamnav.experiments.report.context import SweepContext
from teamnav.experiments.sweep import sweep
from teamnav.experiments.sweep_cli import sweep_command

R1_ALONE = ["robots.0.params.navigator=avoid_past", "robots.1.count=0", "robots.2.count=0", "robots.3.count=0"]
DURATION_S = 30.0  # 300 steps


def probe_trial(scenario, out_dir):
    """A full run (``run`` without ``group_brains``: the process default the sweep sets), its
    metrics, and what the engine built: how many teams a group brain steps, and R1's class."""
    from teamnav.experiments.runner import run

    res = run(scenario, progress=False)
    return {**res.metrics, "probe_group_teams": len(res.sim.group_teams),
            "probe_r1_class": type(res.sim.brains[0][0]).__name__}


def _rows(out: Path) -> list[dict]:
    con = sqlite3.connect(out / "results.sqlite")
    con.row_factory = sqlite3.Row
    try:
        rows = [dict(r) for r in con.execute("SELECT * FROM trials ORDER BY trial_id")]
    finally:
        con.close()
    # what a run's identity and results are (not when, where, how long, or how often it ran)
    drop = {"started_at", "finished_at", "wall_time_s", "cpu_time_s", "host", "pid", "attempts", "retries",
            "retry_errors", "stored_at"}
    out = []
    for r in rows:
        r = {k: v for k, v in r.items() if k not in drop and not k.startswith("probe_")}
        r["metrics"] = {k: v for k, v in json.loads(r["metrics"]).items() if not k.startswith("probe_")}
        out.append(r)
    return out


def _app() -> typer.Typer:
    app = typer.Typer()

    @app.callback()
    def _root() -> None:
        """test app"""

    app.command("sweep")(sweep_command)
    return app


def test_a_flagged_sweep_stores_the_same_trials_and_reaches_the_engine(tmp_path):
    # the CLI: the same stored rows (ids, configuration hash, every metric) with and without the flag
    base = ["sweep", "los-help-simple", *[a for s in R1_ALONE for a in ("--set", s)], "--seeds", "1000-1000",
            "--duration", str(DURATION_S), "-j", "1", "-q"]
    plain = CliRunner().invoke(_app(), [*base, "--out", str(tmp_path / "plain")])
    flagged = CliRunner().invoke(_app(), [*base, "--out", str(tmp_path / "flagged"), "--group-brains"])
    assert plain.exit_code == 0 and flagged.exit_code == 0, (plain.output, flagged.output)
    rows_plain, rows_flagged = _rows(tmp_path / "plain"), _rows(tmp_path / "flagged")
    assert len(rows_plain) == 1 and rows_plain[0]["status"] == "ok"
    assert rows_plain[0]["steps"] == int(DURATION_S * 10)
    assert rows_flagged == rows_plain
    # a rerun with the flag into the unflagged store reuses its trial (the same id)
    again = CliRunner().invoke(_app(), [*base, "--out", str(tmp_path / "plain"), "--group-brains"])
    assert again.exit_code == 0 and "0 ok, 0 failed, 1 skipped" in again.output

    # the flag reaches the engine in the worker, through a section's own trial function too
    # (the report's context passes it to every sweep); without it, the per-robot brains run
    kw = {"set": R1_ALONE, "seeds": [1000], "duration_s": DURATION_S, "trial_fn": probe_trial}
    shared = LocalExecutor(1, keep_pool=True)  # one worker start for both sweeps, as a report shares it
    try:
        sweep("los-help-simple", out_dir=tmp_path / "probe_plain", executor=shared, progress=False, **kw)
        ctx = SweepContext(tmp_path / "report", runner=shared, group_brains=True)
        res = ctx.sweep("los-help-simple", **kw)
    finally:
        shared.close()
    con = sqlite3.connect(res.store_path)
    got = con.execute("SELECT probe_group_teams, probe_r1_class FROM trials").fetchall()
    con.close()
    assert got == [(1, "_R1View")]
    con = sqlite3.connect(tmp_path / "probe_plain" / "results.sqlite")
    got = con.execute("SELECT probe_group_teams, probe_r1_class FROM trials").fetchall()
    con.close()
    assert got == [(0, "LosExplorer")]
    assert _rows(tmp_path / "probe_plain") == _rows(Path(res.store_path).parent) == rows_plain


def test_the_report_owns_the_option_and_run_and_report_pass_it(monkeypatch, tmp_path):
    """A section cannot set ``group_brains`` on its own sweeps (the report does, for all), and
    ``teamnav run`` / ``teamnav report --group-brains`` hand it on."""
    import pytest

    import teamnav.experiments.report as report_mod
    import teamnav.experiments.runner as runner_mod
    from teamnav.cli import app

    with pytest.raises(TypeError, match="group_brains is set by the report"):
        SweepContext(tmp_path).sweep("los-help-simple", group_brains=True)

    seen = {}

    class _Stop(Exception):
        """Ends the probe trial once the engine's brains are seen."""

    def fake_run(scn, **kw):
        seen["run"] = kw.get("group_brains")
        raise _Stop

    def fake_report(names, out, **kw):
        seen["report"] = kw.get("group_brains")
        raise _Stop

    monkeypatch.setattr(runner_mod, "run", fake_run)
    monkeypatch.setattr(report_mod, "run_report", fake_report)
    for args, key, want in (
        (["run", "los-help-simple", "-q", "--group-brains"], "run", True),
        (["run", "los-help-simple", "-q"], "run", False),
        (["report", "los-help", "--quick", "--out", str(tmp_path / "r"), "--group-brains"], "report", True),
        (["report", "los-help", "--quick", "--out", str(tmp_path / "r")], "report", False),
    ):
        seen.clear()
        r = CliRunner().invoke(app, args)
        assert isinstance(r.exception, _Stop), (args, r.output)
        assert seen[key] is want, args


def test_run_follows_the_process_default_only_when_not_told():
    from teamnav import load_scenario
    from teamnav.experiments.runner import group_brains_default, run

    scn = load_scenario("los-help-simple", overrides=R1_ALONE, duration_s=0.3, seed=0)
    with group_brains_default(True):
        assert len(run(scn, progress=False).sim.group_teams) == 1
        assert len(run(scn, progress=False, group_brains=False).sim.group_teams) == 0
    assert len(run(scn, progress=False).sim.group_teams) == 0
