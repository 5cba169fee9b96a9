"""Small dense linear algebra of the Newmark kernel, hand-written for numba's nopython mode
(no BLAS/LAPACK wrappers on tiny matrices, one specialisation per layout). Source shared by the
numba and pure-Python backends (executed after ``_events.py``)."""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # names injected by the loader
    _JIT  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._events import _JIT

@_JIT
def _solve(A, B):
    """Solve A X = B by Gaussian elimination with partial pivoting; A (k, k), B (k, r).

    Hand-written (instead of np.linalg) to keep numba compile times short; used for the modal
    size with non-classical damping only.
    """
    a = A.copy()
    piv = np.empty(a.shape[0], dtype=np.int64)
    _lu_into(a, piv)
    x = B.copy()
    col = np.empty(a.shape[0])
    for j in range(x.shape[1]):
        col[:] = x[:, j]
        _lu_solve(a, piv, col)
        x[:, j] = col
    return x


@_JIT
def _lu_into(a, piv):
    """LU factors of ``a`` in place, partial pivoting (row ``c`` swapped with ``piv[c]``);
    returns False when a pivot is exactly zero (singular)."""
    k = a.shape[0]
    for c in range(k):
        p = c
        big = abs(a[c, c])
        for i in range(c + 1, k):
            if abs(a[i, c]) > big:
                big = abs(a[i, c])
                p = i
        piv[c] = p
        if big == 0.0:
            return False
        if p != c:
            for j in range(k):
                tmp = a[c, j]
                a[c, j] = a[p, j]
                a[p, j] = tmp
        d = a[c, c]
        for i in range(c + 1, k):
            f = a[i, c] / d
            a[i, c] = f
            if f != 0.0:
                for j in range(c + 1, k):
                    a[i, j] -= f * a[c, j]
    return True


@_JIT
def _lu_solve(a, piv, x):
    """Solve with the factors of ``_lu_into``: ``x`` (k,) is overwritten by the solution."""
    k = a.shape[0]
    for c in range(k):
        p = piv[c]
        if p != c:
            tmp = x[c]
            x[c] = x[p]
            x[p] = tmp
    for i in range(k):
        acc = x[i]
        for j in range(i):
            acc -= a[i, j] * x[j]
        x[i] = acc
    for i in range(k - 1, -1, -1):
        acc = x[i]
        for j in range(i + 1, k):
            acc -= a[i, j] * x[j]
        x[i] = acc / a[i, i]


@_JIT
def _modal_solve(kd, cd, Cq, diag, av, rhs, out):
    """Solve (K + av C + av² I) x = rhs for x (mass is identity in modal coordinates): the
    effective stiffness of a step whose velocity is ``av`` Δq + known terms (2/h for the
    trapezoidal rule, ``_kernel_stage.py``)."""
    n = kd.shape[0]
    if diag:
        for i in range(n):
            out[i] = rhs[i] / (kd[i] + av * cd[i] + av * av)
    else:
        Kh = av * Cq.copy()
        for i in range(n):
            Kh[i, i] += kd[i] + av * av
        x = _solve(Kh, rhs.reshape((n, 1)))
        for i in range(n):
            out[i] = x[i, 0]


@_JIT
def _dh_into(kd, cd, Cq, diag, av, D, out):
    """out = D H, with H = (K + av C + av² I)^-1 (symmetric): (H Dᵀ)ᵀ, row-major like D."""
    n = kd.shape[0]
    if diag:
        hi = np.empty(n)
        for i in range(n):
            hi[i] = 1.0 / (kd[i] + av * cd[i] + av * av)
        for j in range(D.shape[0]):
            for i in range(n):
                out[j, i] = D[j, i] * hi[i]
        return
    Kh = av * Cq.copy()
    for i in range(n):
        Kh[i, i] += kd[i] + av * av
    out[:, :] = _solve(Kh, np.ascontiguousarray(D.T)).T


@_JIT
def _damp_mul(cd, Cq, diag, x, out):
    if diag:
        for i in range(x.shape[0]):
            out[i] = cd[i] * x[i]
    else:
        _mv(Cq, x, out)


#: entries of a matrix from which BLAS's gemv beats the explicit loops (measured with one
#: thread: 0.2 µs slower at 4 × 8, 4-6 times faster at 200 × 821)
_BLAS_MIN = 512


@_JIT
def _blas_ok(A, x, out, t):
    """Whether out = A @ x (``t``: Aᵀ @ x) goes to BLAS: large enough, contiguous, and the
    vectors of exactly the product's sizes (callers may pass longer scratch)."""
    r, c = (A.shape[1], A.shape[0]) if t else (A.shape[0], A.shape[1])
    return (r * c >= _BLAS_MIN and A.flags.c_contiguous and x.flags.c_contiguous
            and out.flags.c_contiguous and x.shape[0] == c and out.shape[0] == r)


@_JIT
def _mv(A, x, out):
    """out = A @ x: explicit loops for small A (faster than a BLAS call), BLAS from
    ``_BLAS_MIN`` entries."""
    if _blas_ok(A, x, out, False):
        np.dot(A, x, out)
        return
    for i in range(A.shape[0]):
        acc = 0.0
        for k in range(A.shape[1]):
            acc += A[i, k] * x[k]
        out[i] = acc


@_JIT
def _mtv(A, x, out):
    """out = Aᵀ @ x (as ``_mv``)."""
    if _blas_ok(A, x, out, True):
        np.dot(A.T, x, out)
        return
    for k in range(A.shape[1]):
        out[k] = 0.0
    for a in range(A.shape[0]):
        xa = x[a]
        if xa != 0.0:
            for k in range(A.shape[1]):
                out[k] += xa * A[a, k]
