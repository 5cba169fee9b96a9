"""Record scaling and the EC8 suite check of a folder of records (issue #14, item 4).

Validation criterion of the issue: "the scaling tests check the scaled record's PGA and Sa(T) to
0.1 %". The PGA is max|a| of the scaled samples. Sa(T) = ω² max|u| is checked against an
independent computation: ``scipy.signal.lsim`` (matrix exponential of the state-space SDOF
ü + 2ζωu̇ + ω²u = -a_g, ζ = 5 %, linear interpolation of the input) on the scaled record upsampled
50× by linear interpolation and followed by one period of rest, as in tests/test_motion_spectra.py
(≥ 3000 points per period at T ≤ 0.65 s, so the sampled peak is within 1e-6 of the true one).

Bad input (issue #14): a target of zero or below, a period outside the supported range
(0.01-10 s) and two scaling options at once exit with code 2 and one paragraph, no traceback.

Suite check (EN 1998-1 §3.2.3.1.2(4)a, (4)b): both amplitude rules are linear in a common factor,
so after scaling every record by the reported factor the governing rule holds with equality
(mean PGA = a_g·S or min mean/target spectrum = 0.9) and the other one holds.

Records: El Centro 1940 N-S (bundled, 0-6 s); the paper rack (examples/paper_rack.toml, T1 =
0.65 s, paper §IV); EC8 type 1 ground C synthetic records from ``generate_ec8_suite``.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

from analysis_inputs import record_csv
from rack_inputs import PAPER_RACK
from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.motion import (
    G,
    Record,
    check_ec8_suite,
    ec8_spectrum,
    generate_ec8_suite,
    load_builtin_record,
    read_record,
    read_suite,
    response_spectrum,
    scale_by,
    scale_record,
    scale_to_pga,
    scale_to_sa,
    write_record_csv,
)
from seisrack.motion.scaling import PERIOD_RANGE

TOL = 1e-3  # the 0.1 %


def _elcentro(seconds: float = 6.0) -> Record:
    full = load_builtin_record("elcentro_1940_ns")
    n = int(round(seconds / full.dt)) + 1
    return Record(full.accel[:n], full.dt, name="elcentro_0-6s")


def _lsim_sa(a: np.ndarray, dt: float, T: float, z: float = 0.05, up: int = 50) -> float:
    """Independent Sa(T) [m/s²]: lsim on the record upsampled ``up`` times, then rest for T."""
    w = 2 * math.pi / T
    a = np.concatenate([a, np.zeros(int(math.ceil(T / dt)))])
    t = np.arange((a.size - 1) * up + 1) * dt / up
    fine = np.interp(t, np.arange(a.size) * dt, a)
    sys = signal.lti([[0, 1], [-w * w, -2 * z * w]], [[0], [-1]], [[1, 0]], [[0]])
    _, y, _ = signal.lsim(sys, fine, t, interp=True)
    return w * w * float(np.max(np.abs(y)))


# ------------------------------------------------------------------------------ library
def test_scale_to_pga_exact() -> None:
    rec = _elcentro()
    new, f = scale_to_pga(rec, 2.5)
    assert abs(new.pga / 2.5 - 1) < 1e-12
    assert f == pytest.approx(2.5 / rec.pga, rel=1e-12)
    np.testing.assert_allclose(new.accel, f * rec.accel, rtol=1e-15)
    assert new.dt == rec.dt and new.meta["scale_factor"] == pytest.approx(f)
    assert "scaled by" in new.provenance


@pytest.mark.parametrize(("T", "sa"), [(0.2, 6.0), (0.65, 4.0), (1.5, 1.0)])
def test_scale_to_sa_against_lsim(T: float, sa: float) -> None:
    rec = _elcentro()
    new, f = scale_to_sa(rec, T, sa)
    ref = _lsim_sa(new.accel, new.dt, T, up=50 if T < 1 else 10)
    err = abs(ref / sa - 1)
    assert err < TOL, err
    # the record's PGA follows the same factor
    assert abs(new.pga / (f * rec.pga) - 1) < 1e-12


def test_scale_record_info_and_sa_after() -> None:
    rec = _elcentro()
    new, info = scale_record(rec, sa=3.0, period=0.5)
    assert info["method"] == "sa" and info["period_s"] == 0.5
    assert info["sa_after"] == pytest.approx(3.0, rel=1e-9)
    assert info["sa_after"] / info["sa_before"] == pytest.approx(info["factor"], rel=1e-9)
    assert info["pga_after"] == pytest.approx(new.pga)
    new2, info2 = scale_record(rec, factor=2.0)
    assert info2["factor"] == 2.0 and new2.pga == pytest.approx(2 * rec.pga)
    with pytest.raises(InputError, match="exactly one"):
        scale_record(rec, pga=1.0, factor=2.0)


@pytest.mark.parametrize("bad", [0.0, -1.0, math.inf, math.nan])
def test_bad_targets(bad: float) -> None:
    rec = _elcentro(2.0)
    with pytest.raises(InputError, match="'pga'"):
        scale_to_pga(rec, bad)
    with pytest.raises(InputError, match="'sa'"):
        scale_to_sa(rec, 0.5, bad)
    with pytest.raises(InputError, match="'factor'"):
        scale_by(rec, bad)


@pytest.mark.parametrize("T", [0.0, 0.005, 10.5, -0.3, math.nan])
def test_period_outside_range(T: float) -> None:
    with pytest.raises(InputError, match=r"a period in \[0.01, 10\] s") as exc:
        scale_to_sa(_elcentro(2.0), T, 1.0)
    assert exc.value.field == "period"
    assert PERIOD_RANGE == (0.01, 10.0)


def test_zero_record_cannot_be_scaled() -> None:
    rec = Record(np.zeros(100), 0.01, name="silence")
    with pytest.raises(InputError, match="non-zero"):
        scale_to_pga(rec, 1.0)
    with pytest.raises(InputError, match="non-zero Sa"):
        scale_to_sa(rec, 0.5, 1.0)


# ------------------------------------------------------------------------------ seisrack run
@pytest.fixture(scope="module")
def rec_csv(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return record_csv(tmp_path_factory.mktemp("rec") / "elcentro_5s.csv")


def _run(capsys: pytest.CaptureFixture[str], rec: Path, *args: str) -> tuple[dict, str]:
    assert main(["run", str(PAPER_RACK), "--motion", str(rec), *args, "--json"]) == 0
    out = capsys.readouterr()
    return json.loads(out.out), out.err


def test_cli_scale_pga_m_s2_and_g(capsys: pytest.CaptureFixture[str], rec_csv: Path) -> None:
    base = read_record(rec_csv)
    out, err = _run(capsys, rec_csv, "--scale-pga", "2.5")
    sc = out["scaling"]
    assert sc["method"] == "pga" and sc["target"] == 2.5
    assert sc["factor"] == pytest.approx(2.5 / base.pga, rel=1e-12)
    assert abs(sc["run_ground_pga_m_s2"] / 2.5 - 1) < TOL  # the run's ground peak
    assert abs(sc["pga_after"] / 2.5 - 1) < TOL and "warning" not in err
    # in g, above 3 g: a warning on stderr, not an error
    out, err = _run(capsys, rec_csv, "--scale-pga", "3.2", "--scale-units", "g", "--mu", "100")
    assert abs(out["scaling"]["run_ground_pga_m_s2"] / (3.2 * G) - 1) < TOL
    assert "warning" in err and "3 g" in err


def test_cli_scale_sa_given_period(capsys: pytest.CaptureFixture[str], rec_csv: Path) -> None:
    base = read_record(rec_csv)
    out, _ = _run(capsys, rec_csv, "--scale-sa", "0.65", "5.0")
    sc = out["scaling"]
    assert sc["method"] == "sa" and sc["period_s"] == 0.65 and sc["period_from"] == "given"
    ref = _lsim_sa(sc["factor"] * base.accel, base.dt, 0.65)
    assert abs(ref / 5.0 - 1) < TOL, ref
    assert abs(sc["sa_after"] / 5.0 - 1) < 1e-9
    assert abs(sc["run_ground_pga_m_s2"] / (sc["factor"] * base.pga) - 1) < TOL


def test_cli_scale_sa_t1(capsys: pytest.CaptureFixture[str], rec_csv: Path) -> None:
    base = read_record(rec_csv)
    out, _ = _run(capsys, rec_csv, "--scale-sa", "T1", "0.5", "--scale-units", "g")
    sc = out["scaling"]
    T1 = sc["period_s"]
    assert sc["period_from"] == "T1" and abs(T1 - 0.65) < 0.02  # paper §IV: T1 = 0.65 s
    ref = _lsim_sa(sc["factor"] * base.accel, base.dt, T1)
    assert abs(ref / (0.5 * G) - 1) < TOL, ref
    assert abs(sc["run_ground_pga_m_s2"] / sc["pga_after"] - 1) < TOL


def test_cli_scale_factor_and_vertical(capsys: pytest.CaptureFixture[str], rec_csv: Path,
                                       tmp_path: Path) -> None:
    base = read_record(rec_csv)
    vert = write_record_csv(Record(0.3 * base.accel, base.dt, name="v"), tmp_path / "v.csv")
    out, _ = _run(capsys, rec_csv, "--scale", "0.5", "--vertical", str(vert))
    sc = out["scaling"]
    assert sc["factor"] == 0.5 and sc["method"] == "factor"
    assert sc["vertical_pga_after"] == pytest.approx(0.5 * 0.3 * base.pga, rel=1e-9)
    assert abs(sc["run_ground_pga_m_s2"] / (0.5 * base.pga) - 1) < TOL
    # the text report says how the record was scaled
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--scale", "0.5"]) == 0
    assert "scaling: by a given factor, factor 0.5" in capsys.readouterr().out


@pytest.mark.parametrize(("args", "field"), [
    (["--scale-pga", "0"], "--scale-pga"),
    (["--scale-pga", "-1.5"], "--scale-pga"),
    (["--scale", "0"], "--scale"),
    (["--scale-sa", "0.5", "0"], "--scale-sa VALUE"),
    (["--scale-sa", "0.5", "-2"], "--scale-sa VALUE"),
    (["--scale-sa", "20", "1.0"], "--scale-sa T"),
    (["--scale-sa", "0.001", "1.0"], "--scale-sa T"),
    (["--scale-sa", "T2", "1.0"], "--scale-sa T"),
])
def test_cli_bad_scaling(capsys: pytest.CaptureFixture[str], rec_csv: Path, args: list[str],
                         field: str) -> None:
    assert main(["run", str(PAPER_RACK), "--motion", str(rec_csv), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and "\n\n" not in err and err.count("\n") == 0
    assert f"'{field}'" in err
    if "T'" in f"'{field}'" and args[1] != "T2":
        assert "[0.01, 10] s" in err


def test_cli_two_scaling_options(capsys: pytest.CaptureFixture[str], rec_csv: Path) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["run", str(PAPER_RACK), "--motion", str(rec_csv), "--scale-pga", "2",
              "--scale", "1.5"])
    assert exc.value.code == 2
    err = capsys.readouterr().err.strip()
    assert "not allowed with argument" in err and "Traceback" not in err and "\n\n" not in err


# ------------------------------------------------------------------------------ suite check
def _write_at2(rec: Record, path: Path) -> Path:
    vals = rec.accel / G
    rows = [" ".join(f"{v: .7E}" for v in vals[i:i + 5]) for i in range(0, vals.size, 5)]
    path.write_text("PEER NGA STRONG MOTION DATABASE RECORD\n"
                    f"{rec.name}, test record\nACCELERATION TIME SERIES IN UNITS OF G\n"
                    f"NPTS=  {vals.size}, DT=   {rec.dt:.4f} SEC\n" + "\n".join(rows) + "\n")
    return path


@pytest.fixture(scope="module")
def suite_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """5 records: 3 synthetic (seisrack CSV, m/s²), El Centro as .AT2 (g) and as text in g."""
    d = tmp_path_factory.mktemp("suite")
    for r in generate_ec8_suite(3, seed=11, type=1, ground="C", ag=0.25, duration=14.0):
        write_record_csv(r, d / f"{r.name}.csv")
    full = load_builtin_record("elcentro_1940_ns")
    _write_at2(full, d / "elcentro.AT2")
    half = Record(full.accel[:2000], full.dt, name="elcentro_20s")
    np.savetxt(d / "elcentro_20s.txt", np.column_stack([half.time, half.accel / G]),
               fmt="%.8g", header="time [s], accel [g]")
    (d / "notes.md").write_text("not a record\n")
    return d


def test_read_suite_mixed_formats(suite_dir: Path) -> None:
    recs = read_suite([suite_dir], units="g")
    assert len(recs) == 5
    by = {r.name: r for r in recs}
    ec = load_builtin_record("elcentro_1940_ns")
    assert by["elcentro"].pga == pytest.approx(ec.pga, rel=1e-6)  # AT2 read in g
    assert by["elcentro_20s"].pga == pytest.approx(np.max(np.abs(ec.accel[:2000])), rel=1e-6)
    with pytest.raises(InputError, match="units"):
        read_suite([suite_dir])  # the .txt file does not say its units


def test_cli_check_folder_and_scale(capsys: pytest.CaptureFixture[str], suite_dir: Path) -> None:
    common = ["--type", "1", "--ground", "C", "--ag", "0.3", "--units", "g", "--json"]
    rc = main(["motion", "check", str(suite_dir), "--period", "0.65", *common])
    rep = json.loads(capsys.readouterr().out)
    assert rc == (0 if rep["passed"] else 1) and len(rep["records"]) == 5
    f = rep["scale_factor_needed"]
    # the factor from the report's own arrays, by the definition
    ratio = np.array(rep["mean_psa_m_s2"]) / np.array(rep["target_psa_m_s2"])
    mean_pga = np.mean([r["pga_m_s2"] for r in rep["records"]])
    assert f == pytest.approx(max(0.9 / ratio.min(), rep["ag_S_m_s2"] / mean_pga), rel=1e-12)

    rc = main(["motion", "check", str(suite_dir), "--period", "0.65", "--scale-suite", *common])
    rep = json.loads(capsys.readouterr().out)
    sc = rep["scaled"]
    assert sc["factor"] == pytest.approx(f)
    checks = {c["name"]: c for c in sc["checks"]}
    pga_ratio = checks["mean PGA / (ag·S)"]["value"]
    spec_ratio = checks["min mean/target spectrum in [0.2 T1, 2 T1]"]["value"]
    # the governing rule holds with equality, the other holds
    assert min(pga_ratio - 1.0, spec_ratio - 0.9) == pytest.approx(0.0, abs=1e-9)
    assert pga_ratio >= 1 - 1e-9 and spec_ratio >= 0.9 - 1e-9
    # the scaled mean spectrum, recomputed here with the response spectrum of each scaled record
    recs = read_suite([suite_dir], units="g")
    T = np.array(sc["periods_s"])
    mean = np.mean([response_spectrum(f * r.accel, r.dt, T).psa for r in recs], axis=0)
    np.testing.assert_allclose(mean, sc["mean_psa_m_s2"], rtol=1e-9)
    assert rc == (0 if sc["passed"] else 1)


def test_cli_check_t1_from_rack_and_list(capsys: pytest.CaptureFixture[str],
                                         suite_dir: Path) -> None:
    files = sorted(str(p) for p in suite_dir.glob("*.csv"))
    rc = main(["motion", "check", *files, str(suite_dir / "elcentro.AT2"), "--rack",
               str(PAPER_RACK), "--type", "1", "--ground", "C", "--ag", "0.25", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert len(rep["records"]) == 4 and abs(rep["period_s"] - 0.65) < 0.02
    assert rep["periods_s"][0] == pytest.approx(0.2 * rep["period_s"])
    assert rc in (0, 1)


def test_check_ec8_suite_reports_factor() -> None:
    target = ec8_spectrum(1, "C", 0.3)
    recs = [_elcentro(6.0)] * 3
    rep = check_ec8_suite(recs, target, 0.5)
    scaled = check_ec8_suite([scale_by(r, rep.scale_factor) for r in recs], target, 0.5)
    vals = {i.name: i.value for i in scaled.items}
    assert min(vals["mean PGA / (ag·S)"] - 1, vals["min mean/target spectrum in [0.2 T1, 2 T1]"]
               - 0.9) == pytest.approx(0.0, abs=1e-9)
    assert "scale factor" in rep.text()


def test_cli_check_bad_input(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    common = ["--type", "1", "--ground", "C", "--ag", "0.3", "--period", "0.5"]
    empty = tmp_path / "empty"
    empty.mkdir()
    assert main(["motion", "check", str(empty), *common]) == 2
    assert "a folder holding record files" in capsys.readouterr().err
    assert main(["motion", "check", str(tmp_path / "nope"), *common]) == 2
    assert "an existing record file or folder" in capsys.readouterr().err
