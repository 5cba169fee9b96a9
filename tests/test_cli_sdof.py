"""CLI ``seisrack sdof`` and ``seisrack validate`` (issue #3): JSON keys and clean error exits.

Values come from the paper's §II closed form (Eqs 1–5) and threshold (0.537).
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from seisrack.cli import main


def _run(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def test_sdof_json_keys(capsys, tmp_path):
    png = tmp_path / "s.png"
    rc, out, _ = _run(capsys, ["sdof", "--alpha", "0.5", "--mu", "0.3", "--frequency", "1",
                               "--duration", "3", "--json", "--plot", str(png)])
    assert rc == 0
    data = json.loads(out)
    assert data["regime"] == "stick-slip"
    assert {"time_s", "kind"} <= set(data["events"][0])
    assert data["events"][0]["kind"] == "slip"
    assert {e["kind"] for e in data["events"]} <= {"slip", "stick", "reverse"}
    assert png.stat().st_size > 1000


@pytest.mark.parametrize(("mu", "regime"), [("0.6", "no-sliding"), ("0.2", "continuous-sliding")])
def test_sdof_regimes(capsys, mu, regime):
    rc, out, _ = _run(capsys, ["sdof", "--alpha", "0.5", "--mu", mu, "--frequency", "2",
                               "--duration", "2", "--json"])
    assert rc == 0 and json.loads(out)["regime"] == regime


def test_sdof_threshold(capsys):
    rc, out, _ = _run(capsys, ["sdof", "--threshold", "--json"])
    assert rc == 0
    assert abs(json.loads(out)["continuous_sliding_threshold"] - 0.537) < 5e-4


@pytest.mark.parametrize(
    ("args", "field"),
    [(["--alpha", "0"], "alpha"), (["--alpha", "nan"], "alpha"), (["--mu", "-1"], "mu"),
     (["--mu-dynamic", "0.4"], "mu_dynamic"), (["--duration", "0"], "duration"),
     (["--frequency", "-2"], "frequency"), (["--frequency", "inf"], "frequency")],
)
def test_sdof_bad_input(capsys, args, field):
    base = {"--alpha": "0.5", "--mu": "0.3", "--frequency": "1", "--duration": "1"}
    for k, v in zip(args[::2], args[1::2], strict=True):
        base[k] = v
    argv = ["sdof", "--json"] + [x for kv in base.items() for x in kv]
    rc, out, err = _run(capsys, argv)
    # under --json the error is one JSON object on stdout (issue 14), never a traceback
    assert rc == 2 and json.loads(out)["error"]["field"] == field
    assert "Traceback" not in err and "Traceback" not in out
    rc, out, err = _run(capsys, [a for a in argv if a != "--json"])
    assert rc == 2 and out == "" and f"'{field}'" in err and "Traceback" not in err


def test_sdof_bad_input_subprocess_no_traceback():
    p = subprocess.run([sys.executable, "-m", "seisrack", "sdof", "--alpha", "-1", "--mu", "0.3",
                        "--frequency", "1", "--duration", "1", "--json"],
                       capture_output=True, text=True)
    assert p.returncode == 2 and "Traceback" not in p.stderr + p.stdout
    assert json.loads(p.stdout)["error"]["field"] == "alpha"


def test_validate_json_shape(capsys, monkeypatch):
    import seisrack.paper.examples as exm

    calls = {}

    def fake_run_validation(dt, engine, keep_histories=False):
        calls["dt"] = dt
        entry = {"max_abs_displacement_m": [0.1], "max_abs_sliding_m": 0.0, "sliding_phases": 0,
                 "final_sliding_m": 0.0, "source": "reference"}
        entry["reference"] = dict(entry)
        return {"example2": {k: dict(entry) for k in ("1.0", "0.5", "0.3")},
                "example3": {k: dict(entry) for k in ("10.0", "0.5", "0.3", "0.1")}}

    monkeypatch.setattr(exm, "run_validation", fake_run_validation)
    rc, out, _ = _run(capsys, ["validate", "--json", "--dt", "0.002"])
    data = json.loads(out)
    assert rc == 0 and calls["dt"] == 0.002
    assert list(data["example2"]) == ["1.0", "0.5", "0.3"]
    assert list(data["example3"]) == ["10.0", "0.5", "0.3", "0.1"]


def test_validate_bad_dt(capsys):
    rc, out, _ = _run(capsys, ["validate", "--json", "--dt", "-1"])
    assert rc == 2 and json.loads(out)["error"]["field"] == "--dt"
    rc, out, _ = _run(capsys, ["validate", "--json", "--dt", "1e-9"])  # 1e10 steps: refused
    assert rc == 2 and "1e-05" in json.loads(out)["error"]["allowed"]
