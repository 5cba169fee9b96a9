"""The factors of the design analysis, in one table a user can override.

Every field names its source (:data:`FACTOR_SOURCES`). Values that could not be checked against
the text of the standard are marked *assumption*, here and in ``docs/user/design_analysis.md``,
as :mod:`seisrack.checks.factors` does: the text of EN 16681:2016 and of FEM 10.2.08 was not
available here, so the unit-load factors are placeholders the engineer must check against
their copy of the standard (override them with :meth:`DesignFactors.with_` or
``seisrack design --factors KEY=VALUE``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

from seisrack.errors import InputError

#: the unit-load factors (the rack standard's reductions for the unit loads)
UNIT_LOAD_FACTORS = ("e_d1", "e_d2_down_aisle", "e_d2_cross_aisle", "e_d3")


@dataclass(frozen=True)
class DesignFactors:
    """Factors of :func:`seisrack.design.design_analysis` (see :data:`FACTOR_SOURCES`).

    Unit loads (EN 16681 / FEM 10.2.08; *assumptions*, the standard's values were not
    available here):
        e_d1: unit-load weight modification factor E_D1: the part of the unit loads' weight
            that takes part in the horizontal response (their horizontal mass is
            ``e_d1 · e_d3 · m``).
        e_d2_down_aisle, e_d2_cross_aisle: design spectrum modification factor E_D2 for the
            damping and sliding of the unit loads: multiplies the spectral acceleration of
            every mode in that direction.
        e_d3: rack filling degree E_D3: the fraction of the unit loads present (multiplies
            their horizontal mass).

    Modal response spectrum analysis (EN 1998-1:2004):
        beta: lower bound factor β of the design spectrum, §3.2.2.5(4)P Eqs (3.15)-(3.16),
            recommended value 0.2 (Note).
        damping: viscous damping ratio used in the CQC correlation coefficients and, for an
            elastic analysis (``spectrum="elastic"``), in η of Eq (3.6); 5 % is the reference
            of the elastic spectrum, §3.2.2.2(3).
        well_separated: modes i, j are independent when T_j <= 0.9 T_i, §4.3.3.3.2(2).
        mass_target: the modes taken into account should reach 90 % of the total mass,
            §4.3.3.3.1(3).
        relevant_mass: every mode with an effective mass above 5 % of the total mass is
            taken into account, §4.3.3.3.1(3); the same share decides which modes are
            "relevant" for the SRSS/CQC choice.
        combination_030: the 0.30 of Eqs (4.18)-(4.19), §4.3.3.5.1(3).
        theta_ignore, theta_amplify, theta_max: 0.1, 0.2, 0.3 of §4.4.2.2(2)-(4).
    """

    e_d1: float = 0.8
    e_d2_down_aisle: float = 0.8
    e_d2_cross_aisle: float = 1.0
    e_d3: float = 1.0
    beta: float = 0.2
    damping: float = 0.05
    well_separated: float = 0.9
    mass_target: float = 0.9
    relevant_mass: float = 0.05
    combination_030: float = 0.30
    theta_ignore: float = 0.1
    theta_amplify: float = 0.2
    theta_max: float = 0.3

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise InputError(f"factors.{f.name}", v, "a finite number")
            lo, hi, text = _RANGES[f.name]
            if not lo(v) or not hi(v):
                raise InputError(f"factors.{f.name}", v, text)
        if not (self.theta_ignore <= self.theta_amplify <= self.theta_max):
            raise InputError("factors.theta_*", (self.theta_ignore, self.theta_amplify,
                                                  self.theta_max),
                             "theta_ignore <= theta_amplify <= theta_max")

    def with_(self, **kw: Any) -> DesignFactors:
        """A copy with some factors replaced (an unknown name is an InputError)."""
        known = {f.name for f in fields(self)}
        bad = sorted(set(kw) - known)
        if bad:
            raise InputError("factors", bad[0], ", ".join(sorted(known)))
        return replace(self, **kw)

    def without_unit_load_factors(self) -> DesignFactors:
        """The same table with every unit-load factor 1 (unit loads as rigid masses)."""
        return replace(self, **{k: 1.0 for k in UNIT_LOAD_FACTORS})

    @property
    def mass_factor(self) -> float:
        """E_D1 · E_D3: the share of the unit loads' mass in the horizontal response."""
        return float(self.e_d1 * self.e_d3)

    def e_d2(self, direction: str) -> float:
        """E_D2 of ``direction`` ("down-aisle" or "cross-aisle")."""
        return float(self.e_d2_cross_aisle if direction == "cross-aisle"
                     else self.e_d2_down_aisle)

    def as_dict(self) -> dict[str, float]:
        return {f.name: float(getattr(self, f.name)) for f in fields(self)}


def _gt0(v: float) -> bool:
    return v > 0


def _ge0(v: float) -> bool:
    return v >= 0


def _le1(v: float) -> bool:
    return v <= 1


def _lt1(v: float) -> bool:
    return v < 1


def _any(v: float) -> bool:
    return True


_RANGES = {
    "e_d1": (_gt0, _le1, "a factor in (0, 1]"),
    "e_d2_down_aisle": (_gt0, _le1, "a factor in (0, 1]"),
    "e_d2_cross_aisle": (_gt0, _le1, "a factor in (0, 1]"),
    "e_d3": (_gt0, _le1, "a filling degree in (0, 1]"),
    "beta": (_ge0, _le1, "a lower-bound factor in [0, 1] (EN 1998-1 recommends 0.2)"),
    "damping": (_gt0, _lt1, "a damping ratio in (0, 1), e.g. 0.05"),
    "well_separated": (_gt0, _le1, "a period ratio in (0, 1] (EN 1998-1: 0.9)"),
    "mass_target": (_gt0, _le1, "a mass share in (0, 1] (EN 1998-1: 0.9)"),
    "relevant_mass": (_ge0, _le1, "a mass share in [0, 1] (EN 1998-1: 0.05)"),
    "combination_030": (_ge0, _le1, "a factor in [0, 1] (EN 1998-1: 0.30)"),
    "theta_ignore": (_ge0, _any, "a number >= 0"),
    "theta_amplify": (_ge0, _any, "a number >= 0"),
    "theta_max": (_ge0, _lt1, "a number in [0, 1)"),
}

_ASSUMED = ("assumption: the text of EN 16681 / FEM 10.2.08 was not available here; "
            "a placeholder to check against the standard")

#: the source of each factor (shown by the CLI, the report and the --json output)
FACTOR_SOURCES: dict[str, str] = {
    "e_d1": f"EN 16681 / FEM 10.2.08 unit-load weight modification factor E_D1; {_ASSUMED}",
    "e_d2_down_aisle": "EN 16681 / FEM 10.2.08 design spectrum modification factor E_D2, "
                       f"down-aisle; {_ASSUMED}",
    "e_d2_cross_aisle": "EN 16681 / FEM 10.2.08 design spectrum modification factor E_D2, "
                        "cross-aisle; assumption: 1 (no reduction), the standard's value was "
                        "not available here",
    "e_d3": "EN 16681 / FEM 10.2.08 rack filling degree E_D3; assumption: 1 (every "
            "compartment loaded), set the filling degree of the warehouse",
    "beta": "EN 1998-1 §3.2.2.5(4)P, Eqs (3.15)-(3.16), recommended value",
    "damping": "EN 1998-1 §3.2.2.2(3) (5 % viscous damping of the reference spectrum)",
    "well_separated": "EN 1998-1 §4.3.3.3.2(2)",
    "mass_target": "EN 1998-1 §4.3.3.3.1(3)",
    "relevant_mass": "EN 1998-1 §4.3.3.3.1(3)",
    "combination_030": "EN 1998-1 §4.3.3.5.1(3), Eqs (4.18)-(4.19)",
    "theta_ignore": "EN 1998-1 §4.4.2.2(2)",
    "theta_amplify": "EN 1998-1 §4.4.2.2(3)",
    "theta_max": "EN 1998-1 §4.4.2.2(4)",
}


def parse_factor_overrides(items: list[str] | None, base: DesignFactors | None = None
                           ) -> DesignFactors:
    """``["e_d1=0.9", ...]`` (the CLI's ``--factors``) applied to ``base``."""
    f = base or DesignFactors()
    kw: dict[str, float] = {}
    for item in items or ():
        key, sep, val = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError("--factors", item, "KEY=VALUE, e.g. e_d1=0.8")
        try:
            kw[key] = float(val)
        except ValueError:
            raise InputError(f"--factors {key}", val, "a number") from None
    return f.with_(**kw)
