"""Modal analysis of a compiled rack, 2D or 3D, with the pallets rigidly attached.

The eigensolvers and :class:`ModalResult` are in :mod:`seisrack.fe.eigen` (re-exported here).
With mass-normalised shapes (φᵀMφ = 1) and an influence vector r, the participation factor is
Γ = φᵀ M r and the effective modal mass Γ² (Chopra, *Dynamics of Structures*, 4th ed., §13.2);
Σ Γ² over all modes is rᵀ M r. A 3D rack has a cross-aisle influence vector r_z and the rigid
plan rotation r_θ (Γ² is then an effective mass moment of inertia, Chopra §13.3 for the
torsionally coupled building), so each of its modes is classified by the largest of its three
participation ratios Γ_x²/M_x, Γ_z²/M_z and Γ_θ²/I_θ: down-aisle, cross-aisle or torsional, or
"other" (vertical, local) when all three are below ``OTHER_BELOW`` (the plan rotation is about
the vertical axis through the plan's mass centre, so a pure translation has no torsional
participation). A 2D rack's modes are all in its plane: no classes.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from seisrack.fe.eigen import (  # noqa: F401  (re-exported: the modal API)
    DENSE_MAX_DOF,
    SPARSE_MAX_FRACTION,
    Method,
    ModalResult,
    choose_method,
    modal_from_matrices,
)

DIRECTIONS = ("down-aisle", "cross-aisle", "torsional", "other")
#: a mode whose three participation ratios are all below this is "other" (vertical or local)
OTHER_BELOW = 0.01


def modal_analysis(model: Any, n_modes: int | None = None, *, method: Method = "auto"
                   ) -> ModalResult:
    """Modes of a compiled rack with the pallets rigidly attached.

    ``n_modes=None`` returns all modes (dense solver). Shapes are normalised with the total mass
    (``total_mass_sparse()``). ``method``: see :func:`modal_from_matrices`. A 3D rack's result
    carries its cross-aisle and torsional participation and each mode's class.
    """
    M = model.total_mass_sparse()
    base = modal_from_matrices(model.K_sparse, M, model.r_x, model.r_y, n_modes, method=method)
    if model.r_z is None:
        return base
    phi = base.shapes
    gz = phi.T @ (M @ model.r_z)
    gt = phi.T @ (M @ model.r_theta)
    mz = float(model.r_z @ (M @ model.r_z))
    it = float(model.r_theta @ (M @ model.r_theta))
    pz, pt = gz**2 / mz, gt**2 / it
    ratios = np.column_stack([base.mass_participation, pz, pt])
    best = np.where(ratios.max(axis=1) < OTHER_BELOW, 3, ratios.argmax(axis=1))
    return replace(base, gamma_z=gz, effective_mass_z=gz**2, mass_participation_z=pz,
                   total_mass_z=mz, gamma_theta=gt, effective_inertia_theta=gt**2,
                   participation_theta=pt, total_inertia_theta=it,
                   direction=tuple(DIRECTIONS[i] for i in best))
