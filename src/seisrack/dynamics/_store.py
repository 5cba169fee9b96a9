"""Buffers of the engine: one chunk at full rate, and the samples a run keeps."""

from __future__ import annotations

import numpy as np


class Buffers:
    """Kernel output buffers for one chunk (reused)."""

    def __init__(self, rows: int, nb: int, m: int, nh: int = 0) -> None:
        self.arrays = (
            np.empty((rows, nb)), np.empty((rows, nb)), np.empty((rows, nb)),
            np.empty((rows, m)), np.empty((rows, m)), np.empty((rows, m)),
            np.empty((rows, m), dtype=np.bool_), np.zeros((rows, 5)), np.zeros((rows, nh)),
        )

    def views(self, k: int) -> tuple[np.ndarray, ...]:
        return tuple(a[:k] for a in self.arrays)


class Kept:
    """The samples a run keeps: every ``save_every``-th step and the last one."""

    def __init__(self, n_keep: int, nb: int, m: int, energy: bool, nh: int = 0) -> None:
        self.q = np.empty((n_keep, nb))
        self.qd = np.empty((n_keep, nb))
        self.qdd = np.empty((n_keep, nb))
        self.w = np.empty((n_keep, m))
        self.wd = np.empty((n_keep, m))
        self.lam = np.empty((n_keep, m))
        self.stuck = np.empty((n_keep, m), dtype=np.bool_)
        self.energy = np.zeros((n_keep, 5))
        self.hm = np.zeros((n_keep, nh))
        self.N = np.empty((n_keep, m))
        self.idx = np.empty(n_keep, dtype=np.int64)
        self.count = 0

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
                return
            loc = slice(int(loc[0]), int(loc[-1]) + 1)
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
        c = self.count
        return (self.q[:c], self.qd[:c], self.qdd[:c], self.w[:c], self.wd[:c], self.lam[:c],
                self.stuck[:c], self.energy[:c], self.hm[:c], self.N[:c], self.idx[:c])
