"""Full-rate peaks of a rack run, accumulated chunk by chunk from the engine's ``on_chunk``.

The histories a run keeps may be decimated (``save_every``) or dropped (peaks only, as a study
needs); the peaks are always taken from every analysis step. Everything is evaluated in the
basis coordinates of the engine through operators precomputed once (``(r, k)`` each), so the
cost is O(n_t · r · k) and no ``(n_t, n_dof)`` array is ever formed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.dynamics.engine import Chunk


@dataclass(frozen=True)
class RackOperators:
    """Maps from basis coordinates ``q: (·, r)`` to rack quantities (``q @ op``).

    level: (r, n_level) mean horizontal displacement of each beam level [m per unit q];
    shear: (r,) base shear [N]; base_moment: (r, n_upright); below, above: (r, n_upright ·
    n_level) upright end moments at each connection [N·m]; a1: stiffness-proportional damping
    coefficient (the support reactions include ``a1 K v``); n_upright, n_level: shapes.
    """

    level: np.ndarray
    shear: np.ndarray
    base_moment: np.ndarray
    below: np.ndarray
    above: np.ndarray
    a1: float
    n_upright: int
    n_level: int


def rack_operators(model, phi: np.ndarray) -> RackOperators:  # noqa: ANN001
    """Project the level-averaging and force-recovery operators of ``model`` onto ``phi``."""
    from seisrack.fe.recovery import recovery_operators

    ops = recovery_operators(model)
    level = np.column_stack([phi[np.asarray(d)].mean(axis=0) for d in model.level_dofs])

    def proj(op) -> np.ndarray:  # noqa: ANN001
        return np.asarray((op.T @ phi).T)  # (r, k), sparse op never densified

    return RackOperators(
        level=level, shear=proj(ops.base_shear)[:, 0], base_moment=proj(ops.base_moment),
        below=proj(ops.below), above=proj(ops.above),
        a1=float(model.damping_coefficients[1]), n_upright=ops.n_upright, n_level=ops.n_level,
    )


def connection_moment(below: np.ndarray, above: np.ndarray) -> np.ndarray:
    """Largest-magnitude end moment of the upright segments meeting at each connection."""
    return np.where(np.abs(below) >= np.abs(above), below, above)


class PeakTracker:
    """Accumulates full-rate peaks over the chunks of one run (an ``on_chunk`` callback)."""

    def __init__(self, ops: RackOperators, P: np.ndarray, pallet_level: np.ndarray,  # noqa: N803
                 ag: np.ndarray, h: float, smooth: bool) -> None:
        self.ops, self.P, self.lv = ops, P, pallet_level
        self.ag, self.h, self.smooth = ag, h, smooth
        nl, m = ops.n_level, P.shape[0]
        self.disp = np.zeros(nl)
        self.acc = np.zeros(nl)
        self.force = np.zeros(nl)
        self.total_force = 0.0
        self.shear = 0.0
        self.m_base = 0.0
        self.m_conn = 0.0
        self.slide_max = np.full(m, -np.inf)
        self.slide_min = np.full(m, np.inf)
        self._v_prev: np.ndarray | None = None

    def __call__(self, c: Chunk) -> None:
        o = self.ops
        k0 = int(round(c.t[0] / self.h))
        ag = self.ag[k0:k0 + c.t.shape[0]]
        self.disp = np.maximum(self.disp, np.abs(c.q @ o.level).max(axis=0))
        v = c.qd @ o.level
        a = c.qdd @ o.level
        if self.smooth and v.shape[0] >= 3:  # see analysis.rack.smoothed_acceleration
            a = a.copy()
            a[1:-1] = (v[2:] - v[:-2]) / (2.0 * self.h)
            if self._v_prev is not None:
                a[0] = (v[1] - self._v_prev) / (2.0 * self.h)
        self._v_prev = v[-2] if v.shape[0] >= 2 else None
        self.acc = np.maximum(self.acc, np.abs(a + ag[:, None]).max(axis=0))
        force = np.zeros((c.t.shape[0], o.n_level))
        np.add.at(force.T, self.lv, c.friction.T)
        self.force = np.maximum(self.force, np.abs(force).max(axis=0))
        self.total_force = max(self.total_force, float(np.abs(c.friction.sum(axis=1)).max()))
        self.shear = max(self.shear, float(np.abs(c.q @ o.shear + o.a1 * (c.qd @ o.shear)).max()))
        self.m_base = max(self.m_base, float(np.abs(c.q @ o.base_moment).max(initial=0.0)))
        conn = connection_moment(c.q @ o.below, c.q @ o.above)
        self.m_conn = max(self.m_conn, float(np.abs(conn).max(initial=0.0)))
        if self.P.shape[0]:
            s = c.slider_u - c.q @ self.P.T
            self.slide_max = np.maximum(self.slide_max, s.max(axis=0))
            self.slide_min = np.minimum(self.slide_min, s.min(axis=0))

    def result(self) -> dict[str, np.ndarray | float]:
        return {
            "beam_displacement": self.disp, "beam_acceleration": self.acc,
            "contact_force": self.force, "total_friction_force": self.total_force,
            "base_shear": self.shear, "upright_moment_base": self.m_base,
            "upright_moment_connection": self.m_conn,
            "sliding_max": self.slide_max, "sliding_min": self.slide_min,
        }
