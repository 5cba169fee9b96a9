"""`seisrack motion generate|spectrum|check` through `seisrack.cli.main` (issue #4, item 6)."""

import json
from pathlib import Path

import numpy as np
import pytest

from seisrack.cli import main
from seisrack.motion import read_record


def test_generate_spectrum_check(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    folder = tmp_path / "suite"
    rc = main(["motion", "generate", "--spectrum", "ec8", "--type", "1", "--ground", "C",
               "--ag", "0.3", "--duration", "15", "--count", "3", "--seed", "2",
               "--out", str(folder), "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    files = sorted(folder.glob("*.csv"))
    assert len(files) == 3 and len(out["records"]) == 3
    rec = read_record(files[0])
    assert rec.dt == 0.01 and rec.n == 1501

    rc = main(["motion", "spectrum", str(files[0]), "--periods", "0.1,0.5,1", "--json"])
    assert rc == 0
    sp = json.loads(capsys.readouterr().out)
    assert sp["periods_s"] == [0.1, 0.5, 1.0]
    assert len(sp["psa_m_s2"]) == 3 and all(np.isfinite(sp["psa_m_s2"]))

    rc = main(["motion", "check", *map(str, files), "--type", "1", "--ground", "C",
               "--ag", "0.3", "--period", "0.5", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert {c["name"] for c in rep["checks"]} >= {"number of records", "mean PGA / (ag·S)"}
    assert rc == (0 if rep["passed"] else 1)


def test_generate_one_file_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "one.csv"
    png = tmp_path / "fig15.png"
    rc = main(["motion", "generate", "--type", "2", "--ground", "B", "--ag", "0.2",
               "--duration", "12", "--seed", "1", "--out", str(out), "--plot", str(png)])
    assert rc == 0 and out.is_file() and png.stat().st_size > 1000
    assert out.read_text().splitlines()[0] == "time_s,accel_m_s2"


def test_errors_exit_nonzero_without_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("0,0\n0.01,1\n0.02,oops\n")
    assert main(["motion", "spectrum", str(bad), "--units", "g"]) == 2
    err = capsys.readouterr().err
    assert "line 3" in err and "Traceback" not in err
    assert main(["motion", "spectrum", str(tmp_path / "missing.csv")]) == 2
    assert "Traceback" not in capsys.readouterr().err
    one = tmp_path / "one.txt"
    one.write_text("0\n1\n0\n")
    assert main(["motion", "spectrum", str(one), "--units", "g"]) == 2  # no dt
    assert "dt" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["motion", "generate", "--ag", "0.3", "--out", str(tmp_path)])  # no --seed
    assert exc.value.code == 2


def test_generate_never_overwrites_without_force(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Nothing the user already has is lost: existing record files are kept unless --force."""
    mine = tmp_path / "mine.csv"
    mine.write_text("precious\n")
    base = ["motion", "generate", "--type", "1", "--ground", "C", "--ag", "0.3",
            "--duration", "12", "--seed", "3"]
    assert main([*base, "--out", str(mine)]) == 2
    assert mine.read_text() == "precious\n"
    assert "--force" in capsys.readouterr().err
    suite = tmp_path / "suite"
    assert main([*base, "--count", "2", "--out", str(suite)]) == 0
    written = sorted(p.name for p in suite.iterdir())
    before = {p: p.read_bytes() for p in suite.iterdir()}
    # the second call would write seed 4 again (3 + 1): refused, nothing touched
    assert main([*base[:-1], "4", "--count", "2", "--out", str(suite)]) == 2
    assert {p: p.read_bytes() for p in suite.iterdir()} == before
    assert written == ["EC8_type_1_ground_C_seed3.csv", "EC8_type_1_ground_C_seed4.csv"]
    assert main([*base, "--out", str(mine), "--force"]) == 0
    assert read_record(mine).accel.size > 100


def test_check_folder_text_report(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A folder of records (issue #14 item 4): text report with the common scale factor."""
    folder = tmp_path / "suite"
    assert main(["motion", "generate", "--ag", "0.3", "--duration", "12", "--count", "3",
                 "--seed", "5", "--out", str(folder)]) == 0
    capsys.readouterr()
    rc = main(["motion", "check", str(folder), "--type", "1", "--ground", "C", "--ag", "0.3",
               "--period", "0.5", "--scale-suite"])
    out = capsys.readouterr().out
    assert "3 records" in out and "smallest common scale factor" in out
    assert "after scaling every record by" in out
    assert rc in (0, 1) and ("does NOT comply" in out.split("after scaling")[1]) == (rc == 1)


@pytest.mark.parametrize(("option", "value"), [
    ("--ag", "-1"), ("--ag", "nan"), ("--importance", "9"), ("--duration", "-3"),
    ("--dt", "0"), ("--damping", "2"), ("--seed", "-1"),
])
def test_generate_errors_name_the_option_typed(
        tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, value: str) -> None:
    """A bad ``motion generate`` option is named as the user typed it (``--ag``), not by the
    library's parameter (``ag``), and nothing is written."""
    argv = ["motion", "generate", "--ag", "0.2", "--seed", "1",
            "--out", str(tmp_path / "x.csv")]
    if option in argv:
        argv[argv.index(option) + 1] = value
    else:
        argv += [option, value]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"invalid value for '{option}'" in err and "Traceback" not in err
    assert not (tmp_path / "x.csv").exists()
