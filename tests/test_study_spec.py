"""Study files and their expansion (issue 13): what is checked.

- expansion: the run count is the product racks × occupancy × records × friction samples ×
  levels; ids are 16 hex digits, unique, equal to ``run_id(...)`` of the run's inputs, the same
  on every expansion, and change when a defining input (record content, friction) changes;
- sampling: friction samples are reproducible with the seed, change with it, follow the
  distribution (lognormal: mean and std of ln μ within 4 standard errors; uniform and truncated
  normal: inside their bounds), and do not depend on the order of expansion (adding a stripe or
  a record leaves the existing runs, ids and samples unchanged);
- intensities: PGA scale factors give the target PGA exactly; Sa(T1) uses T1 of the rack's
  modal analysis and the exact response spectrum; IDA grids; ``unit = "g"``;
- occupancy: round-half-up(f · n) pallets kept, reproducibly;
- bad input, each named and reported before any run: missing rack, missing folder, unreadable
  record, unknown bundled record, empty stripes, stripes and ida together, invalid lognormal,
  uniform and truncated-normal parameters, unknown distribution, a zero-PGA record, a scale
  factor above max_scale, an analysis step not dividing the record's, occupancy > 1, unknown
  key; the CLI exits 2 with one paragraph and no traceback, and writes nothing.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.fe.modal import modal_analysis
from seisrack.model import compile_rack, load_rack
from seisrack.motion import Record, response_spectrum, write_record_csv
from seisrack.studies import expand, load_study
from seisrack.studies.expand import run_id

ROOT = Path(__file__).resolve().parent.parent
G = 9.80665


def write_records(folder: Path, n: int = 2, duration: float = 3.0, dt: float = 0.01) -> None:
    """``n`` deterministic test records (filtered noise, 3 s) as CSV files in m/s²."""
    folder.mkdir(parents=True, exist_ok=True)
    t = np.arange(int(round(duration / dt)) + 1) * dt
    for i in range(n):
        rng = np.random.default_rng(100 + i)
        a = np.convolve(rng.standard_normal(t.size), np.ones(5) / 5, mode="same")
        a *= np.sin(np.pi * t / duration) * 2.0  # taper: starts and ends at rest
        write_record_csv(Record(a, dt, name=f"rec{i}"), folder / f"rec{i}.csv")


def make_study(tmp: Path, body: str | None = None, *, n_records: int = 2, extra: str = "",
               name: str = "study.toml") -> Path:
    """A small study of the paper rack in ``tmp`` (default: 2 records × 2 μ × 3 stripes)."""
    tmp.mkdir(parents=True, exist_ok=True)
    shutil.copy(ROOT / "examples" / "paper_rack.toml", tmp / "rack.toml")
    write_records(tmp / "records", n_records)
    if body is None:
        body = """
racks = ["rack.toml"]
seed = 7
[records]
folder = "records"
[intensity]
measure = "pga"
unit = "g"
stripes = [0.1, 0.3, 0.5]
[friction]
dist = "lognormal"
median = 0.4
dispersion = 0.2
samples = 2
"""
    p = tmp / name
    p.write_text(body + extra)
    return p


def test_expansion_count_ids_and_determinism(tmp_path: Path) -> None:
    spec = load_study(make_study(tmp_path))
    runs = expand(spec)
    assert len(runs) == 2 * 2 * 3
    ids = [r.run_id for r in runs]
    assert len(set(ids)) == len(ids)
    assert all(len(i) == 16 and int(i, 16) >= 0 for i in ids)
    assert [r.run_id for r in expand(load_study(tmp_path / "study.toml"))] == ids
    for r in runs:
        assert r.run_id == run_id(r.rack_hash, r.record, r.record_hash, r.im_measure,
                                  r.im_target, r.mu_static, r.mu_dynamic, r.occupancy, r.seed,
                                  spec.dt)
    assert sorted({r.stripe for r in runs}) == [0, 1, 2]
    assert sorted({r.im_target for r in runs}) == pytest.approx([0.1 * G, 0.3 * G, 0.5 * G])
    # scale factor: the scaled record has exactly the target PGA
    from seisrack.motion import read_record

    for r in runs:
        rec = read_record(tmp_path / "records" / f"{r.record}.csv")
        pga = np.max(np.abs(rec.accel))
        assert pga * r.scale_factor == pytest.approx(r.im_target, rel=1e-12)
    # the same friction at every stripe of a (record, sample): common random numbers
    by_cell: dict = {}
    for r in runs:
        by_cell.setdefault((r.record, r.im_target), []).append(r.mu_static)
    for rec_name in ("rec0", "rec1"):
        assert len({tuple(v) for (n, _), v in by_cell.items() if n == rec_name}) == 1


def test_ids_change_with_defining_inputs(tmp_path: Path) -> None:
    ids = {r.run_id for r in expand(load_study(make_study(tmp_path)))}
    rec = tmp_path / "records" / "rec0.csv"
    lines = rec.read_text().splitlines()
    t, a = lines[5].split(",")
    lines[5] = f"{t},{float(a) * 1.001!r}"
    rec.write_text("\n".join(lines) + "\n")
    ids2 = {r.run_id for r in expand(load_study(tmp_path / "study.toml"))}
    assert len(ids & ids2) == 6  # rec1's runs unchanged, rec0's all new


def test_sampling_reproducible_with_seed_and_independent_of_order(tmp_path: Path) -> None:
    p = make_study(tmp_path)
    base = {r.run_id: r for r in expand(load_study(p))}
    # more stripes and another record: the existing runs keep their ids and samples
    text = p.read_text().replace("stripes = [0.1, 0.3, 0.5]", "stripes = [0.5, 0.2, 0.1, 0.3]")
    p2 = tmp_path / "more.toml"
    p2.write_text(text)
    write_records(tmp_path / "records", 3)
    more = {r.run_id: r for r in expand(load_study(p2))}
    assert len(more) == 3 * 2 * 4
    assert set(base) <= set(more)
    for k, r in base.items():
        assert more[k].mu_static == r.mu_static
    # another seed: other samples
    p3 = tmp_path / "seed.toml"
    p3.write_text(p.read_text().replace("seed = 7", "seed = 8"))
    mus = {r.mu_static for r in base.values()}
    assert not mus & {r.mu_static for r in expand(load_study(p3))}


@pytest.mark.parametrize("dist, check", [
    ('dist = "lognormal"\nmedian = 0.4\ndispersion = 0.2', "lognormal"),
    ('dist = "uniform"\nlow = 0.2\nhigh = 0.5', "uniform"),
    ('dist = "truncnormal"\nmean = 0.4\nstd = 0.2\nlow = 0.3\nhigh = 0.6', "truncnormal"),
])
def test_samples_follow_the_distribution(tmp_path: Path, dist: str, check: str) -> None:
    body = f"""
racks = ["rack.toml"]
[records]
folder = "records"
[intensity]
stripes = [1.0]
[friction]
{dist}
samples = 400
dynamic_ratio = 0.8
"""
    runs = expand(load_study(make_study(tmp_path, body, n_records=1)))
    mu = np.array([r.mu_static for r in runs])
    assert mu.size == 400
    assert np.allclose([r.mu_dynamic for r in runs], 0.8 * mu)
    if check == "lognormal":
        ln = np.log(mu)
        assert abs(ln.mean() - math.log(0.4)) < 4 * 0.2 / math.sqrt(400)
        assert abs(ln.std() - 0.2) < 4 * 0.2 / math.sqrt(2 * 400)
    elif check == "uniform":
        assert mu.min() >= 0.2 and mu.max() <= 0.5
        assert abs(mu.mean() - 0.35) < 4 * 0.3 / math.sqrt(12 * 400)
    else:
        assert mu.min() >= 0.3 and mu.max() <= 0.6
        assert mu.min() < 0.32 and mu.max() > 0.58


def test_ida_grid_g_units_and_occupancy(tmp_path: Path) -> None:
    body = """
racks = ["rack.toml"]
seed = 3
[records]
folder = "records"
[intensity]
unit = "g"
ida = {start = 0.1, step = 0.1, stop = 0.5}
[friction]
values = [0.3, 0.5]
dynamic_ratio = 0.9
[occupancy]
fractions = [1.0, 0.5]
"""
    spec = load_study(make_study(tmp_path, body, n_records=1))
    runs = expand(spec)
    assert len(runs) == 2 * 2 * 5
    assert {r.stripe for r in runs} == {-1}
    assert sorted({r.im_target for r in runs}) == pytest.approx([k * 0.1 * G for k in (1, 2, 3,
                                                                                        4, 5)])
    assert {(r.mu_static, r.mu_dynamic) for r in runs} == {(0.3, 0.3 * 0.9), (0.5, 0.5 * 0.9)}
    from seisrack.studies.expand import plan

    pl = plan(spec)
    kept = [v for (_, occ), v in pl.patterns.items() if occ == 0.5]
    assert len(kept) == 1 and len(kept[0]) == 2  # 0.5 of 4 pallets
    assert plan(spec).patterns == pl.patterns


def test_sa_measure_uses_first_period(tmp_path: Path) -> None:
    body = """
racks = ["rack.toml"]
[records]
folder = "records"
[intensity]
measure = "sa"
stripes = [2.0, 4.0]
[friction]
values = [0.4]
"""
    runs = expand(load_study(make_study(tmp_path, body, n_records=1)))
    t1 = modal_analysis(compile_rack(load_rack(tmp_path / "rack.toml")), n_modes=1).periods[0]
    from seisrack.motion import read_record

    rec = read_record(tmp_path / "records" / "rec0.csv")
    sa = response_spectrum(rec.accel, rec.dt, [t1], 0.05).psa[0]
    for r in runs:
        assert r.period_s == pytest.approx(t1, rel=1e-12)
        assert r.scale_factor == pytest.approx(r.im_target / sa, rel=1e-12)


BASE = """
racks = ["rack.toml"]
[records]
folder = "records"
[intensity]
stripes = [1.0, 2.0]
[friction]
values = [0.4]
"""


@pytest.mark.parametrize("edit, field", [
    (('racks = ["rack.toml"]', 'racks = ["nope.toml"]'), "racks[0]"),
    (('folder = "records"', 'folder = "missing"'), "records.folder"),
    (('folder = "records"', 'builtin = ["kobe"]'), "records.builtin[0]"),
    (("stripes = [1.0, 2.0]", "stripes = []"), "intensity.stripes"),
    (("stripes = [1.0, 2.0]", "stripes = [1.0]\nida = {start = 1, step = 1, stop = 2}"),
     "intensity.stripes"),
    (("stripes = [1.0, 2.0]", "stripes = [1.0, -2.0]"), "intensity.stripes[1]"),
    (("values = [0.4]", 'dist = "lognormal"\nmedian = 0.4\ndispersion = 0.0'),
     "friction.dispersion"),
    (("values = [0.4]", 'dist = "lognormal"\nmedian = -0.4\ndispersion = 0.2'),
     "friction.median"),
    (("values = [0.4]", 'dist = "uniform"\nlow = 0.5\nhigh = 0.3'), "friction.high"),
    (("values = [0.4]", 'dist = "truncnormal"\nmean = 0.4\nstd = 0\nlow = 0.1\nhigh = 0.6'),
     "friction.std"),
    (("values = [0.4]", 'dist = "truncnormal"\nmean = 0.4\nstd = 0.01\nlow = 2\nhigh = 3'),
     "friction.low"),
    (("values = [0.4]", 'dist = "weibull"'), "friction.dist"),
    (("values = [0.4]", "values = [0.4]\ndynamic_ratio = 1.5"), "friction.dynamic_ratio"),
    (("values = [0.4]", "values = [0.4, 0.4]"), "friction.values"),
    (('racks = ["rack.toml"]', 'racks = ["rack.toml"]\nsteps = 3'), "steps"),
    (('racks = ["rack.toml"]', 'racks = ["rack.toml"]\n[occupancy]\nfractions = [1.5]'),
     "occupancy.fractions[0]"),
    (('racks = ["rack.toml"]', 'racks = ["rack.toml"]\ndt = 0.003'), "dt"),
    (("stripes = [1.0, 2.0]", "stripes = [1.0, 2000.0]"), "intensity"),
])
def test_bad_input_is_named_before_any_run(tmp_path: Path, edit: tuple[str, str],
                                           field: str) -> None:
    p = make_study(tmp_path, BASE.replace(*edit))
    with pytest.raises(InputError) as info:
        expand(load_study(p))
    assert info.value.field == field, str(info.value)
    assert info.value.allowed


def test_unreadable_and_zero_records(tmp_path: Path) -> None:
    p = make_study(tmp_path, BASE)
    bad = tmp_path / "records" / "zzz.csv"
    bad.write_text("time,accel\n0,1\n0.01,oops\n")
    with pytest.raises(InputError) as info:
        expand(load_study(p))
    assert info.value.field == "records.folder" and "zzz.csv" in str(info.value)
    bad.unlink()
    write_record_csv(Record(np.zeros(301), 0.01, name="flat"), tmp_path / "records" / "flat.csv")
    with pytest.raises(InputError) as info:
        expand(load_study(p))
    assert "flat" in info.value.field and "non-zero intensity" in str(info.value)


def test_cli_bad_input_exit_2_no_traceback(tmp_path: Path) -> None:
    p = make_study(tmp_path, BASE.replace("stripes = [1.0, 2.0]", "stripes = []"))
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "seisrack", "study", str(p), "--out", str(out)],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr and "intensity.stripes" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_cli_dry_run_prints_the_table(tmp_path: Path) -> None:
    p = make_study(tmp_path)
    proc = subprocess.run([sys.executable, "-m", "seisrack", "study", str(p), "--dry-run"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "12 runs" in proc.stdout
    assert proc.stdout.count(": 4 runs") == 3  # runs per stripe
    first = expand(load_study(p))[0].run_id
    assert first in proc.stdout


def test_example_study_has_at_least_60_runs() -> None:
    spec = load_study(ROOT / "examples" / "study_paper_rack.toml")
    runs = expand(spec)
    assert len(runs) >= 60
    assert len({r.stripe for r in runs}) == 3 and spec.friction.kind == "lognormal"
    assert {r.record for r in runs} >= {"elcentro_1940_ns"}
