"""One key, one place: a sweep stores the labels its trials ran, whatever the key's spelling.

``apply_overrides`` reads a list index by its value, so ``robots.0.count``, ``robots.00.count``,
``robots.\u0660.count`` (Arabic-Indic zero), ``robots.\uff10.count`` (full-width zero) and
`` robots.0.count `` (blanks around the key) all set the same field. A sweep compares and stores
keys in one canonical spelling, refuses one field given twice (two grid axes, a grid axis and
set:/cases:, set: and cases: unless ``cases_replace_set`` says the cases win) and runs once,
with a warning, grid values and cases that resolve to the same scenario.
"""

from __future__ import annotations

import json
import sqlite3
import textwrap
import warnings
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from teamnav.experiments.spec import apply_overrides, canonical_key, load_scenario
from teamnav.experiments.sweep import SweepError, SweepSpec, SweepWarning, expand, load_sweep, resolve_spec, sweep

#: every spelling of index 0 that apply_overrides accepts (decimal digits of any script, leading zeros)
ZEROS = ["0", "00", "000", "\u0660", "\uff10", "\u0966", "0\u0660"]
#: blanks that apply_overrides strips around a whole key
BLANKS = ["", " ", "  ", "\t"]


def ran_trial(scenario, out_dir):
    """What the trial really ran, read from its resolved scenario."""
    return {"ran_count": scenario.robots[0].count, "ran_range_m": scenario.robots[0].sensors[0].max_range_m,
            "ran_speed": scenario.robots[0].params["cruise_speed_mps"]}


def spellings(field: str):
    """A strategy of spellings of ``robots.0.<field>``."""
    return st.builds(lambda z, a, b: f"{a}robots.{z}.{field}{b}", st.sampled_from(ZEROS), st.sampled_from(BLANKS),
                     st.sampled_from(BLANKS))


# ---------------------------------------------------------------------------- the spellings
@given(spelt=spellings("count"), value=st.integers(1, 5))
@settings(max_examples=30, deadline=None)
def test_every_spelling_apply_overrides_accepts_is_one_canonical_key(spelt, value):
    assert canonical_key(spelt) == "robots.0.count"
    data = {"robots": [{"count": 8}]}
    notes = apply_overrides(data, {spelt: value})
    assert data == {"robots": [{"count": value}]}
    assert list(notes) == ["robots[0].count"]


def test_the_spellings_set_the_field_in_a_real_scenario():
    for z in ZEROS:
        for form in ({f" robots.{z}.count ": 2}, [f" robots.{z}.count =2"]):
            assert load_scenario("demo", overrides=form, duration_s=1).robots[0].count == 2


def test_what_is_not_an_alias_stays_refused():
    from teamnav.experiments.errors import ScenarioError

    # brackets, blanks inside a part, a sign, a superscript digit (it used to crash in int())
    for key in ["robots[0].count", "robots. 0.count", "robots.+0.count", "robots.\u00b2.count"]:
        with pytest.raises(ScenarioError):
            load_scenario("demo", overrides={key: 2}, duration_s=1)
    assert canonical_key("robots.\u00b2.count") == "robots.\u00b2.count"


# ---------------------------------------------------------------------------- refused: one field twice
LAYERS = ["grid", "set", "case"]


def _sweep_file(tmp_path: Path, layers: dict[str, str]) -> Path:
    """A sweep file giving robots.0.count in each layer of ``layers`` (layer -> spelling)."""
    lines = ["scenario: demo", "duration_s: 1"]
    if "grid" in layers:
        lines.append(f"grid: {{{json.dumps(layers['grid'])}: [1, 2]}}")
    if "grid2" in layers:
        lines[-1] = f"grid: {{{json.dumps(layers['grid'])}: [1, 2], {json.dumps(layers['grid2'])}: [3]}}"
    if "set" in layers:
        lines.append(f"set: {{{json.dumps(layers['set'])}: 3}}")
    if "case" in layers:
        lines.append(f"cases: [{{case: a, {json.dumps(layers['case'])}: 4}}]")
    path = tmp_path / "s.yaml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


@given(pair=st.sampled_from([("grid", "grid2"), ("grid", "set"), ("grid", "case"), ("set", "case")]),
       a=spellings("count"), b=spellings("count"))
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
def test_one_field_in_two_places_is_refused_naming_both_spellings_and_the_file(tmp_path, pair, a, b):
    if pair == ("grid", "grid2") and a.strip() == b.strip():
        b = "robots.00.count" if a.strip() != "robots.00.count" else "robots.0.count"
    path = _sweep_file(tmp_path, {pair[0]: a, pair[1]: b})
    with pytest.raises(SweepError) as info:
        load_sweep(path)
    msg = str(info.value)
    assert str(path) in msg and repr(a) in msg and repr(b) in msg, msg
    assert "\n" not in msg
    if pair == ("set", "case"):
        assert "cases_replace_set" in msg


@pytest.mark.parametrize("earlier,later", [
    ({"set": {"robots.0.count": 3}}, {"grid": {"robots.0": [{"count": 2}]}}),            # the grid replaces set's field
    ({"grid": {"robots.0.params": [{"cruise_speed_mps": 0.3}]}}, {"grid": {"robots.0.params.cruise_speed_mps": [0.4]}}),
])
def test_a_key_that_replaces_what_another_set_is_refused(earlier, later):
    data = {"scenario": "demo", **earlier}
    for k, v in later.items():
        data[k] = {**data.get(k, {}), **v} if isinstance(v, dict) else v
    with pytest.raises(SweepError, match="so a trial would silently drop what .* gives; expected each key"):
        _spec(data)


def _spec(data):
    from teamnav.experiments.sweep_spec import _validate_spec

    return _validate_spec(data, "test")


@pytest.mark.parametrize("later", [
    {"grid": {"robots.0.params.cruise_speed_mps": [0.4, 0.5]}},
    {"cases": [{"case": "a", "robots.0.params.cruise_speed_mps": 0.4}, {"case": "b", "robots.0.count": 2}]},
])
def test_a_grid_axis_or_case_may_refine_a_field_inside_a_set_dict(later):
    """set: is the base; a deeper key in the grid or a case wins inside it, in every trial."""
    from teamnav.experiments.sweep_trials import expand

    spec = _spec({"scenario": "demo", "set": {"robots.0.params": {"cruise_speed_mps": 0.3}}, "duration_s": 1, **later})
    ran = {}
    for t in expand(spec):
        key = "robots.0.params.cruise_speed_mps"
        ran[t.params.get(key, t.params.get("case"))] = t.load().robots[0].params["cruise_speed_mps"]
    assert all(label == value for label, value in ran.items() if label not in ("b",)), ran
    if "cases" in later:
        assert ran["b"] == 0.3  # a case that names nothing keeps set's value


def test_a_key_that_only_adds_inside_another_is_fine():
    spec = _spec({"scenario": "demo", "set": {"robots.0.params": {"cruise_speed_mps": 0.3}},
                  "grid": {"robots.0.params.wander_turn_prob": [0.1, 0.2]}})
    assert list(spec.grid) == ["robots.0.params.wander_turn_prob"]


def test_cases_replace_set_lets_the_cases_win_and_set_give_the_rest(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(textwrap.dedent("""\
        scenario: demo
        duration_s: 1
        set: {robots.00.count: 3}
        cases_replace_set: [robots.0.count]
        cases: [{case: default, radio.p_loss: 0.0}, {case: two, robots.0.count: 2}]
        """), encoding="utf-8")
    spec = load_sweep(path)
    assert spec.set == {"robots.0.count": 3} and spec.cases_replace_set == ["robots.0.count"]
    trials = expand(spec)
    assert [(t.params["case"], t.params["robots.0.count"], t.load().robots[0].count) for t in trials] == [
        ("default", 3, 3), ("two", 2, 2)]
    path.write_text(path.read_text().replace("cases_replace_set: [robots.0.count]", "cases_replace_set: [robots.0.count, radio.p_loss]"))
    with pytest.raises(SweepError, match=r"cases_replace_set: expected keys of set .* 'radio.p_loss'"):
        load_sweep(path)


def test_command_line_keys_are_compared_in_their_canonical_spelling():
    spec = resolve_spec("demo-robots", set=["robots.00.count=2"])  # replaces the grid axis robots.0.count
    assert "robots.0.count" not in spec.grid and spec.set["robots.0.count"] == 2
    with pytest.raises(SweepError, match=r"two spellings of robots.0.count"):
        resolve_spec("demo", grid=["robots.0.count=1,2", "robots.\uff10.count=3"])
    with pytest.raises(SweepError, match=r"two spellings of robots.0.count"):
        resolve_spec("demo", set=["robots.0.count=1", "robots.00.count=3"])
    with pytest.raises(SweepError, match=r"--set robots.0.count: the key is also a --grid axis"):
        resolve_spec("demo", grid=["robots.0.count=1,2"], set=["robots.00.count=3"])


# ---------------------------------------------------------------------------- duplicates: warned, run once
def test_equal_grid_values_and_cases_with_equal_overrides_run_once_with_a_warning():
    spec = _spec({"scenario": "demo", "duration_s": 1, "grid": {"robots.0.count": [2, 2.0, 3, 2]},
                  "cases": [{"case": "a", "radio.p_loss": 0.1}, {"case": "b", "radio.p_loss": 0.10}]})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        trials = expand(spec)
    assert [t.label() for t in trials] == ["case=a robots.0.count=2 seed=0", "case=a robots.0.count=3 seed=0"]
    [w] = [w for w in caught if issubclass(w.category, SweepWarning)]
    text = str(w.message)
    assert "robots.0.count=2.0 runs the same scenario as case 'a' robots.0.count=2" in text
    assert "case 'b' robots.0.count=3 runs the same scenario as case 'a' robots.0.count=3" in text


def test_the_cli_prints_the_duplicate_warning_and_runs_once(tmp_path):
    from teamnav.cli import app

    out = tmp_path / "o"
    res = CliRunner().invoke(app, ["sweep", "demo", "--grid", "robots.0.count=1,1.0", "--duration", "0.5", "--out", str(out),
                                   "-j", "1", "--quiet"])
    assert res.exit_code == 0, res.output
    assert "warning: sweep 'demo': 1 combination(s) left out" in res.output
    assert "1 ok, 0 failed" in res.output


# ---------------------------------------------------------------------------- done when: stored label == what ran
@pytest.mark.parametrize("layer", LAYERS)
def test_stored_labels_equal_what_each_trial_ran_for_every_spelling(tmp_path, layer):
    """One sweep per layer; every spelling of index 0 in it, on three fields (count, a sensor's
    range, a controller parameter), checked against the scenario each trial ran."""
    fields = {"count": [1, 2], "sensors.0.max_range_m": [3.0, 4.0], "params.cruise_speed_mps": [0.2, 0.3]}
    keys = {}
    for i, (field, values) in enumerate(fields.items()):
        z = ZEROS[(i * 3 + LAYERS.index(layer)) % len(ZEROS)]
        zz = ZEROS[(i * 3 + LAYERS.index(layer) + 1) % len(ZEROS)]
        if field.startswith("sensors"):
            field = f"sensors.{zz}.max_range_m"
        keys[f" robots.{z}.{field}"] = values
    if layer == "grid":
        spec = {"grid": keys}
    elif layer == "set":
        spec = {"set": {k: v[1] for k, v in keys.items()}}
    else:
        spec = {"cases": [{"case": f"c{j}", **{k: v[j] for k, v in keys.items()}} for j in range(2)]}
    path = tmp_path / "s.yaml"
    path.write_text(json.dumps({"scenario": "demo", "duration_s": 0.5, **spec}, ensure_ascii=False), encoding="utf-8")
    res = sweep(str(path), out_dir=tmp_path / "o", workers=1, trial_fn=ran_trial, progress=False)
    assert res.failed == 0 and res.done == res.total == (8 if layer == "grid" else 2 if layer == "case" else 1)
    con = sqlite3.connect(tmp_path / "o" / "results.sqlite")
    rows = [(json.loads(p), json.loads(m)) for p, m in con.execute("SELECT params, metrics FROM trials")]
    con.close()
    assert len(rows) == res.total
    for params, metrics in rows:
        assert params["robots.0.count"] == metrics["ran_count"]
        assert params["robots.0.sensors.0.max_range_m"] == metrics["ran_range_m"]
        assert params["robots.0.params.cruise_speed_mps"] == metrics["ran_speed"]
        assert not [k for k in params if k not in ("robots.0.count", "robots.0.sensors.0.max_range_m",
                                                    "robots.0.params.cruise_speed_mps", "duration_s", "case")]
