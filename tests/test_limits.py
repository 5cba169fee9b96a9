"""Sizes estimated before work (issue 23, class 2), and progress on every long step.

- racks: ``bays = {count = 100000000}``, ``subdivisions = 100000``, a 2000 x 50 rack and a
  bracing ``panel = 0.0001`` are refused at load time, naming the field, with the estimated
  DOFs and memory and the limit; the DOF estimate agrees with the compiled models of the
  examples (exactly for the 2D racks whose pallets are off the mesh stations);
- runs: ``--free-vibration 1e7`` is refused before anything is allocated, with the figure;
  a run over the memory budget suggests a ``--save-every``; the memory estimate is checked
  against the peak measured by ``tracemalloc`` (numpy reports its buffers to it);
- modal analyses: too many modes (the dense solver's n² memory) are refused;
- studies: a 2,000,000-run study is refused from the file alone (no expansion) unless
  ``--yes``; a study estimated too long likewise;
- progress: plain lines on a stream that is not a terminal, a heartbeat during one long call.
"""

from __future__ import annotations

import copy
import io
import json
import time
import tomllib
import tracemalloc
from pathlib import Path

import pytest

from rack_inputs import EXAMPLES, PAPER_RACK
from seisrack import limits
from seisrack.cli import main
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack
from seisrack.model.load import rack_from_dict


def _toml(name: str) -> dict:
    with (EXAMPLES / name).open("rb") as fh:
        return tomllib.load(fh)


def _refused(d: dict, field: str) -> InputError:
    t0 = time.perf_counter()
    with pytest.raises(InputError) as exc:
        rack_from_dict(d)
    assert time.perf_counter() - t0 < 30  # refused before any meshing (typically ms)
    assert exc.value.field == field, str(exc.value)
    return exc.value


# ------------------------------------------------------------------------------ racks
def test_huge_bay_count_refused_before_the_lengths_exist():
    d = _toml("warehouse_rack.toml")
    d["geometry"]["bays"] = {"count": 100_000_000, "pitch": 2.7}
    err = _refused(d, "geometry.bays.count")
    assert "10,000" in str(err)


def test_subdivisions_limit():
    d = _toml("warehouse_rack.toml")
    d["geometry"]["subdivisions"] = 100_000
    _refused(d, "geometry.subdivisions")


def test_2000_by_50_rack_names_its_size():
    d = _toml("warehouse_rack.toml")
    d["geometry"]["bays"] = {"count": 2000, "pitch": 2.7}
    d["geometry"]["levels"] = {"count": 50, "pitch": 1.5}
    err = _refused(d, "geometry.bays")
    text = str(err)
    assert "DOFs" in text and f"{limits.MAX_RACK_DOFS:,}" in text and "GB" in text


def test_subdivisions_named_when_they_make_the_rack_large():
    d = _toml("warehouse_rack.toml")
    d["geometry"]["bays"] = {"count": 100, "pitch": 2.7}
    d["geometry"]["levels"] = {"count": 30, "pitch": 1.5}
    d["geometry"]["subdivisions"] = 40
    _refused(d, "geometry.subdivisions")


def test_bracing_panel_of_a_tenth_of_a_millimetre():
    d = _toml("paper_rack_3d.toml")
    d["bracing"]["panel"] = 0.0001
    err = _refused(d, "bracing.panel")
    assert "20,001 panel points" in str(err)
    d["bracing"]["panel"] = [0.0001 * k for k in range(5000)]
    _refused(d, "bracing.panel")


@pytest.mark.parametrize("name", ["paper_rack.toml", "three_level_rack.toml",
                                  "warehouse_rack.toml", "paper_rack_3d.toml",
                                  "warehouse_rack_3d.toml"])
def test_dof_estimate_against_the_compiled_model(name):
    from seisrack.model.load import _extra_heights

    spec = load_rack(EXAMPLES / name)
    g = spec.geometry
    pts = 0 if spec.bracing is None else _extra_heights(g, spec.bracing.panel_points)
    est = limits.rack_size(g.n_bays, g.n_levels, g.subdivisions, len(spec.pallets),
                           three_d=g.depth is not None, panel_points=pts).dofs
    n = compile_rack(spec).n_dof
    assert n <= est <= 1.25 * n  # an upper bound, close (pallets on stations merge)
    if name in ("three_level_rack.toml", "warehouse_rack.toml"):
        assert est == n


# ------------------------------------------------------------------------------ runs
def test_free_vibration_1e7_refused_up_front(monkeypatch, capsys):
    import seisrack.analysis as analysis

    def never(*a, **k):  # noqa: ANN002, ANN003
        raise AssertionError("the run started")

    monkeypatch.setattr(analysis, "run_rack", never)
    assert main(["run", str(PAPER_RACK), "--builtin", "elcentro_1940_ns",
                 "--free-vibration", "1e7", "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--free-vibration"
    assert "record samples" in err["message"] and "analysis steps" in err["message"]


def test_over_budget_suggests_save_every(monkeypatch, capsys):
    monkeypatch.setattr(limits, "memory_budget", lambda: 60e6)
    argv = ["run", str(PAPER_RACK), "--builtin", "elcentro_1940_ns", "--free-vibration",
            "1000", "--json"]
    assert main(argv) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["field"] == "--save-every"
    every = int(err["allowed"].split("--save-every ")[1].rstrip(")"))
    est = limits.estimate_run(n_record=3995, k=2, n_pad=100_000, n_dof=61, n_pallets=4,
                              n_levels=1, save_every=every)
    assert est.memory <= 60e6  # the suggestion fits
    assert main([*argv, "--save-every", str(every)]) == 0
    assert json.loads(capsys.readouterr().out)["status"] == "ok"


def test_a_ritz_basis_too_large_to_prepare_is_refused_by_name():
    """A rack row whose Ritz basis preparation (the static responses of one load pattern per
    pallet and direction, n_dof x 2 m) exceeds the budget is refused naming the rack, not
    --save-every (no choice of kept samples makes it fit); the local engine, which builds no
    such basis, is not."""
    kw = {"n_record": 2001, "k": 2, "n_pad": 0, "n_dof": 60_000, "n_pallets": 4_000,
          "n_levels": 10, "save_every": None, "three_d": True}
    est = limits.estimate_run(**kw)
    assert est.prep_memory == 8.0 * (60_000 * 8_003 + 3 * 8_003 ** 2)  # 5.4 GB
    with pytest.raises(InputError) as exc:
        limits.check_run(est, n_record=2001, n_pad=0, save_every=None, budget=4 * 2**30)
    assert exc.value.field == "rack" and "--engine local" in str(exc.value)
    local = limits.estimate_run(**kw, engine="local")
    assert local.prep_memory == 0.0
    limits.check_run(local, n_record=2001, n_pad=0, save_every=None, budget=4 * 2**30)


def test_the_local_engine_is_priced_as_itself():
    """``--engine local`` on the 40 x 8 row (20,836 DOFs, 960 pallets, 20 s of the EC8 pair at
    5 ms): measured 401.4 s CPU (``benchmarks/results/rack_row.md``, 2026-11-28); the default
    engine's price of the same run (about 2 min) is what the CLI announced before."""
    kw = {"n_record": 2001, "k": 2, "n_pad": 0, "n_dof": 20_836, "n_pallets": 960,
          "n_levels": 8, "save_every": None, "three_d": True}
    local = limits.estimate_run(**kw, engine="local")
    default = limits.estimate_run(**kw)
    assert 401.4 / 1.5 < local.seconds < 401.4 * 1.5, local.seconds
    assert default.seconds < local.seconds / 2
    # the 150-pallet example (10 x 5, 3,364 DOFs): 49.6 s measured
    small = limits.estimate_run(**{**kw, "n_dof": 3_364, "n_pallets": 150, "n_levels": 5},
                                engine="local")
    assert 49.6 / 1.5 < small.seconds < 49.6 * 1.5, small.seconds


def test_run_memory_estimate_against_tracemalloc():
    """The estimate bounds the measured peak of the Python/numpy allocations of a run, within
    a factor of 4 either way (it is meant to tell a typo from a large job)."""
    from seisrack.analysis import analysis_grid, run_rack
    from seisrack.motion import load_builtin_record

    model = compile_rack(load_rack(EXAMPLES / "three_level_rack.toml"))
    rec = load_builtin_record("elcentro_1940_ns")
    run_rack(model, rec)  # warm: the basis and operators are cached per model
    k = analysis_grid(rec, None)
    est = limits.estimate_run(n_record=rec.n, k=k, n_pad=4000, n_dof=model.n_dof,
                              n_pallets=model.n_pallets, n_levels=len(model.level_dofs),
                              save_every=1)
    tracemalloc.start()
    try:
        run_rack(model, rec, free_vibration=40.0)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert est.memory / 4 < peak < 4 * est.memory, (peak, est.memory)


def test_written_run_memory_estimate_counts_the_design_histories(tmp_path):
    """A 3D run written to ``timehistory.nc``: the design histories per kept sample are the
    dataset's own count, and the estimate bounds the measured peak of the run and its writer
    (tracemalloc) within a factor of 4 either way (the estimate used to leave the writer out:
    the 40 x 8 row measured 1.42 GB of process memory against 387 MB estimated)."""
    import numpy as np

    from seisrack.analysis import analysis_grid, run_rack
    from seisrack.motion import generate_ec8_record
    from seisrack.motion.components import combine
    from seisrack.report.rack_io import response_dataset, write_timehistory

    model = compile_rack(load_rack(EXAMPLES / "paper_rack_3d.toml"))
    a = generate_ec8_record(ag=0.25, duration=8.0, dt=0.01, seed=1)
    b = generate_ec8_record(ag=0.25, duration=8.0, dt=0.01, seed=2)
    rec = combine(a, b)
    # warm: the basis and operators are cached per model, and xarray's import alone traces
    # some 40 MB (a fixed cost, not the run's)
    write_timehistory(run_rack(model, rec), tmp_path / "warm.nc", model=model)
    n_design = limits.design_items(n_bays=len(model.upright_x) - 1,
                                   n_levels=len(model.level_y), three_d=True,
                                   n_sides=int(np.max(model.element_side)) + 1)
    tracemalloc.start()
    try:
        resp = run_rack(model, rec)
        write_timehistory(resp, tmp_path / "th.nc", model=model)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    ds = response_dataset(resp, model=model)
    design = ("beam_end_moment", "beam_end_shear", "connector_moment", "connector_rotation",
              "upright_axial_force", "upright_section_moment",
              "upright_section_moment_cross_aisle", "upright_moment_connection",
              "upright_moment_base", "interstorey_drift_ratio",
              "interstorey_drift_ratio_cross_aisle")
    assert n_design == sum(ds[v].size // ds.sizes["time"] for v in design)
    est = limits.estimate_run(n_record=rec.n, k=analysis_grid(rec, None), n_pad=0,
                              n_dof=model.n_dof, n_pallets=model.n_pallets,
                              n_levels=len(model.level_y), save_every=1, three_d=True,
                              n_design=n_design)
    bare = limits.estimate_run(n_record=rec.n, k=analysis_grid(rec, None), n_pad=0,
                               n_dof=model.n_dof, n_pallets=model.n_pallets,
                               n_levels=len(model.level_y), save_every=1, three_d=True)
    assert est.memory / 4 < peak < 4 * est.memory, (peak, est.memory)
    assert est.memory > 1.5 * bare.memory


def test_long_run_is_announced(monkeypatch, capsys):
    monkeypatch.setattr(limits, "ANNOUNCE_S", 0.0)
    assert main(["run", str(PAPER_RACK), "--builtin", "elcentro_1940_ns", "--json"]) == 0
    err = capsys.readouterr().err
    assert "estimated: 7,988 analysis steps" in err


# ------------------------------------------------------------------------------ modal
def test_too_many_modes(monkeypatch, capsys):
    assert main(["modal", str(PAPER_RACK), "--modes", "5000", "--json"]) == 2
    assert json.loads(capsys.readouterr().out)["error"]["field"] == "--modes"
    monkeypatch.setattr(limits, "memory_budget", lambda: 1e5)
    assert main(["modal", str(EXAMPLES / "three_level_rack.toml"), "--modes", "100"]) == 2
    assert "dense solver" in capsys.readouterr().err


# ------------------------------------------------------------------------------ studies
def _study(tmp: Path, samples: int, ida_stop: float) -> Path:
    (tmp / "rack.toml").write_bytes(PAPER_RACK.read_bytes())
    p = tmp / "s.toml"
    p.write_text('racks = ["rack.toml"]\n[records]\nbuiltin = "elcentro_1940_ns"\n'
                 f"[intensity]\nida = {{start = 0.1, step = 0.1, stop = {ida_stop}}}\n"
                 f'[friction]\ndist = "lognormal"\nmedian = 0.4\ndispersion = 0.2\n'
                 f"samples = {samples}\n")
    return p


def test_two_million_run_study_refused_from_the_file(tmp_path, capsys, monkeypatch):
    import seisrack.studies as studies

    monkeypatch.setattr(studies, "plan", lambda *a, **k: pytest.fail("expanded"))
    p = _study(tmp_path, 2000, 100.0)
    t0 = time.perf_counter()
    assert main(["study", str(p), "--out", str(tmp_path / "o"), "--json"]) == 2
    assert time.perf_counter() - t0 < 60
    err = json.loads(capsys.readouterr().out)["error"]
    assert err["value"] == "2,000,000 runs" and "--yes" in err["allowed"]
    assert not (tmp_path / "o").exists()
    from seisrack.studies import load_study
    from seisrack.studies.size import check_study_count

    assert check_study_count(load_study(p), confirmed=True) == 2_000_000


def test_long_study_needs_yes(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("seisrack.studies.size.MAX_STUDY_SECONDS", 1e-3)
    p = _study(tmp_path, 1, 0.2)  # 2 runs
    assert main(["study", str(p), "--out", str(tmp_path / "o"), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]
    assert "2 runs" in err["value"] and "--yes" in err["allowed"]
    assert main(["study", str(p), "--out", str(tmp_path / "o"), "--json", "--yes",
                 "--workers", "1"]) == 0
    assert json.loads(capsys.readouterr().out)["runs_ok"] == 2


def test_ec8_suite_limits(tmp_path):
    from seisrack.studies.spec import study_from_dict

    (tmp_path / "r.toml").write_bytes(PAPER_RACK.read_bytes())
    base = {"racks": ["r.toml"], "intensity": {"stripes": [1.0]},
            "records": {"ec8": {"count": 7}}}
    study_from_dict(base, base=tmp_path)
    for key, value in (("count", 10**9), ("duration", 1e9)):
        d = copy.deepcopy(base)
        d["records"]["ec8"][key] = value
        with pytest.raises(InputError) as exc:
            study_from_dict(d, base=tmp_path)
        assert exc.value.field == f"records.ec8[0].{key}"


# ------------------------------------------------------------------------------ progress
def test_plain_progress_lines():
    from seisrack.progress import PlainProgress

    buf = io.StringIO()
    bar = PlainProgress(1000, "time history", "step", stream=buf, every=0.0)
    for _ in range(4):
        bar.update(250)
    bar.set_postfix(failed=2)
    bar.close()
    lines = buf.getvalue().splitlines()
    assert len(lines) == 5 and lines[-1].endswith("done") and "failed 2" in lines[-1]
    assert lines[1].startswith("seisrack: time history: 500/1,000 steps (50 %)")
    quiet = io.StringIO()
    bar = PlainProgress(10, "x", "step", stream=quiet, every=3600.0)
    bar.update(10)
    bar.close()
    assert quiet.getvalue() == ""  # a short task prints nothing


def test_progress_on_a_pipe_is_plain(monkeypatch):
    from seisrack import progress as pr

    assert isinstance(pr.progress(10, "d", "u", stream=io.StringIO()), pr.PlainProgress)


def test_busy_heartbeat():
    from seisrack.progress import busy

    buf = io.StringIO()
    with busy("modal analysis (1,000 DOFs)", stream=buf, every=0.05):
        time.sleep(0.4)
    assert "modal analysis (1,000 DOFs): still working" in buf.getvalue()
    quick = io.StringIO()
    with busy("quick", stream=quick, every=5.0):
        pass
    assert quick.getvalue() == ""


def test_run_progress_lines_when_not_a_terminal(monkeypatch, capsys):
    from seisrack import progress as pr
    from seisrack.cli import run as run_cli

    monkeypatch.setattr(run_cli, "PROGRESS_MIN_STEPS", 100)
    monkeypatch.setattr(pr, "EVERY_S", 0.0)
    assert main(["run", str(PAPER_RACK), "--builtin", "elcentro_1940_ns", "--json"]) == 0
    cap = capsys.readouterr()
    assert "seisrack: time history:" in cap.err and "steps" in cap.err
    json.loads(cap.out)
