"""The masses that rest on the structure with Coulomb friction: :class:`Sliders` move along one
line (2D racks), :class:`PlanarSliders` in the horizontal plane (3D racks)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError


@dataclass(frozen=True)
class Sliders:
    """Masses resting on structural DOFs with Coulomb friction.

    dof: (m,) index of the horizontal structural DOF each mass rests on (-1: on the ground,
        i.e. a rigid support moving with the ground, as in the paper's §II).
    mass: (m,) [kg]. mu_static, mu_dynamic: (m,) friction coefficients, 0 <= mu_d <= mu_s.
    friction_rate: (m,) [s/m] velocity dependence while sliding, 0 for Coulomb (default):
        mu(v) = mu_d + (mu_s - mu_d) exp(-rate |v|), so mu_s at v = 0 and mu_d as rate → ∞
        (the form of OpenSees' VelDependent friction, with mu_slow = mu_s, mu_fast = mu_d).
    Scalars are broadcast to every slider.
    """

    dof: np.ndarray
    mass: np.ndarray
    mu_static: np.ndarray
    mu_dynamic: np.ndarray
    friction_rate: np.ndarray

    def __init__(self, dof, mass, mu_static, mu_dynamic=None,  # noqa: ANN001
                 friction_rate=0.0) -> None:  # noqa: ANN001
        dof_a = np.atleast_1d(np.asarray(dof))
        if dof_a.ndim != 1:
            raise InputError("sliders.dof", dof, "a 1-D list of DOF indices")
        if dof_a.size and not np.issubdtype(dof_a.dtype, np.integer):
            if not np.all(np.equal(np.mod(dof_a, 1), 0)):
                raise InputError("sliders.dof", dof, "integer DOF indices")
        m = dof_a.size

        def _arr(name: str, val) -> np.ndarray:  # noqa: ANN001
            a = np.asarray(val, dtype=float)
            if a.ndim == 0:
                a = np.full(m, float(a))
            if a.shape != (m,):
                raise InputError(f"sliders.{name}", val, f"a scalar or {m} values (one per slider)")
            if not np.all(np.isfinite(a)):
                raise InputError(f"sliders.{name}", val, "finite numbers")
            return a

        mass_a = _arr("mass", mass)
        mus = _arr("mu_static", mu_static)
        mud = mus.copy() if mu_dynamic is None else _arr("mu_dynamic", mu_dynamic)
        rate = _arr("friction_rate", friction_rate)
        if np.any(rate < 0):
            raise InputError("sliders.friction_rate", rate.tolist(),
                             "rates >= 0 s/m (0: Coulomb friction)")
        if np.any(mass_a <= 0):
            raise InputError("sliders.mass", mass_a.tolist(), "masses > 0 kg")
        if np.any(mus < 0):
            raise InputError("sliders.mu_static", mus.tolist(), "friction coefficients >= 0")
        if np.any(mud < 0):
            raise InputError("sliders.mu_dynamic", mud.tolist(), "friction coefficients >= 0")
        if np.any(mud > mus):
            j = int(np.argmax(mud > mus))
            raise InputError(
                f"sliders.mu_dynamic[{j}]", float(mud[j]),
                f"a value <= mu_static ({mus[j]:g}): dynamic friction cannot exceed static",
            )
        object.__setattr__(self, "dof", dof_a.astype(np.int64))
        object.__setattr__(self, "mass", mass_a)
        object.__setattr__(self, "mu_static", mus)
        object.__setattr__(self, "mu_dynamic", mud)
        object.__setattr__(self, "friction_rate", rate)

    @property
    def count(self) -> int:
        return int(self.dof.size)

    def check_dofs(self, n: int) -> None:
        """InputError unless every DOF index is in [0, n - 1] or -1 (the ground)."""
        bad = self.dof[(self.dof < -1) | (self.dof >= n)]
        if bad.size:
            raise InputError("sliders.dof", bad.tolist(),
                             f"DOF indices in [0, {n - 1}], or -1 (rests on the ground)")

    @property
    def velocity_dependent(self) -> bool:
        return bool(np.any((self.friction_rate > 0) & (self.mu_static > self.mu_dynamic)))


@dataclass(frozen=True)
class PlanarSliders:
    """Pallets resting on structural nodes, free to slide in the horizontal plane.

    dof_x, dof_z: (m, k) int, the x (down-aisle) and z (cross-aisle) translation DOFs of the
        ``k`` points each pallet rests on (-1: the ground, a rigid support moving with it); the
        pallet's support motion is their mean and its friction force is shared equally.
    mass [kg], mu_static, mu_dynamic (0 <= mu_d <= mu_s): (m,) or scalars.
    """

    dof_x: np.ndarray
    dof_z: np.ndarray
    mass: np.ndarray
    mu_static: np.ndarray
    mu_dynamic: np.ndarray

    def __init__(self, dof_x, dof_z, mass, mu_static, mu_dynamic=None) -> None:  # noqa: ANN001
        dx = np.asarray(dof_x)
        dz = np.asarray(dof_z)
        if dx.ndim == 1:
            dx = dx[:, None]
        if dz.ndim == 1:
            dz = dz[:, None]
        if dx.ndim != 2 or dx.shape != dz.shape:
            raise InputError("sliders.dof_z", f"shape {dz.shape}",
                             f"the shape of dof_x {dx.shape}: (pallets, supports)")
        for name, a in (("dof_x", dx), ("dof_z", dz)):
            if a.size and not np.all(np.equal(np.mod(a, 1), 0)):
                raise InputError(f"sliders.{name}", a.tolist(), "integer DOF indices")
        mass_a, mus, mud = mass_and_friction(dx.shape[0], mass, mu_static, mu_dynamic)
        object.__setattr__(self, "dof_x", dx.astype(np.int64))
        object.__setattr__(self, "dof_z", dz.astype(np.int64))
        object.__setattr__(self, "mass", mass_a)
        object.__setattr__(self, "mu_static", mus)
        object.__setattr__(self, "mu_dynamic", mud)

    @property
    def count(self) -> int:
        return int(self.mass.shape[0])

    def check_dofs(self, n: int) -> None:
        """InputError unless every DOF index is in [0, n - 1] or -1 (the ground)."""
        for name, d in (("dof_x", self.dof_x), ("dof_z", self.dof_z)):
            if np.any(d < -1) or np.any(d >= n):
                raise InputError(f"sliders.{name}", d[(d < -1) | (d >= n)].tolist(),
                                 f"DOF indices in [0, {n - 1}] or -1 (the ground)")

    def support_matrix(self, phi: np.ndarray) -> np.ndarray:
        """(2m, r): rows 2p (x) and 2p+1 (z) give pallet p's support motion from ``q``."""
        m, k = self.dof_x.shape
        P = np.zeros((2 * m, phi.shape[1]))
        for c, dofs in enumerate((self.dof_x, self.dof_z)):
            for s in range(k):
                on = dofs[:, s] >= 0
                P[2 * np.flatnonzero(on) + c] += phi[dofs[on, s], :] / k
        return P


def mass_and_friction(m: int, mass, mu_static, mu_dynamic=None  # noqa: ANN001
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(m,) masses [kg], static and dynamic friction coefficients of ``m`` sliders, each given
    as a scalar or ``m`` values (``mu_dynamic`` None: equal to ``mu_static``); InputError on a
    non-finite value, a mass <= 0, a negative coefficient or mu_dynamic > mu_static."""

    def arr(name: str, val) -> np.ndarray:  # noqa: ANN001
        a = np.asarray(val, dtype=float)
        if a.ndim == 0:
            a = np.full(m, float(a))
        if a.shape != (m,) or not np.all(np.isfinite(a)):
            raise InputError(f"sliders.{name}", val, f"a finite scalar or {m} values")
        return a

    mass_a = arr("mass", mass)
    mus = arr("mu_static", mu_static)
    mud = mus.copy() if mu_dynamic is None else arr("mu_dynamic", mu_dynamic)
    if np.any(mass_a <= 0):
        raise InputError("sliders.mass", mass_a.tolist(), "masses > 0 kg")
    if np.any(mus < 0) or np.any(mud < 0):
        raise InputError("sliders.mu", [mus.tolist(), mud.tolist()],
                         "friction coefficients >= 0")
    if np.any(mud > mus):
        j = int(np.argmax(mud > mus))
        raise InputError(f"sliders.mu_dynamic[{j}]", float(mud[j]),
                         f"a value <= mu_static ({mus[j]:g})")
    return mass_a, mus, mud
