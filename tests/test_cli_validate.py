"""``seisrack validate --json`` / ``--plot`` (issue #3): structure of the output, engine-produced.

Source: issue #3, "Validation examples 2 and 3": the JSON holds example2 {"1.0","0.5","0.3"} and
example3 {"10.0","0.5","0.3","0.1"}; each entry holds, from the production engine at dt = 1 ms,
``max_abs_displacement_m`` (one value per structural DOF), ``max_abs_sliding_m``,
``sliding_phases`` and ``final_sliding_m``.

Runtime: a full ``validate`` takes ~20 s, almost all of it in the event-driven reference solver
(DOP853 at rtol 1e-11 with a Python right-hand side, 2–4 s per case; the engine needs ~0.05 s
per case). The engine-vs-reference agreement itself is tested in ``test_engine_examples.py``, so
here the reference is run on the first 0.2 s only (the real solver, a shorter duration) while
the engine runs the full 10 s that the JSON reports.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import seisrack.validation.examples as exm
from seisrack.cli import main
from seisrack.dynamics import Sliders, simulate

KEYS = {"max_abs_displacement_m", "max_abs_sliding_m", "sliding_phases", "final_sliding_m"}


@pytest.fixture
def short_reference(monkeypatch):
    real = exm.run_reference

    def run_reference(ex, mu, save_dt=1e-3):
        return real(dataclasses.replace(ex, duration=0.2), mu, save_dt=save_dt)

    monkeypatch.setattr(exm, "run_reference", run_reference)


def _validate(capsys, argv):
    rc = main(argv)
    out, err = capsys.readouterr()
    assert rc == 0, err
    return out


def test_validate_json_from_engine(capsys, short_reference):
    data = json.loads(_validate(capsys, ["validate", "--json"]))
    assert list(data) == ["example2", "example3"]
    assert list(data["example2"]) == ["1.0", "0.5", "0.3"]
    assert list(data["example3"]) == ["10.0", "0.5", "0.3", "0.1"]
    n_dof = {"example2": 2, "example3": 1}
    for name, entries in data.items():
        for mu, e in entries.items():
            assert KEYS <= set(e), (name, mu)
            assert e["source"] == "engine" and e.get("status") == "ok"
            assert len(e["max_abs_displacement_m"]) == n_dof[name]
            assert all(isinstance(x, float) and x > 0 for x in e["max_abs_displacement_m"])
            assert isinstance(e["sliding_phases"], int) and e["sliding_phases"] >= 0
            assert e["max_abs_sliding_m"] >= abs(e["final_sliding_m"])
    # the values are the engine's at dt = 1 ms: recompute one entry independently
    ex = exm.example3()
    res = simulate(ex.M, ex.C, ex.K, Sliders([ex.slider_dof], [ex.slider_mass], 0.3),
                   dt=1e-3, ground_accel=ex.ground_accel(1e-3), influence=ex.influence, g=ex.g)
    e = data["example3"]["0.3"]
    assert e["max_abs_displacement_m"][0] == pytest.approx(float(np.max(np.abs(res.u))), 1e-12)
    assert e["max_abs_sliding_m"] == pytest.approx(float(np.max(np.abs(res.sliding))), 1e-12)
    assert e["final_sliding_m"] == pytest.approx(float(res.sliding[-1, 0]), 1e-12)
    assert e["sliding_phases"] == res.sliding_phases() > 0
    # never-sliding cases (mu = 1.0 / 10) report no sliding
    assert data["example2"]["1.0"]["sliding_phases"] == 0
    assert data["example3"]["10.0"]["max_abs_sliding_m"] < 1e-12


def test_validate_plot_writes_pngs(capsys, short_reference, tmp_path):
    out_dir = tmp_path / "figs"
    _validate(capsys, ["validate", "--plot", str(out_dir)])
    pngs = sorted(p.name for p in out_dir.glob("*.png"))
    assert pngs == ["example2.png", "example3.png"]
    for p in out_dir.glob("*.png"):
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000
