"""``seisrack modal``: JSON and table output, the plot, and bad input reported without traceback
(issue #2 acceptance: exit code ≠ 0, one paragraph naming the field, no traceback).
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from rack_inputs import BAD_CASES, PAPER_RACK, bad_dict, to_toml
from seisrack.cli import main


def test_json_output(capsys):
    assert main(["modal", str(PAPER_RACK), "--json", "--modes", "3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["periods_s"]) == 3 and len(out["mass_participation"]) == 3
    assert out["periods_s"][0] == pytest.approx(0.65, rel=0.02)
    assert out["mass_participation"][0] >= 0.99
    assert out["periods_s"] == sorted(out["periods_s"], reverse=True)


def test_table_output(capsys):
    assert main(["modal", str(PAPER_RACK), "--modes", "2"]) == 0
    out = capsys.readouterr().out
    assert "period [s]" in out and "cum. x" in out
    assert "0.65" in out.splitlines()[3]


def test_plot_written(tmp_path: Path, capsys):
    png = tmp_path / "modes.png"
    assert main(["modal", str(PAPER_RACK), "--plot", str(png), "--modes", "3"]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(("path", "value", "field"), [c[1:] for c in BAD_CASES],
                         ids=[c[0] for c in BAD_CASES])
def test_bad_input_via_cli(tmp_path: Path, capsys, path, value, field):
    f = tmp_path / "rack.toml"
    f.write_text(to_toml(bad_dict(path, value)))
    assert main(["modal", str(f)]) == 2
    err = capsys.readouterr().err
    assert field in err and "Traceback" not in err
    assert err.count("\n") == 1  # one paragraph


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "seisrack", *args], capture_output=True,
                          text=True, timeout=60)


def test_malformed_toml_subprocess(tmp_path: Path):
    f = tmp_path / "bad.toml"
    f.write_text(PAPER_RACK.read_text().replace("bays = [1.8, 1.8]", "bays = [1.8, 1.8"))
    proc = _run("modal", str(f))
    assert proc.returncode != 0
    assert "Traceback" not in proc.stderr
    assert "line" in proc.stderr and "malformed TOML" in proc.stderr


def test_unknown_key_subprocess(tmp_path: Path):
    f = tmp_path / "bad.toml"
    f.write_text(PAPER_RACK.read_text().replace("mu_dynamic = 0.6\n", "mu_dynamik = 0.6\n", 1))
    proc = _run("modal", str(f), "--json")
    # under --json the error is one JSON object on stdout (issue 14)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr + proc.stdout
    assert json.loads(proc.stdout)["error"]["field"] == "pallets[0].mu_dynamic"  # missing key
    proc = _run("modal", str(f))
    assert proc.returncode == 2 and proc.stdout == ""
    assert "Traceback" not in proc.stderr and "pallets[0].mu_dynamic" in proc.stderr


def test_missing_file_and_bad_modes(tmp_path: Path, capsys):
    assert main(["modal", str(tmp_path / "nope.toml")]) == 2
    assert "not found" in capsys.readouterr().err
    assert main(["modal", str(PAPER_RACK), "--modes", "0"]) == 2
    assert "--modes" in capsys.readouterr().err


def test_mechanism_via_cli(tmp_path: Path, capsys):
    f = tmp_path / "rack.toml"
    f.write_text(PAPER_RACK.read_text().replace("beam_to_upright = 160e3", 'beam_to_upright = '
                 '"pinned"').replace("base = 160e3", 'base = "pinned"'))
    assert main(["modal", str(f)]) == 2
    assert "connections" in capsys.readouterr().err


def test_plot_functions_take_ax_and_return_it():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from seisrack.fe import modal_analysis
    from seisrack.model import compile_rack, load_rack
    from seisrack.report.frame_plot import deformed_lines, plot_frame, plot_mode_shape

    model = compile_rack(load_rack(PAPER_RACK))
    modes = modal_analysis(model, 2)
    ax = plot_frame(model)
    fig, ax2 = plt.subplots()
    assert plot_mode_shape(model, modes, 1, ax=ax2) is ax2
    # the interpolated shape passes through the displaced nodes
    lines = deformed_lines(model, modes.shapes[:, 0], 1.0)
    e0 = model.elements[0]
    top = model.nodes[e0[1]] + modes.shapes[model.node_dofs[e0[1], :2], 0]
    assert lines[0, -1] == pytest.approx(top)
    plt.close(ax.figure)
    plt.close(fig)
