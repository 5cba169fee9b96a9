"""Errors under ``--json`` are JSON too (issue 14, item 6): ``{"error": {"field", "value",
"allowed", "message"}}`` on stdout with exit code 2 and nothing on stderr; without ``--json``
the one-paragraph text error on stderr is unchanged.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from rack_inputs import PAPER_RACK
from seisrack.cli import main


def _error(capsys, argv):
    rc = main(argv)
    cap = capsys.readouterr()
    assert rc == 2
    assert cap.err == ""
    obj = json.loads(cap.out)
    assert set(obj) == {"error"}
    assert set(obj["error"]) == {"field", "value", "allowed", "message"}
    return obj["error"]


def test_input_error_fields(capsys):
    err = _error(capsys, ["run", str(PAPER_RACK), "--builtin", "kobe", "--json"])
    assert err["field"] == "--builtin" and err["value"] == "kobe"
    assert "elcentro_1940_ns" in err["allowed"] and "kobe" in err["message"]


def test_missing_file(capsys, tmp_path: Path):
    err = _error(capsys, ["run", str(tmp_path / "nope.toml"), "--builtin", "elcentro_1940_ns",
                          "--json"])
    assert "nope.toml" in str(err["value"]) + err["message"]


def test_usage_error_is_json(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["run", "--json"])  # the rack and the record are missing
    assert exc.value.code == 2
    cap = capsys.readouterr()
    err = json.loads(cap.out)["error"]
    assert "required" in err["message"] and cap.err == ""


def test_other_command_json_error(capsys):
    err = _error(capsys, ["modal", str(PAPER_RACK), "--modes", "0", "--json"])
    assert err["field"] and err["message"]


def test_text_error_without_json(capsys):
    assert main(["run", str(PAPER_RACK), "--builtin", "kobe"]) == 2
    cap = capsys.readouterr()
    assert cap.out == "" and cap.err.startswith("seisrack: error: ")
    assert cap.err.count("\n") == 1


def test_subprocess_json_error():
    p = subprocess.run([sys.executable, "-m", "seisrack", "run", str(PAPER_RACK), "--builtin",
                        "elcentro_1940_ns", "--mu", "-1", "--json"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "Traceback" not in p.stderr
    assert json.loads(p.stdout)["error"]["field"] == "--mu"
