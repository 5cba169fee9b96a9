"""``plot_hinge_loops``: one moment–rotation line per selected hinge, in kN·m against mrad,
with the most-demanded connector and base plate by default (Agg backend, no display)."""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.analysis.hinges import HingeResponse
from seisrack.errors import InputError
from seisrack.report.hinge_plot import plot_hinge_loops

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def _hinges() -> HingeResponse:
    t = np.linspace(0.0, 1.0, 50)
    amp = np.array([0.010, 0.030, 0.020, 0.012, 0.020])  # rad
    rot = np.sin(8 * t)[:, None] * amp[None, :]
    mom = np.clip(160e3 * rot, -2500.0, 2500.0)
    return HingeResponse(
        labels=("connector L1 B1 left", "connector L1 B1 right", "connector L1 B2 left",
                "base U1", "base U2"),
        kind=("connector", "connector", "connector", "base", "base"),
        law=("elastic-plastic",) * 5, rotation=rot, moment=mom,
        # demand / theta_y: connectors 0.64, 1.9, 1.28; bases 0.64, 2.56 (U1 < U2)
        yield_rotation=np.array([0.015625, 0.015625, 0.015625, 0.01875, 0.0078125]))


def test_default_draws_most_demanded_connector_and_base() -> None:
    import matplotlib.pyplot as plt

    h = _hinges()
    ax = plot_hinge_loops(h)
    lines = ax.get_lines()
    curves = [ln for ln in lines if ln.get_label() in h.labels]
    assert [ln.get_label() for ln in curves] == ["connector L1 B1 right", "base U2"]
    x, y = curves[0].get_data()
    np.testing.assert_allclose(x, 1e3 * h.rotation[:, 1])
    np.testing.assert_allclose(y, 1e-3 * h.moment[:, 1])
    x, y = curves[1].get_data()
    np.testing.assert_allclose(x, 1e3 * h.rotation[:, 4])
    np.testing.assert_allclose(y, 1e-3 * h.moment[:, 4])
    assert "mrad" in ax.get_xlabel() and "kN" in ax.get_ylabel()
    plt.close("all")


def test_selection_overlay_and_style() -> None:
    import matplotlib.pyplot as plt

    h = _hinges()
    _fig, ax = plt.subplots()
    out = plot_hinge_loops(h, which=[0, "base U1"], ax=ax, label="seisrack", color="C0")
    assert out is ax
    plot_hinge_loops(h, which=0, ax=ax, label="OpenSees", color="C1", linestyle="--")
    curves = [ln for ln in ax.get_lines() if ":" in str(ln.get_label())]
    assert [ln.get_label() for ln in curves] == [
        "seisrack: connector L1 B1 left", "seisrack: base U1", "OpenSees: connector L1 B1 left"]
    assert curves[2].get_linestyle() == "--"
    np.testing.assert_allclose(curves[1].get_data()[1], 1e-3 * h.moment[:, 3])
    plt.close("all")


@pytest.mark.parametrize("which", ["base U9", 7, -9, [], True, 1.5])
def test_bad_selection_is_input_error(which) -> None:
    with pytest.raises(InputError) as err:
        plot_hinge_loops(_hinges(), which=which)
    assert err.value.field == "which"


def test_no_hinges_is_input_error() -> None:
    with pytest.raises(InputError) as err:
        plot_hinge_loops(None)
    assert err.value.field == "hinges"

