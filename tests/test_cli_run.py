"""``seisrack run``: JSON keys of issue #5, the text report, the output folder, and bad input
reported as one paragraph with exit code 2 and no traceback (issue #5 acceptance: "a missing
record file, a record that is too short or has a different dt, a μ below 0").

Record: El Centro 1940 N-S, 0-5 s (tests/analysis_inputs.py); rack: examples/paper_rack.toml.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from analysis_inputs import record_csv, short_record
from rack_inputs import PAPER_RACK, paper_dict, to_toml
from seisrack.cli import main
from seisrack.cli import run as run_cli
from seisrack.motion import Record, write_record_csv

ISSUE_PEAK_KEYS = {"beam_displacement_m", "beam_acceleration_m_s2", "total_friction_force_N",
                   "base_shear_N", "pallet_sliding_m", "pallet_residual_m"}


@pytest.fixture(scope="module")
def rec_csv(tmp_path_factory) -> Path:
    return record_csv(tmp_path_factory.mktemp("rec") / "elcentro_5s.csv")


def _json(capsys, *args: str) -> dict:
    assert main(["run", str(PAPER_RACK), *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_keys_per_issue(capsys, rec_csv):
    out = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3")
    assert ISSUE_PEAK_KEYS <= set(out["peaks"])
    assert len(out["peaks"]["pallet_sliding_m"]) == 4
    assert len(out["peaks"]["pallet_residual_m"]) == 4
    assert out["sliding_occurred"] is True
    assert isinstance(out["pallets_at_risk"], list)
    assert out["peaks"]["total_friction_force_N"] == pytest.approx(0.3 * 1600 * 9.81)
    # without the rigid companion run the paper's rule has no alpha, so no verdict (issue 23:
    # this run's own accelerations, with sliding pallets, were once labelled rigid)
    sc = out["simplified_check"]
    assert sc["rule_safe"] is None and sc["assessed"] is False and sc["alpha_rigid"] is None
    assert sc["alpha_source"].startswith("this run, with sliding pallets")
    assert all(p["mu_static"] == 0.3 for p in out["pallets"])
    assert out["dt_s"] == pytest.approx(0.005) and out["duration_s"] == pytest.approx(5.0)


def test_mu_dynamic_and_friction_from_file(capsys, rec_csv):
    out = _json(capsys, "--motion", str(rec_csv), "--mu", "0.4", "--mu-dynamic", "0.3")
    assert {p["mu_dynamic"] for p in out["pallets"]} == {0.3}
    from_file = _json(capsys, "--motion", str(rec_csv))
    assert {p["mu_static"] for p in from_file["pallets"]} == {0.6}  # the TOML's value


def test_no_sliding_above_demand(capsys, rec_csv):
    out = _json(capsys, "--motion", str(rec_csv), "--mu", "100")
    assert out["sliding_occurred"] is False and out["pallets_at_risk"] == []
    assert max(out["peaks"]["pallet_sliding_m"]) < 1e-9


def test_text_report_flags_pallet_at_risk(tmp_path: Path, capsys, rec_csv):
    d = paper_dict()
    d["pallets"][1]["sliding_limit"] = 0.002  # 2 mm: P2 must be flagged
    rack = tmp_path / "rack.toml"
    rack.write_text(to_toml(d))
    assert main(["run", str(rack), "--motion", str(rec_csv), "--mu", "0.3"]) == 0
    out = capsys.readouterr().out
    for text in ("beam displacement", "mm", "m/s²", "kN", "kN·m", "base shear",
                 "Simplified check", "not assessed", "--rigid-check",
                 "reached their free distance: 2 (L1-B1-S2)",
                 "beam acceleration (absolute, raw)", "beam acceleration (low-pass 20 Hz)",
                 "interstorey drift ratio", "connector moment", "upright axial force",
                 "upright N with concomitant M"):
        assert text in out, text
    p2 = next(ln for ln in out.splitlines() if ln.strip().startswith("2 "))
    assert "AT RISK" in p2 and "L1-B1-S2" in p2
    assert sum("AT RISK" in ln for ln in out.splitlines()) == 1


def test_out_folder(tmp_path: Path, capsys, rec_csv):
    xr = pytest.importorskip("xarray")
    pytest.importorskip("matplotlib")
    out_dir = tmp_path / "res"
    out_dir.mkdir()
    (out_dir / "notes.txt").write_text("mine")  # the user's own file: must survive
    (out_dir / "peaks.csv").write_text("stale")  # seisrack's own name: overwritten
    out = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3", "--out", str(out_dir))
    names = {"timehistory.nc", "peaks.csv", "summary.json", "beam_displacement.png",
             "beam_acceleration.png", "contact_force.png", "pallet_sliding.png",
             "sliding_heatmap.png"}
    assert {p.name for p in out_dir.iterdir()} == names | {"notes.txt"}
    assert (out_dir / "notes.txt").read_text() == "mine"
    assert (out_dir / "peaks.csv").read_text().startswith("quantity,level,pallet")
    assert {Path(p).name for p in out["outputs"]} == names
    saved = json.loads((out_dir / "summary.json").read_text())
    assert saved == out
    with xr.open_dataset(out_dir / "timehistory.nc") as ds:
        assert ds.beam_displacement.attrs["units"] == "m"
        assert ds.contact_force.attrs["units"] == "N"
        assert ds.pallet_sliding.dims == ("time", "pallet")
        peak = float(np.abs(ds.beam_displacement).max())
        # one pallet identity everywhere: ids 1.. and labels as in the JSON
        assert ds.pallet.values.tolist() == [p["id"] for p in out["pallets"]] == [1, 2, 3, 4]
        assert ds.pallet_label.values.tolist() == [p["label"] for p in out["pallets"]]
        filt = float(np.abs(ds.beam_acceleration_filtered).max())
    assert peak == pytest.approx(out["peaks"]["beam_displacement_m"], rel=1e-12)
    assert filt == pytest.approx(out["peaks"]["beam_acceleration_filtered_m_s2"], rel=1e-12)
    # a second run into the same folder refuses to overwrite the figures without --force
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--out", str(out_dir),
                 "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--out" and "--force" in err["allowed"]
    before = (out_dir / "beam_displacement.png").stat().st_mtime_ns
    _json(capsys, "--motion", str(rec_csv), "--mu", "0.6", "--out", str(out_dir), "--force")
    assert (out_dir / "beam_displacement.png").stat().st_mtime_ns >= before
    assert json.loads((out_dir / "summary.json").read_text())["pallets"][0]["mu_static"] == 0.6


def test_out_without_plots(tmp_path: Path, capsys, rec_csv):
    pytest.importorskip("xarray")
    out_dir = tmp_path / "new" / "sub"  # created with its parents
    _json(capsys, "--motion", str(rec_csv), "--out", str(out_dir), "--no-plot")
    assert sorted(p.name for p in out_dir.iterdir()) == ["peaks.csv", "summary.json",
                                                         "timehistory.nc"]


def test_builtin_vertical_and_free_vibration(tmp_path: Path, capsys):
    rec = short_record()
    vert = tmp_path / "v.csv"
    write_record_csv(Record(0.3 * rec.accel, rec.dt), vert)
    out = _json(capsys, "--builtin", "elcentro_1940_ns", "--dt", "0.01", "--mu", "0.5",
                "--free-vibration", "1")
    assert out["record"] == "elcentro_1940_ns"
    assert out["duration_s"] == pytest.approx(39.94 + 1.0)
    h = tmp_path / "h.csv"
    write_record_csv(rec, h)
    out = _json(capsys, "--motion", str(h), "--vertical", str(vert), "--mu", "0.5")
    assert out["status"] == "ok"


def test_one_column_file_needs_units_and_dt(tmp_path: Path, capsys):
    f = tmp_path / "acc.txt"
    np.savetxt(f, short_record().accel / 9.80665)
    out = _json(capsys, "--motion", str(f), "--units", "g", "--motion-dt", "0.01", "--mu", "0.3")
    assert out["sliding_occurred"] is True
    assert main(["run", str(PAPER_RACK), "--motion", str(f), "--units", "g"]) == 2
    assert "dt" in capsys.readouterr().err


def test_progress_bar_only_on_a_terminal(monkeypatch, capsys, rec_csv):
    monkeypatch.setattr(run_cli, "PROGRESS_MIN_STEPS", 100)
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--json"]) == 0
    assert capsys.readouterr().err == ""  # not a TTY: no bar
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--json"]) == 0
    captured = capsys.readouterr()
    assert "step" in captured.err and "time history" in captured.err
    json.loads(captured.out)  # stdout stays one JSON object


# ------------------------------------------------------------------------------ bad input
def _bad_cases(tmp: Path, rec_csv: Path) -> list[tuple[str, list[str], str]]:
    rec = short_record()
    short = write_record_csv(Record([0.0, 0.1], 0.01), tmp / "short.csv")
    vdt = write_record_csv(Record(rec.accel, 0.02), tmp / "vdt.csv")
    vlen = write_record_csv(Record(rec.accel[:-10], rec.dt), tmp / "vlen.csv")
    afile = tmp / "afile.txt"
    afile.write_text("x")
    m = ["--motion", str(rec_csv)]
    return [
        ("missing-record", ["--motion", str(tmp / "nope.csv")], "--motion"),
        ("record-is-folder", ["--motion", str(tmp)], "--motion"),
        ("too-short", ["--motion", str(short)], "3 samples"),
        ("dt-not-divisor", [*m, "--dt", "0.003"], "--dt"),
        ("dt-larger", [*m, "--dt", "0.02"], "--dt"),
        ("dt-negative", [*m, "--dt", "-0.01"], "--dt"),
        ("vertical-dt", [*m, "--vertical", str(vdt)], "--vertical"),
        ("vertical-length", [*m, "--vertical", str(vlen)], "--vertical"),
        ("vertical-missing", [*m, "--vertical", str(tmp / "v.csv")], "--vertical"),
        ("mu-negative", [*m, "--mu", "-0.1"], "--mu"),
        ("mu-nan", [*m, "--mu", "nan"], "--mu"),
        ("mud-above-mus", [*m, "--mu", "0.3", "--mu-dynamic", "0.4"], "--mu-dynamic"),
        ("mud-without-mu", [*m, "--mu-dynamic", "0.4"], "--mu-dynamic"),
        ("unknown-builtin", ["--builtin", "kobe"], "--builtin"),
        ("out-is-file", [*m, "--out", str(afile)], "--out"),
        ("out-under-file", [*m, "--out", str(afile / "sub")], "--out"),
        ("plot-without-out", [*m, "--plot"], "--plot"),
        ("free-vibration-negative", [*m, "--free-vibration", "-1"], "--free-vibration"),
        ("bad-units", [*m, "--units", "furlong"], "--units"),
        ("save-every-zero", [*m, "--save-every", "0"], "--save-every"),
    ]




@pytest.fixture(scope="module")
def bad_cases(tmp_path_factory, rec_csv):
    return {c[0]: c[1:] for c in _bad_cases(tmp_path_factory.mktemp("bad"), rec_csv)}


@pytest.mark.parametrize("case", [
    "missing-record", "record-is-folder", "too-short", "dt-not-divisor", "dt-larger",
    "dt-negative", "vertical-dt", "vertical-length", "vertical-missing", "mu-negative",
    "mu-nan", "mud-above-mus", "mud-without-mu", "unknown-builtin", "out-is-file",
    "out-under-file", "plot-without-out", "free-vibration-negative", "bad-units",
    "save-every-zero",
])
def test_bad_input(capsys, bad_cases, case):
    args, field = bad_cases[case]
    assert main(["run", str(PAPER_RACK), *args]) == 2
    captured = capsys.readouterr()
    assert field in captured.err, captured.err
    assert "Traceback" not in captured.err and captured.out == ""
    assert captured.err.count("\n") == 1  # one paragraph


def test_missing_rack_file(capsys, rec_csv, tmp_path: Path):
    assert main(["run", str(tmp_path / "rack.toml"), "--motion", str(rec_csv)]) == 2
    assert "rack.toml" in capsys.readouterr().err


def test_motion_or_builtin_required(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", str(PAPER_RACK)])
    assert exc.value.code == 2


def test_a_filter_below_its_lowest_cut_off_is_refused(capsys, rec_csv):
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--accel-filter", "1e-7",
                 "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--accel-filter" and ">= 0.1 Hz" in err["allowed"]


@pytest.mark.parametrize(("opts", "field"), [(["--scale", "1e300"], "--scale"),
                                           (["--scale-pga", "200", "--scale-units", "g"],
                                            "--scale-pga")])
def test_a_scaling_beyond_any_earthquake_is_refused(capsys, rec_csv, opts, field):
    """--scale 1e300 overflowed the response (inf peaks, a NaN energy residual) and ran on."""
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), *opts, "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == field and "<= 100 g" in err["allowed"]


def test_subprocess_json_and_error(rec_csv, tmp_path: Path):
    def run(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "seisrack", "run", str(PAPER_RACK), *args],
                              capture_output=True, text=True, timeout=120)

    ok = run("--motion", str(rec_csv), "--mu", "0.6", "--json")
    assert ok.returncode == 0, ok.stderr
    assert ISSUE_PEAK_KEYS <= set(json.loads(ok.stdout)["peaks"])
    assert ok.stderr == ""  # no progress bar when stderr is not a terminal
    bad = run("--motion", str(tmp_path / "missing.at2"))
    assert bad.returncode == 2
    assert "missing.at2" in bad.stderr and "Traceback" not in bad.stderr


def test_method_option(capsys, rec_csv):
    """--method picks the time integration; both agree closely on the paper rack (dt = 5 ms)."""
    exact = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3")
    newmark = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3", "--method", "newmark")
    assert (exact["integration"], newmark["integration"]) == ("exact", "newmark")
    a = exact["peaks"]["beam_displacement_m"]
    b = newmark["peaks"]["beam_displacement_m"]
    assert a == pytest.approx(b, rel=5e-3) and a != b


def test_basis_save_every_and_rigid_check(capsys, rec_csv):
    """--basis reduced stays within 0.5 % of the full basis on the paper rack; --save-every
    keeps fewer samples without changing a peak; --rigid-check takes alpha from a rigid run."""
    full = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3", "--basis", "full")
    red = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3", "--basis", "reduced",
                "--save-every", "10", "--rigid-check")
    assert full["basis"]["kind"] == "full" and red["basis"]["kind"] == "reduced"
    assert red["basis"]["size"] < full["basis"]["size"]
    for key in ("beam_displacement_m", "base_shear_N"):
        assert red["peaks"][key] == pytest.approx(full["peaks"][key], rel=5e-3)
    assert red["peaks"]["pallet_sliding_m"] == pytest.approx(full["peaks"]["pallet_sliding_m"],
                                                             rel=5e-3, abs=1e-6)
    assert full["simplified_check"]["alpha_source"].startswith("this run")
    assert red["simplified_check"]["alpha_source"].startswith("rigid companion run")
    assert red["simplified_check"]["rule_safe"] in (True, False)


def test_summary_ids_filtered_acceleration_and_design(capsys, rec_csv):
    """Issue 14 item 6: 1-based pallet ids and labels, raw and filtered floor accelerations
    (each labelled), design quantities per member and as peaks."""
    out = _json(capsys, "--motion", str(rec_csv), "--mu", "0.3", "--accel-filter", "10")
    assert [p["id"] for p in out["pallets"]] == [1, 2, 3, 4]
    assert [p["label"] for p in out["pallets"]] == ["L1-B1-S1", "L1-B1-S2", "L1-B2-S1",
                                                    "L1-B2-S2"]
    assert all(1 <= i <= 4 for i in out["pallets_at_risk"])
    pk = out["peaks"]
    assert pk["acceleration_filter_hz"] == 10.0
    assert 0 < pk["beam_acceleration_filtered_m_s2"] <= pk["beam_acceleration_m_s2"]
    design = out["design"]
    for key in ("interstorey_drift_ratio", "beam_end_moment_Nm", "beam_end_shear_N",
                "connector_moment_Nm", "connector_rotation_rad", "upright_axial_force_N"):
        assert design[key]["max_abs"] > 0 and pk[key] == design[key]["max_abs"]
    assert design["beam_end_moment_Nm"]["labels"] == ["L1-B1-left", "L1-B1-right",
                                                      "L1-B2-left", "L1-B2-right"]
    assert design["upright_n_m"]["labels"] == ["U1-base", "U1-L1", "U2-base", "U2-L1",
                                               "U3-base", "U3-L1"]
    # gravity: the middle upright carries the most (four 400 kg pallets, two bays)
    n_grav = design["upright_axial_force_N"]["gravity"]
    assert n_grav[2] < n_grav[0] < 0


def test_warnings_on_implausible_input(tmp_path: Path, capsys):
    """PGA above 3 g, vertical acceleration below -g, and sliding beyond the rack's length are
    warnings on stderr (exit 0), not errors."""
    rec = short_record(duration=2.0)
    big = tmp_path / "big.csv"
    write_record_csv(Record(rec.accel * (3.5 * 9.81 / rec.pga), rec.dt), big)
    vert = tmp_path / "v.csv"
    write_record_csv(Record(np.full(rec.n, -1.2 * 9.81), rec.dt), vert)
    assert main(["run", str(PAPER_RACK), "--motion", str(big), "--vertical", str(vert),
                 "--mu", "0.05", "--json"]) == 0
    cap = capsys.readouterr()
    json.loads(cap.out)
    assert "warning: the record's PGA is" in cap.err and "above 3 g" in cap.err
    assert "below -g" in cap.err and "lift off" in cap.err
    assert "error" not in cap.err
    # a strong long pulse on low friction: sliding beyond the rack's 3.6 m length
    n = 801
    pulse = tmp_path / "pulse.csv"
    write_record_csv(Record(np.r_[np.full(400, 6.0), np.zeros(n - 400)], 0.01), pulse)
    assert main(["run", str(PAPER_RACK), "--motion", str(pulse), "--mu", "0.01",
                 "--free-vibration", "20", "--json"]) == 0
    cap = capsys.readouterr()
    assert "slid more than the rack's length" in cap.err


def test_errors_are_json_under_json(capsys, bad_cases):
    args, field = bad_cases["mu-negative"]
    assert main(["run", str(PAPER_RACK), *args, "--json"]) == 2
    cap = capsys.readouterr()
    err = json.loads(cap.out)["error"]
    assert err == {"field": "--mu", "value": -0.1, "allowed": "a friction coefficient >= 0",
                   "message": err["message"]}
    assert "--mu" in err["message"] and cap.err == ""
