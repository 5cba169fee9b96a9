"""A local basis: vectors supported on one slice of the structure each, so that the reduced
matrices are block tridiagonal (theory: ``docs/theory/local_engine.md`` §2).

:func:`local_basis` builds, slice by slice, the restrictions to the slice of the static
responses that can occur there — the responses on a patch of slices to the loads in the
patch, the global responses to a few global loads and their harmonic extensions into the
patch — compressed in the slice's energy norm. Its cost grows with the number of slices, not
with its square. The basis reports its size and its error measured against the full model
(:func:`measure_error`).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from seisrack.errors import InputError, SolverError
from seisrack.fe.stability import symmetric_lu

_LOG = logging.getLogger(__name__)

#: relative energy below which a direction of a slice is dropped (of a unit-energy load
#: response). 20 s of two EC8 components against the planar engine with its basis tightened
#: to 0.015 at dt 2.5 ms (benchmarks/results/local_vs_planar_10.md, _20.md): at 0.03 every
#: pallet's peak sliding is within 0.5 % of the largest peak or 1 mm, the level peaks within
#: 0.09 % (150 pallets, 912 vectors) and 0.07 % (300 pallets, 1754 vectors), the same falls
#: within one step, for 13 % and 17 % more run time than at 0.1; at 0.1 (782 and 1485
#: vectors) the 300-pallet row had 13 pallets beyond, level peaks 0.39 % off and two falls
#: more (docs/theory/local_engine.md §6)
DEFAULT_TOL = 0.03
#: slices on each side of a slice in its patch
DEFAULT_PATCH = 1


@dataclass(frozen=True)
class LocalBasis:
    """Block-diagonal basis ``u = V q``: slice ``s`` holds the coordinates
    ``q[offsets[s]:offsets[s+1]]`` and its vectors ``blocks[s]`` (``len(dofs[s])`` × ``sizes[s]``)
    are non-zero on the DOFs ``dofs[s]`` only.

    Reduced matrices (block tridiagonal, zero-padded to ``bmax``): ``Md, Cd, Kd`` (n_s, bmax,
    bmax) diagonal blocks, ``Mo, Co, Ko`` (n_s − 1, bmax, bmax) the blocks (s, s + 1).
    ``error``: the measured errors against the full model (:func:`measure_error`).
    """

    dofs: tuple[np.ndarray, ...]
    blocks: tuple[np.ndarray, ...]
    sizes: np.ndarray
    offsets: np.ndarray
    Md: np.ndarray
    Cd: np.ndarray
    Kd: np.ndarray
    Mo: np.ndarray
    Co: np.ndarray
    Ko: np.ndarray
    n_dof: int
    tol: float
    error: dict = field(default_factory=dict)

    @property
    def n_slices(self) -> int:
        return len(self.blocks)

    @property
    def size(self) -> int:
        return int(self.offsets[-1])

    @property
    def bmax(self) -> int:
        return int(self.Md.shape[1])

    @cached_property
    def phi(self) -> sp.csr_matrix:
        """V as a sparse (n, size) CSR matrix, made once per basis (the default engine's
        :class:`~seisrack.dynamics.basis.Basis` has the same attribute, dense)."""
        return self.matrix().tocsr()

    def matrix(self) -> sp.csc_matrix:
        """V as a sparse (n, size) matrix."""
        rows = np.concatenate([np.repeat(d, b.shape[1]) for d, b in zip(self.dofs, self.blocks,
                                                                          strict=True)])
        cols = np.concatenate([np.tile(np.arange(o, o + b.shape[1]), b.shape[0])
                               for o, b in zip(self.offsets[:-1], self.blocks, strict=True)])
        vals = np.concatenate([b.ravel() for b in self.blocks])
        return sp.csc_matrix((vals, (rows, cols)), shape=(self.n_dof, self.size))

    def rows(self, dofs: np.ndarray) -> np.ndarray:
        """(len(dofs), size) dense rows of V (DOF -1: a zero row)."""
        dofs = np.asarray(dofs)
        out = np.zeros((dofs.size, self.size))
        where = self._where()
        for i, d in enumerate(dofs):
            if d < 0:
                continue
            s, j = where[d]
            out[i, self.offsets[s]:self.offsets[s + 1]] = self.blocks[s][j]
        return out

    def _where(self) -> dict[int, tuple[int, int]]:
        out = {}
        for s, d in enumerate(self.dofs):
            for j, k in enumerate(d):
                out[int(k)] = (s, j)
        return out

    def describe(self) -> dict:
        return {"kind": "local", "size": self.size, "slices": self.n_slices,
                "block_sizes": [int(b) for b in self.sizes], "largest_block": self.bmax,
                "tol": self.tol, "error": dict(self.error)}


def check_slices(K: sp.spmatrix, slices: np.ndarray) -> np.ndarray:
    """Slice indices 0..n_s-1, every slice non-empty, elements within adjacent slices."""
    n = K.shape[0]
    sl = np.asarray(slices)
    if sl.shape != (n,) or (sl.size and not np.issubdtype(sl.dtype, np.integer)):
        raise InputError("slices", f"array of shape {sl.shape}", f"({n},) integer slice indices")
    if sl.size and (sl.min() != 0 or np.any(np.bincount(sl) == 0)):
        raise InputError("slices", "indices with gaps",
                         "slice indices 0, 1, ..., n_s - 1, every slice holding DOFs")
    coo = sp.coo_matrix(K)
    far = np.abs(sl[coo.row] - sl[coo.col]) > 1
    if np.any(far & (coo.data != 0)):
        i = int(np.argmax(far & (coo.data != 0)))
        raise InputError("slices", f"DOFs {coo.row[i]} (slice {sl[coo.row[i]]}) and "
                         f"{coo.col[i]} (slice {sl[coo.col[i]]}) coupled",
                         "slices such that the stiffness couples only adjacent slices")
    return sl.astype(np.int64)


def local_basis(M, C, K, slices: np.ndarray, loads: np.ndarray, patterns: sp.spmatrix,  # noqa: ANN001, N803
                *, global_loads: np.ndarray | None = None, mass_extra: sp.spmatrix | None = None,
                tol: float = DEFAULT_TOL, patch: int = DEFAULT_PATCH, blocks: int = 1
                ) -> LocalBasis:
    """Build the local basis (theory §2).

    M, C, K: (n, n) sparse or dense; slices: (n,) slice of each DOF; loads: (n, k) the
    structure's load patterns (ground loads, per unit of their series); patterns: (n, n_p)
    sparse local load patterns (each pallet's friction force per direction); global_loads:
    (n, g) loads whose global static responses carry the far field into each patch (default:
    ``loads``); mass_extra: the pallets' horizontal masses (attached) for the Krylov blocks.
    tol: relative energy below which a direction is dropped; patch: slices on each side;
    blocks: 1 (static responses) or 2 (plus their fixed-boundary inertia responses).
    """
    if not (np.isfinite(tol) and 0.0 < tol < 1.0):
        raise InputError("basis.tol", tol, "a relative tolerance in (0, 1), e.g. 0.2")
    if isinstance(patch, bool) or not isinstance(patch, int) or patch < 0:
        raise InputError("basis.patch", patch, "an integer >= 0 (slices on each side)")
    if blocks not in (1, 2):
        raise InputError("basis.blocks", blocks, "1 or 2")
    Ks = sp.csr_matrix(K, dtype=float)
    Ms = sp.csr_matrix(M, dtype=float)
    Cs = sp.csr_matrix(C, dtype=float)
    n = Ks.shape[0]
    sl = check_slices(Ks, slices)
    ns = int(sl.max()) + 1 if n else 0
    M0 = Ms if mass_extra is None else (Ms + sp.csr_matrix(mass_extra)).tocsr()
    loads = np.asarray(loads, dtype=float).reshape(n, -1)
    pat = sp.csc_matrix(patterns, dtype=float)
    G = loads if global_loads is None else np.column_stack([loads, global_loads])
    try:
        lu = symmetric_lu(Ks)
    except RuntimeError as exc:
        raise InputError("K", "singular", "a stable structure (positive-definite stiffness)") \
            from exc
    UG = lu.solve(np.asfortranarray(G))
    eG = np.einsum("ij,ij->j", G, UG)
    okG = eG > 1e-300 * max(float(eG.max(initial=0.0)), 1e-300)
    UG = UG[:, okG] / np.sqrt(eG[okG])
    members = [np.flatnonzero(sl == s) for s in range(ns)]
    pat_rows = pat.tocsr()
    Vs = []
    for s in range(ns):
        lo, hi = max(0, s - patch), min(ns - 1, s + patch)
        P = np.concatenate(members[lo:hi + 1])
        Vs.append(_slice_vectors(Ks, M0, P, sl, s, lo, hi, loads, pat_rows, UG, tol, blocks))
    return _assemble(Ms, Cs, Ks, members, Vs, n, tol)


def _slice_vectors(Ks, M0, P, sl, s, lo, hi, loads, pat_rows, UG, tol, blocks):  # noqa: ANN001, ANN202, N803
    """Compressed restrictions to slice ``s`` of the patch ``P``'s candidate responses."""
    inP = np.zeros(Ks.shape[0], dtype=bool)
    inP[P] = True
    rowsP = Ks[P]
    KP = rowsP[:, P].tocsc()
    try:
        lu = symmetric_lu(KP)
    except RuntimeError as exc:
        raise SolverError(f"local basis: the patch of slice {s} is singular ({exc})") from exc
    pP = pat_rows[P]
    used = np.flatnonzero(np.diff(pP.tocsc().indptr) > 0)
    F = np.column_stack([loads[P], pP[:, used].toarray()]) if used.size else loads[P]
    cols = []
    if F.shape[1]:
        X = lu.solve(np.asfortranarray(F))
        e = np.einsum("ij,ij->j", F, X)
        ok = e > 1e-300 * max(float(e.max(initial=0.0)), 1e-300)
        cols.append(X[:, ok] / np.sqrt(e[ok]))
    if UG.shape[1]:
        cols.append(UG[P])
        out = np.flatnonzero(~inP)
        KPB = rowsP[:, out]
        for side in (sl[out] < lo, sl[out] > hi):
            if np.any(side) and KPB[:, side].nnz:
                cols.append(lu.solve(np.asfortranarray(-(KPB[:, side] @ UG[out[side]]))))
    X = np.column_stack(cols) if cols else np.zeros((P.size, 0))
    S = np.flatnonzero(sl[P] == s)
    NS = KP[S][:, S].toarray()
    V = np.zeros((S.size, 0))
    blk = X
    for b in range(blocks):
        Y = blk[S]
        if V.shape[1]:
            Y = Y - V @ (V.T @ (NS @ Y))
        Gm = Y.T @ (NS @ Y)
        lam, Q = np.linalg.eigh(0.5 * (Gm + Gm.T))
        keep = lam > max(tol**2, 1e-12 * float(lam.max(initial=0.0)))
        W = (Y @ Q[:, keep]) / np.sqrt(lam[keep])
        if V.shape[1] and W.shape[1]:  # once more against V, for round-off
            W = W - V @ (V.T @ (NS @ W))
            W = W / np.sqrt(np.einsum("ij,ij->j", W, NS @ W))
        V = np.column_stack([V, W])
        if b + 1 < blocks:
            M0P = M0[P][:, P]
            nxt = lu.solve(np.asfortranarray(M0P @ blk))
            en = np.sqrt(np.maximum(np.einsum("ij,ij->j", M0P @ blk, nxt), 1e-300))
            ek = np.sqrt(np.maximum(np.einsum("ij,ij->j", blk, KP @ blk), 1e-300))
            blk = nxt * (ek / en)
    if V.shape[1] == 0:
        _LOG.info("local basis: no load acts on slice %d; it keeps no vector", s)
    return V


def _assemble(Ms, Cs, Ks, members, Vs, n, tol) -> LocalBasis:  # noqa: ANN001, N803
    ns = len(Vs)
    sizes = np.array([v.shape[1] for v in Vs], dtype=np.int64)
    offsets = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    bmax = int(sizes.max()) if ns else 0
    out = {k: np.zeros((ns, bmax, bmax)) for k in ("Md", "Cd", "Kd")}
    out.update({k: np.zeros((max(ns - 1, 0), bmax, bmax)) for k in ("Mo", "Co", "Ko")})
    for s in range(ns):
        Vi, di, bi = Vs[s], members[s], sizes[s]
        for name, A in (("M", Ms), ("C", Cs), ("K", Ks)):
            rows = A[di]
            d = Vi.T @ (rows[:, di] @ Vi)
            out[name + "d"][s, :bi, :bi] = 0.5 * (d + d.T)
            if s + 1 < ns:
                dj, bj = members[s + 1], sizes[s + 1]
                out[name + "o"][s, :bi, :bj] = Vi.T @ (rows[:, dj] @ Vs[s + 1])
    return LocalBasis(dofs=tuple(members), blocks=tuple(Vs), sizes=sizes, offsets=offsets,
                      n_dof=n, tol=float(tol), **out)


def dense(b: LocalBasis, which: str) -> np.ndarray:
    """The reduced matrix ``which`` ("M", "C", "K") as a dense (size, size) array (tests,
    small structures)."""
    d, o = getattr(b, which + "d"), getattr(b, which + "o")
    N = b.size
    A = np.zeros((N, N))
    for s in range(b.n_slices):
        i0, i1 = b.offsets[s], b.offsets[s + 1]
        A[i0:i1, i0:i1] = d[s, :b.sizes[s], :b.sizes[s]]
        if s + 1 < b.n_slices:
            j1 = b.offsets[s + 2]
            A[i0:i1, i1:j1] = o[s, :b.sizes[s], :b.sizes[s + 1]]
            A[i1:j1, i0:i1] = o[s, :b.sizes[s], :b.sizes[s + 1]].T
    return A


def measure_error(b: LocalBasis, M, K, loads: np.ndarray, patterns: sp.spmatrix,  # noqa: ANN001, N803
                  *, mass_extra: sp.spmatrix | None = None, n_modes: int = 0,
                  samples: int = 6, seed: int = 0) -> dict:
    """Errors of the basis against the full model.

    static: relative energy error ``‖u − u_r‖_K / ‖u‖_K`` of the static responses to each
    column of ``loads`` and to ``samples`` sampled pallet patterns (random combinations of all
    of them and single ones at the ends and the middle); frequency: relative error of the
    lowest ``n_modes`` frequencies of (K, M + mass_extra) (shift-invert Lanczos on the full
    pencil; 0 skips it). Cost O(n) for a long and thin structure (one sparse LU of K).
    """
    Ks = sp.csc_matrix(K, dtype=float)
    n = Ks.shape[0]
    V = b.matrix()
    Kr = dense(b, "K") if b.size <= 3000 else None
    pat = sp.csc_matrix(patterns)
    rng = np.random.default_rng(seed)
    cols = [np.asarray(loads, float).reshape(n, -1)]
    npat = pat.shape[1]
    if npat and samples:
        k = max(samples // 2, 1)
        cols.append(pat @ rng.standard_normal((npat, k)))
        pick = np.unique(np.linspace(0, npat - 1, samples - k).astype(int))
        cols.append(pat[:, pick].toarray())
    F = np.column_stack(cols)
    lu = symmetric_lu(Ks)
    U = lu.solve(np.asfortranarray(F))
    rhs = V.T @ F
    y = np.linalg.solve(Kr, rhs) if Kr is not None else _btd_solve(b, "K", rhs)
    E = U - V @ y
    eu = np.einsum("ij,ij->j", U, Ks @ U)
    err = np.sqrt(np.maximum(np.einsum("ij,ij->j", E, Ks @ E), 0.0) / np.maximum(eu, 1e-300))
    out = {"static_energy_max": float(err.max(initial=0.0)),
           "static_energy_ground": [float(x) for x in err[:cols[0].shape[1]]],
           "static_energy_pallets_max": float(err[cols[0].shape[1]:].max(initial=0.0))}
    if n_modes:
        M0 = sp.csc_matrix(M, dtype=float)
        if mass_extra is not None:
            M0 = (M0 + sp.csc_matrix(mass_extra)).tocsc()
        k_inv = spla.LinearOperator(Ks.shape, matvec=lu.solve, dtype=float)
        w2, _ = spla.eigsh(Ks, k=n_modes, M=M0, sigma=0.0, which="LM", OPinv=k_inv)
        Mr = V.T @ (M0 @ V)
        Mr = Mr.toarray() if sp.issparse(Mr) else Mr
        Kd = Kr if Kr is not None else dense(b, "K")
        w2r = scipy.linalg.eigh(Kd, 0.5 * (Mr + Mr.T), eigvals_only=True,
                                subset_by_index=[0, n_modes - 1])
        f = np.sqrt(np.sort(np.abs(w2))) / (2 * np.pi)
        fr = np.sqrt(np.abs(w2r)) / (2 * np.pi)
        out["frequencies_hz"] = [float(x) for x in f]
        out["frequency_error_max"] = float(np.max(np.abs(fr / f - 1.0)))
    return out


def _btd_solve(b: LocalBasis, which: str, rhs: np.ndarray) -> np.ndarray:
    """Solve the block-tridiagonal reduced ``which`` matrix against rhs (size, k) by a dense
    block Cholesky (numpy; setup and checks only)."""
    d, o = getattr(b, which + "d"), getattr(b, which + "o")
    ns = b.n_slices
    L, Lo = [], []
    for s in range(ns):
        bs = b.sizes[s]
        A = d[s, :bs, :bs].copy()
        if s:
            A -= Lo[s - 1] @ Lo[s - 1].T
        Ls = np.linalg.cholesky(A)
        L.append(Ls)
        if s + 1 < ns:
            Lo.append(scipy.linalg.solve_triangular(Ls, o[s, :bs, :b.sizes[s + 1]],
                                                    lower=True).T)
    x = np.array(rhs, dtype=float, copy=True)
    off = b.offsets
    for s in range(ns):
        xs = x[off[s]:off[s + 1]]
        if s:
            xs -= Lo[s - 1] @ x[off[s - 1]:off[s]]
        x[off[s]:off[s + 1]] = scipy.linalg.solve_triangular(L[s], xs, lower=True)
    for s in range(ns - 1, -1, -1):
        xs = x[off[s]:off[s + 1]]
        if s + 1 < ns:
            xs -= Lo[s].T @ x[off[s + 1]:off[s + 2]]
        x[off[s]:off[s + 1]] = scipy.linalg.solve_triangular(L[s], xs, lower=True, trans=1)
    return x
