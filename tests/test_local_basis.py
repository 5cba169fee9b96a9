"""The local basis (issue 22): block-diagonal vectors, block-tridiagonal reduced matrices, a
measured error, and a linear rack against modal superposition of its full matrices.

References:
- the reduced matrices are the projections Vᵀ K V, Vᵀ M V, Vᵀ C V of the full ones (exact
  algebra);
- the static responses K⁻¹ f of the full model (scipy sparse LU) for the basis' reported error;
- classical modal superposition of the full model (Chopra, *Dynamics of Structures*, 4th ed.,
  §13.1–13.2, with the static correction of the truncated modes, §13.1.7), modes by
  shift-invert Lanczos (scipy ``eigsh``), each modal oscillator integrated exactly for a
  piecewise-linear ground motion (``tests/test_warehouse_modal._sdof_foh``), for a 3D rack
  whose pallets cannot slide (mu = 100) under El Centro 1940 N-S down-aisle and the same
  record 10 s later cross-aisle. Acceptance (issue 22): peak mean displacement of every beam
  level within 0.5 %. Measured: see the test's assertion messages and
  docs/theory/local_engine.md §6.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from seisrack.analysis import run_rack
from seisrack.analysis.prepare import rack_sliders
from seisrack.dynamics.local import LocalSliders, local_basis, measure_error
from seisrack.dynamics.local.basis import dense
from seisrack.dynamics.local.racks import rack_basis, rack_slices
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack, with_friction
from seisrack.motion import Record, load_builtin_record
from seisrack.motion.components import combine

sys.path.insert(0, str(Path(__file__).parent))
from test_warehouse_modal import _sdof_foh  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _row(tmp_path: Path, bays: int, levels: int = 5):
    text = (ROOT / "examples/warehouse_rack_3d.toml").read_text(encoding="utf-8")
    text = text.replace("bays = {count = 10,", f"bays = {{count = {bays},"). \
        replace("levels = {count = 5,", f"levels = {{count = {levels},")
    path = tmp_path / f"row_{bays}x{levels}.toml"
    path.write_text(text, encoding="utf-8")
    return compile_rack(with_friction(load_rack(path), 100.0))


def test_reduced_matrices_are_the_projection(tmp_path):
    model = _row(tmp_path, 3, 2)
    b = rack_basis(model, rack_sliders(model, "local"), check="none")
    V = b.matrix()
    assert b.n_slices == 7  # four upright lines and three bays
    for name, A in (("K", model.K_sparse), ("M", model.M_sparse), ("C", model.C_sparse)):
        full = (V.T @ (A @ V)).toarray()
        np.testing.assert_allclose(dense(b, name), full, rtol=0,
                                   atol=1e-10 * np.abs(full).max())
    # block tridiagonal: vectors live on one slice each, elements join adjacent slices
    sl = rack_slices(model)
    coo = sp.coo_matrix(model.K_sparse)
    assert np.abs(sl[coo.row] - sl[coo.col]).max() == 1


def test_coupled_slices_two_apart_are_refused():
    K = sp.diags([2.0, 2.0, 2.0]) - sp.eye(3, k=2) - sp.eye(3, k=-2)
    sl = LocalSliders([0], 10.0, 0.3)
    with pytest.raises(InputError) as exc:
        local_basis(sp.eye(3), 0 * K, K, np.array([0, 1, 2]), np.ones((3, 1)),
                    sl.patterns(3))
    assert exc.value.field == "slices"


def test_measured_error_falls_with_the_tolerance(tmp_path):
    model = _row(tmp_path, 4, 3)
    errs, sizes = [], []
    for tol in (0.3, 0.1, 0.03):
        b = rack_basis(model, rack_sliders(model, "local"), tol=tol, check="none")
        sl = LocalSliders(model.pallet_dofs, model.pallet_mass, 0.3)
        n = model.n_dof
        loads = np.column_stack([model.M_sparse @ model.r_x, model.M_sparse @ model.r_z])
        err = measure_error(b, model.M_sparse, model.K_sparse, loads, sl.patterns(n),
                            mass_extra=sl.attached_mass(n), n_modes=6)
        errs.append(err["static_energy_max"])
        sizes.append(b.size)
        assert err["frequency_error_max"] < 0.02
    assert sizes[0] < sizes[1] < sizes[2]
    assert errs[0] > errs[1] > errs[2], errs
    assert errs[1] < 0.1


def _modal_reference(model, ag_x, ag_z, dt, levels):  # noqa: ANN001, ANN202
    """Peak |mean displacement| of every level (n_level, 2), x and z, under both components
    (modal superposition with the static correction of the truncated modes), the modal mass
    fraction kept, the number of modes and the highest frequency kept [Hz]."""
    Mt = model.total_mass_sparse().tocsc()
    K = model.K_sparse.tocsc()
    a0, a1 = model.damping_coefficients
    assert a0 == 0.0  # C = a1 K: classical modes with zeta_n = a1 w_n / 2
    comps = ((model.r_x, ag_x), (model.r_z, ag_z))
    k = 60
    while True:
        w2, phi = spla.eigsh(K, k=k, M=Mt, sigma=0)
        frac = min(float(np.sum((phi.T @ (Mt @ r)) ** 2) / (r @ (Mt @ r))) for r, _ in comps)
        if frac >= 0.99 or k >= 480:
            break
        k *= 2
    w = np.sqrt(w2)
    ops = [np.array([phi[np.asarray(d)].mean(axis=0) for d in lv]) for lv in levels]
    total = [0.0, 0.0]
    for r, ag in comps:
        gam = phi.T @ (Mt @ r)
        D = _sdof_foh(w, 0.5 * a1 * w, -ag, dt) * gam
        resid = spla.spsolve(K, Mt @ r) - phi @ (gam / w2)
        for c in range(2):
            rl = np.array([resid[np.asarray(d)].mean() for d in levels[c]])
            total[c] = total[c] + D @ ops[c].T - np.outer(ag, rl)
    return (np.column_stack([np.abs(u).max(axis=0) for u in total]), frac, k,
            float(w.max() / (2 * np.pi)))


def _check_linear_row(tmp_path, bays):  # noqa: ANN001, ANN202
    model = _row(tmp_path, bays, 5)
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(10.0 / rec.dt)) + 1
    dt = 0.005
    t = np.arange(0, 10.0 + dt / 2, dt)
    tr = np.arange(n) * rec.dt
    ax = np.interp(t, tr, rec.accel[:n])
    az = np.interp(t, tr, np.roll(rec.accel, -1000)[:n])
    run = run_rack(model, combine(Record(ax, dt, "x"), Record(az, dt, "z")), dt=dt,
                   engine="local", save_every=None)
    assert run.history.stuck.all() and not run.history.events
    ref, frac, k, f_max = _modal_reference(model, ax, az, dt, model.level_dofs)
    err = np.abs(run.full_peaks["beam_displacement"] / ref - 1.0)
    return err, frac, k, f_max, run


def test_linear_rack_matches_modal_superposition_4_bays(tmp_path):
    err, frac, k, _, _ = _check_linear_row(tmp_path, 4)
    assert frac >= 0.99
    assert err.max() < 0.005, (err, k)


@pytest.mark.slow
def test_linear_40_bay_rack_matches_modal_superposition(tmp_path):
    err, frac, k, f_max, run = _check_linear_row(tmp_path, 40)
    # 480 modes reach only 9.4 Hz (a long row has many local beam and frame modes) and hold
    # 97.6 % of the mass; the modes above enter through the static correction, which is exact
    # for modes far above the record's frequencies and approximate for those near 10 Hz: the
    # reference itself is good to a fraction of a percent here (measured: 0.49 % apart)
    assert frac >= 0.95 and f_max > 8.0, (frac, f_max)
    assert run.history.energy_error() < 1e-6
    assert err.max() < 0.005, (err, k)
