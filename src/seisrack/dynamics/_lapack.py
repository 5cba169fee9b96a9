"""In-place Cholesky factorisation for the Newton matrices of the planar kernel and of the
line kernel with hinges (source shared by the numba and pure-Python backends; theory:
``docs/theory/planar_friction.md`` §2, ``docs/theory/nonlinear_hinges.md``).

The matrices are square, C-ordered and symmetric, and only their lower triangle is read or
written: ``_syrk_lower`` adds GᵀG to it, ``_chol`` overwrites it with the Cholesky factor
L (A = L Lᵀ) and ``_chol_solve`` solves with that factor; the strict upper triangle is left as
it was. Compiled, the first two call LAPACK / BLAS directly
(:mod:`seisrack.dynamics._lapack_symbols`): Fortran reads a C-ordered matrix as its
transpose, so the lower triangle here is Fortran's upper one ("U"), and the rows of G are the
columns of a Fortran matrix X with GᵀG = X Xᵀ. Against ``np.dot(G.T, G)`` and
``np.linalg.cholesky`` this halves the product's work and skips three copies of the matrix.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # compiled: the loader injects _JIT
    _JIT  # type: ignore[used-before-def]  # noqa: B018
    from seisrack.dynamics._lapack_symbols import DPOTRF, DSYRK

    _COMPILED = True
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT  # the numpy versions below are used

    _COMPILED = False

_U = 85  # ord("U")
_N = 78  # ord("N")

if _COMPILED:

    @_JIT
    def _syrk_lower(A, G, ng):
        """A += G[:ng]ᵀ G[:ng] on the lower triangle (A (r, r), G (>= ng, r), C-ordered)."""
        if ng == 0 or A.shape[0] == 0:
            return
        ch = np.empty(2, dtype=np.uint8)
        ch[0] = _U
        ch[1] = _N
        iv = np.empty(3, dtype=np.int32)
        iv[0] = A.shape[0]
        iv[1] = ng
        iv[2] = G.shape[1]
        one = np.ones(1)
        DSYRK(ch.ctypes, ch[1:].ctypes, iv.ctypes, iv[1:].ctypes, one.ctypes, G.ctypes,
              iv[2:].ctypes, one.ctypes, A.ctypes, iv.ctypes)

    @_JIT
    def _chol(A):
        """Lower Cholesky factor of the SPD matrix ``A`` into its lower triangle; False if
        ``A`` is not positive definite (or not finite)."""
        if A.shape[0] == 0:  # every direction held quasi-statically: nothing to factorise
            return True
        ch = np.empty(1, dtype=np.uint8)
        ch[0] = _U
        iv = np.empty(2, dtype=np.int32)
        iv[0] = A.shape[0]
        iv[1] = 0
        DPOTRF(ch.ctypes, iv.ctypes, A.ctypes, iv.ctypes, iv[1:].ctypes)
        if iv[1] != 0:
            return False
        # OpenBLAS' potrf lets a NaN through (its test is ajj <= 0); any NaN or inf of the
        # lower triangle reaches the diagonal of the factor
        for i in range(A.shape[0]):
            if not (np.isfinite(A[i, i]) and A[i, i] > 0.0):
                return False
        return True

else:

    def _syrk_lower(A, G, ng):
        """A += G[:ng]ᵀ G[:ng] on the lower triangle (A (r, r), G (>= ng, r), C-ordered)."""
        if ng > 0:
            A += np.tril(np.dot(G[:ng].T, G[:ng]))

    def _chol(A):
        """Lower Cholesky factor of the SPD matrix ``A`` into its lower triangle; False if
        ``A`` is not positive definite (or not finite)."""
        low = np.tril(A)
        try:
            L = np.linalg.cholesky(low + np.tril(low, -1).T)
        except np.linalg.LinAlgError:
            return False
        if not np.all(np.isfinite(L)):
            return False
        A[np.tril_indices(A.shape[0])] = L[np.tril_indices(A.shape[0])]
        return True


@_JIT
def _chol_solve(L, x):
    """Solve (L Lᵀ) y = x in place (``L``: the lower triangle that ``_chol`` wrote)."""
    n = L.shape[0]
    for i in range(n):
        acc = x[i]
        for k in range(i):
            acc -= L[i, k] * x[k]
        x[i] = acc / L[i, i]
    # Lᵀ y = x by columns of Lᵀ, i.e. rows of L (contiguous)
    for i in range(n - 1, -1, -1):
        xi = x[i] / L[i, i]
        x[i] = xi
        for k in range(i):
            x[k] -= L[i, k] * xi
