"""Writers and figures of a 3D rack time history (``report.rack3d_io``, ``report.sliding_paths``).

One run of the 3D paper rack (examples/paper_rack_3d.toml) under El Centro 1940 NS x 3 as both
horizontal components at 30° (every 2nd step kept), strong enough for the pallets to slide
several centimetres and to fall off the 50 mm overhang. Checked:

- the netCDF file reopens with xarray with the documented dimensions and shapes, a ``units``
  and ``long_name`` on every variable, values equal to the response's arrays, ``fall_time``
  NaN exactly for the pallets not in ``resp.falls`` (and equal to their fall times otherwise),
  and the summary stored as JSON;
- the CSV has one row per pallet with the documented columns, and its numbers equal
  ``resp.peak_sliding``, ``resp.residual``, the fall limits and the falls;
- the files have the 2D run's names;
- the figures are written as non-empty PNGs, not overwritten without ``force`` (nothing is
  written then) and overwritten with it; the plot functions return Figures with one axes per
  loaded level, and the paths are magnified as documented.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis.rack3d import run_rack_3d
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack
from seisrack.motion import load_builtin_record, scale_by
from seisrack.motion.components import combine
from seisrack.report import rack3d_io, rack_io, sliding_paths

xr = pytest.importorskip("xarray")
pytest.importorskip("matplotlib")

ROOT = Path(__file__).resolve().parents[1]
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def run():
    model = compile_rack(load_rack(ROOT / "examples" / "paper_rack_3d.toml"))
    rec = scale_by(load_builtin_record("elcentro_1940_ns"), 3.0)
    resp = run_rack_3d(model, combine(rec, rec, angle_deg=30.0), save_every=2)
    # the checks below need both fallen and (possibly) standing pallets to mean something
    assert resp.falls, "the test motion should make pallets fall"
    return resp, model


def test_file_names_as_2d():
    assert rack3d_io.TIMEHISTORY_FILE == rack_io.TIMEHISTORY_FILE == "timehistory.nc"
    assert rack3d_io.PEAKS_FILE == rack_io.PEAKS_FILE
    assert rack3d_io.SUMMARY_FILE == rack_io.SUMMARY_FILE


def test_netcdf_roundtrip(tmp_path: Path, run):
    resp, model = run
    m, n_t = resp.n_pallets, resp.t.size
    path = rack3d_io.write_timehistory_3d(resp, tmp_path / rack3d_io.TIMEHISTORY_FILE,
                                          model=model, title="3D test ×",
                                          summary=resp.summary())
    assert path == tmp_path / "timehistory.nc"
    assert [p.name for p in tmp_path.iterdir()] == ["timehistory.nc"]  # no temporary left
    with xr.open_dataset(path) as ds:
        assert ds.sizes["time"] == n_t and ds.sizes["pallet"] == m
        assert ds.sizes["direction"] == 2 and ds.sizes["measure"] == 3
        assert ds.sizes["component"] == 3 and ds.sizes["level"] == resp.level_peak.shape[0]
        assert list(ds["pallet"].values) == list(range(1, m + 1))
        assert list(ds["direction"].values) == ["down_aisle", "cross_aisle"]
        assert list(ds["measure"].values) == ["down_aisle", "cross_aisle", "magnitude"]
        assert list(ds["component"].values) == ["x", "z", "vertical"]
        for name in ds.variables:
            if name in ("fall_side",):
                continue
            assert ds[name].attrs.get("units"), name
            assert ds[name].attrs.get("long_name"), name
        assert ds["fall_side"].attrs["long_name"]
        units = {"ground_accel": "m s-2", "sliding": "m", "sliding_velocity": "m s-1",
                 "friction": "N", "normal_force": "N", "stuck": "1", "peak_sliding": "m",
                 "residual_sliding": "m", "fall_time": "s", "level_peak_displacement": "m",
                 "time": "s"}
        for name, unit in units.items():
            assert ds[name].attrs["units"] == unit, name
        dims = {"ground_accel": ("time", "component"),
                "sliding": ("time", "pallet", "direction"),
                "sliding_velocity": ("time", "pallet", "direction"),
                "friction": ("time", "pallet", "direction"), "stuck": ("time", "pallet"),
                "normal_force": ("time", "pallet"), "peak_sliding": ("pallet", "measure"),
                "residual_sliding": ("pallet", "direction"), "fall_time": ("pallet",),
                "fall_side": ("pallet",), "pallet_level": ("pallet",),
                "pallet_bay": ("pallet",), "level_peak_displacement": ("level", "direction")}
        for name, d in dims.items():
            assert ds[name].dims == d, name
        np.testing.assert_array_equal(ds["time"].values, resp.t)
        np.testing.assert_array_equal(ds["ground_accel"].values, resp.ground)
        np.testing.assert_array_equal(ds["sliding"].values, resp.history.sliding)
        np.testing.assert_array_equal(ds["sliding_velocity"].values, resp.history.velocity)
        np.testing.assert_array_equal(ds["friction"].values, resp.history.friction)
        np.testing.assert_array_equal(ds["normal_force"].values, resp.history.normal)
        assert ds["stuck"].dtype == np.int8
        np.testing.assert_array_equal(ds["stuck"].values, resp.history.stuck.astype(np.int8))
        np.testing.assert_array_equal(ds["peak_sliding"].values, resp.peak_sliding)
        np.testing.assert_array_equal(ds["residual_sliding"].values, resp.residual)
        np.testing.assert_array_equal(ds["level_peak_displacement"].values, resp.level_peak)
        np.testing.assert_array_equal(ds["pallet_level"].values, resp.pallet_level)
        np.testing.assert_array_equal(ds["pallet_bay"].values, resp.pallet_bay)
        fallen = {f.pallet: f for f in resp.falls}
        ft, fs = ds["fall_time"].values, [str(s) for s in ds["fall_side"].values]
        for p in range(m):
            if p in fallen:
                assert ft[p] == pytest.approx(fallen[p].time_s, abs=0, rel=1e-15)
                assert fs[p] == fallen[p].side
            else:
                assert math.isnan(ft[p]) and fs[p] == ""
        assert int(np.sum(np.isfinite(ft))) == len(resp.falls)
        assert ds.attrs["title"] == "3D test ?"  # netCDF3 text is ASCII
        assert ds.attrs["record"] == resp.motion_name
        assert ds.attrs["angle_deg"] == 30.0 and ds.attrs["dt"] == resp.dt
        summary = json.loads(ds.attrs["summary_json"])
        assert summary["pallets_falling"] == len(resp.falls)
        assert summary["peak_sliding_m"] == pytest.approx(float(resp.peak_sliding[:, 2].max()))
        np.testing.assert_array_equal(ds["pallet_x"].values,
                                      model.nodes[model.pallet_node[:, 0], 0])


def test_peaks_csv(tmp_path: Path, run):
    resp, _ = run
    path = rack3d_io.write_peaks_csv_3d(resp, tmp_path / rack3d_io.PEAKS_FILE)
    with path.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
        assert reader.fieldnames == [
            "pallet", "level", "bay", "peak_sliding_down_aisle_m",
            "peak_sliding_cross_aisle_m", "peak_sliding_m", "residual_down_aisle_m",
            "residual_cross_aisle_m", "fall_limit_front_m", "fall_limit_rear_m", "falls",
            "fall_time_s", "fall_side"]
    assert len(rows) == resp.n_pallets
    fallen = {f.pallet: f for f in resp.falls}
    for p, r in enumerate(rows):
        assert int(r["pallet"]) == p + 1
        assert int(r["level"]) == resp.pallet_level[p] and int(r["bay"]) == resp.pallet_bay[p]
        got = [float(r[k]) for k in ("peak_sliding_down_aisle_m", "peak_sliding_cross_aisle_m",
                                     "peak_sliding_m")]
        np.testing.assert_allclose(got, resp.peak_sliding[p], rtol=1e-9)
        np.testing.assert_allclose([float(r["residual_down_aisle_m"]),
                                    float(r["residual_cross_aisle_m"])], resp.residual[p],
                                   rtol=1e-9)
        assert float(r["fall_limit_front_m"]) == pytest.approx(resp.fall_front[p], rel=1e-9)
        assert float(r["fall_limit_rear_m"]) == pytest.approx(resp.fall_rear[p], rel=1e-9)
        if p in fallen:
            assert r["falls"] == "yes" and r["fall_side"] == fallen[p].side
            assert float(r["fall_time_s"]) == pytest.approx(fallen[p].time_s, rel=1e-9)
        else:
            assert r["falls"] == "no" and r["fall_time_s"] == "" and r["fall_side"] == ""


def test_figures_written_and_not_overwritten(tmp_path: Path, run):
    resp, model = run
    out = tmp_path / "figs"
    assert sliding_paths.existing_figures_3d(out) == []
    paths = sliding_paths.save_rack3d_figures(resp, model, out, suptitle="test run")
    assert sorted(p.name for p in paths) == ["pallet_sliding.png", "sliding_paths.png"]
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == PNG and len(data) > 10_000
    assert sorted(sliding_paths.existing_figures_3d(out)) == sorted(paths)
    # refuse before writing anything: one figure there is enough to stop
    (out / "sliding_paths.png").unlink()
    before = (out / "pallet_sliding.png").stat().st_mtime_ns
    with pytest.raises(InputError, match="--force"):
        sliding_paths.save_rack3d_figures(resp, model, out)
    assert not (out / "sliding_paths.png").exists()
    assert (out / "pallet_sliding.png").stat().st_mtime_ns == before
    # with force, both are written again
    (out / "pallet_sliding.png").write_bytes(b"old")
    paths = sliding_paths.save_rack3d_figures(resp, model, out, force=True)
    for p in paths:
        assert p.read_bytes()[:8] == PNG


def test_plot_functions(run):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    resp, model = run
    n_loaded = len(set(resp.pallet_level.tolist()))
    fig = sliding_paths.plot_sliding_paths(resp, model)
    try:
        assert isinstance(fig, Figure) and len(fig.axes) == n_loaded
        ax = fig.axes[0]
        # default magnification: the largest peak is drawn about 0.3 m long
        peak = float(resp.peak_sliding[:, 2].max())
        mag = sliding_paths.default_magnify(peak)
        assert 0.2 <= mag * peak <= 0.4
        assert f"x {mag:g}" in ax.get_title()
        # the path of pallet 1 is its sliding, magnified, from its centre
        x0 = model.nodes[model.pallet_node[0, 0], 0]
        paths = [ln for ln in ax.lines if len(ln.get_xdata()) == resp.t.size]
        assert len(paths) == resp.n_pallets
        np.testing.assert_allclose(paths[0].get_xdata(), x0 + mag * resp.sliding[:, 0, 0])
        np.testing.assert_allclose(paths[0].get_ydata(),
                                   model.depth / 2 + mag * resp.sliding[:, 0, 1])
        assert "red" in {ln.get_color() for ln in ax.lines}  # a pallet falls
        assert any("falls" in t.get_text() for t in ax.texts)
    finally:
        plt.close(fig)
    fig = sliding_paths.plot_sliding_paths(resp, model, magnify=1.0)
    try:
        assert "x 1 (true scale)" in fig.axes[0].get_title()
    finally:
        plt.close(fig)
    assert sliding_paths.default_magnify(0.5) == 1.0
    fig = sliding_paths.plot_pallet_histories(resp)
    try:
        assert isinstance(fig, Figure) and len(fig.axes) == 2
        top = np.argsort(-resp.peak_sliding[:, 2], kind="stable")[:4]
        ax_x, ax_z = fig.axes
        curves = [ln for ln in ax_x.lines if len(ln.get_xdata()) == resp.t.size]
        assert len(curves) == min(4, resp.n_pallets)
        np.testing.assert_allclose(curves[0].get_ydata(), resp.sliding[:, top[0], 0] * 1e3)
        limits = {round(float(ln.get_ydata()[0]), 9) for ln in ax_z.lines
                  if ln.get_linestyle() == "--"}
        assert limits == {round(v * 1e3, 9) for p in top
                          for v in (-resp.fall_front[p], resp.fall_rear[p])}
    finally:
        plt.close(fig)
