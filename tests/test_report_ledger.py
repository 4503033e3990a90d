"""The one shape of a section's fidelity record (shared/FIDELITY.md §2), defined in the report
model: comparisons name their column, a ledger row says where each parameter comes from, a
precondition says what was checked on which tuning seeds; report.json and the HTML carry them."""

from __future__ import annotations

import json

import pytest

from teamnav.experiments import report
from teamnav.experiments.report.model import (
    COLUMNS,
    LEDGER_SOURCES,
    Comparison,
    Ledger,
    LedgerRow,
    Precondition,
    SectionSpec,
)

ROWS = (
    LedgerRow("paper", "cruise_speed_mps", 0.4, "implied", "2000 §5: a 33 m route and a ~3 min round trip"),
    LedgerRow("paper", "reverse_carried_crumbs", True, "stated", "2002 §1: 'followed ... backwards towards home'"),
    LedgerRow("paper", "reverse_carried_crumbs", False, "literal-ablation", "2000 §4.1 read literally"),
    LedgerRow("teamnav", "lookahead_m", (1.0, 2.0), "fill", "rule in sweep x, seeds 1000-1009"),
)


@pytest.fixture
def ledger_section():
    def build(ctx):
        return [
            Comparison("claim A", "28 units", "27 ± 2 (n = 10)", True, column="paper"),
            Comparison("claim A", "28 units", "31 ± 1 (n = 10)", True, column="teamnav"),
            Ledger(ROWS),
            Precondition("Robin alone is still ambiguous when it passes the lab", "1000-1009", "9/10 ambiguous",
                         True, claims=("single-detection",)),
        ]

    report.register_section(SectionSpec(key="ledger-test", title="Ledger test", paper="p.txt", build=build))
    yield
    report.unregister_section("ledger-test")


def test_report_json_carries_columns_ledger_and_precondition(tmp_path, ledger_section):
    res = report.run_report("ledger-test", tmp_path / "r", progress=False)
    assert res.ok
    sec = {s["key"]: s for s in json.loads((tmp_path / "r" / "report.json").read_text())["sections"]}["ledger-test"]
    assert [c["column"] for c in sec["comparisons"]] == ["paper", "teamnav"]
    assert [(r["column"], r["name"], r["source"]) for r in sec["ledger"]] == [
        ("paper", "cruise_speed_mps", "implied"), ("paper", "reverse_carried_crumbs", "stated"),
        ("paper", "reverse_carried_crumbs", "literal-ablation"), ("teamnav", "lookahead_m", "fill")]
    assert sec["ledger"][3]["value"] == "(1.0, 2.0)"  # a value JSON cannot hold is written as its repr
    assert sec["precondition"] == [{"what": "Robin alone is still ambiguous when it passes the lab",
                                    "seeds": "1000-1009", "result": "9/10 ambiguous", "holds": True,
                                    "claims": ["single-detection"]}]
    html = (tmp_path / "r" / "index.html").read_text()
    assert "Ledger: where each parameter comes from" in html and "literal-ablation" in html
    assert "precondition" in html and "checked on 1000-1009" in html
    assert "<th>column</th>" in html and COLUMNS["paper"] in html


def test_sections_without_a_ledger_carry_empty_lists(tmp_path, ledger_section):
    report.register_section(SectionSpec(key="plain-test", title="Plain", paper="", build=lambda ctx: [
        Comparison("c", "p", "o", None)]), replace=True)
    try:
        report.run_report("plain-test", tmp_path / "r", progress=False)
    finally:
        report.unregister_section("plain-test")
    sec = json.loads((tmp_path / "r" / "report.json").read_text())["sections"][0]
    assert sec["ledger"] == [] and sec["precondition"] == [] and sec["comparisons"][0]["column"] is None
    assert "<th>column</th>" not in (tmp_path / "r" / "index.html").read_text()


@pytest.mark.parametrize("source", ["guessed", "Stated", "", "fill "])
def test_a_ledger_row_with_an_unknown_source_is_refused(source):
    with pytest.raises(ValueError, match="source must be one of " + ", ".join(LEDGER_SOURCES)):
        LedgerRow("paper", "sigma_hit_m", 0.2, source, "somewhere")


@pytest.mark.parametrize("ref", ["", "   "])
def test_a_ledger_row_must_say_where_its_value_comes_from(ref):
    with pytest.raises(ValueError, match="ref must say where the value comes from"):
        LedgerRow("paper", "sigma_hit_m", 0.2, "fill", ref)


@pytest.mark.parametrize("column", ["paper_rules", "ours", "", None])
def test_columns_are_the_two_the_report_knows(column):
    with pytest.raises(ValueError, match="column must be one of 'paper', 'teamnav'"):
        LedgerRow(column, "x", 1, "stated", "§1")
    if column is not None:
        with pytest.raises(ValueError, match="column must be one of"):
            Comparison("c", "p", "o", True, column=column)
