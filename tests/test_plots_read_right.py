"""Figures that read right (issue 23, class 6, outside the time-history text).

- A "separated" fragility fit (the maximum-likelihood curve is a step, β undetermined) is not
  drawn as a step to probability 1 through a stripe observed at 0.33: the observed fractions
  are joined, θ is marked, and the legend says the fit is separated. A regular fit is drawn
  as its lognormal curve (the reference: ``seisrack.lognormal.fragility_curve``).
- The sliding heat map of a rack whose pallets all slid alike (the paper rack under El
  Centro: four pallets at 7.66 mm) is not one black block, says that they slid alike, and its
  pallet numbers contrast with their cells.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgba  # noqa: E402

from rack_inputs import PAPER_RACK  # noqa: E402
from seisrack.lognormal import fragility_curve  # noqa: E402
from seisrack.report.fragility_plot import fit_is_drawable, plot_fragility  # noqa: E402
from seisrack.studies import fragility as fr  # noqa: E402


def _lum(rgba) -> float:  # noqa: ANN001
    r, g, b, _ = to_rgba(rgba)
    return 0.299 * r + 0.587 * g + 0.114 * b


def test_separated_fit_is_not_drawn_as_a_step():
    im, n, k = np.array([1.0, 2.0, 4.0]), np.array([3, 3, 3]), np.array([0, 1, 3])
    fit = fr.fit_fragility(im, n, k)
    assert fit.status == "separated" and fit.beta == 0.0 and fit.theta == pytest.approx(2.0)
    ax = plot_fragility(im, k / n, fit.theta, fit.beta, label="sliding>0.05m: fitted",
                        status=fit.status)
    curves = [ln for ln in ax.get_lines() if len(ln.get_xdata()) > 2 or
              not np.allclose(ln.get_xdata(), ln.get_xdata()[0])]
    for ln in curves:  # every drawn line passes through the data: 0.33 at IM = 2
        x, y = np.asarray(ln.get_xdata(), float), np.asarray(ln.get_ydata(), float)
        at = np.isclose(x, 2.0)
        assert np.allclose(y[at], 1.0 / 3.0), (x, y)
        assert not np.any((y > 0.9) & (x < 3.9))  # no jump to 1 before the last stripe
    theta_lines = [ln for ln in ax.get_lines() if np.allclose(ln.get_xdata(), 2.0)]
    assert theta_lines  # θ is marked where the step lies
    labels = " ".join(t.get_text() for t in ax.get_legend().get_texts())
    assert "separated" in labels and "β undetermined" in labels
    plt.close(ax.figure)


def test_regular_fit_is_drawn_as_its_lognormal():
    im, n, k = np.array([1.0, 2.0, 3.0, 4.0]), np.array([20] * 4), np.array([1, 6, 13, 18])
    fit = fr.fit_fragility(im, n, k)
    assert fit.status == "ok" and fit_is_drawable(fit.theta, fit.beta, fit.status)
    grid = np.linspace(0.05, 6.0, 50)
    ax = plot_fragility(im, k / n, fit.theta, fit.beta, grid=grid, status=fit.status)
    curve = ax.get_lines()[0]
    np.testing.assert_allclose(curve.get_ydata(), fragility_curve(grid, fit.theta, fit.beta))
    plt.close(ax.figure)
    assert not fit_is_drawable(2.0, 0.0, "separated")
    assert not fit_is_drawable(float("nan"), 0.3, "failed")


@pytest.fixture(scope="module")
def alike():
    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import load_builtin_record

    resp = run_rack(compile_rack(load_rack(PAPER_RACK)), load_builtin_record("elcentro_1940_ns"))
    peak = resp.pallet_peak_sliding()
    assert np.ptp(peak) < 1e-3 * peak.max() and peak.max() > 1e-3  # all alike, ~7.7 mm
    return resp


def test_heatmap_of_pallets_that_slid_alike(alike):
    from seisrack.report.rack_plot import plot_sliding_heatmap

    ax = plot_sliding_heatmap(alike)
    img = ax.get_images()[0]
    cells = img.to_rgba(img.get_array())
    colours = cells[~np.ma.getmaskarray(img.get_array())]
    assert min(_lum(c) for c in colours) > 0.15  # not black
    assert "every pallet slid alike: 7.66 mm" in ax.get_title()
    assert len(ax.texts) == 4
    for t in ax.texts:  # each number contrasts with its cell
        r, c = int(round(t.get_position()[1])), int(round(t.get_position()[0]))
        assert abs(_lum(t.get_color()) - _lum(cells[r, c])) > 0.4
    plt.close(ax.figure)
