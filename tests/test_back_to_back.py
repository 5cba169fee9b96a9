"""Back-to-back (double-entry) racks, issue 21 item 3: two rows of upright frames joined by row
spacers, pallets on each row, falls into either aisle or the flue.

References:
- Two rows with the spacers removed are two copies of the single row: every period of the
  single row appears twice (an exact property of a block-diagonal eigenproblem; measured
  3.5e-14 on ``examples/warehouse_rack_3d_b2b.toml`` and 2.6e-13 on the two-row paper rack here).
- OpenSeesPy, the rack exported by ``seisrack export opensees``: the first ten periods of
  ``examples/warehouse_rack_3d_b2b.toml`` equal seisrack's within 1e-8 (measured 7.7e-13).
  The peer built member by member from the geometry in ``tests/test_model_3d_opensees.py``
  (case ``two_rows``) checks the same frames without the export.
- Geometry by hand: frame positions z = 0, d, d + s, 2d + s, spacer bars of length s at the
  given heights on every upright line, pallets on the beams of their own row.
"""

from __future__ import annotations

import copy
import json
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.fe.modal import modal_analysis
from seisrack.fe.recovery import column_labels, design_operators
from seisrack.model import compile_rack, load_rack, rack_from_dict
from seisrack.model.pallet_layout import FLUE, FRONT_AISLE, REAR_AISLE
from seisrack.model.rack_mesh import SPACER, SPINE
from seisrack.model.rack_mesh3d import build_rack_mesh_3d

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER_3D = EXAMPLES / "paper_rack_3d.toml"
B2B = EXAMPLES / "warehouse_rack_3d_b2b.toml"
DEPTH, FLUE_LENGTH = 1.1, 0.3


def _two_rows(spacer: dict | None = None, **geometry) -> dict:
    """The 3D paper rack with a second row (the same four pallets on it) and spacers every
    0.5 m (0.5, 1.0, 1.5 and 2.0 m)."""
    d = tomllib.loads(PAPER_3D.read_text())
    d["sections"]["spacer"] = {"A": 304e-6}
    d["geometry"]["rows"] = 2
    d["geometry"]["row_spacer"] = spacer if spacer is not None else {
        "length": FLUE_LENGTH, "section": "spacer", "spacing": 0.5}
    d["geometry"].update(geometry)
    d["pallets"] = d["pallets"] + [dict(p, row=2) for p in d["pallets"]]
    return d


def _no_spacers(spec):
    sp = replace(spec.geometry.row_spacer, heights=())
    return replace(spec, geometry=replace(spec.geometry, row_spacer=sp))


# --- input ----------------------------------------------------------------------------------------

def test_spacer_heights_from_spacing_or_list():
    spec = rack_from_dict(_two_rows())
    assert spec.geometry.rows == 2
    assert spec.geometry.row_spacer.heights == (0.5, 1.0, 1.5, 2.0)
    assert spec.geometry.frame_z == (0.0, DEPTH, DEPTH + FLUE_LENGTH, 2 * DEPTH + FLUE_LENGTH)
    # a spacing that does not divide the height: the last spacer at the top
    spec = rack_from_dict(_two_rows({"length": 0.3, "section": "spacer", "spacing": 0.8}))
    assert spec.geometry.row_spacer.heights == pytest.approx((0.8, 1.6, 2.0))
    spec = rack_from_dict(_two_rows({"length": 0.3, "section": "spacer",
                                     "heights": [0.7, 1.9]}))
    assert spec.geometry.row_spacer.heights == (0.7, 1.9)


def test_loading_fills_both_rows(tmp_path):
    one = load_rack(EXAMPLES / "warehouse_rack_3d.toml")
    two = load_rack(B2B)
    assert len(two.pallets) == 2 * len(one.pallets) == 300
    n = len(one.pallets)
    assert [p.row for p in two.pallets] == [1] * n + [2] * n  # row 1 first, then row 2
    for a, b in zip(one.pallets, two.pallets[n:], strict=True):
        assert (a.level, a.bay, a.position) == (b.level, b.bay, b.position)
    # an explicit pallet replaces the table's slots of its cell in its row only
    text = B2B.read_text() + ("\n[[pallets]]\nmass = 900.0\nbay = 1\nlevel = 1\nrow = 2\n"
                              "position = 1.35\nmu_static = 0.3\nmu_dynamic = 0.3\n")
    f = tmp_path / "b2b.toml"
    f.write_text(text)
    spec = load_rack(f)
    row2_cell = [p for p in spec.pallets if (p.row, p.bay, p.level) == (2, 1, 1)]
    row1_cell = [p for p in spec.pallets if (p.row, p.bay, p.level) == (1, 1, 1)]
    assert [p.mass for p in row2_cell] == [900.0] and len(row1_cell) == 3
    assert len(spec.pallets) == 300 - 3 + 1


def test_pallets_overlap_only_within_their_row():
    d = _two_rows()
    rack_from_dict(d)  # the same positions in both rows: no overlap
    d["pallets"].append(dict(d["pallets"][-1], position=0.5))
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "pallets[8].position" and "row 2" in str(err.value)


# --- mesh and compiled model ----------------------------------------------------------------------

def test_mesh_of_two_rows():
    spec = rack_from_dict(_two_rows(), source="two_rows")
    rm = build_rack_mesh_3d(spec)
    nodes = rm.mesh.nodes
    n_line = 3
    assert rm.n_side == 4
    np.testing.assert_array_equal(rm.column_line, np.repeat(np.arange(n_line), 4))
    np.testing.assert_array_equal(rm.column_side, np.tile(np.arange(4), n_line))
    np.testing.assert_allclose(nodes[rm.base_nodes, 2],
                               np.tile(spec.geometry.frame_z, n_line))
    # spacers: every upright line, every height, from side 1 to side 2, length s
    sp = np.flatnonzero(rm.truss_kind == SPACER)
    assert sp.size == n_line * 4
    a, b = nodes[rm.mesh.trusses[sp, 0]], nodes[rm.mesh.trusses[sp, 1]]
    np.testing.assert_allclose(a[:, 2], DEPTH)
    np.testing.assert_allclose(b[:, 2], DEPTH + FLUE_LENGTH)
    np.testing.assert_allclose(a[:, [0, 1]], b[:, [0, 1]])
    assert sorted(set(np.round(a[:, 1], 9))) == [0.5, 1.0, 1.5, 2.0]
    np.testing.assert_allclose(rm.mesh.truss_A[sp], 304e-6)
    # the bracing of both rows: the same number of bars in each upright frame
    z_mid = 0.5 * (nodes[rm.mesh.trusses[:, 0], 2] + nodes[rm.mesh.trusses[:, 1], 2])
    braces = rm.truss_kind == 2
    assert np.sum(braces & (z_mid < DEPTH)) == np.sum(braces & (z_mid > DEPTH + FLUE_LENGTH))
    # beams on all four sides
    for side, z in enumerate(spec.geometry.frame_z):
        np.testing.assert_allclose(nodes[rm.beam_nodes[(0, 0, side)], 2], z)


def test_spine_in_each_rows_back_plane():
    d = _two_rows()
    d["bracing"].update(spine=True, spine_section="brace", spine_bays=[1])
    rm = build_rack_mesh_3d(rack_from_dict(d))
    sp = np.flatnonzero(rm.truss_kind == SPINE)
    z = rm.mesh.nodes[rm.mesh.trusses[sp], 2]
    np.testing.assert_allclose(z[:, 0], z[:, 1])  # in a plane of uprights
    np.testing.assert_allclose(sorted(set(np.round(z[:, 0], 9))),
                               [DEPTH, DEPTH + FLUE_LENGTH])  # the planes on the flue


def test_pallets_rest_on_the_beams_of_their_row():
    model = compile_rack(rack_from_dict(_two_rows()))
    z = model.nodes[model.pallet_node, 2]  # (m, 2)
    row = model.pallet_row
    assert model.n_rows == 2 and model.pallet_node.shape == (8, 2)
    np.testing.assert_allclose(z[row == 0], [[0.0, DEPTH]] * 4)
    np.testing.assert_allclose(z[row == 1], [[DEPTH + FLUE_LENGTH, 2 * DEPTH + FLUE_LENGTH]] * 4)
    assert model.pallet_labels()[0] == "R1-L1-B1-S1" and model.pallet_labels()[4] == \
        "R2-L1-B1-S1"
    np.testing.assert_allclose(model.frame_z, [0.0, DEPTH, DEPTH + FLUE_LENGTH,
                                               2 * DEPTH + FLUE_LENGTH])
    # the vertical mass on the supports of the pallet's row: 200 kg on each
    M = model.M_sparse.diagonal()
    base = compile_rack(_no_pallets(rack_from_dict(_two_rows()))).M_sparse.diagonal()
    np.testing.assert_allclose((M - base)[model.pallet_vdof.ravel()], 200.0)
    # names of the upright columns and beam ends carry the row
    labels = column_labels(model)
    assert labels[:4] == ("U1-R1-front", "U1-R1-rear", "U1-R2-front", "U1-R2-rear")
    assert "L1-B1-R2-rear-left" in design_operators(model).beam_labels


def _no_pallets(spec):
    return replace(spec, pallets=())


def test_fall_sides_front_aisle_flue_rear_aisle():
    lay = compile_rack(rack_from_dict(_two_rows())).layout
    assert lay.n_rows == 2
    sides = [(lay.fall_side(p, -1), lay.fall_side(p, 1)) for p in range(8)]
    assert sides[:4] == [(FRONT_AISLE, FLUE)] * 4
    assert sides[4:] == [(FLUE, REAR_AISLE)] * 4
    one = compile_rack(load_rack(PAPER_3D)).layout
    assert (one.fall_side(0, -1), one.fall_side(0, 1)) == (FRONT_AISLE, REAR_AISLE)


def test_falls_into_the_aisles_and_the_flue():
    """A strong cross-aisle shaking drops pallets of both rows; each fall is named by where it
    goes, and its sign of sliding matches (row 1 towards −z falls into the front aisle)."""
    from seisrack.analysis import run_rack
    from seisrack.motion.components import combine
    from seisrack.motion.records import load_builtin_record
    from seisrack.motion.scaling import scale_by

    model = compile_rack(rack_from_dict(_two_rows()))
    rec = scale_by(load_builtin_record("elcentro_1940_ns"), 3.0)
    resp = run_rack(model, combine(rec, rec, angle_deg=60.0))
    assert resp.falls
    seen = set()
    for f in resp.falls:
        row = int(model.pallet_row[f.pallet])
        k = np.searchsorted(resp.t, f.time_s)
        sign = np.sign(resp.pallet_sliding[k, f.pallet, 1])
        assert f.side == model.layout.fall_side(f.pallet, int(sign))
        assert f.into_aisle == (f.side != FLUE)
        seen.add((row, f.side))
    assert {s for _, s in seen} >= {FLUE} and len({r for r, _ in seen}) == 2, seen
    assert resp.pallet_labels() == model.pallet_labels()  # R1-…, R2-…
    s = resp.summary()
    assert s["pallets_falling_into_aisle"] == sum(f.side != FLUE for f in resp.falls)
    assert {p["row"] for p in s["pallets"]} == {1, 2}


# --- dynamics ----------------------------------------------------------------------------------

def test_without_spacers_two_rows_are_two_single_rows():
    single = modal_analysis(compile_rack(load_rack(PAPER_3D)), 10).periods
    two = modal_analysis(compile_rack(_no_spacers(rack_from_dict(_two_rows()))), 20).periods
    np.testing.assert_allclose(two[0::2], single, rtol=1e-10)
    np.testing.assert_allclose(two[1::2], single, rtol=1e-10)


def test_spacers_couple_the_rows():
    """With spacers the rows are one structure: the pair of cross-aisle modes splits (in phase,
    out of phase through the spacers), unlike two free rows."""
    with_sp = modal_analysis(compile_rack(rack_from_dict(_two_rows())), 12)
    free = modal_analysis(compile_rack(_no_spacers(rack_from_dict(_two_rows()))), 12)
    cross = [T for T, d in zip(with_sp.periods, with_sp.direction, strict=True)
             if d == "cross-aisle"]
    cross_free = [T for T, d in zip(free.periods, free.direction, strict=True)
                  if d == "cross-aisle"]
    assert cross and cross_free and abs(cross[0] / cross_free[0] - 1) > 1e-4


def test_b2b_example_periods_against_opensees():
    pytest.importorskip("openseespy.opensees")
    from seisrack.export import opensees_script

    model = compile_rack(load_rack(B2B))
    ns: dict = {"__name__": "b2b_ops"}
    exec(compile(opensees_script(model, pallets="rigid"), "b2b_ops.py", "exec"), ns)
    T_ops = np.array(ns["modal"](10, "rigid"))
    T = modal_analysis(model, 10).periods
    assert np.abs(T_ops / T - 1).max() < 1e-8  # measured 7.7e-13


# --- bad input ----------------------------------------------------------------------------------

def _with(d: dict, path: str, value) -> dict:
    d = copy.deepcopy(d)
    *head, last = path.split(".")
    t = d
    for k in head:
        t = t[k]
    if value is None:
        del t[last]
    else:
        t[last] = value
    return d


@pytest.mark.parametrize(("path", "value", "field"), [
    ("geometry.rows", 3, "geometry.rows"),
    ("geometry.rows", 0, "geometry.rows"),
    ("geometry.rows", "2", "geometry.rows"),
    ("geometry.row_spacer", None, "geometry.row_spacer"),
    ("geometry.row_spacer.length", 0.0, "geometry.row_spacer.length"),
    ("geometry.row_spacer.section", "tube", "geometry.row_spacer.section"),
    ("geometry.row_spacer.spacing", 2.5, "geometry.row_spacer.spacing"),
    ("geometry.row_spacer.spacing", None, "geometry.row_spacer.spacing"),
    ("geometry.row_spacer.heights", [1.0], "geometry.row_spacer.spacing"),
    ("geometry.row_spacer.colour", "red", "geometry.row_spacer.colour"),
])
def test_bad_row_keys(path, value, field):
    with pytest.raises(InputError) as err:
        rack_from_dict(_with(_two_rows(), path, value))
    assert err.value.field == field


@pytest.mark.parametrize("heights", [[1.0, 0.5], [0.5, 2.5], [0.0, 1.0], [1.0, 1.0]])
def test_spacer_heights_that_do_not_fit(heights):
    d = _two_rows({"length": 0.3, "section": "spacer", "heights": heights})
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field.startswith("geometry.row_spacer.heights")


def test_flue_too_narrow_for_the_overhangs():
    """Row 1's rear overhang (0.05 m) and row 2's front overhang (0.05 m) do not fit a 0.08 m
    flue: the pallets would overlap there."""
    spec = rack_from_dict(_two_rows({"length": 0.08, "section": "spacer", "spacing": 0.5}))
    with pytest.raises(InputError) as err:
        compile_rack(spec)
    assert err.value.field == "geometry.row_spacer.length" and "0.1 m" in str(err.value)


def test_rows_on_a_2d_rack_and_spacer_on_one_row():
    d = tomllib.loads((EXAMPLES / "paper_rack.toml").read_text())
    for key, value in (("rows", 2), ("rows", 1), ("row_spacer", {"length": 0.3})):
        with pytest.raises(InputError) as err:
            rack_from_dict(_with(d, f"geometry.{key}", value))
        assert err.value.field == f"geometry.{key}" and "2D" in str(err.value)
    d3 = tomllib.loads(PAPER_3D.read_text())
    d3["sections"]["spacer"] = {"A": 304e-6}
    d3["geometry"]["row_spacer"] = {"length": 0.3, "section": "spacer", "spacing": 0.5}
    with pytest.raises(InputError) as err:
        rack_from_dict(d3)
    assert err.value.field == "geometry.row_spacer" and "rows = 2" in str(err.value)


def test_pallet_row_beyond_the_racks_rows():
    d = tomllib.loads(PAPER_3D.read_text())
    d["pallets"][1]["row"] = 2
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "pallets[1].row" and "1 row(s)" in str(err.value)
    d = _two_rows()
    d["pallets"][5]["row"] = 3
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "pallets[5].row"


def test_cli_bad_rows_is_one_json_error(tmp_path, capsys):
    f = tmp_path / "rack.toml"
    f.write_text(B2B.read_text().replace("rows = 2", "rows = 4"))
    assert main(["modal", str(f), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "geometry.rows" and err["value"] == 4
    assert main(["modal", str(f)]) == 2
    text = capsys.readouterr().err
    assert "geometry.rows" in text and "Traceback" not in text


# --- spacer bounds (a 1 nm spacer, 1 mm spacing or spacers 0.1 mm apart once gave errors
# naming 'C' or 'bracing.pattern' after a long build; bounds in docs/user/rack_toml.md) ------------

def _small_b2b(**spacer) -> dict:
    """``examples/warehouse_rack_3d_b2b.toml`` cut to 2 bays x 2 levels (uprights 3 m, panel
    points and storey divisions every 0.75 m), with ``spacer`` replacing spacer keys (a value
    None removes the key)."""
    d = tomllib.loads(B2B.read_text())
    d["geometry"].update(bays={"count": 2, "pitch": 2.7}, levels={"count": 2, "pitch": 1.5})
    sp = d["geometry"]["row_spacer"]
    for key, value in spacer.items():
        if value is None:
            sp.pop(key, None)
        else:
            sp[key] = value
    return d


@pytest.mark.parametrize(("spacer", "field", "words"), [
    ({"spacing": 0.001}, "geometry.row_spacer.spacing", ">= 0.05 m"),  # 3,000 per line
    ({"length": 1e-9}, "geometry.row_spacer.length", ">= 0.05 m"),
    ({"spacing": None, "heights": [1.5, 1.5001]}, "geometry.row_spacer.heights[1]",
     "at least 0.05 m above the spacer before it"),
])
def test_reported_spacers_refused_naming_the_key(spacer, field, words):
    with pytest.raises(InputError) as err:
        rack_from_dict(_small_b2b(**spacer))
    assert err.value.field == field and words in str(err.value)
    assert "bracing" not in str(err.value) and "'C'" not in str(err.value)


def test_reported_spacing_refused_at_once_by_the_cli(tmp_path, capsys):
    """The reported command: the error is one JSON paragraph, before any building."""
    f = tmp_path / "rack.toml"
    text = B2B.read_text().replace("count = 10, pitch = 2.7", "count = 2, pitch = 2.7")
    f.write_text(text.replace("count = 5, pitch = 1.5", "count = 2, pitch = 1.5")
                 .replace("spacing = 1.5      #", "spacing = 0.001    #"))
    rec = str(EXAMPLES / "record.csv")
    assert main(["run", str(f), "--motion", rec, "--motion-cross", rec, "--json",
                 "--out", str(tmp_path / "out")]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "geometry.row_spacer.spacing" and err["value"] == 0.001
    assert "3,000 spacers" in err["message"]


@pytest.mark.parametrize(("spacer", "field", "words"), [
    ({"length": 0.0499}, "geometry.row_spacer.length", ">= 0.05 m"),
    ({"spacing": 0.0499}, "geometry.row_spacer.spacing", ">= 0.05 m"),
    # 0.7501 m: 0.1 mm from the panel point at 0.75 m
    ({"spacing": 0.7501}, "geometry.row_spacer.spacing", "bracing member's end (0.75 m)"),
    # 2.98 m and the spacer added at the top, 3 m
    ({"spacing": 1.49}, "geometry.row_spacer.spacing", "at the top of the uprights (3 m)"),
    ({"spacing": None, "heights": [1.5, 1.5499]}, "geometry.row_spacer.heights[1]",
     "above the spacer before it"),
    ({"spacing": None, "heights": [0.0499, 1.5]}, "geometry.row_spacer.heights[0]",
     "above the base"),
    ({"spacing": None, "heights": [1e-7, 1.5]}, "geometry.row_spacer.heights[0]",
     "above the base"),
    ({"spacing": None, "heights": [0.7999, 1.5]}, "geometry.row_spacer.heights[0]",
     "bracing member's end (0.75 m)"),
    ({"spacing": None, "heights": [1.5, 2.9501]}, "geometry.row_spacer.heights[1]",
     "beam level 2 (3 m)"),
    ({"spacing": None, "heights": list(np.arange(1, 1002) * 0.002)},
     "geometry.row_spacer.heights", "at most 1,000"),
])
def test_spacers_too_short_or_too_close(spacer, field, words):
    with pytest.raises(InputError) as err:
        rack_from_dict(_small_b2b(**spacer))
    assert err.value.field == field and words in str(err.value), str(err.value)


def test_spacer_near_a_storey_division():
    """Divisions are mesh nodes: 0.05 m from them, or a quarter of a division if less."""
    d = _small_b2b(spacing=None, heights=[1.2, 3.0])  # 1.2 m: 0.075 from the division at 1.125
    d["geometry"]["subdivisions"] = 8  # divisions 0.1875 m apart; the panel points stay 0.75 m
    rack_from_dict(d)
    d["geometry"]["row_spacer"]["heights"] = [1.16, 3.0]  # 0.035 m from 1.125
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "geometry.row_spacer.heights[0]"
    assert "geometry.subdivisions = 8 (1.125 m)" in str(err.value)
    d["geometry"]["subdivisions"] = 100  # 0.015 m divisions: 3.75 mm suffice off the joints
    d["geometry"]["row_spacer"]["heights"] = [1.104, 3.0]  # 1.104: 0.006 m from 1.11
    rack_from_dict(d)
    d["geometry"]["row_spacer"]["heights"] = [1.1065, 3.0]  # 0.0035 m from 1.11
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert "at least 0.00375 m" in str(err.value)


@pytest.mark.parametrize("spacer", [
    {"length": 0.05},
    {"spacing": 0.05},  # 60 spacers on each line, on the 0.75 m nodes or 0.05 m from them
    {"spacing": None, "heights": [1.5, 1.55]},
    {"spacing": None, "heights": [0.05, 0.8, 1.45, 3.0]},  # 0.05 m from the base and nodes
])
def test_spacers_at_the_bounds_accepted_and_stable(spacer):
    """At the bounds the rack builds and is stable, its first periods near those of the cut
    rack with its spacers 0.3 m long at the beam levels (0.568 s; measured within 0.5 %)."""
    d = _small_b2b(**spacer)
    if "length" in spacer:  # a 0.05 m flue: overhangs of 0.02 m into it (0.04 m in all)
        d["loading"]["overhang"], d["loading"]["depth"] = 0.02, 1.14
    T = modal_analysis(compile_rack(rack_from_dict(d)), 3).periods
    T_ref = modal_analysis(compile_rack(rack_from_dict(_small_b2b())), 3).periods
    np.testing.assert_allclose(T, T_ref, rtol=0.01)


def test_spacers_that_alone_make_the_rack_too_large():
    """Spacers off the upright nodes add a node on every upright: counted before building."""
    d = tomllib.loads(B2B.read_text())
    d["geometry"].update(bays={"count": 30, "pitch": 2.7}, levels={"count": 27, "pitch": 1.5})
    rack_from_dict(d)  # spacing 1.5: on the beam levels
    d["geometry"]["row_spacer"]["spacing"] = 0.05  # 810 spacers per line
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "geometry.row_spacer.spacing"
    assert "300,000 degrees of freedom" in str(err.value)
