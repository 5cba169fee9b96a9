"""The reworked engine (basis="full") against the previous release's exact kernel.

Reference: the exact stick–slip kernel of seisrack at commit
6042fce2d7377be3b8652886f8b10c8a9f611641 (its src/ is identical to that of 4e17cc3, the parent
of the scalable-engine commit 9aa0dd0). That kernel's validation against the independent
event-driven solver is tests/test_engine_examples.py (paper §III.B). Its results were
generated once by ``tests/data/make_previous_exact_kernel.py`` under that commit and stored
in ``tests/data/previous_exact_kernel.json`` (the commit is recorded there too).
The rework changed how the stuck set is handled (rank-one updates of the configuration mass
instead of an m x m contact matrix), the chunking and the peak recovery, but with every mode
kept nothing is truncated, so the same closed-form propagation must give the same peaks up to
round-off.

Cases: the paper rack (examples/paper_rack.toml) at mu 0.3 and 0.6, and the 3-level example
(examples/three_level_rack.toml) with stiffness-proportional damping (3 % at the first period)
so that the exact kernel applies, as given (mu 0.4: it does not slide in these 10 s) and at
mu 0.3 (12 events). El Centro 1940 N-S, first 10 s, dt 5 ms, method "exact".
Acceptance: every peak within 1e-4 of the largest value of that quantity, same event count.
Measured (new - previous, relative to the largest value): pallet sliding <= 9e-14 (paper
rack), 1.6e-8 (3-level at mu 0.3, whose sliding is only 1.65 µm: 3e-14 m), 7e-16 m absolute
where nothing slides; level displacement <= 4e-14; base shear <= 7e-14; event counts 88, 16,
0, 12 in both.
"""

from __future__ import annotations

import functools
import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis import run_rack

DATA = Path(__file__).with_name("data")
REL = 1e-4
#: [m] a sliding peak below this is round-off (the pallet never slides): compared absolutely
ZERO_SLIDING = 1e-9


def _generator():  # noqa: ANN202
    spec = importlib.util.spec_from_file_location(
        "make_previous_exact_kernel", DATA / "make_previous_exact_kernel.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@functools.cache
def _stored() -> dict:
    return json.loads((DATA / "previous_exact_kernel.json").read_text())


@functools.cache
def _new(name: str) -> dict:
    gen = _generator()
    model = gen.cases()[name]
    resp = run_rack(model, gen.record(), dt=_stored()["dt"], method="exact", basis="full",
                    rigid_companion=False)
    assert resp.history.method == "exact"
    assert resp.history.basis["kind"] == "full"
    return {"n_dof": int(model.n_dof), **gen.measure(resp)}


def test_reference_file_names_its_commit():
    ref = _stored()
    assert ref["commit"] == "6042fce2d7377be3b8652886f8b10c8a9f611641"
    assert ref["dt"] == 0.005
    assert set(ref["cases"]) == set(_generator().cases())


def _close(new, old, rel: float, floor: float = 0.0) -> None:
    new, old = np.atleast_1d(new), np.atleast_1d(old)
    assert new.shape == old.shape
    scale = max(float(np.max(np.abs(old))), floor)
    np.testing.assert_allclose(new, old, rtol=0.0, atol=rel * scale)


@pytest.mark.parametrize("name", sorted(json.loads(
    (DATA / "previous_exact_kernel.json").read_text())["cases"]))
def test_full_basis_matches_previous_exact_kernel(name):
    old = _stored()["cases"][name]
    new = _new(name)
    assert new["n_dof"] == old["n_dof"]
    assert new["n_events"] == old["n_events"]
    # a rack that never slides has round-off sliding (1e-16 m): compare on a 1 nm floor
    _close(new["pallet_peak_sliding_m"], old["pallet_peak_sliding_m"], REL, ZERO_SLIDING / REL)
    _close(new["level_peak_displacement_m"], old["level_peak_displacement_m"], REL)
    _close(new["peak_base_shear_N"], old["peak_base_shear_N"], REL)


def test_comparison_detects_a_changed_friction():
    """The check can fail: mu 0.31 instead of 0.3 moves the paper rack's peaks beyond 1e-4."""
    from seisrack.model import compile_rack, with_friction
    from seisrack.model.load import rack_from_dict

    gen = _generator()
    model = compile_rack(with_friction(rack_from_dict(gen._toml("paper_rack.toml")), 0.31))
    resp = run_rack(model, gen.record(), dt=0.005, method="exact", basis="full")
    old = _stored()["cases"]["paper_mu0.3"]
    with pytest.raises(AssertionError):
        _close(gen.measure(resp)["pallet_peak_sliding_m"], old["pallet_peak_sliding_m"], REL)
