"""Every command, fed mutated inputs (issue 23, class 7): nothing crashes, runs away or breaks
the error contract.

The cases (:mod:`fuzz_inputs`, derandomized: one fixed seed) mutate the examples' rack and
study TOMLs (keys deleted, values replaced by zeros, negatives, huge, tiny, non-finite or
wrongly typed values, lists emptied or doubled, bytes truncated, BOMs, invalid UTF-8), record
files (non-finite or non-numeric samples, broken time columns, wrong column counts, too few
lines, other delimiters) and option values, for modal, run and report (2D, and 3D with a
cross-aisle record and an angle), design (2D and 3D), study (2D, 3D record pairs with angles,
a warehouse site file), study summary (on a sound or damaged store), export, motion generate /
spectrum / check, sdof, validate, paper and usage errors.

Each case runs ``seisrack.cli.main`` in a child forked by a fresh server process
(``fuzz_server.py``: its own process group, stdout and stderr captured, address space limited
to a few GB) and must:

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

import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from fuzz_inputs import Case, all_cases, study_files

CASES = all_cases()
#: exit codes every command may return; 1 only where the command reports a FAIL verdict
OK_CODES = (0, 2)
BAD_WORDS = ("Traceback (most recent call last)", "internal error", "out of memory")
SERVER = Path(__file__).with_name("fuzz_server.py")


def _params() -> list:
    return [pytest.param(c, id=c.name, marks=[pytest.mark.slow] if c.slow else [])
            for c in CASES]


class _Server:
    """The fork server (``fuzz_server.py``): a fresh process that forks one child per case
    (this pytest worker may have started OpenMP threads, after which it must not fork)."""

    def __init__(self) -> None:
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(
            [str(Path(__file__).resolve().parents[1] / "src"), os.environ.get("PYTHONPATH", "")]))
        self.proc = subprocess.Popen([sys.executable, str(SERVER)], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, env=env,
                                     start_new_session=True)
        ready = self.proc.stdout.readline()
        assert json.loads(ready) == {"ready": True}, ready

    def run(self, argv: list[str], folder: Path, limit_s: float) -> dict:
        self.proc.stdin.write(json.dumps({"argv": argv, "folder": str(folder),
                                          "limit_s": limit_s}) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()  # the server enforces the time limit
        assert line, "the fuzz server died"
        return json.loads(line)

    def close(self) -> None:
        self.proc.stdin.close()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()


@pytest.fixture(scope="module")
def server():
    srv = _Server()
    yield srv
    srv.close()


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
def test_fuzz_case(case: Case, tmp_path: Path, server: _Server,
                   request: pytest.FixtureRequest) -> None:
    store = request.getfixturevalue("store") if case.store else None
    argv = _materialise(case, tmp_path, store)
    res = server.run(argv, tmp_path, case.limit_s)
    res["argv"] = argv
    check_contract(case, res)
    left = [str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*") if ".tmp" in p.name]
    assert not left, f"temporary files left by {' '.join(argv)}: {left}"


def test_case_count_and_determinism() -> None:
    """The cases are fixed by the seed (the same on every run and xdist worker), and cover
    every command."""
    again = all_cases()
    assert [(c.name, c.argv, c.files) for c in again] == [(c.name, c.argv, c.files)
                                                          for c in CASES]
    commands = {c.argv[0] if c.argv[0] not in ("motion", "study") else
                " ".join(c.argv[:2]) for c in CASES}
    for cmd in ("modal", "run", "report", "export", "sdof", "validate", "paper", "design",
                "motion generate", "motion spectrum", "motion check", "study summary"):
        assert cmd in commands, cmd
    # 3D racks: runs and reports with a cross-aisle record, studies of pairs, a warehouse
    assert any(c.argv[0] in ("run", "report") and "--motion-cross" in c.argv for c in CASES)
    assert any(c.name.startswith("study3d") for c in CASES)
    assert any(c.name.startswith("warehouse") for c in CASES)
    assert any(c.argv[0] == "study" and c.argv[1] != "summary" for c in CASES)
    assert len(CASES) >= 200
