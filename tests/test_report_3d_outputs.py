"""The one writer (``report.rack_io``) and the figures (``report.rack_plot``,
``report.sliding_paths``) on a 3D rack time history.

One run of the 3D paper rack (examples/paper_rack_3d.toml) under El Centro 1940 NS x 3 as both
horizontal components at 30° (every 2nd step kept), strong enough for the pallets to slide
several centimetres and to fall off the 50 mm overhang. Checked against the response's own
arrays (the writer adds nothing of its own):

- the netCDF file reopens with xarray, with a ``direction`` dimension (down_aisle, cross_aisle)
  on exactly the quantities that have one, a ``units`` and ``long_name`` on every variable,
  values equal to the response's arrays, ``fall_time`` NaN exactly for the pallets not in
  ``resp.falls`` (equal to their fall times otherwise), and the summary stored as JSON;
- ``peaks.csv`` has the 2D columns plus ``direction``, per-direction rows equal to the
  response's peaks, each pallet's sliding magnitude, fall limits and fall;
- the figures of a 2D run are written with a panel per direction, plus the plan view, not
  overwritten without ``force`` (nothing is written then); the plan view's paths are the
  pallets' sliding, magnified as documented.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis import run_rack
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack
from seisrack.motion import load_builtin_record, scale_by
from seisrack.motion.components import combine
from seisrack.report import rack_io, rack_plot, sliding_paths

xr = pytest.importorskip("xarray")
pytest.importorskip("matplotlib")

ROOT = Path(__file__).resolve().parents[1]
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def run():
    model = compile_rack(load_rack(ROOT / "examples" / "paper_rack_3d.toml"))
    rec = scale_by(load_builtin_record("elcentro_1940_ns"), 3.0)
    resp = run_rack(model, combine(rec, rec, angle_deg=30.0), save_every=2)
    # the checks below need both fallen and (possibly) standing pallets to mean something
    assert resp.falls, "the test motion should make pallets fall"
    return resp, model


def test_netcdf_roundtrip(tmp_path: Path, run):
    resp, model = run
    m, n_t = resp.n_pallets, resp.t.size
    path = rack_io.write_timehistory(resp, tmp_path / rack_io.TIMEHISTORY_FILE, model=model,
                                     title="3D test ×", summary=resp.summary())
    assert path == tmp_path / "timehistory.nc"
    assert [p.name for p in tmp_path.iterdir()] == ["timehistory.nc"]  # no temporary left
    with xr.open_dataset(path) as ds:
        assert ds.sizes["time"] == n_t and ds.sizes["pallet"] == m
        assert list(ds["direction"].values) == ["down_aisle", "cross_aisle"]
        for name in ds.variables:
            if name in ("fall_side",):
                continue
            assert ds[name].attrs.get("units"), name
            assert ds[name].attrs.get("long_name"), name
        dims = {"ground_accel": ("time", "direction"),
                "beam_displacement": ("time", "level", "direction"),
                "base_shear": ("time", "direction"),
                "upright_moment_base": ("time", "upright", "direction"),
                "pallet_sliding": ("time", "pallet", "direction"),
                "pallet_friction": ("time", "pallet", "direction"),
                "pallet_stuck": ("time", "pallet"), "pallet_normal": ("time", "pallet"),
                "fall_time": ("pallet",), "fall_side": ("pallet",),
                "interstorey_drift_ratio": ("time", "storey"),
                "interstorey_drift_ratio_cross_aisle": ("time", "storey")}
        for name, d in dims.items():
            assert ds[name].dims == d, name
        np.testing.assert_array_equal(ds["time"].values, resp.t)
        np.testing.assert_array_equal(ds["ground_accel"].values, resp.ground_accel)
        np.testing.assert_array_equal(ds["pallet_sliding"].values, resp.pallet_sliding)
        np.testing.assert_array_equal(ds["pallet_friction"].values, resp.pallet_friction)
        np.testing.assert_array_equal(ds["base_shear"].values, resp.base_shear)
        np.testing.assert_array_equal(ds["pallet_level"].values, resp.pallet_level + 1)
        fallen = {f.pallet: f for f in resp.falls}
        ft, fs = ds["fall_time"].values, [str(s) for s in ds["fall_side"].values]
        for p in range(m):
            if p in fallen:
                assert ft[p] == pytest.approx(fallen[p].time_s, abs=0, rel=1e-15)
                assert fs[p] == fallen[p].side
            else:
                assert math.isnan(ft[p]) and fs[p] == ""
        assert ds.attrs["title"] == "3D test ?"  # netCDF3 text is ASCII
        assert ds.attrs["dimension"] == "3D" and ds.attrs["angle_deg"] == 30.0
        summary = json.loads(ds.attrs["summary_json"])
        assert summary["pallets_falling"] == len(resp.falls)
        np.testing.assert_array_equal(ds["pallet_x"].values,
                                      model.nodes[model.pallet_node[:, 0], 0])


def test_peaks_csv(tmp_path: Path, run):
    resp, _ = run
    path = rack_io.write_peaks_csv(resp, tmp_path / rack_io.PEAKS_FILE)
    with path.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        rows = list(reader)
        assert tuple(reader.fieldnames) == rack_io.PEAKS_FIELDS
    by_dir = resp.pallet_peak_sliding_by_direction()
    for d, name in enumerate(("down_aisle", "cross_aisle")):
        sl = {int(r["pallet"]): float(r["value"]) for r in rows
              if r["quantity"] == "pallet_sliding" and r["direction"] == name}
        assert len(sl) == resp.n_pallets
        # peaks over the kept samples, never above the full-rate peaks
        for p, v in sl.items():
            assert v == pytest.approx(np.abs(resp.pallet_sliding[:, p - 1, d]).max(), rel=1e-9)
            assert v <= by_dir[p - 1, d] * (1 + 1e-9)  # the CSV keeps 10 digits
        shear = [float(r["value"]) for r in rows
                 if r["quantity"] == "base_shear" and r["direction"] == name]
        assert shear == [pytest.approx(np.abs(resp.base_shear[:, d]).max(), rel=1e-9)]
    mag = {int(r["pallet"]): float(r["value"]) for r in rows
           if r["quantity"] == "pallet_sliding_magnitude"}
    np.testing.assert_allclose([mag[p + 1] for p in range(resp.n_pallets)],
                               resp.pallet_peak_sliding(), rtol=1e-9)
    falls = {int(r["pallet"]): r for r in rows if r["quantity"] == "pallet_falls"}
    assert set(falls) == {f.pallet + 1 for f in resp.falls}
    for f in resp.falls:
        r = falls[f.pallet + 1]
        assert float(r["time_s"]) == pytest.approx(f.time_s, rel=1e-9) and f.side in r["note"]


def test_figures_written_and_not_overwritten(tmp_path: Path, run):
    resp, model = run
    out = tmp_path / "figs"
    out.mkdir()
    paths = rack_plot.save_rack_figures(resp, out, model=model, suptitle="test run")
    names = sorted(p.name for p in paths)
    assert names == sorted([*rack_plot.RACK_FIGURES, sliding_paths.SLIDING_PATHS_FIGURE])
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == PNG and len(data) > 10_000
    assert sorted(rack_plot.existing_figures(out)) == sorted(paths)
    (out / "sliding_paths.png").unlink()
    before = (out / "pallet_sliding.png").stat().st_mtime_ns
    with pytest.raises(InputError, match="--force"):
        rack_plot.save_rack_figures(resp, out, model=model)
    assert not (out / "sliding_paths.png").exists()
    assert (out / "pallet_sliding.png").stat().st_mtime_ns == before
    paths = rack_plot.save_rack_figures(resp, out, model=model, force=True)
    assert (out / "sliding_paths.png").read_bytes()[:8] == PNG


def test_panels_per_direction(run):
    import matplotlib.pyplot as plt

    resp, _ = run
    fig, axes = plt.subplots(2, 1)
    try:
        for d, ax in enumerate(axes):
            rack_plot.plot_all_pallet_sliding(resp, ax, direction=d)
            assert ("down-aisle" if d == 0 else "cross-aisle") in ax.get_title()
            y = ax.lines[0].get_ydata()
            np.testing.assert_allclose(y, resp.pallet_sliding[:, 0, d] * 1e3)
    finally:
        plt.close(fig)


def test_plan_view(run):
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    resp, model = run
    n_loaded = len(set(resp.pallet_level.tolist()))
    fig = sliding_paths.plot_sliding_paths(resp, model)
    try:
        assert isinstance(fig, Figure) and len(fig.axes) == n_loaded
        ax = fig.axes[0]
        # default magnification: the largest peak is drawn about 0.3 m long
        peak = float(resp.pallet_peak_sliding().max())
        mag = sliding_paths.default_magnify(peak)
        assert 0.2 <= mag * peak <= 0.4 or mag == 1.0
        assert f"x {mag:g}" in ax.get_title()
        x0 = model.nodes[model.pallet_node[0, 0], 0]
        paths = [ln for ln in ax.lines if len(ln.get_xdata()) == resp.t.size]
        assert len(paths) == resp.n_pallets
        np.testing.assert_allclose(paths[0].get_xdata(),
                                   x0 + mag * resp.pallet_sliding[:, 0, 0])
        np.testing.assert_allclose(paths[0].get_ydata(),
                                   model.depth / 2 + mag * resp.pallet_sliding[:, 0, 1])
        assert "red" in {ln.get_color() for ln in ax.lines}  # a pallet falls
        assert any("falls" in t.get_text() for t in ax.texts)
    finally:
        plt.close(fig)
    assert sliding_paths.default_magnify(0.5) == 1.0
