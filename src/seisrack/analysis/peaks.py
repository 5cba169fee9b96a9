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
    design: DesignOps | None = None


#: design quantities tracked per member (name -> attribute of :class:`DesignOps`)
DESIGN_QUANTITIES = ("drift", "beam_moment", "beam_shear", "connector_rotation",
                     "connector_moment", "axial", "section_moment")


@dataclass(frozen=True)
class DesignOps:
    """Design quantities in basis coordinates (``q @ op``, each ``(r, k)``), see
    :class:`seisrack.fe.recovery.DesignOperators` for the conventions.

    drift: (r, n_level) interstorey drift ratio of each storey [-] (mean level displacement
        minus that of the level below, or of the ground, over the storey height);
    beam_moment, beam_shear: (r, n_level·n_bay·2) [N·m], [N]; connector_rotation,
    connector_moment: (r, n_conn) [rad], [N·m]; axial, section_moment: (r, n_upright·
    (n_level + 1)) upright axial force (tension +) [N] and bending moment [N·m] at the same
    sections (base, top of the segment below each level). ``static`` holds each quantity
    under gravity alone (a static solve of the full model), ``labels`` the member labels and
    ``storey_height`` (n_level,) [m].
    """

    drift: np.ndarray
    beam_moment: np.ndarray
    beam_shear: np.ndarray
    connector_rotation: np.ndarray
    connector_moment: np.ndarray
    axial: np.ndarray
    section_moment: np.ndarray
    static: dict[str, np.ndarray]
    labels: dict[str, tuple[str, ...]]
    storey_height: np.ndarray


def rack_operators(model, phi: np.ndarray, design: bool = True) -> RackOperators:  # noqa: ANN001
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
        design=design_ops(model, phi, ops, level) if design else None,
    )


def _sections(base, below, n_up: int, n_lev: int):  # noqa: ANN001, ANN202
    """Stack base (·, n_up) and below (·, n_up·n_lev) moments into the section order
    ``u·(n_lev + 1) + s`` of the axial force."""
    lead = base.shape[:-1]
    out = np.concatenate([np.asarray(base).reshape(*lead, n_up, 1),
                          np.asarray(below).reshape(*lead, n_up, n_lev)], axis=-1)
    return out.reshape(*lead, n_up * (n_lev + 1))


def design_ops(model, phi: np.ndarray, rec, level: np.ndarray) -> DesignOps:  # noqa: ANN001
    """:class:`DesignOps` of ``model`` in the basis ``phi`` (and the gravity state)."""
    import scipy.sparse.linalg as sla

    from seisrack.fe.recovery import design_operators

    d = design_operators(model)
    n_up, n_lev = rec.n_upright, rec.n_level
    y0 = float(np.mean(model.nodes[np.asarray(model.base_nodes), 1]))
    height = np.diff(np.r_[y0, np.asarray(model.level_y, dtype=float)])
    diff = np.eye(n_lev) - np.eye(n_lev, k=1)  # level l minus level l - 1
    drift_map = diff / height[None, :]

    def proj(op) -> np.ndarray:  # noqa: ANN001
        return np.asarray((op.T @ phi).T)

    # gravity alone, K u = -g M r_y (M holds the members and the pallets' vertical masses);
    # a sparse solve of the full model, once per run
    u0 = sla.spsolve(model.K_sparse.tocsc(), -model.g * (model.M_sparse @ model.r_y))
    u0 = np.atleast_2d(u0)
    lvl0 = np.array([u0[0, np.asarray(dofs)].mean() for dofs in model.level_dofs])
    static = {
        "drift": lvl0 @ drift_map,
        "beam_moment": np.asarray(u0 @ d.beam_moment)[0],
        "beam_shear": np.asarray(u0 @ d.beam_shear)[0],
        "connector_rotation": np.asarray(u0 @ d.connector_rotation)[0],
        "connector_moment": np.asarray(u0 @ d.connector_moment)[0],
        "axial": np.asarray(u0 @ d.axial)[0],
        "section_moment": _sections(np.asarray(u0 @ rec.base_moment)[0],
                                    np.asarray(u0 @ rec.below)[0], n_up, n_lev),
    }
    storeys = tuple(f"S{s + 1}" for s in range(n_lev))
    return DesignOps(
        drift=level @ drift_map, beam_moment=proj(d.beam_moment), beam_shear=proj(d.beam_shear),
        connector_rotation=proj(d.connector_rotation),
        connector_moment=proj(d.connector_moment), axial=proj(d.axial),
        section_moment=_sections(proj(rec.base_moment), proj(rec.below), n_up, n_lev),
        static=static,
        labels={"drift": storeys, "beam_moment": d.beam_labels, "beam_shear": d.beam_labels,
                "connector_rotation": d.connector_labels,
                "connector_moment": d.connector_labels, "axial": d.axial_labels,
                "section_moment": d.axial_labels},
        storey_height=height,
    )


def level_sum(friction: np.ndarray, pallet_level: np.ndarray, n_level: int) -> np.ndarray:
    """(n_t, n_level) sum of the pallets' forces ``friction: (n_t, m)`` on each level, added
    in pallet order (as ``np.add.at``, which is far slower: one column per pallet here)."""
    force = np.zeros((friction.shape[0], n_level))
    for j, lv in enumerate(pallet_level.tolist()):
        force[:, lv] += friction[:, j]
    return force


def connection_moment(below: np.ndarray, above: np.ndarray) -> np.ndarray:
    """Largest-magnitude end moment of the upright segments meeting at each connection."""
    return np.where(np.abs(below) >= np.abs(above), below, above)


#: level accelerations kept at full rate for the filtered peak, at most this many values
#: (n_step · n_level); above it the filtered peak is not available (80 MB of float64)
FULL_RATE_ACCEL_MAX = 10_000_000


class PeakTracker:
    """Accumulates full-rate peaks over the chunks of one run (an ``on_chunk`` callback).

    Besides the peaks it keeps the full-rate absolute level accelerations (n_step, n_level)
    when they fit in :data:`FULL_RATE_ACCEL_MAX` values (``keep_accel``), so that a
    zero-phase low-pass filter can be applied afterwards whatever ``save_every`` is; and, when
    the operators carry :class:`DesignOps`, the largest and smallest seismic value of every
    design quantity and, per upright section, the (N, M) pairs at the largest |N| and |M| of
    gravity + seismic.
    """

    def __init__(self, ops: RackOperators, P: np.ndarray, pallet_level: np.ndarray,  # noqa: N803
                 ag: np.ndarray, h: float, smooth: bool, keep_accel: bool = False,
                 design: bool = True) -> None:
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
        self._acc: list[np.ndarray] | None = (
            [] if keep_accel and ag.size * nl <= FULL_RATE_ACCEL_MAX else None)
        self._last_acc: np.ndarray | None = None
        d = ops.design if design else None
        self.dmax: dict[str, np.ndarray] = {}
        self.dmin: dict[str, np.ndarray] = {}
        if d is not None:
            # one (r, Σk) product per chunk instead of one per quantity
            mats = [getattr(d, name) for name in DESIGN_QUANTITIES]
            self._dop = np.ascontiguousarray(np.concatenate(mats, axis=1))
            self._dsplit = np.cumsum([m_.shape[1] for m_ in mats])[:-1]
            self._dmax_all = np.full(self._dop.shape[1], -np.inf)
            self._dmin_all = np.full(self._dop.shape[1], np.inf)
            ns = d.axial.shape[1]
            self.n_at_max_n = np.zeros((2, ns))  # rows: N, M at the largest |N|
            self.nm_at_max_m = np.zeros((2, ns))  # rows: N, M at the largest |M|

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
        a_abs = a + ag[:, None]
        self.acc = np.maximum(self.acc, np.abs(a_abs).max(axis=0))
        if self._acc is not None:  # chunks share their boundary sample: keep it once
            self._acc.append(a_abs[:-1].copy())
            self._last_acc = a_abs[-1].copy()
        if hasattr(self, "_dop"):
            self._design(c.q)
        force = level_sum(c.friction, self.lv, o.n_level)
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

    def _design(self, q: np.ndarray) -> None:
        d = self.ops.design
        # (k, n_t): every reduction below runs along contiguous rows (several times faster
        # than along axis 0 of (n_t, k); the values and the first-maximum ties are the same)
        xt = np.ascontiguousarray((q @ self._dop).T)
        np.maximum(self._dmax_all, xt.max(axis=1, initial=-np.inf), out=self._dmax_all)
        np.minimum(self._dmin_all, xt.min(axis=1, initial=np.inf), out=self._dmin_all)
        vals = dict(zip(DESIGN_QUANTITIES, np.split(xt, self._dsplit, axis=0), strict=True))
        n = vals["axial"] + d.static["axial"][:, None]
        m = vals["section_moment"] + d.static["section_moment"][:, None]
        if n.shape[0] and n.shape[1]:
            rows = np.arange(n.shape[0])
            for rows_at, x in ((self.n_at_max_n, n), (self.nm_at_max_m, m)):
                k = np.argmax(np.abs(x), axis=1)
                better = np.abs(x[rows, k]) > np.abs(rows_at[0 if x is n else 1])
                rows_at[0, better] = n[rows, k][better]
                rows_at[1, better] = m[rows, k][better]

    def level_acceleration(self) -> np.ndarray | None:
        """(n_step + 1, n_level) [m/s²] full-rate absolute level accelerations, or None when
        they were not kept (``keep_accel=False`` or more than :data:`FULL_RATE_ACCEL_MAX`)."""
        if self._acc is None or self._last_acc is None:
            return None
        return np.concatenate([*self._acc, self._last_acc[None, :]], axis=0)

    def result(self) -> dict[str, np.ndarray | float]:
        out = self._result()
        if hasattr(self, "_dop"):
            for name, hi, lo in zip(DESIGN_QUANTITIES,
                                    np.split(self._dmax_all, self._dsplit),
                                    np.split(self._dmin_all, self._dsplit), strict=True):
                self.dmax[name], self.dmin[name] = hi, lo
            out["design_max"] = self.dmax
            out["design_min"] = self.dmin
            out["upright_nm_at_max_n"] = self.n_at_max_n
            out["upright_nm_at_max_m"] = self.nm_at_max_m
        return out

    def _result(self) -> dict[str, np.ndarray | float]:
        return {
            "beam_displacement": self.disp, "beam_acceleration": self.acc,
            "contact_force": self.force, "total_friction_force": self.total_force,
            "base_shear": self.shear, "upright_moment_base": self.m_base,
            "upright_moment_connection": self.m_conn,
            "sliding_max": self.slide_max, "sliding_min": self.slide_min,
        }


#: (summary key, DesignOps attribute, unit, what it is) of each design quantity
DESIGN_KEYS = (
    ("interstorey_drift_ratio", "drift", "1",
     "interstorey drift ratio: mean level displacement minus that of the level below (or of "
     "the ground), over the storey height"),
    ("beam_end_moment_Nm", "beam_moment", "N m",
     "bending moment at the beam ends (member convention)"),
    ("beam_end_shear_N", "beam_shear", "N", "shear force at the beam ends"),
    ("connector_moment_Nm", "connector_moment", "N m",
     "moment of the beam-to-upright connector spring"),
    ("connector_rotation_rad", "connector_rotation", "rad",
     "rotation of the beam-to-upright connector spring"),
    ("upright_axial_force_N", "axial", "N",
     "upright axial force, tension positive, at the base and below each level"),
    ("upright_moment_section_Nm", "section_moment", "N m",
     "upright bending moment at the same sections as the axial force"),
)


def design_history(resp, name: str, *, gravity: bool = True) -> np.ndarray:  # noqa: ANN001
    """(n_t, k) history of one design quantity (a :class:`DesignOps` attribute) at the kept
    samples of ``resp``: seismic part ``q @ op`` plus, with ``gravity``, the gravity state."""
    d = resp.operators.design
    out = resp.history.q @ getattr(d, name)
    return out + d.static[name] if gravity else out


def design_summary(resp) -> dict | None:  # noqa: ANN001
    """Design quantities of a rack run, per member and as peaks (JSON-ready), or None.

    For each quantity: ``labels`` (members), ``gravity`` (static state under gravity alone),
    ``seismic_max`` / ``seismic_min`` (extremes over every analysis step of the response to the
    record, relative to the gravity state), ``peak_abs`` = max |gravity + seismic| per member
    (exact: the gravity part is constant) and ``max_abs`` over the members, with ``max_label``.
    ``upright_n_m`` gives, per upright section, the (N, M) pairs of gravity + seismic at the
    step of the largest |N| and at the step of the largest |M| (an N + M interaction check
    needs the concomitant pair, not the two envelopes). Forces are elastic (K u), as the rest
    of the recovery.
    """
    fp = resp.full_peaks or {}
    ops = resp.operators
    if ops is None or ops.design is None or "design_max" not in fp:
        return None
    d = ops.design
    out: dict = {
        "note": "gravity: static state under gravity alone; seismic_max/min: response to the "
                "record relative to it, over every analysis step; peak_abs: max |gravity + "
                "seismic|; forces are elastic (K u)",
        "storey_height_m": d.storey_height.tolist(),
    }
    for key, name, unit, what in DESIGN_KEYS:
        hi, lo, g0 = fp["design_max"][name], fp["design_min"][name], d.static[name]
        if hi.size == 0:
            out[key] = {"unit": unit, "description": what, "labels": [], "max_abs": 0.0}
            continue
        peak = np.maximum(np.abs(g0 + hi), np.abs(g0 + lo))
        k = int(np.argmax(peak))
        out[key] = {
            "unit": unit, "description": what, "labels": list(d.labels[name]),
            "gravity": g0.tolist(), "seismic_max": hi.tolist(), "seismic_min": lo.tolist(),
            "peak_abs": peak.tolist(), "seismic_peak_abs": np.maximum(hi, -lo).tolist(),
            "max_abs": float(peak[k]), "max_label": d.labels[name][k],
        }
    at_n, at_m = fp["upright_nm_at_max_n"], fp["upright_nm_at_max_m"]
    out["upright_n_m"] = {
        "unit": ["N", "N m"],
        "description": "upright sections: axial force N (tension +) and bending moment M of "
                       "gravity + seismic at the step of the largest |N| and of the largest |M|",
        "labels": list(d.labels["axial"]),
        "at_max_abs_N": [[float(n), float(m)] for n, m in at_n.T],
        "at_max_abs_M": [[float(n), float(m)] for n, m in at_m.T],
    }
    return out
