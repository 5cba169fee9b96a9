"""Writers for a 3D rack time history (:class:`~seisrack.analysis.rack3d.RackResponse3D`).

The same three files as a 2D run (:mod:`seisrack.report.rack_io`), under the same names:

- ``timehistory.nc``: netCDF3 (SciPy writer, no HDF5 needed) with dimensions ``time``,
  ``pallet`` (1-based), ``direction`` (down_aisle, cross_aisle), ``measure`` (down_aisle,
  cross_aisle, magnitude), ``component`` (x, z, vertical) and ``level``; every variable has
  ``units`` (UDUNITS spellings) and ``long_name``.
- ``peaks.csv``: one row per pallet (peak sliding both ways and in magnitude, residual, fall
  limits, whether and when it falls).
- ``summary.json``: ``RackResponse3D.summary()``, written by
  :func:`seisrack.report.rack_io.write_summary_json`.

Directions follow the 3D model's axes: x down-aisle, z cross-aisle (front frame at z = 0,
rear frame at z = depth). Pallets are 1-based in the files, levels and bays 1-based as in the
rack's TOML. SI units. xarray is imported lazily (``pip install 'seisrack[io]'``).
"""

from __future__ import annotations

import csv
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from seisrack import __version__
from seisrack.analysis.rack3d import RackResponse3D
from seisrack.report.rack_io import (
    DATA_FILES,
    PEAKS_FILE,
    SUMMARY_FILE,
    TIMEHISTORY_FILE,
    _ascii_attrs,
    _atomic_write,
    _jsonable,
    write_summary_json,
)

__all__ = ["DATA_FILES", "PEAKS_FILE", "PEAKS_FIELDS_3D", "SUMMARY_FILE", "TIMEHISTORY_FILE",
           "response_dataset_3d", "write_peaks_csv_3d", "write_summary_json",
           "write_timehistory_3d"]

DIRECTIONS = ("down_aisle", "cross_aisle")
MEASURES = ("down_aisle", "cross_aisle", "magnitude")
COMPONENTS = ("x", "z", "vertical")


def _fall_arrays(resp: RackResponse3D) -> tuple[np.ndarray, list[str]]:
    """(m,) fall time [s] (NaN when the pallet does not fall) and side ("front"/"rear"/"")."""
    m = resp.n_pallets
    time = np.full(m, np.nan)
    side = [""] * m
    for f in resp.falls:
        time[f.pallet] = f.time_s
        side[f.pallet] = f.side
    return time, side


# ---------------------------------------------------------------------------------- netCDF
def response_dataset_3d(
    resp: RackResponse3D, *, model: Any = None, title: str = "",
    summary: Mapping[str, Any] | None = None,
) -> Any:
    """The time histories of ``resp`` as an :class:`xarray.Dataset` (SI units, CF attributes).

    model: the :class:`~seisrack.model.frame_model3d.FrameModel3D` that was run (optional; adds
        the pallet positions ``pallet_x``, the upright positions and the frame depth).
    summary: extra JSON-able metadata stored as the global attribute ``summary_json``.
    """
    import xarray as xr

    hist = resp.history
    m = resp.n_pallets
    n_level = resp.level_peak.shape[0]

    def var(dims: tuple[str, ...], data: Any, units: str, long_name: str, **attrs: Any) -> Any:
        return xr.Variable(dims, np.asarray(data), {"units": units, "long_name": long_name,
                                                    **attrs})

    coords: dict[str, Any] = {
        "time": var(("time",), resp.t, "s", "time from the start of the record",
                    standard_name="time", axis="T"),
        "pallet": var(("pallet",), np.arange(1, m + 1, dtype=np.int32), "1",
                      "pallet id (1-based, order of the rack file; as in summary.json)"),
        "direction": var(("direction",), np.array(DIRECTIONS), "1",
                         "horizontal direction: down_aisle = x, cross_aisle = z (towards the "
                         "rear)"),
        "measure": var(("measure",), np.array(MEASURES), "1",
                       "down_aisle |x|, cross_aisle |z| or magnitude sqrt(x2 + z2)"),
        "component": var(("component",), np.array(COMPONENTS), "1",
                         "ground motion component: x down-aisle, z cross-aisle, vertical"),
        "level": var(("level",), np.arange(1, n_level + 1, dtype=np.int32), "1",
                     "beam level number, 1 = lowest"),
        "level_y": var(("level",), resp.level_y, "m", "height of the beam level"),
    }
    if model is not None:
        front = np.asarray(model.pallet_node)[:, 0]
        coords["pallet_x"] = var(("pallet",), np.asarray(model.nodes)[front, 0], "m",
                                 "down-aisle position of the pallet's node")
    fall_time, fall_side = _fall_arrays(resp)
    data: dict[str, Any] = {
        "ground_accel": var(("time", "component"), resp.ground, "m s-2",
                            "ground acceleration (analysis grid; vertical 0 when not given)"),
        "sliding": var(("time", "pallet", "direction"), hist.sliding, "m",
                       "pallet displacement relative to its beams"),
        "sliding_velocity": var(("time", "pallet", "direction"), hist.velocity, "m s-1",
                                "pallet velocity relative to its beams"),
        "friction": var(("time", "pallet", "direction"), hist.friction, "N",
                        "horizontal friction force of the beams on the pallet"),
        "stuck": var(("time", "pallet"), hist.stuck.astype(np.int8), "1",
                     "1 if the pallet sticks to its beams, 0 if it slides",
                     flag_values=np.array([0, 1], dtype=np.int8),
                     flag_meanings="sliding stuck"),
        "normal_force": var(("time", "pallet"), hist.normal, "N",
                            "normal force between the pallet and its beams"),
        "peak_sliding": var(("pallet", "measure"), resp.peak_sliding, "m",
                            "peak sliding over every analysis step (not only the kept ones)"),
        "residual_sliding": var(("pallet", "direction"), resp.residual, "m",
                                "sliding at the end of the run (signed)"),
        "fall_limit_front": var(("pallet",), resp.fall_front, "m",
                                "sliding towards the front aisle (-z) at which the pallet "
                                "falls (NaN: not checked)"),
        "fall_limit_rear": var(("pallet",), resp.fall_rear, "m",
                               "sliding towards the rear (+z) at which the pallet falls "
                               "(NaN: not checked)"),
        "fall_time": var(("pallet",), fall_time, "s",
                         "time of the pallet's fall (NaN: it does not fall)"),
        "fall_side": var(("pallet",), np.array(fall_side, dtype=str), "1",
                         "side the pallet falls to: front (-z), rear (+z), empty if none"),
        "pallet_level": var(("pallet",), np.asarray(resp.pallet_level, dtype=np.int32), "1",
                            "beam level the pallet stands on, 1 = lowest"),
        "pallet_bay": var(("pallet",), np.asarray(resp.pallet_bay, dtype=np.int32), "1",
                          "bay the pallet stands in, 1 = leftmost"),
        "level_peak_displacement": var(("level", "direction"), resp.level_peak, "m",
                                       "peak displacement of the beam level relative to the "
                                       "ground (mean of its nodes)"),
    }
    attrs: dict[str, Any] = {
        "title": title or f"seisrack 3D rack time history, record {resp.motion_name}",
        "Conventions": "CF-1.8",
        "source": f"seisrack {__version__} (planar stick-slip, Newmark average acceleration)",
        "record": resp.motion_name,
        "angle_deg": float(resp.angle_deg),
        "dt": float(resp.dt),
        "analysis_dt_s": float(resp.dt),
        "status": resp.history.status,
        "comment": "SI units; x down-aisle, z cross-aisle (front frame z = 0, rear z = depth); "
                   "motion relative to the ground",
    }
    if model is not None:
        attrs["depth_m"] = float(model.depth)
    if summary is not None:
        attrs["summary_json"] = json.dumps(_jsonable(summary), allow_nan=False)
    return xr.Dataset(data, coords=coords, attrs=_ascii_attrs(attrs))


def write_timehistory_3d(
    resp: RackResponse3D, path: str | Path, *, model: Any = None, title: str = "",
    summary: Mapping[str, Any] | None = None,
) -> Path:
    """Write ``timehistory.nc`` of a 3D run (netCDF3 via SciPy; reopen with
    ``xarray.open_dataset``). Written to a temporary name, then renamed over ``path``."""
    ds = response_dataset_3d(resp, model=model, title=title, summary=summary)
    return _atomic_write(Path(path), lambda p: ds.to_netcdf(p, engine="scipy",
                                                             format="NETCDF3_64BIT"))


# ---------------------------------------------------------------------------------- peaks
#: columns of :func:`write_peaks_csv_3d`, in order
PEAKS_FIELDS_3D = ("pallet", "level", "bay", "peak_sliding_down_aisle_m",
                   "peak_sliding_cross_aisle_m", "peak_sliding_m", "residual_down_aisle_m",
                   "residual_cross_aisle_m", "fall_limit_front_m", "fall_limit_rear_m", "falls",
                   "fall_time_s", "fall_side")


def peak_rows_3d(resp: RackResponse3D) -> list[dict[str, Any]]:
    """One dict per pallet with the :data:`PEAKS_FIELDS_3D` keys (``None`` = not applicable)."""
    fall_time, fall_side = _fall_arrays(resp)

    def num(x: float) -> float | None:
        return float(x) if math.isfinite(float(x)) else None

    rows = []
    for p in range(resp.n_pallets):
        falls = not math.isnan(fall_time[p])
        rows.append({
            "pallet": p + 1, "level": int(resp.pallet_level[p]), "bay": int(resp.pallet_bay[p]),
            "peak_sliding_down_aisle_m": float(resp.peak_sliding[p, 0]),
            "peak_sliding_cross_aisle_m": float(resp.peak_sliding[p, 1]),
            "peak_sliding_m": float(resp.peak_sliding[p, 2]),
            "residual_down_aisle_m": float(resp.residual[p, 0]),
            "residual_cross_aisle_m": float(resp.residual[p, 1]),
            "fall_limit_front_m": num(resp.fall_front[p]),
            "fall_limit_rear_m": num(resp.fall_rear[p]),
            "falls": "yes" if falls else "no",
            "fall_time_s": float(fall_time[p]) if falls else None,
            "fall_side": fall_side[p],
        })
    return rows


def write_peaks_csv_3d(resp: RackResponse3D, path: str | Path) -> Path:
    """Write ``peaks.csv`` of a 3D run: one row per pallet, columns :data:`PEAKS_FIELDS_3D`
    (SI units; empty cell = not applicable, e.g. no fall or a fall limit not checked)."""
    rows = peak_rows_3d(resp)

    def write(p: Path) -> None:
        with p.open("w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=PEAKS_FIELDS_3D)
            w.writeheader()
            for r in rows:
                w.writerow({k: ("" if r[k] is None else
                                f"{r[k]:.10g}" if isinstance(r[k], float) else r[k])
                            for k in PEAKS_FIELDS_3D})

    return _atomic_write(Path(path), write)
