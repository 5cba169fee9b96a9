"""Specification of the masses that rest on the structure with Coulomb friction."""

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

    @property
    def velocity_dependent(self) -> bool:
        return bool(np.any((self.friction_rate > 0) & (self.mu_static > self.mu_dynamic)))
