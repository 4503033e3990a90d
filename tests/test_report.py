"""teamnav report: sections run (or reuse) sweeps and render into one self-contained HTML file;
missing papers and failing sections are shown as missing, never as numbers."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

import teamnav.experiments.report as report
from teamnav.cli import app
from teamnav.experiments.report.context import SweepContext
from teamnav.experiments.report.model import Comparison, MapView, Missing, Plot, SectionSpec, Series, Table, Text
from teamnav.viz.report_figures import mapview_png, plot_png
from teamnav.world import builtin_map

runner = CliRunner()
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: an external resource: src= or href= pointing at http(s):// or a protocol-relative //host
EXTERNAL = re.compile(r"""(?:src|href)\s*=\s*["']?\s*(?:https?:)?//""", re.IGNORECASE)


@pytest.fixture
def sections():
    """Register test sections; unregister them afterwards."""
    added: list[str] = []

    def add(key: str, build, **kw) -> SectionSpec:
        spec = SectionSpec(key=key, title=kw.pop("title", f"Test section {key}"), paper=kw.pop("paper", "test-paper.txt"), build=build, **kw)
        report.register_section(spec)
        added.append(key)
        return spec

    yield add
    for key in added:
        report.unregister_section(key)


def _demo_build(ctx) -> list:
    """A tiny real sweep of the demo scenario (1 s, 2 seeds in quick mode; seed 1 alone in full
    mode, so the full build reuses a quick trial and must see only its own row)."""
    res = ctx.sweep("demo", seeds=2 if ctx.quick else [1], duration_s=1.0, name="fake-demo")
    rows = res.rows()
    grid = builtin_map("office_simple").grid
    x = np.arange(5.0)
    return [
        Text("A paragraph <with> markup to escape."),
        Comparison("trials run", "PAPER-SAYS-379", f"OURS-n={len(rows)}", True, "we differ because of TEST-REASON"),
        Table("Per-trial table", ["seed", "status", "metrics"], [[r["seed"], r["status"], len(r["metrics"] or {})] for r in rows], note="table note"),
        Plot("A plot with bands", "x [s]", "y [m]", [Series("mean", x, x**2, lo=x**2 - 1, hi=x**2 + 1)], hlines=[(4.0, "paper")]),
        MapView("A map", grid, points=[("cloud", np.array([[2.0, 3.0], [4.0, 5.0], [6.0, 7.5]]))], markers=[("R1", 3.0, 3.0)]),
    ]


def _store_rows(out: Path) -> list[tuple]:
    import sqlite3

    con = sqlite3.connect(out / "sweeps" / "fake-demo" / "results.sqlite")
    try:
        return sorted(con.execute("SELECT trial_id, seed, attempts, finished_at FROM trials").fetchall())
    finally:
        con.close()


def test_fake_section_renders_every_block_and_second_build_reuses_the_sweep(tmp_path, sections):
    sections("fake-demo", _demo_build)
    out = tmp_path / "rep"
    res = report.run_report(["fake-demo"], out, quick=True, workers=1, progress=False)
    assert res.ok and res.index == out / "index.html"
    text = res.index.read_text(encoding="utf-8")
    for fragment in ("PAPER-SAYS-379", "OURS-n=2", "TEST-REASON", "Per-trial table", "table note", "A paragraph &lt;with&gt; markup"):
        assert fragment in text, fragment
    imgs = re.findall(r'<img [^>]*src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    assert len(imgs) == 2  # the plot and the map
    import base64

    assert all(base64.b64decode(b).startswith(PNG_MAGIC) for b in imgs)
    assert not EXTERNAL.search(text) and "<script" not in text and "<link" not in text
    assert 'class="holds yes"' in text  # the comparison's ✓
    first = _store_rows(out)
    assert [(seed, attempts) for _, seed, attempts, _ in first] == [(0, 1), (1, 1)]
    summary = json.loads((out / "report.json").read_text())
    first_sweep = summary["sections"][0]["sweeps"][0]
    assert first_sweep | {"elapsed_s": 0, "trials_cpu_s": 0} == {
        "name": "fake-demo", "folder": str(out / "sweeps" / "fake-demo"), "total": 2, "run": 2, "failed": 0, "reused": 0, "elapsed_s": 0,
        "trials_cpu_s": 0, "trials_cpu_measured": 2,
    }
    assert first_sweep["trials_cpu_s"] > 0  # both trials' CPU time, from the store

    # again into the same folder: nothing runs, the store is untouched
    res2 = report.run_report("fake-demo", out, quick=True, workers=1, progress=False)
    assert res2.ok and "OURS-n=2" in res2.index.read_text(encoding="utf-8")
    assert res2.sections[0].sweeps[0]["run"] == 0 and res2.sections[0].sweeps[0]["reused"] == 2
    assert "<td class='num'>0</td><td class='num'>2</td></tr>" in res2.index.read_text(encoding="utf-8")  # footer: run, reused
    assert _store_rows(out) == first

    # the full version shares the sweep folder but sees only its own trial (seed 1, reused)
    res3 = report.run_report("fake-demo", out, quick=False, workers=1, progress=False)
    assert res3.sections[0].sweeps[0]["run"] == 0 and res3.sections[0].sweeps[0]["reused"] == 1
    assert "OURS-n=1" in res3.index.read_text(encoding="utf-8")
    assert _store_rows(out) == first


def test_a_raising_section_is_shown_as_missing_with_its_error_and_the_cli_exits_1(tmp_path, sections):
    sections("fake-fine", lambda ctx: [Text("FINE-SECTION-TEXT")])

    def boom(ctx):
        raise RuntimeError("kaboom 42")

    sections("fake-boom", boom)
    out = tmp_path / "rep"
    result = runner.invoke(app, ["report", "fake-boom", "fake-fine", "--out", str(out), "--quiet"])
    assert result.exit_code == 1, result.output
    assert "fake-boom" in result.stderr and "kaboom 42" in result.stderr
    text = (out / "index.html").read_text(encoding="utf-8")
    assert "FINE-SECTION-TEXT" in text
    boom_html = text[text.index('id="sec-fake-boom"') : text.index('id="sec-fake-fine"')]
    assert re.search(r'class="missing error"><b>not measured:</b> section fake-boom — its build raised RuntimeError: kaboom 42', boom_html)
    statuses = {s["key"]: s["status"] for s in json.loads((out / "report.json").read_text())["sections"]}
    assert statuses == {"fake-boom": "error", "fake-fine": "ok"}


def test_the_report_is_written_after_every_section_with_the_rest_pending(tmp_path, sections):
    seen: dict[str, str] = {}

    def second(ctx):
        seen["index"] = (ctx.out_dir / "index.html").read_text(encoding="utf-8")
        seen["json"] = (ctx.out_dir / "report.json").read_text(encoding="utf-8")
        return [Text("SECOND-DONE")]

    sections("fake-first", lambda ctx: [Text("FIRST-DONE")])
    sections("fake-second", second)
    res = report.run_report(["fake-first", "fake-second"], tmp_path / "r", progress=False)
    assert "FIRST-DONE" in seen["index"] and "SECOND-DONE" not in seen["index"]
    assert "not built yet: the report is still running" in seen["index"]
    assert [s["status"] for s in json.loads(seen["json"])["sections"]] == ["ok", "pending"]
    final = res.index.read_text(encoding="utf-8")
    assert "SECOND-DONE" in final and 'class="status-pending"' not in final and "still running" not in final


def test_a_section_returning_something_else_than_blocks_is_an_error(tmp_path, sections):
    sections("fake-wrong", lambda ctx: [Text("ok"), {"not": "a block"}])
    res = report.run_report("fake-wrong", tmp_path / "r", progress=False)
    assert not res.ok and "block 1 is a dict" in res.errors[0].error


def test_paper_sections_without_a_module_are_missing_not_faked(tmp_path, monkeypatch):
    monkeypatch.setattr(report, "discover_sections", lambda: {})
    res = report.run_report("all", tmp_path / "r", quick=True, progress=False)
    expected = report.expected_sections()
    assert list(expected) == ["los-help", "collab-mcl", "blazing-a-trail", "try-to-see-it-my-way", "robustness", "beyond"]
    assert [s.key for s in res.sections] == list(expected)
    assert res.ok and all(s.status == "missing" for s in res.sections)
    text = res.index.read_text(encoding="utf-8")
    assert text.count("system not built yet") == len(expected)
    for key, (title, paper, _) in expected.items():
        assert f'id="sec-{key}"' in text and paper in text
    assert "<img" not in text and 'class="holds' not in text  # no figure, no verdict invented


def test_a_section_module_that_fails_to_import_is_reported(tmp_path, monkeypatch):
    broken = report._broken_section("collab-mcl", "teamnav.papers.collab_mcl.report.section", "SyntaxError: bad")
    monkeypatch.setattr(report, "discover_sections", lambda: {"collab-mcl": broken})
    res = report.run_report("collab-mcl", tmp_path / "r", progress=False)
    assert not res.ok and "could not be imported: SyntaxError: bad" in res.errors[0].error


def test_cli_unknown_section_gets_did_you_mean_and_exit_2(tmp_path):
    result = runner.invoke(app, ["report", "colab-mcl", "--out", str(tmp_path / "r")])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: ") and "did you mean 'collab-mcl'?" in result.stderr
    assert "Traceback" not in result.output and not (tmp_path / "r").exists()


def test_cli_quick_reaches_the_sections_and_a_report_folder_is_reused(tmp_path, sections):
    seen: list[bool] = []
    sections("fake-quick", lambda ctx: seen.append(ctx.quick) or [Text(f"quick={ctx.quick}")])
    out = tmp_path / "r"
    assert runner.invoke(app, ["report", "fake-quick", "--quick", "--out", str(out), "--quiet"]).exit_code == 0
    assert runner.invoke(app, ["report", "fake-quick", "--out", str(out), "--quiet"]).exit_code == 0
    assert seen == [True, False]
    assert "quick=False" in (out / "index.html").read_text(encoding="utf-8")


def test_cli_refuses_an_out_folder_that_is_not_a_report(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    result = runner.invoke(app, ["report", "all", "--out", str(tmp_path)])
    assert result.exit_code == 2 and "not a report" in result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    result = runner.invoke(app, ["report", "all", "--out", str(tmp_path / "notes.txt")])
    assert result.exit_code == 2 and "existing file" in result.stderr
    result = runner.invoke(app, ["report", "all", "--out", str(tmp_path / "new"), "--executor", "slurm"])
    assert result.exit_code == 2 and "executor" in result.stderr


def test_ctx_sweep_refuses_report_owned_arguments(tmp_path):
    ctx = SweepContext(tmp_path, quick=True)
    with pytest.raises(TypeError, match="workers is set by the report"):
        ctx.sweep("demo", workers=4)


def test_figures_draw_categories_bars_and_steps_and_reject_bad_series():
    plot = Plot(
        "bars",
        "helpers",
        "steps",
        [
            Series("Avoid-Past", ["0", "1", "2", "3"], [554, 426, 302, 257], lo=[500, 400, 280, 240], hi=[600, 450, 320, 270], style="bar"),
            Series("VisBug", ["0", "1", "2", "3"], [841, 294, 255, 201], style="bar"),
            Series("level", ["0", "3"], [300, 300], style="step"),
        ],
        logy=True,
    )
    assert plot_png(plot).startswith(PNG_MAGIC)
    with pytest.raises(ValueError, match="'a': hi has 2 values; expected 3"):
        plot_png(Plot("p", "x", "y", [Series("a", [0, 1, 2], [1, 2, 3], lo=[0, 1, 2], hi=[2, 3])]))
    with pytest.raises(ValueError, match="style expected one of"):
        plot_png(Plot("p", "x", "y", [Series("a", [0], [1], style="pie")]))
    with pytest.raises(ValueError, match=r"expected shape \(n, 2\)"):
        mapview_png(MapView("m", None, points=[("bad", np.zeros((3, 1)))]))
    assert mapview_png(MapView("m", None, markers=[("R", 0.0, 0.0)])).startswith(PNG_MAGIC)


def test_a_figure_that_cannot_be_drawn_becomes_a_missing_box(tmp_path, sections):
    sections("fake-badplot", lambda ctx: [Plot("broken", "x", "y", [Series("a", [0, 1], [1])]), Text("AFTER-THE-PLOT")])
    res = report.run_report("fake-badplot", tmp_path / "r", progress=False)
    text = res.index.read_text(encoding="utf-8")
    assert "figure &#x27;broken&#x27;" in text and "could not be drawn" in text and "AFTER-THE-PLOT" in text


@pytest.mark.slow
def test_report_all_quick_has_every_paper_section(tmp_path):
    """The whole-report check: `teamnav report all --quick` writes a report in which each of
    the four papers is present, as results or as missing, and no section raised. It runs every
    section's quick sweeps (6-11 min on 2 cores), so it is in the slow set."""
    out = tmp_path / "quick"
    result = runner.invoke(app, ["report", "all", "--quick", "--out", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    text = (out / "index.html").read_text(encoding="utf-8")
    summary = {s["key"]: s for s in json.loads((out / "report.json").read_text())["sections"]}
    for key in report.expected_sections():
        assert f'id="sec-{key}"' in text, key
        assert summary[key]["status"] in ("ok", "missing"), (key, summary[key]["error"])
        if summary[key]["status"] == "missing":
            assert summary[key]["missing"], key
    assert not EXTERNAL.search(text)
