"""Every command, fed mutated inputs (issue 23, class 7): nothing crashes, runs away or breaks
the error contract.

The cases (:mod:`fuzz_inputs`, derandomized: one fixed seed) mutate the examples' rack and
study TOMLs (keys deleted, values replaced by zeros, negatives, huge, tiny, non-finite or
wrongly typed values, lists emptied or doubled, bytes truncated, BOMs, invalid UTF-8), record
files (non-finite or non-numeric samples, broken time columns, wrong column counts, too few
lines, other delimiters) and option values, for modal, run (2D and 3D), report, study, study
summary (on a sound or damaged store), export, motion generate / spectrum / check, sdof,
validate, paper and usage errors.

Each case runs ``seisrack.cli.main`` in a forked child (its own process group, with its
stdout and stderr captured, its address space limited to a few GB) and must:

- exit 0 (1 where a command reports a FAIL verdict: validate, motion check, paper, sdof), with
  valid, finite JSON under ``--json``; or exit 2 with the error contract: one paragraph
  ``seisrack: error: ...`` on stderr (a usage message before it for argparse errors), or the
  ``{"error": {"field", "value", "allowed", "message"}}`` object on stdout under ``--json``;
- never print a traceback, an *internal error* (an exception the boundary did not expect) or
  *out of memory* (a size that was not estimated up front);
- finish within its time limit (a hang or a runaway is killed and fails the case);
- leave no temporary file (``*.tmp*``) in its folder.

The first cases of each command run always; the rest are marked ``slow`` (CI runs them too).
"""

from __future__ import annotations

import io
import json
import math
import os
import resource
import select
import shutil
import signal
import sys
import time
import traceback
from pathlib import Path

import numpy as np
import pytest

from fuzz_inputs import Case, all_cases, study_files

CASES = all_cases()
#: exit codes every command may return; 1 only where the command reports a FAIL verdict
OK_CODES = (0, 2)
#: address space of a case's process beyond what it had at the fork (a runaway is refused by
#: the size estimates long before; this only keeps a miss from taking the machine down)
EXTRA_ADDRESS_SPACE = 6 * 2**30
BAD_WORDS = ("Traceback (most recent call last)", "internal error", "out of memory")


def _params() -> list:
    return [pytest.param(c, id=c.name, marks=[pytest.mark.slow] if c.slow else [])
            for c in CASES]


@pytest.fixture(scope="module", autouse=True)
def warm() -> None:
    """Load what the cases use (numba kernels from their cache, matplotlib, pyarrow) once in
    this process: every forked case inherits it instead of loading it again."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401
    import pyarrow.parquet  # noqa: F401

    from seisrack.analysis import run_rack
    from seisrack.analysis.rack3d import run_rack_3d
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import Record
    from seisrack.motion.components import combine

    ROOT = Path(__file__).resolve().parents[1] / "examples"
    rec = Record(np.sin(np.arange(101) * 0.1) * 3.0, 0.01, name="warm")
    for name in ("paper_rack.toml", "paper_rack_nonlinear.toml", "three_level_rack.toml"):
        run_rack(compile_rack(load_rack(ROOT / name)), rec)
    run_rack_3d(compile_rack(load_rack(ROOT / "paper_rack_3d.toml")),
                combine(rec, rec, None, 0.0))
    # not the response spectra: their numba kernels run on OpenMP threads, which a process
    # must not have started before it forks (each case starts them itself)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A finished 4-run study, for the ``study summary`` cases."""
    from seisrack.studies import load_study, run_study

    root = tmp_path_factory.mktemp("fuzz-store")
    for name, data in study_files():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_bytes(data)
    s = run_study(load_study(root / "study.toml"), root / "store", workers=1, progress=False)
    assert s.runs_ok == 4
    return root / "store"


def _materialise(case: Case, folder: Path, store: Path | None) -> list[str]:
    for name, data in case.files:
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
    (folder / "out").mkdir(exist_ok=True)
    if case.store:
        dest = folder / "store"
        shutil.copytree(store, dest)
        damage = (folder / "damage").read_text()
        if damage == "part":
            part = sorted((dest / "runs").glob("part-*.parquet"))[0]
            part.write_bytes(part.read_bytes()[:100])
        elif damage == "study_json":
            (dest / "study.json").write_text("{not json")
        elif damage == "empty":
            shutil.rmtree(dest / "runs")
    return [a.replace("@", str(folder), 1) if a.startswith("@/") else a for a in case.argv]


def _vm_size() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _child(argv: list[str], folder: Path, w: int) -> None:  # pragma: no cover - in the fork
    code, out, err = 99, io.StringIO(), io.StringIO()
    try:
        os.setpgid(0, 0)
        os.chdir(folder)
        if sys.platform.startswith("linux"):
            limit = _vm_size() + EXTRA_ADDRESS_SPACE
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        sys.stdout, sys.stderr = out, err
        from seisrack.cli import main

        try:
            code = main(argv)
        except SystemExit as exc:  # argparse
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except BaseException:  # noqa: BLE001 - reported to the parent as a crash
        err.write(traceback.format_exc())
        code = 98
    try:
        payload = json.dumps({"code": code, "out": out.getvalue(), "err": err.getvalue()})
        data = payload.encode()
        while data:
            data = data[os.write(w, data):]
    finally:
        os._exit(0)


def run_case(case: Case, folder: Path, store: Path | None) -> dict:
    argv = _materialise(case, folder, store)
    r, w = os.pipe()
    sys.stdout.flush()
    sys.stderr.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(r)
        _child(argv, folder, w)
    os.close(w)
    chunks, t0, timed_out = [], time.monotonic(), False
    while True:
        left = case.limit_s - (time.monotonic() - t0)
        if left <= 0:
            timed_out = True
            break
        ready, _, _ = select.select([r], [], [], min(left, 1.0))
        if ready:
            chunk = os.read(r, 1 << 16)
            if not chunk:
                break
            chunks.append(chunk)
    os.close(r)
    if timed_out:
        try:
            os.killpg(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    _, status = os.waitpid(pid, 0)
    try:  # the case's own process group (pool workers): nothing may outlive it
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    if timed_out:
        return {"timed_out": True, "seconds": time.monotonic() - t0, "argv": argv}
    raw = b"".join(chunks)
    if not raw:
        return {"crashed": status, "argv": argv}
    res = json.loads(raw)
    res.update(argv=argv, seconds=time.monotonic() - t0)
    return res


def _finite(obj: object) -> bool:
    if isinstance(obj, float):
        return math.isfinite(obj)
    if isinstance(obj, dict):
        return all(_finite(v) for v in obj.values())
    if isinstance(obj, list):
        return all(_finite(v) for v in obj)
    return True


def check_contract(case: Case, res: dict) -> None:
    where = " ".join(res["argv"])
    assert not res.get("timed_out"), f"no result within {case.limit_s:g} s: {where}"
    assert "crashed" not in res, f"the process died ({res.get('crashed')}): {where}"
    code, out, err = res["code"], res["out"], res["err"]
    for word in BAD_WORDS:
        assert word not in out + err, f"{word!r} from {where}:\n{err[-3000:]}{out[-1000:]}"
    allowed = OK_CODES + ((1,) if case.exit_1_ok else ())
    assert code in allowed, f"exit {code} from {where}:\n{err[-2000:]}"
    as_json = "--json" in res["argv"]
    if code == 2:
        if as_json and out.strip():
            obj = json.loads(out)
            assert set(obj) == {"error"}, where
            assert set(obj["error"]) == {"field", "value", "allowed", "message"}, where
            assert obj["error"]["message"], where
        else:
            lines = [ln for ln in err.splitlines() if ln.startswith("seisrack")]
            assert lines and lines[-1].split(": error: ")[0].startswith("seisrack"), \
                f"no error paragraph from {where}:\n{err[-2000:]}"
            assert err.rstrip().splitlines()[-1] == lines[-1], f"not last: {where}\n{err}"
    elif as_json and out.strip():
        doc = json.loads(out)  # one valid JSON object (NaN is refused by the writer)
        assert _finite(doc), f"non-finite JSON from {where}"


@pytest.mark.parametrize("case", _params())
def test_fuzz_case(case: Case, tmp_path: Path, request: pytest.FixtureRequest) -> None:
    store = request.getfixturevalue("store") if case.store else None
    res = run_case(case, tmp_path, store)
    check_contract(case, res)
    left = [str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*") if ".tmp" in p.name]
    assert not left, f"temporary files left by {' '.join(res['argv'])}: {left}"


def test_case_count_and_determinism() -> None:
    """The cases are fixed by the seed (the same on every run and xdist worker), and cover
    every command."""
    again = all_cases()
    assert [(c.name, c.argv, c.files) for c in again] == [(c.name, c.argv, c.files)
                                                          for c in CASES]
    commands = {c.argv[0] if c.argv[0] not in ("motion", "study") else
                " ".join(c.argv[:2]) for c in CASES}
    for cmd in ("modal", "run", "report", "export", "sdof", "validate", "paper",
                "motion generate", "motion spectrum", "motion check", "study summary"):
        assert cmd in commands, cmd
    assert any(c.argv[0] == "study" and c.argv[1] != "summary" for c in CASES)
    assert len(CASES) >= 200
