"""Writers for a rack time history (:class:`~seisrack.analysis.rack.RackResponse`), 2D or 3D.

- ``timehistory.nc``: every time history as a self-describing netCDF file (xarray Dataset,
  CF-style ``units`` / ``long_name`` attributes, dimensions ``time``, ``level``, ``pallet``,
  ``upright`` and, for a 3D rack, ``direction`` (down_aisle, cross_aisle) on every quantity
  that has one, with the falls into the aisles and the vertical ground motion).
  It is written as netCDF3 (classic, 64-bit offsets) through SciPy's writer, so it needs no
  netCDF4/HDF5 library: xarray + SciPy are enough to write and read it, and every netCDF tool
  (ncdump, Panoply, MATLAB ``ncread``) opens it. NetCDF3 has no compression and ASCII-only text,
  which is why the unit strings below are UDUNITS/CF spellings (``m s-2``, ``N m``).
- ``peaks.csv``: one row per quantity (and per level / pallet / upright / direction /
  connection hinge), with the unit and the time of the peak.
- ``summary.json``: the same object as ``seisrack run --json``.

Every file is written to a temporary name in the target folder and then renamed over the final
name, so an interrupted run never leaves a half-written file in place of a previous result.
xarray is imported lazily (``pip install 'seisrack[io]'``).
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from seisrack import __version__
from seisrack.analysis.rack import RackResponse
from seisrack.dynamics.results import EVENT_KINDS
from seisrack.report.hinge_io import ENERGY_LONG_NAMES, hinge_peak_rows, hinge_variables

#: the file names seisrack writes into an output folder (nothing else there is touched)
TIMEHISTORY_FILE = "timehistory.nc"
PEAKS_FILE = "peaks.csv"
SUMMARY_FILE = "summary.json"
DATA_FILES = (TIMEHISTORY_FILE, PEAKS_FILE, SUMMARY_FILE)


def _atomic_write(path: Path, write: Callable[[Path], None]) -> Path:
    """Call ``write(tmp)`` on a temporary sibling of ``path``, then rename it to ``path``."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        write(tmp)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


# ---------------------------------------------------------------------------------- netCDF
def response_dataset(
    resp: RackResponse, *, model: Any = None, title: str | None = None,
    summary: Mapping[str, Any] | None = None,
) -> Any:
    """The time histories of ``resp`` as an :class:`xarray.Dataset` (SI units, CF attributes).

    model: the :class:`~seisrack.model.frame_model.FrameModel` that was run (optional; adds the
        level heights ``level_y`` and upright positions ``upright_x``).
    summary: extra JSON-able metadata stored as the global attribute ``summary_json``.
    """
    import xarray as xr

    n_level = resp.beam_displacement.shape[1]
    m = resp.n_pallets
    n_up = resp.upright_moment_base.shape[1]
    planar = resp.n_dir > 1
    dirn = ("direction",) if planar else ()  # the direction axis where there are two

    def var(dims: tuple[str, ...], data: Any, units: str, long_name: str, **attrs: Any) -> Any:
        return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name,
                                                    **attrs})

    coords: dict[str, Any] = {
        "time": var(("time",), resp.t, "s", "time from the start of the record",
                    standard_name="time", axis="T"),
        "level": var(("level",), np.arange(1, n_level + 1, dtype=np.int32), "1",
                     "beam level number, 1 = lowest"),
        "upright": var(("upright",), np.arange(1, n_up + 1, dtype=np.int32), "1",
                       "upright column number, 1 = leftmost (front then rear in 3D)"),
    }
    if planar:
        coords["direction"] = var(("direction",), np.array(["down_aisle", "cross_aisle"]), "1",
                                  "horizontal direction: down_aisle = x, cross_aisle = z "
                                  "(towards the rear)")
    if model is not None:
        coords["level_y"] = var(("level",), model.level_y, "m", "height of the beam level")
        coords["upright_x"] = var(("upright",), model.upright_x[model.column_line], "m",
                                  "upright position along the rack")
    data: dict[str, Any] = {
        "ground_accel": var(("time", *dirn), resp.ground_accel, "m s-2",
                            "horizontal ground acceleration (analysis grid)"),
        "beam_displacement": var(("time", "level", *dirn), resp.beam_displacement, "m",
                                 "horizontal displacement of the beam level relative to the "
                                 "ground (mean of its nodes)"),
        "beam_acceleration": var(("time", "level", *dirn), resp.beam_acceleration, "m s-2",
                                 "absolute horizontal acceleration of the beam level (raw, "
                                 "unfiltered)"),
        "contact_force": var(("time", "level", *dirn), resp.contact_force, "N",
                             "total horizontal contact force of the beams on the pallets of "
                             "the level"),
        "total_contact_force": var(("time", *dirn), resp.contact_force.sum(axis=1), "N",
                                   "total horizontal contact force between beams and pallets"),
        "base_shear": var(("time", *dirn), resp.base_shear, "N",
                          "base shear (support reactions, elastic + stiffness-proportional "
                          "damping)"),
        "upright_moment_base": var(("time", "upright", *dirn), resp.upright_moment_base, "N m",
                                   "upright bending moment at the base (bending plane of the "
                                   "direction)"),
        "upright_moment_connection": var(("time", "upright", "level", *dirn),
                                         resp.upright_moment_connection, "N m",
                                         "upright bending moment at the beam connection "
                                         "(larger of the segments below / above)"),
    }
    if resp.vertical_accel is not None:
        data["ground_accel_vertical"] = var(("time",), resp.vertical_accel, "m s-2",
                                            "vertical ground acceleration (analysis grid)")
    if resp.beam_acceleration_filtered is not None:
        data["beam_acceleration_filtered"] = var(
            ("time", "level", *dirn), resp.beam_acceleration_filtered, "m s-2",
            f"absolute horizontal acceleration of the beam level, low-pass filtered at "
            f"{resp.acceleration_filter_hz:g} Hz (zero-phase 4th-order Butterworth)",
            filter_hz=float(resp.acceleration_filter_hz))
    _design_variables(resp, coords, data, var)
    if m:
        hist = resp.history
        coords.update({
            "pallet": var(("pallet",), np.arange(1, m + 1, dtype=np.int32), "1",
                          "pallet id (1-based, order of the rack file; as in summary.json)"),
            "pallet_label": var(("pallet",), np.array(resp.pallet_labels()), "1",
                                "pallet label L{level}-B{bay}-S{slot} (1-based)"),
            "pallet_bay": var(("pallet",), (resp._bay() + 1).astype(np.int32), "1",
                              "bay the pallet stands in, 1 = leftmost"),
            "pallet_level": var(("pallet",), (resp.pallet_level + 1).astype(np.int32), "1",
                                "beam level the pallet stands on"),
            "pallet_x": var(("pallet",), resp.pallet_x, "m",
                            "down-aisle position of the pallet's centre"),
            "pallet_mass": var(("pallet",), resp.pallet_mass, "kg", "pallet mass"),
            "mu_static": var(("pallet",), resp.pallet_mu_static, "1",
                             "static friction coefficient"),
            "mu_dynamic": var(("pallet",), resp.pallet_mu_dynamic, "1",
                              "dynamic friction coefficient"),
            "sliding_limit_neg": var(("pallet",), resp.pallet_limit_neg, "m",
                                     "free sliding distance towards -x (neighbour or upright)"),
            "sliding_limit_pos": var(("pallet",), resp.pallet_limit_pos, "m",
                                     "free sliding distance towards +x (neighbour or upright)"),
        })
        data.update({
            "pallet_sliding": var(("time", "pallet", *dirn), resp.pallet_sliding, "m",
                                  "pallet displacement relative to its beam(s)"),
            "pallet_friction": var(("time", "pallet", *dirn), resp.pallet_friction, "N",
                                   "horizontal force of the beam(s) on the pallet"),
            "pallet_normal": var(("time", "pallet"), hist.normal, "N",
                                 "normal force between pallet and beam"),
            "pallet_stuck": var(("time", "pallet"), hist.stuck.astype(np.int8), "1",
                                "1 if the pallet sticks to its beam, 0 if it slides",
                                flag_values=np.array([0, 1], dtype=np.int8),
                                flag_meanings="sliding stuck"),
        })
        if resp.events:
            coords["event"] = var(("event",), np.arange(1, len(resp.events) + 1,
                                                        dtype=np.int32), "1", "event number")
            data["event_time"] = var(("event",), [e.time_s for e in resp.events], "s",
                                     "time of the contact event")
            data["event_pallet"] = var(("event",), np.array([e.slider + 1 for e in resp.events],
                                                            dtype=np.int32), "1",
                                       "pallet number of the contact event")
            data["event_kind"] = var(
                ("event",), np.array([EVENT_KINDS.index(e.kind) for e in resp.events],
                                     dtype=np.int8), "1", "kind of contact event",
                flag_values=np.arange(len(EVENT_KINDS), dtype=np.int8),
                flag_meanings=" ".join(EVENT_KINDS))
        if planar:
            _fall_variables(resp, data, var)
    hinge_variables(resp, coords, data, var)
    for key, arr in resp.energy.items():
        data[f"energy_{key}"] = var(("time",), arr, "J",
                                    ENERGY_LONG_NAMES.get(key, f"cumulative {key} energy"))
    attrs = {
        "title": title or f"seisrack rack time history, record {resp.record_name}",
        "Conventions": "CF-1.8",
        "source": f"seisrack {__version__} (exact stick-slip, Newmark average acceleration)",
        "record": resp.record_name,
        "dimension": "3D" if planar else "2D",
        "angle_deg": float(resp.angle_deg),
        "analysis_dt_s": float(resp.dt),
        "g_m_s2": float(resp.g),
        "status": resp.status,
        "comment": "SI units; motion relative to the ground unless stated (beam_acceleration "
                   "is absolute); x down-aisle, y up, z cross-aisle (front frame z = 0)",
    }
    if model is not None:
        attrs["depth_m"] = float(model.depth)
    if summary is not None:
        attrs["summary_json"] = json.dumps(_jsonable(summary), allow_nan=False)
    return xr.Dataset(data, coords=coords, attrs=_ascii_attrs(attrs))


def _fall_variables(resp: RackResponse, data: dict[str, Any], var: Callable[..., Any]) -> None:
    """Falls into the aisles (3D racks): limits, time and side per pallet."""
    m = resp.n_pallets
    time = np.full(m, np.nan)
    side = [""] * m
    for f in resp.falls:
        time[f.pallet] = f.time_s
        side[f.pallet] = f.side
    data.update({
        "fall_limit_front": var(("pallet",), resp.fall_front, "m",
                                "sliding towards the front aisle (-z) at which the pallet falls "
                                "(NaN: not checked)"),
        "fall_limit_rear": var(("pallet",), resp.fall_rear, "m",
                               "sliding towards the rear (+z) at which the pallet falls "
                               "(NaN: not checked)"),
        "fall_time": var(("pallet",), time, "s", "time of the pallet's fall (NaN: none)"),
        "fall_side": var(("pallet",), np.array(side, dtype=str), "1",
                         "side the pallet falls to: front (-z), rear (+z), empty if none"),
    })


def _ascii_attrs(attrs: dict[str, Any]) -> dict[str, Any]:
    # netCDF3 text is ASCII: replace anything else rather than fail on a title with "μ" or "×"
    out = {}
    for k, v in attrs.items():
        out[k] = v.encode("ascii", "replace").decode() if isinstance(v, str) else v
    return out


def write_timehistory(
    resp: RackResponse, path: str | Path, *, model: Any = None, title: str | None = None,
    summary: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``timehistory.nc`` (netCDF3 via SciPy; reopen with ``xarray.open_dataset``)."""
    ds = response_dataset(resp, model=model, title=title, summary=summary)
    return _atomic_write(Path(path), lambda p: ds.to_netcdf(p, engine="scipy",
                                                             format="NETCDF3_64BIT"))


#: (netCDF variable, DesignOps attribute, dimension, units, long name) of the design histories
_DESIGN_VARS = (
    ("interstorey_drift_ratio", "drift", "storey", "1",
     "interstorey drift ratio (gravity + seismic)"),
    ("beam_end_moment", "beam_moment", "beam_end", "N m",
     "beam end bending moment (member convention, gravity + seismic, elastic)"),
    ("beam_end_shear", "beam_shear", "beam_end", "N",
     "beam end shear force (gravity + seismic, elastic)"),
    ("connector_moment", "connector_moment", "connector", "N m",
     "beam-to-upright connector moment (gravity + seismic)"),
    ("connector_rotation", "connector_rotation", "connector", "rad",
     "beam-to-upright connector rotation (gravity + seismic)"),
    ("upright_axial_force", "axial", "section", "N",
     "upright axial force, tension positive (gravity + seismic, elastic)"),
    ("upright_section_moment", "section_moment", "section", "N m",
     "upright bending moment at the axial-force sections (gravity + seismic, elastic)"),
    ("interstorey_drift_ratio_cross_aisle", "drift_cross_aisle", "storey", "1",
     "interstorey drift ratio cross-aisle (gravity + seismic)"),
    ("upright_section_moment_cross_aisle", "section_moment_cross_aisle", "section", "N m",
     "upright bending moment in the cross-aisle plane at the axial-force sections"),
)


def _design_variables(resp: RackResponse, coords: dict[str, Any], data: dict[str, Any],
                      var: Callable[..., Any]) -> None:
    """Add the design-quantity histories (and their member labels) when the run has them."""
    ops = getattr(resp, "operators", None)
    if ops is None or ops.design is None:
        return
    from seisrack.analysis.peaks import design_history

    d = ops.design
    for name, attr, dim, units, long_name in _DESIGN_VARS:
        if attr not in d.ops:
            continue
        labels = d.labels[attr]
        if not labels:
            continue
        if f"{dim}_label" not in coords:
            coords[f"{dim}_label"] = var((dim,), np.array(labels), "1", f"{dim} label")
        data[name] = var(("time", dim), design_history(resp, attr), units, long_name)


# ---------------------------------------------------------------------------------- peaks
def _peak(x: np.ndarray, t: np.ndarray) -> tuple[float, float]:
    """(max |x|, time of it) over axis 0 of a 1-D series."""
    k = int(np.argmax(np.abs(x)))
    return float(abs(x[k])), float(t[k])


#: columns of ``peaks.csv``, in order
PEAKS_FIELDS = ("quantity", "level", "pallet", "upright", "direction", "value", "unit",
                "time_s", "note")
#: the direction column's values
_DIRECTION = ("down_aisle", "cross_aisle")


def peak_rows(resp: RackResponse) -> list[dict[str, Any]]:
    """Rows of the peaks table (:data:`PEAKS_FIELDS`).

    ``level``, ``pallet`` and ``upright`` are 1-based, empty when not applicable; ``direction``
    is down_aisle or cross_aisle for a quantity along a direction (every horizontal one of a 2D
    rack is down_aisle), empty otherwise. Values are peaks of the absolute value except for
    residuals, limits, utilisations, fall times and ductilities. With nonlinear connections:
    ``hinge_*`` rows per hinge (:func:`hinge_io.hinge_peak_rows`). A 3D rack adds each pallet's
    peak sliding magnitude and its fall (time, side).
    """
    t = resp.t
    rows: list[dict[str, Any]] = []

    def add(quantity: str, value: float, unit: str, *, time: float | None = None,
            level: int | None = None, pallet: int | None = None, upright: int | None = None,
            direction: int | None = None, note: str = "") -> None:
        rows.append({"quantity": quantity, "level": level, "pallet": pallet,
                     "upright": upright,
                     "direction": None if direction is None else _DIRECTION[direction],
                     "value": value, "unit": unit, "time_s": time, "note": note})

    disp = resp.directional("beam_displacement")
    acc = resp.directional("beam_acceleration")
    acc_f = resp.directional("beam_acceleration_filtered")
    force = resp.directional("contact_force")
    shear = resp.directional("base_shear")
    m_base = resp.directional("upright_moment_base")
    m_conn = resp.directional("upright_moment_connection")
    n_level = disp.shape[1]
    for d in range(resp.n_dir):
        for lv in range(n_level):
            v, tt = _peak(disp[:, lv, d], t)
            add("beam_displacement", v, "m", time=tt, level=lv + 1, direction=d,
                note="relative to the ground")
            v, tt = _peak(acc[:, lv, d], t)
            add("beam_acceleration", v, "m/s2", time=tt, level=lv + 1, direction=d,
                note="absolute, raw")
            if acc_f is not None:
                v, tt = _peak(acc_f[:, lv, d], t)
                add("beam_acceleration_filtered", v, "m/s2", time=tt, level=lv + 1,
                    direction=d, note=f"absolute, low-pass {resp.acceleration_filter_hz:g} Hz")
            v, tt = _peak(force[:, lv, d], t)
            add("contact_force", v, "N", time=tt, level=lv + 1, direction=d,
                note="beams on pallets, this level")
        v, tt = _peak(force[:, :, d].sum(axis=1), t)
        add("total_contact_force", v, "N", time=tt, direction=d, note="beams on all pallets")
        v, tt = _peak(shear[:, d], t)
        add("base_shear", v, "N", time=tt, direction=d)
        for u in range(m_base.shape[1]):
            v, tt = _peak(m_base[:, u, d], t)
            add("upright_moment_base", v, "N*m", time=tt, upright=u + 1, direction=d)
            for lv in range(n_level):
                v, tt = _peak(m_conn[:, u, lv, d], t)
                add("upright_moment_connection", v, "N*m", time=tt, level=lv + 1,
                    upright=u + 1, direction=d)
    design = resp.design_peaks()
    if design is not None:
        from seisrack.analysis.peaks import design_keys

        for key, _, unit, _ in design_keys(resp.operators.design):
            item = design[key]
            for lab, val in zip(item["labels"], item.get("peak_abs", []), strict=True):
                add(key, float(val), unit.replace(" ", "*"), note=f"{lab}, gravity + seismic"
                    + (", moment of the hinge law (kept samples)"
                       if key == "connector_moment_Nm"
                       and getattr(resp, "hinges", None) is not None else ""))
    hinge_peak_rows(resp, add)
    _pallet_rows(resp, add)
    return rows


def _pallet_rows(resp: RackResponse, add: Callable[..., None]) -> None:
    t = resp.t
    util = resp.fall_utilisation()
    residual = resp.directional("pallet_sliding")[-1]
    sliding = resp.directional("pallet_sliding")
    friction = resp.directional("pallet_friction")
    labels = resp.pallet_labels()
    peak = resp.pallet_peak_sliding()
    fall = {f.pallet: f for f in resp.falls}
    for j in range(resp.n_pallets):
        lv = int(resp.pallet_level[j]) + 1
        for d in range(resp.n_dir):
            v, tt = _peak(sliding[:, j, d], t)
            add("pallet_sliding", v, "m", time=tt, level=lv, pallet=j + 1, direction=d,
                note=f"{labels[j]}, relative to its beam")
            add("pallet_residual", float(residual[j, d]), "m", time=float(t[-1]), level=lv,
                pallet=j + 1, direction=d, note="signed, end of record")
            v, tt = _peak(friction[:, j, d], t)
            add("pallet_friction", v, "N", time=tt, level=lv, pallet=j + 1, direction=d)
        if resp.n_dir > 1:
            add("pallet_sliding_magnitude", float(peak[j]), "m", level=lv, pallet=j + 1,
                note=f"{labels[j]}, over every analysis step")
        add("pallet_limit_neg", float(resp.pallet_limit_neg[j]), "m", level=lv, pallet=j + 1,
            direction=0, note="free distance towards -x")
        add("pallet_limit_pos", float(resp.pallet_limit_pos[j]), "m", level=lv, pallet=j + 1,
            direction=0, note="free distance towards +x")
        add("pallet_fall_utilisation", float(util[j]), "1", level=lv, pallet=j + 1,
            direction=0, note="AT RISK" if util[j] >= 1.0 else "")
        if resp.n_dir > 1:
            for name, lim, note in (("pallet_fall_limit_front", resp.fall_front[j],
                                     "sliding towards the front aisle (-z) at which it falls"),
                                    ("pallet_fall_limit_rear", resp.fall_rear[j],
                                     "sliding towards the rear (+z) at which it falls")):
                if np.isfinite(lim):
                    add(name, float(lim), "m", level=lv, pallet=j + 1, direction=1, note=note)
            if j in fall:
                add("pallet_falls", 1.0, "1", time=fall[j].time_s, level=lv, pallet=j + 1,
                    direction=1, note=f"falls to the {fall[j].side}")


def write_peaks_csv(resp: RackResponse, path: str | Path) -> Path:
    """Write the peaks table (:func:`peak_rows`) as CSV with a header row."""
    rows = peak_rows(resp)

    def write(p: Path) -> None:
        with p.open("w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=PEAKS_FIELDS)
            w.writeheader()
            for r in rows:
                w.writerow({k: ("" if r[k] is None else
                                f"{r[k]:.10g}" if isinstance(r[k], float) else r[k])
                            for k in PEAKS_FIELDS})

    return _atomic_write(Path(path), write)


# ---------------------------------------------------------------------------------- JSON
def _jsonable(obj: Any) -> Any:
    from seisrack.jsonable import to_jsonable as _to_jsonable

    return _to_jsonable(obj)


def write_summary_json(summary: Mapping[str, Any], path: str | Path) -> Path:
    """Write a summary dict (``RackResponse.summary()`` plus anything else) as JSON."""
    text = json.dumps(_jsonable(summary), indent=2, allow_nan=False) + "\n"
    return _atomic_write(Path(path), lambda p: p.write_text(text, encoding="utf-8"))
