"""Size and plan limits of a warehouse file and its fast overlap check (seisrack.studies.warehouse).

Checked:

- a group or a warehouse above ``MAX_ROWS`` rows is refused naming ``rows[i].count`` (or
  ``rows[].count`` for the total) and the limit, before any rack file is read (the rack named
  here does not exist, and the count is still the error);
- a plan coordinate beyond ``MAX_PLAN_COORD`` (an origin or a spacing, a group running out of
  range, a row longer than the range) is refused naming its field, with no numpy warning: at
  origin [1e308, 1e308] the old pairwise test overflowed and let overlapping rows through;
- the sort-and-sweep check against an independent reference, the separating-axis test of every
  pair of rows written out here in plain Python, on random small layouts of rows at 0, 90, 180,
  -90 degrees and arbitrary angles, touching or not; and a few thousand rows that fit, then the
  same with one row moved onto another.
"""

from __future__ import annotations

import math
import random
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.studies.warehouse import MAX_PLAN_COORD, MAX_ROWS, warehouse_from_dict

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
RACK_LENGTH = 3.6  # paper_rack.toml: two bays of 1.8 m


@pytest.fixture
def base(tmp_path: Path) -> Path:
    shutil.copy(EXAMPLES / "paper_rack.toml", tmp_path / "rack.toml")
    return tmp_path


def _group(name: str, **kw) -> dict:
    return {"name": name, "rack": "rack.toml", **kw}


# ------------------------------------------------------------------------------ row counts
def test_a_huge_count_is_refused_before_any_rack_is_read(base: Path) -> None:
    doc = {"rows": [_group("A"), {"name": "B", "rack": "missing.toml", "count": 100_000,
                                  "spacing": [0.0, 4.1]}]}
    with pytest.raises(InputError) as exc:
        warehouse_from_dict(doc, base=base)
    assert exc.value.field == "rows[1].count"
    assert exc.value.value == 100_000
    assert f"{MAX_ROWS:,}" in exc.value.allowed


def test_too_many_rows_in_all_are_refused(base: Path) -> None:
    half = MAX_ROWS // 2 + 1
    doc = {"rows": [_group("A", count=half, spacing=[0.0, 4.1]),
                    _group("B", count=half, spacing=[0.0, 4.1], origin=[10.0, 0.0])]}
    with pytest.raises(InputError) as exc:
        warehouse_from_dict(doc, base=base)
    assert exc.value.field == "rows[].count"
    assert f"{2 * half:,} rows" in exc.value.value
    assert f"at most {MAX_ROWS:,}" in exc.value.allowed


def test_a_warehouse_at_the_limit_is_accepted(base: Path) -> None:
    doc = {"rows": [_group("A", count=MAX_ROWS // 2, spacing=[0.0, 1.1]),
                    _group("B", count=MAX_ROWS // 2, spacing=[0.0, 1.1], origin=[3.6, 0.0])]}
    assert warehouse_from_dict(doc, base=base).n_rows == MAX_ROWS  # all rows touch, none overlap


# ------------------------------------------------------------------------------ plan range
def _no_warnings(fn):  # noqa: ANN001, ANN202
    """Run ``fn``; fail on any warning (numpy's RuntimeWarning among them)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with np.errstate(all="warn"):
            try:
                return fn()
            finally:
                assert [str(w.message) for w in caught] == []


def test_huge_origins_are_refused_without_warnings(base: Path) -> None:
    def doc(origin: list[float]) -> dict:
        return {"rows": [_group("A", count=2, spacing=[0.0, 0.5], origin=origin),
                         _group("B", origin=origin)]}

    with pytest.raises(InputError, match="do not overlap"):
        warehouse_from_dict(doc([1.0, 1.0]), base=base)
    for origin, field in (([1e308, 1e308], "rows[0].origin[0]"),
                          ([0.0, -1e308], "rows[0].origin[1]"),
                          ([0.0, MAX_PLAN_COORD * 1.001], "rows[0].origin[1]")):
        with pytest.raises(InputError) as exc:
            _no_warnings(lambda o=origin: warehouse_from_dict(doc(o), base=base))
        assert exc.value.field == field
        assert f"{MAX_PLAN_COORD:g}" in exc.value.allowed


@pytest.mark.parametrize(("row", "field"), [
    ({"count": 2, "spacing": [1e308, 0.0]}, "rows[0].spacing[0]"),
    ({"count": MAX_ROWS, "spacing": [0.0, 20.0]}, "rows[0].spacing"),  # the last row at 2e5 m
    ({"origin": [MAX_PLAN_COORD - 1.0, 0.0]}, "rows[0].origin"),  # the row runs out of range
    ({"origin": [0.0, MAX_PLAN_COORD], "orientation": 45.0}, "rows[0].origin"),
    ({"depth": 2 * MAX_PLAN_COORD}, "rows[0].depth"),
])
def test_rows_out_of_the_plan_range_are_refused(base: Path, row: dict, field: str) -> None:
    with pytest.raises(InputError) as exc:
        _no_warnings(lambda: warehouse_from_dict({"rows": [_group("A", **row)]}, base=base))
    assert exc.value.field == field
    assert f"{MAX_PLAN_COORD:g}" in exc.value.allowed


def test_a_rack_longer_than_the_plan_range_is_refused(base: Path) -> None:
    text = (base / "rack.toml").read_text().replace("bays = [1.8, 1.8]", "bays = [1.8, 2e5]")
    (base / "long.toml").write_text(text)
    with pytest.raises(InputError) as exc:
        warehouse_from_dict({"rows": [{"rack": "long.toml"}]}, base=base)
    assert exc.value.field == "rows[0].rack"
    assert "long" in exc.value.allowed


def test_rows_at_the_edge_of_the_range_are_accepted(base: Path) -> None:
    edge = MAX_PLAN_COORD - RACK_LENGTH
    w = warehouse_from_dict({"rows": [_group("A", origin=[edge, -MAX_PLAN_COORD])]}, base=base)
    assert w.rows[0].footprints()[0].max() == pytest.approx(MAX_PLAN_COORD)


# ------------------------------------------------------------------------------ overlaps
def _separated(a: list, b: list, tol: float = 1e-9) -> bool:
    """The reference: two convex polygons (corners counter-clockwise) are apart or touch when
    their projections on the normal of some edge of either overlap by at most tol."""
    for poly in (a, b):
        for k in range(len(poly)):
            ex = poly[(k + 1) % len(poly)][0] - poly[k][0]
            ey = poly[(k + 1) % len(poly)][1] - poly[k][1]
            pa = [-ey * x + ex * y for x, y in a]
            pb = [-ey * x + ex * y for x, y in b]
            t = tol * math.hypot(ex, ey)
            if max(pa) <= min(pb) + t or max(pb) <= min(pa) + t:
                return True
    return False


def _reference_pairs(doc: dict) -> set[str]:
    """Every overlapping pair, "A #1 and B #2", of the rows of ``doc``, with their corners
    built here from the file's keys (rows RACK_LENGTH long)."""
    rows = []
    for g in doc["rows"]:
        t = math.radians(g["orientation"])
        length, depth = RACK_LENGTH, g["depth"]
        u, v = (math.cos(t), math.sin(t)), (-math.sin(t), math.cos(t))
        for k in range(g["count"]):
            ox, oy = (g["origin"][0] + k * g["spacing"][0], g["origin"][1] + k * g["spacing"][1])
            rows.append((f"{g['name']} #{k + 1}", [
                (ox, oy), (ox + length * u[0], oy + length * u[1]),
                (ox + length * u[0] + depth * v[0], oy + length * u[1] + depth * v[1]),
                (ox + depth * v[0], oy + depth * v[1])]))
    return {f"{a} and {b}" for i, (a, pa) in enumerate(rows) for b, pb in rows[i + 1:]
            if not _separated(pa, pb)}


def _random_layout(rng: random.Random) -> dict:
    groups = []
    for g in range(rng.randint(1, 4)):
        angle = rng.choice([0.0, 90.0, 180.0, -90.0, rng.uniform(-360.0, 360.0)])
        depth = rng.choice([1.1, rng.uniform(0.5, 2.0)])
        t = math.radians(angle)
        # spacing across the rows (touching, apart or overlapping) or anywhere
        across = depth * rng.choice([1.0, 1.0, 0.5, 1.5, rng.uniform(0.8, 3.0)])
        spacing = rng.choice([[-across * math.sin(t), across * math.cos(t)],
                              [rng.uniform(-6.0, 6.0), rng.uniform(-6.0, 6.0)]])
        groups.append(_group(f"G{g}", count=rng.randint(1, 6), orientation=angle, depth=depth,
                             origin=[rng.uniform(0.0, 15.0), rng.uniform(0.0, 15.0)],
                             spacing=spacing))
    return {"rows": groups}


def test_the_fast_check_agrees_with_every_pair_tested(base: Path) -> None:
    rng = random.Random(20240611)
    outcomes = {True: 0, False: 0}
    for _ in range(300):
        doc = _random_layout(rng)
        expected = _reference_pairs(doc)
        outcomes[bool(expected)] += 1
        if not expected:
            w = warehouse_from_dict(doc, base=base)
            assert w.n_rows == sum(g["count"] for g in doc["rows"])
            continue
        with pytest.raises(InputError, match="do not overlap") as exc:
            warehouse_from_dict(doc, base=base)
        assert exc.value.value in expected  # a pair that does overlap
    assert min(outcomes.values()) > 50  # both kinds of layout were drawn


def _big_site(n_groups: int, per_group: int) -> dict:
    """Groups of touching rows side by side (X), aisles of 3 m, plus one row at 30 degrees
    in a clearing above them."""
    rows = [_group(f"G{g}", count=per_group, spacing=[0.0, 1.1],
                   origin=[g * (RACK_LENGTH + 3.0), 0.0]) for g in range(n_groups)]
    rows.append(_group("R", orientation=30.0, origin=[5.0, per_group * 1.1 + 1.0]))
    return {"rows": rows}


def test_a_few_thousand_rows_check_correctly(base: Path) -> None:
    doc = _big_site(30, 100)
    assert warehouse_from_dict(doc, base=base).n_rows == 3001
    # the rotated row moved down onto row 100 of group G0 (and G1's beside it)
    doc["rows"][-1]["origin"] = [2.0, 100 * 1.1 - 0.3]
    with pytest.raises(InputError, match="do not overlap") as exc:
        warehouse_from_dict(doc, base=base)
    assert exc.value.value in ("G0 #100 and R #1", "G1 #100 and R #1")
    # one row of a group shifted by a centimetre into its neighbour
    doc = _big_site(30, 100)
    doc["rows"][17]["spacing"] = [0.0, 1.09]
    with pytest.raises(InputError, match="do not overlap") as exc:
        warehouse_from_dict(doc, base=base)
    assert exc.value.value.startswith("G17 #")
