"""``[damping] stiffness_term``: which stiffness the a1 term of Rayleigh damping multiplies on a
rack with P-Δ: K_E + K_G (``"with_p_delta"``, the default: classical in the modes the engine
integrates in, so the exact propagators apply) or the elastic K_E (``"elastic"``: OpenSees'
``rayleigh`` with betaKinit, whose initial stiffness has no geometric term:
``PDeltaCrdTransf3d::getInitialGlobalStiffMatrix`` leaves the N/L terms out).

References: the definition C = a0·M + a1·K (Chopra, *Dynamics of Structures*, 4th ed.,
Eq. 11.4.8) with K = K_E from the rack without P-Δ (``p_delta = false``, the same mesh) and
K_G = K(P-Δ) − K_E; without P-Δ the two conventions are the same matrix, so the paper's
figures (no P-Δ) do not move. The agreement with OpenSees that "elastic" gives is in
``tests/test_opensees_hinges.py`` (2D) and ``tests/test_opensees_hinges_3d.py`` (3D). The
default stays the one whose sway damping does not grow as the rack nears buckling (with a1 K_E
and a1 set at the softened first period, the sway mode of a near-critical rack is damped
several times its nominal ratio, which hides its drift: ``tests/test_plausibility.py``).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis.rack import non_classical_damping, run_rack
from seisrack.errors import InputError
from seisrack.model import compile_rack, rack_from_dict, with_friction
from seisrack.motion import Record, load_builtin_record

ROOT = Path(__file__).resolve().parents[1]


def _paper(p_delta: bool, term: str | None = None, rack: str = "paper_rack.toml") -> dict:
    d = tomllib.loads((ROOT / "examples" / rack).read_text())
    d["second_order"] = {"p_delta": p_delta}
    if term is not None:
        d["damping"]["stiffness_term"] = term
    return d


def _dense(a) -> np.ndarray:  # noqa: ANN001
    return np.asarray(a.todense())


@pytest.mark.parametrize("rack", ["paper_rack.toml", "paper_rack_3d.toml"])
def test_without_p_delta_both_conventions_are_the_same_matrix(rack):
    el = compile_rack(rack_from_dict(_paper(False, "elastic", rack)))
    pd = compile_rack(rack_from_dict(_paper(False, "with_p_delta", rack)))
    default = compile_rack(rack_from_dict(_paper(False, None, rack)))
    for m in (pd, default):
        assert (el.C_sparse != m.C_sparse).nnz == 0
        assert el.damping_coefficients == m.damping_coefficients
    assert not non_classical_damping(el)


@pytest.mark.parametrize("rack", ["paper_rack.toml", "paper_rack_3d.toml"])
def test_with_p_delta_the_a1_term_takes_the_chosen_stiffness(rack):
    off = compile_rack(rack_from_dict(_paper(False, None, rack)))
    el = compile_rack(rack_from_dict(_paper(True, "elastic", rack)))
    pd = compile_rack(rack_from_dict(_paper(True, None, rack)))  # the default
    assert el.damping_stiffness_term == "elastic" and pd.damping_stiffness_term == "with_p_delta"
    a0, a1 = el.damping_coefficients
    assert pd.damping_coefficients == (a0, a1)  # the period of the softened rack in both
    assert a0 == 0.0 and a1 > 0.0
    K_E, K = _dense(off.K_sparse), _dense(el.K_sparse)
    assert np.abs(K - K_E).max() > 1e-6 * np.abs(K_E).max()  # P-Δ is on
    scale = a1 * np.abs(K_E).max()
    assert np.abs(_dense(el.C_sparse) - a1 * K_E).max() < 1e-12 * scale
    assert np.abs(_dense(pd.C_sparse) - a1 * K).max() < 1e-12 * scale
    assert non_classical_damping(el) and not non_classical_damping(pd)


@pytest.mark.parametrize("value", ["initial", 1, "K_E"])
def test_bad_value_names_the_field(value):
    d = _paper(True)
    d["damping"]["stiffness_term"] = value
    with pytest.raises(InputError) as err:
        rack_from_dict(d)
    assert err.value.field == "damping.stiffness_term"
    assert "with_p_delta" in str(err.value) or "string" in str(err.value)


def test_2d_exact_method_is_refused_with_elastic_damping_and_p_delta():
    rec = load_builtin_record("elcentro_1940_ns")
    short = Record(rec.accel[:201], rec.dt, rec.name)
    el = compile_rack(with_friction(rack_from_dict(_paper(True, "elastic")), 0.3))
    with pytest.raises(InputError) as err:
        run_rack(el, short, method="exact")
    assert err.value.field == "method" and "stiffness_term" in str(err.value)
    assert run_rack(el, short).history.method == "newmark"  # auto: the damping not classical
    pd = compile_rack(with_friction(rack_from_dict(_paper(True)), 0.3))  # the default
    assert pd.damping_stiffness_term == "with_p_delta"
    assert run_rack(pd, short, method="exact").history.method == "exact"
    assert run_rack(pd, short).history.method == "exact"
