"""Plain progress lines for long work whose stderr is not a terminal (CI, nohup, a pipe).

On a terminal, runs and sweeps draw rich progress bars. Anywhere else a bar is either not
drawn at all or drawn only at the end, so a long run was silent for minutes. There, the same
work prints one plain line on stderr every :func:`period_s` seconds instead (10 s by default;
``TEAMNAV_PROGRESS_EVERY_S`` changes it)::

    teamnav run demo: 1200/6000 steps (20%), 35 s elapsed, ~2 min 20 s left
    teamnav sweep demo-robots: 3/12 trials (25%), 3 ok, 0 failed, 9 left, 41 s elapsed, ~2 min 3 s left

The lines come from a background thread, so they keep coming while one step, one trial or
the writing of a run folder takes long (a first run compiles the numba kernels), and cost
the work nothing but an attribute write per update. Nested reporters (a report's sections
around its sweeps) skip a line when another reporter printed one within the period.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time
from typing import Any, Callable

__all__ = ["DEFAULT_PERIOD_S", "PERIOD_ENV", "PlainProgress", "format_duration", "period_s", "stderr_is_terminal"]

#: seconds between two plain progress lines, unless :data:`PERIOD_ENV` says otherwise
DEFAULT_PERIOD_S = 10.0
#: environment variable holding the period in seconds (a number > 0)
PERIOD_ENV = "TEAMNAV_PROGRESS_EVERY_S"

_lock = threading.Lock()
_last_line_at = -math.inf  # time.monotonic() of the last line any reporter printed


def period_s() -> float:
    """Seconds between plain progress lines: ``$TEAMNAV_PROGRESS_EVERY_S`` if it is a number
    > 0 (at least 0.05), else :data:`DEFAULT_PERIOD_S`."""
    text = os.environ.get(PERIOD_ENV, "").strip()
    try:
        value = float(text)
    except ValueError:
        return DEFAULT_PERIOD_S
    return max(0.05, value) if math.isfinite(value) and value > 0 else DEFAULT_PERIOD_S


def stderr_is_terminal() -> bool:
    """Whether stderr is an interactive terminal (False when it is closed or replaced)."""
    try:
        return bool(sys.stderr.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def format_duration(seconds: float) -> str:
    """``"35 s"``, ``"2 min 5 s"``, ``"1 h 3 min"``."""
    if not math.isfinite(seconds):
        return "?"
    s = max(0, int(round(seconds)))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60} min"


def _emit(line: str, *, unless_within: float | None = None) -> bool:
    """Print ``line`` on stderr; with ``unless_within``, only when no line was printed in
    that many seconds. True when printed."""
    global _last_line_at
    with _lock:
        now = time.monotonic()
        if unless_within is not None and now - _last_line_at < unless_within:
            return False
        try:
            print(line, file=sys.stderr, flush=True)
        except (ValueError, OSError):  # stderr closed (a daemon) or a broken pipe: stay quiet
            return False
        _last_line_at = now
        return True


class PlainProgress:
    """Plain progress lines on stderr, one every ``period`` seconds, from a daemon thread.

    Parameters
    ----------
    label : str
        Start of each line (``"teamnav run demo"``).
    total : int, optional
        Units of work (steps, trials); None when unknown (then no fraction and no estimate).
    unit : str
        Name of a unit, plural (``"steps"``).
    details : callable, optional
        Returns extra text for the line (``"3 ok, 0 failed, 9 left"``); called in the thread.
    period : float, optional
        Seconds between lines; default :func:`period_s`.
    quiet_if_recent : bool
        Skip a line when another reporter printed one within the period (for an outer
        reporter whose inner work reports itself).
    waiting : callable, optional
        Returns what the work is stuck on now (``"waiting on controller X, robot Y, step 3
        for 12 s"``) or ""; called in the thread, and when it says something the line shows
        it instead of the phase (which may be stale: "compiling" while a brain hangs).

    Use :meth:`start`, then :meth:`update` (cheap: call it as often as you like) and
    :meth:`phase`, then :meth:`close`.
    """

    def __init__(self, label: str, total: int | None = None, unit: str = "steps", *,
                 details: Callable[[], str] | None = None, period: float | None = None,
                 quiet_if_recent: bool = False, waiting: Callable[[], str] | None = None) -> None:
        self.label, self.total, self.unit = label, total, unit
        self.details = details
        self.waiting = waiting
        self.period = period_s() if period is None else float(period)
        self.quiet_if_recent = quiet_if_recent
        self.done = 0
        self.lines = 0
        self._phase = ""
        self._t0 = time.monotonic()
        self._first: tuple[float, int] | None = None  # (time, done) of the first update: rate after warm-up
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    # ------------------------------------------------------------------ feeding it
    def start(self) -> "PlainProgress":
        self._t0 = time.monotonic()
        self._thread = threading.Thread(target=self._loop, name=f"progress {self.label}", daemon=True)
        self._thread.start()
        return self

    def update(self, done: int) -> None:
        """``done`` units finished so far."""
        if self._first is None:
            self._first = (time.monotonic(), int(done))
        self.done = int(done)

    __call__ = update  # usable as a ``progress(k)`` callback

    def phase(self, text: str) -> None:
        """What is going on besides the counted units (``"writing the run folder"``); "" for none."""
        self._phase = text

    def close(self, final: str | None = None) -> None:
        """Stop the lines; print ``final`` (``"{line}"`` inserts :meth:`line`) if given."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        self._thread = None
        if final is not None:
            _emit(final.replace("{line}", self.line()))
            self.lines += 1

    def __enter__(self) -> "PlainProgress":
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # ------------------------------------------------------------------ the line
    def elapsed_s(self) -> float:
        return time.monotonic() - self._t0

    def remaining_s(self) -> float:
        """Estimated seconds left, from the rate since the first update (so a first step that
        compiled the kernels does not inflate it); nan when unknown."""
        if not self.total or self._first is None:
            return math.nan
        t1, d1 = self._first
        done, now = self.done, time.monotonic()
        if done >= self.total:
            return 0.0
        if done <= d1 or now <= t1:
            return math.nan
        return (self.total - done) * (now - t1) / (done - d1)

    def line(self) -> str:
        done = self.done
        if self.total:
            head = f"{done}/{self.total} {self.unit} ({100.0 * done / self.total:.0f}%)"
        else:
            head = f"{done} {self.unit}"
        parts = [head]
        if self.details is not None:
            try:
                extra = self.details()
            except Exception:  # noqa: BLE001 - a progress line must never break the work
                extra = ""
            if extra:
                parts.append(extra)
        parts.append(f"{format_duration(self.elapsed_s())} elapsed")
        left = self.remaining_s()
        if math.isfinite(left) and done < (self.total or 0):
            parts.append(f"~{format_duration(left)} left")
        text = f"{self.label}: " + ", ".join(parts)
        phase = self._phase
        if self.waiting is not None:
            try:
                phase = self.waiting() or phase
            except Exception:  # noqa: BLE001 - a progress line must never break the work
                pass
        if phase:
            text += f" ({phase})"
        return text

    def _loop(self) -> None:
        while not self._stop.wait(self.period):
            if _emit(self.line(), unless_within=0.9 * self.period if self.quiet_if_recent else None):
                self.lines += 1
