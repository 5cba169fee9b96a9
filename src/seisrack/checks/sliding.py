"""Simplified pallet sliding check of the European rack seismic rules (FEM 10.2.08 / EN 16681).

As published by Castiglioni (*Seismic behaviour of steel storage pallet racking systems*,
Politecnico di Milano, 2008, §"Pallet sliding", quoting prFEM 10.2.08): a pallet that is not
restrained on its beams slides when the seismic force on it exceeds the friction reaction,

    F_i > γ_μS · μ_S · Q_P   ⇔   a_i / g > γ_μS · μ_S,

with a_i the horizontal acceleration of load level i from the design spectrum with E_D1 = 1.
The upper-bound friction coefficient is used for the ULS, the lower bound for the SLS. The
clause text of EN 16681 itself was not available; see ``docs/user/design_checks.md``.

The level acceleration a_i is combined over the modes of the rack with rigidly held pallets
(SRSS of Γ_k φ_k,i S_a(T_k), EN 1998-1 §4.3.3.3.2), with S_a from the given design spectrum or,
without one, from the 5 %-damped response spectrum of the record. On a 3D rack it is computed in
each horizontal direction and the two are combined by SRSS (EN 1998-1 §4.3.3.5.1(2)b): friction
is isotropic, so a pallet slides when the magnitude of the horizontal force on it exceeds
γ_μS·μ_S·Q_P.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.checks.factors import CheckFactors

SOURCE = "FEM 10.2.08 / EN 16681, simplified pallet sliding check"
CLAUSE = ("prFEM 10.2.08 'Pallet sliding' (1)-(2) as published by Castiglioni (2008); "
          "EN 16681 clause text not available here")


def level_accelerations(model: Any, modal: Any, sa: np.ndarray, direction: int = 0
                        ) -> np.ndarray:
    """(n_level,) [m/s²] SRSS peak absolute acceleration of each beam level along
    ``direction`` (0 down-aisle, 1 cross-aisle) under a ground motion along it.

    modal: a ModalResult of ``model``; sa: (n_modes,) [m/s²] spectral acceleration S_a(T_k).
    Eq: a_i = sqrt(Σ_k (Γ_k · φ̄_k,i · S_a(T_k))²), φ̄ the mean modal displacement of the level's
    nodes along the direction, Γ the participation factor of that direction (EN 1998-1
    §4.3.3.3.2, SRSS).
    """
    sa = np.asarray(sa, dtype=float)
    gamma = modal.gamma_x if direction == 0 else modal.gamma_z
    phi_lv = np.array([modal.shapes[np.asarray(d)].mean(axis=0)
                       for d in model.level_dofs[direction]])
    contrib = gamma[None, :] * phi_lv * sa[None, :]  # (n_level, n_modes)
    return np.sqrt(np.sum(contrib**2, axis=1))


def spectral_accelerations(modal: Any, *, spectrum: Any = None, record: Any = None,
                           damping: float = 0.05, direction: int = 0) -> tuple[np.ndarray, str]:
    """(n_modes,) [m/s²] S_a at the modal periods, and a description of where it came from:
    the design spectrum, else the response spectrum of the record (a Record, or the component
    along ``direction`` of a GroundMotion; a missing component gives S_a = 0)."""
    periods = np.asarray(modal.periods, dtype=float)
    if spectrum is not None:
        return np.asarray(spectrum.psa(periods), dtype=float), \
            f"design spectrum {getattr(spectrum, 'name', '')}".strip()
    if record is None:
        raise ValueError("a design spectrum or a record is needed")
    from seisrack.motion import response_spectrum

    if hasattr(record, "horizontal"):  # a GroundMotion: its component along the direction
        comps = record.horizontal
        if direction >= len(comps):
            return np.zeros_like(periods), f"no {('down', 'cross')[direction]}-aisle component"
        accel, name = comps[direction], record.names[direction]
    else:
        accel, name = record.accel, record.name
    sp = response_spectrum(accel, record.dt, periods, damping)
    return np.asarray(sp.psa, dtype=float), \
        f"{100 * damping:g} %-damped response spectrum of record {name}"


def pallet_sliding_check(model: Any, modal: Any, *, spectrum: Any = None, record: Any = None,
                         factors: CheckFactors | None = None) -> dict[str, Any]:
    """The simplified sliding check per pallet, ULS and SLS.

    Returns a JSON-ready dict: ``levels`` (a_i for ULS and SLS [m/s²]), ``pallets`` (1-based
    ``id``, level, μ used, a/g, verdicts), and ``sliding_predicted_uls`` per pallet.
    """
    f = factors or CheckFactors()
    n_dir = len(model.level_dofs)
    spectra = [spectral_accelerations(modal, spectrum=spectrum, record=record,
                                      damping=f.damping, direction=d) for d in range(n_dir)]
    sa_from = "; ".join(dict.fromkeys(how for _, how in spectra))
    by_dir = np.array([f.e_d1_sliding * level_accelerations(model, modal, sa, d)
                       for d, (sa, _) in enumerate(spectra)])  # (n_dir, n_level)
    a_uls = np.sqrt(np.sum(by_dir**2, axis=0))  # the directions combined by SRSS
    a_sls = f.nu_sls * a_uls
    g = float(model.g)
    lv = pallet_levels(model)
    mu_u = (np.full(model.n_pallets, f.mu_uls) if f.mu_uls is not None
            else np.asarray(model.pallet_mu_static, dtype=float))
    mu_s = (np.full(model.n_pallets, f.mu_sls) if f.mu_sls is not None
            else np.asarray(model.pallet_mu_dynamic, dtype=float))
    pallets = []
    for j in range(model.n_pallets):
        au, as_ = a_uls[lv[j]] / g, a_sls[lv[j]] / g
        ru, rs = f.gamma_mu * mu_u[j], f.gamma_mu * mu_s[j]
        pallets.append({
            "id": j + 1,
            "level": int(lv[j]) + 1,
            "alpha_uls": float(au), "mu_uls": float(mu_u[j]),
            "slides_uls": bool(au > ru),
            "alpha_sls": float(as_), "mu_sls": float(mu_s[j]),
            "slides_sls": bool(as_ > rs),
        })
    n_u = sum(p["slides_uls"] for p in pallets)
    n_s = sum(p["slides_sls"] for p in pallets)
    return {
        "name": "pallet_sliding_fem",
        "title": "Pallet sliding, simplified check (FEM 10.2.08 / EN 16681)",
        "source": SOURCE,
        "clause": CLAUSE,
        "rule": "sliding if a_i/g > gamma_mu * mu (ULS: upper-bound mu, SLS: lower-bound mu)",
        "acceleration_from": sa_from,
        "directions": ("SRSS of the down-aisle and cross-aisle level accelerations "
                       "(EN 1998-1 §4.3.3.5.1(2)b)" if n_dir > 1 else "down-aisle"),
        "levels": [{"level": i + 1, "a_uls_m_s2": float(a_uls[i]), "a_sls_m_s2": float(a_sls[i]),
                    **({"a_uls_down_aisle_m_s2": float(by_dir[0, i]),
                        "a_uls_cross_aisle_m_s2": float(by_dir[1, i])} if n_dir > 1 else {})}
                   for i in range(a_uls.size)],
        "pallets": pallets,
        "verdict": (f"ULS: {n_u} of {len(pallets)} pallets predicted to slide "
                    "(a sliding analysis is needed)" if n_u else
                    f"ULS: no pallet predicted to slide ({len(pallets)} pallets)")
        + (f"; SLS: {n_s} predicted to slide" if n_s else "; SLS: none predicted to slide"),
        "ok": n_u == 0,
    }


def pallet_levels(model: Any) -> np.ndarray:
    """(n_pallet,) 0-based beam level of each pallet."""
    return np.asarray(model.pallet_level, dtype=int)
