"""The ``[loading]`` table of a rack TOML: pallets generated per bay and beam level.

A warehouse rack of 10 levels x 20 bays holds hundreds of pallets; the table describes them in a
few lines instead of one ``[[pallets]]`` block each (keys, units and defaults in
``docs/user/rack_toml.md``). :func:`read_loading` validates the table once, at the boundary, and
:func:`place_pallets` merges the generated pallets with the explicit ``[[pallets]]`` blocks:

- each bay of each loaded beam level offers ``pallets_per_bay`` *slots*, centred symmetrically in
  the bay: with a ``gap`` the pallets form a group with that clear distance between neighbours;
  without one the clearances to each other and to the uprights are all equal,
  ``(span - n·width) / (n + 1)``;
- a (bay, level) cell that has explicit pallets keeps only those: the table fills the other cells;
- with ``occupancy < 1`` exactly ``round(occupancy · n_slots)`` (half up) of the table's slots are
  loaded, chosen with ``numpy.random.default_rng(seed)``, so the same file gives the same rack;
- order: by level (bottom to top), then bay (left to right); within a cell the explicit pallets in
  input order, else the table's slots left to right;
- a back-to-back rack (``[geometry] rows = 2``) has the cells of both rows: the table fills row 1
  then row 2 (row outermost in the order above), and an explicit pallet's ``row`` names its cell.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from seisrack.model._reader import Table, check_friction, check_number
from seisrack.model.spec import DEFAULT_PALLET_WIDTH, Geometry, Pallet

#: Most pallets the table places side by side in one bay: three EUR pallets fill a 2.7 m bay,
#: four a 3.6 m one and five a 4.5 m long-span bay; six leaves room for narrow pallets. Whether
#: they fit is checked against each bay's span.
MAX_PALLETS_PER_BAY = 6
#: Keys of the ``[loading]`` table.
LOADING_KEYS = ("pallets_per_bay", "width", "gap", "mass", "mass_per_level", "mu_static",
                "mu_dynamic", "occupancy", "seed", "levels", "sliding_limit", "friction_rate")
_GEOM_TOL = 1e-9  # m, slack for floating-point geometry comparisons


@dataclass(frozen=True)
class Loading:
    """A validated ``[loading]`` table (SI units).

    ``level_mass: (n_levels,) [kg]`` is the mass of each generated pallet on each beam level
    (0 leaves the level empty); ``levels`` are the 1-based beam levels the table loads; ``gap``
    [m] is ``None`` for equal clearances.
    """

    pallets_per_bay: int
    width: float
    gap: float | None
    level_mass: tuple[float, ...]
    mu_static: float
    mu_dynamic: float
    occupancy: float = 1.0
    seed: int = 0
    levels: tuple[int, ...] = ()
    sliding_limit: float | None = None
    friction_rate: float = 0.0


def read_loading(t: Table, geom: Geometry) -> Loading:
    """Validate a ``[loading]`` table against the rack geometry."""
    n = t.integer("pallets_per_bay")
    if not 1 <= n <= MAX_PALLETS_PER_BAY:
        raise t.error("pallets_per_bay", n, f"an integer from 1 to {MAX_PALLETS_PER_BAY}")
    width = t.number("width", DEFAULT_PALLET_WIDTH, positive=True, unit="m")
    gap_raw = t.raw("gap", None)
    gap = None if gap_raw is None else check_number(
        gap_raw, t.field("gap"), nonnegative=True, unit="m", source=t.source)
    _check_fits(t, geom, n, width, gap)
    level_mass = _level_mass(t, geom)
    mu_s, mu_d = check_friction(t.field("mu_static"), t.raw("mu_static"),
                                t.field("mu_dynamic"), t.raw("mu_dynamic"), source=t.source)
    occupancy = t.number("occupancy", 1.0)
    if not 0.0 <= occupancy <= 1.0:
        raise t.error("occupancy", t.raw("occupancy"),
                      "a fraction of the pallet slots in [0, 1] (1 = fully loaded)")
    seed = t.integer("seed", 0, minimum=0)
    levels = _levels(t, geom)
    limit_raw = t.raw("sliding_limit", None)
    limit = None if limit_raw is None else check_number(
        limit_raw, t.field("sliding_limit"), nonnegative=True, unit="m", source=t.source)
    rate = t.number("friction_rate", 0.0, nonnegative=True, unit="s/m")
    t.finish(LOADING_KEYS)
    return Loading(pallets_per_bay=n, width=width, gap=gap, level_mass=level_mass,
                   mu_static=mu_s, mu_dynamic=mu_d, occupancy=occupancy, seed=seed,
                   levels=levels, sliding_limit=limit, friction_rate=rate)


def slot_positions(loading: Loading, span: float) -> tuple[float, ...]:
    """Centre of each slot of a bay of ``span`` [m], from its left upright [m], left to right."""
    n, w = loading.pallets_per_bay, loading.width
    if loading.gap is None:
        c = (span - n * w) / (n + 1)  # equal clearances to each other and to the uprights
        return tuple(c * (i + 1) + w * (i + 0.5) for i in range(n))
    group = n * w + (n - 1) * loading.gap
    start = (span - group) / 2  # the group is centred in the bay
    return tuple(start + w / 2 + i * (w + loading.gap) for i in range(n))


def place_pallets(loading: Loading | None, geom: Geometry, explicit: Sequence[Pallet]
                  ) -> tuple[tuple[Pallet, ...], tuple[str, ...]]:
    """Merge the table's pallets with the explicit ones; return them and a label for each.

    Without a table the explicit pallets are returned in input order. A label names where a
    pallet came from (``pallets[3]`` or ``loading``), for error messages.
    """
    labels = [f"pallets[{i}]" for i in range(len(explicit))]
    if loading is None:
        return tuple(explicit), tuple(labels)
    by_cell: dict[tuple[int, int, int], list[int]] = {}  # (row, level, bay) -> explicit
    for i, p in enumerate(explicit):
        by_cell.setdefault((p.row, p.level, p.bay), []).append(i)
    cells = [(row, level, bay) for row in range(1, geom.rows + 1)
             for level in range(1, geom.n_levels + 1) for bay in range(1, geom.n_bays + 1)]
    slots = [(*cell, s) for cell in cells
             if cell[1] in loading.levels and loading.level_mass[cell[1] - 1] > 0
             and cell not in by_cell for s in range(loading.pallets_per_bay)]
    loaded = _choose(len(slots), loading.occupancy, loading.seed)
    generated: dict[tuple[int, int, int], list[Pallet]] = {}
    for k in loaded:
        row, level, bay, s = slots[k]
        position = slot_positions(loading, geom.bays[bay - 1])[s]
        generated.setdefault((row, level, bay), []).append(Pallet(
            mass=loading.level_mass[level - 1], bay=bay, level=level, position=position,
            mu_static=loading.mu_static, mu_dynamic=loading.mu_dynamic, width=loading.width,
            sliding_limit=loading.sliding_limit, friction_rate=loading.friction_rate,
            row=row))
    pallets: list[Pallet] = []
    out_labels: list[str] = []
    for cell in cells:
        if cell in by_cell:
            for i in by_cell[cell]:
                pallets.append(explicit[i])
                out_labels.append(labels[i])
        else:
            got = generated.get(cell, [])
            pallets.extend(got)
            out_labels.extend(["loading"] * len(got))
    return tuple(pallets), tuple(out_labels)


def _choose(n_slots: int, occupancy: float, seed: int) -> list[int]:
    """Indices (ascending) of the loaded slots: exactly round-half-up(occupancy · n_slots)."""
    k = min(n_slots, math.floor(occupancy * n_slots + 0.5))
    if k == n_slots:
        return list(range(n_slots))
    rng = np.random.default_rng(seed)
    return sorted(int(i) for i in rng.choice(n_slots, size=k, replace=False))


def _check_fits(t: Table, geom: Geometry, n: int, width: float, gap: float | None) -> None:
    span = min(geom.bays)
    bay = geom.bays.index(span) + 1
    need = n * width + (n - 1) * (gap or 0.0)
    if need <= span + _GEOM_TOL:
        return
    where = f"bay {bay} (span {span:g} m)"
    if n * width > span + _GEOM_TOL or gap is None:
        raise t.error("width", width, f"pallets that fit side by side in every bay: "
                      f"{n} x {width:g} m = {n * width:g} m > {where}",
                      hint="Reduce loading.width or loading.pallets_per_bay")
    raise t.error("gap", gap, f"a gap that lets the pallets fit in every bay: {n} x {width:g} m "
                  f"+ {n - 1} x {gap:g} m = {need:g} m > {where}",
                  hint="Reduce loading.gap or omit it for equal clearances")


def _level_mass(t: Table, geom: Geometry) -> tuple[float, ...]:
    has_one, has_list = t.has("mass"), t.has("mass_per_level")
    if has_one and has_list:
        raise t.error("mass_per_level", t.raw("mass_per_level"),
                      "either loading.mass (one mass for every pallet) or loading.mass_per_level "
                      "(one mass per beam level), not both")
    if not has_list:
        if not has_one:
            raise t.error("mass", None, "a pallet mass > 0 [kg] (or mass_per_level, one mass "
                          "per beam level)", hint="Add 'mass' to [loading]")
        return (t.number("mass", positive=True, unit="kg"),) * geom.n_levels
    values = t.array("mass_per_level")
    if len(values) != geom.n_levels:
        raise t.error("mass_per_level", values,
                      f"an array of {geom.n_levels} masses [kg], one per beam level bottom to "
                      f"top (the rack has {geom.n_levels} beam level(s); got {len(values)})")
    return tuple(check_number(v, f"{t.field('mass_per_level')}[{i}]", nonnegative=True,
                              unit="kg (0 leaves the level empty)", source=t.source)
                 for i, v in enumerate(values))


def _levels(t: Table, geom: Geometry) -> tuple[int, ...]:
    if not t.has("levels"):
        return tuple(range(1, geom.n_levels + 1))
    values = t.array("levels", min_len=1)
    seen: set[int] = set()
    for i, v in enumerate(values):
        allowed = (f"a beam level from 1 to {geom.n_levels} (1-based, bottom to top), each "
                   "listed once")
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= geom.n_levels \
                or v in seen:
            raise t.error(f"levels[{i}]", v, allowed)
        seen.add(v)
    return tuple(sorted(seen))
