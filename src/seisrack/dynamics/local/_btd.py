"""Block-tridiagonal algebra of the local engine (source shared by the numba and the
pure-Python backends; theory: ``docs/theory/local_engine.md`` §2–§3).

A symmetric block-tridiagonal matrix is held as ``Ad`` (n_s, bmax, bmax), its diagonal blocks,
and ``Ao`` (n_s − 1, bmax, bmax), the blocks (s, s + 1); block s is ``sizes[s]`` square,
zero-padded. Its Cholesky factor ``L`` is held as ``Ld`` (lower triangles of the diagonal
blocks) and ``X`` with ``X[s] = L_ss⁻¹ A_(s, s+1)`` (= ``L_(s+1, s)ᵀ``), so that
``S_(s+1) = A_(s+1, s+1) − X[s]ᵀ X[s]`` and ``L_(s+1, s+1) = chol(S_(s+1))``: the cost is
``Σ_s (7/3) b_s³``, linear in the number of slices.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)


try:  # names injected by the loader when executed after ``_blas.py``
    _potrf_corner  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics.local._blas import _potrf_corner, _syrk_corner, _trsm_corner

    def _JIT(f):  # type: ignore[no-redef]
        return f


@_JIT
def _trsv_lower(L, b, x):
    """x[:b] = L⁻¹ x[:b] (L lower triangular, rows contiguous)."""
    for i in range(b):
        acc = x[i]
        for k in range(i):
            acc -= L[i, k] * x[k]
        x[i] = acc / L[i, i]


@_JIT
def _trsv_upper(L, b, x):
    """x[:b] = L⁻ᵀ x[:b]."""
    for i in range(b - 1, -1, -1):
        xi = x[i] / L[i, i]
        x[i] = xi
        for k in range(i):
            x[k] -= L[i, k] * xi


@_JIT
def _btd_factor(Hd, Ho, sizes, Ld, X):
    """Cholesky factor of the block-tridiagonal (Hd, Ho) into (Ld, X) (LAPACK / BLAS on the
    blocks, ``_blas.py``). False if the matrix is not positive definite."""
    ns = sizes.shape[0]
    for s in range(ns):
        b = sizes[s]
        L = Ld[s]
        for i in range(b):
            for k in range(i + 1):
                L[i, k] = Hd[s, i, k]
        if s > 0:
            # S = H_ss − Xᵀ X (lower triangle)
            _syrk_corner(L, b, X[s - 1], sizes[s - 1])
        if not _potrf_corner(L, b):
            return False
        if s + 1 < ns:
            bn = sizes[s + 1]
            Xs = X[s]
            for i in range(b):
                for c in range(bn):
                    Xs[i, c] = Ho[s, i, c]
            # X_s = L⁻¹ H_(s, s+1)
            _trsm_corner(L, b, Xs, bn)
    return True


@_JIT
def _btd_condensed(Hd, Ho, sizes, X, Rb, Yb, Le):
    """Cholesky factors ``Le[s]`` of ``E_s = ((H⁻¹)_ss)⁻¹ = H_ss − X_(s−1)ᵀ X_(s−1) −
    Y_sᵀ Y_s``: slice s's block with both sides condensed, the left from the forward factor
    (``X`` of :func:`_btd_factor`), the right from a backward one (``Rb[s]`` = chol of the
    right-condensed ``T_s``, ``Yb[s] = Rb[s+1]⁻¹ H_(s+1, s)``). ``P (Le Leᵀ)⁻¹ Pᵀ`` is then
    the exact compliance of slice s's DOFs (theory §4.1). Cost about that of one factor
    (``E_s`` starts from the backward sweep's ``T_s = H_ss − Y_sᵀ Y_s``).
    False if a block is not positive definite."""
    ns = sizes.shape[0]
    for s in range(ns - 1, -1, -1):
        b = sizes[s]
        R = Rb[s]
        for i in range(b):
            for k in range(i + 1):
                R[i, k] = Hd[s, i, k]
        if s + 1 < ns:
            _syrk_corner(R, b, Yb[s], sizes[s + 1])
        # T_s = H_ss − Y_sᵀ Y_s kept for E_s below (one product fewer per slice)
        E = Le[s]
        for i in range(b):
            for k in range(i + 1):
                E[i, k] = R[i, k]
        if not _potrf_corner(R, b):
            return False
        if s > 0:
            bp = sizes[s - 1]
            Y = Yb[s - 1]
            for i in range(b):
                for c in range(bp):
                    Y[i, c] = Ho[s - 1, c, i]
            # Y_(s−1) = R_s⁻¹ H_(s, s−1)
            _trsm_corner(R, b, Y, bp)
    for s in range(ns):
        b = sizes[s]
        E = Le[s]
        if s > 0:
            _syrk_corner(E, b, X[s - 1], sizes[s - 1])
        if not _potrf_corner(E, b):
            return False
    return True


@_JIT
def _btd_solve(Ld, X, sizes, offsets, x):
    """x = (L Lᵀ)⁻¹ x in place (x (size,))."""
    ns = sizes.shape[0]
    for s in range(ns):
        b = sizes[s]
        o = offsets[s]
        xs = x[o:o + b]
        if s > 0:
            bp = sizes[s - 1]
            op = offsets[s - 1]
            Xp = X[s - 1]
            for r in range(bp):
                v = x[op + r]
                if v != 0.0:
                    for i in range(b):
                        xs[i] -= Xp[r, i] * v
        _trsv_lower(Ld[s], b, xs)
    for s in range(ns - 1, -1, -1):
        b = sizes[s]
        o = offsets[s]
        xs = x[o:o + b]
        if s + 1 < ns:
            bn = sizes[s + 1]
            on = offsets[s + 1]
            Xs = X[s]
            for i in range(b):
                acc = 0.0
                for c in range(bn):
                    acc += Xs[i, c] * x[on + c]
                xs[i] -= acc
        _trsv_upper(Ld[s], b, xs)


@_JIT
def _btd_matvec(Ad, Ao, sizes, offsets, x, out, alpha):
    """out += alpha A x for the symmetric block-tridiagonal A (diagonal blocks stored whole).
    Written as column sweeps (axpy) that the compiler vectorises, except the product of the
    row-major off-diagonal block with the next slice, a dot product on four accumulators."""
    ns = sizes.shape[0]
    for s in range(ns):
        b = sizes[s]
        o = offsets[s]
        D = Ad[s]
        ys = out[o:o + b]
        for k in range(b):
            xk = alpha * x[o + k]
            if xk != 0.0:
                for i in range(b):
                    ys[i] += D[k, i] * xk  # D symmetric: column k is row k
        if s + 1 < ns:
            bn = sizes[s + 1]
            on = offsets[s + 1]
            B = Ao[s]
            yn = out[on:on + bn]
            xn = x[on:on + bn]
            for i in range(b):
                xi = alpha * x[o + i]
                if xi != 0.0:
                    for c in range(bn):
                        yn[c] += B[i, c] * xi
            for i in range(b):
                a0 = 0.0
                a1 = 0.0
                a2 = 0.0
                a3 = 0.0
                c = 0
                while c + 4 <= bn:
                    a0 += B[i, c] * xn[c]
                    a1 += B[i, c + 1] * xn[c + 1]
                    a2 += B[i, c + 2] * xn[c + 2]
                    a3 += B[i, c + 3] * xn[c + 3]
                    c += 4
                while c < bn:
                    a0 += B[i, c] * xn[c]
                    c += 1
                ys[i] += alpha * ((a0 + a1) + (a2 + a3))


@_JIT
def _btd_combine(Md, Cd, Kd, Mo, Co, Ko, sizes, cm, cc, ck, Hd, Ho):
    """H = cm M + cc C + ck K (block by block)."""
    ns = sizes.shape[0]
    for s in range(ns):
        b = sizes[s]
        for i in range(b):
            for k in range(b):
                Hd[s, i, k] = cm * Md[s, i, k] + cc * Cd[s, i, k] + ck * Kd[s, i, k]
        if s + 1 < ns:
            bn = sizes[s + 1]
            for i in range(b):
                for k in range(bn):
                    Ho[s, i, k] = cm * Mo[s, i, k] + cc * Co[s, i, k] + ck * Ko[s, i, k]
