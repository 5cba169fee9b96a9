"""Design spectra: a pluggable protocol and the EN 1998-1:2004 elastic spectra.

Any object with ``name``, ``pga`` [m/s²], ``damping`` and ``psa(periods) -> (n,) [m/s²]``
satisfies :class:`DesignSpectrum`, so another code's spectrum can be used by the generator and the
checks without changing them.

EN 1998-1 (Eurocode 8, part 1):

- horizontal elastic spectrum, §3.2.2.2, Eqs. (3.2)–(3.5), parameters Table 3.2 (Type 1) and
  Table 3.3 (Type 2);
- damping correction η = √(10 / (5 + ξ[%])) ≥ 0.55, Eq. (3.6);
- design ground acceleration on ground A, a_g = γ_I · a_gR, §3.2.1(3);
- vertical elastic spectrum, §3.2.2.3, Eqs. (3.8)–(3.11), Table 3.4 (a_vg / a_g, T_B, T_C, T_D).

The code defines the spectra up to T = 4 s. Beyond 4 s this module keeps the T_D–4 s branch
(∝ 1/T²), which is what spectral matching needs as a smooth continuation; Annex A is not applied.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from seisrack.errors import InputError
from seisrack.motion.records import G

# Table 3.2 (Type 1) and Table 3.3 (Type 2): ground type -> (S, T_B [s], T_C [s], T_D [s])
EC8_HORIZONTAL: dict[int, dict[str, tuple[float, float, float, float]]] = {
    1: {
        "A": (1.00, 0.15, 0.40, 2.0),
        "B": (1.20, 0.15, 0.50, 2.0),
        "C": (1.15, 0.20, 0.60, 2.0),
        "D": (1.35, 0.20, 0.80, 2.0),
        "E": (1.40, 0.15, 0.50, 2.0),
    },
    2: {
        "A": (1.00, 0.05, 0.25, 1.2),
        "B": (1.35, 0.05, 0.25, 1.2),
        "C": (1.50, 0.10, 0.25, 1.2),
        "D": (1.80, 0.10, 0.30, 1.2),
        "E": (1.60, 0.05, 0.25, 1.2),
    },
}
# Table 3.4: spectrum type -> (a_vg / a_g, T_B [s], T_C [s], T_D [s])
EC8_VERTICAL: dict[int, tuple[float, float, float, float]] = {
    1: (0.90, 0.05, 0.15, 1.0),
    2: (0.45, 0.05, 0.15, 1.0),
}


@runtime_checkable
class DesignSpectrum(Protocol):
    """What the generator and the suite checks need from a target spectrum."""

    name: str
    damping: float

    @property
    def pga(self) -> float:
        """[m/s²] zero-period spectral acceleration."""
        ...

    def psa(self, periods: np.ndarray) -> np.ndarray:
        """(n,) [m/s²] pseudo-spectral acceleration at ``periods`` (n,) [s]."""
        ...


def damping_correction(damping: float) -> float:
    """η = √(10 / (5 + ξ)) ≥ 0.55 with ξ in percent, EN 1998-1 Eq. (3.6). ``damping`` is a ratio."""
    return max(math.sqrt(10.0 / (5.0 + 100.0 * damping)), 0.55)


@dataclass(frozen=True)
class EC8Spectrum:
    """EN 1998-1 elastic response spectrum (horizontal §3.2.2.2 or vertical §3.2.2.3).

    Attributes:
        ag: [m/s²] design ground acceleration on type A ground, already including γ_I.
        S: soil factor (1.0 for the vertical spectrum, which has none).
        TB, TC, TD: [s] corner periods.
        damping: viscous damping ratio ξ (0.05 = 5 %).
        plateau: spectral amplification, 2.5 horizontal (Eq. 3.3), 3.0 vertical (Eq. 3.9).
        scale: a_vg / a_g for the vertical spectrum (Table 3.4), 1.0 horizontal.
        name: label, e.g. ``"EC8 type 1 ground C"``.
    """

    ag: float
    S: float
    TB: float
    TC: float
    TD: float
    damping: float = 0.05
    plateau: float = 2.5
    scale: float = 1.0
    name: str = "EC8"

    @property
    def eta(self) -> float:
        """Damping correction factor η, Eq. (3.6)."""
        return damping_correction(self.damping)

    @property
    def pga(self) -> float:
        """[m/s²] spectral value at T = 0: a_g·S (horizontal) or a_vg (vertical)."""
        return self.ag * self.S * self.scale

    def psa(self, periods: np.ndarray | float) -> np.ndarray:
        """(n,) [m/s²] elastic spectral acceleration S_e(T), Eqs. (3.2)–(3.5) / (3.8)–(3.11)."""
        T = np.atleast_1d(np.asarray(periods, dtype=np.float64))
        if np.any(~np.isfinite(T)) or np.any(T < 0):
            raise InputError("periods", periods, "finite periods >= 0 s")
        a0 = self.ag * self.S * self.scale
        top = a0 * self.eta * self.plateau
        out = np.empty_like(T)
        r1 = T <= self.TB
        out[r1] = a0 * (1.0 + T[r1] / self.TB * (self.eta * self.plateau - 1.0))  # Eq. 3.2 / 3.8
        r2 = (T > self.TB) & (T <= self.TC)
        out[r2] = top  # Eq. 3.3 / 3.9
        r3 = (T > self.TC) & (T <= self.TD)
        out[r3] = top * self.TC / T[r3]  # Eq. 3.4 / 3.10
        r4 = T > self.TD
        out[r4] = top * self.TC * self.TD / T[r4] ** 2  # Eq. 3.5 / 3.11
        return out


#: [g] largest reference peak ground acceleration a spectrum is built for: EN 1998-1's national
#: zonation maps stay below 1 g; far above, the value is a unit slip (m/s² given as g), and
#: at 1e300 g the design forces overflowed to inf with the run reported "ok"
AG_MAX_G = 3.0
#: largest importance factor γ_I (EN 1998-1 Table 4.3 gives 0.8–1.4)
IMPORTANCE_MAX = 3.0


def ec8_spectrum(
    type: int | str = 1,
    ground: str = "C",
    ag: float = 0.3,
    *,
    damping: float = 0.05,
    importance: float = 1.0,
    direction: str = "horizontal",
    ag_units: str = "g",
) -> EC8Spectrum:
    """Build an EN 1998-1 elastic spectrum.

    Args:
        type: spectrum type 1 (Ms > 5.5) or 2.
        ground: ground type ``"A"``–``"E"`` (ignored for the vertical spectrum).
        ag: reference peak ground acceleration on type A ground a_gR, in ``ag_units``.
        damping: viscous damping ratio ξ (0 ≤ ξ < 1), 0.05 for 5 %.
        importance: importance factor γ_I; the spectrum uses a_g = γ_I · a_gR (§3.2.1(3)).
        direction: ``"horizontal"`` (§3.2.2.2) or ``"vertical"`` (§3.2.2.3).
        ag_units: ``"g"`` (default) or ``"m/s2"``.

    Returns:
        an :class:`EC8Spectrum`; ``.psa(periods)`` gives (n,) [m/s²].
    """
    try:
        kind = int(type)
    except (TypeError, ValueError):
        kind = -1
    if kind not in (1, 2):
        raise InputError("type", type, "1 or 2")
    units = ag_units.strip().lower() if isinstance(ag_units, str) else ag_units
    if units not in ("g", "m/s2"):
        raise InputError("ag_units", ag_units, "'g' or 'm/s2'")
    top = AG_MAX_G * (1.0 if units == "g" else G)
    if not (isinstance(ag, int | float) and math.isfinite(ag) and 0 < ag <= top):
        raise InputError("ag", ag, f"a peak ground acceleration > 0 and <= {top:g} "
                         + ("g" if units == "g" else f"m/s² ({AG_MAX_G:g} g)"))
    if not (isinstance(damping, int | float) and 0.0 <= damping < 1.0):
        raise InputError("damping", damping, "a damping ratio in [0, 1), e.g. 0.05")
    if not (isinstance(importance, int | float) and math.isfinite(importance)
            and 0 < importance <= IMPORTANCE_MAX):
        raise InputError("importance", importance, f"an importance factor > 0 and <= "
                         f"{IMPORTANCE_MAX:g} (EN 1998-1 Table 4.3: 0.8–1.4)")
    ag_si = float(ag) * (G if units == "g" else 1.0) * float(importance)
    if direction == "horizontal":
        g = str(ground).strip().upper()
        if g not in EC8_HORIZONTAL[kind]:
            raise InputError("ground", ground, "A, B, C, D or E (S1/S2 need a site study)")
        S, TB, TC, TD = EC8_HORIZONTAL[kind][g]
        return EC8Spectrum(
            ag_si, S, TB, TC, TD, float(damping), 2.5, 1.0, f"EC8 type {kind} ground {g}"
        )
    if direction == "vertical":
        ratio, TB, TC, TD = EC8_VERTICAL[kind]
        return EC8Spectrum(
            ag_si, 1.0, TB, TC, TD, float(damping), 3.0, ratio, f"EC8 type {kind} vertical"
        )
    raise InputError("direction", direction, "'horizontal' or 'vertical'")
