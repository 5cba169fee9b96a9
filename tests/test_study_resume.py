"""Killing a study and running it again (issue 13): what is checked.

- driver killed: a study runs in a subprocess (its own process group, one run per part file,
  slowed by the test hook); once some part files exist the whole group (driver and workers) is
  killed with SIGKILL, as a dead machine would be. Every part file left is complete; running the
  study again runs only the missing runs and the table is identical (all columns but
  ``wall_time_s``) to an uninterrupted run, with no run id twice;
- Ctrl-C: SIGINT to the driver flushes the finished rows and exits; the resumed table is
  identical too;
- worker killed: one run kills its worker process with SIGKILL (once, through the test hook);
  the pool is rebuilt, the unfinished batches resubmitted, and the table is identical with the
  killed run recorded once.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from seisrack.studies import load_study, read_runs, run_study
from seisrack.studies.executors import TEST_HOOK_ENV
from seisrack.studies.store import part_files
from test_study_spec import make_study

EXTRA_STRIPES = ("stripes = [0.1, 0.3, 0.5]", "stripes = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]")

# The driver restores Python's Ctrl-C handler: a process started in the background by a
# non-interactive shell (a CI runner, `cmd &`) inherits SIGINT as ignored, unlike a terminal.
DRIVER = """
import signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
from seisrack.studies import load_study, run_study
run_study(load_study(sys.argv[1]), sys.argv[2], workers=1, batch_size=1, flush_rows=1,
          progress=False)
"""


def _comparable(table: pa.Table) -> dict:
    return table.drop_columns(["wall_time_s"]).to_pydict()


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> Path:
    p = make_study(tmp_path_factory.mktemp("study"))
    p.write_text(p.read_text().replace(*EXTRA_STRIPES))  # 24 runs
    return p


@pytest.fixture(scope="module")
def reference(study: Path, tmp_path_factory: pytest.TempPathFactory) -> pa.Table:
    out = tmp_path_factory.mktemp("ref")
    s = run_study(load_study(study), out, workers=2, progress=False)
    assert s.runs_ok == 24
    return read_runs(out)


def _start_driver(study: Path, out: Path) -> subprocess.Popen:
    env = dict(os.environ, **{TEST_HOOK_ENV: json.dumps({"sleep": 0.15})})
    return subprocess.Popen([sys.executable, "-c", DRIVER, str(study), str(out)], env=env,
                            start_new_session=True, stderr=subprocess.PIPE, text=True)


def _wait_for_parts(proc: subprocess.Popen, out: Path, n: int, timeout: float = 60.0) -> None:
    t0 = time.monotonic()
    while len(part_files(out)) < n:
        if proc.poll() is not None:
            pytest.fail(f"the study ended before it was killed: {proc.stderr.read()}")
        if time.monotonic() - t0 > timeout:
            os.killpg(proc.pid, signal.SIGKILL)
            pytest.fail("no part file appeared")
        time.sleep(0.02)


def _check_resumed(study: Path, out: Path, reference: pa.Table) -> None:
    for p in part_files(out):  # every part left is complete and readable
        assert pq.read_table(p).num_rows >= 1
    stored = read_runs(out).num_rows
    assert 0 < stored < 24
    s = run_study(load_study(study), out, workers=2, progress=False)
    assert s.runs_already_stored == stored and s.runs_executed == 24 - stored
    table = read_runs(out)
    ids = table.column("run_id").to_pylist()
    assert len(ids) == len(set(ids)) == 24
    assert _comparable(table) == _comparable(reference)
    # nothing counted twice even before deduplication
    n_raw = sum(pq.read_table(p, columns=["run_id"]).num_rows for p in part_files(out))
    assert n_raw == 24


def test_driver_killed_then_resumed(study: Path, reference: pa.Table, tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = _start_driver(study, out)
    _wait_for_parts(proc, out, 3)
    os.killpg(proc.pid, signal.SIGKILL)  # the driver and its workers: a dead machine
    proc.wait(timeout=30)
    _check_resumed(study, out, reference)


def test_ctrl_c_then_resumed(study: Path, reference: pa.Table, tmp_path: Path) -> None:
    out = tmp_path / "out"
    proc = _start_driver(study, out)
    _wait_for_parts(proc, out, 2)
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C reaches the whole foreground group
    try:
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode != 0
    _check_resumed(study, out, reference)


def test_worker_killed_by_signal(study: Path, reference: pa.Table, tmp_path: Path,
                                 monkeypatch: pytest.MonkeyPatch) -> None:
    victim = reference.column("run_id")[7].as_py()
    flag = tmp_path / "killed"
    monkeypatch.setenv(TEST_HOOK_ENV, json.dumps({"kill_once": [victim, str(flag)]}))
    out = tmp_path / "out"
    s = run_study(load_study(study), out, workers=2, batch_size=3, progress=False)
    assert flag.exists()  # the worker was killed
    assert (s.runs_executed, s.runs_ok, s.runs_failed) == (24, 24, 0)
    table = read_runs(out)
    assert _comparable(table) == _comparable(reference)
    n_raw = sum(pq.read_table(p, columns=["run_id"]).num_rows for p in part_files(out))
    assert n_raw == 24
