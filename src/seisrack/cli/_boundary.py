"""Where every command meets the operating system (issue 23): each exception that reaches the
command line becomes one paragraph (or the ``--json`` error object) naming what went wrong,
the path or option involved, and what to do. No command prints a traceback.

:func:`describe` maps an exception to the four fields of the error contract
(``message``, ``field``, ``value``, ``allowed``) and an exit code:

- :class:`~seisrack.errors.SeisrackError` (bad input, unreadable files): its own fields, 2;
- :class:`OSError` (disk full, read-only or missing folders, permissions, networks): by
  ``errno``, naming the path, 2;
- :class:`MemoryError`: what to make smaller, 2;
- ``KeyboardInterrupt``: "interrupted", 130 (the shell's convention for Ctrl-C, so that a
  script running seisrack stops too);
- anything else (an error inside a library: pyarrow, numba, dask, ...): an *internal error*
  paragraph asking for a report, 2. ``SEISRACK_TRACEBACK=1`` (or ``-v``) prints the traceback
  as well, for that report.

A closed output pipe (``seisrack ... | head``) is not an error: :func:`quiet_broken_pipe`
sends the rest of the output to ``os.devnull`` and the command exits 0 silently, as the Python
documentation recommends (``signal`` module, "Note on SIGPIPE").
"""

from __future__ import annotations

import errno
import os
import sys
from dataclasses import dataclass
from typing import Any

#: the text that marks a bug (the fuzz test asserts that no input produces it)
INTERNAL = "internal error"
#: environment variable that adds the traceback to an internal error
TRACEBACK_ENV = "SEISRACK_TRACEBACK"
#: exit code of an interrupted command (128 + SIGINT, as shells report it)
EXIT_INTERRUPTED = 130


@dataclass(frozen=True)
class Failure:
    """The error contract of one exception: one paragraph and the JSON fields."""

    message: str
    field: str | None = None
    value: Any = None
    allowed: str | None = None
    code: int = 2
    internal: bool = False


#: errno -> (what happened, what is allowed, what to do)
_OS_ERRORS: dict[int, tuple[str, str, str]] = {
    errno.ENOSPC: ("no space left on the device", "a folder on a disk with free space",
                   "Free some space or write somewhere else (--out); nothing half-written was "
                   "left behind"),
    errno.EROFS: ("read-only file system", "a writable folder",
                  "Choose a folder you can write to (--out)"),
    errno.EACCES: ("permission denied", "a path you may read (inputs) or write (outputs)",
                   "Check the permissions, or choose another folder (--out)"),
    errno.EPERM: ("operation not permitted", "a path you may read or write",
                  "Check the permissions, or choose another folder (--out)"),
    errno.ENOENT: ("file or folder not found", "an existing file, or a folder that exists",
                   "Check the path"),
    errno.EISDIR: ("this is a folder, a file was expected", "a file", "Give a file path"),
    errno.ENOTDIR: ("a part of the path is a file, not a folder", "a path through folders",
                    "Check the path"),
    errno.ENAMETOOLONG: ("file name too long", "a shorter path", "Use a shorter path"),
    errno.EMFILE: ("too many open files", "fewer open files",
                   "Raise the limit (ulimit -n) or use fewer workers"),
    errno.EIO: ("input/output error", "a working disk or network share",
                "Check the disk or the network share"),
    errno.EEXIST: ("the path exists already", "a path that does not exist yet",
                   "Remove it or choose another name"),
}
if hasattr(errno, "EDQUOT"):
    _OS_ERRORS[errno.EDQUOT] = ("disk quota exceeded", "a folder within your disk quota",
                                "Free some space or write somewhere else (--out)")


def describe(exc: BaseException) -> Failure:
    """The paragraph and fields the command line reports for ``exc``."""
    from seisrack.errors import SeisrackError

    if isinstance(exc, SeisrackError):
        return Failure(str(exc), getattr(exc, "field", None), getattr(exc, "value", None),
                       getattr(exc, "allowed", None) or None)
    if isinstance(exc, KeyboardInterrupt):
        return Failure("interrupted (Ctrl-C); what was already written is complete (study "
                       "runs already stored are kept: run the same command again to resume)",
                       code=EXIT_INTERRUPTED)
    if isinstance(exc, MemoryError):
        return Failure("out of memory: this analysis needs more memory than the machine has "
                       "free; make it smaller (fewer bays, levels or subdivisions, a shorter "
                       "--free-vibration, --save-every K) or run it on a larger machine",
                       "memory", None, "an analysis that fits in the free memory")
    if isinstance(exc, ConnectionError | TimeoutError) or _is_network(exc):
        return Failure(f"network error: {_first_line(exc)}; check the address (a Dask "
                       "scheduler is given as tcp://SCHEDULER-HOST:8786) and that it is "
                       "running and reachable", "network", None, "a reachable address")
    if isinstance(exc, OSError):
        return _os_failure(exc)
    return Failure(f"{INTERNAL} ({type(exc).__name__}: {_first_line(exc)}); this is a bug in "
                   "seisrack or in a library it uses, not a problem of your input: please "
                   "report it with the command line and the input files "
                   f"({TRACEBACK_ENV}=1 prints the traceback)", internal=True)


def _os_failure(exc: OSError) -> Failure:
    path = exc.filename if exc.filename is not None else None
    if exc.filename2 is not None:
        path = f"{exc.filename} -> {exc.filename2}"
    what, allowed, todo = _OS_ERRORS.get(
        exc.errno or -1, (exc.strerror or _first_line(exc) or type(exc).__name__,
                          "a path that can be read or written", "Check the path and the disk"))
    where = f": {path}" if path is not None else ""
    return Failure(f"{what}{where}. {todo}", "path" if path is not None else "file",
                   None if path is None else str(path), allowed)


def _is_network(exc: BaseException) -> bool:
    import socket

    return isinstance(exc, socket.gaierror | socket.herror)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    line = text.splitlines()[0] if text else ""
    return line if len(line) <= 300 else line[:297] + "..."


def quiet_broken_pipe() -> None:
    """After a ``BrokenPipeError`` on stdout: send what is still buffered to ``os.devnull``
    (so that Python's exit-time flush does not fail again) and say nothing."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout is not a real file (tests)
        pass


def want_traceback(verbose: bool) -> bool:
    return verbose or os.environ.get(TRACEBACK_ENV, "") not in ("", "0")
