"""Child processes that die with the harness.

A harness killed outright (SIGKILL, the OOM killer) runs no handler, so it cannot stop its
runs; they would go on writing into folders that a `--resume` empties and fills again.
Every child is therefore started with PR_SET_PDEATHSIG = SIGKILL (Linux prctl, through
ctypes in a preexec_fn): the kernel kills it when the thread that started it ends.  The
runner's threads wait for their child inside the work item (communicate), and a pool
thread only ends after its work item, so no thread ends while its child runs; the main
thread's children (gnuplot, git) die with the process.

The children also keep the lock of the reports folder (harness/lock.py): it is released
when the last of them has died, not before.

Off Linux (no prctl) children are started as before and may outlive a killed harness.
"""
import ctypes
import os
import signal

from .lock import held_fds

PR_SET_PDEATHSIG = 1


def _load_prctl():
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
    except (OSError, AttributeError):
        return None
    prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong]
    prctl.restype = ctypes.c_int
    return prctl


_PRCTL = _load_prctl()      # resolved here, once: the preexec_fn must not import or look up
_KILL = int(signal.SIGKILL)


def dies_with_parent():
    """A preexec_fn arming PDEATHSIG in the child (None without prctl).  It also checks that
    the parent is still the one that forked: if it died between the fork and the prctl, the
    signal would never come, so the child kills itself.  Kept to two system calls and no
    allocation worth the name: it runs between fork and exec in a threaded process."""
    if _PRCTL is None:
        return None
    parent = os.getpid()

    def arm():
        _PRCTL(PR_SET_PDEATHSIG, _KILL, 0, 0, 0)
        if os.getppid() != parent:
            os.kill(os.getpid(), _KILL)
    return arm


def options(keep_lock=True):
    """Popen keyword arguments for a child of the harness: dies with it and, with keep_lock,
    holds the reports lock until it ends (a run writing under reports/)."""
    return {"preexec_fn": dies_with_parent(), "pass_fds": held_fds() if keep_lock else ()}
