"""Documented contracts that were broken (issue 23, class 5).

- ``study summary --json`` reports its errors as the JSON object (every command does);
- ``export opensees`` takes ``--json`` (the README says every command does);
- errors about ``[loading]`` depth / overhang name ``loading.depth`` / ``loading.overhang``
  (the table the user wrote), not ``pallets[0].depth``;
- a UTF-8 byte-order mark (Excel's "CSV UTF-8", Windows Notepad) is accepted in rack and study
  TOML files and in record files;
- ``seisrack report ... --out DIR/report.html`` creates ``DIR`` as ``run --out`` does;
- every README example writes under ``out/`` (git-ignored): nothing lands in the repository;
- no document, help text or hint shows a real address for a Dask scheduler: the placeholder
  ``tcp://SCHEDULER-HOST:8786``.
"""

from __future__ import annotations

import copy
import json
import re
import shlex
import tomllib
from pathlib import Path

import numpy as np
import pytest

from rack_inputs import EXAMPLES, PAPER_RACK
from seisrack.cli import main
from seisrack.errors import InputError

REPO = Path(__file__).resolve().parents[1]
BOM = b"\xef\xbb\xbf"


def _json_error(capsys, argv: list[str]) -> dict:
    try:
        code = main(argv)
    except SystemExit as exc:  # a usage error: argparse exits (with the JSON object)
        code = exc.code
    assert code == 2
    cap = capsys.readouterr()
    assert cap.err == "", cap.err
    obj = json.loads(cap.out)
    assert set(obj) == {"error"}
    return obj["error"]


# ------------------------------------------------------------------ study summary --json
@pytest.mark.parametrize("extra", [[], ["--boot", "-3"], ["--d-slide", "0"], ["--nope"]])
def test_study_summary_errors_are_json(capsys, tmp_path, extra):
    err = _json_error(capsys, ["study", "summary", str(tmp_path / "nowhere"), *extra, "--json"])
    assert err["message"]
    if extra[:1] == ["--boot"]:
        assert err["field"] == "--boot"
    elif extra[:1] == ["--d-slide"]:
        assert err["field"] == "--d-slide"
    elif not extra:
        assert str(tmp_path / "nowhere") in json.dumps(err)


def test_study_summary_unreadable_store_is_json(capsys, tmp_path):
    (tmp_path / "runs").mkdir()
    (tmp_path / "runs" / "part-0000.parquet").write_bytes(b"not parquet at all")
    err = _json_error(capsys, ["study", "summary", str(tmp_path), "--json"])
    assert "part-0000.parquet" in err["message"]
    assert "internal error" not in err["message"]


# ------------------------------------------------------------------ export opensees --json
def test_export_json(capsys, tmp_path):
    assert main(["export", "opensees", str(PAPER_RACK), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["out"] is None and doc["script"].startswith('"""OpenSeesPy model of')
    assert doc["pallets"] == 4 and doc["lines"] == len(doc["script"].splitlines())
    out = tmp_path / "rack_ops.py"
    assert main(["export", "opensees", str(PAPER_RACK), "--out", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["out"] == str(out) and "script" not in doc and out.is_file()
    err = _json_error(capsys, ["export", "opensees", str(PAPER_RACK), "--out", str(out),
                               "--json"])
    assert err["field"] == "--out"  # exists, no --force


# ------------------------------------------------------------------ [loading] footprint
def _rack_3d_loading(**loading) -> dict:
    with (EXAMPLES / "warehouse_rack_3d.toml").open("rb") as fh:
        d = tomllib.load(fh)
    d = copy.deepcopy(d)
    d["loading"].update(loading)
    for k in [k for k, v in loading.items() if v is None]:
        del d["loading"][k]
    return d


@pytest.mark.parametrize(("loading", "field"), [
    ({"depth": 1.0, "overhang": None}, "loading.depth"),  # not deeper than the frame
    ({"depth": 1.4, "overhang": 0.05}, "loading.depth"),  # more than frame + 2 overhangs
    ({"depth": 1.12, "overhang": 0.05}, "loading.depth"),  # does not reach the rear beam
    ({"depth": 1.2, "overhang": 1.3}, "loading.overhang"),
])
def test_loading_footprint_errors_name_the_loading_table(loading, field):
    from seisrack.model.load import rack_from_dict

    with pytest.raises(InputError) as exc:
        rack_from_dict(_rack_3d_loading(**loading))
    assert exc.value.field == field


def test_explicit_pallet_footprint_errors_name_the_pallet():
    from seisrack.model.load import rack_from_dict

    with (EXAMPLES / "paper_rack_3d.toml").open("rb") as fh:
        d = tomllib.load(fh)
    d["pallets"][2]["depth"] = 1.0
    del d["pallets"][2]["overhang"]
    with pytest.raises(InputError) as exc:
        rack_from_dict(d)
    assert exc.value.field == "pallets[2].depth"


# ------------------------------------------------------------------ byte-order marks
def test_bom_in_rack_and_study_toml(tmp_path, capsys):
    rack = tmp_path / "rack.toml"
    rack.write_bytes(BOM + PAPER_RACK.read_bytes())
    assert main(["modal", str(rack), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["n_dof"] > 0
    study = tmp_path / "study.toml"
    text = (EXAMPLES / "study_paper_rack.toml").read_text(encoding="utf-8")
    text = text.replace('"paper_rack.toml"', json.dumps(str(rack)))
    study.write_bytes(BOM + text.encode())
    assert main(["study", str(study), "--dry-run", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["runs_total"] > 0


def test_bom_in_record_files(tmp_path):
    from seisrack.motion import read_record
    from seisrack.motion.check import _declares_units

    t = np.arange(50) * 0.01
    body = "time_s,accel_m_s2\n" + "".join(f"{a:.3f},{b:.6f}\n"
                                          for a, b in zip(t, np.sin(t), strict=True))
    csv = tmp_path / "excel.csv"
    csv.write_bytes(BOM + body.encode())
    rec = read_record(csv)  # units from the header, as without the BOM
    assert rec.n == 50 and rec.dt == pytest.approx(0.01)
    assert _declares_units(csv)
    one = tmp_path / "notepad.txt"
    one.write_bytes(BOM + "".join(f"{v:.6f}\n" for v in np.sin(t)).encode())
    assert read_record(one, units="g", dt=0.01).n == 50


# ------------------------------------------------------------------ report --out DIR/...
def test_report_creates_its_folder(tmp_path, capsys):
    out = tmp_path / "out" / "rep" / "report.html"
    rec = tmp_path / "rec.csv"
    t = np.arange(300) * 0.01
    np.savetxt(rec, np.column_stack([t, 3.0 * np.sin(2 * np.pi * t)]), delimiter=",",
               header="time_s,accel_m_s2", comments="")
    assert main(["report", str(PAPER_RACK), "--motion", str(rec), "--modes", "2",
                 "--out", str(out), "--json"]) == 0
    assert out.is_file() and (out.parent / "summary.json").is_file()
    json.loads(capsys.readouterr().out)


# ------------------------------------------------------------------ README under out/
_OUTPUT_OPTIONS = ("--out", "--plot", "--report")


def _readme_commands() -> list[list[str]]:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    cmds = []
    for block in re.findall(r"```sh\n(.*?)```", text, flags=re.S):
        for line in block.splitlines():
            line = line.split("#", 1)[0].strip()
            if line.startswith("seisrack "):
                cmds.append(shlex.split(line))
    return cmds


def test_readme_examples_write_under_out():
    cmds = _readme_commands()
    assert len(cmds) >= 15  # the walk-through was found
    outputs = []
    for argv in cmds:
        assert ">" not in argv, argv  # no shell redirection into the repository
        for opt in _OUTPUT_OPTIONS:
            if opt in argv:
                outputs.append(argv[argv.index(opt) + 1])
        if argv[1] == "report":  # its default --out is report.html in the current folder
            assert "--out" in argv, argv
    assert outputs and all(o.startswith("out/") for o in outputs), outputs
    ignored = (REPO / ".gitignore").read_text().splitlines()
    assert "out/" in ignored


# ------------------------------------------------------------------ scheduler placeholder
def test_no_real_scheduler_address_in_docs_help_or_hints():
    files = [REPO / "README.md", *sorted((REPO / "docs").rglob("*.md")),
             *sorted((REPO / "src").rglob("*.py"))]
    pattern = re.compile(r"tcp://(\d{1,3}(?:\.\d{1,3}){3})")
    found = {(str(f.relative_to(REPO)), ip) for f in files
             for ip in pattern.findall(f.read_text(encoding="utf-8", errors="replace"))
             if not ip.startswith("127.")}
    assert not found
    from seisrack.cli import build_parser

    sub = build_parser()._subparsers._group_actions[0].choices["study"]
    assert "tcp://SCHEDULER-HOST:8786" in sub.format_help()
