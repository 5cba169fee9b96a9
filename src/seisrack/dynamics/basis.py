"""Bases of the structure in which the stick–slip engine integrates (theory: §10 of
``docs/theory/stick_slip_engine.md``).

The engine works in coordinates ``u = Φ q`` with ``Φᵀ M Φ = I`` and ``Φᵀ K Φ = diag(ω²)``,
where ``M`` is the structure's own mass (the sliders' horizontal masses are the sliders).

- :func:`full_basis`: every mode of ``(K, M)`` (dense ``eigh``); nothing is truncated.
- :func:`reduced_basis`: a load-dependent Ritz basis of ``r ≪ n`` vectors (Wilson, Yuan &
  Dickens, *Earthquake Eng. Struct. Dyn.* 10, 1982; Craig & Kurdila, *Fundamentals of
  Structural Dynamics*, 2nd ed., §14.6): Krylov blocks ``(K⁻¹ M₀)ᵏ K⁻¹ F`` of the loads that
  actually act — the ground load and the sliders' friction forces — with the sliders rigidly
  attached in ``M₀ = M + Σ m_j e_j e_jᵀ``. The first block is the static response, so the
  quasi-static part of every truncated mode is kept; only inertia of modes outside the Krylov
  space is lost. The truncation is a reported, measured choice (``benchmarks/scale.py``).

Both accept dense arrays or scipy sparse matrices; the reduced basis never forms a dense
``n x n`` matrix (shift-invert Lanczos on a sparse LU of K).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sp

from seisrack.errors import InputError, SolverError
from seisrack.fe.stability import symmetric_lu

_LOG = logging.getLogger(__name__)

#: Krylov blocks of the load-dependent Ritz basis
DEFAULT_BLOCKS = 8
#: relative M₀-norm below which a Ritz direction is dropped
DEFAULT_TOL = 3e-2
#: relative norm below which a Krylov direction counts as linearly dependent
_DEPENDENT = 1e-7
#: up to this many DOFs the Ritz vectors are built with dense algebra (Cholesky of K)
_DENSE_MAX_DOF = 300
#: Krylov blocks after the first are added only while the basis stays within this size (small
#: structures get more blocks for free; large ones keep the cost per contact event low)
DEFAULT_TARGET_SIZE = 40
#: largest reduced basis
DEFAULT_MAX_SIZE = 200
#: columns of the static responses solved and multiplied at a time (bounds the temporaries:
#: a rack row's 2,000 friction patterns on 20,000 DOFs would otherwise copy 320 MB each time)
_CHUNK = 256


@dataclass(frozen=True)
class Basis:
    """Mass-orthonormal basis of the structure: ``phi.T @ M @ phi = I``, ``phi.T @ K @ phi =
    diag(w2)``.

    phi: (n, r); w2: (r,) [rad²/s²] ascending. kind: "full" or "reduced".
    n_modes: basis size (modes of the structure, or Ritz vectors); n_static: Krylov blocks of a
    reduced basis; highest_mode_hz: highest frequency of the basis [Hz]. static_error: the
    largest static energy error of the load patterns the basis was built from (0: every static
    response is in the basis; a full basis has none); capped: directions of the loads' static
    responses above the compression tolerance that the size cap dropped (0: none).
    """

    phi: np.ndarray
    w2: np.ndarray
    kind: str
    n_modes: int
    n_static: int = 0
    highest_mode_hz: float | None = None
    static_error: float = 0.0
    capped: int = 0

    @property
    def size(self) -> int:
        return int(self.w2.shape[0])

    def describe(self) -> dict:
        return {
            "kind": self.kind,
            "size": self.size,
            "modes": self.n_modes,
            "ritz_blocks": self.n_static,
            "highest_mode_hz": self.highest_mode_hz,
            "static_energy_error": self.static_error,
            "capped_directions": self.capped,
        }


def full_basis(M, K) -> Basis:  # noqa: ANN001, N803
    """Every mode of ``(K, M)`` by a dense generalised ``eigh`` (no truncation)."""
    Md = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    Kd = K.toarray() if sp.issparse(K) else np.asarray(K, dtype=float)
    try:
        w2, phi = scipy.linalg.eigh(Kd, Md)
    except np.linalg.LinAlgError as exc:
        raise InputError(
            "M", "not positive definite", "a symmetric positive-definite mass matrix",
            hint="Every DOF needs mass (use a consistent mass matrix for rotations)",
        ) from exc
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    if np.min(w2) < -1e-9 * scale:
        raise InputError(
            "K", f"negative eigenvalue {np.min(w2):.3g}", "a positive semi-definite stiffness"
        )
    return Basis(phi=phi, w2=np.clip(w2, 0.0, None), kind="full", n_modes=int(w2.size))


def reduced_basis(
    M, K, slider_dof: np.ndarray, slider_mass: np.ndarray, loads: np.ndarray,  # noqa: ANN001, N803
    *, tol: float = DEFAULT_TOL, blocks: int = DEFAULT_BLOCKS,
    target_size: int = DEFAULT_TARGET_SIZE, max_size: int = DEFAULT_MAX_SIZE,
    unit_loads: bool = True,
) -> Basis:
    """Load-dependent Ritz basis (Wilson, Yuan & Dickens 1982; block form).

    The first block is the static response ``K⁻¹ F`` to the load patterns that act on the
    structure: ``loads`` (e.g. the ground load ``M₀ r``) and a unit horizontal force at every
    slider's DOF (the friction forces). Each next block is ``K⁻¹ M₀`` times the previous one.
    Every block is made ``M₀``-orthonormal against the basis so far and compressed: with every
    pattern scaled to unit ``M₀``-norm, directions below ``tol`` are dropped, so sliders on one
    beam, whose static responses differ only by the beam's axial strain, share directions.
    The first block is always kept (at most ``max_size`` vectors); up to ``blocks - 1`` more
    are added while the basis stays within ``target_size`` vectors. A final Rayleigh–Ritz step on
    ``(K, M)`` makes the basis M-orthonormal and K-diagonal.

    M, K: (n, n) dense or sparse; slider_dof, slider_mass: (m,) (dof -1: on the ground);
    loads: (n, k) load patterns [N per unit of their time series], dense or sparse. unit_loads:
    False when the caller's ``loads`` already hold the sliders' force patterns (a pallet resting
    on several nodes pushes them together), so no unit force per slider DOF is added.

    Memory: the static responses (n, k) are the one dense array of the load count; the load
    patterns stay sparse and every product with them goes by chunks of ``_CHUNK`` columns.
    """
    n = K.shape[0]
    if not (np.isfinite(tol) and 0 < tol < 1):
        raise InputError("basis.tol", tol, "a relative tolerance in (0, 1), e.g. 1e-4")
    if isinstance(blocks, bool) or not isinstance(blocks, int) or blocks < 1:
        raise InputError("basis.blocks", blocks, "an integer >= 1")
    Ks = sp.csc_matrix(K)
    Ms = sp.csc_matrix(M)
    dof = np.asarray(slider_dof)
    on = dof >= 0
    add = sp.csc_matrix((np.asarray(slider_mass, float)[on], (dof[on], dof[on])), shape=(n, n))
    M0 = (Ms + add).tocsc()
    try:
        if n <= _DENSE_MAX_DOF:
            # small structures: dense Cholesky and products (scipy.sparse's per-call overhead
            # was most of the basis time on the paper rack)
            Ks, Ms, M0 = Ks.toarray(), Ms.toarray(), M0.toarray()
            cho = scipy.linalg.cho_factor(Ks)
            solve = lambda B: scipy.linalg.cho_solve(cho, B)  # noqa: E731
        else:
            solve = symmetric_lu(Ks).solve
    except (RuntimeError, np.linalg.LinAlgError) as exc:
        raise InputError(
            "K", "singular", "a stable structure (positive-definite stiffness)"
        ) from exc
    loads = (sp.csc_matrix(loads, dtype=float) if sp.issparse(loads)
             else sp.csc_matrix(np.asarray(loads, dtype=float).reshape(n, -1)))
    udofs = np.unique(dof[on]) if unit_loads else np.zeros(0, dtype=np.int64)
    unit = sp.csc_matrix((np.ones(udofs.size), (udofs, np.arange(udofs.size))),
                         shape=(n, udofs.size))
    F = sp.hstack([loads, unit], format="csc")
    static = np.empty(F.shape, order="F")  # K⁻¹ F: the static responses
    for c in range(0, F.shape[1], _CHUNK):
        static[:, c:c + _CHUNK] = solve(np.asfortranarray(F[:, c:c + _CHUNK].toarray()))
    block = static
    V = np.zeros((n, 0))
    n_blocks, capped = 0, 0
    while n_blocks < blocks and V.shape[1] < max_size:
        # the first block is compressed at ``tol``; later ones drop only dependent directions
        cut = tol if n_blocks == 0 else _DEPENDENT
        block, over = _orthonormal_block(block, V, M0, cut, max_size - V.shape[1])
        if n_blocks == 0:
            capped = over
        if block.shape[1] == 0:
            break
        if n_blocks and V.shape[1] + block.shape[1] > max(target_size, 1):
            break
        V = np.column_stack([V, block])
        n_blocks += 1
        block = solve(np.asfortranarray(M0 @ block))
    Kr = V.T @ (Ks @ V)
    Mr = V.T @ (Ms @ V)
    try:
        w2, W = scipy.linalg.eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    except np.linalg.LinAlgError as exc:
        raise SolverError(f"reduced basis: Rayleigh-Ritz failed ({exc})") from exc
    w2 = np.clip(w2, 0.0, None)
    phi = np.ascontiguousarray(V @ W)
    err = static_energy_error(phi, w2, F, static)
    if capped:
        _LOG.warning("reduced basis: the size cap of %d vectors dropped %d directions of the "
                     "loads' static responses (largest static energy error %.3g)", max_size,
                     capped, err)
    return Basis(
        phi=phi, w2=w2, kind="reduced", n_modes=int(w2.size), n_static=n_blocks,
        highest_mode_hz=float(np.sqrt(w2[-1]) / (2 * np.pi)) if w2.size else None,
        static_error=err, capped=int(capped),
    )


def static_energy_error(phi: np.ndarray, w2: np.ndarray, F: np.ndarray,
                        static: np.ndarray) -> float:
    """Largest relative energy error of the static responses ``static = K⁻¹ F`` (n, k) of the
    loads ``F`` (n, k) in the basis (``phi`` M-orthonormal, ``phiᵀ K phi = diag(w2)``).

    The K-orthogonal projection of x = K⁻¹ f onto the basis has the strain energy
    Σᵢ (φᵢᵀ f)² / ωᵢ², and x itself fᵀ K⁻¹ f, so the error is
    1 − Σᵢ (φᵢᵀ f)² / ωᵢ² / (fᵀ x) (0 when x is in the basis); rigid-body directions
    (ωᵢ = 0) carry no strain energy and are left out.
    """
    if sp.issparse(F):
        F = sp.csc_matrix(F)
        full = np.asarray(F.multiply(static).sum(axis=0)).ravel()
    else:
        full = np.einsum("ij,ij->j", F, static)
    on = full > 1e-300
    if not np.any(on):
        return 0.0
    stiff = w2 > 1e-12 * max(float(np.max(w2, initial=0.0)), 1e-300)
    proj = (F[:, on].T @ phi[:, stiff]).T
    kept = np.einsum("ij,ij->j", proj, proj / w2[stiff, None])
    return float(np.clip(1.0 - kept / full[on], 0.0, 1.0).max())


def _gram(X, M0):  # noqa: ANN001, ANN202, N803
    """Xᵀ M₀ X, one chunk of columns at a time."""
    G = np.empty((X.shape[1], X.shape[1]))
    for c in range(0, X.shape[1], _CHUNK):
        G[:, c:c + _CHUNK] = X.T @ (M0 @ X[:, c:c + _CHUNK])
    return G


def _orthonormal_block(X, V, M0, tol, limit):  # noqa: ANN001, ANN202, N803
    """M₀-orthonormalise the columns of X against V and among themselves, dropping the
    directions below ``tol`` (relative); at most ``limit`` columns. Returns the block and the
    number of directions above ``tol`` that ``limit`` dropped. X is not modified; against an
    empty V (the first block, the static responses) no copy of it is made."""
    # each load pattern counts alike whatever its units: the columns are scaled to unit M₀-norm
    # before the projection against V (so that ``tol`` is relative to the pattern itself)
    if V.shape[1]:  # a later block: at most the basis size, copies are cheap
        norms = np.sqrt(np.einsum("ij,ij->j", X, M0 @ X))
        X = X[:, norms > 0] / norms[norms > 0]
        for _ in range(2):  # twice is enough (Kahan–Parlett)
            X = X - V @ (V.T @ (M0 @ X))
        s = np.ones(X.shape[1])
        G = _gram(X, M0)
    else:  # the static responses: scaled through their Gram matrix, never copied (a zero
        # column stays zero, and its zero eigenvalue is dropped below)
        G = _gram(X, M0)
        d = np.clip(np.diag(G), 0.0, None)
        s = np.zeros_like(d)
        s[d > 0] = 1.0 / np.sqrt(d[d > 0])
        G = s[:, None] * G * s[None, :]
    lam, Q = np.linalg.eigh(0.5 * (G + G.T))
    keep = lam > tol ** 2
    over = max(int(np.count_nonzero(keep)) - limit, 0)
    lam, Q = lam[keep][::-1][:limit], Q[:, keep][:, ::-1][:, :limit]
    Y = (X @ (s[:, None] * Q)) / np.sqrt(lam)
    if V.shape[1] and Y.shape[1]:  # one more pass against V for round-off
        Y = Y - V @ (V.T @ (M0 @ Y))
        Y = Y / np.sqrt(np.einsum("ij,ij->j", Y, M0 @ Y))
    return Y, over
