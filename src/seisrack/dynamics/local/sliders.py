"""Pallets resting on a structure, free to slide in ``n_dir`` horizontal directions (1 for a
2D rack, 2 for a 3D rack): the data of :func:`seisrack.dynamics.local.simulate_local`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.sliders import mass_and_friction
from seisrack.errors import InputError


@dataclass(frozen=True)
class LocalSliders:
    """support: (m, k, n_dir) int, the DOF of each of the ``k`` points pallet ``p`` rests on,
    per sliding direction (-1: the ground); the pallet's support motion is their mean and its
    friction force is shared equally. mass [kg], mu_static, mu_dynamic (0 <= mu_d <= mu_s):
    (m,) or scalars."""

    support: np.ndarray
    mass: np.ndarray
    mu_static: np.ndarray
    mu_dynamic: np.ndarray

    def __init__(self, support, mass, mu_static, mu_dynamic=None) -> None:  # noqa: ANN001
        sup = np.asarray(support)
        if sup.ndim == 1:
            sup = sup[:, None, None]
        elif sup.ndim == 2:
            sup = sup[:, :, None]
        if sup.ndim != 3 or sup.shape[2] not in (1, 2) or (sup.size and sup.shape[1] < 1):
            raise InputError("sliders.support", f"shape {sup.shape}",
                             "(pallets, supports, directions) with 1 or 2 directions")
        if sup.size and not np.all(np.equal(np.mod(sup, 1), 0)):
            raise InputError("sliders.support", "non-integer entries", "integer DOF indices")
        mass_a, mus, mud = mass_and_friction(sup.shape[0], mass, mu_static, mu_dynamic)
        object.__setattr__(self, "support", sup.astype(np.int64))
        object.__setattr__(self, "mass", mass_a)
        object.__setattr__(self, "mu_static", mus)
        object.__setattr__(self, "mu_dynamic", mud)

    @property
    def count(self) -> int:
        return int(self.support.shape[0])

    @property
    def n_dir(self) -> int:
        return int(self.support.shape[2])

    def patterns(self, n: int) -> sp.csc_matrix:
        """(n, m n_dir) friction force pattern of each pallet and direction (column
        ``p n_dir + d``), shared by its supports."""
        m, k, nd = self.support.shape
        rows, cols, vals = [], [], []
        for d in range(nd):
            for s in range(k):
                on = self.support[:, s, d] >= 0
                rows.append(self.support[on, s, d])
                cols.append(np.flatnonzero(on) * nd + d)
                vals.append(np.full(int(on.sum()), 1.0 / k))
        if not rows:
            return sp.csc_matrix((n, m * nd))
        return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                    np.concatenate(cols))), shape=(n, m * nd))

    def attached_mass(self, n: int) -> sp.csr_matrix:
        """(n, n) the pallets' horizontal masses, shared by their supports (rigidly
        attached)."""
        m, k, nd = self.support.shape
        d = self.support.reshape(m, k * nd)
        on = d >= 0
        w = np.repeat(self.mass / k, k * nd).reshape(m, k * nd)
        mat = sp.csr_matrix((w[on], (d[on], d[on])), shape=(n, n))
        mat.sum_duplicates()
        return mat
