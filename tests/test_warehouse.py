"""The warehouse file (seisrack.studies.warehouse), issue 24 item 4: loader and validator.

Checked by hand: plan footprints of rotated rows (corners from the orientation, origin,
spacing, the rack's length = sum of its bays and its depth), the overlap test (separating axes)
on touching and overlapping rows, and every bad input naming its field.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.studies.warehouse import DEFAULT_DEPTH_2D, load_warehouse, warehouse_from_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_example_warehouse() -> None:
    w = load_warehouse(EXAMPLES / "site_warehouse.toml")
    assert [r.name for r in w.rows] == ["A", "B"]
    a, b = w.rows
    assert (a.count, a.three_d, a.depth) == (4, True, pytest.approx(1.1))
    assert a.length == pytest.approx(10 * 2.7)  # warehouse_rack_3d.toml: 10 bays of 2.7 m
    assert (b.count, b.three_d, b.depth, b.orientation_deg) == (2, False, 1.1, 90.0)
    assert w.n_rows == 6
    assert w.n_pallets == 4 * a.n_pallets + 2 * b.n_pallets
    # row B2: origin (36 - 4.1, 0), length along +Y (90°), depth along -X
    c = w.rows[1].footprints()[1]
    np.testing.assert_allclose(c, [[31.9, 0.0], [31.9, b.length], [31.9 - 1.1, b.length],
                                   [31.9 - 1.1, 0.0]], atol=1e-12)


def _doc(tmp: Path, **row) -> dict:
    import shutil

    shutil.copy(EXAMPLES / "paper_rack.toml", tmp / "rack.toml")
    return {"rows": [{"rack": "rack.toml", **row}]}


def test_defaults_and_rotation(tmp_path: Path) -> None:
    w = warehouse_from_dict(_doc(tmp_path, orientation=30.0, origin=[1.0, 2.0]), base=tmp_path)
    r = w.rows[0]
    assert (r.name, r.count, r.depth, r.three_d) == ("row 1", 1, DEFAULT_DEPTH_2D, False)
    t = math.radians(30.0)
    c = r.footprints()[0]
    np.testing.assert_allclose(c[1], [1 + 3.6 * math.cos(t), 2 + 3.6 * math.sin(t)])
    np.testing.assert_allclose(c[3], [1 - 1.1 * math.sin(t), 2 + 1.1 * math.cos(t)])


def test_touching_rows_are_allowed_overlapping_refused(tmp_path: Path) -> None:
    ok = _doc(tmp_path, count=2, spacing=[0.0, DEFAULT_DEPTH_2D])  # share an edge
    assert warehouse_from_dict(ok, base=tmp_path).n_rows == 2
    with pytest.raises(InputError, match="do not overlap"):
        warehouse_from_dict(_doc(tmp_path, count=2, spacing=[0.0, 0.5]), base=tmp_path)
    # a row rotated across another
    doc = _doc(tmp_path)
    doc["rows"].append({"name": "X", "rack": "rack.toml", "orientation": 90.0,
                        "origin": [1.8, -1.0]})
    with pytest.raises(InputError, match="do not overlap"):
        warehouse_from_dict(doc, base=tmp_path)


@pytest.mark.parametrize(("row", "field", "allowed"), [
    ({"rack": "missing.toml"}, "rows[0].rack", "existing rack TOML"),
    ({"count": 0}, "rows[0].count", ">= 1"),
    ({"count": 2}, "rows[0].spacing", "[dX, dY]"),
    ({"count": 2, "spacing": [0.0, 0.0]}, "rows[0].spacing", "non-zero"),
    ({"orientation": 400.0}, "rows[0].orientation", "[-360, 360]"),
    ({"orientation": "east"}, "rows[0].orientation", "number"),
    ({"origin": [1.0]}, "rows[0].origin", "[X, Y]"),
    ({"depth": -1.0}, "rows[0].depth", "> 0"),
    ({"aisle": 3.0}, "rows[0].aisle", "known keys"),
])
def test_bad_rows(tmp_path: Path, row: dict, field: str, allowed: str) -> None:
    doc = _doc(tmp_path, **row)
    with pytest.raises(InputError) as exc:
        warehouse_from_dict(doc, base=tmp_path)
    assert exc.value.field == field
    assert allowed in exc.value.allowed


def test_bad_documents(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="rows"):
        warehouse_from_dict({"title": "x"}, base=tmp_path)
    doc = _doc(tmp_path, name="A")
    doc["rows"].append({"name": "A", "rack": "rack.toml", "origin": [0.0, 5.0]})
    with pytest.raises(InputError, match="distinct name"):
        warehouse_from_dict(doc, base=tmp_path)
    (tmp_path / "bad.toml").write_text("title = 'x'\n[[rows]]\nrack = 'rack.toml'\n"
                                       "[[rows]\n")
    with pytest.raises(InputError, match="malformed TOML"):
        load_warehouse(tmp_path / "bad.toml")
    with pytest.raises(InputError, match="existing warehouse"):
        load_warehouse(tmp_path / "none.toml")
    (tmp_path / "broken_rack.toml").write_text("title = 'no geometry'\n")
    with pytest.raises(InputError, match="valid rack file"):
        warehouse_from_dict({"rows": [{"rack": "broken_rack.toml"}]}, base=tmp_path)
    d3 = {"rows": [{"rack": str(EXAMPLES / "paper_rack_3d.toml"), "depth": 1.0}]}
    with pytest.raises(InputError, match="no depth for a 3D rack"):
        warehouse_from_dict(d3, base=tmp_path)


def test_plan_figure(tmp_path: Path) -> None:
    pytest.importorskip("matplotlib")
    from seisrack.report.warehouse_plot import plot_warehouse_plan

    w = load_warehouse(EXAMPLES / "site_warehouse.toml")
    ax = plot_warehouse_plan(w, {("A", 0): 0.3}, label="P(fall)")
    assert len(ax.patches) == w.n_rows
    ax.figure.savefig(tmp_path / "plan.png")
    assert (tmp_path / "plan.png").read_bytes()[:4] == b"\x89PNG"


def test_a_back_to_back_rack_is_as_deep_as_its_two_rows_and_flue() -> None:
    from seisrack.model import load_rack
    from seisrack.studies.warehouse import warehouse_from_dict

    ex = Path(__file__).resolve().parents[1] / "examples"
    geo = load_rack(ex / "warehouse_rack_3d_b2b.toml").geometry
    w = warehouse_from_dict({"rows": [{"rack": "warehouse_rack_3d_b2b.toml"}]}, base=ex)
    assert geo.rows == 2
    assert w.rows[0].depth == pytest.approx(2 * geo.depth + geo.row_spacer.length)
