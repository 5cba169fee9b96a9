"""The result of a rack time history: :class:`RackResponse` (arrays, peaks, summary).

Built by :func:`seisrack.analysis.rack.run_rack`; never written back onto the model or spec.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from seisrack.dynamics import Event, TimeHistory

#: sliding below this [m] counts as "no sliding" (round-off of an exact zero)
SLIDING_TOL_M = 1e-6
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
    hinges: Any = None  # HingeResponse (analysis.hinges) with nonlinear connections

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
        from seisrack.analysis.hinges import nonlinear_connector_design
        from seisrack.analysis.peaks import design_summary

        out = design_summary(self)
        if out is not None and self.hinges is not None:
            nonlinear_connector_design(out, self.hinges)
        return out

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
            "energy_J": {k: float(v[-1]) for k, v in self.energy.items()},
            **({} if self.hinges is None else {"hinges": self.hinge_summary()}),
        }

    def hinge_summary(self) -> dict[str, Any]:
        """Nonlinear connections: how many yielded, the largest ductility demand, the
        hysteretic energy and every hinge's peaks (see :class:`HingeResponse`)."""
        rows = self.hinges.peaks()
        duct = [(r["ductility"], r["hinge"]) for r in rows if r["ductility"] is not None]
        top = max(duct) if duct else (None, None)
        hyst = self.energy.get("hysteresis")
        return {
            "count": len(rows),
            "yielded": sum(r["yielded"] for r in rows),
            "peak_ductility": top[0],
            "peak_ductility_hinge": top[1],
            "hysteretic_energy_J": None if hyst is None else float(hyst[-1]),
            "hinges": rows,
        }


def _ratio(demand: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """demand / limit, with 0/0 = 0 and x/0 = inf (a pallet with no free distance)."""
    out = np.zeros_like(demand)
    ok = limit > 0
    out[ok] = demand[ok] / limit[ok]
    out[~ok & (demand > SLIDING_TOL_M)] = np.inf
    return out
