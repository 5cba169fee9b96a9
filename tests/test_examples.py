"""The example input files are regression tests (STYLE: examples double as tests).

Every ``examples/*.toml`` must load, compile and give a stable first mode; the multi-level
example must run through the stick–slip analysis with the engine's invariants intact: the
friction bound per pallet (Coulomb law, paper §III), the energy balance (docs/theory/
stick_slip_engine.md §6) and the total contact force capped at sum(mu_d N) while all slide.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis import run_rack
from seisrack.fe.modal import modal_analysis
from seisrack.model import compile_rack, load_rack
from seisrack.motion import Record, load_builtin_record

_DIR = Path(__file__).parent.parent / "examples"
#: rack files (study files, ``study_*.toml``, are run by tests/test_study_*.py; warehouse
#: files, ``site_*.toml``, are loaded by tests/test_warehouse.py)
EXAMPLES = sorted(p for p in _DIR.glob("*.toml") if not p.name.startswith(("study_", "site_")))
STUDIES = sorted(_DIR.glob("study_*.toml"))


def test_examples_exist() -> None:
    names = {p.name for p in EXAMPLES}
    assert {"paper_rack.toml", "three_level_rack.toml", "warehouse_rack.toml"} <= names


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_study_examples_load_and_expand(path: Path) -> None:
    from seisrack.studies import expand, load_study

    assert len(expand(load_study(path))) >= 60  # issue 13: at least 60 runs


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_compiles_and_has_a_dominant_sway_mode(path: Path) -> None:
    model = compile_rack(load_rack(path))
    modal = modal_analysis(model, n_modes=6)
    assert np.all(np.diff(modal.periods) <= 0)  # mode order: longest period first
    assert 0.05 < modal.periods[0] < 5.0
    assert modal.mass_participation[0] > 0.5
    assert model.n_pallets > 0


def test_three_level_rack_runs_with_invariants() -> None:
    model = compile_rack(load_rack(Path(__file__).parent.parent / "examples/three_level_rack.toml"))
    rec = load_builtin_record("elcentro_1940_ns")
    rec = Record(rec.accel[:600], rec.dt, name="elcentro_6s")  # first 6 s: strong shaking
    res = run_rack(model, rec, dt=0.005)
    hist = res.history
    assert res.status == "ok"
    assert hist.energy_error() < 1e-6
    assert res.beam_displacement.shape[1] == 3 and res.n_pallets == 18
    cap = model.pallet_mu_static * hist.normal
    assert np.all(np.abs(hist.friction) <= cap * (1 + 1e-9))
    # the top level moves most
    peaks = np.max(np.abs(res.beam_displacement), axis=0)
    assert peaks[2] > peaks[1] > peaks[0] > 0
