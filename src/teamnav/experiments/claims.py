"""Verdict rules fixed before the data: one versioned claim file per report section.

``claims/<section>.yaml`` in the folder of the paper that declares the section
(:mod:`teamnav.plugins`; e.g. ``teamnav/papers/los_help/claims/los-help.yaml``) holds, for each claim a report section judges: the
paper's statement (quote and section), the paper's number, the metric, the verdict rule (one or
more conditions, all of which must hold: a metric, a comparison, a threshold and, for a relative
rule, the metric it is relative to), the seeds (report seeds only: below 1000, or fresh judged seeds from 2000; tuning uses 1000-1999,
never a report), the number of runs judged, which column is judged (``paper_rules``: the paper
as written; ``teamnav``: our gap-fills) and the rule's history.

The section computes the named metrics (store columns or derived metrics it names in its
docstring) for each column and calls :func:`judge`; it never hard-codes a threshold. A claim file
is committed before the runs it judges; a later change of a rule is its own commit whose message
says why, and adds a ``history`` entry (the report prints the history beside the rule).

>>> c = Claim.model_validate({"id": "x", "title": "t", "statement": {"quote": "q", "section": "§5"},
...     "paper_number": "2.8x", "metric": "ratio", "rule": [{"metric": "ratio", "op": ">=", "threshold": 2.5}],
...     "seeds": "0-9", "n": 10, "judged": "paper_rules",
...     "history": [{"date": "2026-11-27", "change": "first", "why": "w", "before_data": True}]})
>>> judge(c, {"ratio": 2.6})
(True, 'ratio = 2.6 >= 2.5: holds')
>>> judge(c, {"ratio": float("nan")})[0] is None
True
>>> c.seed_list[:3], rule_text(c)
([0, 1, 2], 'ratio >= 2.5')
"""

from __future__ import annotations

import math
import re
from functools import lru_cache
from pathlib import Path
from typing import Literal, Mapping

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

__all__ = ["CLAIMS_DIR", "Claim", "claims_path", "ClaimFile", "Condition", "JUDGED_SEED_MIN", "TUNING_SEED_MAX", "TUNING_SEED_MIN", "judge", "load_claims", "rule_text"]

#: the folder of the claim files
CLAIMS_DIR = Path(__file__).with_name("claims")  #: claim files of sections the core adds itself (none today)


def claims_path(section: str) -> Path:
    """The claim file of ``section``: ``claims/<section>.yaml`` of the installed paper that
    declares the section, else of :data:`CLAIMS_DIR`."""
    from teamnav import plugins

    for paper in plugins.papers().values():
        if any(s.key == section for s in paper.sections):
            folder = paper.folder()
            if folder is not None:
                return folder / "claims" / f"{section}.yaml"
    return CLAIMS_DIR / f"{section}.yaml"
#: tuning seeds are TUNING_SEED_MIN .. TUNING_SEED_MAX; a claim's seeds lie outside that range: the
#: report seeds below it, or fresh judged seeds above it (FIDELITY §3: judged on seeds no run has
#: touched, e.g. 2000-2029)
TUNING_SEED_MIN = 1000
TUNING_SEED_MAX = 1999
#: the first of the fresh judged seeds (named in a claim file before any run; seeds 0-29 have been
#: looked at many times)
JUDGED_SEED_MIN = TUNING_SEED_MAX + 1

_OPS = {">=": lambda a, b: a >= b, "<=": lambda a, b: a <= b, ">": lambda a, b: a > b, "<": lambda a, b: a < b}
_STRICT = ConfigDict(extra="forbid", frozen=True, strict=False)


class Statement(BaseModel):
    """The paper's words and where they are."""

    model_config = _STRICT
    quote: str = Field(min_length=1)
    section: str = Field(min_length=1)


class Condition(BaseModel):
    """One condition: ``metric op threshold`` or, relative, ``metric op threshold x relative_to``."""

    model_config = _STRICT
    metric: str = Field(min_length=1)
    op: Literal[">=", "<=", ">", "<"]
    threshold: float
    relative_to: str | None = None
    offset: float = 0.0

    @field_validator("threshold")
    @classmethod
    def _finite(cls, v: float) -> float:
        if not math.isfinite(v):
            raise ValueError(f"threshold must be finite, got {v!r}")
        return v


class HistoryEntry(BaseModel):
    """One version of a rule: when, what, why, and whether it was fixed before the data it judges."""

    model_config = _STRICT
    date: str = Field(pattern=r"^\d{4}-\d{2}-\d{2}$")
    change: str = Field(min_length=1)
    why: str = Field(min_length=1)
    before_data: bool
    commit: str | None = Field(None, pattern=r"^[0-9a-f]{7,40}$")


def _parse_seeds(text: str) -> list[int]:
    out: list[int] = []
    for part in text.split(","):
        part = part.strip()
        m = re.fullmatch(r"(\d+)(?:-(\d+))?", part)
        if not m:
            raise ValueError(f"seeds: expected 'a-b' or 'a,b,c', got {text!r}")
        a, b = int(m[1]), int(m[2] or m[1])
        if b < a:
            raise ValueError(f"seeds: range {part!r} runs backwards")
        out += list(range(a, b + 1))
    return out


class Claim(BaseModel):
    """One verdict of a report section (module docstring)."""

    model_config = _STRICT
    id: str = Field(pattern=r"^[a-z0-9][a-z0-9-]*$")
    title: str = Field(min_length=1)
    statement: Statement
    paper_number: str = Field(min_length=1)
    metric: str = Field(min_length=1)
    rule: list[Condition] = Field(min_length=1)
    min_duration_s: float = Field(0.0, ge=0.0)
    seeds: str
    quick_seeds: str | None = None
    n: int = Field(ge=1)  # runs judged in full mode (all cases and both teams where a rule reads both)
    #: a paired verdict: fewer pairs than this (read from the metric ``pairs_metric``) reads "not
    #: judged (n = k)" (FIDELITY §3: at least 5, fixed in the claim file)
    min_pairs: int | None = Field(None, ge=5)
    pairs_metric: str = Field("n_pairs", min_length=1)
    judged: Literal["paper_rules", "teamnav"]
    history: list[HistoryEntry] = Field(min_length=1)
    note: str = ""
    #: For sections whose runs vary a task, not a seed (line-of-sight help): the judged task
    #: numbers, "a-b" or "a,b,c", outside the tuning range like seeds (FIDELITY §3); None: seeds only.
    tasks: str | None = None

    @field_validator("seeds", "quick_seeds", "tasks")
    @classmethod
    def _report_seeds(cls, v: str | None) -> str | None:
        if v is None:
            return v
        seeds = _parse_seeds(v)
        tuning = [x for x in seeds if TUNING_SEED_MIN <= x <= TUNING_SEED_MAX]
        if tuning:
            raise ValueError(f"seeds {v!r}: seeds {TUNING_SEED_MIN}-{TUNING_SEED_MAX} are tuning seeds, never a "
                             f"report's (got {tuning[0]})")
        return v

    @model_validator(mode="after")
    def _n_covers_seeds(self) -> "Claim":
        if self.n < len(self.seed_list):
            raise ValueError(f"claim {self.id}: n = {self.n} runs judged is fewer than its {len(self.seed_list)} seeds")
        return self

    @property
    def seed_list(self) -> list[int]:
        return _parse_seeds(self.seeds)

    @property
    def task_list(self) -> list[int]:
        """The judged tasks (``tasks``; empty when the claim names none)."""
        return _parse_seeds(self.tasks) if self.tasks else []


class ClaimFile(BaseModel):
    """One section's claim file."""

    model_config = _STRICT
    section: str = Field(min_length=1)
    paper: str = Field(min_length=1)
    claims: list[Claim] = Field(min_length=1)

    @model_validator(mode="after")
    def _unique(self) -> "ClaimFile":
        ids = [c.id for c in self.claims]
        dup = sorted({i for i in ids if ids.count(i) > 1})
        if dup:
            raise ValueError(f"claim ids must be unique, repeated: {dup}")
        return self

    def __getitem__(self, claim_id: str) -> Claim:
        for c in self.claims:
            if c.id == claim_id:
                return c
        raise KeyError(f"{self.section}: no claim {claim_id!r}; it has {[c.id for c in self.claims]}")


@lru_cache(maxsize=None)
def load_claims(section: str, folder: str | None = None) -> ClaimFile:
    """The claim file of report section ``section`` (:func:`claims_path`, or
    ``folder/<section>.yaml``), validated.

    Raises
    ------
    FileNotFoundError
        No file for that section.
    ValueError
        The file breaks the schema (unknown keys included) or names another section.
    """
    from teamnav.safe_yaml import safe_load

    path = Path(folder) / f"{section}.yaml" if folder else claims_path(section)
    data = safe_load(path.read_text(encoding="utf-8"))
    cf = ClaimFile.model_validate(data)
    if cf.section != section:
        raise ValueError(f"{path}: section is {cf.section!r}, expected {section!r}")
    return cf


def _fmt(v: float) -> str:
    return f"{v:.3g}" if abs(v) < 1e4 else f"{v:.0f}"


def judge(claim: Claim, values: Mapping[str, float], duration_s: float | None = None) -> tuple[bool | None, str]:
    """Whether ``claim`` holds on ``values`` (metric name -> number), and how it was read.

    None (not judged) when a metric is missing or not finite, when ``duration_s`` is below
    the claim's ``min_duration_s``, or when a paired claim has fewer than ``min_pairs`` pairs.
    """
    if duration_s is not None and duration_s < claim.min_duration_s:
        return None, f"not judged on {duration_s / 60:g}-min runs (the rule needs >= {claim.min_duration_s / 60:g} min)"
    if claim.min_pairs is not None:
        k = values.get(claim.pairs_metric)
        if not isinstance(k, (int, float)) or not math.isfinite(k):
            return None, f"{claim.pairs_metric}: not measured"
        if k < claim.min_pairs:
            return None, f"not judged (n = {int(k)} pairs; the rule needs >= {claim.min_pairs})"
    parts, holds = [], True
    for c in claim.rule:
        a = values.get(c.metric)
        ref = values.get(c.relative_to) if c.relative_to else 1.0
        if not isinstance(a, (int, float)) or not isinstance(ref, (int, float)) or not (math.isfinite(a) and math.isfinite(ref)):
            return None, f"{c.metric}{' / ' + c.relative_to if c.relative_to else ''}: not measured"
        bound = c.threshold * ref + c.offset
        ok = _OPS[c.op](a, bound)
        holds &= ok
        if c.relative_to:
            plus = f" + {_fmt(c.offset)}" if c.offset else ""
            parts.append(f"{c.metric} = {_fmt(a)} {c.op} {_fmt(c.threshold)} x {c.relative_to}{plus} = {_fmt(bound)}")
        else:
            parts.append(f"{c.metric} = {_fmt(a)} {c.op} {_fmt(c.threshold)}")
        if not ok:
            parts[-1] += " (fails)"
    return bool(holds), "; ".join(parts) + (": holds" if holds else ": does not hold")


def rule_text(claim: Claim) -> str:
    """The rule as one line (all conditions must hold)."""
    return " and ".join(f"{c.metric} {c.op} {_fmt(c.threshold)}" + (f" x {c.relative_to}" if c.relative_to else "")
                        + (f" + {_fmt(c.offset)}" if c.offset else "") for c in claim.rule)


def history_text(claim: Claim) -> str:
    """The rule's history as one line per version."""
    return " | ".join(f"{h.date}{' ' + h.commit if h.commit else ''}: {h.change} ({'before' if h.before_data else 'AFTER'} "
                      f"the data; {h.why})" for h in claim.history)
