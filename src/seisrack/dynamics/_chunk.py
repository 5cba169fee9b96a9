"""A chunk of full-rate results, handed to ``simulate(on_chunk=...)`` after each chunk of steps."""

from __future__ import annotations

from functools import cached_property

import numpy as np


class Chunk:
    """Full-rate results of one chunk of steps (views into the engine's buffers: copy to keep).

    t: (k,) [s]; q, qd, qdd: (k, r) basis coordinates; friction: (k, m[, 2]) [N] force of the
    structure on each slider; stuck: (k, m) bool; hinge_moment: (k, n_h) [N·m] (n_h = 0
    without nonlinear hinges); sliding, sliding_v: (k, m[, 2]) [m, m/s] each slider relative to
    its support (sliders on a line: computed on first access from their displacement and
    velocity relative to the ground, ``slider_u``, ``slider_v``, and the support map ``P``).
    Consecutive chunks share their boundary sample.
    """

    def __init__(self, t: np.ndarray, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray,
                 friction: np.ndarray, stuck: np.ndarray, *,
                 hinge_moment: np.ndarray | None = None, sliding: np.ndarray | None = None,
                 sliding_v: np.ndarray | None = None, slider_u: np.ndarray | None = None,
                 slider_v: np.ndarray | None = None, P: np.ndarray | None = None) -> None:  # noqa: N803
        self.t, self.q, self.qd, self.qdd = t, q, qd, qdd
        self.friction, self.stuck = friction, stuck
        self.hinge_moment = np.zeros((t.shape[0], 0)) if hinge_moment is None else hinge_moment
        self.slider_u, self.slider_v, self._P = slider_u, slider_v, P
        if sliding is not None:
            self.__dict__["sliding"] = sliding
        if sliding_v is not None:
            self.__dict__["sliding_v"] = sliding_v

    @cached_property
    def sliding(self) -> np.ndarray:
        return self.slider_u - self.q @ self._P.T

    @cached_property
    def sliding_v(self) -> np.ndarray:
        return self.slider_v - self.qd @ self._P.T
