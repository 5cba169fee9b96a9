"""One study per folder, and ``study.json`` as valid JSON (defects D4 and D5): what is checked.

- ``study.json`` of a PGA study is strict JSON (no ``NaN``/``Infinity``: ``period_s`` is
  ``null``), and a ``study.json`` written before the fix (with ``NaN``) still loads: the study
  resumes and is summarised;
- the same study run again resumes (stored runs are skipped); an extension (a stripe added,
  here below the stored one, which shifts the stripe indices) runs only the new runs, and the
  summary uses the study's stripe indices: one intensity per stripe;
- a changed study (another stripe level) run into the same ``--out`` is refused before any run,
  by the command line (exit 2, one paragraph naming ``--out`` and what to do, no traceback) and
  by :func:`run_study`: ``study.json`` and the stored runs are left as they were;
- a folder already mixed (by a version without the check) is summarised over the runs of its
  ``study.json`` only, and the summary says, in its text and JSON, how many runs it left out.

Each study is one record at one friction value: one run per stripe.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.studies import load_study, read_runs, run_study
from seisrack.studies.store import part_files, read_study_json
from seisrack.studies.summary import format_summary, summarize
from test_study_spec import make_study

G = 9.80665
BODY = """
racks = ["rack.toml"]
seed = 7
[records]
folder = "records"
[intensity]
measure = "pga"
unit = "g"
stripes = {stripes}
"""


def _study(folder: Path, stripes: str, name: str) -> Path:
    return make_study(folder, BODY.format(stripes=stripes), n_records=1, name=name)


def _strict(text: str) -> dict:
    """``json.loads`` refusing NaN and Infinity, as jq and JavaScript's JSON.parse do."""
    def refuse(token: str) -> None:
        raise ValueError(f"not JSON: {token}")

    return json.loads(text, parse_constant=refuse)


def _run(study: Path, out: Path):  # noqa: ANN202
    return run_study(load_study(study), out, workers=1, progress=False)


def _stripe_ims(summary: dict) -> dict[int, tuple[float, int]]:
    """stripe -> (IM [g], runs) of the single group of a summary."""
    (g,) = summary["groups"]
    return {s["stripe"]: (round(s["im"] / G, 6), s["n_runs"]) for s in g["stripes"]["stripes"]}


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Study A (0.3 g), its extension (0.2 g added below) and a changed study B (0.5 g)."""
    tmp = tmp_path_factory.mktemp("definition")
    _study(tmp, "[0.3]", "a.toml")
    _study(tmp, "[0.2, 0.3]", "a_extended.toml")
    _study(tmp, "[0.5]", "b.toml")
    return tmp


@pytest.fixture(scope="module")
def stored_a(folder: Path) -> Path:
    """A run once, into a folder the tests copy before changing."""
    out = folder / "store_a"
    assert _run(folder / "a.toml", out).runs_ok == 1
    return out


def _copy(src: Path, tmp_path: Path) -> Path:
    return Path(shutil.copytree(src, tmp_path / "st"))


def test_pga_study_json_is_strict_json(stored_a: Path) -> None:
    doc = _strict((stored_a / "study.json").read_text())
    assert [r["period_s"] for r in doc["runs"]] == [None]  # PGA: no period
    assert doc["intensity"]["measure"] == "pga"


def test_same_study_resumes(folder: Path, stored_a: Path, tmp_path: Path) -> None:
    out = _copy(stored_a, tmp_path)
    s = _run(folder / "a.toml", out)
    assert (s.runs_already_stored, s.runs_executed) == (1, 0)
    summary = summarize(out, n_boot=0, plots=False)
    assert summary["warnings"] == [] and summary["runs_left_out"] == 0
    assert _stripe_ims(summary) == {0: (0.3, 1)}


def test_old_study_json_with_nan_still_loads(folder: Path, stored_a: Path,
                                             tmp_path: Path) -> None:
    """A study.json written before the fix (``NaN``) is read, resumed and summarised; the
    resume rewrites it as strict JSON."""
    out = _copy(stored_a, tmp_path)
    doc = json.loads((out / "study.json").read_text())
    for r in doc["runs"]:
        r["period_s"] = float("nan")
    (out / "study.json").write_text(json.dumps(doc, indent=1, allow_nan=True))
    assert "NaN" in (out / "study.json").read_text()
    assert read_study_json(out)["runs"][0]["run_id"] == doc["runs"][0]["run_id"]
    summary = summarize(out, n_boot=0, plots=False)
    assert summary["runs_left_out"] == 0 and _stripe_ims(summary) == {0: (0.3, 1)}
    s = _run(folder / "a.toml", out)
    assert (s.runs_already_stored, s.runs_executed) == (1, 0)
    assert _strict((out / "study.json").read_text())["runs"][0]["period_s"] is None


def test_extension_runs_only_the_new_stripe(folder: Path, stored_a: Path,
                                            tmp_path: Path) -> None:
    """0.2 g added below 0.3 g: the stored 0.3 g run (stripe 0 when it ran) is stripe 1 of
    the extended study, and the summary does not pool it with the new 0.2 g run."""
    out = _copy(stored_a, tmp_path)
    s = _run(folder / "a_extended.toml", out)
    assert (s.runs_total, s.runs_already_stored, s.runs_executed) == (2, 1, 1)
    assert sorted(read_runs(out).column("stripe").to_pylist()) == [0, 0]  # as they ran
    summary = summarize(out, n_boot=0, plots=False)
    assert summary["runs_left_out"] == 0 and summary["warnings"] == []
    assert _stripe_ims(summary) == {0: (0.2, 1), 1: (0.3, 1)}


def test_changed_stripe_is_refused_by_the_cli(folder: Path, stored_a: Path, tmp_path: Path,
                                              capsys: pytest.CaptureFixture) -> None:
    out = _copy(stored_a, tmp_path)
    before = (out / "study.json").read_text()
    parts = part_files(out)
    assert main(["study", str(folder / "b.toml"), "--out", str(out), "--workers", "1",
                 "--no-progress", "--json"]) == 2
    captured = capsys.readouterr()
    err = json.loads(captured.out)["error"]
    assert err["field"] == "--out" and err["value"] == str(out)
    assert "a.toml" in err["message"] and "stripe 0" in err["message"]
    assert "new folder for --out" in err["message"] and "Traceback" not in captured.err
    # nothing run, nothing rewritten: A's definition and runs are as they were
    assert (out / "study.json").read_text() == before and part_files(out) == parts
    assert _stripe_ims(summarize(out, n_boot=0, plots=False)) == {0: (0.3, 1)}


def test_changed_stripe_is_refused_by_run_study(folder: Path, stored_a: Path,
                                                tmp_path: Path) -> None:
    out = _copy(stored_a, tmp_path)
    before = (out / "study.json").read_text()
    with pytest.raises(InputError, match="--out") as exc:
        _run(folder / "b.toml", out)
    assert exc.value.field == "--out"
    assert (out / "study.json").read_text() == before and read_runs(out).num_rows == 1


def test_a_mixed_folder_is_summarised_over_its_study_only(
        folder: Path, stored_a: Path, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """A folder where B was run over A by a version without the check: study.json is B's,
    the store holds A's 0.3 g run and B's 0.5 g run, both as stripe 0."""
    out = tmp_path / "mixed"
    assert _run(folder / "b.toml", out).runs_ok == 1
    for p in part_files(stored_a):
        shutil.copy(p, out / "runs" / p.name)
    assert read_runs(out).num_rows == 2
    summary = summarize(out, n_boot=0, plots=False)
    assert summary["runs_total"] == 1 and summary["runs_left_out"] == 1
    assert _stripe_ims(summary) == {0: (0.5, 1)}  # not the median of 0.3 g and 0.5 g
    assert "1 stored runs are left out" in summary["warnings"][0]
    assert format_summary(summary).startswith("warning: 1 stored runs are left out")
    assert main(["study", "summary", str(out), "--boot", "0", "--no-plots", "--json"]) == 0
    js = _strict(capsys.readouterr().out)
    assert js["runs_left_out"] == 1 and "left out" in js["warnings"][0]
    # B resumes there (the stray run is not B's definition's to lose) ...
    s = _run(folder / "b.toml", out)
    assert (s.runs_already_stored, s.runs_executed) == (1, 0)
    # ... and A is refused: B's stored run would lose its definition
    with pytest.raises(InputError, match="--out"):
        _run(folder / "a.toml", out)
