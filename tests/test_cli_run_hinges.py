"""Nonlinear connections in every output of ``seisrack run`` and ``seisrack report``: the JSON
summary, the text report, peaks.csv, timehistory.nc, hinge_loops.png and the HTML report's
"Connections" section; and a linear rack's outputs without any of them.

Rack: examples/paper_rack_nonlinear.toml (elastic-perfectly plastic connectors, My 2.5 kN·m,
and base plates, My 3.0 kN·m). Record: El Centro 1940 N-S at its own scale, first 10 s
(measured: all 7 hinges yield, largest ductility 1.80 at connector L1 B1 left, hysteretic
energy ~35 % of the input). The runs take ~1 s each.
"""

from __future__ import annotations

import csv
import io
import json
import re
from contextlib import redirect_stdout
from pathlib import Path

import pytest

from analysis_inputs import record_csv, short_record
from rack_inputs import PAPER_RACK
from seisrack.cli import main

NONLINEAR = Path(__file__).resolve().parents[1] / "examples" / "paper_rack_nonlinear.toml"
HINGE_LABELS = {"base U1", "base U2", "base U3", "connector L1 B1 left",
                "connector L1 B1 right", "connector L1 B2 left", "connector L1 B2 right"}
HINGE_QUANTITIES = ("hinge_rotation", "hinge_moment", "hinge_residual_rotation",
                    "hinge_ductility")


def _main(*args: str) -> tuple[int, str]:
    buf = io.StringIO()
    with redirect_stdout(buf):
        rc = main(list(args))
    return rc, buf.getvalue()


@pytest.fixture(scope="module")
def rec10(tmp_path_factory) -> Path:
    return record_csv(tmp_path_factory.mktemp("rec") / "elcentro_10s.csv", short_record(10.0))


@pytest.fixture(scope="module")
def nonlinear_run(tmp_path_factory, rec10) -> tuple[dict, Path]:
    pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    out = tmp_path_factory.mktemp("nonlinear") / "out"
    rc, text = _main("run", str(NONLINEAR), "--motion", str(rec10), "--out", str(out),
                     "--json")
    assert rc == 0
    return json.loads(text), out


def _peaks_csv(out: Path) -> list[dict[str, str]]:
    with (out / "peaks.csv").open(encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_json_has_the_hinges(nonlinear_run):
    s, _ = nonlinear_run
    h = s["hinges"]
    assert h["count"] == 7 and {r["hinge"] for r in h["hinges"]} == HINGE_LABELS
    assert h["yielded"] >= 1
    assert h["peak_ductility"] > 1.0 and h["peak_ductility_hinge"] in HINGE_LABELS
    assert h["hysteretic_energy_J"] == s["energy_J"]["hysteresis"] > 0.0
    assert h["hysteretic_energy_J"] < s["energy_J"]["input"]


def test_text_report_shows_the_connections(rec10):
    rc, text = _main("run", str(NONLINEAR), "--motion", str(rec10))
    assert rc == 0
    assert "Connections (nonlinear" in text
    block = text[text.index("Connections (nonlinear"):text.index("Pallets (sliding")]
    rows = [ln for ln in block.splitlines() if ln.strip().startswith(("base U", "connector L"))]
    assert {re.split(r"\s{2,}", ln.strip())[0] for ln in rows} == HINGE_LABELS
    assert any(ln.endswith("YIELDED") for ln in rows)
    assert "elastic-plastic" in rows[0]
    assert re.search(r"hysteretic energy dissipated by the connections: [\d.]+ J = [\d.]+ % of "
                     r"the input energy", block)
    # the design block shows the connectors' hinge moment (never the elastic k·θ beyond My)
    design = text[text.index("Design quantities"):text.index("Connections (nonlinear")]
    m = re.search(r"connector moment \(hinge law\)\s+([\d.]+) kN·m", design)
    assert m and float(m.group(1)) == pytest.approx(2.5, abs=1e-3)  # My of the connectors


def test_peaks_csv_has_the_hinge_rows(nonlinear_run):
    s, out = nonlinear_run
    rows = _peaks_csv(out)
    by_hinge = {r["hinge"]: r for r in s["hinges"]["hinges"]}
    for q, key in zip(HINGE_QUANTITIES, ("peak_rotation_rad", "peak_moment_Nm",
                                         "residual_rotation_rad", "ductility"), strict=True):
        got = [r for r in rows if r["quantity"] == q]
        assert len(got) == 7, q
        for r in got:
            lab = r["note"].split(",")[0]
            assert float(r["value"]) == pytest.approx(by_hinge[lab][key], rel=1e-9), (q, lab)
    rot = {r["note"].split(",")[0]: r for r in rows if r["quantity"] == "hinge_rotation"}
    assert rot["base U2"]["upright"] == "2" and rot["base U2"]["level"] == ""
    assert rot["connector L1 B2 right"]["level"] == "1"
    assert rot["connector L1 B2 right"]["upright"] == "3"
    assert all(r["unit"] == "rad" and r["time_s"] for r in rot.values())
    # the design rows of the connectors hold the law's moments, capped at My = 2.5 kN·m
    conn = [r for r in rows if r["quantity"] == "connector_moment_Nm"]
    assert conn and all("hinge law" in r["note"] for r in conn)
    assert max(float(r["value"]) for r in conn) == pytest.approx(2500.0, rel=1e-9)


def test_netcdf_has_the_hinge_histories(nonlinear_run):
    import numpy as np
    import xarray as xr

    s, out = nonlinear_run
    rows = {r["hinge"]: r for r in s["hinges"]["hinges"]}
    with xr.open_dataset(out / "timehistory.nc") as ds:
        assert ds.hinge_rotation.dims == ("time", "hinge") == ds.hinge_moment.dims
        assert ds.hinge_rotation.attrs["units"] == "rad"
        assert ds.hinge_moment.attrs["units"] == "N m"
        labels = [str(x) for x in ds.hinge.values]
        assert set(labels) == HINGE_LABELS
        assert set(ds.hinge_law.values.tolist()) == {"elastic-plastic"}
        kinds = dict(zip(labels, ds.hinge_kind.values.tolist(), strict=True))
        assert kinds["base U1"] == "base" and kinds["connector L1 B1 left"] == "connector"
        for i, lab in enumerate(labels):
            peak = float(np.max(np.abs(ds.hinge_rotation.values[:, i])))
            assert peak == pytest.approx(rows[lab]["peak_rotation_rad"], rel=1e-12)
            assert float(np.max(np.abs(ds.hinge_moment.values[:, i]))) == pytest.approx(
                rows[lab]["peak_moment_Nm"], rel=1e-12)
            if rows[lab]["ductility"] is not None:
                assert peak / float(ds.hinge_yield_rotation.values[i]) == pytest.approx(
                    rows[lab]["ductility"], rel=1e-12)
        assert float(ds.energy_hysteresis.values[-1]) == pytest.approx(
            s["energy_J"]["hysteresis"], rel=1e-12)
        assert "ELASTIC" in ds.connector_moment.attrs["long_name"]


def test_hinge_loops_figure_is_written(nonlinear_run, rec10, capsys):
    s, out = nonlinear_run
    png = out / "hinge_loops.png"
    assert str(png) in s["outputs"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    # it counts as a figure: a second run into the folder refuses without --force
    rc, text = _main("run", str(NONLINEAR), "--motion", str(rec10), "--out", str(out),
                     "--json")
    assert rc == 2 and "hinge_loops.png" in text


def test_html_report_has_the_connections_section(tmp_path, rec10):
    pytest.importorskip("matplotlib")
    html = tmp_path / "report.html"
    rc, _ = _main("report", str(NONLINEAR), "--motion", str(rec10), "--out", str(html),
                  "--json")
    assert rc == 0
    text = html.read_text(encoding="utf-8")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert '<section id="connections">' in text
    sec = text[text.index('<section id="connections">'):]
    sec = sec[:sec.index("</section>")]
    assert sec.count("<tr data-hinge=") == 7
    assert re.search(r'<figure id="fig-hinge-loops"><img src="data:image/png;base64,', sec)
    # each number cell holds the exact summary.json value
    cells = re.findall(r'<tr data-hinge="(\d+)">|data-key="(\w+)" data-value="([^"]+)"', sec)
    row = None
    n = 0
    for r, key, val in cells:
        if r:
            row = int(r)
            continue
        assert json.loads(val) == summary["hinges"]["hinges"][row][key]
        n += 1
    assert n >= 7 * 3
    assert "8. Design checks" in text  # numbered after the new section


def test_linear_rack_outputs_have_no_hinges(tmp_path):
    pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    import xarray as xr

    rec = record_csv(tmp_path / "ec3.csv", short_record(3.0))
    out = tmp_path / "out"
    rc, text = _main("run", str(PAPER_RACK), "--motion", str(rec), "--out", str(out),
                     "--json")
    assert rc == 0
    s = json.loads(text)
    assert "hinges" not in s and "hysteresis" not in s["energy_J"]
    assert not (out / "hinge_loops.png").exists()
    assert not [r for r in _peaks_csv(out) if r["quantity"].startswith("hinge_")]
    assert not [r for r in _peaks_csv(out) if "ELASTIC" in r["note"]]
    with xr.open_dataset(out / "timehistory.nc") as ds:
        assert not [v for v in (*ds.data_vars, *ds.coords) if str(v).startswith("hinge")]
        assert "ELASTIC" not in ds.connector_moment.attrs["long_name"]
    rc, text = _main("run", str(PAPER_RACK), "--motion", str(rec))
    assert "Connections" not in text and "hinge law" not in text
    assert "connector moment" in text


NONLINEAR_3D = Path(__file__).resolve().parents[1] / "examples" / "paper_rack_3d_nonlinear.toml"


def test_3d_rack_run_report_and_export_have_the_hinges(tmp_path):
    """examples/paper_rack_3d_nonlinear.toml (issue 21): 8 connectors in down-aisle bending and
    6 base plates about both axes, in every output of run and report, and in the export."""
    pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    import numpy as np
    import xarray as xr

    from seisrack.motion import Record

    full = short_record(14.0)
    a = record_csv(tmp_path / "x.csv", short_record(10.0))
    b = record_csv(tmp_path / "z.csv", Record(full.accel[400:1401], full.dt, name="shifted"))
    out = tmp_path / "out"
    rc, text = _main("run", str(NONLINEAR_3D), "--motion", str(a), "--motion-cross", str(b),
                     "--out", str(out), "--json")
    assert rc == 0
    s = json.loads(text)
    h = s["hinges"]
    labels = {r["hinge"] for r in h["hinges"]}
    assert h["count"] == 20 and len(labels) == 20
    assert "base U2-front cross-aisle" in labels and "base U2-rear down-aisle" in labels
    assert "connector L1 B1-front left" in labels and "connector L1 B2-rear right" in labels
    assert h["yielded"] >= 4 and s["energy_J"]["hysteresis"] > 0.0
    assert s["energy_balance_error"] < 1e-6
    rows = [r for r in _peaks_csv(out) if r["quantity"] == "hinge_moment"]
    assert len(rows) == 20
    conn = [r for r in _peaks_csv(out) if r["quantity"] == "connector_moment_Nm"]
    assert conn and all("hinge law" in r["note"] for r in conn)  # the law's moments, <= My
    assert max(float(r["value"]) for r in conn) == pytest.approx(1500.0, rel=1e-9)
    with xr.open_dataset(out / "timehistory.nc") as ds:
        assert ds.hinge_moment.dims == ("time", "hinge") and ds.hinge.size == 20
        assert float(np.max(np.abs(ds.hinge_moment.values))) <= 1800.0 * (1 + 1e-12)
    assert (out / "hinge_loops.png").stat().st_size > 10_000
    html = tmp_path / "report.html"
    rc, _ = _main("report", str(NONLINEAR_3D), "--motion", str(a), "--motion-cross", str(b),
                  "--out", str(html), "--json")
    assert rc == 0
    sec = html.read_text(encoding="utf-8")
    sec = sec[sec.index('<section id="connections">'):]
    assert sec[:sec.index("</section>")].count("<tr data-hinge=") == 20
    script = tmp_path / "ops.py"
    rc, _ = _main("export", "opensees", str(NONLINEAR_3D), "--out", str(script))
    assert rc == 0
    text = script.read_text(encoding="utf-8")
    body = text[text.index("SPRINGS = ["):text.index("# per spring, uniaxialMaterial")]
    dirs = [int(x) for x in re.findall(r"\(\d+, \d+, (\d), [\d.e+]+\)", body)]
    # base plates about x (rx, 4) and z (rz, 6), connectors about z: 6 + 14
    assert sorted(dirs) == [4] * 6 + [6] * 14
    assert text.count("('ElasticPP', 160000.0,") == 20
