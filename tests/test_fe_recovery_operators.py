"""Sparse recovery operators: ``U @ op`` must reproduce the direct recovery functions exactly (to
round-off) for any displacement history, since both apply the same element stiffness rows
(end forces f = k·T·u_e, reactions by nodal equilibrium, the base spring M = -k·θ)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from rack_inputs import EXAMPLES, PAPER_RACK, portal_dict
from seisrack.fe import RecoveryOperators, base_reactions, recovery_operators, upright_moments
from seisrack.model import compile_rack, load_rack, rack_from_dict

CASES = {
    "paper": lambda: load_rack(PAPER_RACK),
    "three_level": lambda: load_rack(EXAMPLES / "three_level_rack.toml"),
    "pinned_base": lambda: rack_from_dict(portal_dict(joint="rigid", base="pinned",
                                                      bays=(1.8, 2.7))),
    "rigid": lambda: rack_from_dict(portal_dict(joint="rigid", base="rigid")),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def model(request):
    return compile_rack(CASES[request.param]())


def _close(a, b):
    """Equal to round-off on the scale of the values."""
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= 1e-12 * max(np.abs(b).max(), 1.0)


def test_shapes_and_format(model):
    op = recovery_operators(model)
    assert isinstance(op, RecoveryOperators)
    n_up, n_lev = model.level_nodes.shape
    assert (op.n_upright, op.n_level) == (n_up, n_lev)
    assert op.base_shear.shape == (model.n_dof, 1)
    assert op.base_moment.shape == (model.n_dof, n_up)
    assert op.below.shape == op.above.shape == (model.n_dof, n_up * n_lev)
    for A in (op.base_shear, op.base_moment, op.below, op.above):
        assert sp.isspmatrix_csr(A)
    # a few non-zeros per column: one element's stiffness row (at most 6 entries)
    for A in (op.base_moment, op.below, op.above):
        assert np.diff(A.tocsc().indptr).max() <= 6


def test_operators_equal_recovery_on_identity(model):
    eye = np.eye(model.n_dof)
    op = recovery_operators(model)
    shear = -base_reactions(model, eye)[..., 0].sum(axis=-1)
    _close((eye @ op.base_shear)[:, 0], shear)
    mom = upright_moments(model, eye)
    n_up, n_lev = model.level_nodes.shape
    _close(eye @ op.base_moment, mom.base)
    _close(eye @ op.below, mom.below.reshape(model.n_dof, n_up * n_lev))
    _close(eye @ op.above, mom.above.reshape(model.n_dof, n_up * n_lev))


def test_operators_on_a_history(model):
    U = np.random.default_rng(7).standard_normal((5, model.n_dof)) * 1e-3
    op = recovery_operators(model)
    _close((U @ op.base_shear)[:, 0], -base_reactions(model, U)[..., 0].sum(axis=-1))
    via_op, direct = op.upright_moments(U), upright_moments(model, U)
    for name in ("base", "below", "above"):
        _close(getattr(via_op, name), getattr(direct, name))
    assert isinstance(U @ op.below, np.ndarray)


def test_base_shear_balances_a_static_push():
    model = compile_rack(load_rack(PAPER_RACK))
    P = np.zeros(model.n_dof)
    P[model.pallet_dof] = 2500.0 / model.n_pallets
    u = np.linalg.solve(model.K, P)
    assert (u @ recovery_operators(model).base_shear)[0] == pytest.approx(2500.0, rel=1e-9)
