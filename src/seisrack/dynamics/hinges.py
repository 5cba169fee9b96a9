"""Nonlinear rotational hinges of a structure, as the engine takes them (issue #12).

A hinge is a rotational spring between two DOFs (or one DOF and the ground) whose moment
follows a hysteresis law (:mod:`seisrack.dynamics._hysteresis`). Its elastic stiffness must
already be in the structure's K (as the rack's connection springs are): the engine applies only
the law's departure from it, ``z = M(θ) − k θ``. See ``docs/theory/nonlinear_hinges.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.dynamics import _hysteresis as hy
from seisrack.dynamics.axial import AxialPDelta
from seisrack.errors import InputError


@dataclass(frozen=True)
class Hinges:
    """dofs: (n_h, 2) int, the two DOFs whose rotation difference ``u[a] − u[b]`` is the hinge
    rotation (``b = -1``: the ground); k: (n_h,) elastic stiffness already in K [N·m/rad];
    law: (n_h,) int law code (``HYST_*``); par: (n_h, HYST_NPAR) law parameters;
    theta0: (n_h,) [rad] rotation in the static state the motion starts from (the engine's
    displacements are measured from it: e.g. the rack under gravity), default 0. The laws
    start there as if loaded monotonically from zero.
    axial: the P-Δ of the members' axial-force change (:mod:`seisrack.dynamics.axial`), the
    structure's other nonlinear internal force, or None (sliders in the plane only)."""

    dofs: np.ndarray
    k: np.ndarray
    law: np.ndarray
    par: np.ndarray
    theta0: np.ndarray | None = None
    axial: AxialPDelta | None = None

    def __post_init__(self) -> None:
        dofs = np.asarray(self.dofs, dtype=np.int64).reshape(-1, 2)
        n_h = dofs.shape[0]
        k = np.asarray(self.k, dtype=float).reshape(-1)
        law = np.asarray(self.law, dtype=np.int64).reshape(-1)
        par = np.asarray(self.par, dtype=float).reshape(n_h, -1) if n_h else \
            np.zeros((0, hy.HYST_NPAR))
        if k.shape != (n_h,) or law.shape != (n_h,) or par.shape != (n_h, hy.HYST_NPAR):
            raise InputError("hinges", f"{n_h} DOF pairs, k {k.shape}, law {law.shape}, "
                             f"par {par.shape}",
                             f"one k, law and a parameter row of {hy.HYST_NPAR} per hinge")
        if np.any(~np.isfinite(k)) or np.any(k <= 0):
            raise InputError("hinges.k", k.tolist(), "finite stiffnesses > 0 N·m/rad")
        if np.any((law < hy.HYST_ELASTIC) | (law > hy.HYST_PINCHING)):
            raise InputError("hinges.law", law.tolist(),
                             f"law codes {hy.HYST_ELASTIC}..{hy.HYST_PINCHING}")
        th0 = np.zeros(n_h) if self.theta0 is None else \
            np.asarray(self.theta0, dtype=float).reshape(-1)
        if th0.shape != (n_h,) or not np.all(np.isfinite(th0)):
            raise InputError("hinges.theta0", th0.tolist(), f"{n_h} finite rotations [rad]")
        for name, v in (("dofs", dofs), ("k", k), ("law", law), ("par", par), ("theta0", th0)):
            object.__setattr__(self, name, np.ascontiguousarray(v))

    @property
    def count(self) -> int:
        return int(self.k.shape[0])

    @property
    def nonlinear(self) -> bool:
        return bool(np.any(self.law != hy.HYST_ELASTIC))

    def operator(self, phi: np.ndarray) -> np.ndarray:
        """(n_h, r) rotations of the basis coordinates: ``θ = Q q`` with ``u = Φ q``."""
        a, b = self.dofs[:, 0], self.dofs[:, 1]
        Q = phi[a, :].copy()  # noqa: N806
        on = b >= 0
        Q[on] -= phi[b[on], :]
        return np.ascontiguousarray(Q)

    def load_vectors(self, n: int) -> np.ndarray:
        """(n, n_h) unit moment pairs of the hinges (Ritz starting vectors for their forces)."""
        out = np.zeros((n, self.count))
        idx = np.arange(self.count)
        out[self.dofs[:, 0], idx] = 1.0
        on = self.dofs[:, 1] >= 0
        out[self.dofs[on, 1], idx[on]] = -1.0
        return out

    def initial_state(self) -> np.ndarray:
        """(n_h, HYST_NSTATE) committed states at ``theta0`` (one monotonic step from the
        virgin state θ = 0, M = 0)."""
        st = np.zeros((self.count, hy.HYST_NSTATE))
        tmp = np.zeros(hy.HYST_NSTATE)
        for i in range(self.count):
            hy._hyst_init(int(self.law[i]), self.par[i], st[i])
            if self.theta0[i] != 0.0:
                hy._hyst_trial(int(self.law[i]), self.par[i], st[i], float(self.theta0[i]), tmp)
                st[i] = tmp
        return st

    def initial_moment(self) -> np.ndarray:
        """(n_h,) [N·m] moments at ``theta0``."""
        return self.initial_state()[:, hy.HYST_S_M].copy()

    def check(self, n: int) -> None:
        """DOFs within the structure's ``n`` DOFs."""
        if self.axial is not None and self.axial.n_dof != n:
            raise InputError("hinges.axial", f"operators on {self.axial.n_dof} DOFs",
                             f"operators on the structure's {n} DOFs")
        d = self.dofs
        bad = (d[:, 0] < 0) | (d[:, 0] >= n) | (d[:, 1] < -1) | (d[:, 1] >= n)
        if np.any(bad):
            raise InputError("hinges.dofs", d[bad].tolist(),
                             f"pairs of DOF indices in [0, {n - 1}] (second may be -1: ground)")


def no_hinges() -> Hinges:
    return Hinges(np.zeros((0, 2), dtype=np.int64), np.zeros(0), np.zeros(0, dtype=np.int64),
                  np.zeros((0, hy.HYST_NPAR)))


def energy_split(strain_total: np.ndarray, q: np.ndarray, kd: np.ndarray, theta: np.ndarray,
                 moment: np.ndarray, k: np.ndarray, theta0: np.ndarray, moment0: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(strain, hysteresis) [J] from the kernel's internal-work column.

    ``strain_total`` = ½ qᵀ diag(kd) q + ∫ z dθ: the structure's work measured from the
    starting state. Every hinge's elastic spring is in ``kd``, so a hinge's work is
    ∫ M dθ = ½ k (θ² − θ0²) + ∫ z dθ. Of it, the hinge keeps M²/(2k) − M0²/(2k) as elastic
    energy it would give back on unloading at its elastic stiffness; the rest is hysteretic
    (dissipated). q: (n_t, r); kd: (r,); theta, moment: (n_t, n_h); theta0, moment0: (n_h,).
    """
    elastic_q = 0.5 * np.einsum("ti,i,ti->t", q, kd, q)
    work_z = strain_total - elastic_q
    hysteresis = work_z + 0.5 * (theta**2 - theta0**2) @ k - (moment**2 - moment0**2) @ (0.5 / k)
    return strain_total - hysteresis, hysteresis
