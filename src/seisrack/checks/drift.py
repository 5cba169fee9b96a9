"""EN 1998-1 §4.4.2.2 interstorey drift sensitivity coefficient θ, from a time history.

    θ = P_tot · d_r / (V_tot · h)                                  (EN 1998-1 Eq. 4.28)

per storey, with P_tot the total gravity load at and above the storey (members and pallets), d_r
the peak interstorey drift of the time history (the mean horizontal displacement of the beam
level above minus that below; no behaviour factor: the analysis is elastic), V_tot the peak
storey shear (the net horizontal force the members and bars crossing the storey carry, over the
kept history) and h the storey height; on a 3D rack in each horizontal direction. Verdicts,
§4.4.2.2(2)-(4): θ ≤ 0.1 P-Δ may be neglected; 0.1 < θ ≤ 0.2 amplify the seismic action effects
by 1/(1-θ); θ ≤ 0.3 at most.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.checks.factors import CheckFactors

SOURCE = "EN 1998-1:2004"
CLAUSE = "§4.4.2.2(2)-(4), Eq. (4.28)"


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


def storey_shear_history(model: Any, U: np.ndarray, direction: int = 0) -> np.ndarray:
    """(n_t, n_storey) [N] storey shear along ``direction``: the elastic forces K u on the DOFs
    of that direction above the bottom of each storey, i.e. the net horizontal force that the
    members and bars crossing the storey carry (the uprights' shears on a plane frame, with the
    bracing on a space frame; :func:`seisrack.fe.storeys.storey_operators`).

    U: (n_t, n_dof) [m, rad] displacements relative to the ground.
    """
    op = storey_shear_operator(model, direction)
    return np.asarray(np.asarray(U) @ op)


def storey_shear_operator(model: Any, direction: int = 0) -> Any:
    """(n_dof, n_storey) sparse map from displacements to the storey shears along
    ``direction`` (see :func:`storey_shear_history`)."""
    from seisrack.fe.storeys import storey_operators

    name = model.directions[direction]
    return next(o.op for o in storey_operators(model, name)
                if o.name.startswith("storey_shear"))


def drift_sensitivity_check(model: Any, response: Any, factors: CheckFactors | None = None
                            ) -> dict[str, Any]:
    """θ per storey and horizontal direction from ``response`` (a RackResponse of ``model``);
    JSON-ready dict. The storey shear is projected onto the run's basis (never an
    (n_t, n_dof) history)."""
    from seisrack.analysis.peaks import project

    f = factors or CheckFactors()
    level_y = np.asarray(model.level_y, dtype=float)
    h = np.diff(np.concatenate([[0.0], level_y]))
    disp_all = response.directional("beam_displacement")  # (n_t, n_level, n_dir)
    P = storey_gravity_loads(model)
    hist = response.history
    rows = []
    ok_all = True
    for d, name in enumerate(model.directions):
        disp = disp_all[..., d]
        rel = np.diff(np.concatenate([np.zeros((disp.shape[0], 1)), disp], axis=1), axis=1)
        d_r = np.max(np.abs(rel), axis=0)
        op = storey_shear_operator(model, d)
        V = np.max(np.abs(hist.q @ project(op, hist.phi)), axis=0)
        for s in range(h.size):
            theta = sensitivity_theta(P[s], d_r[s], V[s], h[s])
            text, ok = theta_verdict(theta, f)
            ok_all &= ok
            rows.append({"storey": s + 1, "direction": name, "height_m": float(h[s]),
                         "P_tot_N": float(P[s]), "drift_m": float(d_r[s]),
                         "drift_ratio": float(d_r[s] / h[s]), "V_tot_N": float(V[s]),
                         "theta": theta,
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
        "verdict": (f"max θ = {worst['theta']:.3f} (storey {worst['storey']}, "
                    f"{worst['direction']}): {worst['verdict']}" if worst else "no storeys"),
        "ok": bool(ok_all),
    }
