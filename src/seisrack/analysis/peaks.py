"""Full-rate peaks of a rack run, accumulated chunk by chunk from the engine's ``on_chunk``.

The histories a run keeps may be decimated (``save_every``) or dropped (peaks only, as a study
needs); the peaks are always taken from every analysis step. Everything is evaluated in the
basis coordinates of the engine through operators precomputed once (``(r, k)`` each), so the
cost is O(n_t · r · k) and no ``(n_t, n_dof)`` array is ever formed. Per-direction quantities
carry a trailing axis of the rack's horizontal directions (one for a 2D rack, down-aisle and
cross-aisle for a 3D rack).
"""

from __future__ import annotations

import functools

import numpy as np

from seisrack.analysis import chunk_pass
from seisrack.analysis.design_pass import design_pass
from seisrack.analysis.operators import (  # noqa: F401  (re-exported)
    DIRECTION_SUFFIX,
    DesignOps,
    RackOperators,
    project,
    rack_operators,
)
from seisrack.dynamics.engine import Chunk
from seisrack.errors import InputError


def level_sum(friction: np.ndarray, pallet_level: np.ndarray, n_level: int) -> np.ndarray:
    """(n_t, n_level[, n_dir]) sum of the pallets' forces ``friction: (n_t, m[, n_dir])`` on
    each level, added in pallet order (as ``np.add.at``, which is far slower here)."""
    force = np.zeros((friction.shape[0], n_level) + friction.shape[2:])
    for j, lv in enumerate(pallet_level.tolist()):
        force[:, lv] += friction[:, j]
    return force


def connection_moment(below: np.ndarray, above: np.ndarray) -> np.ndarray:
    """Largest-magnitude end moment of the upright segments meeting at each connection."""
    return np.where(np.abs(below) >= np.abs(above), below, above)


#: level accelerations kept at full rate for the filtered peak, at most this many values
#: (n_step · n_level · n_dir); above it the filtered peak is not available (80 MB of float64)
FULL_RATE_ACCEL_MAX = 10_000_000


def with_direction(a: np.ndarray, planar: bool) -> np.ndarray:
    """``a`` with a trailing direction axis (added, of length 1, for sliders on a line)."""
    return a if planar else a[..., None]


class PeakTracker:
    """Accumulates full-rate peaks over the chunks of one run (an ``on_chunk`` callback).

    Besides the peaks it keeps the full-rate absolute level accelerations (n_step, n_level,
    n_dir) when they fit in :data:`FULL_RATE_ACCEL_MAX` values (``keep_accel``), so that a
    zero-phase low-pass filter can be applied afterwards whatever ``save_every`` is; and, when
    the operators carry :class:`DesignOps`, the largest and smallest seismic value of every
    design quantity and, per upright section, the (N, M) pairs at the largest |N| and |M| of
    gravity + seismic (M in the down-aisle plane).

    ag: (n_t, n_dir) [m/s²] the ground acceleration of each direction at every step.
    backend: "auto" (the compiled pass of :mod:`seisrack.analysis.chunk_pass` when numba is
    installed), "numba" or "numpy" (the array code below, its twin). keep_series (compiled
    pass only): also keep the full-rate histories the response reports (:meth:`series`), for
    a run that keeps every step.
    """

    def __init__(self, ops: RackOperators, pallet_level: np.ndarray, ag: np.ndarray,
                 h: float, smooth: bool, keep_accel: bool = False, design: bool = True,
                 keep_series: bool = False, backend: str = "auto") -> None:
        self.ops, self.lv = ops, pallet_level
        self.ag, self.h, self.smooth = ag, h, smooth
        nl, m, nd = ops.n_level, pallet_level.shape[0], ops.n_dir
        self.disp = np.zeros((nl, nd))
        self.acc = np.zeros((nl, nd))
        self.acc_mag = np.zeros(nl)
        self.force = np.zeros((nl, nd))
        self.total_force = np.zeros(nd)
        self.shear = np.zeros(nd)
        self.m_base = np.zeros(nd)
        self.m_conn = np.zeros(nd)
        self.slide_max = np.full((m, nd), -np.inf)
        self.slide_min = np.full((m, nd), np.inf)
        self.slide_mag = np.zeros(m)
        self._v_prev: np.ndarray | None = None
        self._acc: list[np.ndarray] | None = (
            [] if keep_accel and ag.size * nl <= FULL_RATE_ACCEL_MAX else None)
        self._last_acc: np.ndarray | None = None
        self._level = np.concatenate(ops.level, axis=1)  # (r, n_level · n_dir)
        d = ops.design if design else None
        self.dmax: dict[str, np.ndarray] = {}
        self.dmin: dict[str, np.ndarray] = {}
        if d is not None:
            # one (r, Σk) operator for every quantity, passed over once per chunk
            mats = [d.ops[name] for name in d.names]
            self._dop = np.ascontiguousarray(np.concatenate(mats, axis=1), dtype=float)
            self._dsplit = np.cumsum([m_.shape[1] for m_ in mats])[:-1]
            first = dict(zip(d.names, np.concatenate([[0], self._dsplit]).tolist(), strict=True))
            self._d_at = (first["axial"], first["section_moment"])
            # writable copies: numba compiles another specialisation for read-only arrays
            self._static = (np.array(d.static["axial"], dtype=float),
                            np.array(d.static["section_moment"], dtype=float))
            self._dmax_all = np.full(self._dop.shape[1], -np.inf)
            self._dmin_all = np.full(self._dop.shape[1], np.inf)
            ns = d.ops["axial"].shape[1]
            self.n_at_max_n = np.zeros((2, ns))  # rows: N, M at the largest |N|
            self.nm_at_max_m = np.zeros((2, ns))  # rows: N, M at the largest |M|
        if backend not in ("auto", "numba", "numpy") or (
                backend == "numba" and not chunk_pass.HAVE_NUMBA):
            raise InputError("backend", backend, '"auto", "numba" or "numpy"'
                             + ("" if chunk_pass.HAVE_NUMBA else " (numba is not installed)"))
        self._fused = backend == "numba" or (backend == "auto" and chunk_pass.HAVE_NUMBA)
        self._backend = "numba" if self._fused else "numpy"
        self._series: dict[str, np.ndarray] | None = None
        if self._fused:
            self._fused_setup(ag.shape[0], keep_series)

    def _fused_setup(self, n_t: int, keep_series: bool) -> None:
        """Operators side by side and the full-run arrays of the compiled pass
        (:mod:`seisrack.analysis.chunk_pass`)."""
        o = self.ops
        nl, nd, nu = o.n_level, o.n_dir, o.n_upright
        lev = self._level
        # transposed, (K, r): each quantity's operator is a contiguous row
        self._wq = np.ascontiguousarray(np.concatenate(
            [lev, o.shear, *o.base_moment, *o.below, *o.above], axis=1).T, dtype=float)
        self._wd = np.ascontiguousarray(np.concatenate([lev, o.shear], axis=1).T, dtype=float)
        self._wa = np.ascontiguousarray(lev.T, dtype=float)
        self._vp = np.zeros(nl * nd)  # level velocities of the step before the chunk
        self._filled = 0
        self._acc_full = None if self._acc is None else np.empty((n_t, nl, nd))
        self._lv64 = np.ascontiguousarray(self.lv, dtype=np.int64)
        self._fsum = np.zeros((nl, nd))
        if keep_series:
            self._series = {
                "disp": np.empty((n_t, nl, nd)), "acc_raw": np.empty((n_t, nl, nd)),
                "shear": np.empty((n_t, nd)), "base": np.empty((n_t, nu, nd)),
                "conn": np.empty((n_t, nu, nl, nd))}

    def _fused_call(self, c: Chunk) -> None:
        o = self.ops
        nl, nd = o.n_level, o.n_dir
        k = c.t.shape[0]
        k0 = int(round(c.t[0] / self.h))
        ag = np.ascontiguousarray(self.ag[k0:k0 + k], dtype=float)
        if self._acc_full is not None:
            a_out, row0 = self._acc_full, k0
        else:
            a_out, row0 = np.empty((k, nl, nd)), 0
        vbuf = np.empty((k, nl * nd) if self.smooth else (0, 0))
        sr = self._series
        series = sr is not None
        none3, none4 = np.empty((0, 0, 0)), np.empty((0, 0, 0, 0))
        kept = chunk_pass.level_pass(
            np.ascontiguousarray(c.q), np.ascontiguousarray(c.qd), np.ascontiguousarray(c.qdd),
            ag, self._wq, self._wd, self._wa, nl, o.n_upright, float(o.a1), bool(self.smooth),
            float(self.h), self._vp, self._v_prev is not None, self.disp, self.acc,
            self.acc_mag, self.shear, self.m_base, self.m_conn, a_out, row0, vbuf, series,
            sr["disp"] if series else none3, sr["acc_raw"] if series else none3,
            sr["shear"] if series else np.empty((0, 0)), sr["base"] if series else none3,
            sr["conn"] if series else none4)
        self._v_prev = self._vp if kept else None
        self._filled = k0 + k
        if hasattr(self, "_dop"):
            self._design(c.q)
        if self.lv.shape[0]:
            planar = c.friction.ndim == 3
            chunk_pass.pallet_pass(
                np.ascontiguousarray(with_direction(c.friction, planar), dtype=float),
                np.ascontiguousarray(with_direction(c.sliding, planar), dtype=float),
                self._lv64, self.force, self.total_force, self.slide_max, self.slide_min,
                self.slide_mag, self._fsum)

    def series(self) -> dict[str, np.ndarray] | None:
        """The full-rate histories the compiled pass kept (``keep_series``): level
        displacement ``disp`` and raw absolute acceleration ``acc_raw`` (n_t, n_level, n_dir),
        base shear ``shear`` (n_t, n_dir), upright base moments ``base`` (n_t, n_upright,
        n_dir), connection moments ``conn`` (n_t, n_upright, n_level, n_dir), and the
        reported absolute level acceleration ``acc`` (:meth:`level_acceleration`); None when
        not kept."""
        if self._series is None or self._acc_full is None:
            return None
        out = {name: a[:self._filled] for name, a in self._series.items()}
        out["acc"] = self._acc_full[:self._filled]
        return out

    def __call__(self, c: Chunk) -> None:
        if self._fused:
            self._fused_call(c)
            return
        o = self.ops
        nl, nd = o.n_level, o.n_dir
        k0 = int(round(c.t[0] / self.h))
        ag = self.ag[k0:k0 + c.t.shape[0]]
        shape = (c.t.shape[0], nd, nl)
        self.disp = np.maximum(self.disp, np.abs(c.q @ self._level).reshape(shape).max(axis=0).T)
        v = (c.qd @ self._level).reshape(shape).transpose(0, 2, 1)  # (k, n_level, n_dir)
        a = (c.qdd @ self._level).reshape(shape).transpose(0, 2, 1)
        if self.smooth and v.shape[0] >= 3:  # see analysis.rack.smoothed_acceleration
            a = a.copy()
            a[1:-1] = (v[2:] - v[:-2]) / (2.0 * self.h)
            if self._v_prev is not None:
                a[0] = (v[1] - self._v_prev) / (2.0 * self.h)
        self._v_prev = v[-2] if v.shape[0] >= 2 else None
        a_abs = a + ag[:, None, :]
        self.acc = np.maximum(self.acc, np.abs(a_abs).max(axis=0))
        mag = np.abs(a_abs[:, :, 0]) if nd == 1 else np.sqrt((a_abs * a_abs).sum(axis=2))
        np.maximum(self.acc_mag, mag.max(axis=0), out=self.acc_mag)
        if self._acc is not None:  # chunks share their boundary sample: keep it once
            self._acc.append(a_abs[:-1].copy())
            self._last_acc = a_abs[-1].copy()
        if hasattr(self, "_dop"):
            self._design(c.q)
        planar = c.friction.ndim == 3
        fr = with_direction(c.friction, planar)
        force = level_sum(fr, self.lv, nl)
        self.force = np.maximum(self.force, np.abs(force).max(axis=0))
        self.total_force = np.maximum(self.total_force, np.abs(fr.sum(axis=1)).max(axis=0))
        sh = c.q @ o.shear + o.a1 * (c.qd @ o.shear)
        self.shear = np.maximum(self.shear, np.abs(sh).max(axis=0))
        for d in range(nd):
            self.m_base[d] = max(self.m_base[d],
                                 float(np.abs(c.q @ o.base_moment[d]).max(initial=0.0)))
            conn = connection_moment(c.q @ o.below[d], c.q @ o.above[d])
            self.m_conn[d] = max(self.m_conn[d], float(np.abs(conn).max(initial=0.0)))
        if self.lv.shape[0]:
            s = with_direction(c.sliding, planar)
            self.slide_max = np.maximum(self.slide_max, s.max(axis=0))
            self.slide_min = np.minimum(self.slide_min, s.min(axis=0))
            mag = np.sqrt((s * s).sum(axis=2)).max(axis=0)
            np.maximum(self.slide_mag, mag, out=self.slide_mag)

    def _design(self, q: np.ndarray) -> None:
        design_pass(q, self._dop, self._dmax_all, self._dmin_all, *self._d_at, *self._static,
                    self.n_at_max_n, self.nm_at_max_m, backend=self._backend)

    def level_acceleration(self) -> np.ndarray | None:
        """(n_step + 1, n_level, n_dir) [m/s²] full-rate absolute level accelerations, or None
        when they were not kept (``keep_accel=False`` or more than :data:`FULL_RATE_ACCEL_MAX`)."""
        if self._fused:
            return None if self._acc_full is None or not self._filled else (
                self._acc_full[:self._filled])
        if self._acc is None or self._last_acc is None:
            return None
        return np.concatenate([*self._acc, self._last_acc[None]], axis=0)

    def result(self) -> dict[str, np.ndarray | float]:
        """The peaks, per direction where the quantity has one (a trailing axis)."""
        out: dict = {
            "beam_displacement": self.disp, "beam_acceleration": self.acc,
            "beam_acceleration_magnitude": self.acc_mag, "contact_force": self.force,
            "total_friction_force": self.total_force,
            "base_shear": self.shear, "upright_moment_base": self.m_base,
            "upright_moment_connection": self.m_conn,
            "sliding_max": self.slide_max, "sliding_min": self.slide_min,
            "sliding_magnitude": self.slide_mag,
        }
        if hasattr(self, "_dop"):
            names = self.ops.design.names
            for name, hi, lo in zip(names, np.split(self._dmax_all, self._dsplit),
                                    np.split(self._dmin_all, self._dsplit), strict=True):
                self.dmax[name], self.dmin[name] = hi, lo
            out["design_max"] = self.dmax
            out["design_min"] = self.dmin
            out["upright_nm_at_max_n"] = self.n_at_max_n
            out["upright_nm_at_max_m"] = self.nm_at_max_m
        return out


#: (summary key, DesignOps name, unit, what it is) of each design quantity (the cross-aisle
#: ones of a 3D rack follow with DIRECTION_SUFFIX in both names)
DESIGN_KEYS = (
    ("interstorey_drift_ratio", "drift", "1",
     "interstorey drift ratio: mean level displacement minus that of the level below (or of "
     "the ground), over the storey height"),
    ("beam_end_moment_Nm", "beam_moment", "N m",
     "bending moment at the beam ends in the vertical plane (member convention)"),
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
#: the cross-aisle twins of the directional quantities (3D racks): name -> (key, description)
_CROSS_AISLE = {
    "drift": ("interstorey_drift_ratio_cross_aisle",
              "interstorey drift ratio cross-aisle (as down-aisle, along z)"),
    "section_moment": ("upright_moment_section_cross_aisle_Nm",
                       "upright bending moment in the cross-aisle plane at the same sections"),
}


def design_keys(design: DesignOps) -> list[tuple[str, str, str, str]]:
    """:data:`DESIGN_KEYS` of the quantities ``design`` has (cross-aisle twins in 3D)."""
    out = []
    for key, name, unit, what in DESIGN_KEYS:
        out.append((key, name, unit, what))
        twin = name + DIRECTION_SUFFIX[1]
        if name in _CROSS_AISLE and twin in design.ops:
            out.append((_CROSS_AISLE[name][0], twin, unit, _CROSS_AISLE[name][1]))
    return out


def design_history(resp, name: str, *, gravity: bool = True) -> np.ndarray:  # noqa: ANN001
    """(n_t, k) history of one design quantity (a :class:`DesignOps` name) at the kept
    samples of ``resp``: seismic part ``q @ op`` plus, with ``gravity``, the gravity state."""
    d = resp.operators.design
    out = resp.history.q @ d.ops[name]
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
    for key, name, unit, what in design_keys(d):
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
        "description": "upright sections: axial force N (tension +) and bending moment M in the "
                       "down-aisle plane of gravity + seismic at the step of the largest |N| "
                       "and of the largest |M|",
        "labels": list(d.labels["axial"]),
        "at_max_abs_N": [[float(n), float(m)] for n, m in at_n.T],
        "at_max_abs_M": [[float(n), float(m)] for n, m in at_m.T],
    }
    return out


#: order of the Butterworth low-pass, applied forward and backward (zero phase)
ACCEL_FILTER_ORDER = 4


def lowpass(a: np.ndarray, h: float, fc: float, order: int = ACCEL_FILTER_ORDER) -> np.ndarray:
    """Zero-phase Butterworth low-pass of ``a: (n_t, ...)`` sampled every ``h`` [s] at ``fc``
    [Hz], along the first axis.

    What ``scipy.signal.sosfiltfilt`` computes (forward and backward: no phase shift, so peaks
    stay at their time; the magnitude response is the square of the order-``order`` filter's,
    -6 dB at fc), with its odd extension of ``3 (2 n_sections + 1)`` samples at each end and
    its initial states, written out here so that the states (``sosfilt_zi``, about 0.7 ms)
    are computed once per filter rather than on every call. A cut-off at or above the Nyquist
    frequency returns ``a`` unchanged.
    """
    from scipy.signal import sosfilt

    a = np.asarray(a, dtype=float)
    if fc >= 0.5 / h or a.shape[0] < 2:
        return a.copy()
    sos, zi = _butter_sos(int(order), float(fc), float(h))
    sos = sos.copy()  # scipy wants it writable
    n = min(3 * (2 * sos.shape[0] + 1), a.shape[0] - 1)
    # odd extension: a "180 degree rotation" of the signal about each end sample
    ext = np.concatenate((2 * a[:1] - a[n:0:-1], a, 2 * a[-1:] - a[-2:-(n + 2):-1]), axis=0)
    zi = zi.reshape(zi.shape + (1,) * (a.ndim - 1))  # (n_sections, 2, 1, ...)
    y, _ = sosfilt(sos, ext, axis=0, zi=zi * ext[:1])
    y, _ = sosfilt(sos, y[::-1], axis=0, zi=zi * y[-1:])
    return y[::-1][n:-n]


@functools.lru_cache(maxsize=32)
def _butter_sos(order: int, fc: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Butterworth second-order sections and their steady-state initial conditions for a unit
    step (``sosfilt_zi``), designed once per (order, fc, h): ~1 ms. Read-only (shared)."""
    from scipy.signal import butter, sosfilt_zi

    sos = butter(order, fc, btype="low", fs=1.0 / h, output="sos")
    zi = sosfilt_zi(sos)
    sos.flags.writeable = zi.flags.writeable = False
    return sos, zi
