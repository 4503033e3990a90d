"""Make docs/replay.png: run a scenario, write its HTML replay, screenshot it in headless Chromium.

Usage (from the repository root; needs Debian's ``chromium`` and ``pip install playwright``)::

    python docs/make_screenshot.py                       # demo, 20 s, scans on -> docs/replay.png
    python docs/make_screenshot.py --scenario depot --duration 30 --at 0.8

It runs ``teamnav run SCENARIO --set record_scans=true --html`` into a temporary folder, opens
``replay.html`` with the same browser set-up as ``tests/test_replay_browser.py``, moves the
scrubber to ``--at`` (a fraction of the run) and saves the page.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ARGS = ["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default="demo")
    ap.add_argument("--duration", type=float, default=20.0)
    ap.add_argument("--at", type=float, default=0.6, help="where on the timeline, 0..1")
    ap.add_argument("--out", type=Path, default=Path(__file__).with_name("replay.png"))
    ap.add_argument("--chromium", default=shutil.which("chromium") or "/usr/bin/chromium")
    a = ap.parse_args()
    from playwright.sync_api import sync_playwright

    work = Path(tempfile.mkdtemp(prefix="teamnav-shot-"))
    try:
        run_dir = work / "run"
        subprocess.run([sys.executable, "-m", "teamnav", "run", a.scenario, "--duration", str(a.duration), "--set",
                        "record_scans=true", "--html", "--quiet", "--out", str(run_dir)], check=True)
        with sync_playwright() as p:
            ctx = p.chromium.launch_persistent_context(str(work / "profile"), executable_path=a.chromium, headless=True,
                                                       args=ARGS, viewport={"width": 1280, "height": 760})
            page = ctx.new_page()
            page.goto((run_dir / "replay.html").as_uri())
            page.wait_for_function("window.teamnavReplay && (teamnavReplay.ready || teamnavReplay.error)", timeout=60_000)
            if page.evaluate("teamnavReplay.error"):
                raise SystemExit(page.evaluate("teamnavReplay.error"))
            page.evaluate(f"teamnavReplay.setFrame(Math.round({a.at} * (teamnavReplay.nFrames - 1)))")
            page.screenshot(path=str(a.out))
            ctx.close()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
