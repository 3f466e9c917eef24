"""Writing files whole, and saying in one line when the harness cannot.

Every file the harness writes goes through write_bytes / write_text: the bytes go to
NAME.tmp beside NAME, which is then renamed over NAME.  A kill at any moment therefore
leaves the old NAME or the new one, never a part of it (at most a NAME.tmp, which every
reader of a run folder refuses and the next write replaces).  When a write fails -- a
full disk, a read-only folder, a path through a regular file -- the NAME.tmp is removed
and a WriteError names NAME and the OS's reason; the command line prints it as one line
and exits with status 3 (harness/__main__.py).
"""
import errno
import os
import shutil
from pathlib import Path

from .errors import WriteError


def failure(action, path, exc):
    """The WriteError for exc, raised by the OS while doing action ('write', ...) on path."""
    error = WriteError(exc.errno, exc.strerror or str(exc), str(path))
    error.action = action
    return error


def describe(exc):
    """One line for any OSError: what could not be done, to which path, and why."""
    if isinstance(exc, WriteError) or not exc.filename:
        return str(exc)
    other = f" -> {exc.filename2}" if exc.filename2 else ""
    return f"{exc.filename}{other}: {exc.strerror}"


def discard(path):
    """Remove path if it is there; a failure to do so is not worth a second error."""
    try:
        os.unlink(path)
    except OSError:
        pass


def write_bytes(path, data):
    """Write data to path whole (NAME.tmp, then rename); WriteError, and no NAME.tmp, on failure.
    An interrupt (KeyboardInterrupt) also removes the NAME.tmp before it goes on."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except OSError as exc:
        discard(tmp)
        raise failure("write", path, exc) from exc
    except BaseException:
        discard(tmp)
        raise


def write_text(path, text):
    """write_bytes of text in UTF-8 (newlines as given: no translation)."""
    write_bytes(path, text.encode("utf-8"))


def copy(source, path):
    """path gets source's bytes, written whole (a figure gnuplot drew in a scratch folder)."""
    try:
        data = Path(source).read_bytes()
    except OSError as exc:
        raise failure("read", source, exc) from exc
    write_bytes(path, data)


def make_dirs(path):
    """The folder path and its parents; a path that is a regular file is said to be one
    (mkdir itself would only say 'File exists')."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except FileExistsError as exc:
        raise failure("write", path, OSError(errno.ENOTDIR, os.strerror(errno.ENOTDIR))) from exc
    except OSError as exc:
        raise failure("write", exc.filename or path, exc) from exc
    return path


def remove(path):
    """Remove the file path if it is there (an old figure before its new rendering)."""
    try:
        Path(path).unlink(missing_ok=True)
    except OSError as exc:
        raise failure("remove", path, exc) from exc


def remove_tree(path):
    """Remove the folder path and everything in it (a run folder before its run)."""
    try:
        shutil.rmtree(path)
    except FileNotFoundError:
        pass
    except OSError as exc:
        raise failure("remove", exc.filename or path, exc) from exc
