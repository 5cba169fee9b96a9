"""Positive definiteness of a sparse symmetric stiffness matrix: a stable frame, not a mechanism.

A symmetric matrix factored without row pivoting, P K Pᵀ = L U with L unit lower triangular, has
U = D Lᵀ (the LU factors are unique), so K = (PᵀL) D (PᵀL)ᵀ and by Sylvester's law of inertia K is
positive definite iff every pivot of D is positive (Golub & Van Loan, *Matrix Computations*,
4th ed., §4.1–4.2). SuperLU is asked for a fill-reducing *symmetric* ordering and diagonal pivots
(threshold 0); if it had to take an off-diagonal pivot, a diagonal of a Schur complement was zero,
which a positive definite matrix cannot have.

In floating point the pivot of a mechanism is not exactly zero but round-off, of either sign: a
pivot counts as positive only above ``rtol`` times the original diagonal entry of its DOF. The
pivot ratios of real racks are 1e-6 (joints of 1 N·m/rad) to 1e-2; a mechanism gives 1e-16 to
1e-13 (a 10-level, 20-bay rack with every joint pinned).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

PIVOT_RTOL = 1e-10


def symmetric_lu(K: sp.spmatrix) -> sla.SuperLU:
    """Sparse LU of symmetric ``K`` with a symmetric fill-reducing ordering and diagonal pivots.

    Raises RuntimeError if a pivot is exactly zero (SuperLU: "Factor is exactly singular").
    """
    return sla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                    options={"SymmetricMode": True})


def is_positive_definite(K: sp.spmatrix, rtol: float = PIVOT_RTOL) -> bool:
    """True if symmetric ``K`` (n, n) is positive definite to within round-off (see module doc).

    Costs one sparse factorisation: O(nnz of the factor) memory, no dense (n, n) work.
    """
    n = K.shape[0]
    if n == 0:
        return True
    diag = K.diagonal()
    if np.any(diag <= 0.0):
        return False  # a DOF without stiffness of its own
    try:
        lu = symmetric_lu(K)
    except RuntimeError:
        return False  # an exactly zero pivot
    if not np.array_equal(lu.perm_r, lu.perm_c):
        return False  # an off-diagonal pivot was needed: a zero diagonal in a Schur complement
    # Pr K Pc = L U: DOF i is eliminated at position perm_c[i] (see scipy's splu example).
    pivots = lu.U.diagonal()[lu.perm_c]
    return bool(np.all(pivots > rtol * diag))
