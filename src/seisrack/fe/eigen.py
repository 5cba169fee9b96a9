"""The generalized symmetric eigenproblem K φ = ω² M φ of a frame: modes and participation
(dense or sparse solver), shared by the 2D and 3D modal analyses (:mod:`seisrack.fe.modal`).

Participation follows Chopra, *Dynamics of Structures*, 4th ed., §13.2: with mass-normalised
shapes (φᵀMφ = 1), the participation factor is Γ = φᵀ M r and the effective modal mass
M* = Γ²; Σ M* over all modes equals the total mass rᵀ M r.

For a :class:`~seisrack.model.FrameModel` the mass is ``total_mass_matrix()``: the pallets
rigidly attached. The total horizontal mass is therefore rᵀ M r over the *free* DOFs (mass lumped
by the consistent mass matrix onto restrained base DOFs does not move and is not counted).

Two solvers give the same :class:`ModalResult`: a dense one (LAPACK ``eigh`` of the inverted
problem, all or the last ``k`` modes) for small problems and for ``n_modes=None``, and a sparse one
(ARPACK Lanczos in shift-invert mode about σ = 0, ``scipy.sparse.linalg.eigsh(K, k, M,
sigma=0)``) when a few modes of a large model are wanted: it factors K once (sparse LU) and never
forms an (n, n) dense matrix. Shift-invert about 0 converges to the lowest frequencies first and
tolerates a (nearly) singular M: massless modes map to eigenvalue 0 of K⁻¹M and are never found.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from seisrack.errors import InputError, SolverError
from seisrack.fe.mesh import FloatArray
from seisrack.fe.stability import symmetric_lu

Method = Literal["auto", "dense", "sparse"]
DENSE_MAX_DOF = 500
"""``method="auto"`` solves problems up to this many DOFs densely."""
SPARSE_MAX_FRACTION = 0.1
"""``method="auto"`` goes sparse only when ``n_modes <= SPARSE_MAX_FRACTION * n_dof``."""


@dataclass(frozen=True)
class ModalResult:
    """Natural modes ordered by mode number: mode 1 (longest period, the fundamental) first.

    Attributes:
        periods: (n_modes,) [s], by ascending mode number (so decreasing values).
        frequencies: (n_modes,) [Hz].
        omega: (n_modes,) [rad/s].
        shapes: (n_dof, n_modes) mass-normalised (φᵀ M φ = 1).
        gamma_x, gamma_y: (n_modes,) participation factors [kg^0.5].
        effective_mass_x, effective_mass_y: (n_modes,) [kg].
        mass_participation: (n_modes,) effective horizontal mass / total horizontal mass [-].
        mass_participation_y: (n_modes,) same for vertical [-].
        total_mass_x, total_mass_y: [kg].
        status: "ok".
    A 3D rack adds the cross-aisle (z) and plan-rotation terms (None / 0 for a 2D rack):
        gamma_z, effective_mass_z [kg], mass_participation_z [-]: (n_modes,); total_mass_z.
        gamma_theta, effective_inertia_theta [kg·m²], participation_theta [-]: (n_modes,);
        total_inertia_theta [kg·m²] about the vertical through the plan mass centre.
        direction: (n_modes,) str class of each mode (see :mod:`seisrack.fe.modal`).
    """

    periods: FloatArray
    frequencies: FloatArray
    omega: FloatArray
    shapes: FloatArray
    gamma_x: FloatArray
    gamma_y: FloatArray
    effective_mass_x: FloatArray
    effective_mass_y: FloatArray
    mass_participation: FloatArray
    mass_participation_y: FloatArray
    total_mass_x: float
    total_mass_y: float
    status: str = "ok"
    gamma_z: FloatArray | None = None
    effective_mass_z: FloatArray | None = None
    mass_participation_z: FloatArray | None = None
    total_mass_z: float = 0.0
    gamma_theta: FloatArray | None = None
    effective_inertia_theta: FloatArray | None = None
    participation_theta: FloatArray | None = None
    total_inertia_theta: float = 0.0
    direction: tuple[str, ...] = ()

    @property
    def n_modes(self) -> int:
        return int(self.periods.shape[0])


def choose_method(n_dof: int, n_modes: int | None, method: Method = "auto") -> str:
    """"dense" or "sparse": what ``method="auto"`` picks for ``n_modes`` of ``n_dof``."""
    if method not in ("auto", "dense", "sparse"):
        raise InputError("method", method, '"auto", "dense" or "sparse"')
    if method != "auto":
        return method
    if n_modes is None or n_dof <= DENSE_MAX_DOF or n_modes > SPARSE_MAX_FRACTION * n_dof:
        return "dense"
    return "sparse"


def modal_from_matrices(K: Any, M: Any, r_x: FloatArray, r_y: FloatArray,
                        n_modes: int | None = None, *, method: Method = "auto") -> ModalResult:
    """Modes of (K, M) with participation for the influence vectors ``r_x`` and ``r_y``.

    Args:
        K, M: (n, n) dense arrays or scipy sparse matrices, symmetric [N/m, kg]. K must be
            positive definite (a stable frame); M positive semi-definite.
        r_x, r_y: (n,) influence vectors.
        n_modes: number of modes, lowest frequencies first; None = all (dense solver).
        method: "dense" (LAPACK), "sparse" (ARPACK shift-invert, needs n_modes < n) or "auto"
            (dense up to ``DENSE_MAX_DOF`` DOFs, for n_modes=None or for more than
            ``SPARSE_MAX_FRACTION`` of the DOFs; sparse otherwise).

    Modes of zero mass (infinite frequency) are dropped, so fewer than ``n_modes`` may be returned.
    """
    n = K.shape[0]
    k = n if n_modes is None else max(1, min(int(n_modes), n))
    how = choose_method(n, n_modes, method)
    if how == "sparse" and k >= n - 1:
        raise InputError("n_modes", n_modes, f"fewer than {n - 1} modes with method='sparse' "
                         f"({n} DOFs)", hint="Use method='dense' for all modes")
    if how == "dense":
        lam, phi = _dense_modes(K, M, k)
    else:
        lam, phi = _sparse_modes(K, M, k)
    keep = lam > 1e-13 * max(float(lam[0]), 0.0)  # massless modes have infinite frequency
    if not keep[0]:
        raise SolverError("modal analysis failed: the mass matrix is zero")
    lam, phi = lam[keep], phi[:, keep]
    k = int(lam.shape[0])
    Mr_x, Mr_y = M @ r_x, M @ r_y
    # Normalise φᵀMφ = 1 (both solvers; the dense one returns φᵀKφ = λ-scaled vectors).
    phi = phi / np.sqrt(np.einsum("ik,ik->k", phi, np.asarray(M @ phi)))
    phi = phi * _sign(phi)
    omega = np.sqrt(1.0 / lam)
    gx = phi.T @ Mr_x
    gy = phi.T @ Mr_y
    mx = float(r_x @ Mr_x)
    my = float(r_y @ Mr_y)
    return ModalResult(
        periods=2 * np.pi / omega, frequencies=omega / (2 * np.pi), omega=omega, shapes=phi,
        gamma_x=gx, gamma_y=gy, effective_mass_x=gx**2, effective_mass_y=gy**2,
        mass_participation=gx**2 / mx if mx > 0 else np.zeros(k),
        mass_participation_y=gy**2 / my if my > 0 else np.zeros(k),
        total_mass_x=mx, total_mass_y=my,
    )


def _sign(phi: FloatArray) -> FloatArray:
    """(n_modes,) ±1 making the largest-magnitude component of each shape positive.

    Components within a relative 1e-6 of the largest count as tied and the lowest DOF index
    among them decides, so that two solvers (or round-off) cannot flip the sign of a shape whose
    extreme components are equal and opposite (an antisymmetric mode of a symmetric rack).
    """
    mag = np.abs(phi)
    top = mag >= (1.0 - 1e-6) * mag.max(axis=0)
    idx = top.argmax(axis=0)  # first DOF among the (near-)largest
    sign = np.sign(phi[idx, np.arange(phi.shape[1])])
    return np.where(sign == 0, 1.0, sign)


def _dense_modes(K: Any, M: Any, k: int) -> tuple[FloatArray, FloatArray]:
    """(λ, φ) of the k largest λ = 1/ω² of M φ = λ K φ, descending."""
    K = K.toarray() if sp.issparse(K) else np.asarray(K, dtype=float)
    M = M.toarray() if sp.issparse(M) else np.asarray(M, dtype=float)
    n = K.shape[0]
    # Solve the inverted problem M φ = λ K φ with λ = 1/ω²: K is positive definite for a
    # stable frame, whereas M may be (nearly) singular when some DOFs carry (almost) no mass.
    try:
        lam, phi = scipy.linalg.eigh(M, K, subset_by_index=[n - k, n - 1])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"modal analysis failed: {exc} (is the frame a mechanism?)") from exc
    return lam[::-1], phi[:, ::-1]


def _sparse_modes(K: Any, M: Any, k: int) -> tuple[FloatArray, FloatArray]:
    """(λ, φ) of the k largest λ = 1/ω² by shift-invert Lanczos about σ = 0, descending."""
    K = sp.csr_matrix(K)
    M = sp.csr_matrix(M)
    n = K.shape[0]
    try:
        lu = symmetric_lu(K)
    except RuntimeError as exc:
        raise SolverError(f"modal analysis failed: {exc} (is the frame a mechanism?)") from exc
    k_inv = sla.LinearOperator((n, n), matvec=lu.solve, dtype=float)
    # A fixed pseudo-random start: reproducible, and not orthogonal to antisymmetric modes
    # (a constant start vector would be, on a symmetric rack).
    v0 = np.random.default_rng(0).standard_normal(n)
    try:
        w2, phi = sla.eigsh(K, k=k, M=M, sigma=0.0, which="LM", OPinv=k_inv, v0=v0,
                            ncv=min(n - 1, max(2 * k + 1, k + 32)))
    except (sla.ArpackNoConvergence, sla.ArpackError) as exc:
        raise SolverError(f"modal analysis failed: {exc}") from exc
    order = np.argsort(w2)  # lowest frequency first
    return 1.0 / w2[order], phi[:, order]
