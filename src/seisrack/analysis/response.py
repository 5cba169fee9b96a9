"""The result of a rack time history: :class:`RackResponse` (arrays, peaks, summary), one type
for a 2D and a 3D rack.

Built by :func:`seisrack.analysis.rack.run_rack`; never written back onto the model or spec.
Per-direction quantities carry a trailing axis of the rack's horizontal directions where there
are two (a 3D rack: down-aisle, cross-aisle); :meth:`RackResponse.directional` gives any of them
with that axis whatever the dimension, which is what code meant for both dimensions reads.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from seisrack.analysis.pallet_contacts import Fall, Impact, describe_contact
from seisrack.dynamics import Event, TimeHistory

#: sliding below this [m] counts as "no sliding" (round-off of an exact zero)
SLIDING_TOL_M = 1e-6
#: [Hz] default cut-off of the low-pass filter of the reported floor (beam) accelerations
#: (docs/theory/floor_acceleration.md): above the sway modes that carry floor acceleration
#: (0.5-10 Hz), below the pallets' local axial beam modes (100-130 Hz) and below the Nyquist
#: frequency of records sampled at 50 Hz
ACCEL_FILTER_HZ = 20.0
#: [Hz] lowest cut-off accepted: below it the filter would take away the sway modes themselves
#: (the first periods of racks stay under 10 s), and far below (about 1e-7 Hz at dt 5 ms) the
#: Butterworth filter's initial state cannot be computed (a singular system)
ACCEL_FILTER_MIN_HZ = 0.1
#: the histories that have a direction (a trailing axis on a 3D rack)
DIRECTIONAL = ("ground_accel", "beam_displacement", "beam_acceleration", "beam_acceleration_raw",
               "beam_acceleration_filtered", "contact_force", "base_shear",
               "upright_moment_base", "upright_moment_connection", "pallet_sliding",
               "pallet_friction")
#: JSON names of the directions
_DIR_KEY = ("down_aisle", "cross_aisle")


@dataclass(frozen=True)
class RackResponse:
    """Response of a rack to one ground motion. Motion is relative to the ground. ``[, d]``
    marks the trailing direction axis of a 3D rack (d = 0 down-aisle, 1 cross-aisle).

    t: (n_t,) [s]; ground_accel: (n_t[, d]) [m/s²] (interpolated onto the analysis grid);
    vertical_accel: (n_t,) or None.
    beam_displacement: (n_t, n_level[, d]) [m] mean horizontal displacement of each beam level.
    beam_acceleration: (n_t, n_level[, d]) [m/s²] absolute horizontal acceleration of each
        level, reported as the central difference of the beam velocity (see
        :func:`~seisrack.analysis.rack.smoothed_acceleration`); ``beam_acceleration_raw`` is
        the scheme's own value; ``beam_acceleration_filtered`` the same low-pass filtered at
        ``acceleration_filter_hz`` (zero-phase Butterworth of the full-rate history), or None.
    contact_force: (n_t, n_level[, d]) [N] total horizontal force of the beams on the pallets.
    base_shear: (n_t[, d]) [N] total horizontal support reaction (elastic + stiffness-
        proportional damping forces), positive opposing positive ground displacement.
    upright_moment_base: (n_t, n_upright[, d]) [N·m]; upright_moment_connection: (n_t,
        n_upright, n_level[, d]) [N·m] largest-magnitude end moment of the upright segments at
        each connection, in the bending plane of each direction (n_upright: the upright
        columns, front and rear in 3D).
    pallet_sliding: (n_t, m[, d]) [m] each pallet relative to its beam(s); pallet_friction:
        (n_t, m[, d]) [N].
    pallet_level, pallet_bay, pallet_slot: (m,) 0-based; pallets are identified by 1-based ids
        in input order and labels ``L{level}-B{bay}-S{slot}`` (:meth:`pallet_labels`).
    falls: first falls into an aisle (3D racks); impacts: first down-aisle contacts between
        neighbouring pallets or with an upright (:mod:`seisrack.analysis.pallet_contacts`).
    operators: the projected recovery and design operators of the run
        (:class:`~seisrack.analysis.peaks.RackOperators`).

    The histories hold the samples the run kept (``run_rack(save_every=...)``; ``t`` gives
    their times). ``full_peaks`` holds the peaks over every analysis step (always computed,
    with the direction axis); the peak methods below read it, so decimating the histories never
    changes a peak.
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
    directions: tuple[str, ...] = ("down-aisle",)
    pallet_slot: np.ndarray | None = None
    vertical_accel: np.ndarray | None = None
    angle_deg: float = 0.0
    level_y: np.ndarray | None = None
    fall_front: np.ndarray | None = None
    fall_rear: np.ndarray | None = None
    falls: tuple[Fall, ...] = ()
    impacts: tuple[Impact, ...] = ()
    pallet_row: np.ndarray | None = None  # (m,) 0-based, back-to-back racks only

    # ------------------------------------------------------------------ shapes
    @property
    def n_dir(self) -> int:
        """Number of horizontal directions (1 for a 2D rack, 2 for a 3D rack)."""
        return len(self.directions)

    @property
    def n_pallets(self) -> int:
        return int(self.pallet_mass.size)

    def directional(self, name: str) -> np.ndarray | None:
        """A history of :data:`DIRECTIONAL` (or a per-direction peak of ``full_peaks``) with
        its trailing direction axis, whatever the rack's dimension."""
        value = getattr(self, name)
        if value is None or self.n_dir > 1:
            return value
        return np.asarray(value)[..., None]

    def _squeeze(self, a: np.ndarray) -> np.ndarray:
        """Drop the direction axis of a peak for a 2D rack (the shape its callers expect)."""
        return a[..., 0] if self.n_dir == 1 else a

    # ------------------------------------------------------------------ pallets
    def pallet_ids(self) -> list[int]:
        """1-based pallet ids in input order (the order of the rack file / ``[loading]``)."""
        return list(range(1, self.n_pallets + 1))

    def _bay(self) -> np.ndarray:
        if self.pallet_bay is not None:
            return np.asarray(self.pallet_bay, dtype=int)
        return np.zeros(self.n_pallets, dtype=int)

    def _slot(self) -> np.ndarray:
        if self.pallet_slot is not None:
            return np.asarray(self.pallet_slot, dtype=int)
        return np.zeros(self.n_pallets, dtype=int)

    def pallet_labels(self) -> list[str]:
        """Readable label of each pallet, ``"L{level}-B{bay}-S{slot}"`` (all 1-based; slot =
        position within the bay and level, left to right), ``"R{row}-L…"`` on a back-to-back
        rack (as :meth:`~seisrack.model.frame_model.FrameModel.pallet_labels`)."""
        bay, slot = self._bay(), self._slot()
        row = [""] * self.n_pallets if self.pallet_row is None else \
            [f"R{int(r) + 1}-" for r in self.pallet_row]
        return [f"{row[j]}L{int(self.pallet_level[j]) + 1}-B{int(bay[j]) + 1}-"
                f"S{int(slot[j]) + 1}" for j in range(self.n_pallets)]

    def _sliding_extremes(self) -> tuple[np.ndarray, np.ndarray]:
        """(m, n_dir), (m, n_dir) [m] largest and smallest sliding over every analysis step."""
        if self.full_peaks is not None:
            return self.full_peaks["sliding_max"], self.full_peaks["sliding_min"]
        s = self.directional("pallet_sliding")
        return np.max(s, axis=0), np.min(s, axis=0)

    def pallet_peak_sliding(self) -> np.ndarray:
        """(m,) [m] peak sliding of each pallet: its largest |sliding| on a 2D rack, the largest
        magnitude of its sliding vector on a 3D rack."""
        if self.n_pallets == 0:
            return np.zeros(0)
        if self.full_peaks is not None:
            return np.asarray(self.full_peaks["sliding_magnitude"])
        s = self.directional("pallet_sliding")
        return np.sqrt((s * s).sum(axis=2)).max(axis=0)

    def pallet_peak_sliding_by_direction(self) -> np.ndarray:
        """(m, n_dir) [m] peak |sliding| of each pallet along each direction."""
        hi, lo = self._sliding_extremes()
        return np.maximum(hi, -lo) if self.n_pallets else np.zeros((0, self.n_dir))

    def pallet_residual(self) -> np.ndarray:
        """(m[, d]) [m] sliding at the end of the record."""
        return self.pallet_sliding[-1].copy()

    def fall_utilisation(self) -> np.ndarray:
        """(m,) largest ratio of down-aisle sliding to the free distance on the side it slid
        towards (1 or more: the pallet reached its neighbour or the upright)."""
        if self.n_pallets == 0:
            return np.zeros(0)
        hi, lo = self._sliding_extremes()
        pos = hi[:, 0].clip(0.0)
        neg = (-lo[:, 0]).clip(0.0)
        return np.maximum(_ratio(pos, self.pallet_limit_pos), _ratio(neg, self.pallet_limit_neg))

    def pallets_at_risk(self) -> list[int]:
        """1-based ids of the pallets whose down-aisle sliding reached their free distance
        (they hit a neighbour or an upright, or may fall), as every output numbers pallets."""
        return [int(j) + 1 for j in np.flatnonzero(self.fall_utilisation() >= 1.0)]

    def sliding_occurred(self) -> bool:
        return bool(np.any(self.pallet_peak_sliding() > SLIDING_TOL_M))

    # ------------------------------------------------------------------ checks and peaks
    def _level_peak(self, name: str) -> np.ndarray:
        """(n_level, n_dir) peak |value| of a per-level history over every analysis step."""
        if self.full_peaks is not None:
            return np.asarray(self.full_peaks[name])
        return np.max(np.abs(self.directional(name)), axis=0)

    def level_acceleration_magnitude(self) -> np.ndarray:
        """(n_level,) [m/s²] peak magnitude of each level's absolute horizontal acceleration
        (its only component on a 2D rack), over every analysis step."""
        fp = self.full_peaks or {}
        if "beam_acceleration_magnitude" in fp:
            return np.asarray(fp["beam_acceleration_magnitude"])
        a = self.directional("beam_acceleration")
        return np.sqrt((a * a).sum(axis=2)).max(axis=0)

    def simplified_check(self) -> dict[str, Any]:
        """The paper's §II/§IV rule "no sliding if mu >= alpha" checked against this run.

        alpha is the peak absolute horizontal acceleration (magnitude) over g of the level a
        pallet stands on, from the companion run with rigidly held pallets: what a designer
        computes without a sliding model. Without that run (``run_rack(rigid_companion=True)``,
        ``seisrack run --rigid-check``) there is no verdict: this run's own accelerations, with
        sliding pallets and the spikes of their stick–slip events, are not the designer's alpha
        (the check would compare the rule against a different motion), so ``rule_safe`` is
        None and ``alpha`` is this run's, labelled as such.
        """
        rigid = self.rigid_beam_acceleration_peak is not None
        alpha_run = self.level_acceleration_magnitude() / self.g
        alpha = np.asarray(self.rigid_beam_acceleration_peak) / self.g if rigid else alpha_run
        lv = self.pallet_level
        predicted = self.pallet_mu_static < alpha[lv]
        slid = self.pallet_peak_sliding() > SLIDING_TOL_M
        unsafe = slid & ~predicted
        return {
            "rule": "no sliding if mu_static >= alpha = peak horizontal beam acceleration / g",
            "alpha_source": "rigid companion run (pallets held)" if rigid else
            "this run, with sliding pallets: not the designer's alpha; no verdict (run "
            "run_rack(rigid_companion=True) or seisrack run --rigid-check)",
            "assessed": rigid,
            "alpha": alpha.tolist(),
            "alpha_rigid": alpha.tolist() if rigid else None,
            "alpha_this_run": alpha_run.tolist(),
            "predicted_sliding": predicted.tolist() if rigid else None,
            "sliding": slid.tolist(),
            "rule_safe": bool(not np.any(unsafe)) if rigid else None,
            "rule_conservative_by": (alpha[lv] - self.pallet_mu_static).tolist()
            if rigid else None,
        }

    def peaks(self) -> dict[str, Any]:
        """Peak values (JSON-ready), the issue #5 ``--json`` schema plus extra fields. A scalar
        is the largest over the levels, members and directions; ``per_direction`` gives each
        direction's."""
        disp = self._level_peak("beam_displacement")
        acc = self._level_peak("beam_acceleration")
        force = self._level_peak("contact_force")
        fp = self.full_peaks
        if fp is not None:
            mb, mc = np.asarray(fp["upright_moment_base"]), np.asarray(
                fp["upright_moment_connection"])
            total, shear = np.asarray(fp["total_friction_force"]), np.asarray(fp["base_shear"])
        else:
            mb = np.abs(self.directional("upright_moment_base")).max(axis=(0, 1))
            conn = self.directional("upright_moment_connection")
            mc = np.abs(conn).max(axis=(0, 1, 2)) if conn.size else np.zeros(self.n_dir)
            total = np.abs(self.directional("contact_force").sum(axis=1)).max(axis=0)
            shear = np.abs(self.directional("base_shear")).max(axis=0)
        acc_f = self.filtered_level_peak()
        out = {
            "beam_displacement_m": float(disp.max()),
            "beam_acceleration_m_s2": float(acc.max()),
            "beam_acceleration_filtered_m_s2": None if acc_f is None else float(acc_f.max()),
            "acceleration_filter_hz": self.acceleration_filter_hz,
            "total_friction_force_N": float(total.max()),
            "base_shear_N": float(shear.max()),
            "upright_moment_base_Nm": float(mb.max()),
            "upright_moment_connection_Nm": float(mc.max()),
            "pallet_sliding_m": self.pallet_peak_sliding().tolist(),
            "pallet_residual_m": self.pallet_residual().tolist(),
            "per_level": {
                "beam_displacement_m": self._squeeze(disp).tolist(),
                "beam_acceleration_m_s2": self._squeeze(acc).tolist(),
                "beam_acceleration_filtered_m_s2": None if acc_f is None
                else self._squeeze(acc_f).tolist(),
                "contact_force_N": self._squeeze(force).tolist(),
            },
            "per_direction": {
                _DIR_KEY[d]: {
                    "beam_displacement_m": float(disp[:, d].max(initial=0.0)),
                    "beam_acceleration_m_s2": float(acc[:, d].max(initial=0.0)),
                    "base_shear_N": float(shear[d]),
                    "total_friction_force_N": float(total[d]),
                    "upright_moment_base_Nm": float(mb[d]),
                    "upright_moment_connection_Nm": float(mc[d]),
                    "pallet_sliding_max_m": float(self.pallet_peak_sliding_by_direction()[:, d]
                                                  .max(initial=0.0)),
                } for d in range(self.n_dir)},
        }
        design = self.design_peaks()
        if design is not None:
            out["interstorey_drift_ratio"] = design["interstorey_drift_ratio"]["max_abs"]
            for key in ("beam_end_moment_Nm", "beam_end_shear_N", "connector_moment_Nm",
                        "connector_rotation_rad", "upright_axial_force_N"):
                out[key] = design[key]["max_abs"]
            if "interstorey_drift_ratio_cross_aisle" in design:
                out["interstorey_drift_ratio_cross_aisle"] = design[
                    "interstorey_drift_ratio_cross_aisle"]["max_abs"]
        return out

    def filtered_level_peak(self) -> np.ndarray | None:
        """(n_level, n_dir) [m/s²] peak of the low-pass filtered absolute level accelerations
        over every analysis step (``acceleration_filter_hz``), or None when not available."""
        fp = self.full_peaks or {}
        val = fp.get("beam_acceleration_filtered")
        return None if val is None else np.asarray(val)

    def design_peaks(self) -> dict[str, Any] | None:
        """Design quantities per member and as peaks (see
        :func:`~seisrack.analysis.peaks.design_summary`)."""
        from seisrack.analysis.hinges import nonlinear_connector_design
        from seisrack.analysis.peaks import design_summary

        out = design_summary(self)
        if out is not None and self.hinges is not None:
            nonlinear_connector_design(out, self.hinges)
        return out

    # ------------------------------------------------------------------ summary
    def pallet_rows(self) -> list[dict[str, Any]]:
        """Per pallet (1-based id, label, level, bay, properties, peaks, limits, falls)."""
        peak, residual, util = (self.pallet_peak_sliding(), self.pallet_residual(),
                                self.fall_utilisation())
        by_dir = self.pallet_peak_sliding_by_direction()
        fall_at = {f.pallet: f for f in self.falls}
        rows = []
        for j, lab in enumerate(self.pallet_labels()):
            row = {
                "id": j + 1, "label": lab, "level": int(self.pallet_level[j]) + 1,
                "bay": int(self._bay()[j]) + 1,
                **({} if self.pallet_row is None else {"row": int(self.pallet_row[j]) + 1}),
                "x_m": float(self.pallet_x[j]),
                "mass_kg": float(self.pallet_mass[j]),
                "mu_static": float(self.pallet_mu_static[j]),
                "mu_dynamic": float(self.pallet_mu_dynamic[j]),
                "peak_sliding_m": float(peak[j]),
                "residual_m": np.asarray(residual[j]).tolist(),
                "limit_neg_m": float(self.pallet_limit_neg[j]),
                "limit_pos_m": float(self.pallet_limit_pos[j]),
                "fall_utilisation": float(util[j]),
                "sliding_phases": self.history.sliding_phases(j),
            }
            if self.n_dir > 1:
                f = fall_at.get(j)
                row.update({
                    "peak_sliding_down_aisle_m": float(by_dir[j, 0]),
                    "peak_sliding_cross_aisle_m": float(by_dir[j, 1]),
                    "fall_limit_front_m": _num(self.fall_front[j]),
                    "fall_limit_rear_m": _num(self.fall_rear[j]),
                    "falls": None if f is None else {"time_s": f.time_s, "side": f.side},
                })
            rows.append(row)
        return rows

    def summary(self) -> dict[str, Any]:
        """Everything the CLI prints with ``--json``."""
        n_slip = sum(1 for e in self.events if e.kind == "slip")
        out = {
            "dimension": "3D" if self.n_dir > 1 else "2D",
            "directions": list(self.directions),
            "record": self.record_name,
            "g_m_s2": self.g,
            "dt_s": self.dt,
            "duration_s": float(self.t[-1]),
            "status": self.status,
            "peaks": self.peaks(),
            "sliding_occurred": self.sliding_occurred(),
            "pallets_at_risk": self.pallets_at_risk(),
            "pallets": self.pallet_rows(),
            "simplified_check": self.simplified_check(),
            "design": self.design_peaks(),
            "n_events": len(self.events),
            "n_slip_events": n_slip,
            "energy_balance_error": self.history.energy_error() if self.energy else None,
            "stuck_friction_ratio_max": self.stuck_friction_ratio(),
            "energy_J": {k: float(v[-1]) for k, v in self.energy.items()},
            "impacts": [{"contact": describe_contact(i), "time_s": i.time_s,
                         "closing_speed_m_s": i.speed_m_s} for i in self.impacts],
            **({} if self.hinges is None else {"hinges": self.hinge_summary()}),
        }
        if self.n_dir > 1:
            out.update(self._falls_summary())
        return out

    def stuck_friction_ratio(self) -> float | None:
        """The largest friction force of a stuck pallet over its static capacity, |λ| /
        (mu_s N), over the kept samples at which the pallet is stuck and still stuck at the next
        sample (a sample at a slip onset holds the force just before the release). Coulomb's
        law bounds it by 1; None without pallets or kept samples."""
        h = self.history
        f = np.asarray(self.pallet_friction, dtype=float)
        st = np.asarray(h.stuck, dtype=bool)
        n = np.asarray(h.normal, dtype=float)
        if f.size == 0 or st.shape[0] == 0 or st.shape != n.shape or f.shape[:2] != st.shape:
            return None
        mag = np.abs(f) if f.ndim == 2 else np.linalg.norm(f, axis=-1)
        held = st.copy()
        held[:-1] &= st[1:]
        cap = self.pallet_mu_static * n
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(held & (cap > 0.0), mag / cap, 0.0)
        return float(np.max(ratio)) if ratio.size else None

    def _falls_summary(self) -> dict[str, Any]:
        levels = sorted({int(v) for v in self.pallet_level})
        by_level = {str(lv + 1): sum(1 for f in self.falls if self.pallet_level[f.pallet] == lv)
                    for lv in levels}
        notes = []
        if self.falls:
            notes.append("the model keeps a fallen pallet on its beams: its peaks and residual "
                         "after the fall time are not physical")
        if self.impacts:
            notes.append("impacts are first contacts; the pallets are not stopped by them in "
                          "the model")
        return {
            "angle_deg": self.angle_deg,
            "pallets_checked_for_falls": int(np.sum(np.isfinite(self.fall_front))),
            "pallets_falling": len(self.falls),
            "pallets_falling_into_aisle": sum(1 for f in self.falls if f.into_aisle),
            "falls_by_level": by_level,
            "falls": [{"pallet": f.pallet + 1, "label": self.pallet_labels()[f.pallet],
                       "level": int(self.pallet_level[f.pallet]) + 1,
                       "bay": int(self._bay()[f.pallet]) + 1, "time_s": f.time_s,
                       "side": f.side} for f in self.falls],
            "notes": notes,
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


def _num(x: float) -> float | None:
    return None if not np.isfinite(float(x)) else float(x)


def _ratio(demand: np.ndarray, limit: np.ndarray) -> np.ndarray:
    """demand / limit, with 0/0 = 0 and x/0 = inf (a pallet with no free distance)."""
    out = np.zeros_like(demand)
    ok = limit > 0
    out[ok] = demand[ok] / limit[ok]
    out[~ok & (demand > SLIDING_TOL_M)] = np.inf
    return out
