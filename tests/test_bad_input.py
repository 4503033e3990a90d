"""Bad input: one message, exit 2, the file and field named, no traceback, nothing half-written.

Every case goes through the command line (typer's CliRunner on ``teamnav.cli.app``)
and is checked the same way: exit status 2, exactly one ``error:`` message on stderr naming the
file (and the field where there is one), no traceback and no exception escaping, and no output
file or folder left behind. The cases:

- the committed corpus ``tests/bad_inputs/`` (see its README.md): scenario files
  (``scenarios/``, each naming what the message must say in its first line ``# expect: ...``),
  damaged run folders for ``teamnav replay`` / ``teamnav export`` (``run_folders/CASE/``: files
  laid over a copy of a real run folder, and ``expect.txt``), and results stores that are not
  teamnav stores (``stores/CASE/``);
- output paths that cannot be written (``/proc``, a folder, below a file);
- hostile sizes through a real subprocess (the alias bomb and the 20 000 brackets that used to
  take 77 s / blow the recursion limit), and a map image too large for memory;
- a hypothesis test generating scenario files, valid and mutated (wrong types, missing fields,
  duplicate keys, deep nesting, bad map references, alias bombs), through ``teamnav validate``.
"""

from __future__ import annotations

import errno
import itertools
import os
import shutil
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from teamnav.cli import app

CORPUS = Path(__file__).resolve().parent / "bad_inputs"
runner = CliRunner()

#: what the message must say for corpus scenario entries that cannot carry a "# expect:" line
_NO_COMMENT = {"empty.yaml": "the file is empty", "not_utf8.yaml": "UTF-8", "scenario_folder.yaml": "directory"}


def _refused(res, *needles: str) -> str:
    """Assert a clean refusal (exit 2, one message, no traceback) naming every needle; return stderr."""
    assert res.exception is None or isinstance(res.exception, SystemExit), f"escaped: {res.exception!r}\n{res.output}"
    assert res.exit_code == 2, f"exit {res.exit_code}:\n{res.output}"
    err = res.stderr
    assert "Traceback" not in res.output and "Traceback" not in err
    assert sum(line.startswith("error:") for line in err.splitlines()) == 1, err
    assert "allow_pickle" not in err and "pickle.load" not in err  # never suggest loading pickles
    for n in needles:
        assert n in err, f"{n!r} not in: {err}"
    return err


def _tree(root: Path) -> dict[str, bytes | None]:
    """Every path under ``root`` (files with their bytes, folders as None)."""
    if not root.exists():
        return {}
    return {str(p.relative_to(root)): (p.read_bytes() if p.is_file() else None) for p in sorted(root.rglob("*"))}


# ---------------------------------------------------------------------------- scenarios (corpus)
def _scenario_cases() -> list[Path]:
    return sorted((CORPUS / "scenarios").iterdir())


def _expected(path: Path) -> str:
    if path.name in _NO_COMMENT:
        return _NO_COMMENT[path.name]
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("# expect: "), f"{path} must start with '# expect: ...'"
    return first[len("# expect: "):]


@pytest.mark.parametrize("path", _scenario_cases(), ids=lambda p: p.name)
def test_corpus_scenario_is_refused_by_validate_and_run(path, tmp_path):
    t0 = time.perf_counter()
    _refused(runner.invoke(app, ["validate", str(path)]), str(path), _expected(path))
    out = tmp_path / "out"
    _refused(runner.invoke(app, ["run", str(path), "--out", str(out), "--quiet"]), str(path), _expected(path))
    assert not out.exists(), "a refused scenario must leave no run folder"
    assert time.perf_counter() - t0 < 30, "refusing bad input must be quick (bounded work)"


def test_corpus_covers_every_scenario_class():
    names = {p.name for p in _scenario_cases()}
    for needed in ("duplicate_key.yaml", "count_true.yaml", "billion_laughs.yaml", "deep_nesting.yaml", "huge_arena.yaml",
                   "scenario_folder.yaml", "recursive_alias.yaml"):
        assert needed in names


# ---------------------------------------------------------------------------- run folders (corpus)
# run_folder: tests/conftest.py (a real, tiny run folder)


def _run_cases() -> list[Path]:
    return sorted(p for p in (CORPUS / "run_folders").iterdir() if p.is_dir())


def _damaged_copy(run_folder: Path, case: Path, dest: Path) -> tuple[Path, list[str]]:
    shutil.copytree(run_folder, dest)
    for f in case.iterdir():
        if f.name != "expect.txt":
            shutil.copy(f, dest / f.name)
    needles = [line for line in (case / "expect.txt").read_text(encoding="utf-8").splitlines() if line.strip()]
    return dest, needles


def test_the_pristine_run_folder_replays_and_exports(run_folder, tmp_path):
    """The cases below fail because of their damage, not because of the folder they are laid on."""
    res = runner.invoke(app, ["replay", str(run_folder), "--out", str(tmp_path / "r.html")])
    assert res.exit_code == 0, res.output
    res = runner.invoke(app, ["export", str(run_folder), "--mcap", str(tmp_path / "r.mcap")])
    assert res.exit_code == 0, res.output


@pytest.mark.parametrize("case", _run_cases(), ids=lambda p: p.name)
def test_damaged_run_folder_is_refused_by_replay_and_export(run_folder, case, tmp_path):
    folder, needles = _damaged_copy(run_folder, case, tmp_path / case.name)
    before = _tree(folder)
    out = tmp_path / "out"
    _refused(runner.invoke(app, ["replay", str(folder), "--out", str(out / "sub" / "r.html")]), str(folder), *needles)
    _refused(runner.invoke(app, ["export", str(folder), "--mcap", str(out / "r.mcap")]), str(folder), *needles)
    _refused(runner.invoke(app, ["replay", str(folder)]), str(folder), *needles)  # default: RUN_DIR/replay.html
    assert not out.exists(), "nothing may be written for a refused run folder"
    assert _tree(folder) == before, "the run folder must be left as it was"


def test_replay_tolerates_a_hostile_scenario_yaml(run_folder, tmp_path):
    """scenario.yaml only titles the page: an alias bomb or a list there is ignored, quickly."""
    folder = tmp_path / "f"
    shutil.copytree(run_folder, folder)
    shutil.copy(CORPUS / "scenarios" / "billion_laughs.yaml", folder / "scenario.yaml")
    t0 = time.perf_counter()
    res = runner.invoke(app, ["replay", str(folder), "--out", str(tmp_path / "r.html")])
    assert res.exit_code == 0, res.output
    assert time.perf_counter() - t0 < 30
    (folder / "scenario.yaml").write_text("- a list\n", encoding="utf-8")
    assert runner.invoke(app, ["replay", str(folder), "--out", str(tmp_path / "r2.html")]).exit_code == 0


# ---------------------------------------------------------------------------- output paths
def _proc_cases() -> list:
    if not Path("/proc/self").is_dir():
        return []
    return [("replay", "--out", "/proc/teamnav-test.html"), ("replay", "--out", "/proc/teamnav-test-dir/a/r.html"),
            ("export", "--mcap", "/proc/teamnav-test.mcap"), ("export", "--mcap", "/proc/teamnav-test-dir/r.mcap")]


@pytest.mark.parametrize("command,option,target", _proc_cases())
def test_unwritable_output_path_is_one_message(run_folder, command, option, target):
    _refused(runner.invoke(app, [command, str(run_folder), option, target]), target, option, "cannot be written")
    assert not Path(target).exists()
    if Path(target).parent != Path("/proc"):
        assert not Path(target).parent.exists()


@pytest.mark.parametrize("command,option", [("replay", "--out"), ("export", "--mcap")])
def test_output_path_that_is_a_folder_or_below_a_file(run_folder, tmp_path, command, option):
    folder = tmp_path / "a_folder"
    folder.mkdir()
    (folder / "keep.txt").write_text("x", encoding="utf-8")
    before = _tree(tmp_path)
    _refused(runner.invoke(app, [command, str(run_folder), option, str(folder)]), str(folder), "found a folder", option)
    below = tmp_path / "a_folder" / "keep.txt" / "deeper" / "x.out"
    _refused(runner.invoke(app, [command, str(run_folder), option, str(below)]), str(below), "cannot be written", option)
    assert _tree(tmp_path) == before, "nothing half-written may be left behind"


def test_atomic_output_leaves_nothing_when_the_writer_fails(tmp_path):
    from teamnav.viz.run_folder import OutputPathError, atomic_output

    target = tmp_path / "new" / "deeper" / "r.html"
    with pytest.raises(OutputPathError, match=r"r\.html: cannot be written .*choose another --out"):
        with atomic_output(target, "HTML file", "--out") as tmp:
            tmp.write_text("half", encoding="utf-8")
            raise OSError(errno.ENOSPC, "No space left on device")
    with pytest.raises(RuntimeError, match="boom"):
        with atomic_output(target, "HTML file", "--out") as tmp:
            tmp.write_text("half", encoding="utf-8")
            raise RuntimeError("boom")
    assert _tree(tmp_path) == {}, "neither the temporary file nor the folders made for it may remain"
    with atomic_output(target, "HTML file", "--out") as tmp:
        tmp.write_text("whole", encoding="utf-8")
    assert target.read_text(encoding="utf-8") == "whole" and sorted(os.listdir(target.parent)) == ["r.html"]


# ---------------------------------------------------------------------------- results stores (corpus)
def _store_cases() -> list[Path]:
    return sorted(p for p in (CORPUS / "stores").iterdir() if p.is_dir())


@pytest.mark.parametrize("case", _store_cases(), ids=lambda p: p.name)
def test_store_that_is_not_a_teamnav_store_is_refused_before_any_trial(case, tmp_path):
    out = tmp_path / "sweep"
    shutil.copytree(case, out, ignore=shutil.ignore_patterns("expect.txt"))
    needles = [line for line in (case / "expect.txt").read_text(encoding="utf-8").splitlines() if line.strip()]
    before = _tree(out)
    t0 = time.perf_counter()
    res = runner.invoke(app, ["sweep", "demo", "--grid", "robots.0.count=1,2", "--seeds", "1", "--duration", "1",
                              "--out", str(out), "--workers", "1", "--quiet"])
    _refused(res, str(out / "results.sqlite"), "use --out with another folder", *needles)
    assert _tree(out) == before, "the refused store must be left exactly as it was (no trial ran, nothing written)"
    assert time.perf_counter() - t0 < 30


def test_check_store_accepts_real_stores_including_one_left_by_kill_9(tmp_path):
    from teamnav.experiments.store import ResultsStore, check_store

    check_store(tmp_path / "absent.sqlite")
    (tmp_path / "empty.sqlite").write_bytes(b"")
    check_store(tmp_path / "empty.sqlite")
    # a store whose last transaction is only in its -wal file (the process died without closing)
    code = ("import os, sys; from teamnav.experiments.store import ResultsStore; "
            "s = ResultsStore(sys.argv[1]); s.register_sweep('x', {'a': 1}); os._exit(0)")
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "killed.sqlite")], check=True, timeout=120)
    assert (tmp_path / "killed.sqlite-wal").exists()
    check_store(tmp_path / "killed.sqlite")
    with ResultsStore(tmp_path / "killed.sqlite") as store:
        assert store.existing() == {}
    con = sqlite3.connect(tmp_path / "killed.sqlite")
    assert con.execute("SELECT name FROM sweeps").fetchall() == [("x",)]
    con.close()


# ---------------------------------------------------------------------------- hostile sizes, real process
@pytest.mark.parametrize("name", ["billion_laughs.yaml", "deep_nesting.yaml"])
@pytest.mark.parametrize("command", ["validate", "run"])
def test_hostile_sizes_in_a_real_process(name, command, tmp_path):
    path = CORPUS / "scenarios" / name
    args = [sys.executable, "-m", "teamnav", command, str(path)] + (["--out", str(tmp_path / "o")] if command == "run" else [])
    t0 = time.perf_counter()
    proc = subprocess.run(args, capture_output=True, text=True, timeout=120, env={**os.environ, "TEAMNAV_DEBUG": ""})
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and str(path) in proc.stderr and _expected(path) in proc.stderr
    assert time.perf_counter() - t0 < 60
    assert not (tmp_path / "o").exists()


def test_map_image_too_large_for_memory(tmp_path, run_folder):
    from PIL import Image

    from teamnav.experiments.spec import MAX_MAP_BYTES

    assert MAX_MAP_BYTES == 2 * 1024**3
    Image.new("1", (8500, 8500), 1).save(tmp_path / "big.png")  # 72 M cells: ~2.7 GiB for the distance transform
    (tmp_path / "big.yaml").write_text("image: big.png\nresolution: 0.05\norigin: [0, 0, 0]\n", encoding="utf-8")
    scn = tmp_path / "s.yaml"
    scn.write_text(f"name: big\nmap: {{file: {tmp_path / 'big.yaml'}}}\nduration_s: 1\nrobots: [{{controller: wander-v1}}]\n",
                   encoding="utf-8")
    _refused(runner.invoke(app, ["validate", str(scn)]), str(scn), "map.file", "GiB", "MAX_MAP_BYTES")
    folder = tmp_path / "run"
    shutil.copytree(run_folder, folder)
    shutil.copy(tmp_path / "big.png", folder / "big.png")
    (folder / "map.yaml").write_text("image: big.png\nresolution: 0.05\norigin: [0, 0, 0]\n", encoding="utf-8")
    _refused(runner.invoke(app, ["replay", str(folder), "--out", str(tmp_path / "r.html")]), str(folder), "map.yaml", "GiB")
    assert not (tmp_path / "r.html").exists()


# ---------------------------------------------------------------------------- generated scenarios
BASE = {
    "name": "gen",
    "map": {"arena": {"width_m": 10, "height_m": 10}},
    "duration_s": 1,
    "robots": [{"controller": "wander-v1", "count": 2, "radius_m": 0.2, "start": {"region": [2, 8, 2, 8]}}],
}
PATHS = ["name", "description", "duration_s", "dt_s", "seed", "record_every", "map", "map.arena", "map.arena.width_m",
         "map.arena.resolution_m", "robots", "robots.0", "robots.0.count", "robots.0.controller", "robots.0.radius_m",
         "robots.0.params", "robots.0.start", "robots.0.start.region", "robots.0.start.near", "robots.0.sensors",
         "robots.0.odometry", "metrics", "give_map", "radio", "places", "places.0", "unknown_key"]
BAD_MAPS = [{"file": "missing.yaml"}, {"file": "notes.txt"}, {"builtin": "nope"}, {"package": "../../x.yaml"},
            {"arena": {"width_m": -1, "height_m": 10}}, {}, {"arena": {"width_m": 1e4, "height_m": 1e4, "resolution_m": 0.5}},
            {"builtin": "trail_office", "resolution_m": 0.001}, {"file": None}, "basement", {"arena": {"width_m": 10}, "builtin": "hexagon"}]
_text = st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=12)
_values = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10, 10**7), st.floats(allow_nan=True, allow_infinity=True), _text),
    lambda inner: st.one_of(st.lists(inner, max_size=3), st.dictionaries(_text, inner, max_size=3)),
    max_leaves=6,
)


def _set(doc: dict, path: str, value) -> None:
    parts = path.split(".")
    node = doc
    for p in parts[:-1]:
        nxt = node[int(p)] if isinstance(node, list) else node.get(p)
        if not isinstance(nxt, (dict, list)):
            nxt = {}
            if isinstance(node, list):
                node[int(p)] = nxt
            else:
                node[p] = nxt
        node = nxt
    if isinstance(node, list):
        node[int(parts[-1])] = value
    else:
        node[parts[-1]] = value


def _delete(doc: dict, path: str) -> None:
    parts = path.split(".")
    node = doc
    for p in parts[:-1]:
        node = node[int(p)] if isinstance(node, list) else node.get(p)
        if not isinstance(node, (dict, list)):
            return
    if isinstance(node, dict):
        node.pop(parts[-1], None)
    elif isinstance(node, list) and int(parts[-1]) < len(node):
        node.pop(int(parts[-1]))


@st.composite
def scenario_texts(draw):
    """``(kind, yaml_text)``: a valid scenario or one mutation of it."""
    import copy

    doc = copy.deepcopy(BASE)
    kind = draw(st.sampled_from(["valid", "vary", "set", "delete", "duplicate", "deep", "bad_map", "bomb", "bool_count",
                                 "named_places"]))
    if kind == "vary":  # still valid: numbers inside their ranges, a second group, an alias used properly
        doc["robots"][0]["count"] = draw(st.integers(0, 5))
        doc["duration_s"] = draw(st.floats(0.1, 100))
        doc["seed"] = draw(st.integers(0, 2**63 - 1))
        doc["map"]["arena"]["width_m"] = draw(st.floats(9, 200))
        if draw(st.booleans()):
            doc["robots"].append({"controller": "idle-v1", "count": draw(st.integers(1, 3)), "start": {"region": [2, 8, 2, 8]}})
    elif kind == "set":
        _set(doc, draw(st.sampled_from(PATHS)), draw(_values))
    elif kind == "delete":
        _delete(doc, draw(st.sampled_from(PATHS)))
    elif kind == "deep":
        depth = draw(st.sampled_from([101, 150, 1000, 20_000]))
        _set(doc, draw(st.sampled_from(PATHS)), "DEEP")
    elif kind == "bad_map":
        doc["map"] = draw(st.sampled_from(BAD_MAPS))
    elif kind == "named_places":  # places by name need a built-in map that has them
        doc["map"] = draw(st.sampled_from([{"builtin": "trail_office"}, {"arena": {"width_m": 10, "height_m": 10}},
                                           {"builtin": "trail_office", "resolution_m": draw(_values)}]))
        doc["places"] = [{"place": draw(st.one_of(st.sampled_from(["home", "resource"]), _values)), "radius_m": 1.0}]
        doc["robots"][0]["start"] = {"near": draw(st.one_of(st.just("home"), _values)), "spread_m": draw(_values)}
    elif kind == "bool_count":
        _set(doc, draw(st.sampled_from(["robots.0.count", "seed", "duration_s", "record_every"])), draw(st.booleans()))
    text = yaml.safe_dump(doc, sort_keys=False, allow_unicode=True, width=10_000)
    if kind == "deep":
        text = text.replace("DEEP", "[" * depth + "]" * depth)
    elif kind == "duplicate":
        lines = text.splitlines()
        keys = [ln for ln in lines if ln and not ln.startswith((" ", "-")) and ":" in ln]
        text += draw(st.sampled_from(keys)).split(":")[0] + ": " + draw(st.sampled_from(["1", "x", "[1, 2]", "null"])) + "\n"
    elif kind == "bomb":
        width, depth = draw(st.sampled_from([(10, 7), (10, 9), (2, 21), (100, 4), (4, 11)]))
        lines = [f"  - &a0 [{', '.join(['lol'] * width)}]"]
        lines += [f"  - &a{i} [{', '.join([f'*a{i - 1}'] * width)}]" for i in range(1, depth)]
        text += "metrics:\n" + "\n".join(lines) + "\n"
    return kind, text


_counter = itertools.count()


@pytest.fixture(scope="module")
def gen_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("generated")


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(case=scenario_texts())
def test_generated_scenarios_are_accepted_or_refused_cleanly(gen_dir, case):
    kind, text = case
    path = gen_dir / f"s{next(_counter)}.yaml"
    path.write_text(text, encoding="utf-8")
    res = runner.invoke(app, ["validate", str(path)])
    assert res.exception is None or isinstance(res.exception, SystemExit), f"{kind}: escaped {res.exception!r}\n{text[:500]}"
    assert res.exit_code in (0, 2), res.output
    assert "Traceback" not in res.output
    event(f"{kind}: exit {res.exit_code}")
    if kind in ("valid", "vary"):
        assert res.exit_code == 0, res.output
    if kind in ("duplicate", "deep", "bad_map", "bomb", "bool_count"):
        assert res.exit_code == 2, f"{kind} accepted:\n{text[:500]}"
    if res.exit_code == 0:
        assert res.stdout.startswith(f"ok: {path}")
    else:
        _refused(res, str(path))
    if kind == "duplicate":
        assert "duplicate key" in res.stderr
    if kind == "deep":
        assert "nested more than" in res.stderr
    if kind == "bomb":
        assert "expands to more than" in res.stderr


@pytest.mark.parametrize("argv", [["run", "demo", "--duration", "0.5", "--set", "robots.0.count=2", "--out"],
                                  ["sweep", "demo-robots", "--seeds", "1", "--duration", "0.5", "--out"]])
def test_run_and_sweep_refuse_an_output_folder_that_cannot_be_made(tmp_path, argv):
    """``--out`` under /proc (or below a file): one message naming the folder, nothing run or written."""
    (tmp_path / "a_file").write_text("x", encoding="utf-8")
    before = _tree(tmp_path)
    targets = [str(tmp_path / "a_file" / "out")] + (["/proc/teamnav-test-out"] if Path("/proc/self").is_dir() else [])
    for target in targets:
        result = runner.invoke(app, argv + [target])
        assert result.exit_code == 2, result.output
        assert "Traceback" not in result.output and target in result.output and "--out" in result.output
        assert not Path(target).exists()
    assert _tree(tmp_path) == before


@pytest.mark.parametrize("command,option,extra", [("replay", "--out", []), ("export", "--mcap", ["--force"])])
def test_output_over_the_run_folders_own_file_is_refused(run_folder, tmp_path, command, option, extra):
    """``--out RUN/trajectories.npz`` would overwrite the very run being shown: refused, the
    run folder untouched."""
    import shutil

    folder = tmp_path / "run"
    shutil.copytree(run_folder, folder)
    before = _tree(folder)
    target = folder / "trajectories.npz"
    _refused(runner.invoke(app, [command, str(folder), option, str(target)] + extra), str(target), "run folder's own", option)
    assert _tree(folder) == before
