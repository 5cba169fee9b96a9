"""Figure of the site hazard curve beside the fitted fragilities (issue 24 item 3)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from matplotlib.axes import Axes


def plot_risk(risk: dict[str, Any], *,
              ax: Axes | None = None) -> Axes:
    """The hazard curve H(x) [1/yr] (log scale, left axis) and, on a right axis, each fitted
    fragility of the curve's measure with the FEMA P-58 storage-rack fragility (dashed) as an
    outside reference; x in the study's units [m/s²]. Returns the left Axes."""
    from seisrack.lognormal import fragility_curve

    if ax is None:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=(7.0, 4.6))
    hz = risk["hazard"]
    x = np.asarray(hz["im_m_s2"], dtype=float)
    ax.loglog(x, hz["annual_frequency"], "k.-", label="site hazard H(x)")
    ax.set_xlabel(f"{risk['measure'].upper()} [m/s²]")
    ax.set_ylabel("annual frequency of exceedance [1/yr]")
    ax.grid(True, which="both", alpha=0.3)
    right = ax.twinx()
    grid = np.geomspace(x.min(), x.max(), 300)
    for f in risk["fragilities"]:
        th, be = f.get("theta_m_s2"), f.get("beta")
        if th is None or be is None:
            continue
        lam = f.get("annual_rate")
        right.plot(grid, fragility_curve(grid, th, be),
                   label=f"{f['name']} ({f['analysis']}): λ = {lam:.2e}/yr")
    ref = risk.get("reference")
    if ref:
        right.plot(grid, fragility_curve(grid, ref["theta_m_s2"], ref["beta"]), "k--", lw=1,
                   label=f"{ref['name']} (0.42 g, β 0.40): λ = {ref['annual_rate']:.2e}/yr")
    right.set_ylim(0.0, 1.02)
    right.set_ylabel("P(exceed | IM) [-]")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = right.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, fontsize="x-small", loc="lower left")
    return ax
