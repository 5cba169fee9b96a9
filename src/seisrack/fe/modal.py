"""Modal analysis of a compiled rack (2D :class:`~seisrack.model.FrameModel` or 3D
:class:`~seisrack.model.frame_model3d.FrameModel3D`), with the pallets rigidly attached.

The eigensolvers, :class:`ModalResult` and the participation (Chopra, *Dynamics of
Structures*, 4th ed., §13.2) are in :mod:`seisrack.fe.eigen`; the 3D participations in
:mod:`seisrack.fe.modal3d`. Both are re-exported here.
"""

from __future__ import annotations

from typing import Any

from seisrack.fe.eigen import (  # noqa: F401  (re-exported: the modal API)
    DENSE_MAX_DOF,
    SPARSE_MAX_FRACTION,
    Method,
    ModalResult,
    choose_method,
    modal_from_matrices,
)
from seisrack.fe.modal3d import modal_analysis_3d


def modal_analysis(model: Any, n_modes: int | None = None, *, method: Method = "auto"
                   ) -> ModalResult:
    """Modes of a :class:`~seisrack.model.FrameModel` with the pallets rigidly attached.

    ``n_modes=None`` returns all modes (dense solver). Shapes are normalised with the total mass
    (``total_mass_sparse()``). ``method``: see :func:`modal_from_matrices`. A 3D rack
    (:class:`~seisrack.model.frame_model3d.FrameModel3D`) gives a
    :class:`~seisrack.fe.modal3d.ModalResult3D` (cross-aisle and torsional participation too).
    """
    if getattr(model, "is_3d", False):
        return modal_analysis_3d(model, n_modes, method=method)
    return modal_from_matrices(model.K_sparse, model.total_mass_sparse(), model.r_x, model.r_y,
                               n_modes, method=method)
