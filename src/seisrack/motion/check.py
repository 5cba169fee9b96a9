"""EN 1998-1 §3.2.3.1.2 compliance of a suite of accelerograms with a target spectrum.

Checks, each reported pass/fail with its numbers:

- §3.2.3.1.2(3): at least 3 accelerograms;
- §3.2.3.1.2(4)a: mean of the records' peak ground accelerations ≥ a_g·S (the target's zero-period
  value);
- §3.2.3.1.2(4)b: in the period range [0.2·T1, 2·T1], no value of the mean 5 %-damped elastic
  spectrum of the suite is below 90 % of the target;
- §3.2.3.1.2(4): stationary part of each record ≥ 10 s. For a synthetic record the envelope's
  plateau (``meta["stationary_duration_s"]``) is used; for others (e.g. files) it is estimated
  as the time between the first and last instants where the 2 s moving RMS acceleration reaches
  half its maximum (-6 dB). EC8 gives no measure; this estimate is ours and is approximate
  (it counts part of the ramps of a trapezoidal envelope).

Scaling a suite. Both amplitude rules are linear in a common factor f applied to every record
(spectra and PGAs scale with f), so the smallest factor meeting both is
``f = max(0.9 / min(mean/target), a_g·S / mean PGA)`` (:func:`suite_scale_factor`). It is
reported with every check (``SuiteReport.scale_factor``); f < 1 means the suite complies with a
margin and could be scaled down by that much.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.errors import InputError
from seisrack.motion.ec8 import DesignSpectrum
from seisrack.motion.records import _HEADER, Record, read_record
from seisrack.motion.spectra import response_spectrum


@dataclass(frozen=True)
class CheckItem:
    """One check: ``name``, ``passed``, the measured ``value``, the ``required`` bound, a note."""

    name: str
    passed: bool
    value: float
    required: float
    note: str = ""


@dataclass(frozen=True, eq=False)
class SuiteReport:
    """Result of :func:`check_ec8_suite`; ``passed`` is True when every check passes.

    ``periods`` (n,) [s], ``mean_psa`` and ``target_psa`` (n,) [m/s²] cover [0.2·T1, 2·T1].
    """

    items: list[CheckItem]
    periods: np.ndarray
    mean_psa: np.ndarray
    target_psa: np.ndarray
    records: list[dict[str, Any]] = field(default_factory=list)
    #: smallest common factor making the suite meet §3.2.3.1.2(4)a and (4)b (see module notes)
    scale_factor: float = float("nan")

    @property
    def passed(self) -> bool:
        return all(i.passed for i in self.items)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready summary."""
        return {
            "passed": self.passed,
            "checks": [vars(i) for i in self.items],
            "records": self.records,
            "scale_factor_needed": self.scale_factor,
            "periods_s": self.periods,
            "mean_psa_m_s2": self.mean_psa,
            "target_psa_m_s2": self.target_psa,
        }

    def text(self) -> str:
        """Plain-text report, one line per check."""
        lines = []
        for i in self.items:
            flag = "PASS" if i.passed else "FAIL"
            lines.append(f"[{flag}] {i.name}: {i.value:.4g} (required {i.required:.4g}) {i.note}")
        lines.append("suite " + ("complies" if self.passed else "does NOT comply"))
        if np.isfinite(self.scale_factor):
            lines.append(f"smallest common scale factor meeting the PGA and spectrum rules: "
                         f"{self.scale_factor:.4g}")
        return "\n".join(lines)


#: file endings :func:`read_suite` picks up in a folder (case-insensitive)
SUITE_SUFFIXES = (".at2", ".csv", ".txt")


def read_suite(
    paths: Sequence[str | Path], units: str | None = None, dt: float | None = None
) -> list[Record]:
    """Read a suite of records from files and/or folders, with :func:`read_record`.

    A folder contributes its files ending in ``.AT2``, ``.csv`` or ``.txt`` (any case), sorted
    by name. ``units`` and ``dt`` apply to the files that need them: PEER ``.AT2`` files are
    always in g and seisrack CSV files declare m/s² in their header, so one suite may mix them
    with ``units`` given for the others.
    """
    files: list[Path] = []
    for entry in paths:
        p = Path(entry)
        if p.is_dir():
            found = sorted(f for f in p.iterdir()
                           if f.is_file() and f.suffix.lower() in SUITE_SUFFIXES)
            if not found:
                raise InputError("files", str(p), "a folder holding record files ("
                                 + ", ".join(SUITE_SUFFIXES) + ")")
            files.extend(found)
        elif p.is_file():
            files.append(p)
        else:
            raise InputError("files", str(p), "an existing record file or folder")
    return [read_record(f, units=None if _declares_units(f) else units, dt=dt) for f in files]


def _declares_units(path: Path) -> bool:
    """True for a ``.AT2`` file (g) or a seisrack CSV whose header gives m/s²."""
    if path.suffix.lower() == ".at2":
        return True
    with path.open(encoding="utf-8-sig", errors="replace") as fh:
        first = fh.readline()
    return first.strip().replace(" ", "").lower() == _HEADER


def stationary_duration(record: Record) -> float:
    """[s] stationary duration: envelope plateau if known, else from the 2 s moving RMS."""
    meta = record.meta or {}
    if "stationary_duration_s" in meta:
        return float(meta["stationary_duration_s"])
    win = max(1, int(round(2.0 / record.dt)))
    rms = np.sqrt(np.convolve(record.accel**2, np.ones(win) / win, mode="same"))
    above = np.flatnonzero(rms >= 0.5 * rms.max())
    return float((above[-1] - above[0]) * record.dt) if above.size else 0.0


def check_ec8_suite(
    records: Sequence[Record],
    target: DesignSpectrum,
    period: float,
    *,
    n_periods: int = 60,
    min_stationary: float = 10.0,
) -> SuiteReport:
    """EC8 §3.2.3.1.2 report for ``records`` against ``target`` with fundamental period T1.

    Args:
        records: the suite, accelerations in m/s².
        target: the elastic spectrum (e.g. ``ec8_spectrum(1, "C", 0.3)``); its damping is used.
        period: [s] fundamental period T1 of the structure.
    """
    if not records:
        raise InputError("records", 0, "at least one record")
    if not (isinstance(period, int | float) and period > 0):
        raise InputError("period", period, "a fundamental period T1 > 0 s")
    T = np.geomspace(0.2 * period, 2.0 * period, n_periods)
    spectra = np.array(
        [response_spectrum(r.accel, r.dt, T, target.damping).psa for r in records]
    )
    mean = spectra.mean(axis=0)
    tgt = target.psa(T)
    ratio = mean / tgt
    pgas = np.array([r.pga for r in records])
    stats = np.array([stationary_duration(r) for r in records])
    k = int(np.argmin(ratio))
    items = [
        CheckItem("number of records", len(records) >= 3, len(records), 3, "§3.2.3.1.2(3)"),
        CheckItem(
            "mean PGA / (ag·S)", bool(pgas.mean() >= target.pga), pgas.mean() / target.pga, 1.0,
            f"mean PGA {pgas.mean():.4g} m/s2 vs {target.pga:.4g} m/s2, §3.2.3.1.2(4)a",
        ),
        CheckItem(
            "min mean/target spectrum in [0.2 T1, 2 T1]", bool(ratio.min() >= 0.9),
            float(ratio.min()), 0.9,
            f"at T = {T[k]:.3g} s, range {T[0]:.3g}-{T[-1]:.3g} s, §3.2.3.1.2(4)b",
        ),
        CheckItem(
            "shortest stationary part [s]", bool(stats.min() >= min_stationary),
            float(stats.min()), min_stationary, "§3.2.3.1.2(4)",
        ),
    ]
    recs = [
        {"name": r.name, "pga_m_s2": p, "stationary_s": s, "duration_s": r.duration}
        for r, p, s in zip(records, pgas, stats, strict=True)
    ]
    factor = suite_scale_factor(mean, tgt, pgas, target.pga)
    return SuiteReport(items, T, mean, tgt, recs, factor)


def suite_scale_factor(
    mean_psa: np.ndarray, target_psa: np.ndarray, pgas: np.ndarray, target_pga: float,
    *, spectrum_fraction: float = 0.9,
) -> float:
    """Smallest common factor f with f·mean ≥ 0.9·target on the range and f·mean PGA ≥ a_g·S.

    Args:
        mean_psa, target_psa: (n,) [m/s²] mean spectrum of the suite and target, same periods.
        pgas: (n_rec,) [m/s²] records' PGAs. target_pga: [m/s²] a_g·S.

    Both rules are linear in f (EN 1998-1 §3.2.3.1.2(4)a, (4)b). Returns inf when the suite's
    mean spectrum or PGA is zero somewhere (no factor can help).
    """
    mean_psa = np.asarray(mean_psa, dtype=float)
    mean_pga = float(np.mean(pgas))
    if np.any(mean_psa <= 0) or not mean_pga > 0:
        return float("inf")
    f_spec = float(np.max(spectrum_fraction * np.asarray(target_psa) / mean_psa))
    return max(f_spec, float(target_pga) / mean_pga)
