"""Scenario files: validation, clear errors naming file and field, overrides, named places."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from teamnav.experiments import registry
from teamnav.experiments.errors import ScenarioError, format_loc
from teamnav.experiments.spec import Scenario, apply_overrides, build_grid, load_scenario, scenario_to_yaml

BASE = """\
name: t
map: {builtin: office_simple}
duration_s: 2.0
robots:
  - count: 2
    controller: wander-v1
    sensors:
      - {kind: laser, n_beams: 30, max_range_m: 5.0}
      - {kind: sonar, n_transducers: 8}
"""


def write(tmp_path: Path, text: str, name: str = "s.yaml") -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def error_of(*args, **kwargs) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        load_scenario(*args, **kwargs)
    return info.value


def test_base_scenario_loads(tmp_path):
    s = load_scenario(write(tmp_path, BASE))
    assert isinstance(s, Scenario)
    assert (s.name, s.n_robots, s.n_steps) == ("t", 2, 20)
    assert s.source == str(tmp_path / "s.yaml")
    assert s.metric_names[0] == "path_length" and "collisions" in s.metric_names


@pytest.mark.parametrize(
    "patch, field, fragments",
    [
        ({"robots.0.cont": 3}, "robots[0].cont", ["unknown key", "did you mean 'count'"]),
        ({"duration_s": "abc"}, "duration_s", ["'abc'"]),
        ({"dt_s": float("nan")}, "dt_s", ["finite", "nan"]),
        ({"radio.p_loss": 1.5}, "radio.p_loss", ["less than or equal to 1", "1.5"]),
        ({"robots.0.sensors.1.max_range_m": -2.0}, "robots[0].sensors[1].max_range_m", ["greater than 0", "-2.0"]),
        ({"duration_s": 1e9}, "duration_s", ["less than or equal to"]),
        ({"metrics": ["path_lenght"]}, "metrics", ["did you mean 'path_length'"]),
        ({"robots.0.controller": "wandr-v1"}, "robots[0].controller", ["did you mean", "wander-v1"]),
        ({"robots.0.params.cruise_speed_mps": -1}, "robots[0].params.cruise_speed_mps", ["greater than 0", "-1"]),
        ({"robots.0.params.bogus": 1}, "robots[0].params.bogus", ["unknown key"]),
        ({"map.builtin": "office_simpel"}, "map.builtin", ["did you mean 'office_simple'"]),
    ],
)
def test_bad_values_name_file_field_and_value(tmp_path, patch, field, fragments):
    path = write(tmp_path, BASE)
    err = error_of(path, overrides=patch)
    assert err.file == str(path)
    assert field in [p.field for p in err.problems]
    text = str(err)
    assert str(path) in text and field in text
    for frag in fragments:
        assert frag in text


def test_nan_written_in_yaml(tmp_path):
    path = write(tmp_path, BASE.replace("duration_s: 2.0", "duration_s: .nan"))
    err = error_of(path)
    assert err.problems[0].field == "duration_s" and "finite" in str(err)


def test_every_problem_is_reported_on_its_own_line(tmp_path):
    path = write(tmp_path, BASE + "radio: {p_loss: 2}\nbogus: 1\n")
    err = error_of(path, overrides={"robots.0.count": -1})
    fields = {p.field for p in err.problems}
    assert {"radio.p_loss", "bogus", "robots[0].count"} <= fields
    assert len(str(err).splitlines()) == 1 + len(err.problems)


def test_yaml_syntax_error_gives_line_and_column(tmp_path):
    path = write(tmp_path, "name: t\nmap: {builtin: [office\nduration_s: 2\n")
    err = error_of(path)
    assert str(path) in str(err) and "line 3" in str(err) and "column" in str(err)


def test_missing_scenario_file_and_unknown_name(tmp_path):
    err = error_of(tmp_path / "nope.yaml")
    assert "nope.yaml" in str(err) and "no such file" in str(err)
    err = error_of("dmeo")
    assert "unknown scenario 'dmeo'" in str(err) and "did you mean 'demo'" in str(err)


def test_top_level_must_be_a_mapping(tmp_path):
    assert "mapping" in str(error_of(write(tmp_path, "- 1\n- 2\n")))
    assert "empty" in str(error_of(write(tmp_path, "", name="e.yaml")))


def test_map_file_relative_to_scenario_folder_missing_and_malformed(tmp_path):
    (tmp_path / "maps").mkdir()
    path = write(tmp_path, BASE.replace("{builtin: office_simple}", "{file: maps/lab.yaml}"))
    err = error_of(path)
    assert err.problems[0].field == "map.file" and str(tmp_path / "maps" / "lab.yaml") in str(err)

    (tmp_path / "maps" / "lab.yaml").write_text("image: lab.pgm\nresolution: -0.05\norigin: [0, 0, 0]\n")
    err = error_of(path)
    text = str(err)
    assert err.problems[0].field == "map.file"
    assert str(path) in text and "lab.yaml" in text and "'resolution'" in text


def test_map_file_relative_path_resolves_and_loads(tmp_path):
    from teamnav.world import MapBuilder, save_map

    (tmp_path / "maps").mkdir()
    save_map(MapBuilder(6.0, 4.0, 0.1).border(0.2).build("box"), tmp_path / "maps" / "box.yaml")
    s = load_scenario(write(tmp_path, BASE.replace("{builtin: office_simple}", "{file: maps/box.yaml}")))
    assert Path(s.map.file) == tmp_path / "maps" / "box.yaml"
    assert build_grid(s).shape == (40, 60)


def test_map_spec_needs_exactly_one_source(tmp_path):
    path = write(tmp_path, BASE.replace("{builtin: office_simple}", "{builtin: office_simple, package: nav2/depot.yaml}"))
    err = error_of(path)
    assert err.problems[0].field == "map" and "exactly one" in str(err)
    err = error_of(write(tmp_path, BASE.replace("{builtin: office_simple}", "{package: nav2/dept.yaml}"), "p.yaml"))
    assert "map.package" in str(err) and "did you mean 'nav2/depot.yaml'" in str(err)


def test_arena_map(tmp_path):
    s = load_scenario(write(tmp_path, BASE.replace("{builtin: office_simple}", "{arena: {width_m: 5, height_m: 3, resolution_m: 0.1}}")))
    g = build_grid(s)
    assert g.shape == (30, 50)
    assert g.cells[0].all() and g.cells[:, 0].all() and not g.cells[15, 25]


def test_overrides_parse_yaml_scalars_and_lists(tmp_path):
    path = write(tmp_path, BASE)
    s = load_scenario(
        path,
        overrides=["robots.0.count=5", "radio.p_loss=0.25", "radio.mode=range", "robot_collisions=false",
                   "robots.0.start.region=[1, 5, 1, 3]"],
        seed=9,
        duration_s=1.5,
    )
    assert s.robots[0].count == 5 and s.radio.p_loss == 0.25 and s.radio.mode == "range"
    assert s.robot_collisions is False and s.robots[0].start.region == (1.0, 5.0, 1.0, 3.0)
    assert (s.seed, s.duration_s) == (9, 1.5)


@pytest.mark.parametrize(
    "item, fragments",
    [
        ("robots.0.cont=3", ["robots[0].cont", "unknown key", "--set robots.0.cont=3"]),
        ("radoi.p_loss=0.1", ["radoi", "did you mean 'radio'", "--set radoi.p_loss=0.1"]),
        ("robots.0.count=abc", ["robots[0].count", "'abc'", "--set robots.0.count=abc"]),
        ("robots.4.count=1", ["--set robots.4.count", "list of 1 item"]),
        ("seed", ["--set", "KEY=VALUE"]),
        ("seed=[1", ["--set seed", "YAML"]),
        ("duration_s.x=1", ["--set duration_s.x", "not a mapping"]),
    ],
)
def test_bad_overrides(tmp_path, item, fragments):
    path = write(tmp_path, BASE)
    text = str(error_of(path, overrides=[item]))
    assert str(path) in text
    for frag in fragments:
        assert frag in text


def test_apply_overrides_reports_which_override_and_creates_sections():
    data = {"name": "x"}
    notes = apply_overrides(data, ["radio.p_loss=0.5"])
    assert data == {"name": "x", "radio": {"p_loss": 0.5}}
    assert notes == {"radio.p_loss": "from --set radio.p_loss=0.5"}


def test_format_loc_drops_union_tags():
    data = {"robots": [{"sensors": [{"kind": "laser"}, {"kind": "sonar", "max_range_m": -1}]}]}
    assert format_loc(("robots", 0, "sensors", 1, "sonar", "max_range_m"), data) == "robots[0].sensors[1].max_range_m"
    assert format_loc(("robots", 0, "odometry", "alpha", 2), data) == "robots[0].odometry.alpha[2]"


def test_named_places_from_builtin_map(tmp_path):
    from teamnav.world import builtin_map

    text = BASE.replace("office_simple", "trail_office") + textwrap.dedent(
        """\
        places:
          - {place: home, radius_m: 1.5, event: took_resource}
          - {name: src, place: source, event: given_resource}
        """
    )
    text = text.replace("    controller: wander-v1\n", "    controller: wander-v1\n    start: {near: home, spread_m: 0.5}\n")
    s = load_scenario(write(tmp_path, text))
    env = builtin_map("trail_office")
    assert (s.places[0].name, s.places[0].x_m, s.places[0].y_m) == ("home", *env.places["home"])
    assert (s.places[1].name, (s.places[1].x_m, s.places[1].y_m)) == ("src", env.places["source"])
    hx, hy = env.places["home"]
    assert s.robots[0].start.region == (hx - 0.5, hx + 0.5, hy - 0.5, hy + 0.5)

    err = error_of(write(tmp_path, text.replace("place: source", "place: sorce"), "b.yaml"))
    assert "places[1].place" in str(err) and "did you mean 'source'" in str(err)
    err = error_of(write(tmp_path, text.replace("trail_office", "office_simple"), "c.yaml"))
    assert "places[0].place" in str(err) or "robots[0].start.near" in str(err)


def test_resolved_yaml_reloads_to_an_equal_scenario(tmp_path):
    text = BASE.replace("office_simple", "trail_office") + "places:\n  - {place: home}\n"
    s = load_scenario(write(tmp_path, text), overrides=["radio.p_loss=0.1"], seed=4)
    out = tmp_path / "run" / "scenario.yaml"
    out.parent.mkdir()
    out.write_text(scenario_to_yaml(s))
    again = load_scenario(out)
    assert again.model_dump() == s.model_dump()  # (equal fields; only the source file differs)
    assert "place:" not in out.read_text()


@pytest.mark.parametrize("name", registry.names())
def test_builtin_scenarios_validate(name):
    s = load_scenario(name)
    assert s.name == name and s.description
    assert build_grid(s).shape[0] > 10


def test_scenario_registry_refuses_duplicates(tmp_path):
    with pytest.raises(ValueError, match="already registered"):
        registry.register("demo", tmp_path / "x.yaml")
    with pytest.raises(KeyError, match="did you mean 'demo'"):
        registry.path("deom")


def test_yaml_booleans_are_yaml_1_2_so_on_stays_a_key(tmp_path):
    # YAML 1.1 (PyYAML's default) reads the PlaceConfig key `on:` as the boolean True
    text = BASE + "places:\n  - {name: p, x_m: 5, y_m: 7, event: here, on: inside}\nrobot_collisions: false\n"
    s = load_scenario(write(tmp_path, text), overrides=["give_map=true"])
    assert s.places[0].on == "inside" and s.robot_collisions is False and s.give_map is True


def test_a_map_file_given_with_set_is_relative_to_the_current_folder(tmp_path, monkeypatch):
    """``--set map={file: maps/x.yaml}`` on a built-in scenario reads the map from where teamnav
    runs (it used to look inside the package's scenario folder); a scenario file's own relative
    map.file stays relative to that file."""
    import shutil

    from teamnav.experiments.spec import PACKAGE_MAP_DIR, load_scenario

    (tmp_path / "maps").mkdir()
    for f in ("tb3_sandbox.yaml", "tb3_sandbox.pgm"):
        shutil.copy(PACKAGE_MAP_DIR / "nav2" / f, tmp_path / "maps" / f)
    monkeypatch.chdir(tmp_path)
    scn = load_scenario("demo", overrides=["map={file: maps/tb3_sandbox.yaml}", "robots.0.start.region=null"])
    assert scn.map.file == str(tmp_path / "maps" / "tb3_sandbox.yaml")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "s.yaml").write_text("name: s\nmap: {file: ../maps/tb3_sandbox.yaml}\nrobots: [{count: 1}]\n")
    assert Path(load_scenario(str(tmp_path / "sub" / "s.yaml")).map.file).resolve() == tmp_path / "maps" / "tb3_sandbox.yaml"


def test_an_env_section_is_accepted_by_run_and_left_out_when_absent(tmp_path):
    """A scenario file with an ``env:`` section (teamnav.env's settings) validates for
    ``teamnav run``; without one, the resolved scenario and its config hash do not mention it."""
    from teamnav.experiments.spec import load_scenario, scenario_to_yaml
    from teamnav.experiments.sweep import config_hash

    plain = load_scenario("demo")
    assert "env" not in scenario_to_yaml(plain)
    with_env = load_scenario("demo", overrides=["env={agents_from: [wanderer], observe_truth: false}"])
    assert with_env.env == {"agents_from": ["wanderer"], "observe_truth": False}
    assert config_hash(with_env) != config_hash(plain)
    assert load_scenario(plain).env is None and config_hash(load_scenario("demo")) == config_hash(plain)
