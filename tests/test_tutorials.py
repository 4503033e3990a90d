"""Every code block of the tutorials (``docs/tutorials/*.md``) runs here, in page order.

Why Sybil: of the three tools that run Markdown code blocks (pytest-markdown-docs, Sybil,
pytest-examples), Sybil is the one that keeps one namespace per page (a later block uses what an
earlier one made, as a reader does), lets a page skip a block with a reason written beside it
(``<!-- skip: next if(not SLOW, reason="...") -->``, shown to the reader as nothing at all) and
takes a parser of our own for the shell blocks, which are most of a command-line tool's
tutorials. pytest-markdown-docs runs Python blocks only; pytest-examples checks the printed
output of Python blocks. We drive Sybil from this module (``Sybil.parse``) rather than through
its pytest plugin, so the pages are found under ``docs/`` while ``testpaths`` stays ``tests``,
and each page is one test, with its own working folder.

How a page's blocks run (the reader's view in brackets):

- ``python``: executed in the page's namespace, in the page's working folder.
- ``bash``: each command in turn, in the page's working folder (a ``cd`` moves it). ``teamnav
  ARGS`` and ``python -m teamnav ARGS`` run the command in this process (through typer's test
  runner, as ``tests/test_cli.py`` does: a fresh interpreter per command would cost a second or
  two of start-up each; the pages of ``FRESH_PROCESS`` are the exception) and must exit 0; ``pip install`` lines are not run (the test
  environment has the extras installed); anything else (``mkdir``, ``cp``, ``cat``) runs in
  ``bash``.
- A block whose info line names a file, ``python title="lab_brains/cautious.py"``, is written to
  that path (relative to the working folder) instead of run: the reader sees the file, the test
  writes exactly that file.
- ``text``, ``yaml``, ``toml`` blocks without a title are shown, not run.

Namespace names a page may use: ``SLOW`` (true in the slow version, ``-m slow``), ``HAVE_RAY``,
``HAVE_PANDAS`` and ``last_output`` (what the last ``teamnav`` command printed).

The default suite runs every page's short version: blocks that take long (a quick report, a Ray
cluster) are skipped there with their reason, and ``test_tutorial_slow`` runs them (``-m slow``).
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import subprocess
import sys
import unittest
from pathlib import Path

import pytest

sybil = pytest.importorskip("sybil", reason="the tutorials' runner (the 'test' extra installs sybil)")
from sybil import Sybil  # noqa: E402
from sybil.evaluators.python import PythonEvaluator  # noqa: E402
from sybil.parsers.markdown.lexers import FencedCodeBlockLexer  # noqa: E402
from sybil.parsers.markdown.skip import SkipParser  # noqa: E402

TUTORIALS = Path(__file__).resolve().parents[1] / "docs" / "tutorials"
#: Pages whose ``teamnav`` commands run in a fresh interpreter, with the page's folder on
#: ``PYTHONPATH``: the fifth-paper page registers a paper through an entry point, which must not
#: stay registered in the test process (other tests list every installed paper).
FRESH_PROCESS = {"07-fifth-paper.md"}
PAGES = sorted(p.name for p in TUTORIALS.glob("[0-9][0-9]-*.md"))
_TITLE = re.compile(r'^(?P<lang>[\w+-]+)\s+title="(?P<path>[^"]+)"\s*$')


def _cwd(ns: dict) -> Path:
    return Path(ns.setdefault("_cwd", os.getcwd()))


def _teamnav_fresh(args: list[str], ns: dict) -> None:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(_cwd(ns)), *filter(None, [os.environ.get("PYTHONPATH")])]))
    res = subprocess.run([sys.executable, "-m", "teamnav", *args], cwd=_cwd(ns), capture_output=True, text=True,
                         env=env, timeout=600)
    ns["last_output"] = res.stdout
    if res.returncode != 0:
        raise AssertionError(f"teamnav {shlex.join(args)} exited {res.returncode}:\n{res.stdout}{res.stderr}")


def _teamnav(args: list[str], ns: dict) -> None:
    if ns.get("_fresh"):
        return _teamnav_fresh(args, ns)
    from typer.testing import CliRunner

    from teamnav.cli import app

    here = os.getcwd()
    os.chdir(_cwd(ns))
    try:
        res = CliRunner().invoke(app, args)
    finally:
        os.chdir(here)
    ns["last_output"] = res.output
    if res.exit_code != 0:
        detail = "".join(__import__("traceback").format_exception(res.exc_info[1])) if res.exc_info and res.exception and not isinstance(res.exception, SystemExit) else ""
        raise AssertionError(f"teamnav {shlex.join(args)} exited {res.exit_code}:\n{res.output}{detail}")


def _commands(source: str) -> list[str]:
    """The block's commands: continuation lines joined, comments and blank lines dropped."""
    joined = re.sub(r"\\\n\s*", " ", source)
    out = []
    for line in joined.splitlines():
        words = shlex.split(line, comments=True)
        if words:
            out.append(line)
    return out


def run_shell(example) -> None:
    ns = example.namespace
    for line in _commands(example.parsed):
        for part in re.split(r"\s&&\s", line):
            words = shlex.split(part, comments=True)
            if not words:
                continue
            if words[0] == "cd":
                ns["_cwd"] = str((_cwd(ns) / words[1]).resolve())
            elif words[0] == "teamnav":
                _teamnav(words[1:], ns)
            elif words[:3] == ["python", "-m", "teamnav"]:
                _teamnav(words[3:], ns)
            elif words[:2] in (["pip", "install"], ["python", "-m"]) and "pip" in words[:3]:
                continue  # the test environment has the extras installed
            else:
                res = subprocess.run(["bash", "-c", part], cwd=_cwd(ns), capture_output=True, text=True)
                ns["last_output"] = res.stdout
                if res.returncode != 0:
                    raise AssertionError(f"{part!r} exited {res.returncode}:\n{res.stdout}{res.stderr}")


class TutorialParser:
    """Fenced blocks: ``python`` runs, ``bash`` runs command by command, ``LANG title="PATH"`` is written."""

    def __init__(self) -> None:
        self.lexer = FencedCodeBlockLexer(language=r".+", mapping={"language": "info", "source": "source"})
        self.python = PythonEvaluator()

    def __call__(self, document):
        for region in self.lexer(document):
            info = region.lexemes["info"].strip()
            titled = _TITLE.match(info)
            if titled:
                region.parsed = (titled.group("path"), str(region.lexemes["source"]))
                region.evaluator = self.write_file
            elif info == "python":
                region.parsed = region.lexemes["source"]
                region.evaluator = self.run_python
            elif info == "bash":
                region.parsed = str(region.lexemes["source"])
                region.evaluator = run_shell
            else:
                continue
            yield region

    @staticmethod
    def write_file(example) -> None:
        path, text = example.parsed
        target = _cwd(example.namespace) / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text, encoding="utf-8")

    def run_python(self, example) -> None:
        here = os.getcwd()
        os.chdir(_cwd(example.namespace))
        try:
            return self.python(example)
        finally:
            os.chdir(here)


def run_page(name: str, tmp_path: Path, monkeypatch, slow: bool) -> int:
    from teamnav.control import registry

    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    # a page registers controllers as a reader would (registry.register); the test process gets
    # its registry back afterwards, and forgets the page's own modules
    monkeypatch.setattr(registry, "_REGISTRY", dict(registry._REGISTRY))
    modules_before = set(sys.modules)
    try:
        ran = _run_examples(name, tmp_path, slow)
    finally:
        for module in set(sys.modules) - modules_before:
            if str(getattr(sys.modules[module], "__file__", None) or "").startswith(str(tmp_path)):
                del sys.modules[module]
    return ran


def _run_examples(name: str, tmp_path: Path, slow: bool) -> int:
    document = Sybil(parsers=[TutorialParser(), SkipParser()]).parse(TUTORIALS / name)
    document.namespace.update(SLOW=slow, HAVE_RAY=importlib.util.find_spec("ray") is not None,
                              HAVE_PANDAS=importlib.util.find_spec("pandas") is not None, _cwd=str(tmp_path),
                              last_output="", _fresh=name in FRESH_PROCESS)
    examples = list(document)
    assert examples, f"{name}: no code block found"
    skipped = []
    for example in examples:
        try:
            example.evaluate()
        except unittest.SkipTest as why:  # a block the page skips, with its reason: the rest still runs
            skipped.append(f"line {example.line}: {why}")
    if skipped:
        print(f"{name}: skipped " + "; ".join(skipped))
    return len(examples) - len(skipped)


def test_the_seven_tutorials_are_there():
    assert len(PAGES) == 7, PAGES
    assert SLOW_PAGES == ["04-sweeps.md", "05-report.md"]  # the Ray block; the report section


@pytest.mark.parametrize("name", PAGES)
def test_tutorial(name, tmp_path, monkeypatch):
    # every block runs (raising on a failed assertion or command) unless the page skips it
    assert run_page(name, tmp_path, monkeypatch, slow=False) >= 1, f"{name}: every code block was skipped"


#: Pages with blocks that run only in the slow set (a skip directive that reads ``SLOW``).
SLOW_PAGES = [p for p in PAGES if "SLOW" in (TUTORIALS / p).read_text(encoding="utf-8")]


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW_PAGES)
def test_tutorial_slow(name, tmp_path, monkeypatch):
    assert run_page(name, tmp_path, monkeypatch, slow=True) >= 1, f"{name}: every code block was skipped"
