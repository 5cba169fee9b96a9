"""``seisrack design``: text and JSON output on 2D and 3D racks, and bad input reported as one
paragraph (or a JSON error object) with exit code 2, never a traceback (issue 24).

The numbers are checked against the library call they come from and, for the paper rack's
single dominant mode, against M*_1·S_d(T_1)·E_D2 (EN 1998-1 Eq 3.14-3.15 design spectrum,
Chopra §13.8); the analysis itself is validated in tests/test_design_analysis.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from seisrack.cli import main

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER = str(EXAMPLES / "paper_rack.toml")
PAPER_3D = str(EXAMPLES / "paper_rack_3d.toml")


def test_design_json_2d(capsys) -> None:  # noqa: ANN001
    assert main(["design", PAPER, "--ec8", "1", "C", "0.3", "--q", "2", "--json",
                 "--factors", "e_d1=1", "e_d2_down_aisle=0.9"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["directions"] == ["down-aisle"] and out["q"] == {"down-aisle": 2.0}
    assert out["factors"]["e_d1"] == 1.0 and out["factors"]["e_d2_down_aisle"] == 0.9
    assert "assumption" in out["factor_sources"]["e_d1"]
    assert out["modal_rule"]["down-aisle"] == "srss"
    q = out["quantities"]
    for key in ("base_shear_x", "level_force_x", "drift_x", "upright_axial_force",
                "upright_moment", "beam_end_moment", "connector_moment"):
        assert key in q
    # one dominant mode: V ≈ M*_1 · 0.9 · S_d(T_1) (EN 1998-1 Eq 3.15, T_C < T_1 < T_D)
    from seisrack.design import design_spectrum

    t1, m1 = out["modes"]["periods_s"][0], out["modes"]["effective_mass_kg"]["down-aisle"][0]
    v = m1 * 0.9 * design_spectrum(1, "C", 0.3, 2.0).psa(t1)[0]
    assert q["base_shear_x"]["max"] == pytest.approx(v, rel=0.01)
    st = out["storeys"]["down-aisle"]["storeys"][0]
    assert st["drift_s_m"] == pytest.approx(2.0 * st["drift_e_m"])
    assert out["modes"]["cumulative_mass"]["down-aisle"] >= 0.9


def test_design_text_3d(capsys) -> None:  # noqa: ANN001
    assert main(["design", PAPER_3D, "--ec8", "1", "C", "0.3", "--q", "2", "1.5",
                 "--directions-rule", "0.30"]) == 0
    out = capsys.readouterr().out
    assert "down-aisle: base shear" in out and "cross-aisle: base shear" in out
    assert "Eqs (4.18)-(4.19)" in out
    assert "q = 1.5" in out
    # member forces in 3D: upright moments in both bending planes, connectors
    assert "upright_moment_cross_aisle" in out or "upright moment" in out.lower()


def test_design_elastic_needs_q1(capsys) -> None:  # noqa: ANN001
    assert main(["design", PAPER, "--ec8", "1", "C", "0.3", "--q", "1", "--elastic",
                 "--damping", "model", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert "elastic spectrum" in out["spectra"]["down-aisle"]
    assert out["modes"]["damping"][0] == pytest.approx(0.02 * 0.65 / out["modes"][
        "periods_s"][0], rel=0.05)  # stiffness-proportional damping: ζ ∝ 1/T


@pytest.mark.parametrize(("extra", "field"), [
    (["--q", "0.8"], "--q"),
    (["--q", "2", "--factors", "e_d1=1.5"], "factors.e_d1"),
    (["--q", "2", "--factors", "e_d9=1"], "factors"),
    (["--q", "2", "--factors", "e_d1"], "--factors"),
    (["--q", "2", "--direction", "cross-aisle"], "--direction"),
    (["--q", "2", "--elastic"], "--q"),
    (["--q", "2", "3"], "--q"),
    (["--q", "2", "--damping", "much"], "--damping"),
    (["--q", "2", "--modes", "0"], "n_modes"),
])
def test_design_bad_input(extra: list[str], field: str, capsys) -> None:  # noqa: ANN001
    assert main(["design", PAPER, "--ec8", "1", "C", "0.3", "--json", *extra]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == field
    assert err["allowed"]
    assert main(["design", PAPER, "--ec8", "1", "C", "0.3", *extra]) == 2
    cap = capsys.readouterr()
    assert "Traceback" not in cap.err and "error:" in cap.err


def test_design_bad_ec8(capsys) -> None:  # noqa: ANN001
    assert main(["design", PAPER, "--ec8", "3", "C", "0.3", "--q", "2", "--json"]) == 2
    assert json.loads(capsys.readouterr().out)["error"]["field"] == "type"
    assert main(["design", PAPER, "--ec8", "1", "C", "big", "--q", "2", "--json"]) == 2
    assert json.loads(capsys.readouterr().out)["error"]["field"] == "--ec8 AG"
