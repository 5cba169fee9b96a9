"""Progress of long steps on stderr, whether or not stderr is a terminal (issue 23).

- :func:`progress` (a known amount of work: analysis steps, study runs): a tqdm bar on a
  terminal; otherwise (a log file, a CI job, ``2> log``) a plain line at most every
  :data:`EVERY_S` seconds with the count, the rate and the time left, and one at the end if
  any was printed. Short tasks print nothing.
- :func:`busy` (one long call that cannot report: building a large rack, a modal analysis,
  expanding a study): a line every :data:`EVERY_S` seconds saying it is still working, from a
  daemon thread, starting after the first :data:`EVERY_S` seconds (so quick steps are silent).

This is for the command line and the study runner (STYLE: progress bars belong to them); the
library's numerics report progress through callbacks only.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any, TextIO

#: [s] interval of the plain progress lines (and the delay before the first one)
EVERY_S = 5.0

__all__ = ["EVERY_S", "PlainProgress", "busy", "progress"]


def _stream(stream: TextIO | None) -> TextIO:
    return sys.stderr if stream is None else stream


def _is_tty(stream: TextIO) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def progress(total: int, desc: str, unit: str, *, stream: TextIO | None = None,
             every: float | None = None) -> Any:
    """A tqdm bar on a terminal, else a :class:`PlainProgress` (``update``, ``set_postfix``,
    ``close``, as tqdm)."""
    out = _stream(stream)
    if _is_tty(out):
        try:
            from tqdm import tqdm
        except ImportError:  # tqdm is in the [io]/[all] extras
            pass
        else:
            return tqdm(total=total, unit=unit, desc=desc, file=out, leave=False,
                        dynamic_ncols=True, smoothing=0.1)
    return PlainProgress(total, desc, unit, stream=out, every=EVERY_S if every is None else every)


class PlainProgress:
    """Plain progress lines on a stream that is not a terminal."""

    def __init__(self, total: int, desc: str, unit: str, *, stream: TextIO | None = None,
                 every: float = EVERY_S) -> None:
        self.total, self.desc, self.unit = int(total), desc, unit
        self.stream = _stream(stream)
        self.every = every
        self.n = 0
        self.postfix: dict[str, Any] = {}
        self.t0 = self.last = time.monotonic()
        self.printed = False

    def update(self, n: int = 1) -> None:
        self.n += n
        now = time.monotonic()
        if now - self.last >= self.every:
            self.last = now
            self._line(now)

    def set_postfix(self, refresh: bool = True, **kw: Any) -> None:  # noqa: ARG002 - tqdm's
        self.postfix.update(kw)

    def close(self) -> None:
        if self.printed:
            self._line(time.monotonic(), done=True)

    def _line(self, now: float, done: bool = False) -> None:
        el = now - self.t0
        pct = 100.0 * self.n / self.total if self.total else 100.0
        rate = self.n / el if el > 0 else 0.0
        left = (self.total - self.n) / rate if rate > 0 else float("nan")
        tail = "done" if done else (f"about {_fmt_s(left)} left" if left == left else "")
        extra = "".join(f", {k} {v}" for k, v in self.postfix.items())
        try:
            print(f"seisrack: {self.desc}: {self.n:,}/{self.total:,} {self.unit}s "
                  f"({pct:.0f} %), {_fmt_s(el)} elapsed{extra}{', ' + tail if tail else ''}",
                  file=self.stream, flush=True)
        except (OSError, ValueError):  # a closed stderr: progress is not worth an error
            return
        self.printed = True


@contextmanager
def busy(desc: str, *, stream: TextIO | None = None, every: float | None = None
         ) -> Iterator[None]:
    """While the block runs, say every ``every`` seconds (after the first) that ``desc`` is
    still running."""
    out = _stream(stream)
    every = EVERY_S if every is None else every
    stop = threading.Event()
    t0 = time.monotonic()

    def beat() -> None:
        while not stop.wait(every):
            try:
                print(f"seisrack: {desc}: still working, {_fmt_s(time.monotonic() - t0)} "
                      "elapsed", file=out, flush=True)
            except (OSError, ValueError):
                return

    t = threading.Thread(target=beat, name="seisrack-busy", daemon=True)
    t.start()
    try:
        yield
    finally:
        stop.set()
        t.join(timeout=1.0)


def _fmt_s(s: float) -> str:
    if s >= 3600:
        return f"{s / 3600:.1f} h"
    if s >= 60:
        return f"{s / 60:.1f} min"
    return f"{s:.0f} s"
