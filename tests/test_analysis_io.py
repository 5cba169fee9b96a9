"""Writers and figures of a rack time history (issue #5: "time histories saved in a standard
self-describing format (netCDF via xarray), plus a peaks table (CSV)", "figures like Fig. 16a–d").

The netCDF file is netCDF3 written by SciPy (no HDF5 needed); it must reopen with xarray with
the same numbers, units and long names. The peaks table must agree with ``RackResponse.peaks()``.
The overlay figure draws one line per μ, as the paper's Fig. 16 does for μ = 0.80 … 0.30.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from analysis_inputs import paper_model, short_record
from seisrack.analysis import run_rack
from seisrack.report import rack_io, rack_plot

xr = pytest.importorskip("xarray")
pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def responses():
    rec = short_record()
    return {f"μ = {mu:.2f}": run_rack(paper_model(mu), rec) for mu in (0.8, 0.3)}


def test_netcdf_roundtrip(tmp_path: Path, responses):
    resp = responses["μ = 0.30"]
    model = paper_model(0.3)
    path = rack_io.write_timehistory(resp, tmp_path / "th.nc", model=model, title="μ test ×",
                                     summary=resp.summary())
    with xr.open_dataset(path) as ds:
        assert dict(ds.sizes) == {"time": resp.t.size, "level": 1, "pallet": 4, "upright": 3,
                                  "event": len(resp.events)}
        np.testing.assert_array_equal(ds.beam_displacement.values, resp.beam_displacement)
        np.testing.assert_array_equal(ds.pallet_sliding.values, resp.pallet_sliding)
        np.testing.assert_array_equal(ds.time.values, resp.t)
        for name, unit in [("beam_displacement", "m"), ("beam_acceleration", "m s-2"),
                           ("contact_force", "N"), ("base_shear", "N"), ("time", "s"),
                           ("upright_moment_base", "N m"), ("pallet_sliding", "m"),
                           ("pallet_mass", "kg"), ("ground_accel", "m s-2")]:
            assert ds[name].attrs["units"] == unit
            assert ds[name].attrs["long_name"]
        for v in ds.data_vars.values():
            assert "units" in v.attrs and "long_name" in v.attrs, v.name
        assert ds.level_y.values.tolist() == [2.0]
        assert ds.attrs["title"] == "? test ?"  # netCDF3 text is ASCII
        assert json.loads(ds.attrs["summary_json"])["peaks"]["pallet_sliding_m"] == \
            pytest.approx(resp.pallet_peak_sliding().tolist())
        assert ds.event_kind.attrs["flag_meanings"] == "slip stick reverse"


def test_peaks_csv_matches_peaks(tmp_path: Path, responses):
    resp = responses["μ = 0.30"]
    path = rack_io.write_peaks_csv(resp, tmp_path / "peaks.csv")
    rows = list(csv.DictReader(path.open()))
    pk = resp.peaks()
    by = {(r["quantity"], r["pallet"]): r for r in rows}
    assert float(by["beam_displacement", ""]["value"]) == pytest.approx(
        pk["beam_displacement_m"], rel=1e-9)
    assert by["beam_displacement", ""]["unit"] == "m"
    assert float(by["total_contact_force", ""]["value"]) == pytest.approx(
        pk["total_friction_force_N"], rel=1e-9)
    assert float(by["base_shear", ""]["value"]) == pytest.approx(pk["base_shear_N"], rel=1e-9)
    for j in range(4):
        assert float(by["pallet_sliding", str(j + 1)]["value"]) == pytest.approx(
            pk["pallet_sliding_m"][j], rel=1e-9)
        assert float(by["pallet_residual", str(j + 1)]["value"]) == pytest.approx(
            pk["pallet_residual_m"][j], rel=1e-9, abs=1e-15)
    assert all(r["unit"] for r in rows)


def test_atomic_write_keeps_old_file_on_failure(tmp_path: Path):
    target = tmp_path / "keep.txt"
    target.write_text("old")

    def boom(p: Path) -> None:
        p.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        rack_io._atomic_write(target, boom)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["keep.txt"]


@pytest.mark.parametrize("quantity", ["beam_displacement", "beam_acceleration",
                                      "contact_force", "pallet_sliding", "16d", "base_shear"])
def test_overlay_one_line_per_mu(responses, quantity):
    ax = rack_plot.plot_rack_histories(responses, quantity)
    lines = [ln for ln in ax.get_lines() if ln.get_label() in responses]
    assert sorted(ln.get_label() for ln in lines) == sorted(responses)
    assert "[" in ax.get_ylabel() and ax.get_xlabel() == "time [s]"
    assert ax.get_title()
    t, y, _ = rack_plot.rack_history(responses["μ = 0.30"], quantity)
    line = next(ln for ln in lines if ln.get_label() == "μ = 0.30")
    np.testing.assert_allclose(line.get_ydata(), y)
    import matplotlib.pyplot as plt

    plt.close(ax.figure)


def test_contact_force_overlay_draws_caps(responses):
    ax = rack_plot.plot_rack_histories(responses, "contact_force")
    caps = sorted({round(abs(ln.get_ydata()[0]), 6) for ln in ax.get_lines()
                   if ln.get_linestyle() == "--"})
    assert caps == pytest.approx([0.3 * 1600 * 9.81e-3, 0.8 * 1600 * 9.81e-3])
    import matplotlib.pyplot as plt

    plt.close(ax.figure)


def test_save_fig16_and_given_axes(tmp_path: Path, responses):
    import matplotlib.pyplot as plt

    paths = rack_plot.save_fig16(responses, tmp_path)
    assert [p.name for p in paths] == list(rack_plot.FIG16_FILES)
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)
    fig, ax = plt.subplots()
    assert rack_plot.plot_pallet_sliding(responses["μ = 0.30"], ax) is ax
    assert len([ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]) == 8  # ± limits
    plt.close(fig)


def test_unknown_quantity(responses):
    from seisrack.errors import InputError

    with pytest.raises(InputError, match="quantity"):
        rack_plot.plot_rack_histories(responses, "banana")
