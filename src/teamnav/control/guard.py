"""What happens when a brain misbehaves: errors that name it, and a time limit per call.

A brain is code the simulator does not own (often an outside ``--controller`` class). When its
constructor or its ``step`` raises, returns something that is not an action, or never
returns, the run stops with a :class:`BrainError` that names the controller (as the scenario
names it: ``module:Class`` or ``/path/file.py:Class``), the robot (``GROUP[K]``, its index in
its group, and its robot id), the step and what went wrong, in one line::

    controller my_brain:Bad on robot wanderer[3] (id 3) raised at step 17: ValueError: no scan

The brain's own exception is the error's ``__cause__``; :meth:`BrainError.brain_traceback`
formats it for ``teamnav run --debug``.

- :class:`BrainBuildError`: the brain cannot be built (its constructor raised). Like a bad
  scenario, it is refused before anything runs (``teamnav run`` exit status 2).
- :class:`BrainStepError`: a brain failed mid-run (``step``/``step_batch`` raised or returned
  something that is not an action; exit status 3).
  :class:`BrainReturnError` for the latter.
- :class:`BrainTimeoutError`: one call took longer than the run's limit
  (``teamnav run --brain-timeout SECONDS``; exit status 3).

All are :class:`ValueError` s, so callers that treat a bad scenario as a ``ValueError`` (sweeps
record a failed trial) keep working.

The time limit (:class:`BrainTimer`) uses ``SIGALRM`` (``signal.setitimer``) in the main thread
on POSIX: the timer is armed just before each brain call and disarmed right after it, so the
engine's own kernels never run under it, and a run without a limit arms nothing. The signal
handler raises inside the brain's Python code (a ``time.sleep`` or a Python loop is
interrupted; a single long C call, e.g. one huge numpy operation, is interrupted when it
returns). Where ``SIGALRM`` cannot be used (Windows, a thread other than the main one), a
call that returns late is still refused once it returns.
"""

from __future__ import annotations

import signal
import threading
import time
import traceback
from typing import Any, Callable

__all__ = [
    "BrainBuildError", "BrainError", "BrainReturnError", "BrainStepError", "BrainTimeoutError", "BrainTimer", "TimeUp",
    "describe", "robot_label",
]


def robot_label(group: str, index_in_group: int | None, robot_id: int | None) -> str:
    """``wanderer[3] (id 7)``; ``wanderer (all robots)`` for a batched group's call."""
    if index_in_group is None:
        return f"{group} (all robots)"
    return f"{group}[{index_in_group}] (id {robot_id})"


class BrainError(ValueError):
    """A brain (controller) failed; ``str()`` is the one line that says which, where and how.

    Attributes
    ----------
    controller : str
        The controller as the scenario names it.
    robot : str
        ``GROUP[K] (id I)`` (see :func:`robot_label`).
    step : int or None
        The step whose observation the brain was given (None: while being built).
    what : str
        What went wrong (``ValueError: ...``).
    """

    def __init__(self, controller: str, robot: str, step: int | None, what: str) -> None:
        self.controller, self.robot, self.step, self.what = controller, robot, step, what
        super().__init__(self._line())

    def _line(self) -> str:
        when = "while being built" if self.step is None else f"at step {self.step}"
        return f"controller {self.controller} on robot {self.robot} failed {when}: {self.what}"

    def __reduce__(self):  # picklable (sweeps send failures between processes)
        return (type(self), (self.controller, self.robot, self.step, self.what))

    def brain_traceback(self) -> str:
        """The traceback of the brain's own exception (``__cause__``), or "" when there is none."""
        cause = self.__cause__
        if cause is None:
            return ""
        return "".join(traceback.format_exception(type(cause), cause, cause.__traceback__))


class BrainBuildError(BrainError):
    """The brain's constructor raised: the run cannot start."""

    def _line(self) -> str:
        return f"controller {self.controller} on robot {self.robot} raised while being built: {self.what}"


class BrainStepError(BrainError):
    """The brain failed mid-run: its step raised or returned something that is not an action."""

    def _line(self) -> str:
        return f"controller {self.controller} on robot {self.robot} raised at step {self.step}: {self.what}"


class BrainReturnError(BrainStepError):
    """The brain's step returned something that is not an action (or not a finite one)."""

    def _line(self) -> str:
        return f"controller {self.controller} on robot {self.robot} returned a bad value at step {self.step}: {self.what}"


class BrainTimeoutError(BrainStepError):
    """One brain call took longer than the run's time limit."""

    def _line(self) -> str:
        return f"controller {self.controller} on robot {self.robot} timed out at step {self.step}: {self.what}"


def describe(exc: BaseException) -> str:
    """``ValueError: message`` (``SystemExit: sys.exit(1) called`` for an exit)."""
    if isinstance(exc, SystemExit):
        return f"SystemExit: sys.exit({exc.code!r}) called"
    text = str(exc)
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class TimeUp(TimeoutError):
    """A brain call ran past the limit of a :class:`BrainTimer`."""


class _Alarm(BaseException):
    """Raised by the SIGALRM handler inside a brain call that ran past its limit (a
    BaseException, so a brain's own ``except Exception`` does not swallow it)."""


class BrainTimer:
    """A limit of ``seconds`` per brain call (see the module docstring).

    Use it as a context manager around the stepping (it installs and then restores the
    ``SIGALRM`` handler) and call brains through :meth:`call`.
    """

    def __init__(self, seconds: float) -> None:
        if not (isinstance(seconds, (int, float)) and seconds > 0 and seconds < float("inf")):
            raise ValueError(f"a brain time limit must be a number of seconds > 0, got {seconds!r}")
        self.seconds = float(seconds)
        self._old: Any = None
        self.signals = False

    def __enter__(self) -> "BrainTimer":
        self.signals = hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
        if self.signals:
            self._old = signal.signal(signal.SIGALRM, self._on_alarm)
        return self

    def __exit__(self, *exc: Any) -> None:
        if self.signals:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, self._old if self._old is not None else signal.SIG_DFL)
            self.signals = False

    @staticmethod
    def _on_alarm(signum, frame) -> None:
        raise _Alarm()

    def call(self, fn: Callable[[Any], Any], arg: Any) -> Any:
        """``fn(arg)`` within the limit; :class:`TimeUp` when it ran past it."""
        if not self.signals:
            t0 = time.perf_counter()
            out = fn(arg)
            if time.perf_counter() - t0 > self.seconds:
                raise TimeUp(self.message())
            return out
        try:
            signal.setitimer(signal.ITIMER_REAL, self.seconds)
            try:
                return fn(arg)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
        except _Alarm as exc:  # chained: --debug shows where the brain was when the time ran out
            raise TimeUp(self.message()) from exc

    def message(self) -> str:
        return f"no answer within the limit of {self.seconds:g} s per call (--brain-timeout)"
