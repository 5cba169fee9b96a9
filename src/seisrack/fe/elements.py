"""Euler–Bernoulli beam-column element matrices, vectorised over elements.

Local DOF order per element: ``[u_i, v_i, θ_i, u_j, v_j, θ_j]`` (axial, transverse, rotation).
Stiffness and consistent mass are the standard cubic-Hermite / linear-axial forms
(Przemieniecki, *Theory of Matrix Structural Analysis*, 1968, §5 and §11; Cook et al.,
*Concepts and Applications of FEA*, 4th ed., §2.4 and §11.3). Every function returns
``(n_el, 6, 6)`` arrays built from index tables, with no Python loop over elements.
"""

from __future__ import annotations

import numpy as np

from seisrack.fe.mesh import FloatArray


def local_stiffness(E: FloatArray, A: FloatArray, I: FloatArray, L: FloatArray) -> FloatArray:
    """(n_el, 6, 6) local stiffness [N/m, N, N·m]."""
    n = L.shape[0]
    k = np.zeros((n, 6, 6))
    ea = E * A / L
    b1, b2, b3, b4 = 12 * E * I / L**3, 6 * E * I / L**2, 4 * E * I / L, 2 * E * I / L
    k[:, 0, 0] = k[:, 3, 3] = ea
    k[:, 0, 3] = k[:, 3, 0] = -ea
    k[:, 1, 1] = k[:, 4, 4] = b1
    k[:, 1, 4] = k[:, 4, 1] = -b1
    k[:, 1, 2] = k[:, 2, 1] = k[:, 1, 5] = k[:, 5, 1] = b2
    k[:, 2, 4] = k[:, 4, 2] = k[:, 4, 5] = k[:, 5, 4] = -b2
    k[:, 2, 2] = k[:, 5, 5] = b3
    k[:, 2, 5] = k[:, 5, 2] = b4
    return k


def local_consistent_mass(rho_a: FloatArray, L: FloatArray) -> FloatArray:
    """(n_el, 6, 6) local consistent mass [kg, kg·m, kg·m²] for mass per length ``rho_a`` [kg/m]."""
    n = L.shape[0]
    m = np.zeros((n, 6, 6))
    ax = rho_a * L / 6.0
    m[:, 0, 0] = m[:, 3, 3] = 2 * ax
    m[:, 0, 3] = m[:, 3, 0] = ax
    c = rho_a * L / 420.0
    bend = np.array([[156, 22, 54, -13],
                     [22, 4, 13, -3],
                     [54, 13, 156, -22],
                     [-13, -3, -22, 4]], dtype=float)
    # powers of L carried by each entry (v: L^0, θ: L^1)
    p = np.array([0, 1, 0, 1])
    powers = p[:, None] + p[None, :]
    idx = np.array([1, 2, 4, 5])
    m[:, idx[:, None], idx[None, :]] = c[:, None, None] * bend * L[:, None, None] ** powers
    return m


def rotation(c: FloatArray, s: FloatArray) -> FloatArray:
    """(n_el, 6, 6) transformation T with u_local = T @ u_global."""
    n = c.shape[0]
    t = np.zeros((n, 6, 6))
    for o in (0, 3):  # two node blocks, not a loop over elements
        t[:, o, o] = t[:, o + 1, o + 1] = c
        t[:, o, o + 1] = s
        t[:, o + 1, o] = -s
        t[:, o + 2, o + 2] = 1.0
    return t


def to_global(k_local: FloatArray, T: FloatArray) -> FloatArray:
    """Tᵀ k T for every element (any size of element matrix)."""
    return np.einsum("eji,ejk,ekl->eil", T, k_local, T)
