"""Record files: PEER NGA .AT2 and text/CSV readers, the CSV writer, the bundled record.

Sources: the PEER NGA strong-motion file layout (4 header lines, line 4 "NPTS=..., DT=... SEC",
values in g); the bundled El Centro 1940 N-S record's published characteristics (PGA ≈ 0.31 g near
t ≈ 2.1 s), see src/seisrack/data/records/PROVENANCE.md.
"""

from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import FileFormatError, InputError
from seisrack.motion import (
    G,
    Record,
    list_builtin_records,
    load_builtin_record,
    read_record,
    write_record_csv,
)

AT2 = """PEER NGA STRONG MOTION DATABASE RECORD
Test event, test station
ACCELERATION TIME SERIES IN UNITS OF G
NPTS=    7, DT=   .0100 SEC
  0.0  0.1  -0.2  0.3  0.1
  0.0  0.05
"""


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_read_at2(tmp_path: Path) -> None:
    rec = read_record(_write(tmp_path, "x.AT2", AT2))
    assert rec.dt == pytest.approx(0.01) and rec.n == 7
    np.testing.assert_allclose(rec.accel[:4], np.array([0.0, 0.1, -0.2, 0.3]) * G)
    assert "PEER" in rec.provenance
    old = AT2.replace("NPTS=    7, DT=   .0100 SEC", "   7   0.0100   NPTS, DT")
    assert read_record(_write(tmp_path, "y.at2", old)).n == 7


def test_at2_errors_give_line_numbers(tmp_path: Path) -> None:
    bad = AT2.replace("-0.2", "-0.2x")
    with pytest.raises(FileFormatError) as exc:
        read_record(_write(tmp_path, "b.AT2", bad))
    assert exc.value.line == 5 and "line 5" in str(exc.value)
    with pytest.raises(FileFormatError, match="NPTS=7"):
        read_record(_write(tmp_path, "c.AT2", AT2 + "  0.1\n"))
    with pytest.raises(FileFormatError) as exc:
        read_record(_write(tmp_path, "d.AT2", AT2.replace("0.05", "nan")))
    assert exc.value.line == 6
    with pytest.raises(InputError):
        read_record(_write(tmp_path, "e.AT2", AT2), units="m/s2")


@pytest.mark.parametrize("dt", ["1e-300", "1e-7", "1e300", "2.0"])
def test_a_step_no_accelerogram_has_is_refused(tmp_path: Path, dt: str) -> None:
    """DT = 1e-300 reached the acceleration filter's design (a LinAlgError), 1e300 was blamed
    on --dt: the readers take steps from 1e-6 to 1 s, naming the line."""
    with pytest.raises(FileFormatError, match="not the step of an accelerogram") as exc:
        read_record(_write(tmp_path, "x.AT2", AT2.replace("DT=   .0100", f"DT= {dt}")))
    assert exc.value.line == 4
    t = [0.0, float(dt), 2 * float(dt)]
    text = "time_s,accel_m_s2\n" + "".join(f"{x!r},0.1\n" for x in t)
    with pytest.raises(FileFormatError, match="not the step of an accelerogram"):
        read_record(_write(tmp_path, "x.csv", text))


def test_one_and_two_column_text(tmp_path: Path) -> None:
    one = _write(tmp_path, "one.txt", "# comment\n0.0\n0.5\n-0.5\n0.0\n")
    r1 = read_record(one, units="m/s2", dt=0.02)
    assert r1.n == 4 and r1.dt == 0.02 and r1.accel[1] == 0.5
    with pytest.raises(InputError) as exc:
        read_record(one, units="m/s2")
    assert exc.value.field == "dt"
    with pytest.raises(InputError) as exc:
        read_record(one, dt=0.02)
    assert exc.value.field == "units"
    two = _write(tmp_path, "two.csv", "t,a\n0.0,0.0\n0.005,0.1\n0.010,-0.1\n0.015,0.0\n")
    r2 = read_record(two, units="g")
    assert r2.dt == pytest.approx(0.005) and r2.accel[1] == pytest.approx(0.1 * G)
    ws = _write(tmp_path, "ws.txt", "0 0\n0.01 1\n0.02 2\n")
    assert read_record(ws, units="m/s2").dt == pytest.approx(0.01)


def test_text_errors(tmp_path: Path) -> None:
    nonuni = _write(tmp_path, "n.csv", "0.0,0\n0.01,1\n0.02,2\n0.035,3\n0.045,4\n")
    with pytest.raises(FileFormatError, match="non-uniform") as exc:
        read_record(nonuni, units="g")
    assert exc.value.line == 4
    ragged = _write(tmp_path, "r.csv", "0.0,0\n0.01,1\n0.02\n")
    with pytest.raises(FileFormatError) as exc:
        read_record(ragged, units="g")
    assert exc.value.line == 3
    inf = _write(tmp_path, "i.txt", "0\n1\ninf\n")
    with pytest.raises(FileFormatError, match="non-finite") as exc:
        read_record(inf, units="g", dt=0.01)
    assert exc.value.line == 3
    with pytest.raises(FileFormatError, match="number"):
        read_record(_write(tmp_path, "w.txt", "0\n1\nabc\n"), units="g", dt=0.01)
    with pytest.raises(FileFormatError):
        read_record(_write(tmp_path, "s.txt", "0\n"), units="g", dt=0.01)


def test_csv_round_trip(tmp_path: Path) -> None:
    rec = Record(np.array([0.0, 1.25, -2.5, 0.125]), 0.01, name="x")
    p = write_record_csv(rec, tmp_path / "x.csv")
    assert p.read_text().splitlines()[0] == "time_s,accel_m_s2"
    back = read_record(p)  # units from the header
    np.testing.assert_allclose(back.accel, rec.accel)
    assert back.dt == pytest.approx(0.01)
    with pytest.raises(InputError):
        read_record(p, units="g")


def test_record_validation() -> None:
    with pytest.raises(InputError):
        Record(np.array([0.0, np.nan]), 0.01)
    with pytest.raises(InputError):
        Record(np.array([0.0, 1.0]), -0.01)
    r = Record([0.0, 1.0, 0.0], 0.5)
    assert r.duration == 1.0 and r.pga == 1.0
    with pytest.raises(ValueError):
        r.accel[0] = 3.0  # read-only


def test_builtin_el_centro() -> None:
    assert "elcentro_1940_ns" in list_builtin_records()
    rec = load_builtin_record("elcentro_1940_ns")
    assert rec.n == 3995 and rec.dt == 0.01
    assert rec.pga / G == pytest.approx(0.313, abs=0.002)
    assert rec.time[np.argmax(np.abs(rec.accel))] == pytest.approx(2.15, abs=0.05)
    assert "public domain" in rec.provenance
    with pytest.raises(InputError):
        load_builtin_record("kobe")
