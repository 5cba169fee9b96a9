"""Study stores that survive (issue 23, class 4).

- a part file that is truncated (a full disk), garbage, or foreign (a Parquet file of another
  schema) is named, moved to ``runs/quarantine/`` with a note of why (never deleted), and its
  runs are recomputed on resume: the table is then identical to an uninterrupted run's;
- ``study summary`` on such a store names the file and says how to recompute it;
- a full disk while a part is written is the one-paragraph error naming the file, with no
  temporary file left; a read-only study folder likewise, before any run;
- after ``kill -9`` of the driver, its pool workers exit by themselves (no orphans);
- ``--scheduler`` pointed at something that is not a Dask scheduler (a TCP server this test
  starts on 127.0.0.1 that answers like an HTTP server) is a clear error within the timeout;

"""

from __future__ import annotations

import errno
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from seisrack.cli import main
from seisrack.studies import load_study, read_runs, run_study
from seisrack.studies.executors import TEST_HOOK_ENV
from seisrack.studies.store import QUARANTINE_DIR, StoreError, check_parts, part_files
from test_study_spec import make_study

ROOT = Path(__file__).resolve().parents[1]


def _comparable(table: pa.Table) -> dict:
    return table.drop_columns(["wall_time_s"]).to_pydict()


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_study(tmp_path_factory.mktemp("study"))  # 12 runs


@pytest.fixture(scope="module")
def reference(study: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, pa.Table]:
    out = tmp_path_factory.mktemp("ref")
    # one run per part file, so that damaging one part loses exactly its run
    s = run_study(load_study(study), out, workers=2, batch_size=1, flush_rows=1,
                  progress=False)
    assert s.runs_ok == 12 and len(part_files(out)) == 12
    return out, read_runs(out)


def _damage(path: Path, how: str) -> None:
    if how == "truncated":
        path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])
    elif how == "garbage":
        path.write_bytes(b"this is not a parquet file\n" * 20)
    else:  # foreign: a sound Parquet file of another schema
        pq.write_table(pa.table({"run_id": ["x"], "temperature": [21.5]}), path)


@pytest.mark.parametrize("how", ["truncated", "garbage", "foreign"])
def test_bad_part_is_set_aside_and_its_runs_recomputed(study, reference, tmp_path, how,
                                                       capsys):
    ref_dir, ref_table = reference
    out = tmp_path / "store"
    shutil.copytree(ref_dir, out)
    bad = part_files(out)[3]
    lost = set(pq.read_table(bad, columns=["run_id"]).column(0).to_pylist())
    _damage(bad, how)
    before = bad.read_bytes()
    # the summary names the file and says how to recompute it (no traceback)
    assert main(["study", "summary", str(out), "--no-plots", "--boot", "0"]) == 2
    err = capsys.readouterr().err
    assert bad.name in err and "quarantine" in err and "seisrack study" in err
    assert "internal error" not in err and err.count("\n") == 1
    kept = out / "runs" / QUARANTINE_DIR / bad.name
    assert kept.read_bytes() == before  # moved, never deleted
    assert bad.name in (kept.parent / (bad.name + ".reason.txt")).read_text()
    # the resume recomputes exactly the runs of that file
    s = run_study(load_study(study), out, workers=1, progress=False)
    assert s.runs_executed == len(lost) and s.parts_set_aside == ()
    assert _comparable(read_runs(out)) == _comparable(ref_table)


def test_resume_sets_bad_parts_aside_itself(study, reference, tmp_path):
    ref_dir, ref_table = reference
    out = tmp_path / "store"
    shutil.copytree(ref_dir, out)
    for p in part_files(out)[:2]:
        _damage(p, "garbage")
    s = run_study(load_study(study), out, workers=1, progress=False)
    assert len(s.parts_set_aside) == 2 and "quarantine" in s.parts_set_aside[0]
    assert s.runs_executed == 2
    assert _comparable(read_runs(out)) == _comparable(ref_table)
    assert len(list((out / "runs" / QUARANTINE_DIR).glob("*.parquet"))) == 2
    assert check_parts(out) == []


def test_reader_meeting_a_bad_part_names_it(reference, tmp_path):
    ref_dir, _ = reference
    out = tmp_path / "store"
    shutil.copytree(ref_dir, out)
    bad = part_files(out)[0]
    _damage(bad, "truncated")
    with pytest.raises(StoreError, match=bad.name):
        read_runs(out)
    assert not bad.exists() and (out / "runs" / QUARANTINE_DIR / bad.name).exists()


def test_disk_full_while_writing_a_part(study, tmp_path, monkeypatch, capsys):
    """ENOSPC in the middle of a part file: one paragraph naming it; no temporary file and no
    half-written part is left; the runs are not lost for good (resume runs them)."""
    import pyarrow.parquet as pq_mod

    real = pq_mod.write_table

    def full(table, where, *a, **k):  # noqa: ANN001
        Path(where).write_bytes(b"PAR1 half of a file")
        raise OSError(errno.ENOSPC, "No space left on device")

    out = tmp_path / "store"
    monkeypatch.setattr(pq_mod, "write_table", full)
    assert main(["study", str(study), "--out", str(out), "--workers", "1",
                 "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "no space left" in err and "part-" in err and "Traceback" not in err
    leftovers = [p.name for p in (out / "runs").iterdir()] if (out / "runs").exists() else []
    assert leftovers == []
    monkeypatch.setattr(pq_mod, "write_table", real)
    assert main(["study", str(study), "--out", str(out), "--workers", "1", "--no-progress",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["runs_ok"] == 12


def test_read_only_study_folder(study, tmp_path, monkeypatch, capsys):
    """The first write (study.json) fails as on a read-only file system: the error names the
    file, before any run, and leaves nothing behind."""
    import seisrack.atomic as atomic

    def read_only(path, text):  # noqa: ANN001
        raise OSError(errno.EROFS, "Read-only file system", str(path))

    monkeypatch.setattr(atomic, "write_text", read_only)
    monkeypatch.setattr("seisrack.studies.store.write_text", read_only)
    out = tmp_path / "ro"
    assert main(["study", str(study), "--out", str(out), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "read-only" in err["message"] and err["value"].endswith("study.json")
    assert not (out / "runs").exists()


DRIVER = """
import signal, sys
from seisrack.studies import load_study, run_study
run_study(load_study(sys.argv[1]), sys.argv[2], workers=2, batch_size=1, flush_rows=1,
          progress=False)
"""


def _children(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True,
                         text=True).stdout
    return [int(x) for x in out.split()]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    stat = Path(f"/proc/{pid}/stat")
    return not (stat.exists() and stat.read_text().split(")")[-1].split()[0] == "Z")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc and ps")
def test_workers_die_with_a_killed_driver(study, tmp_path):
    env = dict(os.environ, **{TEST_HOOK_ENV: json.dumps({"sleep": 0.5})})
    proc = subprocess.Popen([sys.executable, "-c", DRIVER, str(study), str(tmp_path / "s")],
                            env=env, stderr=subprocess.PIPE, text=True)
    workers: list[int] = []
    t0 = time.monotonic()
    while time.monotonic() - t0 < 120:
        workers = [c for c in _children(proc.pid) if _alive(c)]
        if len(workers) >= 2 and part_files(tmp_path / "s"):
            break
        assert proc.poll() is None, proc.stderr.read()
        time.sleep(0.1)
    assert len(workers) >= 2, "the pool did not start"
    proc.kill()  # SIGKILL: the driver cannot shut its pool down
    proc.wait(timeout=30)
    t0 = time.monotonic()
    while any(_alive(w) for w in workers) and time.monotonic() - t0 < 30:
        time.sleep(0.1)
    left = [w for w in workers if _alive(w)]
    for w in left:  # do not leave them behind if the test fails
        os.kill(w, signal.SIGKILL)
    assert not left, f"orphaned workers: {left}"


class _NotAScheduler:
    """A TCP server on 127.0.0.1 that answers every connection like an HTTP server."""

    def __enter__(self) -> str:
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.stop = False
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()
        return f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"

    def _serve(self) -> None:
        self.sock.settimeout(0.2)
        while not self.stop:
            try:
                c, _ = self.sock.accept()
            except OSError:
                continue
            try:
                c.settimeout(1.0)
                c.recv(4096)
                c.sendall(b"HTTP/1.1 200 OK\r\nContent-Length: 5\r\n\r\nhello" * 8)
            except OSError:
                pass
            finally:
                c.close()

    def __exit__(self, *exc: object) -> None:
        self.stop = True
        self.thread.join(timeout=5)
        self.sock.close()


def test_scheduler_that_is_not_dask(study, tmp_path, capsys):
    pytest.importorskip("distributed")
    with _NotAScheduler() as address:
        t0 = time.monotonic()
        code = main(["study", str(study), "--out", str(tmp_path / "s"), "--scheduler",
                     address, "--json"])
        took = time.monotonic() - t0
    assert code == 2 and took < 60
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--scheduler" and err["value"] == address
    assert "SCHEDULER-HOST" in err["allowed"]


