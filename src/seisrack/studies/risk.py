"""Risk per year: a site hazard curve and a lognormal fragility give the mean annual frequency.

    λ_DS = ∫ P(DS | IM = x) |dH(x)| = ∫ H(x) f(x) dx          (integration by parts)

with H(x) the annual frequency of exceeding IM = x (the site's hazard curve) and
P(DS | x) = Φ(ln(x/θ)/β) the fragility (:mod:`seisrack.studies.fragility`), f its density.
The probability of at least one exceedance in t years (Poisson) is 1 − exp(−λ t), t = 50.

*Tabulated curve.* H is interpolated linearly in log-log between the points (a power law
H = k0·x^(−k) on each interval) and extended beyond the first and last points by the power
laws of the end intervals. On each interval the integral of H times the lognormal density has
a closed form, ∫ e^(a+bu) N(u; ln θ, β²) du = e^(a + b ln θ + b²β²/2) [Φ(·) − Φ(·)], so the
integral of the interpolated curve is exact; the only approximation is the interpolation
(second order in the spacing of the points in ln x; docs/theory/hazard_integration.md). The
share of λ that comes from the extrapolated tails is reported.

*Closed form* (Cornell et al. 2002, J. Struct. Eng. 128(4), Eq 10; Jalayer 2003): for a power
law H = k0·x^(−k) and β > 0, λ = k0·θ^(−k)·exp(k²β²/2) (:func:`power_law_rate`).

The hazard curve file (CSV, docs/user/hazard_curve.md)::

    # measure = pga          (or sa: Sa(T1) of the rack at the study's damping)
    # units = g              (g, m/s2, cm/s2 or gal)
    # source = ...           (optional)
    im,annual_frequency
    0.05,2.1e-2
    ...
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy import special

from seisrack.errors import FileFormatError, InputError
from seisrack.motion.records import G

#: accepted units of the hazard curve's intensity, with their factor to m/s²
UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0, "cm/s2": 0.01, "gal": 0.01}
MEASURES = ("pga", "sa")
YEARS = 50.0

#: the FEMA P-58 storage-rack fragility, an outside reference (PGA = peak floor acceleration
#: for a rack on the ground floor): median 0.42 g, β 0.40
FEMA_P58_RACK = {"name": "FEMA P-58 storage racks", "measure": "pga",
                 "theta_m_s2": 0.42 * G, "beta": 0.40,
                 "source": "FEMA P-58 fragility database as distributed in NIST's open "
                           "fragility database: storage racks, median peak floor acceleration "
                           "0.42 g, dispersion 0.40 (values as given in issue 24; the "
                           "database entry itself was not available here)"}


@dataclass(frozen=True)
class HazardCurve:
    """A site hazard curve in SI.

    im: (n,) [m/s²] increasing intensities; rate: (n,) [1/yr] decreasing annual frequencies of
    exceedance; measure: "pga" or "sa"; units_given: the file's units; source: a note.
    """

    im: np.ndarray
    rate: np.ndarray
    measure: str
    units_given: str = "m/s2"
    source: str = ""

    def __call__(self, x: Any) -> np.ndarray:
        """H(x) [1/yr], log-log interpolation, power-law extension beyond the ends."""
        lx, ly = np.log(self.im), np.log(self.rate)
        u = np.log(np.asarray(x, dtype=float))
        k = np.clip(np.searchsorted(lx, u) - 1, 0, lx.size - 2)
        slope = (ly[k + 1] - ly[k]) / (lx[k + 1] - lx[k])
        return np.exp(ly[k] + slope * (u - lx[k]))


def hazard_curve(im: Any, rate: Any, measure: str = "pga", *, units: str = "m/s2",
                 source: str = "", field: str = "hazard") -> HazardCurve:
    """A validated :class:`HazardCurve` from arrays in ``units``: at least 2 points, finite,
    positive, intensities strictly increasing and frequencies strictly decreasing."""
    if measure not in MEASURES:
        raise InputError(f"{field}.measure", measure, "pga or sa")
    key = str(units).strip().lower()
    if key not in UNITS:
        raise InputError(f"{field}.units", units, "an acceleration unit: g, m/s2, cm/s2 or gal")
    x = np.asarray(im, dtype=float).ravel()
    h = np.asarray(rate, dtype=float).ravel()
    if x.size != h.size:
        raise InputError(f"{field}", (x.size, h.size), "as many frequencies as intensities")
    if x.size < 2:
        raise InputError(f"{field}.points", int(x.size), "at least 2 points")
    if not (np.all(np.isfinite(x)) and np.all(x > 0)):
        raise InputError(f"{field}.im", x.tolist(), "finite intensities > 0")
    if not (np.all(np.isfinite(h)) and np.all(h > 0)):
        raise InputError(f"{field}.annual_frequency", h.tolist(), "finite frequencies > 0 [1/yr]")
    if np.any(np.diff(x) <= 0):
        raise InputError(f"{field}.im", x.tolist(), "strictly increasing intensities")
    if np.any(np.diff(h) >= 0):
        i = int(np.flatnonzero(np.diff(h) >= 0)[0])
        raise InputError(f"{field}.annual_frequency", h.tolist(),
                         f"frequencies decreasing with the intensity (row {i + 2} is not below "
                         f"row {i + 1})")
    return HazardCurve(x * UNITS[key], h, measure, key, source)


def load_hazard_curve(path: str | Path, measure: str | tuple[str, ...] | None = None
                      ) -> HazardCurve:
    """Read a hazard curve CSV (module docstring); ``measure``: the study's (one or several),
    which the curve's must be."""
    p = Path(path)
    if not p.is_file():
        raise InputError("--hazard", str(p), "an existing hazard curve CSV file")
    meta: dict[str, str] = {}
    rows: list[list[str]] = []
    try:
        text = p.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise FileFormatError(str(p), f"not UTF-8 text ({exc.reason})") from None
    lines = text.splitlines()
    for n, line in enumerate(lines, 1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, sep, val = s.lstrip("#").partition("=")
            if sep:
                meta[key.strip().lower()] = val.strip()
            continue
        rows.append([c.strip() for c in next(csv.reader([s]))] + [str(n)])
    if not rows:
        raise FileFormatError(str(p), "no data rows (im,annual_frequency)")
    head = [c.lower() for c in rows[0][:-1]]
    if head[:2] != ["im", "annual_frequency"]:
        raise FileFormatError(str(p), f"the first row must be the header "
                              f"'im,annual_frequency', got {','.join(rows[0][:-1])!r}",
                              int(rows[0][-1]))
    for key in ("measure", "units"):
        if key not in meta:
            raise InputError(f"{p.name}: {key}", None, f"a header line '# {key} = ...' "
                             + ("(pga or sa)" if key == "measure" else "(g, m/s2, cm/s2 or "
                                                                        "gal)"))
    x, h = [], []
    for r in rows[1:]:
        try:
            x.append(float(r[0]))
            h.append(float(r[1]))
        except (ValueError, IndexError):
            raise FileFormatError(str(p), f"expected two numbers, got {','.join(r[:-1])!r}",
                                  int(r[-1])) from None
    got = meta["measure"].lower()
    allowed = (measure,) if isinstance(measure, str) else measure
    if allowed is not None and got not in allowed:
        raise InputError(f"{p.name}: measure", got,
                         f"the study's intensity measure, {' or '.join(allowed)}",
                         hint="Give a hazard curve of the study's measure (PGA for "
                              "measure = \"pga\", Sa(T1) at the rack's period for \"sa\")")
    return hazard_curve(x, h, got, units=meta["units"], source=meta.get("source", ""),
                        field=p.name)


def power_law_rate(k0: float, k: float, theta: float, beta: float) -> float:
    """λ = k0·θ^(−k)·exp(k²β²/2) for H = k0·x^(−k) (Cornell et al. 2002, Eq 10)."""
    return float(k0 * theta ** (-k) * math.exp(0.5 * k * k * beta * beta))


def annual_rate(curve: HazardCurve, theta: float, beta: float) -> dict[str, float]:
    """λ [1/yr] of the lognormal fragility (θ [m/s²], β) on ``curve``, with the share from the
    extrapolated tails and the probability in 50 years (``p50``)."""
    if not (math.isfinite(theta) and theta > 0 and math.isfinite(beta) and beta >= 0):
        raise InputError("fragility", (theta, beta), "a median theta > 0 and beta >= 0")
    lx, ly = np.log(curve.im), np.log(curve.rate)
    mu = math.log(theta)
    if beta == 0.0:  # a step at θ: λ = H(θ)
        lam = float(curve(theta))
        tail = 0.0 if lx[0] <= mu <= lx[-1] else 1.0
        return _rates(lam, tail)
    b = np.diff(ly) / np.diff(lx)  # slope of ln H in ln x on each interval
    a = ly[:-1] - b * lx[:-1]
    edges = [(-np.inf, lx[0], a[0], b[0])] + [
        (lx[i], lx[i + 1], a[i], b[i]) for i in range(lx.size - 1)] + [
        (lx[-1], np.inf, a[-1], b[-1])]
    parts = np.array([_segment(lo, hi, ai, bi, mu, beta) for lo, hi, ai, bi in edges])
    lam = float(parts.sum())
    tail = float((parts[0] + parts[-1]) / lam) if lam > 0 else 0.0
    return _rates(lam, tail)


def _segment(lo: float, hi: float, a: float, b: float, mu: float, beta: float) -> float:
    """∫_lo^hi e^(a + b u) N(u; μ, β²) du (closed form)."""
    s = mu + b * beta * beta
    scale = math.exp(a + b * mu + 0.5 * b * b * beta * beta)
    return scale * float(special.ndtr((hi - s) / beta) - special.ndtr((lo - s) / beta))


def _rates(lam: float, tail: float) -> dict[str, float]:
    return {"annual_rate": lam, "return_period_yr": 1.0 / lam if lam > 0 else math.inf,
            "p50": float(-math.expm1(-YEARS * lam)), "extrapolated_share": tail}


def risk_summary(curve: HazardCurve, fragility: list[dict[str, Any]]) -> dict[str, Any]:
    """λ and the 50-year probability of every fitted fragility of a study summary whose
    measure is the curve's, and of the FEMA P-58 storage-rack reference (PGA only)."""
    rows = []
    for f in fragility:
        if f.get("im_measure") != curve.measure:
            continue
        th, be = f.get("theta"), f.get("beta")
        row = {k: f.get(k) for k in ("name", "rack", "analysis", "status")}
        row.update({"theta_m_s2": th, "beta": be})
        if th is None or be is None or not (th > 0 and be >= 0):
            row.update({"annual_rate": None, "p50": None, "return_period_yr": None,
                        "extrapolated_share": None, "note": "no fitted fragility"})
        else:
            row.update(annual_rate(curve, float(th), float(be)))
        rows.append(row)
    ref = None
    if curve.measure == "pga":
        ref = {**FEMA_P58_RACK, **annual_rate(curve, FEMA_P58_RACK["theta_m_s2"],
                                               FEMA_P58_RACK["beta"])}
    return {"measure": curve.measure, "units_given": curve.units_given, "source": curve.source,
            "years": YEARS, "hazard": {"im_m_s2": curve.im.tolist(),
                                       "annual_frequency": curve.rate.tolist()},
            "fragilities": rows, "reference": ref,
            "method": "lambda = integral of H(x) f(x) dx, H interpolated log-log and extended "
                      "by the end power laws, exact per interval; p50 = 1 - exp(-50 lambda)"}


def format_risk(risk: dict[str, Any]) -> list[str]:
    """Text lines of a study summary's ``risk`` entry."""
    def num(x: Any, spec: str) -> str:
        return "-" if x is None else format(x, spec)

    lines = [f"\nrisk per year on the hazard curve {risk.get('file', '')} "
             f"({risk['measure'].upper()}): mean annual frequency, return period, probability "
             f"in {risk['years']:g} years"]
    for f in risk["fragilities"]:
        lines.append(f"  {f['analysis']:7s} {f['name']:22s} lambda {num(f['annual_rate'], '.3e')}"
                     f"/yr  T {num(f['return_period_yr'], '.4g')} yr  "
                     f"P50 {num(f['p50'], '.3%')}"
                     + (f"  ({100 * f['extrapolated_share']:.1f} % from the extrapolated "
                        "tails)" if f.get("extrapolated_share") else ""))
    ref = risk.get("reference")
    if ref:
        lines.append(f"  reference {ref['name']} (median {ref['theta_m_s2'] / G:.2f} g, beta "
                     f"{ref['beta']:.2f}): lambda {ref['annual_rate']:.3e}/yr, P50 "
                     f"{ref['p50']:.3%}")
    return lines
