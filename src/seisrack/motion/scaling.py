"""Amplitude scaling of a ground-acceleration record (issue #14, item 4).

Three plain functions, SI units (m/s², s):

- :func:`scale_by`: multiply the record by a factor > 0;
- :func:`scale_to_pga`: the factor that makes the peak ground acceleration equal a target;
- :func:`scale_to_sa`: the factor that makes the 5 %-damped (by default) pseudo-spectral
  acceleration Sa(T) = ω² max|u| at one period equal a target.

Amplitude scaling is linear: the response spectrum of ``f·a(t)`` is ``f`` times the spectrum of
``a(t)`` (the SDOF equation ``ü + 2ζωu̇ + ω²u = -a_g`` is linear), so one factor meets the target
exactly; Sa is computed with :func:`seisrack.motion.response_spectrum` (exact for
piecewise-linear input, peaks between samples included).
"""

from __future__ import annotations

import math
from typing import Any

from seisrack.errors import InputError
from seisrack.motion.records import Record
from seisrack.motion.spectra import response_spectrum

#: [s] periods at which :func:`scale_to_sa` accepts a target. Below 0.01 s Sa is the PGA (scale
#: to the PGA instead); 10 s covers every rack and the EC8 spectra (defined up to 4 s).
PERIOD_RANGE = (0.01, 10.0)


def _check_positive(field: str, value: Any, what: str) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    if not (ok and math.isfinite(value) and value > 0):
        raise InputError(field, value, f"a finite {what} > 0")
    return float(value)


def scale_by(record: Record, factor: float) -> Record:
    """``record`` with every acceleration multiplied by ``factor`` (> 0, finite).

    The name is kept; the provenance and ``meta["scale_factor"]`` (cumulative) say it was scaled.
    """
    f = _check_positive("factor", factor, "scale factor")
    meta = dict(record.meta or {})
    meta["scale_factor"] = f * float(meta.get("scale_factor", 1.0))
    prov = f"{record.provenance}; scaled by {f:.6g}" if record.provenance else f"scaled by {f:.6g}"
    return Record(record.accel * f, record.dt, name=record.name, provenance=prov, meta=meta)


def scale_to_pga(record: Record, pga: float) -> tuple[Record, float]:
    """Scale ``record`` so that its peak ground acceleration is ``pga`` [m/s²].

    Returns ``(scaled record, factor)``. Raises :class:`InputError` for a target that is not
    finite and > 0, or a record whose PGA is zero.
    """
    target = _check_positive("pga", pga, "target peak ground acceleration [m/s²]")
    before = record.pga
    if not before > 0:
        raise InputError("record", record.name, "a record with a non-zero acceleration",
                         hint="A record of zeros cannot be scaled to a PGA")
    factor = target / before
    return scale_by(record, factor), factor


def spectral_acceleration(record: Record, period: float, damping: float = 0.05) -> float:
    """[m/s²] pseudo-spectral acceleration Sa(T) = (2π/T)² max|u| of ``record``."""
    return float(response_spectrum(record.accel, record.dt, [period], damping).psa[0])


def check_period(period: Any, field: str = "period") -> float:
    """``period`` as a float if it lies in :data:`PERIOD_RANGE`, else :class:`InputError`."""
    lo, hi = PERIOD_RANGE
    ok = isinstance(period, int | float) and not isinstance(period, bool)
    if not (ok and math.isfinite(period) and lo <= period <= hi):
        raise InputError(field, period, f"a period in [{lo:g}, {hi:g}] s",
                         hint="Below 0.01 s Sa equals the PGA: scale to the PGA instead"
                         if ok and math.isfinite(period) and period < lo else None)
    return float(period)


def scale_to_sa(
    record: Record, period: float, sa: float, damping: float = 0.05
) -> tuple[Record, float]:
    """Scale ``record`` so that its pseudo-spectral acceleration at ``period`` is ``sa``.

    Args:
        record: the record, accelerations in m/s².
        period: [s] oscillator period T, within :data:`PERIOD_RANGE` (0.01-10 s).
        sa: [m/s²] target pseudo-spectral acceleration Sa(T) = ω² Sd(T).
        damping: viscous damping ratio ζ in [0, 1) (default 5 %).

    Returns ``(scaled record, factor)``. Raises :class:`InputError` for a target that is not
    finite and > 0, a period outside the range, a damping outside [0, 1), or a record whose
    Sa(T) is zero.
    """
    target = _check_positive("sa", sa, "target spectral acceleration [m/s²]")
    T = check_period(period)
    if not (isinstance(damping, int | float) and 0.0 <= damping < 1.0):
        raise InputError("damping", damping, "a damping ratio in [0, 1)")
    before = spectral_acceleration(record, T, damping)
    if not before > 0:
        raise InputError("record", record.name, f"a record with a non-zero Sa({T:g} s)",
                         hint="A record of zeros cannot be scaled to a spectral acceleration")
    factor = target / before
    return scale_by(record, factor), factor


def scale_record(
    record: Record,
    *,
    pga: float | None = None,
    sa: float | None = None,
    period: float | None = None,
    factor: float | None = None,
    damping: float = 0.05,
) -> tuple[Record, dict[str, Any]]:
    """Scale ``record`` by exactly one rule and describe what was done.

    Give ``pga`` [m/s²], or ``sa`` [m/s²] with ``period`` [s], or ``factor``. Returns the scaled
    record and a JSON-ready dict ``{method, target, factor, pga_before, pga_after}`` plus, for
    ``sa``, ``period_s``, ``damping``, ``sa_before`` and ``sa_after`` [m/s²].
    """
    given = [k for k, v in (("pga", pga), ("sa", sa), ("factor", factor)) if v is not None]
    if len(given) != 1:
        raise InputError("scaling", ", ".join(given) or None, "exactly one of pga, sa, factor")
    info: dict[str, Any]
    if pga is not None:
        new, f = scale_to_pga(record, pga)
        info = {"method": "pga", "target": float(pga)}
    elif sa is not None:
        if period is None:
            raise InputError("period", None, "a period in [0.01, 10] s with sa")
        new, f = scale_to_sa(record, period, sa, damping)
        info = {"method": "sa", "target": float(sa), "period_s": float(period),
                "damping": float(damping),
                "sa_before": spectral_acceleration(record, period, damping),
                "sa_after": spectral_acceleration(new, period, damping)}
    else:
        f = _check_positive("factor", factor, "scale factor")
        new = scale_by(record, f)
        info = {"method": "factor", "target": f}
    info.update(factor=f, pga_before=record.pga, pga_after=new.pga)
    return new, info
