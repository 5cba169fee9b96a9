"""The sliding reduction of a study (issue 24 item 2): per intensity and friction, the peaks with
sliding pallets over the same with the pallets held rigidly (the rigid companion run of each
record and intensity, :func:`seisrack.studies.executors.run_one`), with mean and lognormal
dispersion, and the points of the ratio against μ/α for the figure.

α is the rigid run's peak absolute level acceleration over g (column ``rigid_alpha``); the
code's assumed reduction (E_D1·E_D2·E_D3 of :class:`seisrack.design.DesignFactors`) is given
beside it. Statistics as :func:`seisrack.design.sliding_reduction.ratio_statistics`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from seisrack.design.sliding_reduction import QUANTITIES, nominal_code_reduction, ratio_statistics

#: store columns this summary reads (numbers)
COLUMNS = tuple(c for pair in QUANTITIES.values() for c in pair[:2]) + ("rigid_alpha",)


def _ratios(r: dict[str, np.ndarray], idx: np.ndarray) -> dict[str, np.ndarray]:
    out = {}
    for key, (col, rcol, _) in QUANTITIES.items():
        a, b = r[col][idx], r[rcol][idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            out[key] = np.where(b > 0, a / b, np.nan)
    return out


def reduction_summary(r: dict[str, np.ndarray], idx: np.ndarray) -> dict[str, Any] | None:
    """The sliding reduction of the "ok" runs ``idx`` of one group (None without rigid peaks).

    r: the study's columns as arrays (``summary.runs_as_arrays``, with :data:`COLUMNS`).
    Rows per intensity (and per μ when the friction takes repeated values): ``n`` runs and the
    statistics of each ratio; ``points``: every run's μ/α and ratios, for the figure.
    """
    ok = idx[r["status"][idx] == "ok"]
    have = ok[np.isfinite(r["rigid_base_shear_N"][ok])]
    if have.size == 0:
        return None
    ratios = _ratios(r, have)
    alpha = r["rigid_alpha"][have]
    mu = r["mu_static"][have]
    im = r["im_target"][have]
    with np.errstate(divide="ignore", invalid="ignore"):
        mu_alpha = np.where(alpha > 0, mu / alpha, np.nan)
    rows = []
    for x in np.unique(im):
        at = im == x
        mus = np.unique(mu[at])
        by_mu = mus.size < at.sum()  # repeated friction values: one row per μ
        for m in (mus if by_mu else [None]):
            sel = at & (mu == m) if m is not None else at
            row: dict[str, Any] = {"im": float(x), "mu_static": None if m is None else float(m),
                                   "n": int(sel.sum()),
                                   "alpha_mean": float(np.nanmean(alpha[sel]))}
            for key in QUANTITIES:
                row[key] = ratio_statistics(ratios[key][sel])
            rows.append(row)
    return {
        "quantities": {k: v[2] for k, v in QUANTITIES.items()},
        "rows": rows,
        "overall": {k: ratio_statistics(ratios[k]) for k in QUANTITIES},
        "n_runs": int(have.size), "n_runs_without_rigid": int(ok.size - have.size),
        "points": {"record": [str(v) for v in r["record"][have]], "im": im.tolist(),
                   "mu_static": mu.tolist(), "alpha": alpha.tolist(),
                   "mu_over_alpha": [None if not math.isfinite(v) else float(v)
                                     for v in mu_alpha],
                   **{k: [None if not math.isfinite(v) else float(v) for v in ratios[k]]
                      for k in QUANTITIES}},
        "code_nominal": nominal_code_reduction(),
    }


def format_reduction(red: dict[str, Any]) -> list[str]:
    """Text lines of :func:`reduction_summary` for ``study summary``."""
    def cell(st: dict[str, Any]) -> str:
        if not st["n"]:
            return f"{'-':>13}"
        beta = "-" if st["beta"] is None else f"{st['beta']:.2f}"
        return f"{st['mean']:>6.3f} ({beta:>4})"

    lines = ["  sliding reduction, peak with sliding / peak with rigid pallets: mean (beta)",
             f"  {'IM':>7} {'mu':>6} {'n':>4} {'alpha':>6} {'base shear':>13} "
             f"{'connector M':>13} {'upright M':>13}"]
    for row in red["rows"]:
        mu = "-" if row["mu_static"] is None else f"{row['mu_static']:.3g}"
        lines.append(f"  {row['im']:>7.3g} {mu:>6} {row['n']:>4} {row['alpha_mean']:>6.3f} "
                     + " ".join(cell(row[k]) for k in QUANTITIES))
    nom = red["code_nominal"]
    lines.append(f"  code's assumed reduction E_D1·E_D2·E_D3 = {nom['down-aisle']:.3f} "
                 "down-aisle (factors are assumptions, see docs/user/design_analysis.md)")
    return lines
