"""BLAS / LAPACK blocks of the local engine's block Cholesky factorisation (source shared by
the numba and the pure-Python backends; theory: ``docs/theory/local_engine.md`` §2).

Each block is the leading ``b × b`` (or ``b × bn``) corner of a C-ordered ``bmax × bmax``
array; Fortran reads it as its transpose with leading dimension ``bmax``, so the lower triangle
here is Fortran's upper one. Compiled, the routines are LAPACK ``dpotrf`` and BLAS ``dtrsm``,
``dsyrk`` through SciPy's ``cython_lapack`` / ``cython_blas`` (registered as LLVM symbols,
:mod:`seisrack.dynamics._lapack_symbols`); the Python twin uses numpy and SciPy.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # compiled: the loader injects _JIT
    _JIT  # type: ignore[used-before-def]  # noqa: B018
    from seisrack.dynamics._lapack_symbols import DPOTRF, DSYRK, _external

    DTRSM = _external("scipy.linalg.cython_blas", "dtrsm", 11)
    _BLAS = True
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    import scipy.linalg

    from seisrack.dynamics._lapack import _chol

    _JIT = None  # the numpy versions below are used
    _BLAS = False

_U = 85  # ord("U")
_N = 78  # ord("N")
_R = 82  # ord("R")

if _BLAS:

    @_JIT
    def _potrf_corner(A, b):
        """Lower Cholesky factor of A[:b, :b] in place; False if not positive definite."""
        if b == 0:
            return True
        ch = np.empty(1, dtype=np.uint8)
        ch[0] = _U
        iv = np.empty(3, dtype=np.int32)
        iv[0] = b
        iv[1] = A.shape[1]
        iv[2] = 0
        DPOTRF(ch.ctypes, iv.ctypes, A.ctypes, iv[1:].ctypes, iv[2:].ctypes)
        if iv[2] != 0:
            return False
        for i in range(b):
            if not (np.isfinite(A[i, i]) and A[i, i] > 0.0):
                return False
        return True

    @_JIT
    def _trsm_corner(L, b, X, bn):
        """X[:b, :bn] = L[:b, :b]⁻¹ X[:b, :bn] (L lower triangular)."""
        if b == 0 or bn == 0:
            return
        ch = np.empty(4, dtype=np.uint8)
        ch[0] = _R
        ch[1] = _U
        ch[2] = _N
        ch[3] = _N
        iv = np.empty(4, dtype=np.int32)
        iv[0] = bn
        iv[1] = b
        iv[2] = L.shape[1]
        iv[3] = X.shape[1]
        one = np.ones(1)
        DTRSM(ch.ctypes, ch[1:].ctypes, ch[2:].ctypes, ch[3:].ctypes, iv.ctypes,
              iv[1:].ctypes, one.ctypes, L.ctypes, iv[2:].ctypes, X.ctypes, iv[3:].ctypes)

    @_JIT
    def _syrk_corner(S, bn, X, b):
        """S[:bn, :bn] −= X[:b, :bn]ᵀ X[:b, :bn] on the lower triangle."""
        if b == 0 or bn == 0:
            return
        ch = np.empty(2, dtype=np.uint8)
        ch[0] = _U
        ch[1] = _N
        iv = np.empty(4, dtype=np.int32)
        iv[0] = bn
        iv[1] = b
        iv[2] = X.shape[1]
        iv[3] = S.shape[1]
        al = np.empty(2)
        al[0] = -1.0
        al[1] = 1.0
        DSYRK(ch.ctypes, ch[1:].ctypes, iv.ctypes, iv[1:].ctypes, al.ctypes, X.ctypes,
              iv[2:].ctypes, al[1:].ctypes, S.ctypes, iv[3:].ctypes)

else:

    def _potrf_corner(A, b):
        """Lower Cholesky factor of A[:b, :b] in place; False if not positive definite."""
        return True if b == 0 else _chol(A[:b, :b])

    def _trsm_corner(L, b, X, bn):
        """X[:b, :bn] = L[:b, :b]⁻¹ X[:b, :bn] (L lower triangular)."""
        if b and bn:
            X[:b, :bn] = scipy.linalg.solve_triangular(np.tril(L[:b, :b]), X[:b, :bn],
                                                       lower=True)

    def _syrk_corner(S, bn, X, b):
        """S[:bn, :bn] −= X[:b, :bn]ᵀ X[:b, :bn] on the lower triangle."""
        if b and bn:
            S[:bn, :bn] -= np.tril(X[:b, :bn].T @ X[:b, :bn])
