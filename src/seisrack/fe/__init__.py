"""Euler–Bernoulli frame finite elements (plane and space): matrices, assembly, damping, modes,
recovery."""

from seisrack.fe.assembly import assemble, assemble_sparse, scatter
from seisrack.fe.mesh import FrameMesh, line_mesh
from seisrack.fe.modal import ModalResult, modal_analysis, modal_from_matrices
from seisrack.fe.recovery import (
    RecoveryOperators,
    UprightMoments,
    base_reactions,
    element_end_forces,
    recovery_operators,
    support_reactions,
    upright_moments,
)
from seisrack.fe.stability import is_positive_definite

__all__ = [
    "FrameMesh", "ModalResult", "RecoveryOperators", "UprightMoments", "assemble",
    "assemble_sparse", "base_reactions", "element_end_forces", "is_positive_definite",
    "line_mesh", "modal_analysis", "modal_from_matrices", "recovery_operators", "scatter",
    "support_reactions", "upright_moments",
]
