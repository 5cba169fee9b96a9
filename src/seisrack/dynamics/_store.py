"""Buffers of the engine: one chunk at full rate, and the samples a run keeps
(:func:`keep_index`: every ``save_every``-th step and the last one), with the memory they take
checked before anything is allocated (:func:`check_kept_memory`)."""

from __future__ import annotations

import os

import numpy as np

from seisrack.errors import InputError

#: default cap on what one run's kept histories and buffers may take [bytes]
DEFAULT_MAX_MEMORY = 4 * 2**30


def kept_samples(n_steps: int, save_every: int | None) -> int:
    """How many samples a run of ``n_steps`` keeps (every ``save_every``-th and the last;
    ``None``: the first and the last)."""
    if save_every is None:
        return 2
    return n_steps // save_every + 1 + (1 if n_steps % save_every else 0)


def keep_index(n_steps: int, save_every: int | None) -> np.ndarray:
    """The steps a run keeps (:func:`kept_samples` of them)."""
    if save_every is None:
        return np.array([0, n_steps])
    idx = np.arange(0, n_steps + 1, save_every)
    if idx[-1] != n_steps:
        idx = np.append(idx, n_steps)
    return idx


def memory_budget(max_memory: float | None) -> float | None:
    """Bytes one run may take: ``max_memory`` if given, else half of the memory free now and
    at most :data:`DEFAULT_MAX_MEMORY` (studies run several at once; ask for more with
    ``max_memory=``); None where the free memory cannot be read."""
    if max_memory is not None:
        return max_memory
    try:
        avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return None
    return min(0.5 * avail, DEFAULT_MAX_MEMORY)


def check_memory(n_steps: int, save_every: int | None, chunk: int, nb: int, m: int,
                 max_memory: float | None) -> None:
    """Refuse a run of ``n_steps`` keeping every ``save_every``-th sample of ``nb``
    coordinates and ``m`` slider columns whose histories and buffers would not fit, before
    allocating them."""
    per_row = 8 * (3 * nb + 4 * m + 5) + m
    check_kept_memory(n_steps, save_every, per_row + 8 * m,
                      (chunk + 1) * (per_row + 8 * (nb + 2 * m)) + 8 * 4 * (n_steps + 1),
                      max_memory, f"{nb} coordinates and {m} sliders",
                      "Keep fewer samples (save_every=k, or None with on_chunk for peaks only)")


def check_kept_memory(n_steps: int, save_every: int | None, per_sample: float, fixed: float,
                      max_memory: float | None, what: str, hint: str) -> np.ndarray:
    """The steps a run of ``n_steps`` keeps (:func:`keep_index`), once a run keeping every
    ``save_every``-th sample at ``per_sample`` bytes each, with ``fixed`` bytes of buffers, is
    known to fit (:func:`refuse_over_budget`, before anything is allocated); ``what``: what a
    sample holds (for the message)."""
    n_keep = kept_samples(n_steps, save_every)
    refuse_over_budget(n_keep * per_sample + fixed, max_memory,
                       f"{n_steps} steps keeping {n_keep} samples of {what}", hint)
    return keep_index(n_steps, save_every)


def refuse_over_budget(need: float, max_memory: float | None, what: str, hint: str) -> None:
    """InputError (field ``n_steps``) when a run needing ``need`` bytes, described by
    ``what``, exceeds :func:`memory_budget`; nothing where the free memory is unknown."""
    budget = memory_budget(max_memory)
    if budget is None:  # pragma: no cover - non-POSIX: the free memory is unknown
        return
    if need > budget:
        raise InputError("n_steps", f"{what} ({need / 2**30:.2f} GiB)",
                         f"a run that fits in {budget / 2**30:.2f} GiB", hint=hint)


class Buffers:
    """Kernel output buffers for one chunk (reused)."""

    def __init__(self, rows: int, nb: int, m: int, nh: int = 0) -> None:
        self.arrays = (
            np.empty((rows, nb)), np.empty((rows, nb)), np.empty((rows, nb)),
            np.empty((rows, m)), np.empty((rows, m)), np.empty((rows, m)),
            np.empty((rows, m), dtype=np.bool_), np.zeros((rows, 6)), np.zeros((rows, nh)),
        )

    def views(self, k: int) -> tuple[np.ndarray, ...]:
        return tuple(a[:k] for a in self.arrays)


class Kept:
    """The samples a run keeps: every ``save_every``-th step and the last one."""

    def __init__(self, n_steps: int, save_every: int | None, nb: int, m: int, energy: bool,
                 nh: int = 0) -> None:
        self._sizes = (kept_samples(n_steps, save_every), nb, m, nh)
        self.count = 0
        self._made = False  # the arrays are made at the first copy: a run kept whole in one
        # chunk adopts the chunk's buffers and never needs them

    def _make(self) -> None:
        n_keep, nb, m, nh = self._sizes
        self.q = np.empty((n_keep, nb))
        self.qd = np.empty((n_keep, nb))
        self.qdd = np.empty((n_keep, nb))
        self.w = np.empty((n_keep, m))
        self.wd = np.empty((n_keep, m))
        self.lam = np.empty((n_keep, m))
        self.stuck = np.empty((n_keep, m), dtype=np.bool_)
        self.energy = np.zeros((n_keep, 6))
        self.hm = np.zeros((n_keep, nh))
        self.N = np.empty((n_keep, m))
        self.idx = np.empty(n_keep, dtype=np.int64)
        self._made = True

    def take(self, start: int, stop: int, n_steps: int, every: int | None,
             outs: tuple[np.ndarray, ...], N: np.ndarray) -> None:  # noqa: N803
        steps = np.arange(start if start == 0 else start + 1, stop + 1)
        if every is None:
            sel = steps[(steps == 0) | (steps == n_steps)]
        else:
            sel = steps[(steps % every == 0) | (steps == n_steps)]
        if sel.size == 0:
            return
        loc = sel - start
        if loc[-1] - loc[0] == loc.size - 1:  # every step (save_every=1): a slice, no gather
            if start == 0 and stop == n_steps and loc.size == outs[0].shape[0]:
                # the whole run in one chunk, every sample kept: adopt the chunk's buffers
                # (not reused: this is the last chunk) instead of copying them
                (self.q, self.qd, self.qdd, self.w, self.wd, self.lam, self.stuck,
                 self.energy, self.hm) = outs
                self.N, self.idx, self.count = N, sel, sel.size
                self._made = True
                return
            loc = slice(int(loc[0]), int(loc[-1]) + 1)
        if not self._made:
            self._make()
        a, b = self.count, self.count + sel.size
        for dst, src in zip(
            (self.q, self.qd, self.qdd, self.w, self.wd, self.lam, self.stuck, self.energy,
             self.hm),
            outs, strict=True,
        ):
            dst[a:b] = src[loc]
        self.N[a:b] = N[loc]
        self.idx[a:b] = sel
        self.count = b

    def result(self) -> tuple[np.ndarray, ...]:
        if not self._made:
            self._make()
        c = self.count
        return (self.q[:c], self.qd[:c], self.qdd[:c], self.w[:c], self.wd[:c], self.lam[:c],
                self.stuck[:c], self.energy[:c], self.hm[:c], self.N[:c], self.idx[:c])
