"""The EN 1998-1 design spectrum for elastic analysis, with the behaviour factor q.

EN 1998-1:2004 §3.2.2.5(4)P, horizontal components:

    0 <= T <= T_B:   S_d = a_g·S·[2/3 + T/T_B·(2.5/q − 2/3)]            (3.13)
    T_B <= T <= T_C: S_d = a_g·S·2.5/q                                  (3.14)
    T_C <= T <= T_D: S_d = a_g·S·2.5/q·T_C/T           >= β·a_g         (3.15)
    T_D <= T:        S_d = a_g·S·2.5/q·T_C·T_D/T²      >= β·a_g         (3.16)

with S, T_B, T_C, T_D from Tables 3.2/3.3 (:data:`seisrack.motion.ec8.EC8_HORIZONTAL`),
a_g = γ_I·a_gR (§3.2.1(3)) and β the lower bound factor (recommended 0.2). The design spectrum
carries no damping correction η: q accounts for damping other than 5 % (§3.2.2.5(3)).

With q = 1 this is not the elastic spectrum S_e of §3.2.2.2 below T_B (2/3 instead of 1 at
T = 0); the analysis offers S_e itself (``spectrum="elastic"``) for an elastic comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from seisrack.errors import InputError
from seisrack.motion.ec8 import ec8_spectrum


@dataclass(frozen=True)
class EC8DesignSpectrum:
    """EN 1998-1 §3.2.2.5 design spectrum S_d(T) for a behaviour factor q.

    Attributes:
        ag: [m/s²] design ground acceleration on type A ground (γ_I included).
        S, TB, TC, TD: soil factor and corner periods [s] (Tables 3.2/3.3).
        q: behaviour factor (>= 1).
        beta: lower bound factor β.
        name: label, e.g. ``"EC8 type 1 ground C design, q = 2"``.
        damping: 0.05, nominal (the :class:`~seisrack.motion.ec8.DesignSpectrum` protocol).
    """

    ag: float
    S: float
    TB: float
    TC: float
    TD: float
    q: float = 1.0
    beta: float = 0.2
    name: str = "EC8 design"
    damping: float = 0.05

    @property
    def pga(self) -> float:
        """[m/s²] S_d(0) = 2/3·a_g·S (Eq 3.13 at T = 0)."""
        return 2.0 / 3.0 * self.ag * self.S

    def psa(self, periods: np.ndarray | float) -> np.ndarray:
        """(n,) [m/s²] design spectral acceleration S_d(T), Eqs (3.13)-(3.16)."""
        T = np.atleast_1d(np.asarray(periods, dtype=np.float64))
        if np.any(~np.isfinite(T)) or np.any(T < 0):
            raise InputError("periods", periods, "finite periods >= 0 s")
        a = self.ag * self.S
        plateau = a * 2.5 / self.q
        out = np.empty_like(T)
        r1 = T <= self.TB
        out[r1] = a * (2.0 / 3.0 + T[r1] / self.TB * (2.5 / self.q - 2.0 / 3.0))  # Eq 3.13
        r2 = (T > self.TB) & (T <= self.TC)
        out[r2] = plateau  # Eq 3.14
        r3 = (T > self.TC) & (T <= self.TD)
        out[r3] = np.maximum(plateau * self.TC / T[r3], self.beta * self.ag)  # Eq 3.15
        r4 = T > self.TD
        out[r4] = np.maximum(plateau * self.TC * self.TD / T[r4] ** 2,
                             self.beta * self.ag)  # Eq 3.16
        return out


#: largest behaviour factor accepted: EN 16681 gives racks q up to 4, EN 1998-1 the most
#: ductile steel frames about 6.5; above 10 the value is a slip (q = 1e300 made the design
#: drifts q d_e overflow)
Q_MAX = 10.0


def check_q(q: float, field: str = "q") -> float:
    """q as a float, or an InputError: a behaviour factor >= 1 (1 = elastic)."""
    if isinstance(q, bool) or not isinstance(q, int | float) or not math.isfinite(q) or q < 1 \
            or q > Q_MAX:
        raise InputError(field, q, f"a behaviour factor q >= 1 (1 = elastic) and <= {Q_MAX:g}")
    return float(q)


def design_spectrum(type: int | str = 1, ground: str = "C", ag: float = 0.3, q: float = 1.0,
                    *, importance: float = 1.0, beta: float = 0.2, ag_units: str = "g"
                    ) -> EC8DesignSpectrum:
    """The EN 1998-1 §3.2.2.5 design spectrum (horizontal) for spectrum ``type`` (1 or 2),
    ground type A–E, reference a_gR ``ag`` in ``ag_units`` ("g" or "m/s2"), behaviour factor
    ``q`` (>= 1), importance factor γ_I and lower bound factor ``beta``."""
    q = check_q(q)
    if isinstance(beta, bool) or not isinstance(beta, int | float) or not 0 <= beta <= 1:
        raise InputError("beta", beta, "a lower-bound factor in [0, 1] (EN 1998-1: 0.2)")
    el = ec8_spectrum(type, ground, ag, importance=importance, ag_units=ag_units)
    kind = el.name.replace("EC8 ", "")
    return EC8DesignSpectrum(el.ag, el.S, el.TB, el.TC, el.TD, q, float(beta),
                             f"EC8 {kind} design spectrum, q = {q:g}")


def design_spectra(ec8: tuple[int | str, str, float], q: float | tuple[float, ...],
                   directions: tuple[str, ...], *, importance: float = 1.0,
                   beta: float = 0.2, elastic: bool = False, ag_units: str = "g"
                   ) -> dict[str, object]:
    """{direction: spectrum} for ``seisrack design`` and the report.

    ec8: (type, ground, a_gR); q: one behaviour factor, or one per direction in the order of
    ``directions`` (down-aisle first). ``elastic``: the elastic spectrum S_e of §3.2.2.2 (taken
    at each mode's damping by the analysis) instead of S_d; it needs q = 1.
    """
    qs = (q,) if isinstance(q, int | float) else tuple(q)
    if len(qs) not in (1, len(directions)):
        raise InputError("--q", list(qs), f"one behaviour factor, or one per direction "
                         f"({', '.join(directions)})")
    qs = tuple(check_q(v, "--q") for v in qs)
    if len(qs) == 1:
        qs = qs * len(directions)
    typ, ground, ag = ec8
    if elastic:
        if any(v != 1.0 for v in qs):
            raise InputError("--q", list(qs), "q = 1 with the elastic spectrum (--elastic)")
        el = ec8_spectrum(typ, ground, ag, importance=importance, ag_units=ag_units)
        el = replace(el, name=f"{el.name} elastic spectrum (§3.2.2.2)")
        return {d: el for d in directions}
    return {d: design_spectrum(typ, ground, ag, qd, importance=importance, beta=beta,
                               ag_units=ag_units) for d, qd in zip(directions, qs, strict=True)}
