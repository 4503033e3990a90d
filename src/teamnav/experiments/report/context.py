"""The ``ctx`` a report section's ``build(ctx)`` gets (the ReportContext of ``report.model``).

``ctx.sweep(name_or_spec, **kwargs)`` runs a sweep into ``OUT/sweeps/<sweep name>/`` through
:func:`teamnav.experiments.sweep.sweep`, with the report's executor, workers and progress
setting; the other keyword arguments are sweep's own (``grid``, ``seeds``, ``set``,
``duration_s``, ``name``, ``retry_failed``, ``artifacts``, ``trial_fn``). Because the store is
resumable, building the report again reuses every finished trial.

The result's ``rows()`` and ``dataframe()`` hold only the trials of *this* call: the quick and
the full versions of a sweep share its folder (same name) but not their trials (other seeds or
durations make other trial ids), and a section never sees the other version's rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from teamnav.experiments.sweep import SweepResult

__all__ = ["ReportSweepResult", "SweepContext"]

#: sweep() arguments that belong to the report, not to the section
_REPORT_OWNED = ("out_dir", "workers", "progress", "executor", "address", "group_brains")


@dataclass
class ReportSweepResult(SweepResult):
    """A :class:`~teamnav.experiments.sweep.SweepResult` restricted to one call's trials.

    ``trial_ids`` are the ids of the trials the call asked for; ``rows()`` and ``dataframe()``
    return only those (``all_trials=True`` returns every row of the sweep's name)."""

    trial_ids: frozenset[str] = frozenset()

    def rows(self, *, all_sweeps: bool = False, all_trials: bool = False) -> list[dict[str, Any]]:
        rows = super().rows(all_sweeps=all_sweeps)
        if all_sweeps or all_trials:
            return rows
        return [r for r in rows if r["trial_id"] in self.trial_ids]

    def dataframe(self, *, all_sweeps: bool = False, all_trials: bool = False):
        df = super().dataframe(all_sweeps=all_sweeps)
        if all_sweeps or all_trials:
            return df
        return df[df["trial_id"].isin(sorted(self.trial_ids))].reset_index(drop=True)


class SweepContext:
    """What a section's ``build`` gets (implements ``report.model.ReportContext``).

    Parameters
    ----------
    out_dir : Path
        The report folder; sweeps go to ``out_dir/sweeps/<sweep name>/``.
    quick : bool
        The short version of the report.
    executor, workers, address :
        Passed to every sweep (see :func:`teamnav.experiments.sweep.sweep`).
    progress : bool
        Show the sweeps' progress bars.
    section : str
        The key of the section being built (for messages).
    runner : Executor, optional
        An executor object every sweep of this context uses instead of a new ``executor`` per
        sweep (``run_report`` shares one ``LocalExecutor(keep_pool=True)`` across the report's
        sweeps, so the worker processes start once per report, not once per sweep).
    group_brains : bool
        Every sweep's trials step teams through their compiled group brains where they have
        one (``teamnav report --group-brains``; the same runs, bit for bit).

    Attributes
    ----------
    sweeps : list of dict
        One entry per :meth:`sweep` call: ``name``, ``folder``, ``total``, ``run`` (trials run
        now), ``failed``, ``reused`` (trials found in the store), ``elapsed_s``,
        ``trials_cpu_s`` (the CPU time of its finished trials as the store recorded them, run
        now or found there: the sweep's cost on a shared machine) and ``trials_cpu_measured``
        (how many of them recorded one).
    """

    def __init__(
        self,
        out_dir: str | Path,
        *,
        quick: bool = False,
        executor: str = "local",
        workers: int | None = None,
        address: str | None = None,
        progress: bool = False,
        section: str = "",
        runner: Any = None,
        group_brains: bool = False,
    ) -> None:
        self.out_dir = Path(out_dir)
        self.quick = bool(quick)
        self.executor = executor
        self.workers = workers
        self.address = address
        self.progress = bool(progress)
        self.section = section
        self.runner = runner
        self.group_brains = bool(group_brains)
        self.sweeps: list[dict[str, Any]] = []

    @property
    def section_dir(self) -> Path:
        """``out_dir/<section key>/`` for a section's extra files (created on first use)."""
        path = self.out_dir / (self.section or "section")
        path.mkdir(parents=True, exist_ok=True)
        return path

    def sweep(self, name_or_spec: Any, **kwargs: Any) -> ReportSweepResult:
        """Run or reuse a sweep into ``out_dir/sweeps/<sweep name>/``.

        Parameters
        ----------
        name_or_spec : SweepSpec, str or Path
            As :func:`teamnav.experiments.sweep.sweep`.
        **kwargs
            sweep's keyword arguments except ``out_dir``, ``workers``, ``progress``,
            ``executor``, ``address`` and ``group_brains`` (the report sets those).

        Returns
        -------
        ReportSweepResult
            ``rows()`` holds this call's trials only.

        Raises
        ------
        TypeError
            A report-owned argument was given.
        SweepError
            As sweep.
        """
        from teamnav.experiments.sweep import expand, resolve_spec, sweep

        owned = [k for k in _REPORT_OWNED if k in kwargs]
        if owned:
            raise TypeError(
                f"ctx.sweep: {', '.join(owned)} is set by the report (teamnav report --executor/--workers/--address/--quiet), "
                f"not by a section; received {owned[0]}={kwargs[owned[0]]!r}"
            )
        spec_keys = ("grid", "seeds", "set", "duration_s", "name")
        spec = resolve_spec(name_or_spec, **{k: kwargs.pop(k) for k in spec_keys if k in kwargs})
        folder = self.out_dir / "sweeps" / spec.sweep_name
        res = sweep(
            spec,
            out_dir=folder,
            executor=self.runner if self.runner is not None else self.executor,
            workers=self.workers,
            address=self.address,
            progress=self.progress,
            group_brains=self.group_brains,
            **kwargs,
        )
        ids = frozenset(t.trial_id for t in expand(spec))
        cpu, measured = _trials_cpu_s(res.store_path, ids)
        self.sweeps.append(
            {
                "name": res.name,
                "folder": str(folder),
                "total": res.total,
                "run": res.done + res.failed,
                "failed": res.failed,
                "reused": res.skipped,
                "elapsed_s": round(res.elapsed_s, 3),
                "trials_cpu_s": round(cpu, 3),
                "trials_cpu_measured": measured,
            }
        )
        return ReportSweepResult(
            name=res.name,
            store_path=res.store_path,
            total=res.total,
            done=res.done,
            failed=res.failed,
            skipped=res.skipped,
            elapsed_s=res.elapsed_s,
            failures=res.failures,
            trial_ids=ids,
        )


def _trials_cpu_s(store_path, ids: frozenset) -> tuple[float, int]:
    """The summed CPU time of the trials ``ids`` as the store recorded them (run now or found
    there), and how many of them have one (a store written before trials kept their CPU time
    has none)."""
    import sqlite3

    try:
        con = sqlite3.connect(f"file:{store_path}?mode=ro", uri=True)
        try:
            rows = con.execute("SELECT trial_id, cpu_time_s FROM trials WHERE status = 'ok'").fetchall()
        finally:
            con.close()
    except sqlite3.Error:
        return 0.0, 0
    got = [float(c) for tid, c in rows if tid in ids and c is not None]
    return float(sum(got)), len(got)
