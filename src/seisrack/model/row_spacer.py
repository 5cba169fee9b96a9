"""``rows`` and ``[geometry.row_spacer]`` of a 3D rack: two rows of upright frames back to back
(a double-entry rack) joined by row spacers, pin-ended members between the facing uprights of
the two rows at given heights (``docs/user/rack_toml.md``, "Back-to-back rows").

:func:`read_rows` reads the keys with their bounds (a spacer's length, the gaps between
spacers); :func:`check_spacer_nodes` then keeps each spacer on an upright node or clear of the
base, the beam levels, the bracing ends and the storey divisions, once ``[bracing]`` is read.
Both run before the model is built: spacers a few millimetres apart made the stiffness near
singular and were refused by the wrong checks (a "mechanism" of the bracing, an asymmetric
damping matrix).
"""

from __future__ import annotations

import bisect
import math
from typing import Any

from seisrack.limits import MAX_PANEL_POINTS, MIN_NODE_GAP
from seisrack.model._reader import Table, check_number
from seisrack.model.spec import Geometry, RowSpacer, Section

_GEOM_TOL = 1e-9  # m, slack for floating-point geometry comparisons
#: [m] upright heights this close share one node (the 3D mesher merges them)
NODE_MERGE = 1e-6
#: [m] shortest spacer: it joins the centrelines of two uprights side by side across the flue,
#: which are at least an upright's width apart (pallet-rack uprights are 50-150 mm wide; real
#: spacers are 0.1-0.5 m long). A 1e-9 m bar (EA/L ~ 1e17 N/m) made the stiffness so badly
#: scaled that the stability check took an upright frame for a mechanism.
_MIN_SPACER_LENGTH = 0.05
#: [m] closest a spacer may be to another spacer, the base, a beam level or a bracing end on the
#: same upright without sharing its node (:data:`seisrack.limits.MIN_NODE_GAP`)
_MIN_SPACER_GAP = MIN_NODE_GAP


def read_rows(t: Table, top: float, depth: float | None, sections: dict[str, Section]
          ) -> tuple[int, RowSpacer | None]:
    """``rows`` (1, or 2 back to back) and ``[geometry.row_spacer]``: 3D racks only."""
    if depth is None:
        for key in ("rows", "row_spacer"):
            if t.has(key):
                raise t.error(key, t.raw(key), "no rows or row spacers in a 2D rack (they "
                              "are keys of a 3D rack)", hint="Give [geometry] depth (the "
                              "upright-frame depth, m) for a 3D rack, then rows = 2 and "
                              "[geometry.row_spacer] for a back-to-back (double-entry) rack")
        return 1, None
    rows = t.integer("rows", 1)
    if rows not in (1, 2):
        raise t.error("rows", rows, "1 (one row of upright frames) or 2 (two rows back to "
                                    "back, joined by [geometry.row_spacer])")
    if rows == 1:
        if t.has("row_spacer"):
            raise t.error("row_spacer", t.raw("row_spacer"), "no row spacer on a rack of one "
                          "row", hint="Set [geometry] rows = 2 for a back-to-back rack")
        return 1, None
    if not t.has("row_spacer"):
        raise t.error("row_spacer", None, "a [geometry.row_spacer] table (length, section, "
                      "spacing or heights): two rows back to back are joined by row spacers")
    st = t.table("row_spacer")
    length = st.number("length", positive=True, unit="m")
    if length < _MIN_SPACER_LENGTH - _GEOM_TOL:
        raise st.error("length", length, f"a spacer length >= {_MIN_SPACER_LENGTH:g} m (the "
                       "distance between the centrelines of two uprights side by side across "
                       "the flue: at least an upright's width; real spacers are 0.1-0.5 m)")
    section = st.string("section")
    if section not in sections:
        raise st.error("section", section, f"one of the [sections]: {', '.join(sorted(sections))}")
    if st.has("spacing") == st.has("heights"):
        raise st.error("spacing", st.raw("spacing", None), "either spacing (a vertical spacing, "
                       "m) or heights (a list of heights, m), not both and not neither")
    if st.has("spacing"):
        h = st.number("spacing", positive=True, unit="m")
        if h > top + _GEOM_TOL:
            raise st.error("spacing", h, f"a spacing <= the upright height {top:g} m (a "
                           "spacer must fit on the uprights)")
        n = int(math.floor(top / h + 1e-9))
        low = max(_MIN_SPACER_GAP, top / (MAX_PANEL_POINTS - 1))  # with the one at the top
        if h < low - _GEOM_TOL:  # before the heights are built
            raise st.error("spacing", h, f"a spacing >= {low:.3g} m (spacers at least "
                           f"{_MIN_SPACER_GAP:g} m apart and at most {MAX_PANEL_POINTS:,} on the "
                           f"{top:g} m uprights)", hint=f"{h:g} m gives {n:,} spacers on each "
                           "upright line; real racks have one at each beam level or every "
                           "1-2 m")
        heights = [k * h for k in range(1, n + 1)]
        if top - heights[-1] > 1e-6 * top:
            heights.append(top)  # and one at the top of the uprights
            if top - heights[-2] < _MIN_SPACER_GAP - _GEOM_TOL:
                raise st.error("spacing", h, f"a spacing whose last spacer ({heights[-2]:g} "
                               f"m) is at least {_MIN_SPACER_GAP:g} m below the one at the top "
                               f"of the uprights ({top:g} m)", hint="Or list the spacers "
                               "with heights = [...]")
    else:
        raw = st.array("heights", min_len=1)
        if len(raw) > MAX_PANEL_POINTS:
            raise st.error("heights", f"{len(raw)} heights", f"at most {MAX_PANEL_POINTS:,} "
                           "spacer heights on an upright line")
        heights = [check_number(v, f"{st.field('heights')}[{i}]", positive=True, unit="m",
                                source=st.source) for i, v in enumerate(raw)]
        if any(b <= a for a, b in zip(heights[:-1], heights[1:], strict=True)) \
                or heights[-1] > top + _GEOM_TOL:
            raise st.error("heights", raw, f"an increasing list of heights in (0, {top:g}] m "
                           "(on the uprights, above the floor)")
        for i in range(1, len(heights)):
            if heights[i] - heights[i - 1] < _MIN_SPACER_GAP - _GEOM_TOL:
                raise st.error(f"heights[{i}]", heights[i], f"a height at least "
                               f"{_MIN_SPACER_GAP:g} m above the spacer before it "
                               f"(heights[{i - 1}] = {heights[i - 1]:g} m)",
                               hint="Two spacers closer than that are one joint in this "
                                    "model, and upright nodes that close make the stiffness "
                                    "matrix near singular")
    st.finish(("length", "section", "spacing", "heights"))
    return 2, RowSpacer(length=length, section=section, heights=tuple(heights))


def check_spacer_nodes(st: Table, geom: Geometry, bracing: Any) -> None:
    """Each row spacer shares an upright node (within ``NODE_MERGE``) or keeps clear of it:
    ``_MIN_SPACER_GAP`` from the base, the beam levels and the bracing ends, and from the
    storey divisions the less of that and a quarter of a division (see ``_MIN_SPACER_GAP``)."""
    key = "spacing" if st.has("spacing") else "heights"
    ys = (0.0, *geom.level_y)
    ends = () if bracing is None else bracing.heights
    n = geom.subdivisions
    for i, y in enumerate(geom.row_spacer.heights):  # type: ignore[union-attr]
        level = _nearest(ys, y)
        near = [(level, _MIN_SPACER_GAP,
                 "the base" if level == 0.0 else f"beam level {ys.index(level)}"),
                (_nearest(ends, y), _MIN_SPACER_GAP, "a bracing member's end")]
        s = min(bisect.bisect_left(ys, y) - 1, geom.n_levels - 1)  # storey of y (0-based)
        step = (ys[s + 1] - ys[s]) / n
        k = round((y - ys[s]) / step)
        if 0 < k < n:  # a mesh node: the gap need not exceed a quarter of a division
            near.append((ys[s] + k * step, min(_MIN_SPACER_GAP, 0.25 * step),
                         f"an upright node of geometry.subdivisions = {n}"))
        for node, gap, what in near:
            d = abs(y - node)
            shared = d <= NODE_MERGE and node > 0.0  # a spacer at the base would do nothing
            if d < gap - _GEOM_TOL and not shared:
                which = "it is" if key == "heights" else f"the spacer at {y:g} m is"
                rule = (f"at least {gap:g} m above the base ({which} {d:.3g} m)"
                        if node == 0.0 else f"at {what} ({node:g} m) or at least {gap:g} m "
                        f"from it ({which} {d:.3g} m away)")
                field, value, allowed = ((f"heights[{i}]", y, f"a spacer height {rule}")
                                         if key == "heights" else
                                         (key, st.raw(key), f"a spacing whose spacers are {rule}"))
                raise st.error(field, value, allowed,
                               hint="Upright nodes that close make the stiffness matrix near "
                                    "singular" + ("; or list the spacers with heights = [...]"
                                                  if key == "spacing" else ""))


def _nearest(sorted_values: tuple[float, ...], y: float) -> float:
    """The value of ``sorted_values`` nearest ``y`` (inf if there is none)."""
    i = bisect.bisect_left(sorted_values, y)
    near = [sorted_values[j] for j in (i - 1, i) if 0 <= j < len(sorted_values)]
    return min(near, key=lambda v: abs(v - y), default=math.inf)
