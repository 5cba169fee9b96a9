"""One BLAS thread around the engine's small dense algebra (threadpoolctl)."""

from __future__ import annotations

import contextlib
import functools
import threading
from collections.abc import Callable, Iterator

from threadpoolctl import ThreadpoolController

_CONTROLLER: list[ThreadpoolController] = []
#: how deep this thread is inside one_blas_thread: only the outermost sets and restores
_DEPTH = threading.local()


def blas_controller() -> ThreadpoolController:
    """One inspection of the loaded BLAS libraries per process (it reads /proc/self/maps:
    about 1 ms, too much to repeat on every run of a study)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]


@contextlib.contextmanager
def one_blas_thread() -> Iterator[None]:
    """A context limiting BLAS to one thread: the kernels' algebra is small (r x r), and a
    threaded BLAS only adds spinning threads, which made runs 5-10x slower on a loaded 2-core
    machine (measured on the warehouse rack). Nested uses (``run_rack`` around the engine's
    chunk loop) set the limit once: each setting and restoring costs ~0.1 ms."""
    depth = getattr(_DEPTH, "n", 0)
    if depth:
        _DEPTH.n = depth + 1
        try:
            yield
        finally:
            _DEPTH.n = depth
        return
    with blas_controller().limit(limits=1, user_api="blas"):
        _DEPTH.n = 1
        try:
            yield
        finally:
            _DEPTH.n = 0


def single_blas_thread(func: Callable) -> Callable:
    """Decorator: run ``func`` with one BLAS thread. The rack's post-processing is small dense
    algebra too: with a second, spinning OpenBLAS thread the nonlinear paper rack's run took
    twice the CPU (56 ms against 28)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        with one_blas_thread():
            return func(*args, **kwargs)

    return wrapper
