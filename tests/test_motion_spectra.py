"""Response spectra checked against independent solutions.

Sources:
- closed form: steady-state plus transient response of a damped SDOF to a harmonic ground
  acceleration (Chopra, *Dynamics of Structures*, §3.2, Eqs. 3.2.1–3.2.4), evaluated here on a
  dense time grid;
- ``scipy.signal.lsim`` (matrix-exponential solution of the state-space SDOF with linear
  interpolation of the input) on a record upsampled 50× by linear interpolation — the same
  piecewise-linear input, solved by independent code and sampled finely enough (≥ 1000 points per
  period at T = 0.05 s) to see the true peaks.
"""

import math

import numpy as np
import pytest
from scipy import signal

from seisrack.errors import InputError
from seisrack.motion import load_builtin_record, response_spectrum
from seisrack.motion.spectra import HAVE_NUMBA

BACKENDS = ["numpy"] + (["numba"] if HAVE_NUMBA else [])


def _record(seconds: float = 6.0, dt: float = 0.01) -> tuple[np.ndarray, float]:
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(seconds / dt) + 1
    return np.interp(np.arange(n) * dt, rec.time, rec.accel), dt


def _lsim_peak(a: np.ndarray, dt: float, T: float, z: float, up: int, tail: float) -> float:
    w = 2 * math.pi / T
    # the record followed by rest: zeros appended on the record's own grid, then upsampled
    a = np.concatenate([a, np.zeros(int(math.ceil(tail / dt)))])
    n = a.size
    t = np.arange((n - 1) * up + 1) * dt / up
    fine = np.interp(t, np.arange(n) * dt, a)
    sys = signal.lti([[0, 1], [-w * w, -2 * z * w]], [[0], [-1]], [[1, 0]], [[0]])
    _, y, _ = signal.lsim(sys, fine, t, interp=True)
    return float(np.max(np.abs(y)))


@pytest.mark.parametrize("backend", BACKENDS)
def test_against_lsim_on_upsampled_record(backend: str) -> None:
    a, dt = _record()
    T = np.array([0.05, 0.1, 0.25, 0.65, 1.5, 4.0])
    sp = response_spectrum(a, dt, T, 0.05, backend=backend)
    ref = np.array([_lsim_peak(a, dt, t, 0.05, up=50 if t < 1 else 10, tail=t) for t in T])
    err = np.abs(sp.sd / ref - 1.0)
    assert err.max() < 2e-3, err
    np.testing.assert_allclose(sp.psa, (2 * np.pi / T) ** 2 * sp.sd)
    np.testing.assert_allclose(sp.psv, (2 * np.pi / T) * sp.sd)


def test_sampling_alone_would_underestimate_short_periods() -> None:
    """Sub-sampling and the in-step peak matter: the grid maximum misses the peak at T = 2.5 dt."""
    a, dt = _record(4.0, 0.02)
    T = 0.05
    ref = _lsim_peak(a, dt, T, 0.05, up=200, tail=T)
    exact = response_spectrum(a, dt, [T]).sd[0]
    grid = _lsim_peak(a, dt, T, 0.05, up=1, tail=0.0)
    assert abs(exact / ref - 1) < 2e-3
    assert grid / ref < 0.99  # what a method sampling only the record's grid would report


@pytest.mark.parametrize(("T", "z"), [(0.3, 0.05), (1.0, 0.02), (2.0, 0.0)])
def test_closed_form_sdof_under_sine(T: float, z: float) -> None:
    # ü + 2ζωu̇ + ω²u = -A sin(Ω t), from rest (Chopra Eq. 3.2.1-3.2.4)
    A, W = 2.0, 2 * np.pi / 0.7
    w = 2 * np.pi / T
    wd = w * np.sqrt(1 - z * z)
    dt = 0.001
    t = np.arange(0, 8.0 + dt / 2, dt)
    r = W / w
    den = (1 - r * r) ** 2 + (2 * z * r) ** 2
    C = -A / w**2 * (1 - r * r) / den
    D = -A / w**2 * (-2 * z * r) / den
    # initial conditions u(0) = 0, u̇(0) = 0 fix the transient constants
    a0 = -D
    b0 = (-(C * W) + z * w * a0) / wd
    tt = np.arange(0, 8.0, 1e-5)
    u = np.exp(-z * w * tt) * (a0 * np.cos(wd * tt) + b0 * np.sin(wd * tt)) + C * np.sin(
        W * tt
    ) + D * np.cos(W * tt)
    ref = np.max(np.abs(u))
    sd = response_spectrum(A * np.sin(W * t), dt, [T], z, free_vibration=False).sd[0]
    # the sine is sampled at 1 ms and interpolated linearly: O((WΔt)²/8) input error
    assert sd == pytest.approx(ref, rel=5e-4)


def test_free_vibration_option() -> None:
    # a single pulse: the peak of a long-period oscillator comes after the pulse has ended
    dt = 0.01
    a = np.zeros(51)
    a[10:20] = 5.0
    with_fv = response_spectrum(a, dt, [3.0])
    without = response_spectrum(a, dt, [3.0], free_vibration=False)
    assert with_fv.free_vibration and not without.free_vibration
    assert with_fv.sd[0] > 1.2 * without.sd[0]


@pytest.mark.skipif(not HAVE_NUMBA, reason="numba not installed")
def test_numba_numpy_parity() -> None:
    a, dt = _record(3.0, 0.01)
    T = np.geomspace(0.02, 3.0, 25)
    s1 = response_spectrum(a, dt, T, 0.05, backend="numba")
    s2 = response_spectrum(a, dt, T, 0.05, backend="numpy")
    np.testing.assert_allclose(s1.sd, s2.sd, rtol=1e-12)


def test_zero_period_is_pga_and_bad_input() -> None:
    a, dt = _record(2.0)
    sp = response_spectrum(a, dt, [0.0, 0.5])
    assert sp.psa[0] == pytest.approx(np.max(np.abs(a)))
    with pytest.raises(InputError):
        response_spectrum(a, dt, [-1.0])
    with pytest.raises(InputError):
        response_spectrum(a, 0.0, [1.0])
    with pytest.raises(InputError):
        response_spectrum(np.array([0.0, np.nan, 1.0]), dt, [1.0])
    with pytest.raises(InputError):
        response_spectrum(a, dt, [1.0], damping=1.0)


@pytest.mark.parametrize("backend", BACKENDS)
def test_free_vibration_closed_form_equals_stepping(backend: str) -> None:
    # the free vibration after the record is taken in closed form from the final state; it
    # must equal stepping through explicit trailing zeros (one period of the longest oscillator)
    a, dt = _record(4.0, 0.01)
    T = np.array([0.04, 0.3, 1.0, 2.5, 6.0])
    closed = response_spectrum(a, dt, T, 0.05, backend=backend).sd
    padded = np.concatenate([a, np.zeros(int(np.ceil(T.max() / dt)) + 2)])
    stepped = response_spectrum(padded, dt, T, 0.05, backend=backend, free_vibration=False).sd
    np.testing.assert_allclose(closed, stepped, rtol=1e-6)
    # and for an undamped oscillator, whose free vibration does not decay
    a0 = response_spectrum(a, dt, [2.5], 0.0, backend=backend).sd
    s0 = response_spectrum(padded, dt, [2.5], 0.0, backend=backend, free_vibration=False).sd
    np.testing.assert_allclose(a0, s0, rtol=1e-6)
