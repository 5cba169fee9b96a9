"""Studies of 3D racks (issue 21): record pairs, the incidence angle as a study variable, falls
into the aisles and sliding per direction in the store and the fragilities.

Checked, against independent arithmetic or a direct run:

- a folder of PEER-style pairs (``..._H1.AT2`` / ``..._H2.AT2``) groups into pairs by name,
  the first down-aisle; an odd file, two components of different lengths, pairs or an angle on
  a 2D rack are refused before any run, naming the field;
- a pair's intensity is the geometric mean of its two components' PGA, so each run's scale
  factor is target / sqrt(PGA1·PGA2);
- uniformly sampled angles lie in [low, high], are the same at every intensity level (common
  random numbers) and do not depend on the order of expansion; the run ids of a down-aisle
  study are those of earlier versions (its store resumes);
- a row equals a direct ``run_rack`` of the same rack under the same scaled, turned pair
  (falls into the aisles, peak sliding per direction);
- 1 worker and a Dask LocalCluster give the same table; the summary fits the aisle-fall and
  per-direction sliding states for the 3D rack.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.studies import expand, load_study, read_runs, run_study
from seisrack.studies.expand import run_id
from test_study_spec import make_study

ROOT = Path(__file__).resolve().parents[1]


def _at2(path: Path, g: np.ndarray, dt: float = 0.01) -> None:
    lines = ["PEER NGA STRONG MOTION DATABASE RECORD", path.stem, "ACCELERATION IN G",
             f"NPTS= {g.size}, DT= {dt:.4f} SEC"]
    lines += [" ".join(f"{v: .7E}" for v in g[i:i + 5]) for i in range(0, g.size, 5)]
    path.write_text("\n".join(lines) + "\n")


def _pairs(folder: Path, n: int = 2, seconds: float = 3.0) -> list[tuple[float, float]]:
    """``n`` pairs of decaying sines (g); the PGAs [m/s²] of each pair (x, z) as read back."""
    from seisrack.motion import read_record

    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(0.0, seconds, 0.01)
    pgas = []
    for k in range(n):
        a = (0.2 + 0.05 * k) * np.sin(2 * np.pi * (1.5 + 0.3 * k) * t) * np.exp(-0.3 * t)
        b = (0.15 + 0.04 * k) * np.sin(2 * np.pi * (2.2 + 0.2 * k) * t + 0.4) * np.exp(-0.3 * t)
        _at2(folder / f"RSN{k + 1}_TEST_H1.AT2", a)
        _at2(folder / f"RSN{k + 1}_TEST_H2.AT2", b)
        pgas.append(tuple(read_record(folder / f"RSN{k + 1}_TEST_{c}.AT2").pga
                          for c in ("H1", "H2")))
    return pgas


BODY = """
racks = ["rack.toml"]
seed = 11
[records]
folder = "pairs"
pairs = true
[intensity]
measure = "pga"
unit = "g"
stripes = [0.3, 0.6]
[friction]
values = [0.3]
"""


def _study3d(tmp: Path, extra: str = "", body: str = BODY) -> tuple[Path, list]:
    tmp.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "examples" / "paper_rack_3d.toml", tmp / "rack.toml")
    pgas = _pairs(tmp / "pairs")
    (tmp / "study.toml").write_text(body + extra)
    return tmp / "study.toml", pgas


def test_pairs_group_by_name_and_scale_by_the_geometric_mean(tmp_path: Path) -> None:
    path, pgas = _study3d(tmp_path)
    runs = expand(load_study(path))
    assert len(runs) == 2 * 2
    assert sorted({r.record for r in runs}) == ["RSN1_TEST", "RSN2_TEST"]
    for r in runs:
        assert r.components == 2 and r.angle_deg == 0.0
        k = int(r.record[3]) - 1
        gm = math.sqrt(pgas[k][0] * pgas[k][1])
        assert r.scale_factor == pytest.approx(r.im_target / gm, rel=1e-12)


def test_sampled_angles_are_common_across_levels(tmp_path: Path) -> None:
    path, _ = _study3d(tmp_path, '[angle]\ndist = "uniform"\nlow = 0.0\nhigh = 90.0\n'
                                 "samples = 3\n")
    runs = expand(load_study(path))
    assert len(runs) == 2 * 3 * 2
    for rec in ("RSN1_TEST", "RSN2_TEST"):
        by_level = {}
        for r in runs:
            if r.record == rec:
                by_level.setdefault(r.im_target, []).append(r.angle_deg)
        lists = list(by_level.values())
        assert all(v == lists[0] for v in lists) and len(set(lists[0])) == 3
        assert all(0.0 <= a <= 90.0 for a in lists[0])
    assert [r.run_id for r in expand(load_study(path))] == [r.run_id for r in runs]


def test_down_aisle_ids_are_unchanged(tmp_path: Path) -> None:
    """A one-component study at 0°: the id is the hash of the same ten inputs as before."""
    spec = load_study(make_study(tmp_path))
    for r in expand(spec):
        assert r.components == 1 and r.angle_deg == 0.0
        assert r.run_id == run_id(r.rack_hash, r.record, r.record_hash, r.im_measure,
                                  r.im_target, r.mu_static, r.mu_dynamic, r.occupancy, r.seed,
                                  spec.dt)


@pytest.mark.parametrize("extra, field", [
    ("[angle]\nvalues = [0.0, 30.0]\n", "angle"),
    ("[angle]\nvalues = [0.0, 0.0]\n", "angle.values"),
    ("[angle]\nvalues = [400.0]\n", "angle.values[0]"),
    ('[angle]\ndist = "uniform"\nlow = 10.0\nhigh = 5.0\n', "angle.high"),
    ('[angle]\ndist = "normal"\nhigh = 5.0\n', "angle.dist"),
])
def test_bad_angle_or_2d_rack_is_refused(tmp_path: Path, extra: str, field: str) -> None:
    # the 2D paper rack: an angle (a cross-aisle component) needs a 3D rack
    path = make_study(tmp_path, extra=extra)
    with pytest.raises(InputError) as exc:
        expand(load_study(path))
    assert exc.value.field == field


def test_unpaired_or_mismatched_files_are_refused(tmp_path: Path) -> None:
    path, _ = _study3d(tmp_path)
    _at2(tmp_path / "pairs" / "RSN9_ALONE_H1.AT2", np.zeros(50))
    with pytest.raises(InputError, match="exactly two files") as exc:
        expand(load_study(path))
    assert exc.value.field == "records.pairs"
    _at2(tmp_path / "pairs" / "RSN9_ALONE_H2.AT2", np.zeros(60))
    with pytest.raises(InputError, match="same time step and length"):
        expand(load_study(path))


def test_pairs_on_a_2d_rack_are_refused(tmp_path: Path) -> None:
    path, _ = _study3d(tmp_path)
    shutil.copy(ROOT / "examples" / "paper_rack.toml", tmp_path / "rack.toml")
    with pytest.raises(InputError, match="3D rack") as exc:
        expand(load_study(path))
    assert exc.value.field == "records"


@pytest.fixture(scope="module")
def stored(tmp_path_factory: pytest.TempPathFactory):
    tmp = tmp_path_factory.mktemp("s3d")
    path, _ = _study3d(tmp, "[angle]\nvalues = [0.0, 45.0]\n")
    s = run_study(load_study(path), tmp / "out", workers=1, progress=False)
    assert (s.runs_total, s.runs_ok) == (8, 8)
    return path, tmp / "out", read_runs(tmp / "out")


def test_a_row_equals_a_direct_run(stored) -> None:
    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack, with_friction
    from seisrack.motion import read_record
    from seisrack.motion.components import combine

    path, _, table = stored
    rows = table.to_pylist()
    row = max(rows, key=lambda r: (r["angle_deg"], r["im_target"]))
    assert row["angle_deg"] == 45.0
    folder = path.parent / "pairs"
    a = read_record(folder / f"{row['record']}_H1.AT2")
    b = read_record(folder / f"{row['record']}_H2.AT2")
    f = row["scale_factor"]
    model = compile_rack(with_friction(load_rack(path.parent / "rack.toml"), 0.3))
    motion = combine(a, b, angle_deg=45.0)
    resp = run_rack(model, motion.scaled(f), save_every=None, dt=0.005)
    by_dir = resp.pallet_peak_sliding_by_direction().max(axis=0)
    assert row["peak_sliding_down_aisle_max_m"] == pytest.approx(by_dir[0], rel=1e-9)
    assert row["peak_sliding_cross_aisle_max_m"] == pytest.approx(by_dir[1], rel=1e-9)
    assert row["n_aisle_fall"] == len(resp.falls)
    assert row["any_aisle_fall"] == bool(resp.falls)
    assert row["peak_sliding_max_m"] == pytest.approx(resp.pallet_peak_sliding().max(),
                                                      rel=1e-9)


def test_dask_gives_the_same_table(stored, tmp_path: Path) -> None:
    pytest.importorskip("dask.distributed")
    path, _, table = stored
    run_study(load_study(path), tmp_path, executor="dask", workers=2, batch_size=2,
              progress=False)
    other = read_runs(tmp_path)
    assert other.drop_columns(["wall_time_s"]).to_pydict() == \
        table.drop_columns(["wall_time_s"]).to_pydict()


def test_summary_fits_the_aisle_falls_and_the_directions(stored) -> None:
    from seisrack.studies.summary import summarize

    _, out, _ = stored
    s = summarize(out, n_boot=5, write=False, plots=False)
    g = s["groups"][0]
    assert g["dimension"] == "3D"
    names = set(g["stripes"]["fragility"])
    assert {"aisle_fall", "sliding_down_aisle>0.05m", "sliding_cross_aisle>0.05m"} <= names
    assert "aisle_fall" in s["damage_states"]


def test_falls_into_the_flue_are_not_aisle_falls() -> None:
    """A back-to-back rack's pallet that falls into the flue counts among the falls, not among
    the falls into an aisle (the study's fragility state)."""
    from types import SimpleNamespace

    from seisrack.analysis.pallet_contacts import Fall
    from seisrack.studies.executors import _direction_columns

    res = SimpleNamespace(falls=[Fall(0, 1.0, "flue"), Fall(3, 2.0, "rear aisle")],
                          pallet_peak_sliding_by_direction=lambda: np.ones((4, 2)))
    cols = _direction_columns(res)
    assert (cols["n_aisle_fall"], cols["any_aisle_fall"]) == (1, True)
    res.falls = [Fall(0, 1.0, "flue")]
    assert _direction_columns(res)["any_aisle_fall"] is False
