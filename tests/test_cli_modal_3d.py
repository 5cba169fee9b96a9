"""``seisrack modal`` on a 3D rack: periods with participation down-aisle (x), cross-aisle (z)
and in plan rotation (θ), each mode's class, JSON and the 3D mode-shape figure. The numbers
themselves are validated against OpenSeesPy in tests/test_model_3d_opensees.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seisrack.cli import main

RACK = Path(__file__).parent.parent / "examples" / "paper_rack_3d.toml"


def test_json_has_both_directions_and_torsion(capsys):
    assert main(["modal", str(RACK), "--json", "--modes", "8"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["three_d"] is True and len(out["periods_s"]) == 8
    assert out["direction"][0] == "down-aisle"
    assert "cross-aisle" in out["direction"] and "torsional" in out["direction"]
    assert out["periods_s"] == sorted(out["periods_s"], reverse=True)
    assert max(out["mass_participation_z"]) > 0.9  # one dominant cross-aisle mode
    assert out["mass_participation_x"][0] > 0.9
    assert out["plan_centre_m"][1] == pytest.approx(0.55, abs=0.01)  # mid-depth
    assert out["total_mass_x_kg"] == pytest.approx(out["total_mass_z_kg"], rel=1e-3)


def test_table_classifies_modes(capsys):
    assert main(["modal", str(RACK), "--modes", "6"]) == 0
    out = capsys.readouterr().out
    assert "z-part." in out and "θ-part." in out
    assert "cross-aisle" in out and "torsional" in out and "down-aisle" in out


def test_plot_written(tmp_path: Path, capsys):
    pytest.importorskip("matplotlib")
    png = tmp_path / "modes3d.png"
    assert main(["modal", str(RACK), "--plot", str(png), "--modes", "3"]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plot_functions_return_axes():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack, load_rack
    from seisrack.report.frame_plot3d import plot_frame_3d, plot_mode_shape_3d

    model = compile_rack(load_rack(RACK))
    res = modal_analysis(model, 2)
    ax = plot_frame_3d(model)
    assert ax is not None and ax.name == "3d"
    ax2 = plot_mode_shape_3d(model, res, 2)
    assert "mode 2" in ax2.get_title()
    plt.close("all")


def test_report_on_3d_rack(tmp_path, capsys):
    """``seisrack report`` takes a 3D rack (issue 21): the HTML and summary.json are written
    and the summary is the 3D run's."""
    out = tmp_path / "r.html"
    code = main(["report", str(RACK), "--builtin", "elcentro_1940_ns", "--out", str(out),
                 "--json"])
    assert code == 0
    s = json.loads(capsys.readouterr().out)
    assert s["dimension"] == "3D" and s["directions"] == ["down-aisle", "cross-aisle"]
    assert out.exists() and (tmp_path / "summary.json").exists()
    assert {r["direction"] for r in s["design_checks"]["checks"][-1]["storeys"]} == {
        "down-aisle", "cross-aisle"}
