"""IDA with a stop rule (issue 13 item 1): what is checked.

A small IDA study of the paper rack (2 short records x 2 low friction values = 4 curves of 6
PGA levels) is run once without a rule (the reference) and once with ``stop_when =
"sliding"``, its threshold chosen from the reference so that the rule holds mid-curve:

- each curve stops at the first level where the reference's peak sliding exceeds the
  threshold; the runs up to it equal the reference's (bit for bit, all columns but
  ``wall_time_s``), the runs above are "skipped" with the stop level and the rule as reason,
  NaN peaks; curves that never exceed run every level;
- the table is identical on 1 worker, 2 workers (curves never split across batches) and a Dask
  LocalCluster, and after a worker killed in the middle of a curve;
- a second call runs nothing and skips nothing (every skipped run counted once);
- ``summarize``: ``runs_total``, ``runs_ok``, ``runs_failed``, ``runs_skipped``, and IDA
  capacities for the rule's threshold equal the reference's (the crossing lies below the stop),
  and a state not reached by a stopped curve has the stop level as capacity;
- removing the rule runs the skipped levels and gives the reference table; extending the grid
  upwards records the new levels above a stop as skipped, without a run, and equals a direct
  run of the extended study;
- bad input (a rule with stripes, outside ``ida``, an unknown rule, ``sliding_m <= 0``, a
  missing or superfluous ``sliding_m``) is an InputError naming the key, before any run.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pyarrow as pa
import pytest

from seisrack.errors import InputError
from seisrack.studies import expand, load_study, read_runs, run_study
from seisrack.studies.executors import TEST_HOOK_ENV
from seisrack.studies.run import make_batches
from test_study_spec import make_study

N_LEVELS = 6
BODY = """
racks = ["rack.toml"]
seed = 3
[records]
folder = "records"
[intensity]
measure = "pga"
unit = "g"
ida = {{start = 0.1, step = 0.1, stop = {stop}{rule}}}
[friction]
values = [0.1, 0.15]
"""


def _comparable(table: pa.Table) -> dict:
    """Every column but ``wall_time_s``; NaN as "nan" so that equal tables compare equal."""
    def fix(v):  # noqa: ANN001, ANN202
        return "nan" if isinstance(v, float) and math.isnan(v) else v

    return {k: [fix(v) for v in col]
            for k, col in table.drop_columns(["wall_time_s"]).to_pydict().items()}


def _curves(table: pa.Table) -> dict:
    """(record, mu_static) -> rows sorted by IM."""
    out: dict = {}
    for row in table.to_pylist():
        out.setdefault((row["record"], row["mu_static"]), []).append(row)
    return {k: sorted(v, key=lambda w: w["im_target"]) for k, v in out.items()}


def _study(folder: Path, rule: str = "", stop: float = 0.6) -> Path:
    return make_study(folder, BODY.format(stop=stop, rule=rule))


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, pa.Table]:
    folder = tmp_path_factory.mktemp("ida_full")
    out = folder / "out"
    s = run_study(load_study(_study(folder)), out, workers=1, progress=False)
    assert (s.runs_total, s.runs_ok, s.runs_skipped) == (4 * N_LEVELS, 4 * N_LEVELS, 0)
    return out, read_runs(out)


@pytest.fixture(scope="module")
def threshold(reference: tuple[Path, pa.Table]) -> float:
    """A sliding threshold crossed mid-curve (between levels 3 and 4) by the first curve."""
    curves = _curves(reference[1])
    s = [w["peak_sliding_max_m"] for w in next(iter(curves.values()))]
    assert s[2] < s[3], f"sliding should grow with the level: {s}"
    return 0.5 * (s[2] + s[3])


def _rule(threshold: float) -> str:
    return f', stop_when = "sliding", sliding_m = {threshold!r}'


@pytest.fixture(scope="module")
def stopped(threshold: float, tmp_path_factory: pytest.TempPathFactory
            ) -> tuple[Path, Path, pa.Table]:
    folder = tmp_path_factory.mktemp("ida_stop")
    study = _study(folder, _rule(threshold))
    out = folder / "out"
    s = run_study(load_study(study), out, workers=1, progress=False)
    table = read_runs(out)
    status = table.column("status").to_pylist()
    assert s.runs_total == 4 * N_LEVELS and s.runs_failed == 0
    assert (s.runs_ok, s.runs_skipped) == (status.count("ok"), status.count("skipped"))
    assert s.runs_executed == s.runs_ok
    return study, out, table


def test_curves_stop_at_the_first_exceedance(reference, threshold, stopped) -> None:
    ref = _curves(reference[1])
    got = _curves(stopped[2])
    assert got.keys() == ref.keys()
    stops = []
    for key, rows in got.items():
        full = ref[key]
        above = [i for i, w in enumerate(full) if w["peak_sliding_max_m"] > threshold]
        k = above[0] if above else len(full) - 1
        stops.append(k if above else None)
        for w, f in zip(rows[:k + 1], full[:k + 1], strict=True):  # run: as without the rule
            w, f = dict(w), dict(f)
            w.pop("wall_time_s"), f.pop("wall_time_s")
            assert w == f
        for w in rows[k + 1:]:  # above the stop level: not run
            assert w["status"] == "skipped"
            assert w["error"] == (f"IDA stopped at IM = {full[k]['im_target']!r} m/s² by rule "
                                  f'stop_when = "sliding", sliding_m = {threshold!r}')
            assert math.isnan(w["peak_sliding_max_m"]) and w["pallet_peak_sliding_m"] == []
            assert w["wall_time_s"] == 0.0 and w["stripe"] == -1
    # the first curve stops mid-curve, on level 4 of 6 (the threshold is between 3 and 4)
    assert stops[0] == 3
    assert any(s is not None and s < N_LEVELS - 1 for s in stops)


def test_two_workers_same_table(stopped, tmp_path: Path) -> None:
    study, _, table = stopped
    s = run_study(load_study(study), tmp_path / "a", workers=2, batch_size=2, progress=False)
    assert s.workers == 2
    assert _comparable(read_runs(tmp_path / "a")) == _comparable(table)
    run_study(load_study(study), tmp_path / "b", workers=2, progress=False)
    assert _comparable(read_runs(tmp_path / "b")) == _comparable(table)


def test_batches_never_split_a_curve(stopped) -> None:
    runs = expand(load_study(stopped[0]))
    for size in (1, 2, 7, 13, None):
        batches = make_batches(runs, 2, size, by_curve=True)
        assert sorted(r.run_id for b in batches for r in b) == sorted(r.run_id for r in runs)
        where = {}
        for i, b in enumerate(batches):
            for r in b:
                where.setdefault((r.record, r.mu_static), set()).add(i)
        assert all(len(v) == 1 for v in where.values())


def test_resume_after_completion_runs_nothing(stopped) -> None:
    study, out, table = stopped
    s = run_study(load_study(study), out, workers=2, progress=False)
    assert (s.runs_executed, s.runs_skipped, s.runs_already_stored) == (0, 0, 4 * N_LEVELS)
    assert s.part_files_written == 0
    assert _comparable(read_runs(out)) == _comparable(table)


def test_summary_counts_and_capacities(reference, threshold, stopped) -> None:
    from seisrack.studies.summary import summarize

    table = stopped[2]
    status = table.column("status").to_pylist()
    s = summarize(stopped[1], d_slide=[threshold], n_boot=20, write=False)
    assert s["runs_total"] == 4 * N_LEVELS and s["runs_failed"] == 0
    assert (s["runs_ok"], s["runs_skipped"]) == (status.count("ok"), status.count("skipped"))
    assert s["runs_skipped"] > 0 and s["failure_reasons"] == {}
    full = summarize(reference[0], d_slide=[threshold], n_boot=20, write=False)
    name = f"sliding>{threshold:g}m"
    cap = s["groups"][0]["ida"]["fragility"][name]["capacities"]
    assert cap == full["groups"][0]["ida"]["fragility"][name]["capacities"]
    curves = s["groups"][0]["ida"]["curves"]
    assert len(curves) == 4
    assert any(cv["stopped_im"] is not None for cv in curves)
    falls = s["groups"][0]["ida"]["fragility"]["any_fall"]["capacities"]
    for cv, c in zip(curves, falls, strict=True):
        if cv["stopped_im"] is not None:  # ends one step below its first skipped level
            assert cv["stopped_im"] > cv["im"][-1] and len(cv["im"]) < N_LEVELS
            if not any(cv["any_fall"]):  # collapse convention: capacity = the stop level
                assert c == cv["im"][-1]


def test_removing_the_rule_runs_the_skipped_levels(reference, stopped, tmp_path: Path) -> None:
    import shutil

    _, out, table = stopped
    n_skipped = table.column("status").to_pylist().count("skipped")
    shutil.copytree(out, tmp_path / "out")
    s = run_study(load_study(_study(tmp_path)), tmp_path / "out", workers=2, progress=False)
    assert s.runs_executed == n_skipped and s.runs_skipped == 0
    assert _comparable(read_runs(tmp_path / "out")) == _comparable(reference[1])


def test_extended_grid_skips_above_a_stored_stop(threshold, stopped, tmp_path: Path) -> None:
    small = run_study(load_study(_study(tmp_path / "s", _rule(threshold), stop=0.4)),
                      tmp_path / "out", workers=1, progress=False)
    assert small.runs_total == 4 * 4
    s = run_study(load_study(_study(tmp_path / "s", _rule(threshold))), tmp_path / "out",
                  workers=2, progress=False)
    assert s.runs_already_stored == 16 and s.runs_total == 4 * N_LEVELS
    assert s.runs_ok + s.runs_skipped == 8
    assert _comparable(read_runs(tmp_path / "out")) == _comparable(stopped[2])


def test_worker_killed_mid_curve(stopped, tmp_path: Path,
                                 monkeypatch: pytest.MonkeyPatch) -> None:
    study, _, table = stopped
    victim = next(w for w in table.to_pylist() if w["status"] == "ok"
                  and w["im_target"] > 0.15 * 9.80665)["run_id"]
    monkeypatch.setenv(TEST_HOOK_ENV, json.dumps({"kill_once": [victim,
                                                                str(tmp_path / "killed")]}))
    run_study(load_study(study), tmp_path / "out", workers=2, progress=False)
    assert (tmp_path / "killed").exists()
    assert _comparable(read_runs(tmp_path / "out")) == _comparable(table)


@pytest.mark.slow
def test_dask_same_table(stopped, tmp_path: Path) -> None:
    pytest.importorskip("dask.distributed")
    study, _, table = stopped
    s = run_study(load_study(study), tmp_path, executor="dask", workers=2, progress=False)
    assert s.executor == "dask"
    assert _comparable(read_runs(tmp_path)) == _comparable(table)


@pytest.mark.parametrize(("intensity", "field"), [
    ('stripes = [1.0, 2.0]\nstop_when = "fall"', "intensity.stop_when"),
    ('ida = {start = 1, step = 1, stop = 3}\nsliding_m = 0.2', "intensity.sliding_m"),
    ('ida = {start = 1, step = 1, stop = 3, stop_when = "collapse"}', "intensity.ida.stop_when"),
    ('ida = {start = 1, step = 1, stop = 3, stop_when = "sliding", sliding_m = 0}',
     "intensity.ida.sliding_m"),
    ('ida = {start = 1, step = 1, stop = 3, stop_when = "sliding", sliding_m = -0.1}',
     "intensity.ida.sliding_m"),
    ('ida = {start = 1, step = 1, stop = 3, stop_when = "sliding"}', "intensity.ida.sliding_m"),
    ('ida = {start = 1, step = 1, stop = 3, stop_when = "fall", sliding_m = 0.1}',
     "intensity.ida.sliding_m"),
    ('ida = {start = 1, step = 1, stop = 3, sliding_m = 0.1}', "intensity.ida.sliding_m"),
])
def test_bad_stop_rule(tmp_path: Path, intensity: str, field: str) -> None:
    body = f'racks = ["rack.toml"]\n[records]\nfolder = "records"\n[intensity]\n{intensity}\n'
    with pytest.raises(InputError) as exc:
        load_study(make_study(tmp_path, body, n_records=1))
    assert field in str(exc.value)
    assert not (tmp_path / "out").exists()


def test_fall_rule_parsed(tmp_path: Path) -> None:
    body = ('racks = ["rack.toml"]\n[records]\nfolder = "records"\n[intensity]\n'
            'ida = {start = 1, step = 1, stop = 3, stop_when = "fall"}\n')
    spec = load_study(make_study(tmp_path, body, n_records=1))
    rule = spec.intensity.ida_stop
    assert rule.when == "fall" and rule.label == 'stop_when = "fall"'
    assert rule.holds({"status": "ok", "any_fall": True, "peak_sliding_max_m": 0.0})
    assert not rule.holds({"status": "ok", "any_fall": False, "peak_sliding_max_m": 9.0})
    assert not rule.holds({"status": "failed", "any_fall": True, "peak_sliding_max_m": 9.0})
