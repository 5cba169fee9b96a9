"""The P-Δ of the change of the members' axial forces during the motion (``[second_order]
axial = "current"``), as the engine takes it.

With P-Δ the structure's K holds the geometric stiffness of the gravity axial forces N_g
(:mod:`seisrack.fe.geometric`), constant. When the axial forces are those of the current state,
N(t) = N_g + ΔN(u), the geometric stiffness changes with the motion; the engine applies its
departure from the K it integrates, an internal force

    f(u) = K_G(ΔN(u)) (u_g + u) = Σ_g s_g ΔN_{o(g)}(u) (b_g · (u_g + u)) b_g,

where every member's geometric stiffness per unit axial force is written by its eigenpairs,
k̂_e = Σ s_g b_g b_gᵀ (rank 2 per member in 3D for the chord form, one per bending plane), ΔN is
linear in u (each member's elastic axial force, as :func:`seisrack.fe.geometric.axial_forces`)
and u_g is the static displacement under gravity that u is measured from. This is what
OpenSees' ``geomTransf PDelta`` computes with the axial force of the current iterate; f is not
the gradient of a potential (its work over a cycle need not vanish), so the engine accounts its
work apart (``energy["p_delta"]``). In basis coordinates (u = Φ q) it is
``f(q) = Gᵀ (s ∘ (A q)[o] ∘ (c + G q))`` with ``A = axial Φ``, ``G = rows Φ``, ``c = rows u_g``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from seisrack.errors import InputError


@dataclass(frozen=True)
class AxialPDelta:
    """axial: (n_m, n) ΔN of the members (beam-columns, then bars) per unit displacement of the
    structure's DOFs [N/m]; rows: (n_g, n) the factors b_g of the members' unit geometric
    stiffness [1]; owner: (n_g,) the member (row of ``axial``) of each factor; scale: (n_g,)
    s_g [1/m]; offset: (n_g,) b_g · u_g [m] at the static state the motion starts from."""

    axial: sp.csr_matrix
    rows: sp.csr_matrix
    owner: np.ndarray
    scale: np.ndarray
    offset: np.ndarray

    def __post_init__(self) -> None:
        n_g = self.rows.shape[0]
        n_m = self.axial.shape[0]
        owner = np.asarray(self.owner, dtype=np.int64).reshape(-1)
        if (self.rows.shape[1] != self.axial.shape[1] or owner.shape != (n_g,)
                or np.asarray(self.scale).shape != (n_g,)
                or np.asarray(self.offset).shape != (n_g,)
                or (n_g and (owner.min() < 0 or owner.max() >= n_m))):
            raise InputError("axial_p_delta", f"axial {self.axial.shape}, rows "
                             f"{self.rows.shape}, owner {owner.shape}",
                             "one owner member, scale and offset per factor row, and operators "
                             "on the same DOFs")
        object.__setattr__(self, "owner", owner)

    @property
    def n_dof(self) -> int:
        return int(self.axial.shape[1])

    def reduced(self, phi: np.ndarray) -> tuple[np.ndarray, ...]:
        """(A (n_m, r), G (n_g, r), owner, scale, offset) in the basis ``phi`` (n, r), each
        C-contiguous, as the kernels take them."""
        A = np.ascontiguousarray(self.axial @ phi)  # noqa: N806
        G = np.ascontiguousarray(self.rows @ phi)  # noqa: N806
        return (A, G, np.ascontiguousarray(self.owner),
                np.ascontiguousarray(self.scale, dtype=float),
                np.ascontiguousarray(self.offset, dtype=float))

    def force(self, u: np.ndarray) -> np.ndarray:
        """f(u) (n,) [N] at the displacement ``u`` (n,) from the static state (the module's
        formula, on the structure's DOFs: a reference for the kernels)."""
        dn = self.axial @ u
        return self.rows.T @ (self.scale * dn[self.owner] * (self.offset + self.rows @ u))


def no_axial(r: int) -> tuple[np.ndarray, ...]:
    """The kernels' empty operators (no current-axial P-Δ) for a basis of ``r`` vectors."""
    return (np.zeros((0, r)), np.zeros((0, r)), np.zeros(0, dtype=np.int64), np.zeros(0),
            np.zeros(0))
