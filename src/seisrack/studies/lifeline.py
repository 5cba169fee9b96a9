"""Worker processes that die with the process that started them (issue 23).

A study's driver may be killed outright (``kill -9``, the out-of-memory killer, a closed
terminal): it then cannot shut its process pool down, and the workers, orphaned, would go on
computing runs nobody stores, until killed by hand. :func:`die_with_parent` is called first in
every worker (the pool's ``initializer``) and makes sure they follow the driver:

- on Linux, ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` (through ``ctypes``): the kernel kills the
  worker as soon as its parent exits;
- everywhere, a daemon thread polls the parent pid every :data:`POLL_S` seconds and ends the
  worker with ``os._exit`` once the parent is gone (re-parented). This is the portable
  fallback, and it also covers the race where the parent died before ``prctl`` was called.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
import time

#: [s] how often a worker checks that its parent is alive (fallback to PR_SET_PDEATHSIG)
POLL_S = 1.0
#: from <linux/prctl.h>
_PR_SET_PDEATHSIG = 1

_started = False


def die_with_parent(parent_pid: int | None = None) -> None:
    """End this process when ``parent_pid`` (default: the current parent) exits."""
    global _started
    if _started:
        return
    parent = os.getppid() if parent_pid is None else int(parent_pid)
    # a direct child (fork, spawn) polls its parent pid; a grandchild (forkserver) probes it
    direct = os.getppid() == parent
    if direct and sys.platform.startswith("linux"):
        _pdeathsig()
    if not _alive(parent, direct):
        os._exit(1)
    t = threading.Thread(target=_watch, args=(parent, direct), name="seisrack-lifeline",
                         daemon=True)
    t.start()
    _started = True


def _pdeathsig() -> None:
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - no prctl: the thread covers it
        pass


def _alive(parent: int, direct: bool) -> bool:
    if direct:  # re-parented (to init or a subreaper) means the parent has exited
        return os.getppid() == parent
    try:
        os.kill(parent, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover - exists, owned by someone else
        return True
    return True


def _watch(parent: int, direct: bool) -> None:
    while True:
        time.sleep(POLL_S)
        if not _alive(parent, direct):
            os._exit(1)
