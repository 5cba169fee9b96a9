"""The ``[bracing]`` table of a 3D rack: upright-frame bracing patterns and the spine.

Every upright frame (the front and the rear upright of one line, ``geometry.depth`` apart) is
braced alike in its cross-aisle plane by pin-ended members between *panel points*, heights on
the front (``F``) and rear (``R``) uprights. ``panel`` is a spacing h (points 0, h, 2h, ... and
the top of the uprights) or an explicit increasing list of heights [m] in [0, top]. Patterns
(k = panel index, bottom to top; see ``docs/user/rack_toml.md`` for figures in words):

- ``"Z"``: a horizontal at every panel point, one diagonal per panel, all parallel
  (F_k → R_{k+1});
- ``"D"``: horizontals, diagonals alternating in direction (F_k → R_{k+1}, then R_{k+1} →
  F_{k+2}, ...), a zig-zag;
- ``"K"``: horizontals, and in each panel two diagonals from the front upright at mid-panel to
  the rear upright's panel points R_k and R_{k+1};
- ``"X"``: horizontals and both diagonals in every panel (not connected where they cross);
- an array of members ``[["F0", "R1"], ["R1", "F2"], ...]``: each end is ``F`` or ``R`` and a
  panel-point index.

A member whose ends are at the same height uses ``horizontal_section``, any other
``diagonal_section``. Bracing eccentricities (members meeting the upright off its centroid and
off each other) are ignored: the members join the upright centrelines at the panel points.

Spine bracing (``spine = true``) braces the rear plane down-aisle: one diagonal per braced storey
(``spine_levels``, 1-based storeys, default all) in each braced bay (``spine_bays``, default
all), between the rear uprights' level nodes, alternating in direction storey by storey, with
``spine_section``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from seisrack.limits import MAX_PANEL_POINTS, MIN_NODE_GAP
from seisrack.model._reader import Table, check_number

PATTERNS = ("Z", "D", "K", "X")
BRACING_KEYS = ("pattern", "panel", "horizontal_section", "diagonal_section", "spine",
                "spine_section", "spine_bays", "spine_levels")
_END_RE = re.compile(r"^\s*([FRfr])\s*(\d+)\s*$")
_TOL = 1e-9

FRONT, REAR = 0, 1


@dataclass(frozen=True)
class Bracing:
    """A validated ``[bracing]`` table.

    ``members``: ((side_a, y_a, side_b, y_b), ...) with side FRONT (0) or REAR (1) and heights
    [m] above the base, the same for every upright frame. ``sections``: the section name of
    each member. ``spine_bays``/``spine_levels``: 0-based bays and storeys with a spine
    diagonal (empty when there is no spine).
    """

    pattern: str
    panel_points: tuple[float, ...]
    members: tuple[tuple[int, float, int, float], ...]
    sections: tuple[str, ...]
    spine_section: str | None = None
    spine_bays: tuple[int, ...] = ()
    spine_levels: tuple[int, ...] = ()

    @property
    def heights(self) -> tuple[float, ...]:
        """Every height [m] where a member meets an upright (upright nodes are needed there)."""
        ys = {m[1] for m in self.members} | {m[3] for m in self.members}
        return tuple(sorted(ys))


def read_bracing(t: Table, top: float, n_bays: int, n_levels: int, sections: Any) -> Bracing:
    """Validate ``[bracing]`` for uprights of height ``top`` [m]."""
    points = _panel_points(t, top)
    raw = t.raw("pattern")
    if isinstance(raw, str):
        if raw.upper() not in PATTERNS:
            raise t.error("pattern", raw, 'one of "Z", "D", "K", "X" or an array of members '
                                          '[["F0", "R1"], ...]')
        pattern = raw.upper()
        members = _pattern_members(pattern, points)
    elif isinstance(raw, list):
        pattern = "list"
        members = _explicit_members(t, raw, points)
    else:
        raise t.error("pattern", raw, '"Z", "D", "K", "X" or an array of members')
    names = sorted(sections)
    need_h = any(a[1] == a[3] for a in members)
    need_d = any(a[1] != a[3] for a in members)
    h_sec = _section(t, "horizontal_section", names, need_h)
    d_sec = _section(t, "diagonal_section", names, need_d)
    secs = tuple(h_sec if a[1] == a[3] else d_sec for a in members)
    spine = t.raw("spine", False)
    if not isinstance(spine, bool):
        raise t.error("spine", spine, "true or false")
    s_sec, s_bays, s_levels = None, (), ()
    if spine:
        s_sec = _section(t, "spine_section", names, True)
        s_bays = _indices(t, "spine_bays", n_bays, "bay")
        s_levels = _indices(t, "spine_levels", n_levels, "storey")
    t.finish(BRACING_KEYS)
    return Bracing(pattern=pattern, panel_points=points, members=members, sections=secs,
                   spine_section=s_sec, spine_bays=s_bays, spine_levels=s_levels)


def _panel_points(t: Table, top: float) -> tuple[float, ...]:
    raw = t.raw("panel")
    if isinstance(raw, list):
        pts = [check_number(v, f"{t.field('panel')}[{i}]", nonnegative=True, unit="m",
                            source=t.source) for i, v in enumerate(raw)]
        if len(pts) > MAX_PANEL_POINTS:
            raise t.error("panel", f"{len(pts)} heights", f"at most {MAX_PANEL_POINTS} panel "
                                                          "points on an upright")
        if len(pts) < 2 or any(b <= a for a, b in zip(pts[:-1], pts[1:], strict=True)) \
                or pts[-1] > top + _TOL:
            raise t.error("panel", raw, f"an increasing array of at least 2 heights in "
                                        f"[0, {top:g}] m (the top of the uprights)")
        for i in range(1, len(pts)):
            if pts[i] - pts[i - 1] < MIN_NODE_GAP - _TOL:
                raise t.error(f"panel[{i}]", pts[i], f"a panel point at least {MIN_NODE_GAP:g} "
                              f"m above the one before it (panel[{i - 1}] = {pts[i - 1]:g} m)",
                              hint="Nearer points are one joint in this model, and upright "
                                   "nodes that close make the stiffness matrix near singular")
        return tuple(pts)
    h = t.number("panel", positive=True, unit="m")
    if h > top + _TOL:
        raise t.error("panel", raw, f"a panel height <= the upright height {top:g} m")
    n = int(math.floor(top / h + 1e-9))
    if n + 1 > MAX_PANEL_POINTS:  # checked before the points are built (a mm for m typo)
        raise t.error("panel", h, f"a panel height >= {top / (MAX_PANEL_POINTS - 1):.3g} m "
                      f"(at most {MAX_PANEL_POINTS} panel points on the {top:g} m upright)",
                      hint=f"{h:g} m gives {n + 1:,} panel points; is the panel in metres?")
    pts = [k * h for k in range(n + 1)]
    if top - pts[-1] > 1e-6 * top:
        if top - pts[-1] < MIN_NODE_GAP - _TOL:  # a sliver of a panel under the top point
            raise t.error("panel", h, f"a panel height whose last point ({pts[-1]:g} m) is at "
                          f"least {MIN_NODE_GAP:g} m below the top of the uprights ({top:g} m), "
                          "or that divides it", hint="Nearer points are one joint in this "
                          "model; or list the panel points with panel = [...]")
        pts.append(top)
    return tuple(pts)


def _pattern_members(pattern: str, y: tuple[float, ...]
                     ) -> tuple[tuple[int, float, int, float], ...]:
    out = [(FRONT, yk, REAR, yk) for yk in y]  # horizontals at every panel point
    for k in range(len(y) - 1):
        lo, hi = y[k], y[k + 1]
        if pattern == "Z":
            out.append((FRONT, lo, REAR, hi))
        elif pattern == "D":
            out.append((FRONT, lo, REAR, hi) if k % 2 == 0 else (REAR, lo, FRONT, hi))
        elif pattern == "K":
            mid = 0.5 * (lo + hi)
            out += [(FRONT, mid, REAR, lo), (FRONT, mid, REAR, hi)]
        else:  # X
            out += [(FRONT, lo, REAR, hi), (REAR, lo, FRONT, hi)]
    return tuple(out)


def _explicit_members(t: Table, raw: list[Any], y: tuple[float, ...]
                      ) -> tuple[tuple[int, float, int, float], ...]:
    allowed = (f'a member ["F<k>", "R<k>"]: each end F (front) or R (rear) upright and a '
               f"panel-point index 0..{len(y) - 1}")
    out = []
    for i, mem in enumerate(raw):
        field = f"pattern[{i}]"
        if not isinstance(mem, list) or len(mem) != 2:
            raise t.error(field, mem, allowed)
        ends = []
        for e in mem:
            m = _END_RE.match(e) if isinstance(e, str) else None
            if m is None or int(m.group(2)) >= len(y):
                raise t.error(field, mem, allowed)
            ends.append((FRONT if m.group(1).upper() == "F" else REAR, y[int(m.group(2))]))
        if ends[0] == ends[1] or ends[0][0] == ends[1][0]:
            raise t.error(field, mem, "a member joining the front and the rear upright")
        out.append((ends[0][0], ends[0][1], ends[1][0], ends[1][1]))
    return tuple(out)


def _section(t: Table, key: str, names: list[str], required: bool) -> str | None:
    if not required and not t.has(key):
        t.raw(key, None)
        return None
    name = t.string(key)
    if name not in names:
        raise t.error(key, name, f"one of the [sections]: {', '.join(names)}")
    return name


def _indices(t: Table, key: str, n: int, what: str) -> tuple[int, ...]:
    raw = t.raw(key, None)
    if raw is None:
        return tuple(range(n))
    if not isinstance(raw, list) or not raw or any(
            isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= n for v in raw):
        raise t.error(key, raw, f"a non-empty array of {what} numbers from 1 to {n}")
    return tuple(sorted({v - 1 for v in raw}))
