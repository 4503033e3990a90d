"""The HTML replay in a real browser: Debian's headless Chromium driven by Playwright.

Never skipped in CI: ``.ci/run`` installs ``chromium`` when it is missing and sets
``TEAMNAV_REQUIRE_BROWSER=1``, so a missing browser there is a failure. On a developer's fresh
machine without Debian's ``chromium`` the test is skipped with a message saying how to get it,
so the README's test command still works. Playwright (from the test extra) drives that binary;
Playwright's own browser downloads are never used.
"""

from __future__ import annotations

import os
import shutil
import tempfile

import pytest
from playwright.sync_api import sync_playwright

import _replay_run
from teamnav.viz.replay import build_replay

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
if not os.path.exists(CHROMIUM) and os.environ.get("TEAMNAV_REQUIRE_BROWSER") != "1":
    pytest.skip("Debian's chromium is not installed (apt-get install -y chromium); "
                ".ci/run installs it and never skips this test", allow_module_level=True)
ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    run_dir = _replay_run.make_run(tmp_path_factory.mktemp("lab"))
    html = build_replay(run_dir, run_dir / "replay.html").path
    profile = tempfile.mkdtemp(prefix="teamnav-chromium-")
    messages: list[tuple[str, str]] = []
    with sync_playwright() as p:
        ctx = p.chromium.launch_persistent_context(profile, executable_path=CHROMIUM, headless=True, args=ARGS,
                                                   viewport={"width": 1200, "height": 760})
        try:
            pg = ctx.new_page()
            pg.on("console", lambda m: messages.append((m.type, m.text)))
            pg.on("pageerror", lambda e: messages.append(("pageerror", str(e))))
            pg.goto(html.as_uri())
            pg.wait_for_function("window.teamnavReplay && (teamnavReplay.ready || teamnavReplay.error)", timeout=30_000)
            pg.messages = messages
            yield pg
        finally:
            ctx.close()
            shutil.rmtree(profile, ignore_errors=True)


def test_loads_without_console_errors_and_draws(page):
    assert page.evaluate("teamnavReplay.error") is None
    assert page.evaluate("teamnavReplay.ready") is True
    errors = [m for m in page.messages if m[0] in ("error", "pageerror")]
    assert errors == []
    assert page.evaluate("teamnavReplay.errors") == []
    drawn = page.evaluate("teamnavReplay.canvasHash()")
    assert drawn["colours"] >= 8, drawn  # map, robots, rays...: not a blank canvas


def test_scrubber_moves_the_robots(page):
    n = page.evaluate("teamnavReplay.nFrames")
    page.locator("#scrub").focus()
    page.keyboard.press("Home")
    assert page.evaluate("teamnavReplay.frame") == 0
    before_px = page.evaluate("teamnavReplay.robotScreen()")
    before_png = page.locator("#view").screenshot()
    page.keyboard.press("End")  # the range input's own keyboard handling fires `input`
    assert page.evaluate("teamnavReplay.frame") == n - 1
    assert page.locator("#clock").inner_text().endswith(f"frame {n}/{n}")
    after_px = page.evaluate("teamnavReplay.robotScreen()")
    moved = [abs(a[0] - b[0]) + abs(a[1] - b[1]) for a, b in zip(before_px, after_px)]
    assert min(moved) > 5, moved
    assert page.locator("#view").screenshot() != before_png


def test_every_layer_toggle_changes_the_picture(page):
    events = page.evaluate("JSON.parse(document.getElementById('teamnav-meta').textContent).events")
    page.evaluate(f"teamnavReplay.setFrame({max(e['f'] for e in events)})")  # a frame with an event and every layer
    names = page.evaluate("teamnavReplay.layers")
    assert {"map", "true", "trails", "belief", "scans", "detections", "messages", "crumbs", "goal", "state", "events"} <= set(names)
    for name in names:
        box = page.locator(f"#layer-{name}")
        shown = page.evaluate("teamnavReplay.canvasHash().hash")
        box.click()
        assert not box.is_checked()
        hidden = page.evaluate("teamnavReplay.canvasHash().hash")
        box.click()
        assert box.is_checked() and page.evaluate("teamnavReplay.canvasHash().hash") == shown
        assert hidden != shown, f"toggling layer {name!r} did not change the picture"


def test_play_follow_and_state_panel(page):
    page.evaluate("teamnavReplay.setFrame(0)")
    page.locator("#speed").select_option("5")
    page.locator("#play").click()
    page.wait_for_function("teamnavReplay.frame > 3", timeout=5_000)
    page.locator("#play").click()
    assert page.evaluate("teamnavReplay.isPlaying()") is False
    page.locator("#follow").select_option("2")
    f = page.evaluate("teamnavReplay.frame")
    x, y = page.evaluate("teamnavReplay.robotScreen()")[2]
    w, h = page.evaluate("[document.getElementById('view').clientWidth, document.getElementById('view').clientHeight]")
    assert abs(x - w / 2) < 1 and abs(y - h / 2) < 1  # the followed robot stays in the middle
    page.locator("#fwd").click()
    assert page.evaluate("teamnavReplay.frame") == f + 1
    table = page.locator("#robots").inner_text()
    assert "searching" in table or "carrying" in table
