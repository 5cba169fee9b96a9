"""The warehouse file (issue 24 item 4): the rack rows of a whole warehouse, validated once.

A warehouse TOML lists groups of identical rack rows (docs/user/warehouse_toml.md)::

    title = "Warehouse A"
    [[rows]]
    name = "A"                    # optional label (default "row 1", "row 2", ...)
    rack = "racks/selective.toml" # a rack file (2D or 3D), relative to this file
    count = 4                     # rows of this rack (default 1)
    orientation = 0.0             # [deg] rack's down-aisle axis from the record's first
                                  # component, counter-clockwise in plan (default 0)
    origin = [0.0, 0.0]           # [m] plan position of the first row's origin
    spacing = [0.0, 3.6]          # [m] plan offset from one row of the group to the next
                                  # (required when count > 1)
    depth = 1.1                   # [m] plan depth of a 2D rack (3D racks give their own)

Plan: X along the record's first horizontal component, Y along the second. A row starts at its
origin (the base of its first upright, front frame), runs its length (the sum of its bays)
along (cos θ, sin θ) and its depth along (−sin θ, cos θ). A runner will excite a row with
a_down = a_1 cos θ + a_2 sin θ and a_cross = −a_1 sin θ + a_2 cos θ. Rows may not overlap.

Only the loader and validator exist; running a warehouse study waits for 3D studies.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.errors import FileFormatError, InputError
from seisrack.model._reader import Table, check_number

#: plan depth of a 2D rack row when the row does not give one [m] (a EUR-pallet rack frame)
DEFAULT_DEPTH_2D = 1.1
_ROW_KEYS = ("name", "rack", "count", "orientation", "origin", "spacing", "depth")


@dataclass(frozen=True)
class WarehouseRow:
    """A group of identical rack rows.

    rack: resolved path of the rack file; rack_as_given: as written; count: rows in the group;
    orientation_deg [deg]; origin, spacing: (X, Y) [m]; length, depth: plan size of one row
    [m]; three_d: the rack file is a 3D rack; n_pallets: pallets per row.
    """

    name: str
    rack: str
    rack_as_given: str
    count: int
    orientation_deg: float
    origin: tuple[float, float]
    spacing: tuple[float, float]
    length: float
    depth: float
    three_d: bool
    n_pallets: int

    def footprints(self) -> list[np.ndarray]:
        """(4, 2) [m] plan corners of each of the ``count`` rows, counter-clockwise."""
        t = math.radians(self.orientation_deg)
        u = np.array([math.cos(t), math.sin(t)])
        v = np.array([-math.sin(t), math.cos(t)])
        out = []
        for k in range(self.count):
            o = np.asarray(self.origin) + k * np.asarray(self.spacing)
            out.append(np.array([o, o + self.length * u, o + self.length * u + self.depth * v,
                                 o + self.depth * v]))
        return out


@dataclass(frozen=True)
class Warehouse:
    """A validated warehouse: its row groups, title and source file."""

    rows: tuple[WarehouseRow, ...]
    title: str = ""
    source: str | None = None

    @property
    def n_rows(self) -> int:
        """Total number of rack rows (every group's count)."""
        return sum(r.count for r in self.rows)

    @property
    def n_pallets(self) -> int:
        return sum(r.count * r.n_pallets for r in self.rows)

    def placements(self) -> list[dict[str, Any]]:
        """One dict per rack row: group name, index in the group, rack, orientation, corners."""
        return [{"group": r.name, "index": k, "rack": r.rack,
                 "orientation_deg": r.orientation_deg, "corners": c}
                for r in self.rows for k, c in enumerate(r.footprints())]


def load_warehouse(path: str | Path) -> Warehouse:
    """Read and validate a warehouse TOML file (paths inside are relative to it)."""
    p = Path(path)
    if not p.is_file():
        raise InputError("warehouse", str(p), "an existing warehouse TOML file")
    try:
        data = tomllib.loads(p.read_bytes().decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise FileFormatError(str(p), f"not UTF-8 text ({exc.reason})") from None
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(str(p), f"malformed TOML: {exc}") from None
    return warehouse_from_dict(data, base=p.parent, source=str(p))


def warehouse_from_dict(d: Any, *, base: str | Path = ".", source: str | None = None
                        ) -> Warehouse:
    """Validate a parsed warehouse document; rack paths are taken from ``base``."""
    root = Table(d, "", source)
    title = root.string("title", "")
    raw = root.raw("rows")
    if not isinstance(raw, list) or not raw or not all(isinstance(r, dict) for r in raw):
        raise root.error("rows", raw, "one or more [[rows]] tables")
    root.finish(("title", "rows"))
    rows = tuple(_row(Table(r, f"rows[{i}]", source), i, Path(base)) for i, r in enumerate(raw))
    names = [r.name for r in rows]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError("rows.name", dup[0], "a distinct name for each group of rows",
                         source=source)
    w = Warehouse(rows=rows, title=title, source=source)
    _check_overlaps(w, source)
    return w


def _pair(t: Table, key: str, default: Any) -> tuple[float, float]:
    val = t.raw(key, default)
    if not isinstance(val, list) or len(val) != 2:
        raise t.error(key, val, "an array [X, Y] of two numbers [m]")
    return (check_number(val[0], f"{t.field(key)}[0]", unit="m", source=t.source),
            check_number(val[1], f"{t.field(key)}[1]", unit="m", source=t.source))


def _plan_depth(geometry: Any) -> float:
    """A rack's plan depth: a 2D rack's default, a 3D rack's front frame to rear frame (both
    rows and the flue of a back-to-back rack)."""
    z = getattr(geometry, "frame_z", (0.0,))
    if getattr(geometry, "depth", None) is None:
        return DEFAULT_DEPTH_2D
    return float(z[-1] - z[0]) if len(z) > 1 else float(geometry.depth)


def _row(t: Table, i: int, base: Path) -> WarehouseRow:
    from seisrack.model import load_rack

    name = t.string("name", f"row {i + 1}")
    given = t.string("rack")
    rp = base / given if not Path(given).is_absolute() else Path(given)
    if not rp.is_file():
        raise t.error("rack", given, f"an existing rack TOML file (looked for {rp})")
    try:
        spec = load_rack(rp)
    except InputError as exc:
        raise t.error("rack", given, "a valid rack file", hint=str(exc)) from None
    count = t.integer("count", 1, minimum=1)
    angle = t.number("orientation", 0.0, unit="deg")
    if not -360.0 <= angle <= 360.0:
        raise t.error("orientation", angle, "an angle in [-360, 360] degrees")
    origin = _pair(t, "origin", [0.0, 0.0])
    if count > 1 and not t.has("spacing"):
        raise t.error("spacing", None, "an array [dX, dY] [m] from one row to the next "
                      f"(count = {count})")
    spacing = _pair(t, "spacing", [0.0, 0.0])
    depth_3d = getattr(spec.geometry, "depth", None)
    if t.has("depth"):
        if depth_3d is not None:
            raise t.error("depth", t.data["depth"], "no depth for a 3D rack (its file gives "
                          f"depth = {depth_3d:g} m)")
        depth = t.number("depth", positive=True, unit="m")
    else:
        depth = _plan_depth(spec.geometry)
    t.finish(_ROW_KEYS)
    if count > 1 and math.hypot(*spacing) == 0.0:
        raise t.error("spacing", list(spacing), "a non-zero offset between the rows of a group")
    return WarehouseRow(name=name, rack=str(rp), rack_as_given=given, count=count,
                        orientation_deg=angle, origin=origin, spacing=spacing,
                        length=float(sum(spec.geometry.bays)), depth=depth,
                        three_d=depth_3d is not None, n_pallets=len(spec.pallets))


def _overlap(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether two convex plan polygons (4, 2) overlap with a positive area (separating axes)."""
    for poly in (a, b):
        for k in range(len(poly)):
            e = poly[(k + 1) % len(poly)] - poly[k]
            n = np.array([-e[1], e[0]])
            pa, pb = a @ n, b @ n
            if pa.max() <= pb.min() + tol * np.linalg.norm(n) or \
                    pb.max() <= pa.min() + tol * np.linalg.norm(n):
                return False
    return True


def _check_overlaps(w: Warehouse, source: str | None) -> None:
    pl = w.placements()
    for i in range(len(pl)):
        for j in range(i + 1, len(pl)):
            if _overlap(pl[i]["corners"], pl[j]["corners"]):
                a, b = pl[i], pl[j]
                raise InputError("rows", f"{a['group']} #{a['index'] + 1} and {b['group']} "
                                 f"#{b['index'] + 1}", "rows that do not overlap in plan",
                                 source=source, hint="Check origin, spacing and orientation")
