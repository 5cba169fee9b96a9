"""One BLAS thread around the engine's small dense algebra (threadpoolctl)."""

from __future__ import annotations

import functools
from collections.abc import Callable

from threadpoolctl import ThreadpoolController

_CONTROLLER: list[ThreadpoolController] = []


def blas_controller() -> ThreadpoolController:
    """One inspection of the loaded BLAS libraries per process (it reads /proc/self/maps:
    about 1 ms, too much to repeat on every run of a study)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]


def one_blas_thread():  # noqa: ANN201
    """A context limiting BLAS to one thread: the kernels' algebra is small (r x r), and a
    threaded BLAS only adds spinning threads, which made runs 5-10x slower on a loaded 2-core
    machine (measured on the warehouse rack)."""
    return blas_controller().limit(limits=1, user_api="blas")


def single_blas_thread(func: Callable) -> Callable:
    """Decorator: run ``func`` with one BLAS thread. The rack's post-processing is small dense
    algebra too: with a second, spinning OpenBLAS thread the nonlinear paper rack's run took
    twice the CPU (56 ms against 28)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        with one_blas_thread():
            return func(*args, **kwargs)

    return wrapper
