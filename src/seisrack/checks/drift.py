"""EN 1998-1 §4.4.2.2 interstorey drift sensitivity coefficient θ, from a time history.

    θ = P_tot · d_r / (V_tot · h)                                  (EN 1998-1 Eq. 4.28)

per storey, with P_tot the total gravity load at and above the storey (members and pallets),
d_r the peak interstorey drift of the time history (the mean horizontal displacement of the
beam level above minus that below; no behaviour factor: the analysis is elastic), V_tot the peak
storey shear (sum of the upright shears of the storey, from the element end forces of the kept
history) and h the storey height. Verdicts, §4.4.2.2(2)-(4): θ ≤ 0.1 P-Δ may be neglected;
0.1 < θ ≤ 0.2 amplify the seismic action effects by 1/(1-θ); θ ≤ 0.3 at most.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.checks.factors import CheckFactors
from seisrack.fe.recovery import element_end_forces

SOURCE = "EN 1998-1:2004"
CLAUSE = "§4.4.2.2(2)-(4), Eq. (4.28)"
#: kept samples per chunk when recovering upright shears (bounds memory for large racks)
_CHUNK = 2000


def theta_verdict(theta: float, f: CheckFactors) -> tuple[str, bool]:
    """Verdict text of one storey and whether it passes."""
    if theta <= f.theta_ignore:
        return f"θ ≤ {f.theta_ignore:g}: second-order (P-Δ) effects may be neglected", True
    if theta <= f.theta_amplify:
        return (f"{f.theta_ignore:g} < θ ≤ {f.theta_amplify:g}: amplify seismic action effects "
                f"by 1/(1-θ) = {1.0 / (1.0 - theta):.3f}"), True
    if theta <= f.theta_max:
        return (f"{f.theta_amplify:g} < θ ≤ {f.theta_max:g}: a second-order analysis is "
                "required"), True
    return f"θ > {f.theta_max:g}: not allowed", False


def sensitivity_theta(P_tot: float, d_r: float, V_tot: float, h: float) -> float:
    """θ = P_tot · d_r / (V_tot · h), EN 1998-1 Eq. (4.28) [N, m, N, m -> -]; 0 if V_tot = 0."""
    return float(P_tot * d_r / (V_tot * h)) if V_tot > 0 else 0.0


def storey_gravity_loads(model: Any) -> np.ndarray:
    """(n_storey,) [N] gravity load at and above each storey (members + pallets).

    The vertical mass of each free node is the row sum of the structure mass matrix on its uy
    DOF (the consistent mass lumped by rows; pallets' vertical masses are already on uy).
    """
    m_v = np.asarray(model.M_sparse @ model.r_y).ravel()  # (n_dof,) [kg] on uy DOFs
    nd = model.mesh.node_dofs
    free = nd[:, 1] >= 0
    # nodes of a semi-rigid joint share their translational DOFs: count each uy DOF once
    dofs, first = np.unique(nd[free, 1], return_index=True)
    y = model.mesh.nodes[free, 1][first]
    m = m_v[dofs]
    bottoms = np.concatenate([[0.0], np.asarray(model.level_y, dtype=float)[:-1]])
    tol = 1e-9 * max(1.0, float(np.max(model.level_y)))
    return np.array([float(model.g) * m[y > b + tol].sum() for b in bottoms])


def storey_shear_history(model: Any, U: np.ndarray) -> np.ndarray:
    """(n_t, n_storey) [N] sum of the upright shears of each storey (lowest segment per column).

    U: (n_t, n_dof) [m, rad] displacements relative to the ground.
    """
    kind = np.asarray(model.element_kind)
    storey = np.asarray(model.element_storey)
    line = np.asarray(model.element_line)
    y0 = model.mesh.nodes[model.mesh.elements[:, 0], 1]
    n_storey = model.n_level
    picks: list[np.ndarray] = []
    for s in range(n_storey):
        sel = []
        for col in np.unique(line[kind == 0]):
            cand = np.flatnonzero((kind == 0) & (storey == s) & (line == col))
            if cand.size:
                sel.append(cand[np.argmin(y0[cand])])
        picks.append(np.array(sel, dtype=int))
    out = np.empty((U.shape[0], n_storey))
    for a in range(0, U.shape[0], _CHUNK):
        f = element_end_forces(model, U[a:a + _CHUNK])  # (n, n_el, 6), local V_i = [..., 1]
        for s, el in enumerate(picks):
            out[a:a + _CHUNK, s] = f[:, el, 1].sum(axis=1)
    return out


def drift_sensitivity_check(model: Any, response: Any, factors: CheckFactors | None = None
                            ) -> dict[str, Any]:
    """θ per storey from ``response`` (a RackResponse of ``model``); JSON-ready dict."""
    f = factors or CheckFactors()
    level_y = np.asarray(model.level_y, dtype=float)
    h = np.diff(np.concatenate([[0.0], level_y]))
    disp = np.asarray(response.beam_displacement)  # (n_t, n_level)
    rel = np.diff(np.concatenate([np.zeros((disp.shape[0], 1)), disp], axis=1), axis=1)
    d_r = np.max(np.abs(rel), axis=0)
    P = storey_gravity_loads(model)
    V = np.max(np.abs(storey_shear_history(model, np.asarray(response.history.u))), axis=0)
    rows = []
    ok_all = True
    for s in range(h.size):
        theta = sensitivity_theta(P[s], d_r[s], V[s], h[s])
        text, ok = theta_verdict(theta, f)
        ok_all &= ok
        rows.append({"storey": s + 1, "height_m": float(h[s]), "P_tot_N": float(P[s]),
                     "drift_m": float(d_r[s]), "drift_ratio": float(d_r[s] / h[s]),
                     "V_tot_N": float(V[s]), "theta": theta,
                     "amplification": float(1.0 / (1.0 - theta)) if theta < 1 else None,
                     "verdict": text, "ok": ok})
    worst = max(rows, key=lambda r: r["theta"]) if rows else None
    return {
        "name": "drift_sensitivity_ec8",
        "title": "Interstorey drift sensitivity θ (EN 1998-1 §4.4.2.2)",
        "source": SOURCE,
        "clause": CLAUSE,
        "rule": "theta = P_tot d_r / (V_tot h); <= 0.1 neglect P-Delta, <= 0.2 amplify by "
                "1/(1-theta), <= 0.3 second-order analysis, > 0.3 not allowed",
        "storeys": rows,
        "verdict": (f"max θ = {worst['theta']:.3f} (storey {worst['storey']}): {worst['verdict']}"
                    if worst else "no storeys"),
        "ok": bool(ok_all),
    }
