"""The reduced basis reports its measured static error and any directions its size cap dropped
(issue 22: "no silent truncation").

Reference for the error: the strain energy of the K-orthogonal projection of each static
response x = K⁻¹ f onto the basis, computed independently here by a least-squares solve in the
K inner product on dense matrices (numpy.linalg.lstsq of the Cholesky-weighted system), against
the energy fᵀ K⁻¹ f of x itself (Clough & Penzien, *Dynamics of Structures*, 2nd ed., §13-4:
the Ritz approximation is the K-orthogonal projection; error in the energy norm). A basis
holding every static response has no error (to round-off); a basis that drops directions has
the error of what it drops.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.linalg

from seisrack.checks.plausibility import basis_cap
from seisrack.dynamics.basis import reduced_basis, static_energy_error


def _chain(n: int, k: float = 1e6, m: float = 50.0) -> tuple[np.ndarray, np.ndarray]:
    """A fixed–free spring chain (tridiagonal K) with lumped masses."""
    K = np.zeros((n, n))
    for i in range(n):
        K[i, i] += k
        if i + 1 < n:
            K[i, i] += k
            K[i, i + 1] = K[i + 1, i] = -k
    return np.diag(np.full(n, m)), K


def _energy_error_by_projection(phi: np.ndarray, K: np.ndarray, f: np.ndarray) -> float:
    """1 − ‖P x‖²_K / ‖x‖²_K with P the K-orthogonal projection onto span(phi)."""
    x = np.linalg.solve(K, f)
    L = scipy.linalg.cholesky(K, lower=False)  # K = Lᵀ L: the K-norm is the 2-norm of L·
    c, *_ = np.linalg.lstsq(L @ phi, L @ x, rcond=None)
    px = phi @ c
    return 1.0 - float(px @ K @ px) / float(x @ K @ x)


def test_static_energy_error_matches_the_k_projection():
    rng = np.random.default_rng(3)
    M, K = _chain(30)
    F = rng.standard_normal((30, 4))
    full_w2, full_phi = scipy.linalg.eigh(K, M)
    for keep in (3, 8, 15, 30):  # the lowest modes: the error falls to zero with all of them
        phi, w2 = full_phi[:, :keep], full_w2[:keep]
        ours = static_energy_error(phi, w2, F, np.linalg.solve(K, F))
        ref = max(_energy_error_by_projection(phi, K, F[:, j]) for j in range(4))
        assert abs(ours - ref) <= 1e-10 + 1e-8 * ref, (keep, ours, ref)
    assert static_energy_error(full_phi, full_w2, F, np.linalg.solve(K, F)) < 1e-10


def test_ritz_basis_reports_zero_error_when_it_holds_every_static_response():
    M, K = _chain(40)
    dof = np.array([9, 19, 29, 39])
    # no compression (tol 1e-9): the first block holds the five static responses
    b = reduced_basis(M, K, dof, np.full(4, 400.0), (M @ np.ones(40))[:, None], tol=1e-9)
    assert b.capped == 0 and b.static_error < 1e-10
    # compressed at the default tolerance, directions go, and the error says how much
    c = reduced_basis(M, K, dof, np.full(4, 400.0), (M @ np.ones(40))[:, None], blocks=1)
    assert c.capped == 0 and 0.0 <= c.static_error < 0.05
    d = b.describe()
    assert d["capped_directions"] == 0 and d["static_energy_error"] == b.static_error


def test_a_capped_basis_says_what_it_dropped(caplog):
    M, K = _chain(60)
    dof = np.arange(2, 60, 3)  # 20 sliders: 21 independent static responses with the ground load
    loads = (M @ np.ones(60))[:, None]
    with caplog.at_level(logging.WARNING, logger="seisrack.dynamics.basis"):
        small = reduced_basis(M, K, dof, np.full(dof.size, 400.0), loads, max_size=8, tol=1e-9)
    assert small.size == 8 and small.capped == 21 - 8
    assert "dropped 13 directions" in caplog.text
    # the reported error is the independent projection's, and it is not small
    F = np.zeros((60, 1 + dof.size))
    F[:, 0] = loads[:, 0]
    F[dof, 1 + np.arange(dof.size)] = 1.0
    ref = max(_energy_error_by_projection(small.phi, K, F[:, j]) for j in range(F.shape[1]))
    assert abs(small.static_error - ref) <= 1e-8 * ref and ref > 0.01
    big = reduced_basis(M, K, dof, np.full(dof.size, 400.0), loads, max_size=200, tol=1e-9)
    assert big.capped == 0 and big.static_error < 1e-9


def test_the_run_summary_warns_about_a_capped_basis():
    assert basis_cap({"basis": {"kind": "reduced", "size": 40, "capped_directions": 0}}) == []
    assert basis_cap({"basis": {"kind": "local", "size": 900}}) == []
    (w,) = basis_cap({"basis": {"kind": "reduced", "size": 200, "capped_directions": 141,
                                "static_energy_error": 0.241}})
    assert w["code"] == "basis_cap" and "141 directions" in w["message"]
    assert "24.1 %" in w["message"] and w["value"] == 141


def test_sparse_patterns_chunked_solves_and_the_symmetric_lu_change_nothing(monkeypatch):
    """A rack row's 2,000 friction patterns on 20,000 DOFs (issue 22) are kept sparse, solved
    and multiplied by chunks of columns on a symmetric-ordered sparse LU of K: the basis equals
    the dense path's (Cholesky of K, dense loads), and its static error the independent
    projection's."""
    import scipy.sparse as sp

    from seisrack.dynamics import basis as basis_mod

    n = 420  # above the dense path's limit
    M, K = _chain(n)
    dof = np.arange(5, n, 8)  # 52 sliders
    loads = (M @ np.ones(n))[:, None]
    pats = np.zeros((n, dof.size))
    pats[dof, np.arange(dof.size)] = 1.0
    dense_loads = np.column_stack([loads, pats])
    opts = {"tol": 1e-2, "blocks": 2, "unit_loads": False}
    sparse = reduced_basis(sp.csr_matrix(M), sp.csr_matrix(K), dof, np.full(dof.size, 400.0),
                           sp.csc_matrix(dense_loads), **opts)
    monkeypatch.setattr(basis_mod, "_CHUNK", 7)  # chunk boundaries inside the patterns
    chunked = reduced_basis(sp.csr_matrix(M), sp.csr_matrix(K), dof, np.full(dof.size, 400.0),
                            dense_loads, **opts)
    monkeypatch.setattr(basis_mod, "_DENSE_MAX_DOF", 10 * n)  # dense Cholesky of K instead
    dense = reduced_basis(M, K, dof, np.full(dof.size, 400.0), dense_loads, **opts)
    assert sparse.size == chunked.size == dense.size and 20 < dense.size < dof.size
    low = dense.size // 2  # the static block's Ritz values (the top ones are round-off's)
    for other in (sparse, chunked):
        assert np.allclose(other.w2[:low], dense.w2[:low], rtol=1e-9, atol=0.0)
        assert abs(other.static_error - dense.static_error) <= 1e-9 * dense.static_error
    ref = max(_energy_error_by_projection(sparse.phi, K, dense_loads[:, j])
              for j in range(dense_loads.shape[1]))
    assert abs(sparse.static_error - ref) <= 1e-7 * ref and ref > 1e-4
