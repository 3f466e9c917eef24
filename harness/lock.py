"""One harness at a time per reports folder.

Two invocations on the same checkout would each empty the other's run folders, and one
could report ok for a folder that then holds the other's failed run.  So every command
that writes under the reports root holds an exclusive flock on <reports>/.harness.lock
while it works.  A second one waits up to WAIT seconds, then refuses with Busy (errors.py; exit
status 75, harness/__main__.py), naming the process that holds the lock.

The runs inherit the lock's descriptor (held_fds(), passed to every child): the lock is
released only when the harness *and every run it started* have ended.  So a `--resume`
right after the harness was killed cannot empty a folder that a dying run still writes
into; it waits the few milliseconds those runs take to die (harness/children.py), then
takes the lock.

The lock file holds 'PID COMMAND' of its holder, for the refusal's message only; the
flock alone decides.  Writing it is best effort (on a full disk the lock still works).
"""
import fcntl
import os
import time
from contextlib import contextmanager
from pathlib import Path

from .errors import Busy
from .files import failure, make_dirs

LOCK_NAME = ".harness.lock"
WAIT = 1.0      # seconds a second invocation waits for the lock before it refuses
POLL = 0.02     # seconds between its attempts

_held = []      # descriptors of the locks this process holds (given to its children)


def held_fds():
    """The lock descriptors a child process must keep open (Popen's pass_fds)."""
    return tuple(_held)


@contextmanager
def reports_lock(root, command):
    """Hold the lock of the reports folder root (created if missing) while within;
    Busy if another harness keeps it for WAIT seconds, WriteError if it cannot be created."""
    path = make_dirs(root) / LOCK_NAME
    try:
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        raise failure("write", path, exc) from exc
    try:
        _acquire(fd, path)
        _mark(fd, f"{os.getpid()} {command}\n")
        _held.append(fd)
        try:
            yield path
        finally:
            _held.remove(fd)
            _mark(fd, "")
    finally:
        os.close(fd)


def _acquire(fd, path):
    """flock fd, trying for WAIT seconds; Busy (with the holder) when it stays taken."""
    deadline = time.monotonic() + WAIT
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() >= deadline:
                raise Busy(path, _holder(fd)) from None
            time.sleep(POLL)


def _mark(fd, text):
    """The lock file's text becomes text (best effort: the flock is what counts)."""
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, text.encode(), 0)
    except OSError:
        pass


def _holder(fd):
    """(pid, command) written by the holder, or (None, '') when it wrote nothing readable."""
    try:
        words = os.pread(fd, 200, 0).decode(errors="replace").split()
        return int(words[0]), " ".join(words[1:])
    except (OSError, ValueError, IndexError):
        return None, ""

