"""MkDocs hooks of the teamnav site (``hooks:`` in ``mkdocs.yml``).

Four things a plain MkDocs build cannot do:

- ``{{ include "src/teamnav/papers/los_help/README.md" }}`` on a line of its own puts a file of
  the repository into the page, so that each paper's README stays the one place its rules are
  written down and the site shows it as it is (its first heading is dropped: the page has its
  own title).
- Relative links are read against the file that wrote them (the page, or the included file).
  One that lands in ``docs/`` becomes a link to that page; one that lands elsewhere in the
  repository (a module, a claim file) becomes the path in code, ``src/...``, since the site does
  not carry the source; one that lands nowhere is left alone, so ``mkdocs build --strict``
  fails on it. The pages under ``docs/report/`` are shown as they are written: only their
  links are read this way, at build time, never rewritten on disk.
- ``{{ paper-rules "module:ParamsClass" }}`` becomes a table of that brain's gap-fills
  (``PAPER_RULES``): each flag, teamnav's default and the paper's value.
- ``{{ teamnav-cli-help }}`` becomes the ``--help`` text of ``teamnav`` and of every one of its
  commands, taken from the installed command at build time, so the reference cannot fall behind.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"

_INCLUDE = re.compile(r'^\{\{ include "(?P<path>[^"]+)" \}\}[ \t]*$', re.MULTILINE)
_CLI = re.compile(r"^\{\{ teamnav-cli-help \}\}[ \t]*$", re.MULTILINE)
_RULES = re.compile(r'^\{\{ paper-rules "(?P<entry>[\w.]+:\w+)" \}\}[ \t]*$', re.MULTILINE)
# [text](target) and ![alt](target), not inside inline code; a target has no spaces
_LINK = re.compile(r"(?P<bang>!?)\[(?P<text>[^\]\n]*)\]\((?P<target>[^)\s]+)\)")
_FENCE = re.compile(r"^(```|~~~).*?^\1[ \t]*$", re.MULTILINE | re.DOTALL)


def _split_fences(text: str) -> list[tuple[bool, str]]:
    """``text`` in pieces, each marked whether it lies inside a fenced code block."""
    out, at = [], 0
    for m in _FENCE.finditer(text):
        out.append((False, text[at:m.start()]))
        out.append((True, m.group(0)))
        at = m.end()
    out.append((False, text[at:]))
    return out


def relink(text: str, source_dir: Path, page_dir: Path) -> str:
    """Read every relative link of ``text`` (written in ``source_dir``) for a page in ``page_dir``."""

    def one(m: re.Match) -> str:
        target = m.group("target")
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith(("#", "/")):
            return m.group(0)
        path, _, anchor = target.partition("#")
        resolved = (source_dir / path).resolve()
        if not resolved.exists():
            return m.group(0)  # a broken link stays a link: the strict build reports it
        if resolved.is_relative_to(DOCS):
            rel = os.path.relpath(resolved, page_dir)
            return f"{m.group('bang')}[{m.group('text')}]({rel}{'#' + anchor if anchor else ''})"
        repo_path = resolved.relative_to(ROOT).as_posix()
        if m.group("bang"):
            return f"`{repo_path}`"
        text = m.group("text")
        return f"{text} (`{repo_path}`)" if text.strip("`") != repo_path and text != repo_path else f"`{repo_path}`"

    return "".join(piece if fenced else _LINK.sub(one, piece) for fenced, piece in _split_fences(text))


def _include(m: re.Match, page_dir: Path) -> str:
    path = ROOT / m.group("path")
    text = path.read_text(encoding="utf-8")
    text = re.sub(r"\A# [^\n]*\n+", "", text)  # the page has its own title
    return relink(text, path.parent, page_dir)


def cli_help() -> str:
    """The ``--help`` of ``teamnav`` and of each of its commands, as Markdown."""
    from typer.main import get_command
    from typer.testing import CliRunner

    from teamnav.cli import app

    runner = CliRunner()
    parts = []
    command = get_command(app)
    names = [None, *sorted(getattr(command, "commands", {}))]
    for name in names:
        args = ([name] if name else []) + ["--help"]
        res = runner.invoke(app, args, env={"COLUMNS": "100", "TERM": "dumb", "NO_COLOR": "1"})
        if res.exit_code != 0:
            raise RuntimeError(f"teamnav {' '.join(args)} failed: {res.output}")
        title = f"teamnav {name}" if name else "teamnav"
        parts.append(f"## `{title}`\n\n```text\n{res.output.rstrip()}\n```\n")
    return "\n".join(parts)


def _value(v) -> str:
    return f"`{v!r}`" if not isinstance(v, str) else f"`{v}`"


def paper_rules_table(entry: str) -> str:
    """A Params class's gap-fills (its ``PAPER_RULES``): each flag, teamnav's default and the
    paper's value, which ``paper_rules: true`` sets."""
    import importlib

    module, _, name = entry.partition(":")
    params = getattr(importlib.import_module(module), name)
    rules = getattr(params, "PAPER_RULES", None)
    if not rules:
        raise RuntimeError(f"{entry} declares no PAPER_RULES")
    rows = ["| parameter | teamnav's default | the paper's value (`paper_rules: true`) |", "| --- | --- | --- |"]
    for key, paper_value in rules.items():
        field = params.model_fields.get(key)
        default = _value(field.default) if field is not None else "—"
        rows.append(f"| `{key}` | {default} | {_value(paper_value)} |")
    return "\n".join(rows) + "\n"


def on_page_markdown(markdown: str, page, config, files) -> str:
    src = Path(page.file.abs_src_path)
    markdown = _INCLUDE.sub(lambda m: _include(m, src.parent), markdown)
    markdown = _RULES.sub(lambda m: paper_rules_table(m.group("entry")), markdown)
    if _CLI.search(markdown):
        markdown = _CLI.sub(lambda m: cli_help(), markdown)
    return relink(markdown, src.parent, src.parent)
