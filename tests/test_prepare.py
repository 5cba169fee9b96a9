"""What a rack's runs share, prepared once (``seisrack.analysis.prepare_run``): the pallets as
the prepared engine's sliders (built once, a run sets only their friction), the local basis
as a sparse matrix made once, the recovery operators from one pass over the members.

References: the compiled model's own arrays (pallet supports, masses, friction), and the
operators built separately (``recovery_operators``, ``design_operators``), which the one-pass
builder must reproduce exactly.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis import prepare_run, run_rack
from seisrack.analysis.engines import run_sliders
from seisrack.analysis.prepare import RIGID_MU
from seisrack.dynamics import PlanarSliders, Sliders
from seisrack.dynamics.local import LocalSliders
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack
from seisrack.motion import Record

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def paper():
    return compile_rack(load_rack(ROOT / "examples/paper_rack.toml"))


def test_each_engine_prepares_its_own_sliders_once(paper):
    """The default engine's sliders of a 2D rack lie on the supports' down-aisle DOFs, the
    local engine's on every support and direction; neither builds the other's."""
    default = prepare_run(paper, design=False)
    local = prepare_run(paper, design=False, engine="local")
    assert type(default.sliders) is Sliders and type(local.sliders) is LocalSliders
    np.testing.assert_array_equal(default.sliders.dof, paper.pallet_dofs[:, 0, 0])
    np.testing.assert_array_equal(local.sliders.support, paper.pallet_dofs)
    for s in (default.sliders, local.sliders):
        np.testing.assert_array_equal(s.mass, paper.pallet_mass)
        np.testing.assert_array_equal(s.mu_static, paper.pallet_mu_static)
    model3d = compile_rack(load_rack(ROOT / "examples/paper_rack_3d.toml"))
    planar = prepare_run(model3d, design=False).sliders
    assert type(planar) is PlanarSliders
    np.testing.assert_array_equal(planar.dof_z, model3d.pallet_dofs[:, :, 1])


def test_a_run_sets_the_friction_of_the_prepared_sliders(paper):
    """A study's run (same structure, other friction) and the rigid companion take the
    prepared pallets with their own friction; the prepared sliders are left as they were."""
    prepared = prepare_run(paper, design=False)
    n = paper.n_pallets
    other = replace(paper, pallet_mu_static=np.full(n, 0.31), pallet_mu_dynamic=np.full(n, 0.27))
    s = run_sliders(prepared, other)
    np.testing.assert_array_equal(s.dof, prepared.sliders.dof)
    np.testing.assert_array_equal(s.mass, paper.pallet_mass)
    assert np.all(s.mu_static == 0.31) and np.all(s.mu_dynamic == 0.27)
    np.testing.assert_array_equal(s.friction_rate, paper.pallet_friction_rate)
    rigid = run_sliders(prepared, other, RIGID_MU)
    assert np.all(rigid.mu_static == RIGID_MU) and np.all(rigid.mu_dynamic == RIGID_MU)
    assert np.all(rigid.friction_rate == 0.0)
    np.testing.assert_array_equal(prepared.sliders.mu_static, paper.pallet_mu_static)
    local = prepare_run(paper, design=False, engine="local")
    assert np.all(run_sliders(local, other).mu_dynamic == 0.27)


def test_a_prepared_run_of_other_pallets_is_refused(paper):
    """The sliders come from the prepared run: a model whose pallets weigh otherwise is
    refused by name before any work, not run with the prepared masses."""
    prepared = prepare_run(paper, design=False)
    heavier = replace(paper, pallet_mass=2.0 * np.asarray(paper.pallet_mass))
    with pytest.raises(InputError) as exc:
        run_rack(heavier, Record(np.zeros(5), 0.01), prepared=prepared)
    assert exc.value.field == "prepared" and "pallets" in str(exc.value)


def test_the_local_basis_matrix_is_made_once(paper):
    b = prepare_run(paper, design=False, engine="local").basis
    assert b.phi is b.phi
    np.testing.assert_array_equal(b.phi.toarray(), b.matrix().toarray())


def test_one_pass_gives_both_operator_sets(paper):
    from seisrack.fe.recovery import design_operators, rack_operators, recovery_operators

    rec, des = rack_operators(paper)
    rec_only, none = rack_operators(paper, design=False)
    assert none is None
    ref_rec, ref_des = recovery_operators(paper), design_operators(paper)
    for a, b, c in ((rec.base_shear, rec_only.base_shear, ref_rec.base_shear),
                    (rec.below[0], rec_only.below[0], ref_rec.below[0]),
                    (des.axial, des.axial, ref_des.axial),
                    (des.connector_moment, des.connector_moment, ref_des.connector_moment)):
        np.testing.assert_array_equal(a.toarray(), c.toarray())
        np.testing.assert_array_equal(b.toarray(), c.toarray())


def test_the_local_engine_runs_its_rigid_companion(paper):
    """The companion run (every pallet held, RIGID_MU) on the local engine: its peak level
    accelerations against the default engine's companion on the same rack, an independent
    integrator (global basis, exact propagators): measured 0.034 % apart on the paper rack,
    1 s of El Centro (the local basis's own error)."""
    from seisrack.motion import load_builtin_record

    rec = load_builtin_record("elcentro_1940_ns")
    rec = replace(rec, accel=rec.accel[:int(round(1.0 / rec.dt)) + 1])
    local = run_rack(paper, rec, engine="local", rigid_companion=True)
    default = run_rack(paper, rec, rigid_companion=True)
    a, b = local.rigid_beam_acceleration_peak, default.rigid_beam_acceleration_peak
    assert a is not None and a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=0.005)
