"""A report context for section tests: full mode without running any trial.

Each ``sweep`` call records ``(sweep name, seeds, duration_s)`` in ``asked`` and answers with the
rows that the test's ``rows_for(spec, seeds)`` builds from the sweep's spec (its cases)."""

from __future__ import annotations


class FakeRows:
    """What ``ctx.sweep`` returns: its ``rows()``."""

    def __init__(self, rows):
        self._rows = rows

    def rows(self):
        return self._rows


class FakeFullContext:
    quick = False
    progress = False

    def __init__(self, rows_for):
        self.asked: list[tuple[str, list[int], float]] = []
        self._rows_for = rows_for

    def sweep(self, name_or_spec, *, seeds, duration_s):
        from teamnav.experiments.sweep import load_sweep

        spec = load_sweep(name_or_spec) if isinstance(name_or_spec, str) else name_or_spec
        name = spec.sweep_name if hasattr(spec, "sweep_name") else spec.name
        self.asked.append((name, list(seeds), duration_s))
        return FakeRows(self._rows_for(spec, list(seeds)))
