"""What a run keeps (``save_every``), the up-front memory check and the input checks of the
engine's storage and basis arguments.

Reference: for (a) and (b) the same run with every sample kept (``save_every=1``): decimation
must only select rows, never change them, and the peaks of a rack run are taken over every step
whatever is kept (``RackResponse.full_peaks``). For (c) the arithmetic floor of what keeping
``n`` samples costs: each kept sample holds at least ``q, qd, qdd`` (3 r float64), so 1e7
samples of a 2-coordinate system cannot take less than 0.45 GiB; a run is refused before it
allocates (tracemalloc, which numpy reports to, sees far less than the run would need).
(d) follows STYLE.md: an InputError names the field.
"""

from __future__ import annotations

import re
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from seisrack.analysis import run_rack
from seisrack.dynamics import Sliders, simulate
from seisrack.dynamics.basis import Basis, full_basis
from seisrack.errors import InputError
from seisrack.model import compile_rack, load_rack, with_friction
from seisrack.motion import Record
from seisrack.motion.records import load_builtin_record

PAPER = Path(__file__).resolve().parents[1] / "examples" / "paper_rack.toml"
DT = 0.01
N_STEPS = 1000  # 1000 % 7 = 6: the last sample is not a multiple of 7


def _building():  # noqa: ANN202
    """3-storey shear building, C = a1 K, two sliders (one on the roof, one on floor 1)."""
    k, m = 4.0e5, 1.0e3
    K = k * np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    M = m * np.eye(3)
    C = 0.004 * K
    sl = Sliders(np.array([2, 0]), np.array([300.0, 200.0]), np.array([0.2, 0.3]),
                 np.array([0.15, 0.25]))
    t = np.arange(N_STEPS + 1) * DT
    ag = 4.0 * np.sin(2 * np.pi * 1.7 * t) * np.exp(-0.2 * t)
    return M, C, K, sl, ag


def _fields(h) -> dict:  # noqa: ANN001
    return {
        "t": h.t, "q": h.q, "qd": h.qd, "qdd": h.qdd, "slider_u": h.slider_u,
        "slider_v": h.slider_v, "sliding": h.sliding, "friction": h.friction,
        "normal": h.normal, "stuck": h.stuck,
        **{f"energy.{k}": v for k, v in h.energy.items()},
    }


@pytest.mark.parametrize("chunk_steps", [None, 50])
def test_save_every_keeps_every_kth_row_and_the_last_exactly(chunk_steps):
    M, C, K, sl, ag = _building()
    full = simulate(M, C, K, sl, dt=DT, ground_accel=ag, chunk_steps=chunk_steps)
    dec = simulate(M, C, K, sl, dt=DT, ground_accel=ag, chunk_steps=chunk_steps, save_every=7)
    expect = np.r_[np.arange(0, N_STEPS + 1, 7), N_STEPS]
    assert full.sample_index is None or np.array_equal(full.sample_index,
                                                       np.arange(N_STEPS + 1))
    np.testing.assert_array_equal(dec.sample_index, expect)
    assert len(full.events) > 4  # the sliders do slide: the stick-slip state is exercised
    assert [(e.time_s, e.slider, e.kind) for e in dec.events] == [
        (e.time_s, e.slider, e.kind) for e in full.events]
    a, b = _fields(full), _fields(dec)
    assert set(a) == set(b) and len(a) >= 10
    for name in a:
        np.testing.assert_array_equal(b[name], a[name][expect], err_msg=name)


def test_save_every_none_keeps_first_and_last():
    M, C, K, sl, ag = _building()
    full = simulate(M, C, K, sl, dt=DT, ground_accel=ag)
    ends = simulate(M, C, K, sl, dt=DT, ground_accel=ag, save_every=None)
    np.testing.assert_array_equal(ends.sample_index, [0, N_STEPS])
    np.testing.assert_array_equal(ends.q, full.q[[0, -1]])
    np.testing.assert_array_equal(ends.sliding, full.sliding[[0, -1]])


def _flat(d, prefix: str = "") -> dict:  # noqa: ANN001
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flat(v, f"{prefix}{k}."))
        else:
            out[prefix + k] = np.asarray(v, dtype=float)
    return out


def test_run_rack_peaks_do_not_depend_on_what_is_kept():
    full = load_builtin_record("elcentro_1940_ns")
    rec = Record(full.accel[:501], full.dt, name="elcentro_0-5s")
    model = compile_rack(with_friction(load_rack(PAPER), 0.3))
    every = run_rack(model, rec, dt=0.005, save_every=1)
    none = run_rack(model, rec, dt=0.005, save_every=None)
    assert none.t.shape[0] == 2 and every.t.shape[0] == 1001
    assert np.max(every.pallet_peak_sliding()) > 0.01  # the pallets slide
    np.testing.assert_allclose(none.pallet_peak_sliding(), every.pallet_peak_sliding(),
                               rtol=1e-12, atol=0.0)
    a, b = _flat(every.peaks()), _flat(none.peaks())
    assert set(a) == set(b)
    for k in a:
        np.testing.assert_allclose(b[k], a[k], rtol=1e-12, atol=0.0, err_msg=k)
    # and the full-rate peaks are the peaks of the kept full history
    np.testing.assert_allclose(every.pallet_peak_sliding(),
                               np.max(np.abs(every.pallet_sliding), axis=0), rtol=1e-12)
    np.testing.assert_allclose(a["base_shear_N"], np.max(np.abs(every.base_shear)), rtol=1e-12)


def _two_dof():  # noqa: ANN202
    K = np.array([[2.0e4, -1.0e4], [-1.0e4, 1.0e4]])
    return np.eye(2) * 100.0, 0.002 * K, K, Sliders(np.array([1]), np.array([50.0]), 0.3)


def test_ten_million_steps_refused_up_front_naming_n_steps_and_gib():
    M, C, K, sl = _two_dof()
    tracemalloc.start()
    try:
        with pytest.raises(InputError) as err:
            simulate(M, C, K, sl, dt=1e-3, n_steps=10_000_000, max_memory=1e9)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert err.value.field == "n_steps"
    gib = [float(x) for x in re.findall(r"([0-9.]+) GiB", str(err.value))]
    assert len(gib) == 2, str(err.value)
    floor = (10_000_001 * 3 * 2 * 8) / 2**30  # q, qd, qdd of 2 coordinates, every sample
    assert floor <= gib[0] < 10 * floor  # what the run needs
    assert gib[1] == pytest.approx(1e9 / 2**30, abs=0.01)  # the limit given
    assert peak < 0.25 * gib[0] * 2**30  # nothing of the histories was allocated


def test_memory_check_counts_only_kept_samples():
    """10 000 steps: refused at 2.5 MB when every sample is kept (> 10 000 x 3 x 2 x 8 B of
    q, qd, qdd plus a chunk buffer), accepted with save_every=None (first and last only)."""
    M, C, K, sl = _two_dof()
    limit = 2.5e6
    with pytest.raises(InputError) as err:
        simulate(M, C, K, sl, dt=1e-3, n_steps=10_000, max_memory=limit, save_every=1)
    assert err.value.field == "n_steps"
    h = simulate(M, C, K, sl, dt=1e-3, n_steps=10_000, max_memory=limit, save_every=None)
    assert h.status == "ok" and h.q.shape[0] == 2
    # a decimated history needs less too
    simulate(M, C, K, sl, dt=1e-3, n_steps=10_000, max_memory=limit, save_every=100)


def test_bad_basis_name():
    M, C, K, sl = _two_dof()
    with pytest.raises(InputError) as err:
        simulate(M, C, K, sl, dt=1e-3, n_steps=10, basis="bogus")
    assert err.value.field == "basis" and "bogus" in str(err.value)
    model = compile_rack(with_friction(load_rack(PAPER), 0.3))
    rec = Record(np.zeros(5), 0.01)
    with pytest.raises(InputError) as err:
        run_rack(model, rec, dt=0.005, basis="bogus")
    assert err.value.field == "basis"


@pytest.mark.parametrize("value", [0, -1, 1.5, True])
def test_bad_save_every(value):
    M, C, K, sl = _two_dof()
    with pytest.raises(InputError) as err:
        simulate(M, C, K, sl, dt=1e-3, n_steps=10, save_every=value)
    assert err.value.field == "save_every"


def test_basis_with_wrong_number_of_rows():
    M, C, K, sl = _two_dof()
    K3 = np.diag([1.0e4, 2.0e4, 3.0e4])
    wrong = full_basis(np.eye(3), K3)
    assert isinstance(wrong, Basis) and wrong.phi.shape[0] == 3
    with pytest.raises(InputError) as err:
        simulate(M, C, K, sl, dt=1e-3, n_steps=10, basis=wrong)
    assert err.value.field == "basis" and "2 rows" in str(err.value)
    # the right size is accepted
    simulate(M, C, K, sl, dt=1e-3, n_steps=10, basis=full_basis(M, K))
