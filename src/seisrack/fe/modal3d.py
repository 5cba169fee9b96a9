"""Modal analysis of a 3D rack: participation down-aisle, cross-aisle and in plan rotation.

With mass-normalised shapes (φᵀMφ = 1) and an influence vector r, the participation factor is
Γ = φᵀ M r and the effective modal mass Γ² (Chopra, *Dynamics of Structures*, 4th ed., §13.2;
for a rotation about the vertical, r = r_θ and Γ² is an effective mass moment of inertia,
Chopra §13.3 for the torsionally coupled building). Σ Γ² over all modes is rᵀ M r. Each mode
is classified by the largest of its three participation ratios Γ_x²/M_x, Γ_z²/M_z and
Γ_θ²/I_θ: down-aisle, cross-aisle or torsional, or "other" (vertical, local) when all three
are below ``OTHER_BELOW`` (the plan rotation is about the vertical axis
through the plan's mass centre, so a pure translation has no torsional participation).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from seisrack.fe.eigen import Method, ModalResult, modal_from_matrices
from seisrack.fe.mesh import FloatArray

DIRECTIONS = ("down-aisle", "cross-aisle", "torsional", "other")
#: a mode whose three participation ratios are all below this is "other" (vertical or local)
OTHER_BELOW = 0.01


@dataclass(frozen=True)
class ModalResult3D(ModalResult):
    """:class:`ModalResult` (x = down-aisle) plus cross-aisle (z) and plan-rotation terms.

    gamma_z, effective_mass_z [kg], mass_participation_z [-]: (n_modes,); total_mass_z [kg].
    gamma_theta, effective_inertia_theta [kg·m²], participation_theta [-]: (n_modes,);
    total_inertia_theta [kg·m²] about the vertical through the plan mass centre.
    direction: (n_modes,) str, one of ``DIRECTIONS``.
    """

    gamma_z: FloatArray | None = None
    effective_mass_z: FloatArray | None = None
    mass_participation_z: FloatArray | None = None
    total_mass_z: float = 0.0
    gamma_theta: FloatArray | None = None
    effective_inertia_theta: FloatArray | None = None
    participation_theta: FloatArray | None = None
    total_inertia_theta: float = 0.0
    direction: tuple[str, ...] = ()


def modal_analysis_3d(model: Any, n_modes: int | None = None, *, method: Method = "auto"
                      ) -> ModalResult3D:
    """Modes of a :class:`~seisrack.model.frame_model3d.FrameModel3D`, pallets attached."""
    M = model.total_mass_sparse()
    base = modal_from_matrices(model.K_sparse, M, model.r_x, model.r_y, n_modes, method=method)
    phi = base.shapes
    gz = phi.T @ (M @ model.r_z)
    gt = phi.T @ (M @ model.r_theta)
    mz = float(model.r_z @ (M @ model.r_z))
    it = float(model.r_theta @ (M @ model.r_theta))
    pz, pt = gz**2 / mz, gt**2 / it
    ratios = np.column_stack([base.mass_participation, pz, pt])
    best = np.where(ratios.max(axis=1) < OTHER_BELOW, 3, ratios.argmax(axis=1))
    direction = tuple(DIRECTIONS[i] for i in best)
    fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
    return ModalResult3D(**fields, gamma_z=gz, effective_mass_z=gz**2, mass_participation_z=pz,
                         total_mass_z=mz, gamma_theta=gt, effective_inertia_theta=gt**2,
                         participation_theta=pt, total_inertia_theta=it, direction=direction)
