"""Sparse recovery operators: ``U @ op`` must reproduce the direct recovery functions exactly (to
round-off) for any displacement history, since both apply the same element stiffness rows
(end forces f = k·T·u_e, reactions by nodal equilibrium, the base spring M = -k·θ), in every
horizontal direction of a 2D or a 3D rack (a 3D rack's bracing bars take part in the base
reactions); and the base shear balances a static push in each direction."""

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
    "paper_3d": lambda: load_rack(EXAMPLES / "paper_rack_3d.toml"),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def model(request):
    return compile_rack(CASES[request.param]())


def _close(a, b):
    """Equal to round-off on the scale of the values."""
    assert a.shape == b.shape
    assert np.abs(a - b).max() <= 1e-12 * max(np.abs(b).max(), 1.0)


#: the reaction slot of each horizontal direction (x, then z in 3D)
SLOT = (0, 2)


def test_shapes_and_format(model):
    op = recovery_operators(model)
    assert isinstance(op, RecoveryOperators)
    n_up, n_lev = model.level_nodes.shape
    assert (op.n_upright, op.n_level, op.n_dir) == (n_up, n_lev, model.n_dir)
    assert op.base_shear.shape == (model.n_dof, model.n_dir)
    for d in range(model.n_dir):
        assert op.base_moment[d].shape == (model.n_dof, n_up)
        assert op.below[d].shape == op.above[d].shape == (model.n_dof, n_up * n_lev)
        for A in (op.base_shear, op.base_moment[d], op.below[d], op.above[d]):
            assert sp.isspmatrix_csr(A)
        # a few non-zeros per column: one element's stiffness row (2·ndf entries at most)
        for A in (op.base_moment[d], op.below[d], op.above[d]):
            assert np.diff(A.tocsc().indptr).max() <= 2 * model.mesh.ndf


def test_operators_equal_recovery_on_identity(model):
    eye = np.eye(model.n_dof)
    op = recovery_operators(model)
    n_up, n_lev = model.level_nodes.shape
    reactions = base_reactions(model, eye)
    for d in range(model.n_dir):
        _close((eye @ op.base_shear)[:, d], -reactions[..., SLOT[d]].sum(axis=-1))
        mom = upright_moments(model, eye, d)
        _close(eye @ op.base_moment[d], mom.base)
        _close(eye @ op.below[d], mom.below.reshape(model.n_dof, n_up * n_lev))
        _close(eye @ op.above[d], mom.above.reshape(model.n_dof, n_up * n_lev))


def test_operators_on_a_history(model):
    U = np.random.default_rng(7).standard_normal((5, model.n_dof)) * 1e-3
    op = recovery_operators(model)
    reactions = base_reactions(model, U)
    for d in range(model.n_dir):
        _close((U @ op.base_shear)[:, d], -reactions[..., SLOT[d]].sum(axis=-1))
        via_op, direct = op.upright_moments(U, d), upright_moments(model, U, d)
        for name in ("base", "below", "above"):
            _close(getattr(via_op, name), getattr(direct, name))
        assert isinstance(U @ op.below[d], np.ndarray)


@pytest.mark.parametrize("name", ["paper", "paper_3d"])
def test_base_shear_balances_a_static_push(name):
    model = compile_rack(CASES[name]())
    for d in range(model.n_dir):
        P = np.zeros(model.n_dof)
        P[model.pallet_dofs[:, 0, d]] = 2500.0 / model.n_pallets
        u = np.linalg.solve(model.K, P)
        shear = u @ recovery_operators(model).base_shear
        assert shear[d] == pytest.approx(2500.0, rel=1e-9)
        assert abs(shear[1 - d]) < 1e-9 * 2500.0 if model.n_dir == 2 else True
