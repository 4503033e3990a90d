"""File modes teamnav gives what it writes, and one writer per destination.

Modes: the user's umask, as any other tool.

``tempfile.mkstemp`` and ``mkdtemp`` create 0600 files and 0700 folders whatever the umask;
teamnav writes through them (atomic writes, staging folders) and then gives each file
``0o666 & ~umask`` and each folder ``0o777 & ~umask``.

One writer per destination: :func:`claim` holds ``.NAME.lock`` (created with ``O_EXCL``, holding
the pid and host) beside a run folder, a report folder or an output file while teamnav writes
it, so a second ``teamnav run``/``export``/``replay``/``report`` into the same place refuses
(or waits) instead of silently replacing the first one's work. :func:`destination_problem`
says what is wrong with a destination (a symbolic link, a file where a folder must be, a
read-only folder) before any work starts.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import secrets
import shutil
import socket
import threading
import time
from pathlib import Path
from typing import Callable, Iterator

__all__ = ["HOST", "LOW_SPACE_BYTES", "ClaimError", "claim", "claim_path", "current_umask", "destination_problem", "dir_mode",
           "file_mode", "write_cause"]

_UMASK_LOCK = threading.Lock()


def current_umask() -> int:
    """This process's umask, read without changing it where the system allows
    (``/proc/self/status``); elsewhere set and restored at once, under a lock."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    with _UMASK_LOCK:
        mask = os.umask(0o077)
        os.umask(mask)
    return mask


def file_mode() -> int:
    """Mode of a new ordinary file under the current umask (``0o666 & ~umask``)."""
    return 0o666 & ~current_umask()


def dir_mode() -> int:
    """Mode of a new folder under the current umask (``0o777 & ~umask``)."""
    return 0o777 & ~current_umask()


# ---------------------------------------------------------------------------- claims
#: this host, as claims and staging names spell it (letters, digits and '-'; at most 32)
HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:32] or "host"
#: seconds between two looks at a claim held by another process (``wait=True``)
CLAIM_POLL_S = 0.2


class ClaimError(ValueError):
    """Another process is writing the same destination (its claim names it)."""

    def __init__(self, message: str, holder: dict | None = None) -> None:
        super().__init__(message)
        self.holder = holder or {}


def claim_path(dest: str | os.PathLike) -> Path:
    """The claim file of ``dest``: ``.NAME.lock`` beside it."""
    dest = Path(dest)
    return dest.parent / f".{dest.name}.lock"


def _read_claim(path: Path) -> dict | None:
    """The claim's fields, ``{}`` when unreadable or half-written, None when it is gone."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        return None
    except OSError:
        return {}
    try:
        text = os.read(fd, 4096).decode("utf-8", "replace")
    except OSError:
        return {}
    finally:
        os.close(fd)
    try:
        doc = json.loads(text)
    except ValueError:
        return {}
    return doc if isinstance(doc, dict) else {}


def _holder_words(holder: dict) -> str:
    pid, host = holder.get("pid"), holder.get("host")
    if pid is None:
        return "another process"
    return f"process {pid}" + (f" on {host}" if host and host != HOST else "") + (
        f" ({holder['command']})" if holder.get("command") else "")


def _stale(holder: dict | None) -> bool:
    """A claim left by a process of this host that is gone."""
    from teamnav.experiments.signals import pid_alive

    if not holder:
        return False
    pid = holder.get("pid")
    return holder.get("host") == HOST and isinstance(pid, int) and not pid_alive(pid)


def _take_over(path: Path, holder: dict) -> None:
    """Remove the stale claim ``holder`` read at ``path``; a claim that replaced it meanwhile
    (a process that took it over first) is put back."""
    aside = path.with_name(f"{path.name}.{HOST}-{os.getpid()}.{secrets.token_hex(4)}.stale")
    try:
        os.rename(path, aside)
    except OSError:
        return  # someone else removed it first
    if _read_claim(aside) == holder:
        with contextlib.suppress(OSError):
            os.unlink(aside)
        return
    try:  # not the stale one: give the live claim back
        os.link(aside, path)
    except OSError:
        pass
    with contextlib.suppress(OSError):
        os.unlink(aside)


@contextlib.contextmanager
def claim(dest: str | os.PathLike, what: str, *, command: str = "", wait: bool = False,
          say: Callable[[str], None] | None = None) -> Iterator[Path]:
    """Hold an exclusive claim on ``dest`` (a run folder, an output file) while inside.

    The claim is the file ``.NAME.lock`` beside ``dest``, created with ``O_EXCL`` and holding
    this process's pid and host; a second writer into the same ``dest`` finds it and raises
    :class:`ClaimError` naming the holder (or, with ``wait``, waits until it is released:
    ``say`` is told once). A claim left by a process of this host that is gone (SIGKILL) is
    taken over. The claim is removed on the way out, whatever the way (an exception, Ctrl-C,
    SIGTERM inside :func:`teamnav.experiments.signals.sigterm_raises`). ``dest``'s folder must
    exist.

    Raises
    ------
    ClaimError
        Another live process holds the claim (and ``wait`` is False).
    OSError
        The claim file cannot be created (a read-only folder): the caller names the path.
    """
    path = claim_path(dest)
    token = secrets.token_hex(8)
    body = json.dumps({"pid": os.getpid(), "host": HOST, "token": token, "command": command,
                       "started_at": time.strftime("%Y-%m-%dT%H:%M:%S%z")}).encode()
    told = False
    while True:
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), file_mode())
        except FileExistsError:
            holder = _read_claim(path)
            if holder is None:
                continue  # released between the two calls
            if _stale(holder):
                _take_over(path, holder)
                continue
            if not holder:  # being written this instant, or not ours to read: look again
                time.sleep(0.05)
                holder = _read_claim(path)
                if holder is None or _stale(holder):
                    continue
            if not wait:
                raise ClaimError(f"{what} {dest}: {_holder_words(holder)} is writing it (claim {path}); "
                                 "wait for it, pass --wait, or choose another destination", holder) from None
            if not told and say is not None:
                say(f"waiting: {_holder_words(holder)} is writing {dest}")
                told = True
            time.sleep(CLAIM_POLL_S)
            continue
        try:
            os.write(fd, body)
        finally:
            os.close(fd)
        break
    try:
        yield path
    finally:
        mine = _read_claim(path)
        if mine is not None and mine.get("token") == token:
            with contextlib.suppress(OSError):
                os.unlink(path)


# ---------------------------------------------------------------------------- destinations
def _link_words(path: Path) -> str:
    try:
        target = os.readlink(path)
    except OSError:
        target = "?"
    if path.exists():
        return f"is a symbolic link (to {target})"
    return f"is a dangling symbolic link (to {target}, which does not exist)"


def destination_problem(path: str | os.PathLike, *, folder: bool) -> str | None:
    """What stops teamnav from writing ``path`` (a folder when ``folder``, else a file), in a
    few words naming the path at fault, or None. Changes nothing.

    Refused: ``path`` itself a symbolic link (dangling or not: the result would replace the
    link, not write where it points), ``path`` a folder where a file is asked for (a file where a
    folder is asked for is the caller's to judge: ``--force`` replaces it), a file or a dangling
    link where a folder above ``path`` must be, and the nearest existing folder above ``path``
    read-only (or not searchable) for this user.
    """
    path = Path(path)
    if path.is_symlink():
        return f"{path} {_link_words(path)}"
    if not folder and path.is_dir():
        return f"{path} is a folder, not a file"
    parent = path.parent
    while True:
        if parent.is_symlink() and not parent.exists():
            return f"{parent} {_link_words(parent)}"
        if parent.exists():
            break
        if parent == parent.parent:
            return f"{parent} does not exist"
        parent = parent.parent
    if not parent.is_dir():
        return f"{parent} is a file, not a folder"
    if not os.access(parent, os.W_OK | os.X_OK):
        return f"{parent} is read-only" + ("" if os.access(parent, os.X_OK) else " (and cannot be searched)")
    return None


#: below this much free space in a file's folder, a writer's vague error (SQLite's "disk I/O
#: error", the MCAP writer's "I/O error") is read as a full disk
LOW_SPACE_BYTES = 1 << 20


def write_cause(exc: BaseException, path: str | os.PathLike) -> str:
    """Why writing ``path`` failed, in words. SQLite says "disk I/O error" (or "database or disk
    is full") and the MCAP writer "I/O error" for a full disk, so the folder's free space is read
    to say "no space left on device"."""
    """Why writing ``path`` failed, in words: SQLite says "disk I/O error" (or "database or disk
    is full") for a full disk, so the folder's free space is read to say "no space left on device"."""
    text = getattr(exc, "strerror", None) or str(exc)
    try:
        free = shutil.disk_usage(Path(path).parent).free
    except OSError:
        return text
    return f"no space left on device: {free} bytes free in {Path(path).parent}" if free < LOW_SPACE_BYTES else text
