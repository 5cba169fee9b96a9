"""Earthquake time history of a rack with sliding pallets (paper §IV).

Glue from a compiled :class:`~seisrack.model.frame_model.FrameModel` and a ground-motion
:class:`~seisrack.motion.records.Record` to the stick–slip engine, and from the engine's
:class:`~seisrack.dynamics.results.TimeHistory` to the quantities a rack engineer reads:
beam-level displacement and acceleration, total pallet–beam contact force, base shear, upright
moments, and each pallet's sliding against its fall limit.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from seisrack.analysis.peaks import PeakTracker, connection_moment, rack_operators
from seisrack.dynamics import Event, Sliders, TimeHistory, simulate
from seisrack.dynamics.basis import Basis
from seisrack.errors import InputError
from seisrack.model.frame_model import FrameModel
from seisrack.motion.records import Record

#: sliding below this [m] counts as "no sliding" (round-off of an exact zero)
SLIDING_TOL_M = 1e-6
#: default upper bound of the analysis time step [s]
DEFAULT_MAX_DT = 0.005
#: friction coefficient used for the companion run with rigidly held pallets
RIGID_MU = 1.0e6
#: [Hz] default cut-off of the low-pass filter of the reported floor (beam) accelerations
#: (docs/theory/floor_acceleration.md): above the sway modes that carry floor acceleration
#: (0.5-10 Hz), below the pallets' local axial beam modes (100-130 Hz) and below the Nyquist
#: frequency of records sampled at 50 Hz
ACCEL_FILTER_HZ = 20.0
#: order of the Butterworth low-pass, applied forward and backward (zero phase)
ACCEL_FILTER_ORDER = 4


@dataclass(frozen=True)
class RackResponse:
    """Response of a rack to one ground motion. Motion is relative to the ground.

    t: (n_t,) [s]; ground_accel: (n_t,) [m/s²] (interpolated onto the analysis grid).
    beam_displacement: (n_t, n_level) [m] mean horizontal displacement of each beam level.
    beam_acceleration: (n_t, n_level) [m/s²] absolute horizontal acceleration of each level,
        reported as the central difference of the beam velocity (see
        :func:`smoothed_acceleration`); ``beam_acceleration_raw`` is the scheme's own value.
    contact_force: (n_t, n_level) [N] total horizontal force of the beams on the pallets.
    base_shear: (n_t,) [N] total horizontal support reaction (elastic + stiffness-proportional
        damping forces), positive opposing positive ground displacement.
    upright_moment_base: (n_t, n_upright) [N·m]; upright_moment_connection: (n_t, n_upright,
        n_level) [N·m] largest-magnitude end moment of the upright segments at each connection.
    pallet_sliding: (n_t, m) [m] each pallet relative to its beam; pallet_friction: (n_t, m) [N].

    beam_acceleration_filtered: (n_t, n_level) [m/s²] the same, low-pass filtered at
        ``acceleration_filter_hz`` (zero-phase Butterworth of the full-rate history; see
        docs/theory/floor_acceleration.md), or None.
    pallet_bay: (m,) 0-based bay of each pallet; pallets are identified by 1-based ids in
        input order and labels ``L{level}-B{bay}-S{slot}`` (:meth:`pallet_labels`).
    operators: the projected recovery and design operators of the run
        (:class:`~seisrack.analysis.peaks.RackOperators`), for :meth:`design_peaks` and
        :func:`~seisrack.analysis.peaks.design_history`.

    The histories hold the samples the run kept (``run_rack(save_every=...)``; ``t`` gives
    their times). ``full_peaks`` holds the peaks over every analysis step (always computed);
    the peak methods below read it, so decimating the histories never changes a peak.
    """

    t: np.ndarray
    ground_accel: np.ndarray
    beam_displacement: np.ndarray
    beam_acceleration: np.ndarray
    contact_force: np.ndarray
    base_shear: np.ndarray
    upright_moment_base: np.ndarray
    upright_moment_connection: np.ndarray
    pallet_sliding: np.ndarray
    pallet_friction: np.ndarray
    pallet_level: np.ndarray
    pallet_x: np.ndarray
    pallet_mass: np.ndarray
    pallet_mu_static: np.ndarray
    pallet_mu_dynamic: np.ndarray
    pallet_limit_neg: np.ndarray
    pallet_limit_pos: np.ndarray
    events: list[Event]
    energy: dict[str, np.ndarray]
    g: float
    dt: float
    record_name: str
    status: str
    history: TimeHistory = field(repr=False)
    rigid_beam_acceleration_peak: np.ndarray | None = None
    beam_acceleration_raw: np.ndarray | None = None
    full_peaks: dict[str, Any] | None = None
    pallet_bay: np.ndarray | None = None
    beam_acceleration_filtered: np.ndarray | None = None
    acceleration_filter_hz: float = ACCEL_FILTER_HZ
    operators: Any = field(default=None, repr=False)

    # ------------------------------------------------------------------ derived results
    @property
    def n_pallets(self) -> int:
        return int(self.pallet_mass.size)

    def pallet_ids(self) -> list[int]:
        """1-based pallet ids in input order (the order of the rack file / ``[loading]``)."""
        return list(range(1, self.n_pallets + 1))

    def pallet_slot(self) -> np.ndarray:
        """(m,) 0-based position of each pallet within its (level, bay), left to right."""
        bay = self._bay()
        slot = np.zeros(self.n_pallets, dtype=int)
        for j in range(self.n_pallets):
            same = (self.pallet_level == self.pallet_level[j]) & (bay == bay[j])
            slot[j] = int(np.sum(same & ((self.pallet_x < self.pallet_x[j]) | (
                (self.pallet_x == self.pallet_x[j]) & (np.arange(self.n_pallets) < j)))))
        return slot

    def _bay(self) -> np.ndarray:
        if self.pallet_bay is not None:
            return np.asarray(self.pallet_bay, dtype=int)
        return np.zeros(self.n_pallets, dtype=int)

    def pallet_labels(self) -> list[str]:
        """Readable label of each pallet, ``"L{level}-B{bay}-S{slot}"`` (all 1-based; slot =
        position within the bay and level, left to right)."""
        bay, slot = self._bay(), self.pallet_slot()
        return [f"L{int(self.pallet_level[j]) + 1}-B{int(bay[j]) + 1}-S{int(slot[j]) + 1}"
                for j in range(self.n_pallets)]

    def pallet_peak_sliding(self) -> np.ndarray:
        """(m,) [m] peak |sliding| of each pallet."""
        if self.n_pallets == 0:
            return np.zeros(0)
        hi, lo = self._sliding_extremes()
        return np.maximum(hi, -lo)

    def _sliding_extremes(self) -> tuple[np.ndarray, np.ndarray]:
        """(m,), (m,) [m] largest and smallest sliding over every analysis step."""
        if self.full_peaks is not None:
            return self.full_peaks["sliding_max"], self.full_peaks["sliding_min"]
        return np.max(self.pallet_sliding, axis=0), np.min(self.pallet_sliding, axis=0)

    def pallet_residual(self) -> np.ndarray:
        """(m,) [m] sliding at the end of the record."""
        if self.n_pallets == 0:
            return np.zeros(0)
        return self.pallet_sliding[-1].copy()

    def fall_utilisation(self) -> np.ndarray:
        """(m,) largest ratio of sliding to the free distance on the side it slid towards."""
        if self.n_pallets == 0:
            return np.zeros(0)
        hi, lo = self._sliding_extremes()
        pos = hi.clip(0.0)
        neg = (-lo).clip(0.0)
        return np.maximum(_ratio(pos, self.pallet_limit_pos), _ratio(neg, self.pallet_limit_neg))

    def pallets_at_risk(self) -> list[int]:
        """0-based indices of pallets whose sliding reached their free distance (may fall).

        The summary (``summary()["pallets_at_risk"]``) lists the 1-based pallet ids instead."""
        return [int(j) for j in np.flatnonzero(self.fall_utilisation() >= 1.0)]

    def sliding_occurred(self) -> bool:
        return bool(np.any(self.pallet_peak_sliding() > SLIDING_TOL_M))

    def simplified_check(self) -> dict[str, Any]:
        """The paper's §II/§IV rule "no sliding if mu >= alpha" checked against this run.

        alpha is the peak absolute beam acceleration over g of the level a pallet stands on,
        taken from the companion run with rigidly held pallets (what a designer computes without
        a sliding model), and also reported for this run.
        """
        alpha_run = self._level_peak("beam_acceleration") / self.g
        alpha_rigid = (
            self.rigid_beam_acceleration_peak / self.g
            if self.rigid_beam_acceleration_peak is not None
            else alpha_run
        )
        lv = self.pallet_level
        predicted = self.pallet_mu_static < alpha_rigid[lv]
        slid = self.pallet_peak_sliding() > SLIDING_TOL_M
        unsafe = slid & ~predicted
        return {
            "rule": "no sliding if mu_static >= alpha = peak beam acceleration / g",
            "alpha_source": "rigid companion run" if self.rigid_beam_acceleration_peak
            is not None else "this run (run_rack(rigid_companion=True) for rigid pallets)",
            "alpha_rigid": alpha_rigid.tolist(),
            "alpha_this_run": alpha_run.tolist(),
            "predicted_sliding": predicted.tolist(),
            "sliding": slid.tolist(),
            "rule_safe": bool(not np.any(unsafe)),
            "rule_conservative_by": (alpha_rigid[lv] - self.pallet_mu_static).tolist(),
        }

    def peaks(self) -> dict[str, Any]:
        """Peak values (JSON-ready), the issue #5 ``--json`` schema plus extra fields."""
        disp = self._level_peak("beam_displacement")
        acc = self._level_peak("beam_acceleration")
        force = self._level_peak("contact_force")
        fp = self.full_peaks
        if fp is not None:
            mb, mc = fp["upright_moment_base"], fp["upright_moment_connection"]
            total, shear = fp["total_friction_force"], fp["base_shear"]
        else:
            mb = np.max(np.abs(self.upright_moment_base))
            conn = self.upright_moment_connection
            mc = np.max(np.abs(conn)) if conn.size else 0.0
            total = np.max(np.abs(self.contact_force.sum(axis=1)))
            shear = np.max(np.abs(self.base_shear))
        acc_f = self.filtered_level_peak()
        out = {
            "beam_displacement_m": float(disp.max()),
            "beam_acceleration_m_s2": float(acc.max()),
            "beam_acceleration_filtered_m_s2": None if acc_f is None else float(acc_f.max()),
            "acceleration_filter_hz": self.acceleration_filter_hz,
            "total_friction_force_N": float(total),
            "base_shear_N": float(shear),
            "upright_moment_base_Nm": float(mb),
            "upright_moment_connection_Nm": float(mc),
            "pallet_sliding_m": self.pallet_peak_sliding().tolist(),
            "pallet_residual_m": self.pallet_residual().tolist(),
            "per_level": {
                "beam_displacement_m": disp.tolist(),
                "beam_acceleration_m_s2": acc.tolist(),
                "beam_acceleration_filtered_m_s2": None if acc_f is None else acc_f.tolist(),
                "contact_force_N": force.tolist(),
            },
        }
        design = self.design_peaks()
        if design is not None:
            out["interstorey_drift_ratio"] = design["interstorey_drift_ratio"]["max_abs"]
            for key in ("beam_end_moment_Nm", "beam_end_shear_N", "connector_moment_Nm",
                        "connector_rotation_rad", "upright_axial_force_N"):
                out[key] = design[key]["max_abs"]
        return out

    def filtered_level_peak(self) -> np.ndarray | None:
        """(n_level,) [m/s²] peak of the low-pass filtered absolute level accelerations over
        every analysis step (``acceleration_filter_hz``), or None when not available."""
        fp = self.full_peaks or {}
        val = fp.get("beam_acceleration_filtered")
        return None if val is None else np.asarray(val)

    def design_peaks(self) -> dict[str, Any] | None:
        """Design quantities per member and as peaks (see :func:`design_summary`)."""
        from seisrack.analysis.peaks import design_summary

        return design_summary(self)

    def _level_peak(self, name: str) -> np.ndarray:
        """(n_level,) peak |value| of a per-level history over every analysis step."""
        if self.full_peaks is not None:
            return np.asarray(self.full_peaks[name])
        return np.max(np.abs(getattr(self, name)), axis=0)

    def summary(self) -> dict[str, Any]:
        """Everything the CLI prints with ``--json``."""
        n_slip = sum(1 for e in self.events if e.kind == "slip")
        peak, residual, util = (
            self.pallet_peak_sliding(), self.pallet_residual(), self.fall_utilisation()
        )
        return {
            "record": self.record_name,
            "g_m_s2": self.g,
            "dt_s": self.dt,
            "duration_s": float(self.t[-1]),
            "status": self.status,
            "peaks": self.peaks(),
            "sliding_occurred": self.sliding_occurred(),
            "pallets_at_risk": [j + 1 for j in self.pallets_at_risk()],
            "pallets": [
                {
                    "id": j + 1,
                    "label": lab,
                    "level": int(self.pallet_level[j]) + 1,
                    "bay": int(self._bay()[j]) + 1,
                    "x_m": float(self.pallet_x[j]),
                    "mass_kg": float(self.pallet_mass[j]),
                    "mu_static": float(self.pallet_mu_static[j]),
                    "mu_dynamic": float(self.pallet_mu_dynamic[j]),
                    "peak_sliding_m": float(peak[j]),
                    "residual_m": float(residual[j]),
                    "limit_neg_m": float(self.pallet_limit_neg[j]),
                    "limit_pos_m": float(self.pallet_limit_pos[j]),
                    "fall_utilisation": float(util[j]),
                    "sliding_phases": self.history.sliding_phases(j),
                }
                for j, lab in enumerate(self.pallet_labels())
            ],
            "simplified_check": self.simplified_check(),
            "design": self.design_peaks(),
            "n_events": len(self.events),
            "n_slip_events": n_slip,
            "energy_balance_error": self.history.energy_error() if self.energy else None,
        }


def _ratio(demand: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """demand / limit, with 0/0 = 0 and x/0 = inf (a pallet with no free distance)."""
    out = np.zeros_like(demand)
    ok = limit > 0
    out[ok] = demand[ok] / limit[ok]
    out[~ok & (demand > SLIDING_TOL_M)] = np.inf
    return out


def analysis_grid(record: Record, dt: float | None, max_dt: float = DEFAULT_MAX_DT) -> int:
    """Number of analysis steps per record step (the analysis dt is ``record.dt / k``)."""
    if dt is None:
        return max(1, math.ceil(record.dt / max_dt - 1e-9))
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    ratio = record.dt / dt
    k = round(ratio)
    if k < 1 or abs(ratio - k) > 1e-6 * max(ratio, 1.0):
        raise InputError(
            "dt", dt,
            f"the record's time step {record.dt:g} s divided by a whole number "
            f"(e.g. {record.dt:g}, {record.dt / 2:g}, {record.dt / 4:g} s)",
        )
    return int(k)


def _resample(a: np.ndarray, k: int) -> np.ndarray:
    """Linear interpolation of a record onto ``k`` sub-steps per record step (exact for the
    piecewise-linear excitation the engine assumes)."""
    if k == 1:
        return np.asarray(a, dtype=float)
    n = a.size
    x = np.arange((n - 1) * k + 1) / k
    return np.interp(x, np.arange(n), a)


def run_rack(
    model: FrameModel,
    record: Record,
    *,
    dt: float | None = None,
    vertical: Record | None = None,
    free_vibration: float = 0.0,
    backend: str = "auto",
    rigid_companion: bool = False,
    progress: Callable[[int], None] | None = None,
    throw: bool = True,
    method: str = "auto",
    basis: str | Basis = "auto",
    save_every: int | None = 1,
    track_energy: bool = True,
    max_memory: float | None = None,
    accel_filter_hz: float = ACCEL_FILTER_HZ,
) -> RackResponse:
    """Time history of ``model`` under the horizontal ground acceleration ``record``.

    dt: analysis step [s], a whole divisor of ``record.dt`` (default: the largest such step
        ≤ 5 ms). vertical: optional vertical ground acceleration (same dt and length); the
        pallets' normal forces become m (g + a_v) and the structure is loaded vertically.
    free_vibration: seconds of zero ground motion appended after the record.
    rigid_companion: also run the rack with rigidly held pallets, so that the simplified
        check's alpha is the designer's (rigid) one; off by default (it costs a second run):
        the check then uses this run's beam accelerations.
    progress: called with the number of analysis steps just completed, an increment (as
        ``tqdm.update`` expects), after each chunk of steps of the main run.
    method: time integration of :func:`seisrack.dynamics.simulate` ("auto", "exact" or
        "newmark"); basis: its ``basis`` ("auto": every mode up to 50 DOFs, a reduced
        load-dependent Ritz basis above).
    save_every: keep every k-th sample of the histories (``None``: first and last only, for
        studies); peaks are always taken over every step. max_memory: bytes the histories may
        take (default half of the available memory, at most 4 GiB); a longer run is refused up front.
    accel_filter_hz: [Hz] cut-off of the zero-phase low-pass filter of the reported floor
        accelerations (``beam_acceleration_filtered``; the raw ``beam_acceleration`` is kept),
        applied to the full-rate level accelerations whatever ``save_every`` is.
    """
    if not (isinstance(accel_filter_hz, int | float) and math.isfinite(accel_filter_hz)
            and accel_filter_hz > 0):
        raise InputError("accel_filter_hz", accel_filter_hz, "a frequency > 0 Hz")
    if not isinstance(record, Record):
        raise InputError("record", type(record).__name__, "a seisrack.motion.Record")
    if record.accel.size < 3:
        raise InputError(
            "record", f"{record.accel.size} samples", "a record of at least 3 samples"
        )
    if not (math.isfinite(free_vibration) and free_vibration >= 0):
        raise InputError("free_vibration", free_vibration, "a duration >= 0 s")
    k = analysis_grid(record, dt)
    h = record.dt / k
    ag_rec = np.asarray(record.accel, dtype=float)
    av_rec = None
    if vertical is not None:
        if abs(vertical.dt - record.dt) > 1e-9 * record.dt:
            raise InputError(
                "vertical.dt", vertical.dt, f"the horizontal record's time step {record.dt:g} s"
            )
        if vertical.accel.size != record.accel.size:
            raise InputError(
                "vertical", f"{vertical.accel.size} samples",
                f"the horizontal record's length ({record.accel.size} samples)",
            )
        av_rec = np.asarray(vertical.accel, dtype=float)
    n_pad = int(round(free_vibration / record.dt))
    if n_pad:
        ag_rec = np.concatenate([ag_rec, np.zeros(n_pad)])
        if av_rec is not None:
            av_rec = np.concatenate([av_rec, np.zeros(n_pad)])
    ag = _resample(ag_rec, k)
    av = None if av_rec is None else _resample(av_rec, k)
    sliders = Sliders(
        model.pallet_dof, model.pallet_mass, model.pallet_mu_static, model.pallet_mu_dynamic
    )
    mats = (model.M_sparse, model.C_sparse, model.K_sparse)
    common = dict(dt=h, ground_accel=ag, influence=model.r_x, vertical_accel=av,
                  vertical_influence=None if av is None else model.r_y, g=model.g,
                  backend=backend, throw=throw, method=method)
    # the basis is built once and shared with the companion run
    bas = basis if isinstance(basis, Basis) else _basis_for(model, sliders, basis, av)
    level_of_dof = {int(d): lv for lv, dofs in enumerate(model.level_dofs) for d in dofs}
    pallet_level = np.array([level_of_dof[int(d)] for d in model.pallet_dof], dtype=int)
    P = bas.phi[model.pallet_dof, :]  # (m, r) support of each pallet
    ops = rack_operators(model, bas.phi)
    # the smoothing of Newmark's period-2h acceleration residue is decided after the run;
    # track both and keep the one that applies
    # the design quantities do not depend on the smoothing: the first tracker has them
    trackers = {s: PeakTracker(ops, P, pallet_level, ag, h, smooth=s, keep_accel=True,
                               design=not s) for s in (False, True)}

    def on_chunk(c) -> None:  # noqa: ANN001
        for t in trackers.values():
            t(c)

    hist = simulate(*mats, sliders, **common, progress=progress, basis=bas,
                    save_every=save_every, on_chunk=on_chunk, track_energy=track_energy,
                    max_memory=max_memory)
    tracker = trackers[hist.method == "newmark"]
    peaks = {**trackers[False].result(), **tracker.result()}
    acc_full = tracker.level_acceleration()
    acc_filt = None if acc_full is None else lowpass(acc_full, h, accel_filter_hz)
    peaks["beam_acceleration_filtered"] = (
        None if acc_filt is None else np.abs(acc_filt).max(axis=0))
    rigid_peak = None
    if rigid_companion and model.n_pallets:
        rig = PeakTracker(ops, P, pallet_level, ag, h, smooth=False, design=False)
        rigid_sl = Sliders(model.pallet_dof, model.pallet_mass, RIGID_MU, RIGID_MU)
        common["method"] = "exact" if hist.method == "exact" else method
        simulate(*mats, rigid_sl, **common, basis=bas, save_every=None, on_chunk=rig,
                 track_energy=False)
        rigid_peak = rig.result()["beam_acceleration"]
    resp = _response(model, hist, ag, h, record.name, rigid_peak, ops, pallet_level, peaks)
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    return replace(resp, acceleration_filter_hz=float(accel_filter_hz),
                   beam_acceleration_filtered=None if acc_filt is None else acc_filt[idx])


def lowpass(a: np.ndarray, h: float, fc: float, order: int = ACCEL_FILTER_ORDER) -> np.ndarray:
    """Zero-phase Butterworth low-pass of ``a: (n_t, k)`` sampled every ``h`` [s] at ``fc`` [Hz].

    ``scipy.signal.sosfiltfilt`` (forward and backward: no phase shift, so peaks stay at their
    time; the magnitude response is the square of the order-``order`` filter's, -6 dB at fc).
    A cut-off at or above the Nyquist frequency returns ``a`` unchanged.
    """
    from scipy.signal import butter, sosfiltfilt

    a = np.asarray(a, dtype=float)
    if fc >= 0.5 / h or a.shape[0] < 2:
        return a.copy()
    sos = butter(order, fc, btype="low", fs=1.0 / h, output="sos")
    pad = min(3 * (2 * sos.shape[0] + 1), a.shape[0] - 1)
    return sosfiltfilt(sos, a, axis=0, padlen=pad)


def pallet_bays(model: FrameModel) -> np.ndarray:
    """(m,) 0-based bay of each pallet, from its node's x between the uprights."""
    x = np.asarray(model.nodes[model.pallet_node, 0], dtype=float)
    ux = np.asarray(model.upright_x, dtype=float)
    return np.clip(np.searchsorted(ux, x, side="right") - 1, 0, max(ux.size - 2, 0))


def _basis_for(model: FrameModel, sliders: Sliders, basis: str, av) -> Basis:  # noqa: ANN001
    from seisrack.dynamics.basis import full_basis, reduced_basis
    from seisrack.dynamics.engine import AUTO_FULL_MAX_DOF

    if basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if basis == "full" or (basis == "auto" and model.n_dof <= AUTO_FULL_MAX_DOF):
        return full_basis(model.M_sparse, model.K_sparse)
    loads = [model.total_mass_sparse() @ model.r_x]
    if av is not None:
        loads.append(model.M_sparse @ model.r_y)
    return reduced_basis(model.M_sparse, model.K_sparse, sliders.dof, sliders.mass,
                         np.column_stack(loads))


def smoothed_acceleration(v: np.ndarray, a: np.ndarray, h: float) -> np.ndarray:
    """Acceleration reported at grid points: ``(v[n+1] - v[n-1]) / (2 h)`` (``a`` at the ends).

    Average-acceleration Newmark is not L-stable: after every stick/slip event (a jump of the
    friction forces) the very stiff, heavily over-damped modes of the frame (beam axial modes,
    excited by the pallets' horizontal forces) keep a non-decaying component of period 2h in the
    *accelerations*, while displacements and velocities stay accurate. Since
    ``(v[n+1] - v[n-1]) / (2h) = (a[n-1] + 2 a[n] + a[n+1]) / 4`` for this scheme, the central
    difference removes that period-2h component exactly and is second-order accurate elsewhere;
    a physical acceleration jump at an event is spread over one step on each side.
    v, a: (n_t, k) relative velocity and acceleration; returns (n_t, k).
    """
    out = np.array(a, dtype=float, copy=True)
    if v.shape[0] >= 3:
        out[1:-1] = (v[2:] - v[:-2]) / (2.0 * h)
    return out


def _response(
    model: FrameModel, hist: TimeHistory, ag: np.ndarray, h: float, name: str,
    rigid_peak: np.ndarray | None, ops, pallet_level: np.ndarray, peaks: dict,  # noqa: ANN001
) -> RackResponse:
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    agk = ag[idx]
    disp = hist.q @ ops.level
    vel = hist.qd @ ops.level
    acc_raw = hist.qdd @ ops.level + agk[:, None]
    contiguous = idx.shape[0] == ag.shape[0]
    if hist.method == "newmark" and contiguous:
        acc = smoothed_acceleration(vel, acc_raw - agk[:, None], h) + agk[:, None]
    else:  # exact propagators leave no period-2h residue; decimated samples are not smoothed
        acc = acc_raw
    n_level = len(model.level_dofs)
    force = np.zeros((idx.shape[0], n_level))
    np.add.at(force.T, pallet_level, hist.friction.T)
    # Support reactions include the stiffness-proportional damping forces (C = a0 M + a1 K):
    # the member forces are K (u + a1 v); the a0 M v part acts on the masses, not the supports.
    base_shear = hist.q @ ops.shear + ops.a1 * (hist.qd @ ops.shear)
    n_t = idx.shape[0]
    mom_base = hist.q @ ops.base_moment
    shape = (n_t, ops.n_upright, ops.n_level)
    conn = connection_moment((hist.q @ ops.below).reshape(shape),
                             (hist.q @ ops.above).reshape(shape))
    return RackResponse(
        t=hist.t,
        ground_accel=agk,
        beam_displacement=disp,
        beam_acceleration=acc,
        beam_acceleration_raw=acc_raw,
        contact_force=force,
        base_shear=base_shear,
        upright_moment_base=mom_base,
        upright_moment_connection=conn,
        pallet_sliding=hist.sliding,
        pallet_friction=hist.friction,
        pallet_level=pallet_level,
        pallet_x=np.asarray(model.nodes[model.pallet_node, 0], dtype=float),
        pallet_mass=np.asarray(model.pallet_mass, dtype=float),
        pallet_mu_static=np.asarray(model.pallet_mu_static, dtype=float),
        pallet_mu_dynamic=np.asarray(model.pallet_mu_dynamic, dtype=float),
        pallet_limit_neg=np.asarray(model.pallet_limit_neg, dtype=float),
        pallet_limit_pos=np.asarray(model.pallet_limit_pos, dtype=float),
        events=hist.events,
        energy=hist.energy,
        g=float(model.g),
        dt=h,
        record_name=name,
        status=hist.status,
        history=hist,
        rigid_beam_acceleration_peak=rigid_peak,
        full_peaks=peaks,
        pallet_bay=pallet_bays(model),
        operators=ops,
    )
