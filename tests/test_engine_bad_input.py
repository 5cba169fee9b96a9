"""Bad input to the stick–slip engine gets a clear ``InputError`` naming the field (issue #3).

Source: issue #3 ("non-finite values, dt <= 0, mismatched sizes, mu < 0, mu_d > mu_s, a mass on a
DOF that does not exist get a clear error") and docs/dev/interfaces.md (``InputError(field,
value, allowed)``, also a ``ValueError``; never an assert or a silent NaN).
"""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.dynamics import Sliders, simulate
from seisrack.errors import InputError

N_STEPS = 20
DT = 0.01


def _ok():
    M = np.diag([100.0, 50.0])
    K = np.array([[3e4, -1e4], [-1e4, 1e4]])
    C = 0.01 * K
    sl = Sliders(dof=[1], mass=[200.0], mu_static=[0.3], mu_dynamic=[0.2])
    ag = np.sin(np.arange(N_STEPS + 1) * DT * 10.0)
    return M, C, K, sl, {"dt": DT, "ground_accel": ag}


def _with(**changes):
    M, C, K, sl, kw = _ok()
    args = {"M": M, "C": C, "K": K, "sliders": sl}
    for k in list(changes):
        if k in args:
            args[k] = changes.pop(k)
    kw.update(changes)
    return args, kw


def _raises(field: str, **changes):
    args, kw = _with(**changes)
    kw.setdefault("backend", "numba")
    with pytest.raises(InputError) as info:
        simulate(args["M"], args["C"], args["K"], args["sliders"], **kw)
    err = info.value
    assert isinstance(err, ValueError)
    assert err.field == field and f"'{field}'" in str(err), str(err)
    return err


def test_reference_case_is_valid():
    args, kw = _with()
    res = simulate(args["M"], args["C"], args["K"], args["sliders"], **kw)
    assert res.status == "ok"


def _bad(a, idx, val):
    a = np.array(a, dtype=float)
    a[idx] = val
    return a


M0, C0, K0, _, KW0 = _ok()
AG0 = KW0["ground_accel"]


@pytest.mark.parametrize(
    ("field", "changes"),
    [
        # non-finite values
        ("M", {"M": _bad(M0, (0, 0), np.nan)}),
        ("C", {"C": _bad(C0, (1, 0), np.inf)}),
        ("K", {"K": _bad(K0, (1, 1), np.nan)}),
        ("ground_accel", {"ground_accel": _bad(AG0, 5, np.nan)}),
        ("force", {"force": _bad(np.zeros((N_STEPS + 1, 2)), (3, 1), np.inf)}),
        ("vertical_accel", {"vertical_accel": _bad(np.zeros(N_STEPS + 1), 2, np.nan)}),
        ("influence", {"influence": np.array([1.0, np.nan])}),
        # dt <= 0 or not finite
        ("dt", {"dt": 0.0}),
        ("dt", {"dt": -1e-3}),
        ("dt", {"dt": float("nan")}),
        ("dt", {"dt": float("inf")}),
        # mismatched sizes
        ("force", {"force": np.zeros((N_STEPS + 1, 3))}),
        ("force", {"force": np.zeros((N_STEPS, 2))}),
        ("influence", {"influence": np.ones(3)}),
        ("C", {"C": np.zeros((3, 3))}),
        ("K", {"K": np.eye(3)}),
        ("M", {"M": np.ones(3)}),
        ("vertical_accel", {"vertical_accel": np.zeros(N_STEPS + 5)}),
        # a mass on a DOF that does not exist
        ("sliders.dof", {"sliders": Sliders(dof=[2], mass=[1.0], mu_static=[0.3])}),
        ("sliders.dof", {"sliders": Sliders(dof=[0, -2], mass=[1.0, 1.0], mu_static=0.3)}),
        # not positive definite / not symmetric
        ("M", {"M": np.diag([100.0, -50.0])}),
        ("M", {"M": np.diag([100.0, 0.0])}),
        ("M", {"M": np.array([[100.0, 1.0], [0.0, 50.0]])}),
        ("K", {"K": np.array([[3e4, -1e4], [-2e4, 1e4]])}),
        ("K", {"K": -K0}),
        # other fields
        ("g", {"g": 0.0}),
        ("backend", {"backend": "cuda"}),
        ("n_steps", {"ground_accel": None}),
    ],
)
def test_engine_rejects(field, changes):
    _raises(field, **changes)


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("sliders.mu_static", {"mu_static": [-0.1]}),
        ("sliders.mu_dynamic", {"mu_static": [0.3], "mu_dynamic": [-0.1]}),
        ("sliders.mu_dynamic[0]", {"mu_static": [0.3], "mu_dynamic": [0.4]}),
        ("sliders.mass", {"mass": [0.0]}),
        ("sliders.mass", {"mass": [-5.0]}),
        ("sliders.mass", {"mass": [np.nan]}),
        ("sliders.mu_static", {"mu_static": [np.inf]}),
        ("sliders.mass", {"mass": [1.0, 2.0]}),
        ("sliders.dof", {"dof": [0.5]}),
    ],
)
def test_sliders_reject(field, kwargs):
    args = {"dof": [0], "mass": [1.0], "mu_static": [0.3]} | kwargs
    with pytest.raises(InputError) as info:
        Sliders(**args)
    assert info.value.field == field and f"'{field}'" in str(info.value), str(info.value)


def test_method_names_and_exact_needs_classical_damping():
    M, C, K, sl, kw = _ok()
    with pytest.raises(InputError) as exc:
        simulate(M, C, K, sl, method="rk4", **kw)
    assert exc.value.field == "method"
    rayleigh = 0.5 * M + 0.01 * K  # mass term: not classical once the slider sticks
    with pytest.raises(InputError) as exc:
        simulate(M, rayleigh, K, sl, method="exact", **kw)
    assert exc.value.field == "method" and "not classical" in str(exc.value)
    # "auto" falls back to Newmark there, and takes the exact kernel for C = 0.01 K
    assert simulate(M, rayleigh, K, sl, **kw).method == "newmark"
    assert simulate(M, C, K, sl, **kw).method == "exact"
