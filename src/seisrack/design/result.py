"""The result of the design analysis: frozen dataclasses of arrays, JSON-ready by ``as_dict``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


def _list(a: Any) -> Any:
    if a is None:
        return None
    return np.asarray(a, dtype=float).tolist()


@dataclass(frozen=True)
class Quantity:
    """One response quantity of the design analysis.

    by_direction: {excitation direction: (k,) modal combination of the response to that
    component}; seismic: (k,) the directions combined (the design seismic action effect E);
    gravity: (k,) static value under gravity alone (members only, else None); design: (k,)
    max |gravity ± seismic| = |gravity| + seismic (members only, else None).
    """

    name: str
    unit: str
    description: str
    kind: str
    labels: tuple[str, ...]
    by_direction: dict[str, np.ndarray]
    seismic: np.ndarray
    gravity: np.ndarray | None = None
    design: np.ndarray | None = None

    @property
    def governing(self) -> tuple[str, float]:
        """(label, value) of the largest design (else seismic) value."""
        v = self.design if self.design is not None else self.seismic
        k = int(np.argmax(v))
        return self.labels[k], float(v[k])

    def as_dict(self) -> dict[str, Any]:
        lab, val = self.governing
        return {"unit": self.unit, "description": self.description, "kind": self.kind,
                "labels": list(self.labels),
                "by_direction": {d: _list(v) for d, v in self.by_direction.items()},
                "seismic": _list(self.seismic), "gravity": _list(self.gravity),
                "design": _list(self.design), "max": val, "max_label": lab}


@dataclass(frozen=True)
class StoreyCheck:
    """EN 1998-1 §4.4.2.2 per storey, one horizontal direction.

    height, P_tot [N], drift_e (elastic analysis), drift_s = q·drift_e (§4.3.4) [m],
    V_tot [N], theta [-], amplification 1/(1 − θ) [-] (1 where θ <= θ_ignore): (n_storey,);
    verdicts: (n_storey,) text; ok: every storey within θ_max.
    """

    direction: str
    q: float
    height: np.ndarray
    P_tot: np.ndarray
    drift_e: np.ndarray
    drift_s: np.ndarray
    V_tot: np.ndarray
    theta: np.ndarray
    amplification: np.ndarray
    verdicts: tuple[str, ...]
    ok: bool

    def as_dict(self) -> dict[str, Any]:
        rows = []
        for s in range(self.height.size):
            rows.append({"storey": s + 1, "height_m": float(self.height[s]),
                         "P_tot_N": float(self.P_tot[s]), "drift_e_m": float(self.drift_e[s]),
                         "drift_s_m": float(self.drift_s[s]),
                         "drift_ratio": float(self.drift_s[s] / self.height[s]),
                         "V_tot_N": float(self.V_tot[s]), "theta": float(self.theta[s]),
                         "amplification": float(self.amplification[s]),
                         "verdict": self.verdicts[s]})
        return {"direction": self.direction, "q": self.q, "storeys": rows, "ok": self.ok}


@dataclass(frozen=True)
class DesignResult:
    """The modal response spectrum analysis of one rack (:func:`~seisrack.design.design_analysis`).

    Modes (pallet horizontal mass scaled by E_D1·E_D3): periods [s], omega [rad/s], damping
    [-] (used in CQC and, for an elastic spectrum, in η): (n_modes,);
    effective_mass: {direction: (n_modes,) [kg]}, total_mass: {direction: [kg]}.
    spectra: {direction: spectrum name}; q: {direction: behaviour factor}; sa: {direction:
    (n_modes,) [m/s²] spectral acceleration used, E_D2 included}.
    modal_rule, modal_rule_reason: {direction: "srss"/"cqc", why}; direction_rule: "srss",
    "0.30" or "single" and its text.
    quantities: {name: :class:`Quantity`}; storeys: {direction: :class:`StoreyCheck`}.
    notes: what the reader should know (modes below 90 % of the mass, missing 3D members).
    """

    three_d: bool
    directions: tuple[str, ...]
    periods: np.ndarray
    omega: np.ndarray
    damping: np.ndarray
    effective_mass: dict[str, np.ndarray]
    total_mass: dict[str, float]
    spectra: dict[str, str]
    q: dict[str, float]
    sa: dict[str, np.ndarray]
    modal_rule: dict[str, str]
    modal_rule_reason: dict[str, str]
    direction_rule: str
    direction_rule_text: str
    quantities: dict[str, Quantity]
    storeys: dict[str, StoreyCheck]
    factors: dict[str, float]
    factor_sources: dict[str, str]
    mass_factor: float
    notes: tuple[str, ...] = ()
    status: str = "ok"
    meta: dict[str, Any] = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        return int(self.periods.size)

    def cumulative_mass(self, direction: str) -> float:
        """Share of the total mass in ``direction`` reached by the modes taken into account."""
        return float(np.sum(self.effective_mass[direction]) / self.total_mass[direction])

    def base_shear(self, direction: str = "down-aisle") -> float:
        """[N] design base shear in ``direction`` (directions combined)."""
        return float(self.quantities[f"base_shear_{_ax(direction)}"].seismic[0])

    def as_dict(self) -> dict[str, Any]:
        modes = {"periods_s": _list(self.periods), "damping": _list(self.damping),
                 "effective_mass_kg": {d: _list(m) for d, m in self.effective_mass.items()},
                 "total_mass_kg": dict(self.total_mass),
                 "cumulative_mass": {d: self.cumulative_mass(d) for d in self.directions},
                 "sa_m_s2": {d: _list(v) for d, v in self.sa.items()}}
        return {
            "three_d": self.three_d, "directions": list(self.directions),
            "spectra": dict(self.spectra), "q": dict(self.q), "modes": modes,
            "mass_factor_unit_loads": self.mass_factor,
            "modal_rule": dict(self.modal_rule), "modal_rule_reason": dict(self.modal_rule_reason),
            "direction_rule": self.direction_rule, "direction_rule_text": self.direction_rule_text,
            "quantities": {k: q.as_dict() for k, q in self.quantities.items()},
            "storeys": {d: s.as_dict() for d, s in self.storeys.items()},
            "factors": dict(self.factors), "factor_sources": dict(self.factor_sources),
            "notes": list(self.notes), "status": self.status, **self.meta,
        }


def _ax(direction: str) -> str:
    return "z" if direction == "cross-aisle" else "x"
