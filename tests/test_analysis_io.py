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
                                  "event": len(resp.events), "storey": 1, "beam_end": 4,
                                  "connector": 4, "section": 6}
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


def test_netcdf_ids_labels_design(tmp_path: Path, responses):
    """Issue 14 item 6: the netCDF pallet coordinate holds the 1-based ids of the JSON, with
    their labels; the design histories carry their member labels and match the JSON peaks."""
    resp = responses["μ = 0.30"]
    s = resp.summary()
    path = rack_io.write_timehistory(resp, tmp_path / "th.nc", model=paper_model(0.3))
    with xr.open_dataset(path) as ds:
        assert ds.pallet.values.tolist() == [p["id"] for p in s["pallets"]]
        assert ds.pallet_label.values.tolist() == [p["label"] for p in s["pallets"]]
        assert ds.beam_end_label.values.tolist() == s["design"]["beam_end_moment_Nm"]["labels"]
        np.testing.assert_allclose(np.abs(ds.beam_end_moment.values).max(axis=0),
                                   s["design"]["beam_end_moment_Nm"]["peak_abs"], rtol=1e-12)
        np.testing.assert_allclose(np.abs(ds.upright_axial_force.values).max(axis=0),
                                   s["design"]["upright_axial_force_N"]["peak_abs"], rtol=1e-12)
        assert ds.beam_acceleration_filtered.attrs["filter_hz"] == 20.0
        assert "raw" in ds.beam_acceleration.attrs["long_name"]
    rows = rack_io.peak_rows(resp)
    assert any(r["quantity"] == "beam_acceleration_filtered" for r in rows)
    notes = [r["note"] for r in rows if r["quantity"] == "pallet_sliding"]
    assert notes[1].startswith("L1-B1-S2")


def test_rack_figures_every_level_and_force(tmp_path: Path):
    """The user's rack: one line per level, a heat map cell per pallet with a colour bar, no
    overwrite without force."""
    import matplotlib.pyplot as plt

    from seisrack.errors import InputError
    from seisrack.model import compile_rack, load_rack

    resp = run_rack(compile_rack(load_rack("examples/three_level_rack.toml")), short_record(2.0))
    paths = rack_plot.save_rack_figures(resp, tmp_path)
    assert [p.name for p in paths] == list(rack_plot.RACK_FIGURES)
    assert all(p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for p in paths)
    with pytest.raises(InputError, match="--force"):
        rack_plot.save_rack_figures(resp, tmp_path)
    assert len(rack_plot.save_rack_figures(resp, tmp_path, force=True)) == 5
    ax = rack_plot.plot_levels(resp, "beam_displacement")
    assert [ln.get_label() for ln in ax.get_lines()][:3] == ["level 1", "level 2", "level 3"]
    plt.close(ax.figure)
    val, ids, n_slot = rack_plot.sliding_grid(resp)
    assert val.shape == (3, 6) and n_slot == 2
    assert ids.tolist() == [[1, 2, 3, 4, 5, 6], [7, 8, 9, 10, 11, 12], [13, 14, 15, 16, 17, 18]]
    np.testing.assert_allclose(val.ravel(), resp.pallet_peak_sliding())
    ax = rack_plot.plot_sliding_heatmap(resp)
    assert len(ax.figure.axes) == 2  # the heat map and its colour bar
    assert sorted(int(t.get_text()) for t in ax.texts) == list(range(1, 19))
    plt.close(ax.figure)
