"""Ground-motion records: the :class:`Record` container, file readers and writers, bundled records.

Units are explicit at the boundary and SI inside: a file in g is converted once, on reading, with
standard gravity ``G = 9.80665 m/s²`` (ISO 80000-3). Supported inputs:

- PEER NGA ``.AT2`` files: four header lines, the fourth giving NPTS and DT, then values in g;
- one-column text (``dt`` must be given) and two-column text/CSV ``time, accel`` (``dt`` is taken
  from the time column, which must be uniform). Separators: comma, semicolon or white space;
  ``#`` starts a comment; one non-numeric header line is allowed. A header ``time_s,accel_m_s2``
  (what :func:`write_record_csv` writes) declares the units m/s².
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.errors import FileFormatError, InputError

G = 9.80665  # standard gravity [m/s²]

_UNITS = {"g": G, "m/s2": 1.0, "m/s^2": 1.0, "m/s²": 1.0, "m_s2": 1.0}
_SEP = re.compile(r"[,;\s]+")
_HEADER = "time_s,accel_m_s2"
# relative tolerance on time steps read from a time column (files carry ~6 significant digits)
_DT_RTOL = 1e-4
#: [s] shortest time step of a ground motion: accelerograms are sampled at 50-1000 Hz; a step
#: of 1e-300 s (a PEER file's DT) reached the acceleration filter's design, singular there
MIN_DT = 1e-6
#: [s] longest time step of a record file (a sample a second at most; 1e300 s passed the reader
#: and was blamed on --dt)
MAX_DT = 1.0


@dataclass(frozen=True, eq=False)
class Record:
    """A uniformly sampled ground-acceleration record.

    Attributes:
        accel: (n,) [m/s²] ground acceleration, sample ``k`` at time ``k * dt``.
        dt: [s] time step.
        name: short label.
        provenance: where the record comes from (file, generator and seed, bundled source).
        meta: free-form metadata (e.g. ``stationary_duration_s`` of a synthetic record).
    """

    accel: np.ndarray
    dt: float
    name: str = "record"
    provenance: str = ""
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        a = np.array(self.accel, dtype=np.float64)
        if a.ndim != 1 or a.size < 2:
            raise InputError("accel", f"shape {a.shape}", "a 1-D array of at least 2 samples")
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise InputError("accel", f"non-finite value at sample {bad[0]}", "finite numbers")
        dt = float(self.dt)
        if not (math.isfinite(dt) and dt >= MIN_DT):
            raise InputError("dt", self.dt, f"a finite time step >= {MIN_DT:g} s (an "
                             "accelerogram sampled at most at 1 MHz)")
        a.setflags(write=False)
        object.__setattr__(self, "accel", a)
        object.__setattr__(self, "dt", dt)

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.accel.size)

    @property
    def duration(self) -> float:
        """[s] time of the last sample, ``(n - 1) * dt``."""
        return (self.n - 1) * self.dt

    @property
    def time(self) -> np.ndarray:
        """(n,) [s] sample times."""
        return np.arange(self.n) * self.dt

    @property
    def pga(self) -> float:
        """[m/s²] peak ground acceleration, ``max |accel|``."""
        return float(np.max(np.abs(self.accel)))


def _unit_factor(units: str | None, field_name: str = "units") -> float:
    if units is None:
        raise InputError(field_name, None, "'g' or 'm/s2'", hint="Say which units the file uses")
    key = units.strip().lower().replace(" ", "")
    if key not in _UNITS:
        raise InputError(field_name, units, "'g' or 'm/s2'")
    return _UNITS[key]


def _check_dt(dt: float | None) -> float | None:
    if dt is None:
        return None
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    return float(dt)


def _parse_float(tok: str, path: str, lineno: int) -> float:
    try:
        val = float(tok)
    except ValueError:
        raise FileFormatError(path, f"expected a number, got {tok!r}", lineno) from None
    if not math.isfinite(val):
        raise FileFormatError(path, f"non-finite value {tok!r}", lineno)
    return val


def _read_at2(path: str, lines: list[str]) -> tuple[np.ndarray, float, str]:
    """PEER NGA .AT2: 3 descriptive lines, line 4 has NPTS and DT, then values in g."""
    if len(lines) < 5:
        raise FileFormatError(path, "AT2 file too short: expected 4 header lines and data")
    head = lines[3]
    m_n = re.search(r"NPTS\s*=\s*(\d+)", head, re.I)
    m_dt = re.search(r"DT\s*=\s*([0-9.eE+-]+)", head, re.I)
    if m_n and m_dt:
        npts, dt = int(m_n.group(1)), _parse_float(m_dt.group(1), path, 4)
    else:  # older layout: "  5368   0.0100   NPTS, DT"
        toks = head.split()
        try:
            npts, dt = int(toks[0]), float(toks[1])
        except (ValueError, IndexError):
            raise FileFormatError(path, "line 4 must give NPTS and DT", 4) from None
    if npts < 2 or not (math.isfinite(dt) and dt > 0):
        raise FileFormatError(path, f"invalid NPTS={npts} or DT={dt}", 4)
    if not MIN_DT <= dt <= MAX_DT:
        raise FileFormatError(path, f"DT={dt:g} s is not the step of an accelerogram "
                              f"({MIN_DT:g} to {MAX_DT:g} s)", 4)
    vals: list[float] = []
    for lineno, line in enumerate(lines[4:], start=5):
        for tok in line.split():
            vals.append(_parse_float(tok, path, lineno))
    if len(vals) != npts:
        raise FileFormatError(path, f"header says NPTS={npts} but {len(vals)} values were read")
    return np.asarray(vals), dt, lines[1].strip()


def _read_columns(
    path: str, lines: list[str], dt: float | None, units: str | None
) -> tuple[np.ndarray, float, str | None]:
    rows: list[list[float]] = []
    linenos: list[int] = []
    header_units: str | None = None
    ncol: int | None = None
    for lineno, raw in enumerate(lines, start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        toks = [t for t in _SEP.split(line) if t]
        if not rows and header_units is None and not _looks_numeric(toks[0]):
            # one header line allowed before the data
            if line.replace(" ", "").lower() == _HEADER:
                header_units = "m/s2"
            else:
                header_units = ""
            continue
        if ncol is None:
            ncol = len(toks)
            if ncol not in (1, 2):
                raise FileFormatError(path, f"expected 1 or 2 columns, found {ncol}", lineno)
        elif len(toks) != ncol:
            raise FileFormatError(path, f"expected {ncol} column(s), found {len(toks)}", lineno)
        rows.append([_parse_float(t, path, lineno) for t in toks])
        linenos.append(lineno)
    if len(rows) < 2:
        raise FileFormatError(path, "fewer than 2 data lines")
    arr = np.asarray(rows)
    if header_units and units is not None and _unit_factor(units) != _UNITS[header_units]:
        raise InputError(
            "units", units, f"'{header_units}' (declared by the header of {path})"
        )
    if ncol == 1:
        if dt is None:
            raise InputError(
                "dt", None, "a time step > 0 s", source=path,
                hint="A one-column file carries no time: pass dt (CLI: --dt)",
            )
        return arr[:, 0], dt, header_units or None
    t = arr[:, 0]
    steps = np.diff(t)
    dt_file = float(t[1] - t[0])  # the first step is the reference: report the first deviation
    if not dt_file > 0:
        raise FileFormatError(path, "time column is not increasing", linenos[1])
    if not MIN_DT <= dt_file <= MAX_DT:
        raise FileFormatError(path, f"a time step of {dt_file:g} s is not the step of an "
                              f"accelerogram ({MIN_DT:g} to {MAX_DT:g} s)", linenos[1])
    bad = np.flatnonzero(np.abs(steps - dt_file) > _DT_RTOL * dt_file + 1e-9)
    if bad.size:
        k = bad[0]
        raise FileFormatError(
            path,
            f"non-uniform time step: {steps[k]:.6g} s between t={t[k]:.6g} and "
            f"t={t[k + 1]:.6g} (first step {dt_file:.6g} s); resample the record first",
            linenos[k + 1],
        )
    dt_file = float((t[-1] - t[0]) / (t.size - 1))  # mean step: fewer rounding digits lost
    if dt is not None and abs(dt - dt_file) > _DT_RTOL * dt_file:
        raise InputError("dt", dt, f"{dt_file:.6g} s, the step of the time column", source=path)
    return arr[:, 1], float(dt_file), header_units or None


def _looks_numeric(tok: str) -> bool:
    try:
        float(tok)
    except ValueError:
        return False
    return True


def read_record(
    path: str | Path, units: str | None = None, dt: float | None = None, name: str | None = None
) -> Record:
    """Read an accelerogram file into a :class:`Record` (acceleration in m/s²).

    Args:
        path: a PEER NGA ``.AT2`` file, or a 1- or 2-column text/CSV file.
        units: units of the acceleration values in the file, ``"g"`` or ``"m/s2"``. Optional for
            ``.AT2`` (always g) and for CSV files with the header ``time_s,accel_m_s2``;
            required otherwise.
        dt: [s] time step, required for one-column files; for two-column files it must agree
            with the time column if given.
        name: record label (default: the file stem).

    Raises:
        FileFormatError: malformed file (with the line number), non-finite values, non-uniform
            time steps, NPTS mismatch.
        InputError: missing or inconsistent ``units`` / ``dt``.
    """
    p = Path(path)
    dt = _check_dt(dt)
    text = p.read_text(encoding="utf-8-sig", errors="replace")  # Excel, Notepad: a BOM
    lines = text.splitlines()
    spath = str(p)
    if p.suffix.lower() == ".at2":
        if units is not None and _unit_factor(units) != G:
            raise InputError("units", units, "'g' (PEER .AT2 files are in g)", source=spath)
        values, dt_file, title = _read_at2(spath, lines)
        if dt is not None and abs(dt - dt_file) > _DT_RTOL * dt_file:
            raise InputError("dt", dt, f"{dt_file:g} s, the DT of the file header", source=spath)
        factor, dt_used, prov = G, dt_file, f"PEER NGA file {spath}: {title}"
    else:
        values, dt_used, header_units = _read_columns(spath, lines, dt, units)
        factor = _unit_factor(units if header_units is None else header_units)
        prov = f"file {spath}"
    return Record(values * factor, dt_used, name=name or p.stem, provenance=prov)


def write_record_csv(record: Record, path: str | Path) -> Path:
    """Write ``record`` as CSV with header ``time_s,accel_m_s2`` (SI, 17 significant digits).

    Returns the path written. Read it back with ``read_record(path)`` (units from the header).
    """
    from seisrack.atomic import atomic_write

    data = np.column_stack([record.time, record.accel])
    return atomic_write(path, lambda p: np.savetxt(p, data, delimiter=",", header=_HEADER,
                                                   comments="", fmt="%.10g"))


# name -> (file, units, dt [s], description)
_BUILTIN: dict[str, tuple[str, str, float, str]] = {
    "elcentro_1940_ns": (
        "elcentro_1940_ns.txt",
        "g",
        0.01,
        "Imperial Valley 1940-05-19, El Centro (IVID substation), N-S; US Coast and Geodetic "
        "Survey recording (public domain); values as distributed in quakeio 0.1.21 (BSD). "
        "See seisrack/data/records/PROVENANCE.md",
    ),
}


def list_builtin_records() -> list[str]:
    """Names accepted by :func:`load_builtin_record`."""
    return sorted(_BUILTIN)


def load_builtin_record(name: str) -> Record:
    """Load a bundled real accelerogram (acceleration in m/s²) with its provenance.

    ``list_builtin_records()`` gives the names; ``"elcentro_1940_ns"`` is El Centro 1940 N-S
    (3995 samples at 0.01 s, PGA 0.313 g).
    """
    if name not in _BUILTIN:
        raise InputError("name", name, ", ".join(list_builtin_records()))
    fname, units, dt, desc = _BUILTIN[name]
    ref = resources.files("seisrack") / "data" / "records" / fname
    with resources.as_file(ref) as fpath:
        rec = read_record(fpath, units=units, dt=dt, name=name)
    return Record(rec.accel, rec.dt, name=name, provenance=desc)
