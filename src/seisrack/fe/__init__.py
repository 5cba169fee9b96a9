"""2D Euler–Bernoulli frame finite elements: matrices, assembly, damping, modes, recovery."""

from seisrack.fe.assembly import assemble, scatter
from seisrack.fe.mesh import FrameMesh, line_mesh
from seisrack.fe.modal import ModalResult, modal_analysis, modal_from_matrices
from seisrack.fe.recovery import (
    UprightMoments,
    base_reactions,
    element_end_forces,
    support_reactions,
    upright_moments,
)

__all__ = [
    "FrameMesh", "ModalResult", "UprightMoments", "assemble", "base_reactions",
    "element_end_forces", "line_mesh", "modal_analysis", "modal_from_matrices", "scatter",
    "support_reactions", "upright_moments",
]
