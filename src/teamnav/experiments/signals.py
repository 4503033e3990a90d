"""SIGTERM handled like Ctrl-C, and processes that end with their parent.

``kill PID`` (SIGTERM: what ``timeout``, systemd, Slurm and CI runners send) used to end a run
or a sweep on the spot: a run left its ``.NAME.*.partial`` staging folder, a sweep left its
worker processes running, orphaned. Inside :func:`sigterm_raises`, SIGTERM instead raises
:class:`Terminated` (a :class:`KeyboardInterrupt`) in the main thread, so the same cleanup as
for Ctrl-C runs (``finally`` blocks, ``except BaseException``: the staging folder removed,
the worker pool stopped, the results store closed), and then the process still ends by
SIGTERM, so whoever sent it sees the exit status it expects (143 in a shell).

:func:`die_with_parent` is for worker processes: they end when their parent does, even when
the parent is killed with SIGKILL and could clean up nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import signal
import sys
import threading
import time
from pathlib import Path
from typing import Iterator

__all__ = ["Terminated", "die_with_parent", "pid_alive", "sigterm_deferred", "sigterm_raises"]

#: prctl option: signal this process gets when the thread that created it ends (linux/prctl.h)
_PR_SET_PDEATHSIG = 1


class Terminated(KeyboardInterrupt):
    """SIGTERM arrived (see :func:`sigterm_raises`)."""


@contextlib.contextmanager
def sigterm_raises() -> Iterator[None]:
    """While inside, SIGTERM raises :class:`Terminated` in the main thread; when it leaves
    the block, the process ends by SIGTERM.

    Does nothing outside the main thread (Python runs signal handlers only there) and when
    SIGTERM already has a handler (the program's own, or an outer :func:`sigterm_raises`:
    then the outer one ends the process). A second SIGTERM during the cleanup is ignored;
    SIGKILL remains for a cleanup that hangs.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        current = signal.getsignal(signal.SIGTERM)
    except (AttributeError, ValueError):  # pragma: no cover - no SIGTERM here
        current = None
    if current is not signal.SIG_DFL:
        yield
        return
    fired = False

    def handler(signum, frame) -> None:  # noqa: ARG001 - signal handler signature
        nonlocal fired
        if fired:
            return  # already cleaning up
        fired = True
        raise Terminated(f"terminated by signal {signum} (SIGTERM)")

    signal.signal(signal.SIGTERM, handler)
    try:
        yield
    except Terminated:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os.kill(os.getpid(), signal.SIGTERM)  # end as the sender meant; returns only if blocked
        time.sleep(0.5)
        raise
    finally:
        if signal.getsignal(signal.SIGTERM) is handler:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def sigterm_deferred() -> Iterator[None]:
    """Hold SIGTERM back while inside (it is delivered on the way out): for steps that must
    not be cut in two, such as creating a folder and recording its name. A no-op where
    ``signal.pthread_sigmask`` does not exist (Windows)."""
    block = getattr(signal, "pthread_sigmask", None)
    if block is None:
        yield
        return
    previous = block(signal.SIG_BLOCK, {signal.SIGTERM})
    try:
        yield
    finally:
        block(signal.SIG_SETMASK, previous)  # a held SIGTERM's handler runs here


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine and is not a zombie.

    Errs on the side of "alive" when it cannot tell (another user's process, Windows).
    """
    if pid <= 0:
        return False
    if os.name == "nt":  # os.kill would terminate it; never guess there
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # EPERM: exists, belongs to someone else
        return True
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return True
    state = stat.rpartition(")")[2].split()[:1]
    return state not in (["Z"], ["X"])  # a zombie is dead, only not yet reaped


def _watch_parent(parent_pid: int, poll_s: float) -> None:
    while True:
        time.sleep(poll_s)
        if os.getppid() != parent_pid:
            os.kill(os.getpid(), signal.SIGTERM)  # cleanup handlers run (a trial's staging folder)
            time.sleep(10.0)
            os._exit(1)  # noqa: SLF001 - the cleanup hung: go anyway


def die_with_parent(parent_pid: int | None = None, *, poll_s: float = 1.0) -> None:
    """Make this process end when its parent does (call it first thing in a worker).

    On Linux the kernel sends SIGTERM the moment the parent dies (``prctl(PR_SET_PDEATHSIG)``);
    elsewhere, and as a second line of defence, a daemon thread polls the parent id every
    ``poll_s`` seconds and sends SIGTERM itself (then ends the process 10 s later whatever
    happened). If the parent is already gone when this is called, the process ends at once.

    Parameters
    ----------
    parent_pid : int, optional
        The parent's pid as the parent saw it (``os.getpid()`` there); default: the parent
        now. Passing it closes the window where the parent dies before this call.
    """
    expected = os.getppid() if parent_pid is None else int(parent_pid)
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):  # no libc / no prctl: the watchdog still works
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)
    if os.getppid() != expected:  # the parent died before the kernel was told to watch it
        os._exit(1)  # noqa: SLF001 - nothing of ours to clean up yet
    threading.Thread(target=_watch_parent, args=(expected, poll_s), name="die-with-parent", daemon=True).start()
