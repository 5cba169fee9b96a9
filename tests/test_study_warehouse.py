"""A study of a whole warehouse (issue 24 item 4): every group of rack rows of a warehouse file
at its orientation, and the expected number of falling pallets per intensity level.

Checked, against independent arithmetic or a direct run:

- each group is its rack turned by minus its orientation (the plan convention of
  docs/user/warehouse_toml.md: down-aisle a1·cos θ + a2·sin θ, cross-aisle −a1·sin θ + a2·cos θ);
  ``racks`` or ``angle`` beside ``warehouse``, a missing warehouse file or a bad one are refused
  naming the field;
- a 3D row equals a direct ``run_rack`` of its rack under the pair turned by −θ; a 2D row equals
  a direct run of its rack under the one record a1·cos θ + a2·sin θ, built here by hand;
- the expected number of falls of a level is Σ over groups of count × (mean over the level's
  runs of the group's falls), recomputed from the stored table; P(a row loses a pallet) is the
  fraction of those runs with a fall; the groups are ranked by their share;
- on a power-law hazard curve the expected falls per year are Σ E_i·ΔH_i over bins with edges at
  the geometric midpoints, by hand (FEMA P-58-1 2012 §8.2);
- the summary writes one plan figure per level, its JSON and an HTML section; a second run
  resumes (no new runs); a Dask LocalCluster gives the same table.
"""

from __future__ import annotations

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.studies import expand, load_study, read_runs, run_study
from test_study_3d import _pairs

ROOT = Path(__file__).resolve().parents[1]

SITE = """
title = "two groups"
[[rows]]
name = "A"
rack = "rack3d.toml"
count = 3
orientation = 30.0
origin = [0.0, 0.0]
spacing = [0.0, 5.0]
[[rows]]
name = "B"
rack = "rack2d.toml"
count = 2
orientation = 90.0
origin = [40.0, 0.0]
spacing = [-3.0, 0.0]
depth = 1.1
"""

STUDY = """
warehouse = "site.toml"
seed = 5
[records]
folder = "pairs"
pairs = true
[intensity]
measure = "pga"
unit = "g"
stripes = [0.3, 0.7]
[friction]
values = [0.3]
"""


def _warehouse(tmp: Path, study: str = STUDY, site: str = SITE) -> Path:
    tmp.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "examples" / "paper_rack_3d.toml", tmp / "rack3d.toml")
    shutil.copy(ROOT / "examples" / "paper_rack.toml", tmp / "rack2d.toml")
    _pairs(tmp / "pairs")
    (tmp / "site.toml").write_text(site)
    (tmp / "study.toml").write_text(study)
    return tmp / "study.toml"


def test_groups_are_racks_at_minus_their_orientation(tmp_path: Path) -> None:
    spec = load_study(_warehouse(tmp_path))
    assert spec.racks_as_given == ("rack3d.toml", "rack2d.toml")
    assert spec.rack_angles == ((-30.0,), (-90.0,))
    runs = expand(spec)
    assert len(runs) == 2 * 2 * 2  # groups x pairs x stripes
    assert {(r.rack, r.angle_deg, r.components) for r in runs} == {
        ("rack3d.toml", -30.0, 2), ("rack2d.toml", -90.0, 2)}


@pytest.mark.parametrize("extra, field, match", [
    ('racks = ["rack3d.toml"]\n', "racks", "warehouse file gives the racks"),
    ("[angle]\nvalues = [0.0]\n", "angle", "warehouse file gives the racks"),
])
def test_racks_or_angle_beside_a_warehouse_are_refused(tmp_path: Path, extra: str, field: str,
                                                      match: str) -> None:
    head, tail = STUDY.split("[records]")
    path = _warehouse(tmp_path, head + extra + "[records]" + tail if extra.startswith("racks")
                      else STUDY + extra)
    with pytest.raises(InputError, match=match) as exc:
        load_study(path)
    assert exc.value.field == field


def test_a_missing_or_bad_warehouse_is_refused(tmp_path: Path) -> None:
    path = _warehouse(tmp_path, STUDY.replace("site.toml", "nowhere.toml"))
    with pytest.raises(InputError, match="existing warehouse TOML file") as exc:
        load_study(path)
    assert exc.value.field == "warehouse"
    path = _warehouse(tmp_path / "bad", site=SITE.replace("count = 3", "count = 0"))
    with pytest.raises(InputError) as exc:
        load_study(path)
    assert "count" in str(exc.value.field)


@pytest.fixture(scope="module")
def stored(tmp_path_factory: pytest.TempPathFactory):
    tmp = tmp_path_factory.mktemp("wh")
    path = _warehouse(tmp)
    s = run_study(load_study(path), tmp / "out", workers=1, progress=False)
    assert (s.runs_total, s.runs_ok) == (8, 8)
    return path, tmp / "out", read_runs(tmp / "out").to_pylist()


def _direct(path: Path, row: dict, three_d: bool):  # noqa: ANN202
    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack, with_friction
    from seisrack.motion import Record, read_record
    from seisrack.motion.components import combine

    folder = path.parent / "pairs"
    a = read_record(folder / f"{row['record']}_H1.AT2")
    b = read_record(folder / f"{row['record']}_H2.AT2")
    rack = "rack3d.toml" if three_d else "rack2d.toml"
    model = compile_rack(with_friction(load_rack(path.parent / rack), 0.3))
    if three_d:
        motion = combine(a, b, angle_deg=-30.0).scaled(row["scale_factor"])
    else:  # by hand: the component along a row at 90° is the second one
        th = math.radians(90.0)
        x = math.cos(th) * a.accel + math.sin(th) * b.accel
        motion = Record(row["scale_factor"] * x, a.dt, name="along B")
    return run_rack(model, motion, save_every=None, dt=0.005)


def test_a_3d_row_equals_a_direct_run(stored) -> None:
    path, _, rows = stored
    row = max((r for r in rows if r["rack"] == "rack3d.toml"), key=lambda r: r["im_target"])
    resp = _direct(path, row, True)
    by_dir = resp.pallet_peak_sliding_by_direction().max(axis=0)
    assert row["peak_sliding_down_aisle_max_m"] == pytest.approx(by_dir[0], rel=1e-9)
    assert row["peak_sliding_cross_aisle_max_m"] == pytest.approx(by_dir[1], rel=1e-9)
    assert row["n_aisle_fall"] == len(resp.falls)


def test_a_2d_row_takes_the_motion_along_its_axis(stored) -> None:
    path, _, rows = stored
    row = max((r for r in rows if r["rack"] == "rack2d.toml"), key=lambda r: r["im_target"])
    resp = _direct(path, row, False)
    assert row["peak_sliding_max_m"] > 1e-3  # it slid: the comparison means something
    assert row["peak_sliding_max_m"] == pytest.approx(resp.pallet_peak_sliding().max(),
                                                      rel=1e-9)
    assert row["peak_sliding_cross_aisle_max_m"] is None


def test_expected_falls_are_count_times_the_mean(stored) -> None:
    from seisrack.studies.summary import summarize

    _, out, rows = stored
    s = summarize(out, n_boot=3, write=True, plots=True)
    wh = s["warehouse"]
    assert wh["n_rows"] == 5
    levels = sorted({r["im_target"] for r in rows})
    assert [lv["im"] for lv in wh["levels"]] == pytest.approx(levels)
    for lv, im in zip(wh["levels"], levels, strict=True):
        expect = {}
        for name, rack, count, falls, anyf in (
                ("A", "rack3d.toml", 3, "n_aisle_fall", "any_aisle_fall"),
                ("B", "rack2d.toml", 2, "n_fall", "any_fall")):
            sel = [r for r in rows if r["rack"] == rack and r["im_target"] == im]
            assert len(sel) == 2
            expect[name] = count * sum(r[falls] for r in sel) / len(sel)
            g = next(g for g in lv["groups"] if g["group"] == name)
            assert g["expected"] == pytest.approx(expect[name])
            assert g["p_row_loses_a_pallet"] == pytest.approx(
                sum(bool(r[anyf]) for r in sel) / len(sel))
        assert lv["expected_falls"] == pytest.approx(sum(expect.values()))
        ranked = [k for k, v in sorted(expect.items(), key=lambda kv: -kv[1]) if v > 0]
        assert lv["driven_by"] == ranked
    # something fell at the top stripe, so the figures colour more than one value
    assert wh["levels"][-1]["expected_falls"] > 0
    for k in range(len(levels)):
        assert (out / "summary" / f"warehouse_plan_{k}.png").stat().st_size > 5000
    doc = json.loads((out / "summary" / "summary.json").read_text())
    assert doc["warehouse"]["levels"][-1]["expected_falls"] == pytest.approx(
        wh["levels"][-1]["expected_falls"])
    from seisrack.studies.summary import format_summary

    text = format_summary(s)
    assert "expected number of falling pallets" in text and "3 rows x" in text
    assert np.isfinite(wh["levels"][0]["expected_falls"])


def test_a_second_run_resumes(stored) -> None:
    path, out, _ = stored
    s = run_study(load_study(path), out, workers=1, progress=False)
    assert (s.runs_total, s.runs_already_stored, s.runs_executed) == (8, 8, 0)


def test_falls_per_year_on_a_power_law_hazard() -> None:
    """Σ E_i·[H(lower_i) − H(upper_i)] with edges at geometric midpoints, by hand, on
    H = k0·x^(−k) (exact on a power law: the log-log interpolation reproduces it)."""
    from seisrack.studies.risk import hazard_curve
    from seisrack.studies.warehouse_summary import annual_falls

    k0, k = 1e-3, 2.5
    xs = np.geomspace(0.5, 20.0, 6)
    curve = hazard_curve(xs, k0 * xs ** -k)
    im = [2.0, 4.0, 8.0]
    s = {"levels": [{"im": x, "expected_falls": e1 + e2,
                     "groups": [{"group": "A", "expected": e1}, {"group": "B", "expected": e2}]}
                    for x, e1, e2 in zip(im, [0.0, 3.0, 10.0], [1.0, 1.0, 2.0], strict=True)]}
    out = annual_falls(s, curve)
    h = lambda x: k0 * x ** -k  # noqa: E731
    e = [2.0 / math.sqrt(2.0), math.sqrt(8.0), math.sqrt(32.0)]  # edges below each stripe
    dl = [h(e[0]) - h(e[1]), h(e[1]) - h(e[2]), h(e[2])]
    assert out["per_group"]["A"] == pytest.approx(3.0 * dl[1] + 10.0 * dl[2], rel=1e-10)
    assert out["per_group"]["B"] == pytest.approx(dl[0] + dl[1] + 2.0 * dl[2], rel=1e-10)
    total = sum(n * d for n, d in zip([1.0, 4.0, 12.0], dl, strict=True))
    assert out["expected_per_year"] == pytest.approx(total, rel=1e-10)
    assert out["top_bin_share"] == pytest.approx(12.0 * dl[2] / total, rel=1e-10)
    assert out["bins"][0]["lower_m_s2"] == pytest.approx(e[0])


def test_cli_summary_with_a_hazard_gives_falls_per_year(stored, tmp_path: Path) -> None:
    import subprocess
    import sys

    _, out, _ = stored
    hz = tmp_path / "hazard.csv"
    hz.write_text("# measure = pga\n# units = g\nim,annual_frequency\n0.05,2e-2\n0.2,2e-3\n"
                  "0.5,2e-4\n1.0,2e-5\n")
    p = subprocess.run([sys.executable, "-m", "seisrack", "study", "summary", str(out),
                        "--hazard", str(hz), "--json", "--no-plots",
                        "--report", str(tmp_path / "study.html")],
                       capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    per_year = doc["warehouse"]["per_year"]
    assert per_year["expected_per_year"] > 0
    assert per_year["expected_in_50_years"] == pytest.approx(50 * per_year["expected_per_year"])
    html = (tmp_path / "study.html").read_text()
    assert '<section id="warehouse">' in html and 'id="table-warehouse"' in html
    assert html.count('id="fig-warehouse-') == 2 and "falling pallets per year" in html


def test_dask_gives_the_same_table(stored, tmp_path: Path) -> None:
    pytest.importorskip("dask.distributed")
    path, _, rows = stored
    run_study(load_study(path), tmp_path, executor="dask", workers=2, batch_size=3,
              progress=False)
    other = read_runs(tmp_path).drop_columns(["wall_time_s"]).to_pylist()
    key = lambda r: r["run_id"]  # noqa: E731
    mine = [{k: v for k, v in r.items() if k != "wall_time_s"} for r in rows]
    assert sorted(other, key=key) == sorted(mine, key=key)


def test_a_damaged_study_json_is_named_and_rewritten(stored, tmp_path: Path) -> None:
    """The summary names an unreadable study.json instead of failing; running the study again
    rewrites it without running anything, and the warehouse section comes back."""
    from seisrack.studies.summary import summarize

    path, out, _ = stored
    good = (out / "study.json").read_text()
    try:
        (out / "study.json").write_text("{bad")
        s = summarize(out, n_boot=0, write=False, plots=False)
        assert "warehouse" not in s and "study.json could not be read" in s["notes"][0]
        r = run_study(load_study(path), out, workers=1, progress=False)
        assert r.runs_executed == 0
        assert "warehouse" in summarize(out, n_boot=0, write=False, plots=False)
    finally:
        (out / "study.json").write_text(good)
