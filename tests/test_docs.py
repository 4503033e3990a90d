"""The documentation site builds with ``mkdocs build --strict``: a broken link, a page missing from
the nav or a docstring the API reference cannot read fails here, so it fails CI.

The build needs the ``docs`` tools, which the ``test`` extra installs too (``pip install
'.[test]'``, the one command CI runs): without them this test fails, saying so, rather than
skipping, since a skipped build would let a broken site through CI.
"""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "docs"))
try:
    import hooks  # docs/hooks.py: the site's include, link and CLI-help hooks
finally:
    sys.path.remove(str(ROOT / "docs"))


def test_the_site_builds_strict(tmp_path):
    if importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings_handlers") is None:
        pytest.fail("mkdocs and mkdocstrings are missing: pip install '.[test]' (or '.[docs]') installs them")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    res = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")],
                         cwd=ROOT, capture_output=True, text=True, env=env, timeout=300)
    assert res.returncode == 0, res.stdout + res.stderr
    site = tmp_path / "site"
    for page in ("tutorials/01-first-run", "tutorials/07-fifth-paper", "papers/los-help", "report/los-help",
                 "reference/cli", "api/env", "api/report"):
        assert (site / page / "index.html").is_file(), page
    cli = (site / "reference/cli/index.html").read_text(encoding="utf-8")
    assert "teamnav sweep" in cli and "--seeds" in cli  # the help text, taken from the command at build time
    api = (site / "api/report/index.html").read_text(encoding="utf-8")
    assert "LedgerRow" in api and "Precondition" in api
    rules = (site / "papers/los-help/index.html").read_text(encoding="utf-8")
    assert "los_help" in rules  # the paper's README, included as it is


def test_links_are_read_against_the_file_that_wrote_them(tmp_path):
    page_dir = hooks.DOCS / "papers"
    readme_dir = hooks.ROOT / "src/teamnav/papers/los_help"
    text = ("[notes](../../../../docs/report/los-help.md#top) [code](brains/__init__.py) [gone](nowhere.md) "
            "[web](https://example.org) [here](#anchor)\n```\n[in a fence](brains/__init__.py)\n```\n")
    out = hooks.relink(text, readme_dir, page_dir)
    assert "[notes](../report/los-help.md#top)" in out  # a page of the site: a link from the page
    assert "code (`src/teamnav/papers/los_help/brains/__init__.py`)" in out  # the source: its path
    assert "[gone](nowhere.md)" in out  # broken: left for the strict build to report
    assert "[web](https://example.org)" in out and "[here](#anchor)" in out
    assert "[in a fence](brains/__init__.py)" in out  # code blocks are shown as written


def test_the_readme_opens_with_the_two_commands_and_its_links_resolve():
    """The README is one screen that links into the site: its two set-up commands come first, as
    ``.ci/run`` runs the second one, and every relative link it makes lands on a file."""
    import re

    text = (ROOT / "README.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```bash\n(.*?)```", text, re.S)
    assert [b.strip() for b in blocks[:2]] == [
        "pip install . && teamnav run demo",
        "pip install '.[test]' && python -m pytest -x -q -n auto --hypothesis-profile=ci"]
    assert blocks[1].strip() in (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    targets = [t for t in re.findall(r"\]\(([^)\s#]+)", text) if not re.match(r"^[a-z]+:", t)]
    assert targets, "the README links into the site"
    assert [t for t in targets if not (ROOT / t).exists()] == []
