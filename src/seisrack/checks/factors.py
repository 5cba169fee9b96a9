"""The factors of the design checks, in one table a user can override.

Every field names its source. Values that could not be checked against the text of the
standard are marked *assumption* here and in ``docs/user/design_checks.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from typing import Any

from seisrack.errors import InputError


@dataclass(frozen=True)
class CheckFactors:
    """Factors of :mod:`seisrack.checks` (override with ``dataclasses.replace`` or ``with_``).

    Pallet sliding (FEM 10.2.08 / EN 16681, as published by Castiglioni, *Seismic behaviour of
    steel storage pallet racking systems*, Politecnico di Milano 2008, §"Pallet sliding"):
        gamma_mu: partial factor γ_μS on the pallet–beam friction coefficient ("usually assumed
            γ_μS = 1").
        e_d1_sliding: unit-load weight modification factor E_D1 used for the sliding check
            (the design spectrum is used "with modification factor E_D1 = 1").
        mu_uls: upper-bound static friction for the ULS check; ``None`` = each pallet's
            ``mu_static`` from the rack file (*assumption*: the standard's Table of bounds was
            not available here).
        mu_sls: lower-bound static friction for the SLS check; ``None`` = each pallet's
            ``mu_dynamic`` (*assumption*, as above).
        nu_sls: reduction factor ν of the design action for the damage-limitation (SLS)
            requirement, EN 1998-1 §4.4.3.2(2), recommended 0.5 (importance classes I–II).
        damping: viscous damping ratio of the spectra used for the level accelerations
            (EN 1998-1 §3.2.2.2, 5 %).

    Interstorey drift sensitivity (EN 1998-1 §4.4.2.2(2)-(4)):
        theta_ignore: P-Δ effects need not be taken into account for θ ≤ 0.1.
        theta_amplify: for 0.1 < θ ≤ 0.2 they may be taken into account approximately by
            multiplying the seismic action effects by 1/(1-θ).
        theta_max: θ shall not exceed 0.3.
    """

    gamma_mu: float = 1.0
    e_d1_sliding: float = 1.0
    mu_uls: float | None = None
    mu_sls: float | None = None
    nu_sls: float = 0.5
    damping: float = 0.05
    theta_ignore: float = 0.1
    theta_amplify: float = 0.2
    theta_max: float = 0.3

    def __post_init__(self) -> None:
        for f in fields(self):
            v = getattr(self, f.name)
            if v is None:
                continue
            if not isinstance(v, int | float) or not v == v or v < 0:
                raise InputError(f"checks.{f.name}", v, "a number >= 0")
        if not (self.theta_ignore <= self.theta_amplify <= self.theta_max):
            raise InputError("checks.theta_*", (self.theta_ignore, self.theta_amplify,
                                                 self.theta_max),
                             "theta_ignore <= theta_amplify <= theta_max")
        if not 0 < self.nu_sls <= 1:
            raise InputError("checks.nu_sls", self.nu_sls, "a factor in (0, 1]")

    def with_(self, **kw: Any) -> CheckFactors:
        """A copy with some factors replaced (unknown names are an InputError)."""
        known = {f.name for f in fields(self)}
        bad = sorted(set(kw) - known)
        if bad:
            raise InputError("checks", bad[0], ", ".join(sorted(known)))
        return replace(self, **kw)

    def as_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}


#: the source of each factor (shown in the report and the --json output)
FACTOR_SOURCES: dict[str, str] = {
    "gamma_mu": "FEM 10.2.08 / EN 16681 pallet sliding, as published by Castiglioni (2008)",
    "e_d1_sliding": "FEM 10.2.08 / EN 16681 pallet sliding, as published by Castiglioni (2008)",
    "mu_uls": "assumption: rack-file mu_static (upper bound of the standard not available)",
    "mu_sls": "assumption: rack-file mu_dynamic (lower bound of the standard not available)",
    "nu_sls": "EN 1998-1 §4.4.3.2(2), recommended value",
    "damping": "EN 1998-1 §3.2.2.2 (5 % elastic spectrum)",
    "theta_ignore": "EN 1998-1 §4.4.2.2(2)",
    "theta_amplify": "EN 1998-1 §4.4.2.2(3)",
    "theta_max": "EN 1998-1 §4.4.2.2(4)",
}
