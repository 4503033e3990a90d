"""Security: hostile strings from scenario files and run folders never run as
script in the HTML replay or the report; no pickle is loaded from user files; YAML is only
ever safe-loaded; nothing listens on a network port.

The source checks read ``src/teamnav`` with :mod:`ast` (so a call split over lines, an import
alias or a ``from numpy import load`` is seen, and docstrings are not) and fail naming the file
and line. The browser checks open the pages in Debian's headless ``chromium`` driven by
Playwright, as ``tests/test_replay_browser.py`` does: skipped without that browser unless
``TEAMNAV_REQUIRE_BROWSER=1`` (``.ci/run``), where a missing browser is a failure.
"""

from __future__ import annotations

import ast
import html
import importlib
import json
import os
import re
import shutil
import tempfile
from html.parser import HTMLParser
from pathlib import Path

import pytest
import yaml

import _replay_run
from teamnav.experiments.spec import read_yaml
from teamnav.viz.replay import _decode, build_replay

SRC = Path(__file__).resolve().parents[1] / "src" / "teamnav"

# ---------------------------------------------------------------------------- hostile strings
#: each payload, if it ever ran, would set window.__pwned and the page title
SCRIPT = "<script>window.__pwned=1;document.title='PWNED'</script>"
IMG = "\"><img src=x onerror=\"window.__pwned=2;document.title='PWNED'\">"
CLOSE = "</script>"
COMMENT = "<!--<script>"  # inside a <script> element: the "double-escaped" state, which eats its </script>
SEPARATORS = "\u2028\u2029"
ENTITIES = "&amp;&lt;b&gt;"  # must show as typed, not decoded once more

SCENARIO_NAME = f"{SCRIPT} {IMG} {CLOSE}"  # names are validated on load: only a run folder edited by hand holds this
DESCRIPTION = f"{SCRIPT} {IMG} {CLOSE} {COMMENT}"
GROUP_A = f"{SCRIPT} {COMMENT}"
GROUP_B = f"{IMG}{CLOSE}{SEPARATORS}"
SENSOR = "\"><img src=x onerror=alert(1)>"  # short: the recorder's scan key is made from it (64 characters at most)
PLACE = f"{CLOSE}<script>window.__pwned=6</script>"
EVENT = f"<img src=x onerror=window.__pwned=7>{ENTITIES}"
LAYER_NOTE = f"{IMG} {COMMENT}"  # layers.json of a run folder edited by hand
STATE_LABEL = f"{SCRIPT}{ENTITIES}"


def _where(path: Path, node: ast.AST) -> str:
    line = path.read_text(encoding="utf-8").splitlines()[node.lineno - 1].strip()
    return f"{path.relative_to(SRC.parents[1])}:{node.lineno}: {line}"


def _sources() -> list[tuple[Path, ast.Module]]:
    files = sorted(SRC.rglob("*.py"))
    assert len(files) > 50, f"found only {len(files)} Python files under {SRC}"
    return [(p, ast.parse(p.read_text(encoding="utf-8"), filename=str(p))) for p in files]


def _aliases(tree: ast.Module) -> dict[str, str]:
    """Local name -> dotted name it was imported as (``np`` -> ``numpy``, ``load`` -> ``numpy.load``)."""
    out: dict[str, str] = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                out[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            for a in node.names:
                out[a.asname or a.name] = f"{node.module}.{a.name}"
    return out


def _dotted(node: ast.AST, aliases: dict[str, str]) -> str | None:
    """``np.lib.load`` -> ``numpy.lib.load`` through the module's imports; None if not a name."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    return ".".join([aliases.get(node.id, node.id)] + parts[::-1])


def _calls(sources):
    for path, tree in sources:
        aliases = _aliases(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                yield path, tree, node, _dotted(node.func, aliases)


@pytest.fixture(scope="module")
def sources():
    return _sources()


# ---------------------------------------------------------------------------- no pickles
_PICKLE_LOADERS = re.compile(
    r"^(c?pickle|dill|cloudpickle|joblib|marshal|shelve)\.(load|loads|Unpickler|open)$|^_pickle\.(load|loads|Unpickler)$"
    r"|^pandas\.read_pickle$|^torch\.load$|\.read_pickle$"
)


def test_no_pickle_is_ever_loaded(sources):
    bad = []
    for path, _tree, call, name in _calls(sources):
        if name and _PICKLE_LOADERS.search(name):
            bad.append(f"{_where(path, call)}  ({name} can run code from the file)")
        for kw in call.keywords:
            if kw.arg == "allow_pickle" and not (isinstance(kw.value, ast.Constant) and kw.value.value is False):
                bad.append(f"{_where(path, call)}  (allow_pickle must be the constant False)")
    assert not bad, "pickles loaded from files:\n" + "\n".join(bad)


def test_every_np_load_says_allow_pickle_false(sources):
    bad = []
    for path, _tree, call, name in _calls(sources):
        if name in ("numpy.load", "numpy.lib.npyio.load"):
            ok = any(kw.arg == "allow_pickle" and isinstance(kw.value, ast.Constant) and kw.value.value is False
                     for kw in call.keywords)
            if not ok:
                bad.append(f"{_where(path, call)}  (add allow_pickle=False)")
    assert not bad, "np.load without allow_pickle=False:\n" + "\n".join(bad)


# ---------------------------------------------------------------------------- safe YAML
_YAML_UNSAFE = {"Loader", "CLoader", "FullLoader", "CFullLoader", "UnsafeLoader", "CUnsafeLoader", "unsafe_load",
                "unsafe_load_all", "full_load", "full_load_all", "UnsafeConstructor", "FullConstructor", "Constructor"}


def _is_safe_loader(cls) -> bool:
    from yaml.constructor import FullConstructor, SafeConstructor

    return isinstance(cls, type) and issubclass(cls, SafeConstructor) and not issubclass(cls, FullConstructor)


def test_yaml_is_only_safe_loaded(sources):
    bad = []
    for path, tree in sources:
        aliases = _aliases(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "yaml":
                for a in node.names:
                    if a.name in _YAML_UNSAFE:
                        bad.append(f"{_where(path, node)}  (yaml.{a.name} constructs arbitrary Python objects)")
            name = _dotted(node, aliases) if isinstance(node, (ast.Attribute, ast.Name)) else None
            if name and name.startswith("yaml.") and name.split(".", 1)[1] in _YAML_UNSAFE:
                bad.append(f"{_where(path, node)}  ({name} constructs arbitrary Python objects)")
    for path, _tree, call, name in _calls(sources):
        if name not in ("yaml.load", "yaml.load_all"):
            continue
        loader = next((kw.value for kw in call.keywords if kw.arg == "Loader"), call.args[1] if len(call.args) > 1 else None)
        if loader is None:
            bad.append(f"{_where(path, call)}  ({name} without a Loader)")
            continue
        if any(isinstance(n, ast.Call) for n in ast.walk(loader)):
            bad.append(f"{_where(path, call)}  (a Loader computed by a call: use a SafeLoader class by name)")
            continue
        try:
            module = importlib.import_module(".".join(path.relative_to(SRC.parent).with_suffix("").parts))
            cls = eval(compile(ast.Expression(loader), str(path), "eval"), vars(module))  # a name or yaml.X
        except Exception as exc:  # noqa: BLE001 - report it as unresolvable
            bad.append(f"{_where(path, call)}  (cannot resolve its Loader: {exc})")
            continue
        if not _is_safe_loader(cls):
            bad.append(f"{_where(path, call)}  (Loader {getattr(cls, '__name__', cls)!r} is not a SafeLoader)")
    assert not bad, "YAML loaded unsafely:\n" + "\n".join(bad)


def test_the_scenario_loader_refuses_python_tags():
    with pytest.raises(yaml.YAMLError):
        read_yaml("name: !!python/object/apply:os.system ['echo pwned']\n")


# ---------------------------------------------------------------------------- no listening sockets
_SERVERS = ("http.server", "socketserver", "xmlrpc.server", "wsgiref.simple_server", "asyncio.start_server",
            "asyncio.base_events.Server", "aiohttp.web", "flask", "uvicorn", "tornado", "websockets.serve", "ray.serve")
_LOCAL = {"127.0.0.1", "localhost", "::1"}


def test_nothing_listens_on_a_network_port(sources):
    """Today nothing in teamnav opens a server. One added later must bind to localhost: a server
    module only in a file that names 127.0.0.1 / localhost, every ``bind`` / ``create_server`` /
    ``start_server`` call given such an address, and no ``0.0.0.0`` anywhere."""
    bad = []
    for path, tree in sources:
        aliases = _aliases(tree)
        consts_of = lambda node: {a.value for a in ast.walk(node) if isinstance(a, ast.Constant)}  # noqa: E731
        local_file = bool(consts_of(tree) & _LOCAL)
        networked = any(m.split(".")[0] in ("socket", "asyncio", "ssl") for m in aliases.values())
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                mods = [a.name for a in node.names] if isinstance(node, ast.Import) else [node.module or ""]
                mods += [f"{node.module}.{a.name}" for a in node.names] if isinstance(node, ast.ImportFrom) else []
                if not local_file and any(m == s or m.startswith(s + ".") for m in mods for s in _SERVERS):
                    bad.append(f"{_where(path, node)}  (a server module, and no 127.0.0.1 to bind it to)")
            elif isinstance(node, ast.Constant) and node.value in ("0.0.0.0", "::", "[::]"):
                bad.append(f"{_where(path, node)}  (binds every interface)")
            elif isinstance(node, ast.Call):
                name = _dotted(node.func, aliases) or ""
                opens = name.endswith((".create_server", ".start_server")) or (networked and name.endswith(".bind"))
                if opens and not consts_of(node) & _LOCAL:
                    bad.append(f"{_where(path, node)}  (listens beyond this machine: bind to 127.0.0.1)")
    assert not bad, "network listeners:\n" + "\n".join(bad)


def test_a_local_ray_is_started_without_its_dashboard(sources):
    """``--executor ray`` without ``--address`` starts Ray here: without the dashboard, whose
    web server would otherwise listen. (Joining a cluster with ``--address`` is the user's Ray.)"""
    for path, tree in sources:
        text = path.read_text(encoding="utf-8")
        inits = [c for _p, _t, c, name in _calls([(path, tree)]) if name == "ray.init"]
        if inits:
            assert "include_dashboard=False" in text, f"{_where(path, inits[0])}  (a local ray.init needs include_dashboard=False)"
            assert not re.search(r"dashboard_host\s*=\s*['\"](0\.0\.0\.0|::)", text), f"{path}: dashboard on every interface"


# ---------------------------------------------------------------------------- a hostile run folder
@pytest.fixture(scope="module")
def hostile_run(tmp_path_factory) -> Path:
    """The replay tests' lab scenario (every layer, scans, detections, radio, place events) with
    hostile strings in every free-text field a scenario file has, run for 2 s; then its folder is
    edited as someone handing it over could: the scenario name and a layer's description and labels."""
    from teamnav.experiments.runner import run

    _replay_run.register()
    doc = read_yaml(_replay_run.SCENARIO)
    doc["description"] = DESCRIPTION
    doc["duration_s"] = 2.0
    lab = doc["robots"][0]
    lab.update(name=GROUP_A, count=2)
    lab["sensors"][0]["name"] = SENSOR
    doc["robots"].append({"name": GROUP_B, "count": 1, "controller": "wander-v1", "sensors": [{"kind": "laser", "n_beams": 8}],
                          "start": lab["start"]})
    doc["places"] = [{"name": PLACE, "x_m": 4.0, "y_m": 3.0, "radius_m": 10.0, "event": EVENT, "on": "inside"}]
    folder = tmp_path_factory.mktemp("hostile")
    yml = folder / "hostile.yaml"
    yml.write_text(yaml.safe_dump(doc, allow_unicode=True), encoding="utf-8")
    out = folder / "run"
    run(str(yml), out_dir=out, progress=False)

    scn = read_yaml((out / "scenario.yaml").read_text(encoding="utf-8"))
    assert scn["description"] == DESCRIPTION and [g["name"] for g in scn["robots"]] == [GROUP_A, GROUP_B]
    scn["name"] = SCENARIO_NAME
    (out / "scenario.yaml").write_text(yaml.safe_dump(scn, allow_unicode=True), encoding="utf-8")
    layers = json.loads((out / "layers.json").read_text(encoding="utf-8"))
    layers["layers"]["goal"]["description"] = LAYER_NOTE
    labels = layers["layers"]["state"]["labels"]
    assert labels, layers["layers"]["state"]
    labels[0] = STATE_LABEL  # the state every lab robot starts in
    (out / "layers.json").write_text(json.dumps(layers), encoding="utf-8")
    build_replay(out, out / "replay.html")
    return out


def _meta_block(page: str) -> str:
    start = page.index('id="teamnav-meta">') + len('id="teamnav-meta">')
    return page[start: page.index("</script>", start)]


def test_replay_metadata_cannot_leave_its_script_element(hostile_run):
    page = (hostile_run / "replay.html").read_text(encoding="utf-8")
    block = _meta_block(page)
    assert not set(block) & set("<>&" + SEPARATORS), "the metadata JSON holds a raw <, >, & or line separator"
    meta, _ = _decode(page)
    assert meta["title"].startswith(SCENARIO_NAME + " — ")
    assert meta["robots"]["group"] == [GROUP_A, GROUP_A, GROUP_B]
    assert {(e["event"], e["place"]) for e in meta["events"]} == {(EVENT, PLACE)}
    assert SENSOR in {s["sensor"] for s in meta["scans"]}
    by_name = {L["name"]: L for L in meta["layers"]}
    assert by_name["goal"]["description"] == LAYER_NOTE and by_name["state"]["labels"][0] == STATE_LABEL


def test_replay_page_holds_no_hostile_markup(hostile_run):
    page = (hostile_run / "replay.html").read_text(encoding="utf-8")
    assert len(re.findall(r"<script\b", page, re.I)) == 3  # metadata, data, the page's own script
    assert len(re.findall(r"</script", page, re.I)) == 3
    assert "<img" not in page.lower() and "<!--<script" not in page.lower()
    title = page[page.index("<title>") + 7: page.index("</title>")]
    assert html.unescape(title).startswith(SCENARIO_NAME) and "<" not in title and '"' not in title
    csp = re.search(r'<meta http-equiv="Content-Security-Policy" content="([^"]+)">', page)
    assert csp and "script-src 'sha256-" in html.unescape(csp.group(1)) and "default-src 'none'" in html.unescape(csp.group(1))


# ---------------------------------------------------------------------------- the report
class _Tags(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, list]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, attrs))


def _hostile_report() -> str:
    import numpy as np

    from teamnav.experiments.report import SectionOutcome
    from teamnav.experiments.report.html import render_report
    from teamnav.experiments.report.model import Comparison, MapView, Missing, Plot, Series, Table, Text
    from teamnav.world import builtin_map

    blocks = [
        Text(f"{DESCRIPTION}\n\n{ENTITIES}"),
        Comparison(GROUP_A, PLACE, EVENT, True, GROUP_B),
        Table(SCENARIO_NAME, [SCRIPT, IMG], [[GROUP_A, 1.5], [EVENT, None]], note=COMMENT),
        Plot(IMG, SCRIPT, CLOSE, [Series(GROUP_B, [0.0, 1.0], [0.0, 1.0])], hlines=[(0.5, PLACE)], caption=SCRIPT),
        MapView(SCRIPT, builtin_map("office_simple").grid, points=[(GROUP_A, np.array([[2.0, 3.0]]))],
                markers=[(PLACE, 3.0, 3.0)], caption=IMG),
        Missing(SCRIPT, IMG),
    ]
    sections = [
        SectionOutcome(key=f"k{IMG}", title=SCENARIO_NAME, paper=CLOSE, status="ok", blocks=blocks, summary=DESCRIPTION),
        SectionOutcome(key="broken", title=GROUP_B, paper="p.txt", status="error", blocks=[Missing(EVENT, SCRIPT)],
                       error=SCRIPT, traceback=f"Traceback\n  {IMG}\nValueError: {SCRIPT}"),
    ]
    return render_report(sections, {"quick": True, "executor": f"local{SCRIPT}", "address": IMG, "wall_s": 1.0})


@pytest.fixture(scope="module")
def report_page(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("report") / "index.html"
    out.write_text(_hostile_report(), encoding="utf-8")
    return out


def test_report_escapes_every_string(report_page):
    text = report_page.read_text(encoding="utf-8")
    parser = _Tags()
    parser.feed(text)
    tags = {t for t, _ in parser.tags}
    assert not tags & {"script", "iframe", "object", "embed", "svg", "math", "base", "form", "link"}, tags
    handlers = [(t, a) for t, attrs in parser.tags for a, _ in attrs if a.lower().startswith("on")]
    assert handlers == []
    imgs = [dict(attrs) for t, attrs in parser.tags if t == "img"]
    assert len(imgs) == 2 and all(i["src"].startswith("data:image/png;base64,") for i in imgs)  # the two figures
    for s in (SCENARIO_NAME, DESCRIPTION, GROUP_A, GROUP_B, PLACE, EVENT, SCRIPT, IMG, CLOSE, COMMENT):
        assert s not in text, f"{s!r} appears unescaped"
    assert html.escape(SCENARIO_NAME) in text and html.escape(ENTITIES) in text


# ---------------------------------------------------------------------------- in a real browser
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: runs before any of the page's own scripts: a payload that ran would leave a trace here
HOOK = ("window.__pwned = 0; window.__dialogs = [];"
        "window.alert = window.confirm = window.prompt = (m) => { window.__pwned = 'dialog'; window.__dialogs.push(String(m)); };")


@pytest.fixture(scope="module")
def browser():
    if not os.path.exists(CHROMIUM):
        if os.environ.get("TEAMNAV_REQUIRE_BROWSER") == "1":
            pytest.fail(f"TEAMNAV_REQUIRE_BROWSER=1 but Debian's chromium is not at {CHROMIUM}")
        pytest.skip("Debian's chromium is not installed (apt-get install -y chromium); .ci/run installs it and never skips this test")
    from playwright.sync_api import sync_playwright

    profile = tempfile.mkdtemp(prefix="teamnav-chromium-")
    with sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(profile, executable_path=CHROMIUM, headless=True, args=ARGS,
                                                   viewport={"width": 1200, "height": 760})
        ctx.add_init_script(HOOK)
        try:
            yield ctx
        finally:
            ctx.close()
            shutil.rmtree(profile, ignore_errors=True)


def _open(ctx, path: Path):
    page = ctx.new_page()
    page.messages = []
    page.on("console", lambda m: page.messages.append((m.type, m.text)))
    page.on("pageerror", lambda e: page.messages.append(("pageerror", str(e))))
    page.on("dialog", lambda d: (page.messages.append(("dialog", d.message)), d.dismiss()))
    page.goto(path.as_uri())
    return page


def _no_trace(page, title: str) -> None:
    assert page.evaluate("window.__pwned") == 0, page.evaluate("window.__dialogs")
    assert page.title() == title  # the literal text, not the 'PWNED' a payload would set
    assert page.evaluate("document.querySelectorAll('[onerror], [onload], iframe, object, embed').length") == 0
    errors = [m for m in page.messages if m[0] in ("error", "pageerror", "dialog")]
    assert errors == [], errors


def test_replay_runs_no_hostile_script_and_still_draws(browser, hostile_run):
    page = _open(browser, hostile_run / "replay.html")
    page.wait_for_function("window.teamnavReplay && (teamnavReplay.ready || teamnavReplay.error)", timeout=30_000)
    assert page.evaluate("teamnavReplay.error") is None and page.evaluate("teamnavReplay.errors") == []
    meta = json.loads(page.evaluate("document.getElementById('teamnav-meta').textContent"))
    assert meta["title"].startswith(SCENARIO_NAME)
    assert page.evaluate("document.scripts.length") == 3
    assert page.evaluate("document.images.length") == 0
    assert page.evaluate("document.getElementById('title').textContent") == meta["title"]
    assert page.evaluate("teamnavReplay.canvasHash()")["colours"] >= 8  # map, robots, scans: not blank

    page.evaluate("teamnavReplay.setFrame(0)")
    robots = page.evaluate("document.getElementById('robots').textContent")
    assert GROUP_A in robots and GROUP_B in robots and STATE_LABEL in robots
    layers = page.evaluate("document.getElementById('layers').textContent")
    assert SENSOR in layers and LAYER_NOTE in layers and GROUP_A in layers
    page.evaluate("teamnavReplay.setFrame(teamnavReplay.nFrames - 1)")
    events = page.evaluate("document.getElementById('events').textContent")
    assert EVENT in events and PLACE in events
    page.wait_for_timeout(200)  # an <img onerror> would have fired by now
    _no_trace(page, meta["title"])


def test_replay_policy_blocks_injected_markup(browser, hostile_run):
    """A second line of defence: the page's Content-Security-Policy runs no inline handler and
    no script element but its own, even if markup got in."""
    page = _open(browser, hostile_run / "replay.html")
    page.wait_for_function("window.teamnavReplay && teamnavReplay.ready", timeout=30_000)
    page.evaluate("""() => {
        document.getElementById('summary').innerHTML = '<img src=x onerror="window.__pwned=8">';
        const s = document.createElement('script'); s.textContent = 'window.__pwned = 9'; document.body.appendChild(s);
    }""")
    page.wait_for_timeout(300)
    assert page.evaluate("window.__pwned") == 0
    assert any("Content Security Policy" in m[1] for m in page.messages), page.messages


def test_report_runs_no_hostile_script(browser, report_page):
    page = _open(browser, report_page)
    page.wait_for_load_state("load")
    page.wait_for_timeout(200)
    assert page.evaluate("document.scripts.length") == 0
    assert page.evaluate("document.images.length") == 2  # the two figures, as data: URIs
    assert page.evaluate("document.querySelector('section h2').textContent") == SCENARIO_NAME
    assert DESCRIPTION in page.evaluate("document.body.textContent")
    _no_trace(page, "teamnav report (quick)")
