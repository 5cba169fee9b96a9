"""The nonlinear connections (``RackResponse.hinges``) in the written results: rows of
``peaks.csv`` and variables of ``timehistory.nc`` (called by :mod:`seisrack.report.rack_io`).

Nothing is added for a rack whose connections are all elastic (``resp.hinges is None``).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import numpy as np

#: long names of the energy terms written as ``energy_<term>`` (others: "cumulative <term>")
ENERGY_LONG_NAMES = {
    "input": "cumulative energy input by the ground motion",
    "kinetic": "kinetic energy (relative to the ground)",
    "strain": "strain energy, relative to the gravity state",
    "damping": "cumulative energy dissipated by viscous damping",
    "friction": "cumulative energy dissipated by pallet-beam friction",
    "hysteresis": "cumulative energy dissipated by the hysteresis of the nonlinear "
                  "connections (connectors and base plates)",
    "algorithmic": "cumulative energy taken out by the integration's L-stable steps after "
                   "contact events (numerical, not physical)",
}

#: what the hinge rotation is measured from (the same in the CSV notes and netCDF)
ROTATION_ORIGIN = "from the zero-moment state, gravity included"

_CONNECTOR = re.compile(r"connector L(\d+) B(\d+) (left|right)$")
_BASE = re.compile(r"base U(\d+)$")


def hinge_place(label: str) -> tuple[int | None, int | None]:
    """(level, upright), 1-based, of a hinge label (``"connector L1 B2 right"`` -> (1, 3),
    ``"base U2"`` -> (None, 2)); (None, None) for a label of another form."""
    m = _CONNECTOR.match(label)
    if m:
        return int(m.group(1)), int(m.group(2)) + (m.group(3) == "right")
    m = _BASE.match(label)
    if m:
        return None, int(m.group(1))
    return None, None


def hinge_peak_rows(resp: Any, add: Callable[..., None]) -> None:
    """Add the rows of every hinge to the peaks table through ``add`` (rack_io.peak_rows):
    ``hinge_rotation`` (peak |rotation|), ``hinge_moment`` (peak |moment|),
    ``hinge_residual_rotation`` (signed, end of record) and ``hinge_ductility`` (peak rotation
    / yield rotation; only for a hinge that can yield). The note names the hinge and its law.
    """
    h = getattr(resp, "hinges", None)
    if h is None:
        return
    t = np.asarray(resp.t)
    rot = np.asarray(h.rotation, dtype=float)
    mom = np.asarray(h.moment, dtype=float)
    for i, row in enumerate(h.peaks()):
        lab = row["hinge"]
        level, upright = hinge_place(lab)
        where = f"{lab}, {row['law']}"
        k_r = int(np.argmax(np.abs(rot[:, i])))
        k_m = int(np.argmax(np.abs(mom[:, i])))
        add("hinge_rotation", row["peak_rotation_rad"], "rad", time=float(t[k_r]),
            level=level, upright=upright, note=f"{where}, {ROTATION_ORIGIN}")
        add("hinge_moment", row["peak_moment_Nm"], "N*m", time=float(t[k_m]), level=level,
            upright=upright, note=where)
        add("hinge_residual_rotation", row["residual_rotation_rad"], "rad", time=float(t[-1]),
            level=level, upright=upright, note=f"{where}, signed, end of record")
        if row["ductility"] is not None:
            add("hinge_ductility", float(row["ductility"]), "1", time=float(t[k_r]),
                level=level, upright=upright,
                note=f"{where}, peak rotation / yield rotation"
                     + (", YIELDED" if row["yielded"] else ""))


def hinge_variables(resp: Any, coords: dict[str, Any], data: dict[str, Any],
                    var: Callable[..., Any]) -> None:
    """Add ``hinge_rotation`` and ``hinge_moment`` (time × hinge), the ``hinge`` coordinate
    (labels) with ``hinge_kind``, ``hinge_law`` and ``hinge_yield_rotation``; and mark the
    design variable ``connector_moment`` as elastic (k·θ) when connections are nonlinear."""
    h = getattr(resp, "hinges", None)
    if h is None:
        return
    coords["hinge"] = var(("hinge",), np.array(h.labels), "1",
                          "connection hinge: beam-to-upright connector (level, bay, end) or "
                          "base plate (upright)")
    coords["hinge_kind"] = var(("hinge",), np.array(h.kind), "1", "kind of connection hinge")
    coords["hinge_law"] = var(("hinge",), np.array(h.law), "1",
                              "moment-rotation law of the connection hinge")
    coords["hinge_yield_rotation"] = var(
        ("hinge",), np.asarray(h.yield_rotation, dtype=float), "rad",
        "yield rotation of the connection hinge (inf: elastic, never yields)")
    data["hinge_rotation"] = var(("time", "hinge"), np.asarray(h.rotation, dtype=float), "rad",
                                 f"rotation of the connection hinge, {ROTATION_ORIGIN}")
    data["hinge_moment"] = var(("time", "hinge"), np.asarray(h.moment, dtype=float), "N m",
                               "moment of the connection hinge (its nonlinear law, gravity "
                               "included)")
    if "connector_moment" in data:
        v = data["connector_moment"]
        v.attrs["long_name"] = (v.attrs["long_name"] + ", ELASTIC k*rotation: not the "
                                "connector's moment once it yields, see hinge_moment")
        v.attrs["comment"] = "elastic design operator; the nonlinear connector moments are " \
                             "hinge_moment"
