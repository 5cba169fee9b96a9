"""Load a rack from TOML and validate it (the schema is in ``docs/dev/interfaces.md``).

Everything a user can get wrong is caught here and reported as an
:class:`~seisrack.errors.InputError` naming the field path (``pallets[2].mu_dynamic``), the value
and what is allowed; malformed TOML becomes a :class:`~seisrack.errors.FileFormatError` with the
line number.

``geometry.bays`` and ``geometry.levels`` are arrays of lengths or ``{count, pitch}`` tables; the
optional ``[loading]`` table generates pallets (:mod:`seisrack.model.loading`).
"""

from __future__ import annotations

import bisect
import math
import re
import tomllib
from dataclasses import replace
from pathlib import Path
from typing import Any

from seisrack.errors import FileFormatError, InputError
from seisrack.limits import (
    MAX_COUNT,
    MAX_RACK_DOFS,
    MAX_SUBDIVISIONS,
    check_rack_size,
    rack_size,
)
from seisrack.model._reader import Table, check_friction, check_number
from seisrack.model.loading import place_pallets, read_loading
from seisrack.model.row_spacer import NODE_MERGE, check_spacer_nodes, read_rows
from seisrack.model.spec import (
    DEFAULT_G,
    DEFAULT_PALLET_WIDTH,
    DEFAULT_SUBDIVISIONS,
    PINNED,
    RIGID,
    STIFFNESS_TERMS,
    Connections,
    Damping,
    Geometry,
    Hysteresis,
    Material,
    Pallet,
    RackSpec,
    SecondOrder,
    Section,
)

_TOP_KEYS = ("title", "g", "material", "sections", "geometry", "connections", "damping",
             "second_order", "hysteresis", "loading", "pallets", "bracing")
_PALLET_3D_KEYS = ("depth", "overhang")  # pallet keys of 3D racks (pallets and [loading])
_LINE_RE = re.compile(r"\(at line (\d+), column (\d+)\)")
_GEOM_TOL = 1e-9  # m, slack for floating-point geometry comparisons


def load_rack(path: str | Path) -> RackSpec:
    """Read and validate a rack TOML file."""
    p = Path(path)
    with p.open("rb") as fh:
        raw = fh.read()
    try:
        data = tomllib.loads(raw.decode("utf-8-sig"))  # a BOM (Windows Notepad) is fine
    except UnicodeDecodeError as exc:
        raise FileFormatError(str(p), f"not UTF-8 text ({exc.reason})") from None
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = _LINE_RE.search(msg)
        line = int(m.group(1)) if m else None
        msg = _LINE_RE.sub("", msg).strip()
        if m:
            msg += f" (column {m.group(2)})"
        raise FileFormatError(str(p), f"malformed TOML: {msg}", line=line) from None
    return rack_from_dict(data, source=str(p))


def rack_from_dict(d: Any, source: str | None = None) -> RackSpec:
    """Validate a parsed TOML document (a dict) and build a :class:`RackSpec`."""
    root = Table(d, "", source)
    title = root.string("title", "")
    g = root.number("g", DEFAULT_G, positive=True, unit="m/s²")
    material = _material(root.table("material"))
    three_d = isinstance(root.data.get("geometry"), dict) and "depth" in root.data["geometry"]
    sections = _sections(root.table("sections"), three_d)
    geometry = _geometry(root.table("geometry"), sections)
    connections = _connections(root.table("connections"), three_d)
    bracing = _bracing(root, geometry, sections)
    spacers = None
    if geometry.row_spacer is not None:
        spacers = root.table("geometry").table("row_spacer")
        check_spacer_nodes(spacers, geometry, bracing)
    damping = _damping(root.table("damping", {}))
    second_order = _second_order(root.table("second_order", {}))
    hysteresis = _hysteresis(root.table("hysteresis", {}), connections)
    raw_pallets = root.array("pallets", [])
    explicit = tuple(
        _pallet(Table(p, f"pallets[{i}]", source), geometry) for i, p in enumerate(raw_pallets)
    )
    loading, footprint = None, {}
    if root.has("loading"):
        lt = root.table("loading")
        # the 3D keys are read here; the rest of the table by seisrack.model.loading
        footprint = _footprint(lt, geometry)
        rest = Table({k: v for k, v in lt.data.items() if k not in _PALLET_3D_KEYS},
                     lt.path, source)
        loading = read_loading(rest, geometry)
    root.finish(_TOP_KEYS)
    _check_size(geometry, bracing, loading, len(explicit), source, spacers)
    pallets, labels = place_pallets(loading, geometry, explicit)
    fields = [{k: f"{lab}.{k}" for k in _PALLET_3D_KEYS} for lab in labels]
    if footprint:  # [loading] depth/overhang: for the pallets that do not give their own
        for p, f in zip(pallets, fields, strict=True):
            f.update({k: f"loading.{k}" for k in footprint if getattr(p, k) is None})
        pallets = tuple(replace(p, **{k: v for k, v in footprint.items()
                                      if getattr(p, k) is None}) for p in pallets)
    _check_footprints(pallets, fields, geometry, source)
    _check_overlaps(pallets, labels, source)
    return RackSpec(material=material, sections=sections, geometry=geometry,
                    connections=connections, damping=damping, pallets=pallets, g=g,
                    title=title, source=source, second_order=second_order,
                    hysteresis=hysteresis, bracing=bracing)


__all__ = ["check_friction", "load_rack", "rack_from_dict"]


def _material(t: Table) -> Material:
    m = Material(E=t.number("E", positive=True, unit="Pa"),
                 density=t.number("density", positive=True, unit="kg/m³"),
                 poisson=t.number("poisson", 0.3, unit="-"))
    if not -1.0 < m.poisson < 0.5:
        raise t.error("poisson", m.poisson, "a Poisson's ratio in (-1, 0.5) (steel: 0.3)")
    t.finish(("E", "density", "poisson"))
    return m


def _sections(t: Table, three_d: bool = False) -> dict[str, Section]:
    out: dict[str, Section] = {}
    for name in list(t.data):
        s = t.table(name)
        if not three_d:
            out[name] = Section(name=name, A=s.number("A", positive=True, unit="m²"),
                                I=s.number("I", positive=True, unit="m⁴"))
            s.finish(("A", "I"))
            continue
        out[name] = _section_3d(s, name)
    if not out:
        raise t.error("<name>", {}, "at least one named section, e.g. [sections.beam]")
    return out


def _section_3d(s: Table, name: str) -> Section:
    """A section of a 3D rack: ``I`` and ``Iz`` are the same (down-aisle-plane bending), the
    others optional here; what the members need is checked by the 3D compiler."""
    opt = {k: (s.number(k, positive=True, unit="m⁴") if s.has(k) else None)
           for k in ("I", "Iz", "Iy", "J", "Ip")}
    if opt["I"] is not None and opt["Iz"] is not None and opt["I"] != opt["Iz"]:
        raise s.error("Iz", opt["Iz"], f"the same value as I ({opt['I']:g}), or only one of "
                                       "them (both mean bending in the down-aisle plane)")
    i_z = opt["I"] if opt["I"] is not None else opt["Iz"]
    sec = Section(name=name, A=s.number("A", positive=True, unit="m²"),
                  I=math.nan if i_z is None else i_z, Iy=opt["Iy"], J=opt["J"], Ip=opt["Ip"])
    s.finish(("A", "I", "Iz", "Iy", "J", "Ip"))
    return sec


def _section_names(t: Table, key: str, n: int, what: str, sections: dict[str, Section]
                   ) -> tuple[str, ...]:
    value = t.raw(key)
    allowed = f"a section name ({', '.join(sorted(sections))}) or an array of {n} names"
    names = [value] * n if isinstance(value, str) else value
    if not isinstance(names, list) or len(names) != n:
        raise t.error(key, value, allowed + f", one per {what}")
    for i, name in enumerate(names):
        if not isinstance(name, str) or name not in sections:
            field = key if isinstance(value, str) else f"{key}[{i}]"
            raise t.error(field, name, f"one of the [sections]: {', '.join(sorted(sections))}")
    return tuple(names)


def _lengths(t: Table, key: str) -> tuple[float, ...]:
    """An array of lengths [m], or ``{count = n, pitch = h}`` for n equal lengths h."""
    value = t.raw(key)
    if isinstance(value, dict):
        c = t.table(key)
        count = c.integer("count", minimum=1)
        if count > MAX_COUNT:  # before the lengths are built
            raise c.error("count", count, f"an integer from 1 to {MAX_COUNT:,}",
                          hint="Model a part of the row: bays far apart behave alike")
        pitch = c.number("pitch", positive=True, unit="m")
        c.finish(("count", "pitch"))
        return (pitch,) * count
    if not isinstance(value, list) or not value:
        raise t.error(key, value, "a non-empty array of lengths [m] or a table "
                                  "{count = <integer >= 1>, pitch = <length > 0, m>}")
    return tuple(check_number(v, f"{t.field(key)}[{i}]", positive=True, unit="m",
                              source=t.source) for i, v in enumerate(value))


def _geometry(t: Table, sections: dict[str, Section]) -> Geometry:
    bays = _lengths(t, "bays")
    levels = _lengths(t, "levels")
    depth = t.number("depth", positive=True, unit="m") if t.has("depth") else None
    rows, spacer = read_rows(t, sum(levels), depth, sections)
    geom = Geometry(
        bays=bays, levels=levels,
        beam_sections=_section_names(t, "beam_section", len(levels), "level", sections),
        upright_sections=_section_names(t, "upright_section", len(levels), "storey", sections),
        subdivisions=_subdivisions(t),
        depth=depth, rows=rows, row_spacer=spacer,
    )
    t.finish(("bays", "levels", "beam_section", "upright_section", "subdivisions", "depth",
              "rows", "row_spacer"))
    return geom


def _subdivisions(t: Table) -> int:
    n = t.integer("subdivisions", DEFAULT_SUBDIVISIONS, minimum=1)
    if n > MAX_SUBDIVISIONS:
        raise t.error("subdivisions", n, f"an integer from 1 to {MAX_SUBDIVISIONS} (default "
                      f"{DEFAULT_SUBDIVISIONS}, which converges the first modes to about 1e-4)")
    return n


def _check_size(geom: Geometry, bracing: Any, loading: Any, n_explicit: int,
                source: str | None, spacers: Table | None = None) -> None:
    """Refuse a rack too large to build before it is meshed (or its pallets placed); name
    the row spacers (``spacers``: their table) when their nodes alone make it too large."""
    n_pallets = n_explicit
    if loading is not None:  # an upper bound: every slot of every loaded level
        n_pallets += (sum(1 for lv in loading.levels if loading.level_mass[lv - 1] > 0)
                      * geom.n_bays * loading.pallets_per_bay * geom.rows)

    def size_of(extra_heights: int) -> Any:
        return rack_size(geom.n_bays, geom.n_levels, geom.subdivisions, n_pallets,
                         three_d=geom.depth is not None, panel_points=extra_heights,
                         rows=geom.rows)

    panel = () if bracing is None else bracing.panel_points
    points = _extra_heights(geom, panel)
    size = size_of(points)
    if spacers is not None and size.dofs <= MAX_RACK_DOFS:
        heights = geom.row_spacer.heights  # type: ignore[union-attr]
        merged: list[float] = []  # spacers off the nodes add a node on every upright
        for y in sorted(panel + heights):
            if not merged or y - merged[-1] > NODE_MERGE:
                merged.append(y)
        full = size_of(_extra_heights(geom, tuple(merged)))
        if full.dofs > MAX_RACK_DOFS:
            key = "spacing" if spacers.has("spacing") else "heights"
            raise spacers.error(
                key, spacers.raw(key) if key == "spacing" else f"{len(heights)} heights",
                f"row spacers that leave the rack at most {MAX_RACK_DOFS:,} degrees of freedom",
                hint=f"A spacer off the upright nodes adds a node on every upright: with these "
                     f"{len(heights):,} spacers on each upright line the rack has about "
                     f"{full.dofs:,} DOFs ({size.dofs:,} without); put them at the beam levels "
                     "or the bracing panel points, or use fewer")
    check_rack_size(size, n_bays=geom.n_bays, n_levels=geom.n_levels,
                    default_subdivisions=DEFAULT_SUBDIVISIONS,
                    subdivisions=geom.subdivisions,
                    panel=None if bracing is None else f"{points} panel points",
                    source=source)


def _extra_heights(geom: Geometry, panel_points: tuple[float, ...]) -> int:
    """Panel points that are not already upright nodes (the 3D mesher merges them)."""
    if geom.n_levels * geom.subdivisions > 1_000_000:
        return len(panel_points)  # an upper bound, without building a million heights
    ys = (0.0, *geom.level_y)
    nodes = sorted(ys[s] + (ys[s + 1] - ys[s]) * i / geom.subdivisions
                   for s in range(geom.n_levels) for i in range(geom.subdivisions + 1))
    extra = 0
    for y in panel_points:
        i = bisect.bisect_left(nodes, y)
        near = [abs(nodes[j] - y) for j in (i - 1, i) if 0 <= j < len(nodes)]
        extra += not near or min(near) > 1e-6
    return extra


def _spring(t: Table, key: str) -> float:
    value = t.raw(key)
    allowed = 'a stiffness >= 0 [N·m/rad], "rigid" or "pinned"'
    if isinstance(value, str):
        word = value.strip().lower()
        if word == "rigid":
            return RIGID
        if word == "pinned":
            return PINNED
        raise t.error(key, value, allowed)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
            or value < 0:
        raise t.error(key, value, allowed)
    return float(value)


def _connections(t: Table, three_d: bool = False) -> Connections:
    c = Connections(beam_to_upright=_spring(t, "beam_to_upright"), base=_spring(t, "base"),
                    base_cross=_spring(t, "base_cross") if three_d and t.has("base_cross")
                    else None)
    t.finish(("beam_to_upright", "base") + (("base_cross",) if three_d else ()))
    return c


def _bracing(root: Table, geom: Geometry, sections: dict[str, Section]) -> Any:
    """``[bracing]``: required by a 3D rack, refused by a 2D one."""
    if geom.depth is None:
        if root.has("bracing"):
            raise root.error("bracing", root.raw("bracing"), "no [bracing] table in a 2D rack",
                             hint="Give [geometry] depth (the upright-frame depth, m) for a "
                                  "3D rack with braced upright frames")
        return None
    from seisrack.model.bracing import read_bracing

    if not root.has("bracing"):
        raise root.error("bracing", None, "a [bracing] table (a 3D rack needs braced upright "
                                          "frames)", hint="Add [bracing] with pattern, panel, "
                                                          "horizontal_section, diagonal_section")
    return read_bracing(root.table("bracing"), geom.level_y[-1], geom.n_bays, geom.n_levels,
                        sections)


def _footprint(t: Table, geom: Geometry) -> dict[str, float]:
    """Pallet ``depth`` and ``overhang`` [m] (3D racks), validated against the frame depth."""
    out: dict[str, float] = {}
    for key in _PALLET_3D_KEYS:
        if t.has(key):
            if geom.depth is None:
                raise t.error(key, t.raw(key), "no pallet depth or overhang in a 2D rack",
                              hint="Give [geometry] depth for a 3D rack")
            out[key] = t.number(key, nonnegative=key == "overhang", positive=key == "depth",
                                unit="m")
    depth, over = out.get("depth"), out.get("overhang")
    if depth is not None and over is not None and over >= depth:
        raise t.error("overhang", over, f"an overhang >= 0 and < the pallet depth {depth:g} m")
    if depth is not None and over is not None and geom.depth is not None:
        allowed = geom.depth + 2.0 * over
        if depth > allowed + _GEOM_TOL:
            raise t.error("depth", depth, f"a pallet depth <= the frame depth + 2 x overhang = "
                                          f"{geom.depth:g} + 2 x {over:g} = {allowed:g} m")
    return out


def _check_footprints(pallets: tuple[Pallet, ...], fields: list[dict[str, str]],
                      geom: Geometry, source: str | None) -> None:
    """Each 3D pallet rests on the front and the rear beam: its depth and overhang agree with
    the frame depth. ``fields[i]`` names where pallet i's depth and overhang were written
    (``pallets[3].depth`` or ``loading.depth``), so the error points at the line to change."""
    if geom.depth is None:
        return
    d = geom.depth
    for p, f in zip(pallets, fields, strict=True):
        if p.depth is None:
            continue
        if p.overhang is None:
            if p.depth <= d + _GEOM_TOL:
                raise InputError(f["depth"], p.depth, f"a pallet deeper than the frame "
                                 f"({d:g} m): it must rest on the front and the rear beam",
                                 source=source, hint="Or give its overhang beyond the beams")
            continue
        if p.overhang >= p.depth:
            raise InputError(f["overhang"], p.overhang,
                             f"an overhang >= 0 and < the pallet depth {p.depth:g} m",
                             source=source)
        if p.depth > d + 2.0 * p.overhang + _GEOM_TOL:
            raise InputError(f["depth"], p.depth, f"a pallet depth <= the frame depth + 2 x "
                             f"overhang = {d:g} + 2 x {p.overhang:g} = "
                             f"{d + 2.0 * p.overhang:g} m", source=source)
        if p.depth <= d + p.overhang + _GEOM_TOL:
            raise InputError(f["depth"], p.depth, f"a depth > frame depth + overhang = "
                             f"{d + p.overhang:g} m (the pallet must reach the rear beam)",
                             source=source)


def _period(t: Table, key: str, value: Any) -> float:
    return check_number(value, t.field(key), positive=True, unit="s", source=t.source)


def _ratio(t: Table, key: str, value: Any) -> float:
    r = check_number(value, t.field(key), nonnegative=True, source=t.source)
    if r >= 1.0:
        raise t.error(key, value, "a damping ratio in [0, 1) (0.02 means 2 %)")
    return r


def _damping(t: Table) -> Damping:
    kind = t.string("kind", "none")
    term = t.string("stiffness_term", "with_p_delta")
    if term not in STIFFNESS_TERMS:
        raise t.error("stiffness_term", term,
                      '"with_p_delta" (a1 times K_E + K_G, the default) or "elastic" (a1 times '
                      'the elastic stiffness K_E, as OpenSees\' rayleigh with betaKinit)')
    if kind == "none":
        t.finish(("kind", "stiffness_term"))
        return Damping(stiffness_term=term)
    if kind == "stiffness":
        ratio = _ratio(t, "ratio", t.raw("ratio"))
        period_raw = t.raw("period", "first")
        period: Any = "first" if period_raw == "first" else _period(t, "period", period_raw)
        t.finish(("kind", "ratio", "period", "stiffness_term"))
        return Damping(kind="stiffness", ratio=ratio, period=period, stiffness_term=term)
    if kind == "rayleigh":
        pairs_raw = t.array("pairs")
        pairs = []
        for i, pair in enumerate(pairs_raw):
            if not isinstance(pair, list) or len(pair) != 2:
                raise t.error(f"pairs[{i}]", pair, "a [period_s, ratio] pair")
            pairs.append((_period(t, f"pairs[{i}][0]", pair[0]),
                          _ratio(t, f"pairs[{i}][1]", pair[1])))
        if len(pairs) != 2:
            raise t.error("pairs", pairs_raw, "exactly two [period_s, ratio] pairs")
        if pairs[0][0] == pairs[1][0]:
            raise t.error("pairs", pairs_raw, "two pairs with different periods")
        t.finish(("kind", "pairs", "stiffness_term"))
        return Damping(kind="rayleigh", pairs=tuple(pairs), stiffness_term=term)
    raise t.error("kind", kind, '"stiffness", "rayleigh" or "none"')


def _second_order(t: Table) -> SecondOrder:
    p_delta = t.raw("p_delta", False)
    if not isinstance(p_delta, bool):
        raise t.error("p_delta", p_delta, "true or false")
    form = t.string("form", "consistent")
    if form not in ("consistent", "p_delta_only"):
        raise t.error("form", form, '"consistent" or "p_delta_only"')
    axial = t.string("axial", "gravity")
    if axial not in ("gravity", "current"):
        raise t.error("axial", axial, '"gravity" (the gravity axial forces, held constant) or '
                      '"current" (gravity plus their change during the motion)')
    if axial == "current" and not p_delta:
        raise t.error("axial", axial, '"gravity" while p_delta is false (the axial forces '
                      'act through the geometric stiffness: set p_delta = true)')
    t.finish(("p_delta", "form", "axial"))
    return SecondOrder(p_delta=p_delta, form=form, axial=axial)  # type: ignore[arg-type]


def _hysteresis(t: Table, connections: Connections) -> Hysteresis:
    from seisrack.model.hinge_law import parse_hinge_law

    laws = {}
    for key in ("beam_to_upright", "base"):
        if t.has(key):
            laws[key] = parse_hinge_law(t.table(key).data, t.field(key),
                                        getattr(connections, key), source=t.source)
    t.finish(("beam_to_upright", "base"))
    return Hysteresis(**laws)


def friction_rate(t: Table) -> float:
    """Optional ``friction_rate`` [s/m] (velocity-dependent friction; 0 = Coulomb)."""
    return t.number("friction_rate", 0.0, nonnegative=True, unit="s/m")


def _pallet(t: Table, geom: Geometry) -> Pallet:
    mass = t.number("mass", positive=True, unit="kg")
    bay = t.integer("bay")
    if not 1 <= bay <= geom.n_bays:
        raise t.error("bay", bay, f"an integer from 1 to {geom.n_bays} (the rack has "
                                  f"{geom.n_bays} bay(s))")
    level = t.integer("level")
    if not 1 <= level <= geom.n_levels:
        raise t.error("level", level, f"an integer from 1 to {geom.n_levels} (the rack has "
                                      f"{geom.n_levels} beam level(s))")
    row = t.integer("row", 1)
    if not 1 <= row <= geom.rows:
        raise t.error("row", row, f"an integer from 1 to {geom.rows} (the rack has "
                                  f"{geom.rows} row(s) of upright frames)",
                      hint=None if geom.rows > 1 else "A back-to-back rack has [geometry] "
                      "rows = 2 (3D racks)")
    mu_s, mu_d = check_friction(t.field("mu_static"), t.raw("mu_static"),
                                t.field("mu_dynamic"), t.raw("mu_dynamic"), source=t.source)
    width = t.number("width", DEFAULT_PALLET_WIDTH, positive=True, unit="m")
    span = geom.bays[bay - 1]
    position = t.number("position", unit="m")
    lo, hi = width / 2, span - width / 2
    if not (lo - _GEOM_TOL <= position <= hi + _GEOM_TOL):
        allowed = (f"a centre position in [{lo:g}, {hi:g}] m so that the pallet (width "
                   f"{width:g} m) lies within bay {bay} (span {span:g} m)")
        if hi < lo:
            allowed = f"a pallet no wider than its bay: width {width:g} m > span {span:g} m"
        raise t.error("position", position, allowed)
    limit_raw = t.raw("sliding_limit", None)
    limit = None if limit_raw is None else check_number(
        limit_raw, t.field("sliding_limit"), nonnegative=True, unit="m", source=t.source)
    rate = friction_rate(t)
    fp = _footprint(t, geom)
    t.finish(("mass", "bay", "level", "row", "position", "mu_static", "mu_dynamic", "width",
              "sliding_limit", "friction_rate") + _PALLET_3D_KEYS)
    return Pallet(mass=mass, bay=bay, level=level, position=position, mu_static=mu_s,
                  mu_dynamic=mu_d, width=width, sliding_limit=limit, friction_rate=rate,
                  depth=fp.get("depth"), overhang=fp.get("overhang"), row=row)


def _check_overlaps(pallets: tuple[Pallet, ...], labels: tuple[str, ...],
                    source: str | None) -> None:
    """Pallets on the same bay, level and row must not overlap (``labels[i]`` names pallet
    i)."""
    seen: dict[tuple[int, int, int], list[int]] = {}  # earlier pallets of each cell
    for i, a in enumerate(pallets):
        earlier = seen.setdefault((a.row, a.bay, a.level), [])
        for j in earlier:
            b = pallets[j]
            gap = abs(a.position - b.position) - (a.width + b.width) / 2
            if gap < -_GEOM_TOL:
                raise InputError(
                    f"{labels[i]}.position", a.position,
                    f"a position that does not overlap {labels[j]} (centre {b.position:g} m, "
                    f"width {b.width:g} m) on bay {a.bay}, level {a.level}"
                    + (f", row {a.row}" if a.row > 1 else ""), source=source)
        earlier.append(i)
