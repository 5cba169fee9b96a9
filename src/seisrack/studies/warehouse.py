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

Limits (refused with an :class:`~seisrack.errors.InputError` naming the field):

- :data:`MAX_ROWS` rack rows in all (the sum of every group's ``count``), checked on the parsed
  document before any rack file is read. A study does not run a row each: the rows of a group
  share their runs (seisrack.studies.spec), so ``count`` costs nothing in the number of runs,
  which :data:`seisrack.limits.MAX_STUDY_RUNS` bounds. What grows with the rows is the plan
  work: the overlap check below and the plan figures of the summary, one per intensity level,
  which draw each row (about 4 ms a row here, so some 40 s a figure at the limit).
- :data:`MAX_PLAN_COORD` [m] on every plan coordinate: origins, spacings and every corner of
  every row, and on a row's length and depth.

Overlaps are found by a sort and sweep of the rows' bounding boxes along the axis where they
overlap least, then the separating-axis test, vectorised, on the candidate pairs only: a few
thousand rows check in milliseconds where the test of every pair took minutes.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.errors import FileFormatError, InputError
from seisrack.model._reader import Table, check_number

#: plan depth of a 2D rack row when the row does not give one [m] (a EUR-pallet rack frame)
DEFAULT_DEPTH_2D = 1.1
#: Most rack rows of a warehouse (every group's ``count`` summed). The largest warehouses are
#: about 1 km across; with a row every 4 m or so (a 1.1 m deep row and a 3 m aisle) and a few
#: rows along each line, that is a few thousand rows. 10,000 (the limit of a rack's bays,
#: ``seisrack.limits.MAX_COUNT``) leaves room; beyond, ``count`` is a typo. The study's runs do
#: not grow with it (a group's rows share their runs); its plan figures do, about 4 ms a row.
MAX_ROWS = 10_000
#: [m] largest plan coordinate, |X| and |Y|, of any corner of any row (and largest origin,
#: spacing, row length and depth). 100 times the largest warehouses, so that site coordinates
#: fit; and small enough that a corner is exact to about 1e-11 m (1e5 x 2.2e-16), well below
#: the 1e-9 m tolerance that lets rows touch: at 1e7 m, rounding alone would reach it, and at
#: 1e308 m the overlap test overflows and let overlapping rows through.
MAX_PLAN_COORD = 1.0e5
#: [m] projections closer than this (per unit of the axis) count as touching, not overlapping
_TOUCH_TOL = 1e-9
#: candidate pairs tested at once (bounds the memory of the vectorised test to some 50 MB)
_CHUNK = 1 << 16
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

    def corners(self) -> np.ndarray:
        """(count, 4, 2) [m] plan corners of the group's rows, each counter-clockwise."""
        t = math.radians(self.orientation_deg)
        u = np.array([math.cos(t), math.sin(t)])
        v = np.array([-math.sin(t), math.cos(t)])
        o = np.asarray(self.origin) + np.arange(self.count)[:, None] * np.asarray(self.spacing)
        return np.stack([o, o + self.length * u, o + self.length * u + self.depth * v,
                         o + self.depth * v], axis=1)

    def footprints(self) -> list[np.ndarray]:
        """(4, 2) [m] plan corners of each of the ``count`` rows, counter-clockwise."""
        return list(self.corners())


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
    _check_row_count(raw, source)  # before any rack file is read
    racks: dict[Path, Any] = {}  # a rack file named by several groups is read once
    rows = tuple(_row(Table(r, f"rows[{i}]", source), i, Path(base), racks)
                 for i, r in enumerate(raw))
    names = [r.name for r in rows]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError("rows.name", dup[0], "a distinct name for each group of rows",
                         source=source)
    w = Warehouse(rows=rows, title=title, source=source)
    _check_overlaps(w, source)
    return w


def _check_row_count(raw: list[dict[str, Any]], source: str | None) -> None:
    """Refuse a group or a warehouse of more than :data:`MAX_ROWS` rows, from the parsed
    document alone (a count of the wrong type is left to :func:`_row` to name)."""
    total = 0
    for i, r in enumerate(raw):
        c = r.get("count", 1)
        if isinstance(c, bool) or not isinstance(c, int):
            continue
        if c > MAX_ROWS:
            raise InputError(f"rows[{i}].count", c, f"an integer from 1 to {MAX_ROWS:,} (the "
                             "rows of a whole warehouse)", source=source,
                             hint="A real warehouse has a few thousand rows at most; check "
                                  "the count for a typo")
        total += max(c, 0)
    if total > MAX_ROWS:
        raise InputError("rows[].count", f"{total:,} rows in {len(raw)} groups",
                         f"a warehouse of at most {MAX_ROWS:,} rack rows (the sum of every "
                         "group's count)", source=source,
                         hint="Split the site into several warehouse files")


def _pair(t: Table, key: str, default: Any) -> tuple[float, float]:
    val = t.raw(key, default)
    if not isinstance(val, list) or len(val) != 2:
        raise t.error(key, val, "an array [X, Y] of two numbers [m]")
    out = []
    for k in (0, 1):
        x = check_number(val[k], f"{t.field(key)}[{k}]", unit="m", source=t.source)
        if not abs(x) <= MAX_PLAN_COORD:
            raise InputError(f"{t.field(key)}[{k}]", val[k], f"a number [m] from "
                             f"{-MAX_PLAN_COORD:g} to {MAX_PLAN_COORD:g} (plan positions and "
                             "offsets stay within the warehouse's range)", source=t.source)
        out.append(x)
    return out[0], out[1]


def _plan_depth(geometry: Any) -> float:
    """A rack's plan depth: a 2D rack's default, a 3D rack's front frame to rear frame (both
    rows and the flue of a back-to-back rack)."""
    z = getattr(geometry, "frame_z", (0.0,))
    if getattr(geometry, "depth", None) is None:
        return DEFAULT_DEPTH_2D
    return float(z[-1] - z[0]) if len(z) > 1 else float(geometry.depth)


def _row(t: Table, i: int, base: Path, racks: dict[Path, Any]) -> WarehouseRow:
    from seisrack.model import load_rack

    name = t.string("name", f"row {i + 1}")
    given = t.string("rack")
    rp = base / given if not Path(given).is_absolute() else Path(given)
    if not rp.is_file():
        raise t.error("rack", given, f"an existing rack TOML file (looked for {rp})")
    if rp.resolve() not in racks:
        try:
            racks[rp.resolve()] = load_rack(rp)
        except InputError as exc:
            raise t.error("rack", given, "a valid rack file", hint=str(exc)) from None
    spec = racks[rp.resolve()]
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
    length = float(sum(spec.geometry.bays))
    for key, what, size in (("rack", "long (the sum of its bays)", length),
                            ("depth" if t.has("depth") else "rack", "deep", depth)):
        if not size <= MAX_PLAN_COORD:
            raise t.error(key, t.data[key], f"a row at most {MAX_PLAN_COORD:g} m {what}",
                          hint=f"This row would be {size:g} m {what.split()[0]}")
    row = WarehouseRow(name=name, rack=str(rp), rack_as_given=given, count=count,
                       orientation_deg=angle, origin=origin, spacing=spacing, length=length,
                       depth=depth, three_d=depth_3d is not None, n_pallets=len(spec.pallets))
    _check_extent(t, row)
    return row


def _check_extent(t: Table, row: WarehouseRow) -> None:
    """Every corner of the group within ±:data:`MAX_PLAN_COORD`, from its first and last rows
    (plain floats: an overflow becomes inf, refused, and warns of nothing)."""
    th = math.radians(row.orientation_deg)
    dx = (0.0, row.length * math.cos(th), row.length * math.cos(th) - row.depth * math.sin(th),
          -row.depth * math.sin(th))
    dy = (0.0, row.length * math.sin(th), row.length * math.sin(th) + row.depth * math.cos(th),
          row.depth * math.cos(th))
    ends = [(row.origin[0] + k * row.spacing[0], row.origin[1] + k * row.spacing[1])
            for k in (0, row.count - 1)]
    xs = [ox + d for ox, _ in ends for d in dx]
    ys = [oy + d for _, oy in ends for d in dy]
    if all(abs(c) <= MAX_PLAN_COORD for c in xs + ys):
        return
    first_in = all(abs(ends[0][0] + a) <= MAX_PLAN_COORD and abs(ends[0][1] + b)
                   <= MAX_PLAN_COORD for a, b in zip(dx, dy, strict=True))
    key = "spacing" if row.count > 1 and first_in else "origin"
    raise t.error(key, list(getattr(row, key)), f"rows within {MAX_PLAN_COORD:g} m of the plan "
                  "origin in X and Y", hint=f"The group's {row.count} row(s) would span X from "
                  f"{min(xs):g} to {max(xs):g} m and Y from {min(ys):g} to {max(ys):g} m "
                  f"(rows {row.length:g} m long and {row.depth:g} m deep); move the origin or "
                  "shorten the spacing")


def _overlaps(a: np.ndarray, b: np.ndarray, tol: float = _TOUCH_TOL) -> np.ndarray:
    """(m,) bool: whether the convex polygons ``a[k]`` and ``b[k]``, (m, 4, 2) [m], overlap with
    a positive area. Separating axes: they do not when, on the normal of an edge of either,
    their projections are disjoint or overlap by at most ``tol`` (touching rows)."""
    out = np.ones(len(a), dtype=bool)
    for poly in (a, b):
        e = np.roll(poly, -1, axis=1) - poly  # (m, 4, 2): edge k from corner k to k + 1
        nx, ny = -e[:, :, 1, None], e[:, :, 0, None]  # (m, 4 edges, 1)
        pa = a[:, None, :, 0] * nx + a[:, None, :, 1] * ny  # (m, 4 edges, 4 corners)
        pb = b[:, None, :, 0] * nx + b[:, None, :, 1] * ny
        t = tol * np.hypot(nx[..., 0], ny[..., 0])
        sep = (pa.max(axis=2) <= pb.min(axis=2) + t) | (pb.max(axis=2) <= pa.min(axis=2) + t)
        out &= ~sep.any(axis=1)
    return out


def _candidate_pairs(lo: np.ndarray, hi: np.ndarray, tol: float = _TOUCH_TOL
                     ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Pairs (i, j), i != j, of boxes ``lo``-``hi`` (n, 2) [m] that overlap by more than
    ``-tol`` in X and in Y, as arrays i, j of at most :data:`_CHUNK` pairs at a time.

    Sort and sweep along the axis where fewer boxes overlap: sorted by their lower bound, box p
    meets boxes p + 1 to end[p] - 1 on that axis, and the other axis filters them. No overlap is
    lost: when two rows' bounding boxes overlap by at most ``tol`` along X (or Y), so does their
    penetration depth (the least overlap of their projections over all directions); for convex
    polygons it is reached on an edge normal, where :func:`_overlaps` calls them touching."""
    best = None
    for ax in (0, 1):
        order = np.argsort(lo[:, ax], kind="stable")
        los, his = lo[order, ax], hi[order, ax]
        end = np.searchsorted(los, his + tol, side="left")
        cnt = np.maximum(end - np.arange(len(los)) - 1, 0)
        if best is None or cnt.sum() < best[2].sum():
            best = (ax, order, cnt)
    ax, order, cnt = best
    other = 1 - ax
    cum = np.concatenate([[0], np.cumsum(cnt)])
    start = 0
    while start < len(cnt):
        stop = max(int(np.searchsorted(cum, cum[start] + _CHUNK, side="right")) - 1, start + 1)
        c = cnt[start:stop]
        p = np.repeat(np.arange(start, stop), c)
        q = p + 1 + np.arange(len(p)) - np.repeat(cum[start:stop] - cum[start], c)
        i, j = order[p], order[q]
        keep = (lo[i, other] < hi[j, other] + tol) & (lo[j, other] < hi[i, other] + tol)
        if keep.any():
            yield i[keep], j[keep]
        start = stop


def _check_overlaps(w: Warehouse, source: str | None) -> None:
    """Refuse rows that overlap in plan (touching is allowed); names the first pair found."""
    corners = np.concatenate([r.corners() for r in w.rows])  # (n, 4, 2)
    group = np.repeat(np.arange(len(w.rows)), [r.count for r in w.rows])
    index = np.concatenate([np.arange(r.count) for r in w.rows])
    for i, j in _candidate_pairs(corners.min(axis=1), corners.max(axis=1)):
        hit = _overlaps(corners[i], corners[j])
        if hit.any():
            a, b = np.minimum(i[hit], j[hit]), np.maximum(i[hit], j[hit])
            k = np.lexsort((b, a))[0]
            ra, rb = w.rows[group[a[k]]], w.rows[group[b[k]]]
            raise InputError("rows", f"{ra.name} #{index[a[k]] + 1} and {rb.name} "
                             f"#{index[b[k]] + 1}", "rows that do not overlap in plan",
                             source=source, hint="Check origin, spacing and orientation")
