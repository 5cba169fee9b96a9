"""Running a study and its store (issue 13): what is checked.

- the store's schema is the contract the post-processing reads (column names and types);
- one small study (12 runs of the paper rack, 3 s records) on 1 worker, on 2 workers and on a
  Dask LocalCluster of 2 workers gives identical tables, bit for bit, in every column but
  ``wall_time_s``, and so does a cluster given by its scheduler address;
- every row is consistent with a direct ``run_rack`` of the same scaled record and friction
  (peak sliding, base shear, falls);
- a run that fails (made to fail through the test hook) is a row with status "failed", its
  reason and NaN peaks, and the study goes on;
- ``read_runs`` keeps one row per run id when a run is stored twice, sorted by id;
- ``seisrack study ... --json`` runs the study and a second call runs nothing (resume);
  ``seisrack study summary DIR --json`` reaches the summary with the run counts.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pyarrow as pa
import pytest

from seisrack.studies import COLUMNS, expand, load_study, read_runs, run_study
from seisrack.studies.executors import TEST_HOOK_ENV
from seisrack.studies.store import part_files, write_part
from test_study_spec import make_study


def _comparable(table: pa.Table) -> dict:
    return table.drop_columns(["wall_time_s"]).to_pydict()


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_study(tmp_path_factory.mktemp("study"))


@pytest.fixture(scope="module")
def reference(study: Path, tmp_path_factory: pytest.TempPathFactory) -> pa.Table:
    out = tmp_path_factory.mktemp("ref")
    s = run_study(load_study(study), out, workers=1, progress=False)
    assert (s.runs_total, s.runs_executed, s.runs_ok, s.runs_failed) == (12, 12, 12, 0)
    return read_runs(out)


def test_schema_is_the_contract(reference: pa.Table) -> None:
    assert reference.schema.names == [c for c, _ in COLUMNS]
    types = {f.name: str(f.type) for f in reference.schema}
    assert types["run_id"] == "string" and types["stripe"] == "int64"
    assert types["pallet_peak_sliding_m"] == "list<item: double>"
    assert types["any_fall"] == "bool" and types["n_fall"] == "int64"
    assert reference.num_rows == 12
    ids = reference.column("run_id").to_pylist()
    assert ids == sorted(ids) and len(set(ids)) == 12


def test_rows_match_a_direct_run(study: Path, reference: pa.Table) -> None:
    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.model.spec import with_friction
    from seisrack.motion import Record, read_record

    runs = {r.run_id: r for r in expand(load_study(study))}
    rows = reference.to_pylist()
    for row in rows[:3]:
        r = runs[row["run_id"]]
        rec = read_record(study.parent / "records" / f"{r.record}.csv")
        model = compile_rack(with_friction(load_rack(study.parent / "rack.toml"), r.mu_static,
                                           r.mu_dynamic))
        res = run_rack(model, Record(rec.accel * r.scale_factor, rec.dt), dt=0.005)
        assert row["peak_sliding_max_m"] == res.pallet_peak_sliding().max()
        assert row["pallet_peak_sliding_m"] == res.pallet_peak_sliding().tolist()
        assert row["base_shear_N"] == res.peaks()["base_shear_N"]
        assert row["n_fall"] == len(res.pallets_at_risk())
        assert row["drift_ratio_max"] == pytest.approx(res.peaks()["beam_displacement_m"] / 2.0)
        assert row["mu_static"] == r.mu_static and row["stripe"] == r.stripe
    # the stripes slide more as the intensity grows
    by_stripe = [np.mean([w["peak_sliding_max_m"] for w in rows if w["stripe"] == k])
                 for k in range(3)]
    assert by_stripe[0] <= by_stripe[1] <= by_stripe[2] and by_stripe[2] > 0


def test_two_workers_same_table(study: Path, reference: pa.Table, tmp_path: Path) -> None:
    s = run_study(load_study(study), tmp_path, workers=2, batch_size=2, progress=False)
    assert s.runs_executed == 12 and s.workers == 2
    assert len(part_files(tmp_path)) >= 1
    assert _comparable(read_runs(tmp_path)) == _comparable(reference)


@pytest.mark.slow
def test_dask_local_cluster_same_table(study: Path, reference: pa.Table,
                                       tmp_path: Path) -> None:
    pytest.importorskip("dask.distributed")
    s = run_study(load_study(study), tmp_path, executor="dask", workers=2, batch_size=3,
                  progress=False)
    assert s.executor == "dask" and s.runs_ok == 12
    assert _comparable(read_runs(tmp_path)) == _comparable(reference)


def test_failed_run_is_recorded_and_study_continues(study: Path, reference: pa.Table,
                                                   tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    victim = reference.column("run_id")[4].as_py()
    monkeypatch.setenv(TEST_HOOK_ENV, json.dumps({"fail": [victim]}))
    s = run_study(load_study(study), tmp_path, workers=2, progress=False)
    assert (s.runs_ok, s.runs_failed) == (11, 1)
    rows = {r["run_id"]: r for r in read_runs(tmp_path).to_pylist()}
    bad = rows[victim]
    assert bad["status"] == "failed" and "made to fail" in bad["error"]
    assert math.isnan(bad["peak_sliding_max_m"]) and math.isnan(bad["base_shear_N"])
    ref = {r["run_id"]: r for r in reference.to_pylist()}
    for k, row in rows.items():
        if k != victim:
            assert row["status"] == "ok" and row["error"] == ""
            assert row["base_shear_N"] == ref[k]["base_shear_N"]


def test_read_runs_deduplicates(reference: pa.Table, tmp_path: Path) -> None:
    rows = reference.to_pylist()
    write_part(tmp_path, rows[:8])
    write_part(tmp_path, rows[5:])
    assert len(part_files(tmp_path)) == 2
    t = read_runs(tmp_path)
    assert _comparable(t) == _comparable(reference)


def test_cli_runs_then_resumes(study: Path, reference: pa.Table, tmp_path: Path,
                               capsys: pytest.CaptureFixture) -> None:
    from seisrack.cli import main

    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    assert first["runs_executed"] == 12 and first["runs_already_stored"] == 0
    assert main(["study", str(study), "--out", str(out), "--json"]) == 0
    second = json.loads(capsys.readouterr().out)
    assert second["runs_executed"] == 0 and second["runs_already_stored"] == 12
    doc = json.loads((out / "study.json").read_text())
    assert len(doc["runs"]) == 12 and "stripes" in doc["study_toml"]
    assert _comparable(read_runs(out)) == _comparable(reference)


@pytest.mark.slow
def test_dask_scheduler_address_same_table(study: Path, reference: pa.Table,
                                           tmp_path: Path) -> None:
    distributed = pytest.importorskip("dask.distributed")
    # a scheduler this test starts itself, on the loopback interface only
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        s = run_study(load_study(study), tmp_path, scheduler=cluster.scheduler_address,
                      progress=False)
    assert s.executor == "dask" and s.runs_ok == 12
    assert _comparable(read_runs(tmp_path)) == _comparable(reference)


def test_cli_study_summary_dispatch(study: Path, tmp_path: Path,
                                    capsys: pytest.CaptureFixture) -> None:
    pytest.importorskip("seisrack.studies.summary")
    from seisrack.cli import main

    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--json"]) == 0
    capsys.readouterr()
    assert main(["study", "summary", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["runs_total"] == 12 and doc["runs_ok"] == 12 and doc["runs_failed"] == 0


def test_local_workers_are_bounded(study: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                   capsys: pytest.CaptureFixture) -> None:
    """--workers 300 on 2 cores forked 300 processes for a 6-run study (9 GB, 12 times
    slower). At most LOCAL_WORKERS_PER_CPU per CPU, and no more processes than batches."""
    import os

    from seisrack.cli import main
    from seisrack.errors import InputError
    from seisrack.studies import executors

    monkeypatch.setattr(os, "cpu_count", lambda: 2)
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--workers", "300", "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--workers" and "at most 8 local workers" in err["allowed"]
    assert not out.exists()
    with pytest.raises(InputError, match="workers"):
        run_study(load_study(study), tmp_path / "api", workers=9, progress=False)
    sizes = []
    real = executors.LocalExecutor.__init__

    def spy(self, pl, n, *args, **kw):  # noqa: ANN001, ANN002, ANN003, ANN202
        sizes.append(n)
        real(self, pl, n, *args, **kw)

    monkeypatch.setattr(executors.LocalExecutor, "__init__", spy)
    s = run_study(load_study(study), tmp_path / "b", workers=8, batch_size=6, progress=False)
    assert s.runs_ok == 12 and sizes == [2]  # 12 runs in batches of 6: two processes
