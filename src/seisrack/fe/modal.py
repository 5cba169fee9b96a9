"""Modal analysis: generalized symmetric eigenproblem K φ = ω² M φ.

Participation follows Chopra, *Dynamics of Structures*, 4th ed., §13.2: with mass-normalised
shapes (φᵀMφ = 1), the participation factor is Γ = φᵀ M r and the effective modal mass
M* = Γ²; Σ M* over all modes equals the total mass rᵀ M r.

For a :class:`~seisrack.model.FrameModel` the mass is ``total_mass_matrix()``: the pallets
rigidly attached. The total horizontal mass is therefore rᵀ M r over the *free* DOFs (mass lumped
by the consistent mass matrix onto restrained base DOFs does not move and is not counted).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg

from seisrack.errors import SolverError
from seisrack.fe.mesh import FloatArray


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

    @property
    def n_modes(self) -> int:
        return int(self.periods.shape[0])


def modal_analysis(model: Any, n_modes: int | None = None) -> ModalResult:
    """Modes of a :class:`~seisrack.model.FrameModel` with the pallets rigidly attached.

    ``n_modes=None`` returns all modes. Shapes are normalised with ``total_mass_matrix()``.
    """
    return modal_from_matrices(model.K, model.total_mass_matrix(), model.r_x, model.r_y, n_modes)


def modal_from_matrices(K: FloatArray, M: FloatArray, r_x: FloatArray, r_y: FloatArray,
                        n_modes: int | None = None) -> ModalResult:
    """Modes of (K, M) with participation for the influence vectors ``r_x`` and ``r_y``.

    K must be positive definite (a stable frame); M positive semi-definite. Modes of zero mass
    (infinite frequency) are dropped, so fewer than ``n_modes`` may be returned.
    """
    n = K.shape[0]
    k = n if n_modes is None else max(1, min(int(n_modes), n))
    # Solve the inverted problem M φ = λ K φ with λ = 1/ω²: K is positive definite for a
    # stable frame, whereas M may be (nearly) singular when some DOFs carry (almost) no mass.
    try:
        lam, phi = scipy.linalg.eigh(M, K, subset_by_index=[n - k, n - 1])
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise SolverError(f"modal analysis failed: {exc} (is the frame a mechanism?)") from exc
    lam, phi = lam[::-1], phi[:, ::-1]
    keep = lam > 1e-13 * max(float(lam[0]), 0.0)  # massless modes have infinite frequency
    if not keep[0]:
        raise SolverError("modal analysis failed: the mass matrix is zero")
    lam, phi = lam[keep], phi[:, keep]
    k = int(lam.shape[0])
    phi = phi / np.sqrt(lam)  # φᵀKφ = 1 → φᵀMφ = 1
    w2 = 1.0 / lam
    # Sign convention: make the largest-magnitude component of each shape positive.
    sign = np.sign(phi[np.abs(phi).argmax(axis=0), np.arange(k)])
    phi = phi * np.where(sign == 0, 1.0, sign)
    omega = np.sqrt(w2)
    gx = phi.T @ (M @ r_x)
    gy = phi.T @ (M @ r_y)
    mx = float(r_x @ M @ r_x)
    my = float(r_y @ M @ r_y)
    return ModalResult(
        periods=2 * np.pi / omega, frequencies=omega / (2 * np.pi), omega=omega, shapes=phi,
        gamma_x=gx, gamma_y=gy, effective_mass_x=gx**2, effective_mass_y=gy**2,
        mass_participation=gx**2 / mx if mx > 0 else np.zeros(k),
        mass_participation_y=gy**2 / my if my > 0 else np.zeros(k),
        total_mass_x=mx, total_mass_y=my,
    )
