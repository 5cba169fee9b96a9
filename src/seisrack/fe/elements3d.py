"""3D Euler–Bernoulli beam-column and truss element matrices, vectorised over elements.

Local DOF order per beam element (12): ``[u, v, w, θx, θy, θz]`` at node i, then at node j
(axial, the two transverse translations, twist and the two bending rotations). The stiffness is
the classical uncoupled form: linear axial, St Venant torsion (G J / L, G = E / (2 (1 + ν))) and
a cubic-Hermite bending element in each principal plane, with ``Iz`` governing bending in the
local x–y plane (v, θz) and ``Iy`` bending in the local x–z plane (w, θy), whose rotation sign
is opposite (θy = −dw/dx). The consistent mass uses the same shape functions: linear for axial
and for twist (torsional mass with the polar moment ``Ip`` [m⁴], ρ Ip L / 6 · [[2, 1], [1, 2]]),
cubic Hermite for the transverse translations (rotary inertia of bending neglected, as in the
2D element). References: Przemieniecki, *Theory of Matrix Structural Analysis*, 1968, §5.4
(Eq. 5.116, space-frame stiffness) and §11.3 (Eq. 11.42, consistent mass); McGuire, Gallagher &
Ziemian, *Matrix Structural Analysis*, 2nd ed., 2000, §4.4 (Eq. 4.34) and §5.2 (transformation).

Local axes follow OpenSees' ``geomTransf Linear $tag $vecxzX $vecxzY $vecxzZ`` convention: the
local x axis runs from node i to node j; ``vecxz`` is any vector in the local x–z plane (not
parallel to x); the local y axis is ``vecxz × x`` (normalised) and the local z axis ``x × y``.
The rows of λ = [x; y; z] are the local axes in global components, and the element
transformation is T = diag(λ, λ, λ, λ), with u_local = T u_global.

Trusses (bracing members, pinned at both ends) carry axial stiffness only. Their consistent
mass is that of linear interpolation of all three translations, ρ A L / 6 · [[2 I₃, I₃], [I₃,
2 I₃]] (rotation invariant, so it is assembled in global axes directly), the form of OpenSees'
``truss … -rho -cMass``.

Every function returns ``(n_el, 12, 12)`` (beams) or ``(n_el, 6, 6)`` (trusses) arrays built
from index tables, with no Python loop over elements.
"""

from __future__ import annotations

import numpy as np

from seisrack.fe.elements import to_global
from seisrack.fe.mesh import FloatArray

# Hermite bending block on (v_i, θ_i, v_j, θ_j) and the powers of L of its entries.
_P = np.array([0, 1, 0, 1])
_POW = _P[:, None] + _P[None, :]
_K_BEND = np.array([[12, 6, -12, 6],
                    [6, 4, -6, 2],
                    [-12, -6, 12, -6],
                    [6, 2, -6, 4]], dtype=float)  # · E I / L³ · L^pow
_M_BEND = np.array([[156, 22, 54, -13],
                    [22, 4, 13, -3],
                    [54, 13, 156, -22],
                    [-13, -3, -22, 4]], dtype=float)  # · ρ A L / 420 · L^pow
_XY = np.array([1, 5, 7, 11])  # (v_i, θz_i, v_j, θz_j)
_XZ = np.array([2, 4, 8, 10])  # (w_i, θy_i, w_j, θy_j)
_SIGN_XZ = np.array([1.0, -1.0, 1.0, -1.0])  # θy = −dw/dx
_TWO = np.array([[1.0, -1.0], [-1.0, 1.0]])
_LIN_MASS = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6.0


def _put_pair(out: FloatArray, idx: tuple[int, int], block: FloatArray, c: FloatArray) -> None:
    i = np.array(idx)
    out[:, i[:, None], i[None, :]] += c[:, None, None] * block


def _put_bend(out: FloatArray, idx: np.ndarray, sign: np.ndarray, block: FloatArray,
              c: FloatArray, L: FloatArray) -> None:
    b = block * np.outer(sign, sign)
    out[:, idx[:, None], idx[None, :]] += c[:, None, None] * b * L[:, None, None] ** _POW


def local_stiffness_3d(E: FloatArray, G: FloatArray, A: FloatArray, Iy: FloatArray,
                       Iz: FloatArray, J: FloatArray, L: FloatArray) -> FloatArray:
    """(n_el, 12, 12) local stiffness [N/m, N, N·m] (Przemieniecki Eq. 5.116)."""
    k = np.zeros((L.shape[0], 12, 12))
    _put_pair(k, (0, 6), _TWO, E * A / L)  # axial
    _put_pair(k, (3, 9), _TWO, G * J / L)  # St Venant torsion
    _put_bend(k, _XY, np.ones(4), _K_BEND, E * Iz / L**3, L)
    _put_bend(k, _XZ, _SIGN_XZ, _K_BEND, E * Iy / L**3, L)
    return k


def local_consistent_mass_3d(rho: FloatArray, A: FloatArray, Ip: FloatArray, L: FloatArray
                             ) -> FloatArray:
    """(n_el, 12, 12) local consistent mass [kg, kg·m, kg·m²] (Przemieniecki Eq. 11.42 without
    rotary inertia of bending). ``rho`` [kg/m³], ``Ip`` polar moment of area [m⁴]."""
    m = np.zeros((L.shape[0], 12, 12))
    _put_pair(m, (0, 6), _LIN_MASS, rho * A * L)
    _put_pair(m, (3, 9), _LIN_MASS, rho * Ip * L)
    c = rho * A * L / 420.0
    _put_bend(m, _XY, np.ones(4), _M_BEND, c, L)
    _put_bend(m, _XZ, _SIGN_XZ, _M_BEND, c, L)
    return m


def local_axes(xi: FloatArray, xj: FloatArray, vecxz: FloatArray) -> FloatArray:
    """(n_el, 3, 3) λ whose rows are the local x, y, z axes in global components.

    ``xi``, ``xj``: (n_el, 3) end coordinates [m]; ``vecxz``: (n_el, 3) or (3,) a vector in
    the local x–z plane (OpenSees convention, see the module docstring). Raises ValueError if
    ``vecxz`` is parallel to an element axis or an element has zero length.
    """
    d = np.asarray(xj, float) - np.asarray(xi, float)
    L = np.linalg.norm(d, axis=1)
    if np.any(L <= 0.0):
        raise ValueError("zero-length element")
    ex = d / L[:, None]
    v = np.broadcast_to(np.asarray(vecxz, float), ex.shape)
    ey = np.cross(v, ex)
    ny = np.linalg.norm(ey, axis=1)
    if np.any(ny <= 1e-9 * np.linalg.norm(v, axis=1)):
        raise ValueError("vecxz is parallel to an element axis")
    ey = ey / ny[:, None]
    ez = np.cross(ex, ey)
    return np.stack([ex, ey, ez], axis=1)


def transformation_3d(lam: FloatArray) -> FloatArray:
    """(n_el, 12, 12) T = diag(λ, λ, λ, λ) with u_local = T u_global."""
    T = np.zeros((lam.shape[0], 12, 12))
    for o in (0, 3, 6, 9):  # four 3x3 blocks, not a loop over elements
        T[:, o:o + 3, o:o + 3] = lam
    return T


def beam_matrices_3d(xi: FloatArray, xj: FloatArray, vecxz: FloatArray, *, E: FloatArray,
                     G: FloatArray, A: FloatArray, Iy: FloatArray, Iz: FloatArray,
                     J: FloatArray, rho: FloatArray, Ip: FloatArray | None = None
                     ) -> tuple[FloatArray, FloatArray]:
    """Global-axis stiffness and consistent mass of 3D beam-columns, each (n_el, 12, 12).

    ``Ip`` (polar moment of area, torsional inertia) defaults to ``Iy + Iz``.
    """
    L = np.linalg.norm(np.asarray(xj, float) - np.asarray(xi, float), axis=1)
    T = transformation_3d(local_axes(xi, xj, vecxz))
    Ip = Iy + Iz if Ip is None else Ip
    k = to_global(local_stiffness_3d(E, G, A, Iy, Iz, J, L), T)
    m = to_global(local_consistent_mass_3d(rho, A, Ip, L), T)
    return k, m


def truss_matrices_3d(xi: FloatArray, xj: FloatArray, *, E: FloatArray, A: FloatArray,
                      rho: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Global stiffness and consistent mass of pin-ended bars, each (n_el, 6, 6) on
    ``[ux_i, uy_i, uz_i, ux_j, uy_j, uz_j]``: k = EA/L [[nnᵀ, −nnᵀ], [−nnᵀ, nnᵀ]] with n the
    unit axis (McGuire et al. §4.3), m = ρAL/6 [[2 I, I], [I, 2 I]]."""
    d = np.asarray(xj, float) - np.asarray(xi, float)
    L = np.linalg.norm(d, axis=1)
    n = d / L[:, None]
    nn = np.einsum("ei,ej->eij", n, n)
    k = np.einsum("ab,eij->eaibj", _TWO, nn).reshape(-1, 6, 6) * (E * A / L)[:, None, None]
    m = np.einsum("ab,ij->abij", _LIN_MASS, np.eye(3)).transpose(0, 2, 1, 3).reshape(6, 6)
    return k, m[None] * (rho * A * L)[:, None, None]
