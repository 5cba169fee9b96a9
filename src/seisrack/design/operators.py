"""Named response-quantity operators of a compiled rack, for the modal combination (the
storey quantities are in :mod:`seisrack.fe.storeys`, re-exported here).

Each :class:`NamedOperator` is a sparse ``(n_dof, k)`` map from free-DOF displacements to k
values of one response quantity (``u @ op``). The design analysis only evaluates
``op.T @ U`` for the modal displacements ``U`` (n_dof, n_modes), so it is generic over them.

- Storey quantities, for any rack (2D or 3D) and each horizontal direction (down-aisle x,
  cross-aisle z): base shear and storey shears (the elastic forces ``K u`` on the DOFs of that
  direction above the bottom of the storey: for a structure on its supports these equal the
  support reactions; ``rᵀ K u_k = Γ_k² ω_k² D_k`` per mode), mean level displacements and
  interstorey drifts.
- Member quantities from :func:`seisrack.fe.recovery.recovery_operators` and
  :func:`~seisrack.fe.recovery.design_operators` (2D and 3D racks): upright axial force and
  bending moment at the base and below each level (in the bending plane of each horizontal
  direction), beam end moments, connector moments.
"""

from __future__ import annotations

from typing import Any

import scipy.sparse as sp

from seisrack.fe.storeys import (  # noqa: F401  (re-exported)
    AXIS,
    DIRECTIONS,
    NamedOperator,
    base_height,
    directions_of,
    influence,
    level_dofs,
    storey_heights,
    storey_operators,
)


def _section_columns(base: sp.csr_matrix, below: sp.csr_matrix, n_up: int, n_lev: int
                     ) -> sp.csr_matrix:
    """(n_dof, n_up·(n_lev + 1)) base and below-level moments in the section order
    ``u·(n_lev + 1) + s`` of the upright axial force."""
    order = []
    for u in range(n_up):
        order.append(base[:, [u]])
        order.append(below[:, u * n_lev:(u + 1) * n_lev])
    return sp.csr_matrix(sp.hstack(order))


def member_operators(model: Any) -> tuple[list[NamedOperator], str]:
    """Member force operators of ``model`` and a note ("": they are all there).

    Upright axial force N and bending moment M at the base and below each level (the moment
    in the bending plane of each horizontal direction: ``upright_moment`` down-aisle,
    ``upright_moment_cross_aisle`` on a 3D rack), beam end moments, connector moments.
    """
    from seisrack.fe import recovery

    rec, des = recovery.rack_operators(model)  # one pass over the members
    n_up, n_lev = rec.n_upright, rec.n_level
    out = [NamedOperator("upright_axial_force", des.axial, des.axial_labels, "N",
                         "upright axial force, tension positive, at the base and below each "
                         "level", "member")]
    for d, (name, plane) in enumerate((("upright_moment", "down-aisle"),
                                       ("upright_moment_cross_aisle", "cross-aisle"))
                                      [:rec.n_dir]):
        section = _section_columns(rec.base_moment[d], rec.below[d], n_up, n_lev)
        out.append(NamedOperator(name, section, des.axial_labels, "N m",
                                 f"upright bending moment in the {plane} plane at the base and "
                                 "below each level", "member"))
    out += [
        NamedOperator("beam_end_moment", des.beam_moment, des.beam_labels, "N m",
                      "bending moment at the beam ends", "member"),
        NamedOperator("connector_moment", des.connector_moment, des.connector_labels, "N m",
                      "moment of the beam-to-upright connector", "member"),
    ]
    return out, ""
