"""``seisrack export opensees``: the exported OpenSeesPy script is the same rack (issue 14, item 5).

Reference: seisrack's own modal analysis of the same compiled rack,
``seisrack.fe.modal.modal_analysis(model, n_modes)``, with the pallets rigidly attached (total
mass). Acceptance: the periods of the exported script with ``pallets="rigid"`` agree within
0.1 % (the model is the same node for node, so they agree to round-off: measured ~1e-12).

The script is executed in a subprocess (OpenSees keeps global state). Tests that need
openseespy skip without it; the text tests (valid Python, deterministic, header) always run.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from seisrack.cli import main
from seisrack.export import opensees_script
from seisrack.fe.modal import modal_analysis
from seisrack.model import compile_rack, load_rack

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
TOL = 1e-3


def _model(name: str):
    return compile_rack(load_rack(EXAMPLES / name))


def _script_periods(script: Path, n: int, pallets: str = "rigid") -> list[float]:
    code = (f"import json, runpy; ns = runpy.run_path({str(script)!r}, run_name='exported'); "
            f"print('PERIODS=' + json.dumps(ns['modal']({n}, {pallets!r})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=True)
    line = [x for x in out.stdout.splitlines() if x.startswith("PERIODS=")][-1]
    return json.loads(line.removeprefix("PERIODS="))


def test_script_is_valid_python_with_documented_header() -> None:
    model = _model("three_level_rack.toml")
    text = opensees_script(model, source="three_level_rack.toml")
    compile(text, "rack_ops.py", "exec")
    head = text.split('"""', 2)[1]
    for needed in ("seisrack", "three_level_rack.toml", model.title, "Units: SI",
                   "dispBeamColumn", "elasticBeamColumn", "ElasticPP", "regularised Coulomb",
                   "mu_s = mu_d", "K_INIT", "Rayleigh"):
        assert needed in head, needed
    for needed in ("import openseespy.opensees as ops", "def build(", "def modal(",
                   "def run(", 'if __name__ == "__main__":', "ops.region("):
        assert needed in text, needed
    # this rack has mu_dynamic < mu_static: the header says mu_static is used
    assert "mu_dynamic < mu_static" in head


def test_script_is_deterministic_and_compact() -> None:
    a = opensees_script(_model("warehouse_rack.toml"), pallets="rigid")
    b = opensees_script(_model("warehouse_rack.toml"), pallets="rigid")
    assert a == b
    # data tables packed several items a line: 1441 nodes, 1220 members, 421 springs and
    # 400 pallets (3482 items) in under a third of the lines one item a line would take
    # (measured: 1042 table lines; the whole script, functions and header included, 1524)
    table_lines, inside = 0, False
    for line in a.splitlines():
        if line.endswith("= ["):
            inside = True
        elif line == "]":
            inside = False
        elif inside:
            table_lines += 1
    assert 0 < table_lines < 3482 / 3
    assert len(a.splitlines()) < table_lines + 600
    assert opensees_script(_model("paper_rack.toml"), mu=0.3) != opensees_script(
        _model("paper_rack.toml"), mu=0.4)


def test_bad_arguments_are_input_errors() -> None:
    from seisrack.errors import InputError

    model = _model("paper_rack.toml")
    for kw in ({"pallets": "glued"}, {"mu": -0.1}, {"mu": float("nan")}, {"k_init": 0.0}):
        with pytest.raises(InputError):
            opensees_script(model, **kw)


@pytest.mark.parametrize("name", ["paper_rack.toml", "three_level_rack.toml"])
def test_periods_match_seisrack_modal(name: str, tmp_path: Path) -> None:
    pytest.importorskip("openseespy.opensees")
    model = _model(name)
    script = tmp_path / "rack_ops.py"
    script.write_text(opensees_script(model, pallets="rigid"))
    T_ops = np.array(_script_periods(script, 6))
    T_ref = modal_analysis(model, 6).periods
    err = np.abs(T_ops / T_ref - 1.0)
    assert err.max() < TOL, f"{name}: periods {T_ops} vs seisrack {T_ref} (rel. err {err})"


def test_warehouse_periods_match_seisrack_modal(tmp_path: Path) -> None:
    pytest.importorskip("openseespy.opensees")
    model = _model("warehouse_rack.toml")
    script = tmp_path / "rack_ops.py"
    script.write_text(opensees_script(model, pallets="rigid"))
    t0 = time.perf_counter()
    T_ops = np.array(_script_periods(script, 3))
    wall = time.perf_counter() - t0
    T_ref = modal_analysis(model, 3).periods
    err = np.abs(T_ops / T_ref - 1.0)
    assert err.max() < TOL, f"periods {T_ops} vs seisrack {T_ref} (rel. err {err})"
    assert wall < 60.0, f"ARPACK modal analysis of the exported warehouse rack took {wall:.0f} s"


def test_friction_script_runs_as_program_and_module(tmp_path: Path) -> None:
    """``python rack_ops.py`` prints the periods; run(ag, dt) gives peak level displacements
    equal to the rigid model's while nothing slides (mu large), and changed when pallets slide."""
    pytest.importorskip("openseespy.opensees")
    model = _model("paper_rack.toml")
    script = tmp_path / "rack_ops.py"
    script.write_text(opensees_script(model, pallets="friction", mu=100.0, k_init=1e9))
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=120, check=True)
    assert model.title in out.stdout and "period" in out.stdout
    code = (
        f"import json, math, runpy; ns = runpy.run_path({str(script)!r}, run_name='x'); "
        "ag = [3.0 * math.sin(2 * math.pi * 1.5 * k * 0.005) for k in range(401)]; "
        "r = [ns['run'](ag, 0.005, p)[0] for p in ('rigid', 'friction')]; "
        "ns['PALLETS'][:] = [(a, b, m, 0.05, lv) for a, b, m, _, lv in ns['PALLETS']]; "
        "r.append(ns['run'](ag, 0.005, 'friction')[0]); print('PEAKS=' + json.dumps(r))"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=True)
    rigid, held, sliding = json.loads(
        [x for x in res.stdout.splitlines() if x.startswith("PEAKS=")][-1][6:])
    assert held == pytest.approx(rigid, rel=1e-3)
    assert rigid > 0.0 and abs(sliding / rigid - 1.0) > 0.05


# --- CLI ---------------------------------------------------------------------------------------

def test_cli_writes_stdout(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["export", "opensees", str(EXAMPLES / "paper_rack.toml"), "--pallets",
                 "rigid"]) == 0
    text = capsys.readouterr().out
    compile(text, "rack_ops.py", "exec")
    assert "PALLET_MODE = 'rigid'" in text
    assert text == opensees_script(_model("paper_rack.toml"), pallets="rigid",
                                   source="paper_rack.toml")


def test_cli_out_file_and_force(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rack = str(EXAMPLES / "paper_rack.toml")
    out = tmp_path / "rack_ops.py"
    assert main(["export", "opensees", rack, "--out", str(out), "--mu", "0.3"]) == 0
    first = out.read_text()
    assert "0.3, 0)" in first and capsys.readouterr().out == ""
    assert main(["export", "opensees", rack, "--out", str(out), "--mu", "0.5"]) == 2
    err = capsys.readouterr().err
    assert "--force" in err and "Traceback" not in err
    assert out.read_text() == first
    assert main(["export", "opensees", rack, "--out", str(out), "--mu", "0.5", "--force"]) == 0
    assert out.read_text() != first


@pytest.mark.parametrize("args", [
    ["missing_rack.toml"],
    ["{bad}"],
    ["{rack}", "--mu", "-1"],
    ["{rack}", "--k-init", "0"],
    ["{rack}", "--pallets", "glued"],
])
def test_cli_bad_input_exits_2(args: list[str], tmp_path: Path,
                               capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("title = 'x'\n[geometry\nbays = [\n")
    argv = ["export", "opensees",
            *(a.format(bad=bad, rack=EXAMPLES / "paper_rack.toml") for a in args)]
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse usage errors
        code = exc.code
    assert code == 2
    err = capsys.readouterr().err
    assert "error" in err and "Traceback" not in err


# --- nonlinear connections ([hysteresis], issue 12) ----------------------------------------------

_HYSTERESIS_TOML = """
[hysteresis.beam_to_upright]
law = "pinching"
envelope_rotation = [0.01, 0.03, 0.06, 0.10]
envelope_moment = [1600.0, 2400.0, 2800.0, 3000.0]
negative_envelope_rotation = [0.008, 0.025, 0.05, 0.09]
negative_envelope_moment = [1280.0, 2000.0, 2300.0, 2450.0]
reload_rotation_ratio = 0.3
reload_moment_ratio = 0.2
unload_moment_ratio = 0.05

[hysteresis.base]
law = "elastic-plastic"
yield_moment = 3000.0
"""


def _nonlinear_rack(tmp_path: Path) -> Path:
    rack = tmp_path / "paper_rack_nl.toml"
    rack.write_text((EXAMPLES / "paper_rack.toml").read_text() + _HYSTERESIS_TOML)
    return rack


def _script_namespace(text: str) -> dict:
    """The script's tables (its module body up to the functions; openseespy not needed)."""
    head = text.split("# --- tags", 1)[0].replace("import openseespy.opensees as ops", "")
    ns: dict = {}
    exec(compile(head, "rack_ops.py", "exec"), ns)
    return ns


def test_nonlinear_springs_get_the_laws_materials(tmp_path: Path) -> None:
    from seisrack.export.opensees_materials import opensees_uniaxial
    from seisrack.model.frame_model import BASE_PLATE

    spec = load_rack(_nonlinear_rack(tmp_path))
    model = compile_rack(spec)
    text = opensees_script(model, pallets="rigid", hysteresis=spec.hysteresis)
    ns = _script_namespace(text)
    mats, springs = ns["SPRING_MATERIALS"], ns["SPRINGS"]
    assert len(mats) == len(springs) == model.hinge_dofs.shape[0] == 7
    for n, mat in enumerate(mats):
        law = spec.hysteresis.base if model.hinge_kind[n] == BASE_PLATE \
            else spec.hysteresis.beam_to_upright
        args = opensees_uniaxial(law, n + 1)
        assert (mat[0], *mat[1:]) == (args[0], *args[2:])
    assert {m[0] for m in mats} == {"Pinching4", "ElasticPP"}
    head = text.split('"""', 2)[1]
    assert "Pinching4" in head and "hinge rotation" in head and "K_initial" in head


def test_nonlinear_spring_orientation_is_seisrack_hinge_rotation(tmp_path: Path) -> None:
    """zeroLength deformation u_j − u_i = seisrack's u[a] − u[b] with hinge_dofs = (a, b): node
    j owns DOF a (beam end / base), node i owns b (upright) or is a fixed ground node."""
    spec = load_rack(_nonlinear_rack(tmp_path))
    model = compile_rack(spec)
    ns = _script_namespace(opensees_script(model, hysteresis=spec.hysteresis))
    ground = {g[0] for g in ns["GROUND_NODES"]}
    rz = model.mesh.node_dofs[:, 2]
    for (i, j, direction, k), (a, b), kh in zip(ns["SPRINGS"], model.hinge_dofs, model.hinge_k,
                                                strict=True):
        assert direction == 3 and k == kh
        assert rz[j - 1] == a
        assert (i in ground) if b < 0 else (rz[i - 1] == b)


def test_linear_rack_text_is_unchanged_by_hysteresis_argument() -> None:
    spec = load_rack(EXAMPLES / "paper_rack.toml")
    model = compile_rack(spec)
    text = opensees_script(model, source="paper_rack.toml")
    assert text == opensees_script(model, source="paper_rack.toml", hysteresis=spec.hysteresis)
    assert "SPRING_MATERIALS = []" in text and "Pinching4" not in text


def test_nonlinear_export_needs_the_matching_laws(tmp_path: Path) -> None:
    from dataclasses import replace

    from seisrack.errors import InputError
    from seisrack.model.hinge_law import HingeLaw

    spec = load_rack(_nonlinear_rack(tmp_path))
    model = compile_rack(spec)
    with pytest.raises(InputError) as err:
        opensees_script(model)
    assert err.value.field == "hysteresis"
    other = replace(spec.hysteresis,
                    base=HingeLaw("elastic-plastic", 160e3, yield_moment=2000.0))
    with pytest.raises(InputError) as err:
        opensees_script(model, hysteresis=other)
    assert err.value.field == "hysteresis.base" and "2000" in str(err.value)
    with pytest.raises(InputError) as err:
        opensees_script(model, hysteresis=replace(spec.hysteresis, base="epp"))
    assert err.value.field == "hysteresis.base"


def test_cli_exports_the_hysteresis(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rack = _nonlinear_rack(tmp_path)
    assert main(["export", "opensees", str(rack), "--pallets", "rigid"]) == 0
    text = capsys.readouterr().out
    spec = load_rack(rack)
    assert text == opensees_script(compile_rack(spec), pallets="rigid", source=rack.name,
                                   hysteresis=spec.hysteresis)
    assert "'Pinching4'" in text and "'ElasticPP'" in text


def test_nonlinear_script_runs_in_opensees(tmp_path: Path) -> None:
    """The exported nonlinear script builds and runs; a strong pulse leaves a residual drift."""
    pytest.importorskip("openseespy.opensees")
    spec = load_rack(_nonlinear_rack(tmp_path))
    script = tmp_path / "rack_ops.py"
    script.write_text(opensees_script(compile_rack(spec), pallets="rigid",
                                      hysteresis=spec.hysteresis))
    code = (
        f"import json, math, runpy; ns = runpy.run_path({str(script)!r}, run_name='x'); "
        "ag = [6.0 * math.sin(2 * math.pi * 1.0 * k * 0.005) if k < 200 else 0.0 "
        "for k in range(1201)]; h = ns['history'](ag, 0.005); "
        "epp = [n for n, m in enumerate(ns['SPRING_MATERIALS']) if m[0] == 'ElasticPP']; "
        "print('OUT=' + json.dumps([h['level_displacement'][-1][0], "
        "max(abs(row[n]) for row in h['spring_force'] for n in epp)]))"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, check=True)
    drift, m_max = json.loads([x for x in res.stdout.splitlines() if x.startswith("OUT=")][-1][4:])
    assert 1e-3 < abs(drift) < 0.2
    assert m_max == pytest.approx(3000.0, rel=1e-9)  # the bases (ElasticPP) reached My
