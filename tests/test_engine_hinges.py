"""Nonlinear hinges in the stick–slip engine (issue #12).

References:
- an elastic–perfectly plastic single-DOF oscillator under a sine ground acceleration, solved
  independently here by event-driven integration (scipy ``solve_ivp``, DOP853, rtol 1e-12):
  elastic phases ``m ü + c u̇ + k (u − u_p) = −m a_g``, plastic phases with the spring force
  held at ±F_y, yield when ``k (u − u_p)`` reaches ±F_y, unloading when the velocity changes
  sign (Chopra, *Dynamics of Structures*, §7.1–7.3, the elastoplastic system). The engine
  (average-acceleration Newmark with Newton on the hinge inside the step) must converge to it
  at order 2 (fitted over eight time steps) and close its energy balance;
- the engine's own linear path: a hinge that never yields gives the linear Newmark run;
- the untruncated (full) basis: the default reduced basis of a hinge run keeps the peaks;
- the energy balance input = kinetic + strain + damping + friction + hysteresis on the
  nonlinear paper rack with sliding pallets (issue #12: within 1e-6 of the input), and the
  order of convergence of the pallets' peak sliding with hinges yielding.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from seisrack.analysis import run_rack
from seisrack.analysis.hinges import rack_hinges
from seisrack.dynamics import Sliders, simulate
from seisrack.dynamics.hinges import Hinges
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack
from seisrack.model.hinge_law import HingeLaw
from seisrack.model.spec import with_friction
from seisrack.motion.records import load_builtin_record

ROOT = Path(__file__).resolve().parents[1]

M1, K1, FY, ZETA = 1.0, (2 * np.pi) ** 2, 2.0, 0.02
C1 = 2 * ZETA * np.sqrt(K1 * M1)
A_G, W_G, T_END = 6.0, 2 * np.pi * 0.8, 6.0
NO_SLIDERS = Sliders(np.zeros(0, dtype=int), np.zeros(0), np.zeros(0))


def _ag(t):
    return A_G * np.sin(W_G * t)


def _epp_reference():
    """Event-driven EPP oscillator: list of (t0, t1, dense solution) phases."""
    t0, y0, up, phase, out = 0.0, [0.0, 0.0], 0.0, 0, []
    while t0 < T_END - 1e-12:
        if phase == 0:
            def rhs(t, y, up=up):
                return [y[1], (-M1 * _ag(t) - C1 * y[1] - K1 * (y[0] - up)) / M1]

            def up_yield(t, y, up=up):
                return K1 * (y[0] - up) - FY

            def down_yield(t, y, up=up):
                return K1 * (y[0] - up) + FY

            up_yield.terminal = down_yield.terminal = True
            up_yield.direction, down_yield.direction = 1, -1
            events = [up_yield, down_yield]
        else:
            def rhs(t, y, s=phase):
                return [y[1], (-M1 * _ag(t) - C1 * y[1] - s * FY) / M1]

            def unload(t, y):
                return y[1]

            unload.terminal = True
            unload.direction = -phase
            events = [unload]
        sol = solve_ivp(rhs, (t0, T_END), y0, events=events, rtol=1e-12, atol=1e-14,
                        dense_output=True, method="DOP853")
        out.append((t0, sol.t[-1], sol.sol))
        y0 = [sol.y[0, -1], sol.y[1, -1]]
        if sol.status == 1:
            if phase == 0:
                phase = 1 if len(sol.t_events[0]) else -1
            else:
                up = y0[0] - phase * FY / K1
                phase = 0
        t0 = sol.t[-1]
    return out


def _at(phases, t):
    u = np.empty_like(t)
    for a, b, f in phases:
        sel = (t >= a) & (t <= b)
        u[sel] = f(t[sel])[0]
    return u


def _epp_hinge(my=FY):
    code, par = HingeLaw("elastic-plastic", K1, yield_moment=my).pack()
    return Hinges([[0, -1]], [K1], [code], [par])


def _sdof(dt, hinges, **kw):
    t = np.arange(int(round(T_END / dt)) + 1) * dt
    r = simulate(np.array([[M1]]), np.array([[C1]]), np.array([[K1]]), NO_SLIDERS, dt=dt,
                 ground_accel=_ag(t), hinges=hinges, **kw)
    return t, r, r.q[:, 0] * r.phi[0, 0]


def test_epp_oscillator_converges_at_order_two():
    ref = _epp_reference()
    assert len(ref) > 10  # the oscillator yields in both directions many times
    dts = [0.01 * 2.0**-k for k in range(8)]
    errs = []
    for dt in dts:
        t, r, u = _sdof(dt, _epp_hinge())
        assert r.status == "ok"
        assert r.energy_error() < 1e-10
        errs.append(float(np.max(np.abs(u - _at(ref, t)))))
    order = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    # kinks of the law fall anywhere inside a step (they are not located), so successive
    # ratios scatter; the fitted order over the eight steps is the scheme's
    assert 1.8 < order < 2.6, (order, errs)
    assert errs[-1] < 2e-6 * 0.77  # relative to the peak displacement (0.77 m)


def test_hinge_that_never_yields_is_the_linear_run():
    dt = 0.005
    _, lin, u_lin = _sdof(dt, None, method="newmark")
    _, nl, u_nl = _sdof(dt, _epp_hinge(my=1e9))
    assert nl.hinge_moment is not None and nl.hinge_moment.shape[1] == 1
    np.testing.assert_allclose(u_nl, u_lin, rtol=0, atol=1e-12 * np.abs(u_lin).max())
    np.testing.assert_allclose(nl.hinge_moment[:, 0], K1 * u_nl, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(nl.energy["hysteresis"])) < 1e-9 * np.max(nl.energy["input"])


def test_epp_cycle_energy_is_hysteretic():
    _, r, _u = _sdof(0.002, _epp_hinge())
    th, mom = r.hinge_rotation[:, 0], r.hinge_moment[:, 0]
    assert np.max(np.abs(mom)) == pytest.approx(FY, rel=1e-12)
    # the hysteresis column is the work of the hinge minus its recoverable elastic energy
    work = np.concatenate([[0.0], np.cumsum(0.5 * (mom[1:] + mom[:-1]) * np.diff(th))])
    np.testing.assert_allclose(r.energy["hysteresis"], work - mom**2 / (2 * K1),
                               atol=1e-9 * work[-1])
    assert r.energy["hysteresis"][-1] > 0.5 * r.energy["input"][-1]


def _nonlinear_rack(mu):
    return compile_rack(with_friction(load_rack(ROOT / "examples" / "paper_rack_nonlinear.toml"),
                                      mu))


def _record(seconds, scale):
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(seconds / rec.dt)) + 1
    return dataclasses.replace(rec, accel=scale * rec.accel[:n])


def test_rack_energy_balance_with_hinges_and_sliding():
    model = _nonlinear_rack(0.5)
    r = run_rack(model, _record(15.0, 2.0), dt=0.005)
    h = r.history
    assert h.method == "newmark" and h.status == "ok"
    assert r.hinges is not None and any(p["yielded"] for p in r.hinges.peaks())
    assert np.max(np.abs(r.pallet_sliding)) > 0.01
    assert h.energy["hysteresis"][-1] > 0.0 and h.energy["friction"][-1] > 0.0
    assert h.energy_error() < 1e-6


def test_rack_reduced_basis_keeps_the_full_peaks():
    model = _nonlinear_rack(0.5)
    rec = _record(15.0, 2.0)
    full = run_rack(model, rec, dt=0.005, basis="full")
    red = run_rack(model, rec, dt=0.005)
    assert red.history.basis["kind"] == "reduced" and full.history.basis["kind"] == "full"
    for a, b in ((red.beam_displacement, full.beam_displacement),
                 (red.pallet_sliding, full.pallet_sliding),
                 (red.hinges.rotation, full.hinges.rotation)):
        # measured 8e-5 (16 vectors against 61)
        assert np.max(np.abs(a)) == pytest.approx(np.max(np.abs(b)), rel=5e-4)


def test_rack_sliding_converges_with_yielding_hinges():
    """Peak pallet sliding and peak hinge rotation against a run at 0.078 ms, dt from 5 ms
    (the default) to 0.3125 ms: fitted order ≥ 1.8 (issue 22; measured 1.90 and 1.87 with
    the composite steps after events, 1.94 and 1.92 with the trapezoidal rule throughout).
    At 10 ms the composite steps' errors are lower than the trapezoidal rule's (1.2 % against
    1.5 % of the peak sliding, 0.56 % against 0.94 % of the peak rotation): the fit starts at
    5 ms, where both schemes are in their asymptotic range."""
    model = _nonlinear_rack(0.5)
    rec = _record(8.0, 2.0)
    h = rack_hinges(model)
    assert h is not None and h.nonlinear

    def peaks(dt):
        r = run_rack(model, rec, dt=dt)
        return np.array([np.max(np.abs(r.pallet_sliding)),
                         np.max(np.abs(r.hinges.rotation))])

    dts = [0.005 / 2**k for k in range(5)]
    ref = peaks(0.01 / 128)
    errs = np.array([np.abs(peaks(dt) - ref) / ref for dt in dts])
    for col in range(2):
        order = np.polyfit(np.log(dts), np.log(errs[:, col]), 1)[0]
        assert order >= 1.8, (col, order, errs[:, col])
    assert np.all(errs[-1] < 1e-4)


def test_bad_hinges_are_refused():
    with pytest.raises(InputError, match="hinges"):
        Hinges([[0, -1]], [K1, K1], [1], np.zeros((1, 40)))
    with pytest.raises(InputError, match="hinges.k"):
        Hinges([[0, -1]], [-1.0], [1], np.zeros((1, 40)))
    with pytest.raises(InputError, match="hinges.dofs"):
        _sdof(0.01, Hinges([[3, -1]], [K1], [1], _epp_hinge().par))
    with pytest.raises(InputError, match="method"):
        _sdof(0.01, _epp_hinge(), method="exact")


def _chunk_case(friction_rate: float):  # noqa: ANN202
    """The nonlinear rack (mu 0.5 / 0.4), El Centro x 2, 6 s: simulate's arguments."""
    model = _nonlinear_rack(0.5)
    rec = _record(6.0, 2.0)
    t = np.arange(int(round(6.0 / 0.005)) + 1) * 0.005
    ag = np.interp(t, rec.time, rec.accel)
    sl = Sliders(model.pallet_dofs[:, 0, 0], model.pallet_mass, 0.5, 0.4,
                 friction_rate=friction_rate)
    args = (model.M_sparse, model.C_sparse, model.K_sparse, sl)
    return args, dict(dt=0.005, ground_accel=ag, influence=model.r_x,
                      hinges=rack_hinges(model))


def _assert_chunks_equal(many, one):  # noqa: ANN001
    # a resumed chunk re-derives the accelerations and the hinges' corrections from the
    # state (round-off: measured 2e-11 - 1.2e-9 of the peaks; a stuck pallet's force, set by the
    # accelerations, where Newmark's 4/h² amplifies the 1e-12 Newton tolerance, 1.3e-7)
    for name, tol in (("q", 1e-8), ("sliding", 1e-8), ("friction", 1e-6),
                      ("hinge_moment", 1e-8)):
        np.testing.assert_allclose(getattr(many, name), getattr(one, name), rtol=0,
                                   atol=tol * np.max(np.abs(getattr(one, name))))
    for key, e in one.energy.items():
        np.testing.assert_allclose(many.energy[key], e, atol=1e-10 * np.max(one.energy["input"]))


def test_chunked_run_equals_one_chunk():
    """Hinge states, the hinge work and velocity-dependent sliding carry over chunk ends."""
    args, kw = _chunk_case(5.0)
    one = simulate(*args, **kw)
    many = simulate(*args, **kw, chunk_steps=97)
    assert len(one.events) > 5
    _assert_chunks_equal(many, one)


def test_a_chunk_ending_inside_a_composite_window_changes_nothing():
    """The composite steps after an event (``_kernel_stage.py``) span the rest of the event's
    step and the next one: a chunk that ends right after an event's step hands the next chunk
    a composite step still to take (``e_state``), and the algorithmic energy term."""
    args, kw = _chunk_case(0.0)
    one = simulate(*args, **kw)
    assert len(one.events) > 5 and np.max(np.abs(one.energy["algorithmic"])) > 0.0
    # the first chunk ends at the end of the step of the first event
    k = int(np.floor(one.events[0].time_s / 0.005)) + 1
    many = simulate(*args, **kw, chunk_steps=k)
    assert [(e.slider, e.kind) for e in many.events] == [(e.slider, e.kind) for e in one.events]
    _assert_chunks_equal(many, one)


def test_connections_start_from_their_gravity_moment():
    """A connector's moment under gravity equals k θ of the design operators' own static
    gravity solve (and, without P-Δ, the beam end moment there: equilibrium of the beam end
    node; with P-Δ the beams' geometric end forces, not in the elastic member forces, make
    up the measured 0.24 %)."""
    model = _nonlinear_rack(0.5)
    h = rack_hinges(model)
    m0 = h.initial_moment()
    assert np.all(np.abs(m0) < 0.5 * 2500.0)
    r = run_rack(model, _record(2.0, 0.01), dt=0.005)  # a whisper: stays elastic
    design = r.summary()["design"]["connector_moment_Nm"]
    grav = dict(zip(design["labels"], design["gravity"], strict=True))
    for lab, mom in zip(r.hinges.labels, m0, strict=True):
        if lab.startswith("connector"):
            _, lev, bay, end = lab.split()
            assert abs(mom) == pytest.approx(abs(grav[f"{lev}-{bay}-{end}"]), rel=1e-9)
    np.testing.assert_allclose(r.hinges.moment[0], m0, rtol=1e-12)


def test_gravity_that_yields_a_connection_is_refused():
    import tomllib

    from seisrack.model.load import rack_from_dict

    d = tomllib.loads((ROOT / "examples" / "paper_rack_nonlinear.toml").read_text())
    d["hysteresis"]["beam_to_upright"]["yield_moment"] = 300.0  # < the gravity moment (~600)
    with pytest.raises(InputError, match="hysteresis.beam_to_upright") as exc:
        compile_rack(rack_from_dict(d))
    assert "gravity rotation" in str(exc.value)


def test_hinge_peaks_do_not_depend_on_decimation():
    model = _nonlinear_rack(0.5)
    rec = _record(8.0, 2.0)
    full = run_rack(model, rec, dt=0.005).hinges.peaks()
    dec = run_rack(model, rec, dt=0.005, save_every=7).hinges.peaks()
    for a, b in zip(full, dec, strict=True):
        assert b["peak_rotation_rad"] == pytest.approx(a["peak_rotation_rad"], rel=1e-12)
        assert b["peak_moment_Nm"] == pytest.approx(a["peak_moment_Nm"], rel=1e-12)


def test_study_runs_use_the_hinge_basis():
    """A study prepares each rack once (seisrack.analysis.prepare_run, as studies.executors
    does); with nonlinear connections its basis must be the hinge-augmented Ritz basis
    run_rack builds, not the elastic one."""
    from seisrack.analysis import prepare_run

    model = _nonlinear_rack(0.5)
    rec = _record(8.0, 2.0)
    prepared = prepare_run(model)
    direct = run_rack(model, rec, dt=0.005)
    assert prepared.basis.size == direct.history.basis["size"] == 16
    via = run_rack(model, rec, dt=0.005, basis=prepared.basis)
    np.testing.assert_array_equal(via.hinges.moment, direct.hinges.moment)
