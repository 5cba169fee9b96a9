"""Racks described in a few lines: ``{count, pitch}`` geometry and the ``[loading]`` table.

Checked here:
- ``bays``/``levels`` given as ``{count, pitch}`` equal the array form exactly;
- the table generates ``pallets_per_bay`` pallets per bay and loaded level, at the documented
  positions (equal clearances ``(span - n·width)/(n + 1)``, or a centred group with ``gap``),
  with one mass or one mass per level, on the chosen ``levels``;
- ``occupancy`` loads exactly round-half-up(occupancy · n_slots) slots, reproducibly per ``seed``;
- explicit ``[[pallets]]`` blocks override the table cell by cell, and the documented order;
- every kind of bad input raises an InputError naming the field (one case also via the CLI);
- ``examples/warehouse_rack.toml`` loads to 400 pallets on 10 levels x 20 bays.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest

from rack_inputs import EXAMPLES, paper_dict, to_toml
from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.model import load_rack, rack_from_dict

WAREHOUSE = EXAMPLES / "warehouse_rack.toml"


def table_dict(**loading: Any) -> dict[str, Any]:
    """The paper rack (2 bays x 1.8 m) with 3 levels, its pallets replaced by a [loading] table.

    ``mass`` is 500 kg unless ``mass_per_level`` is given (``mass=None`` leaves it out).
    """
    d = paper_dict()
    d["geometry"]["levels"] = [2.0, 1.5, 1.5]
    d["pallets"] = []
    mass = {} if "mass_per_level" in loading else {"mass": 500.0}
    d["loading"] = {"pallets_per_bay": 2, **mass, "mu_static": 0.4, "mu_dynamic": 0.3,
                    **loading}
    if d["loading"].get("mass", 0.0) is None:
        del d["loading"]["mass"]
    return d


def cells(spec) -> list[tuple[int, int]]:
    return [(p.level, p.bay) for p in spec.pallets]


# --- geometry: count + pitch -------------------------------------------------------------------

def test_count_pitch_equals_list_form():
    d_list, d_count = paper_dict(), paper_dict()
    d_list["geometry"].update(bays=[2.7] * 4, levels=[1.5] * 3)
    d_count["geometry"].update(bays={"count": 4, "pitch": 2.7}, levels={"count": 3, "pitch": 1.5})
    a, b = rack_from_dict(d_list), rack_from_dict(d_count)
    assert a.geometry == b.geometry
    assert b.geometry.bays == (2.7, 2.7, 2.7, 2.7) and b.geometry.levels == (1.5, 1.5, 1.5)
    assert a.pallets == b.pallets


@pytest.mark.parametrize(("key", "table", "field"), [
    ("levels", {"count": 0, "pitch": 1.5}, "geometry.levels.count"),
    ("levels", {"count": 2.0, "pitch": 1.5}, "geometry.levels.count"),
    ("bays", {"count": 2, "pitch": 0.0}, "geometry.bays.pitch"),
    ("bays", {"count": 2, "pitch": -2.7}, "geometry.bays.pitch"),
    ("bays", {"pitch": 2.7}, "geometry.bays.count"),
    ("levels", {"count": 2, "pitch": 1.5, "height": 3.0}, "geometry.levels.height"),
    ("bays", [], "geometry.bays"),
])
def test_bad_count_pitch(key, table, field):
    d = paper_dict()
    d["geometry"][key] = table
    with pytest.raises(InputError) as info:
        rack_from_dict(d, source="rack.toml")
    assert info.value.field == field
    assert field in str(info.value) and "allowed" in str(info.value)


# --- the table ---------------------------------------------------------------------------------

def test_full_table_equal_clearances():
    spec = rack_from_dict(table_dict(width=0.5))
    assert len(spec.pallets) == 2 * 2 * 3  # per bay x bays x levels
    c = (1.8 - 2 * 0.5) / 3  # equal clearances to each other and to the uprights
    for p in spec.pallets:
        assert p.width == 0.5 and p.mass == 500.0
        assert (p.mu_static, p.mu_dynamic) == (0.4, 0.3)
        assert p.sliding_limit is None
    assert [p.position for p in spec.pallets[:2]] == pytest.approx([c + 0.25, 2 * c + 0.75])
    assert cells(spec) == [(lv, b) for lv in (1, 2, 3) for b in (1, 1, 2, 2)]


def test_default_width_is_eur_pallet():
    spec = rack_from_dict(table_dict(pallets_per_bay=1))
    assert {p.width for p in spec.pallets} == {0.8}
    assert [p.position for p in spec.pallets] == pytest.approx([0.9] * 6)


def test_three_per_bay():
    spec = rack_from_dict(table_dict(pallets_per_bay=3, width=0.5))
    c = (1.8 - 3 * 0.5) / 4
    assert [p.position for p in spec.pallets[:3]] == pytest.approx(
        [c + 0.25, 2 * c + 0.75, 3 * c + 1.25])


def test_four_eur_pallets_in_a_3_6_m_bay():
    d = table_dict(pallets_per_bay=4)
    d["geometry"]["bays"] = {"count": 2, "pitch": 3.6}
    spec = rack_from_dict(d)
    assert len(spec.pallets) == 4 * 2 * 3
    c = (3.6 - 4 * 0.8) / 5  # 80 mm clearances
    assert [p.position for p in spec.pallets[:4]] == pytest.approx(
        [c + 0.4, 2 * c + 1.2, 3 * c + 2.0, 4 * c + 2.8])


def test_gap_centres_the_group():
    spec = rack_from_dict(table_dict(width=0.6, gap=0.1))
    left, right = spec.pallets[0], spec.pallets[1]
    assert right.position - left.position == pytest.approx(0.6 + 0.1)
    assert (left.position + right.position) / 2 == pytest.approx(0.9)  # symmetric in the bay
    assert left.position - 0.3 == pytest.approx((1.8 - 1.3) / 2)


def test_unequal_spans_use_each_bay():
    d = table_dict(pallets_per_bay=1)
    d["geometry"]["bays"] = [1.8, 2.4]
    spec = rack_from_dict(d)
    assert [p.position for p in spec.pallets[:2]] == pytest.approx([0.9, 1.2])


def test_mass_per_level_and_levels():
    spec = rack_from_dict(table_dict(mass_per_level=[900.0, 600.0, 300.0]))
    assert [p.mass for p in spec.pallets] == [900.0] * 4 + [600.0] * 4 + [300.0] * 4
    spec = rack_from_dict(table_dict(mass_per_level=[900.0, 0.0, 300.0]))
    assert {p.level for p in spec.pallets} == {1, 3}  # a zero mass leaves the level empty
    spec = rack_from_dict(table_dict(levels=[3, 1]))
    assert [p.level for p in spec.pallets] == [1] * 4 + [3] * 4
    assert spec.pallet_mass_total == 8 * 500.0


def test_sliding_limit_passed_on():
    spec = rack_from_dict(table_dict(sliding_limit=0.05))
    assert {p.sliding_limit for p in spec.pallets} == {0.05}


@pytest.mark.parametrize(("occupancy", "expected"), [
    (0.0, 0), (0.25, 3), (0.5, 6), (0.7, 8), (0.625, 8), (1.0, 12),
])
def test_occupancy_exact_count(occupancy, expected):
    # 12 slots; 0.625 * 12 = 7.5 rounds half up to 8, 0.7 * 12 = 8.4 rounds to 8
    spec = rack_from_dict(table_dict(occupancy=occupancy, seed=7))
    assert len(spec.pallets) == expected


def test_occupancy_reproducible_and_seed_dependent():
    a = rack_from_dict(table_dict(occupancy=0.5, seed=1))
    b = rack_from_dict(table_dict(occupancy=0.5, seed=1))
    assert a.pallets == b.pallets
    layouts = {tuple((p.level, p.bay, round(p.position, 9)) for p in
                     rack_from_dict(table_dict(occupancy=0.5, seed=s)).pallets)
               for s in range(6)}
    assert len(layouts) > 1  # other seeds load other slots
    default = rack_from_dict(table_dict(occupancy=0.5))
    assert default.pallets == rack_from_dict(table_dict(occupancy=0.5, seed=0)).pallets
    # the loaded slots are a subset of the full table's slots, still in order
    full = [(p.level, p.bay, p.position) for p in rack_from_dict(table_dict()).pallets]
    chosen = [(p.level, p.bay, p.position) for p in a.pallets]
    assert chosen == [s for s in full if s in chosen]


def test_explicit_pallets_override_their_cell_and_order():
    d = table_dict()
    d["pallets"] = [
        {"mass": 1000.0, "bay": 2, "level": 2, "position": 0.9, "mu_static": 0.5,
         "mu_dynamic": 0.5},
        {"mass": 100.0, "bay": 1, "level": 3, "position": 1.3, "mu_static": 0.2,
         "mu_dynamic": 0.2},
        {"mass": 200.0, "bay": 1, "level": 3, "position": 0.45, "mu_static": 0.2,
         "mu_dynamic": 0.2},
    ]
    spec = rack_from_dict(d)
    assert len(spec.pallets) == 12 - 2 + 1 - 2 + 2
    assert cells(spec) == [(1, 1), (1, 1), (1, 2), (1, 2), (2, 1), (2, 1), (2, 2),
                           (3, 1), (3, 1), (3, 2), (3, 2)]
    assert spec.pallets[6].mass == 1000.0  # the only pallet of bay 2, level 2
    assert [p.mass for p in spec.pallets[7:9]] == [100.0, 200.0]  # explicit, input order
    assert {p.mass for p in spec.pallets[9:]} == {500.0}


def test_explicit_cells_are_not_table_slots():
    d = table_dict(occupancy=1 / 3, seed=3)
    d["pallets"] = [{"mass": 1000.0, "bay": 1, "level": 1, "position": 0.9,
                     "mu_static": 0.5, "mu_dynamic": 0.5}]
    spec = rack_from_dict(d)
    generated = [p for p in spec.pallets if p.mass == 500.0]
    assert len(generated) == round(10 / 3)  # 10 table slots remain
    assert all((p.level, p.bay) != (1, 1) for p in generated)


def test_without_table_input_order_is_kept():
    d = paper_dict()
    d["pallets"] = list(reversed(d["pallets"]))
    spec = rack_from_dict(d)
    assert [(p.bay, p.position) for p in spec.pallets] == [(2, 1.35), (2, 0.45), (1, 1.35),
                                                            (1, 0.45)]


def test_overlap_with_explicit_still_checked():
    d = table_dict()
    d["pallets"] = [
        {"mass": 1.0, "bay": 1, "level": 2, "position": 0.5, "mu_static": 0.2, "mu_dynamic": 0.2},
        {"mass": 1.0, "bay": 2, "level": 1, "position": 0.5, "mu_static": 0.2, "mu_dynamic": 0.2},
        {"mass": 1.0, "bay": 1, "level": 2, "position": 0.9, "mu_static": 0.2, "mu_dynamic": 0.2},
    ]
    with pytest.raises(InputError) as info:
        rack_from_dict(d)
    assert info.value.field == "pallets[2].position"  # named by its input index
    assert "pallets[0]" in str(info.value)


# --- bad input ---------------------------------------------------------------------------------

def _without(d: dict[str, Any], key: str) -> dict[str, Any]:
    d = copy.deepcopy(d)
    del d["loading"][key]
    return d


BAD_LOADING = [
    ("too-wide", table_dict(width=1.0), "loading.width", "1.8"),
    ("gap-too-wide", table_dict(width=0.8, gap=0.3), "loading.gap", "1.9"),
    ("three-eur-in-1.8", table_dict(pallets_per_bay=3), "loading.width", "2.4"),
    ("zero-width", table_dict(width=0.0), "loading.width", "> 0"),
    ("negative-gap", table_dict(gap=-0.1), "loading.gap", ">= 0"),
    ("occupancy-above-1", table_dict(occupancy=1.2), "loading.occupancy", "[0, 1]"),
    ("occupancy-negative", table_dict(occupancy=-0.1), "loading.occupancy", "[0, 1]"),
    ("mass-per-level-short", table_dict(mass_per_level=[500.0, 500.0]),
     "loading.mass_per_level", "3 masses"),
    ("mass-per-level-negative", table_dict(mass_per_level=[500.0, -1.0, 2.0]),
     "loading.mass_per_level[1]", ">= 0"),
    ("mass-and-mass-per-level", table_dict(mass=500.0, mass_per_level=[1.0, 1.0, 1.0]),
     "loading.mass_per_level", "not both"),
    ("no-mass", table_dict(mass=None), "loading.mass", "mass_per_level"),
    ("zero-mass", table_dict(mass=0.0), "loading.mass", "> 0"),
    ("ppb-zero", table_dict(pallets_per_bay=0), "loading.pallets_per_bay", "1 to 6"),
    ("ppb-seven", table_dict(pallets_per_bay=7, width=0.2), "loading.pallets_per_bay", "1 to 6"),
    ("four-eur-in-1.8", table_dict(pallets_per_bay=4), "loading.width", "3.2"),
    ("ppb-float", table_dict(pallets_per_bay=2.0), "loading.pallets_per_bay", "integer"),
    ("mu-dynamic-above-static", table_dict(mu_dynamic=0.5), "loading.mu_dynamic", "<= "),
    ("mu-missing", _without(table_dict(), "mu_static"), "loading.mu_static", "required"),
    ("seed-negative", table_dict(occupancy=0.5, seed=-1), "loading.seed", ">= 0"),
    ("seed-float", table_dict(occupancy=0.5, seed=1.5), "loading.seed", "integer"),
    ("level-out-of-range", table_dict(levels=[1, 4]), "loading.levels[1]", "1 to 3"),
    ("level-twice", table_dict(levels=[2, 2]), "loading.levels[1]", "once"),
    ("levels-empty", table_dict(levels=[]), "loading.levels", "at least 1"),
    ("unknown-key", table_dict(pallet_mass=800.0), "loading.pallet_mass", "known keys"),
    ("not-a-table", {**table_dict(), "loading": 3}, "loading", "TOML table"),
]


@pytest.mark.parametrize(("d", "field", "allowed"), [c[1:] for c in BAD_LOADING],
                         ids=[c[0] for c in BAD_LOADING])
def test_bad_loading_names_field(d, field, allowed):
    with pytest.raises(InputError) as info:
        rack_from_dict(d, source="rack.toml")
    err = info.value
    assert err.field == field
    msg = str(err)
    assert field in msg and allowed in msg and "rack.toml" in msg
    assert "\n" not in msg


def test_bad_loading_via_cli(tmp_path: Path, capsys):
    f = tmp_path / "rack.toml"
    f.write_text(to_toml(table_dict(occupancy=1.5)))
    assert main(["modal", str(f)]) == 2
    err = capsys.readouterr().err
    assert "loading.occupancy" in err and "1.5" in err and "[0, 1]" in err
    assert "Traceback" not in err and err.count("\n") == 1


# --- the warehouse example ---------------------------------------------------------------------

def test_warehouse_example_loads():
    spec = load_rack(WAREHOUSE)
    g = spec.geometry
    assert (g.n_levels, g.n_bays) == (10, 20)
    assert g.levels == (1.5,) * 10 and g.bays == (2.7,) * 20
    assert len(spec.pallets) == 400
    assert {(p.level, p.bay) for p in spec.pallets} == {(lv, b) for lv in range(1, 11)
                                                        for b in range(1, 21)}
    assert spec.pallet_mass_total == pytest.approx(400 * 800.0)
    assert {p.mu_static for p in spec.pallets} == {0.3}
    assert spec.damping.kind == "stiffness"
