"""Elastic response spectra of a ground-acceleration record, exact for piecewise-linear input.

Each oscillator ``ü + 2ζω u̇ + ω² u = -a_g(t)`` (u relative to the ground) is advanced with the
exact recurrence for an excitation linear within each step (Nigam & Jennings 1969; Chopra,
*Dynamics of Structures*, §5.2). With ``p = -a_g = p_k + r τ`` on a step, the particular solution
is ``u_p = α + β τ`` with ``β = r/ω²``, ``α = p_k/ω² - 2ζ r/ω³`` and the homogeneous part is the
damped free vibration, so ``x(τ) = Φ(τ) (x_k - x_p(0)) + x_p(τ)`` with Φ the free-vibration
transition matrix. Nothing is approximated for piecewise-linear input.

Peaks between samples. A peak of |u| that falls between samples would be missed by looking at
samples only (up to 1 - cos(π dt/T), 4.9 % at T = 10 dt). Two measures remove that:

1. sub-sampling: a period shorter than ``points_per_period * dt`` is integrated with
   ``m = ceil(points_per_period * dt / T)`` sub-steps per record step, interpolating the input
   linearly (still exact: the input *is* piecewise linear);
2. in-step extremum: where the velocity changes sign inside a (sub-)step, the time of zero
   velocity is located from the cubic Hermite interpolant of (u, u̇) at both ends, refined by one
   Newton step on the exact in-step solution, and the exact u there is taken.

Free vibration after the record. By default (``free_vibration=True``) the record is taken as
followed by rest (the acceleration returning linearly to zero over one (sub-)step), not as cut
off, and the peak of the free vibration that follows is included. It is found in closed form from
the final state: |u| is largest at the start of the free vibration or at its first zero of
velocity, within half a damped period (Chopra Eq. 2.2.4), so this equals following each
oscillator for one of its periods, as the reference solutions in the tests and benchmark do. Pass
``free_vibration=False`` to keep the maximum over the record duration only; this matters only
for periods comparable with the duration of the record.

Two implementations give the same numbers: a numba kernel (loop over periods, then steps) and a
pure-numpy twin (vectorised over periods). ``backend="auto"`` uses numba when installed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError

try:  # optional accelerator
    import numba as _numba
except ImportError:  # pragma: no cover - exercised where numba is absent
    _numba = None

HAVE_NUMBA = _numba is not None


@dataclass(frozen=True, eq=False)
class Spectrum:
    """Elastic response spectrum of a record.

    Attributes:
        periods: (n_T,) [s] oscillator periods.
        sd: (n_T,) [m] peak relative displacement max|u|.
        psv: (n_T,) [m/s] pseudo-velocity ω·sd.
        psa: (n_T,) [m/s²] pseudo-acceleration ω²·sd (at T = 0: the peak ground acceleration).
        damping: viscous damping ratio ζ.
        free_vibration: whether the free vibration after the record was included.
    """

    periods: np.ndarray
    sd: np.ndarray
    psv: np.ndarray
    psa: np.ndarray
    damping: float
    free_vibration: bool = True


def step_coefficients(omega: np.ndarray, zeta: float, h: np.ndarray) -> tuple[np.ndarray, ...]:
    """Exact one-step maps for a piecewise-linear excitation, vectorised over oscillators.

    Returns eight (n,) arrays ``a11, a12, a21, a22, b10, b11, b20, b21`` such that
    ``u_{k+1} = a11 u_k + a12 v_k + b10 p_k + b11 p_{k+1}`` and
    ``v_{k+1} = a21 u_k + a22 v_k + b20 p_k + b21 p_{k+1}`` for ``ü + 2ζωu̇ + ω²u = p``
    (unit mass, step ``h`` [s], ω [rad/s]).
    """
    w = np.asarray(omega, dtype=np.float64)
    wd = w * math.sqrt(1.0 - zeta * zeta)
    e = np.exp(-zeta * w * h)
    c = np.cos(wd * h)
    s = np.sin(wd * h)
    zs = zeta * w / wd * s
    # free-vibration transition matrix Φ(h) (Chopra §2.2 closed form)
    a11 = e * (c + zs)
    a12 = e * s / wd
    a21 = -w * w * a12
    a22 = e * (c - zs)
    # particular solution u_p = α + βτ, linear in (p_k, p_{k+1}); r = (p_{k+1} - p_k) / h:
    # α = p_k/ω² - 2ζ r/ω³, β = r/ω²; then u_{k+1} = Φ11 (u_k - α) + Φ12 (v_k - β) + α + β h,
    # v_{k+1} = Φ21 (u_k - α) + Φ22 (v_k - β) + β
    iw2h = 1.0 / (w * w * h)
    g = 2.0 * zeta / (w * w * w * h)
    al0, al1 = 1.0 / (w * w) + g, -g
    be0, be1 = -iw2h, iw2h
    b10 = (1.0 - a11) * al0 + (h - a12) * be0
    b11 = (1.0 - a11) * al1 + (h - a12) * be1
    b20 = -a21 * al0 + (1.0 - a22) * be0
    b21 = -a21 * al1 + (1.0 - a22) * be1
    return a11, a12, a21, a22, b10, b11, b20, b21


def _hermite_peak(u0: float, v0: float, u1: float, v1: float, h: float) -> tuple[float, float]:
    """Zero of u̇ in a step from the cubic Hermite interpolant of (u, u̇): (s ∈ [0, 1], H(s))."""
    # H(s) = u0 + a1 s + a2 s² + a3 s³ on s ∈ [0, 1]; H'(0) and H'(1) have opposite signs
    a1 = h * v0
    a2 = 3.0 * (u1 - u0) - h * (2.0 * v0 + v1)
    a3 = 2.0 * (u0 - u1) + h * (v0 + v1)
    if abs(a3) < 1e-12 * (abs(a2) + abs(a1) + 1e-300):
        s = -a1 / (2.0 * a2) if a2 != 0.0 else 0.5
    else:
        disc = max(a2 * a2 - 3.0 * a3 * a1, 0.0)
        q = -(a2 + math.copysign(math.sqrt(disc), a2))
        s = q / (3.0 * a3)
        if not (0.0 <= s <= 1.0) and q != 0.0:
            s = a1 / q
    s = min(max(s, 0.0), 1.0)
    return s, u0 + s * (a1 + s * (a2 + s * a3))


def _exact_peak(
    u0: float, v0: float, pa: float, pb: float, s: float,
    w: float, z: float, wd: float, h: float,
) -> float:
    """|u| at the zero of velocity near ``τ = s h``: one Newton step on the exact solution."""
    r = (pb - pa) / h
    beta = r / (w * w)
    alpha = pa / (w * w) - 2.0 * z * r / (w * w * w)
    c1 = u0 - alpha
    c2 = v0 - beta
    tau = s * h
    zw_wd = z * w / wd
    u = 0.0
    for it in range(2):  # evaluate, Newton step on v(τ) = 0, evaluate again
        e = math.exp(-z * w * tau)
        c = math.cos(wd * tau)
        sn = math.sin(wd * tau)
        u = e * (c + zw_wd * sn) * c1 + e * sn / wd * c2 + alpha + beta * tau
        if it == 1:
            break
        v = -e * w * w / wd * sn * c1 + e * (c - zw_wd * sn) * c2 + beta
        acc = pa + r * tau - 2.0 * z * w * v - w * w * u
        if acc != 0.0:
            tau = min(max(tau - v / acc, 0.0), h)
    return abs(u)


# The in-step peak is looked for only where u̇ changes sign and an end value reaches cand[i] times
# the running maximum. For a harmonic response sampled every ωh radians the peak exceeds the end
# values by at most 1/cos(ωh/2); cand = 0.9·cos(ωh/2) leaves a wide margin for damping and forcing
# and makes the branch rare (hence cheap). The exact solution is then evaluated only when the
# Hermite estimate (error ~ (ωh)⁴/384, < 0.05 % at 10 points per period) comes within _REFINE of
# the running maximum.
_REFINE = 0.99


def _free_peak(u0: float, v0: float, w: float, z: float, wd: float) -> float:
    """Largest |u| of the free vibration from ``(u0, v0)``: at t = 0 or at the first u̇ = 0."""
    # u(t) = e^{-ζωt} (u0 cos θ + (v0 + ζω u0)/ωd sin θ), θ = ωd t (Chopra Eq. 2.2.4);
    # u̇ ∝ Y cos θ - X sin θ with X = ω² u0 + ζω v0, Y = ωd v0: zero at θ = atan2(Y, X) + kπ.
    # |u| at successive zeros of u̇ decays, and u is monotonic between them, so the first zero
    # with θ > 0 (θ ≤ π: within half a damped period) and t = 0 bound the whole free vibration
    th = math.atan2(wd * v0, w * w * u0 + z * w * v0)
    if th <= 0.0:
        th += math.pi
    u1 = math.exp(-z * w * th / wd) * (u0 * math.cos(th) + (v0 + z * w * u0) / wd * math.sin(th))
    return max(abs(u0), abs(u1))


def _kernel_py(
    p: np.ndarray, c: np.ndarray, z: float, h: float, free: bool, out: np.ndarray,
) -> None:
    """Scalar kernel (compiled by numba): max |u| over ``p`` for each oscillator into ``out``.

    ``c`` (11, n_osc) holds, per oscillator, the eight step coefficients of
    :func:`step_coefficients`, then ω, ω_d and the candidate threshold (one array: one argument
    to unbox per call).

    Steps are the outer loop and oscillators the inner one: the oscillators' recurrences are
    independent, so the inner loop has no branch and compiles to SIMD instructions; the rare
    in-step peak candidates it flags are handled in a second loop. With ``free``, the largest
    |u| of the free vibration from the final state is added (:func:`_free_peak`).
    """
    n = p.shape[0]
    nper = c.shape[1]
    a11, a12, a21, a22, b10, b11, b20, b21 = c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]
    w, wd, cand = c[8], c[9], c[10]
    u = np.zeros(nper)
    v = np.zeros(nper)
    un = np.zeros(nper)
    vn = np.zeros(nper)
    umax = np.zeros(nper)
    flag = np.zeros(nper, dtype=np.int64)
    for k in range(n - 1):
        p0 = p[k]
        p1 = p[k + 1]
        nhit = 0
        for i in range(nper):
            ui = u[i]
            vi = v[i]
            u1 = a11[i] * ui + a12[i] * vi + b10[i] * p0 + b11[i] * p1
            v1 = a21[i] * ui + a22[i] * vi + b20[i] * p0 + b21[i] * p1
            un[i] = u1
            vn[i] = v1
            um = umax[i]
            au = abs(u1)
            umax[i] = au if au > um else um
            # a sign change of u̇ near the running maximum: a peak may lie inside the step
            f = int(vi * v1 < 0.0) & int(max(abs(ui), au) > cand[i] * um)
            flag[i] = f
            nhit += f
        if nhit > 0:
            for i in range(nper):
                if flag[i] != 0:
                    s, hp = _hermite_peak_nb(u[i], v[i], un[i], vn[i], h)
                    if abs(hp) > _REFINE * umax[i]:
                        pk = _exact_peak_nb(u[i], v[i], p0, p1, s, w[i], z, wd[i], h)
                        if pk > umax[i]:
                            umax[i] = pk
        u, un = un, u
        v, vn = vn, v
    if free:
        for i in range(nper):
            pk = _free_peak_nb(u[i], v[i], w[i], z, wd[i])
            if pk > umax[i]:
                umax[i] = pk
    out[:] = umax


def _kernel_numpy(
    p: np.ndarray, c: np.ndarray, z: float, h: float, free: bool, out: np.ndarray,
) -> None:
    """Pure-numpy twin of the kernel: the same recurrence and tests, vectorised over oscillators."""
    a11, a12, a21, a22, b10, b11, b20, b21, w, wd, cand = c
    u = np.zeros(w.size)
    v = np.zeros(w.size)
    umax = np.zeros(w.size)
    for k in range(p.size - 1):
        p0, p1 = p[k], p[k + 1]
        u1 = a11 * u + a12 * v + b10 * p0 + b11 * p1
        v1 = a21 * u + a22 * v + b20 * p0 + b21 * p1
        au = np.abs(u1)
        prev = umax
        umax = np.maximum(umax, au)
        hit = (v * v1 < 0.0) & (np.maximum(np.abs(u), au) > cand * prev)
        for i in np.flatnonzero(hit):
            s, hp = _hermite_peak(u[i], v[i], u1[i], v1[i], h)
            if abs(hp) > _REFINE * umax[i]:
                pk = _exact_peak(u[i], v[i], p0, p1, s, w[i], z, wd[i], h)
                umax[i] = max(umax[i], pk)
        u, v = u1, v1
    if free:
        for i in range(w.size):
            umax[i] = max(umax[i], _free_peak(u[i], v[i], w[i], z, wd[i]))
    out[:] = umax


if HAVE_NUMBA:
    _hermite_peak_nb = _numba.njit(cache=True)(_hermite_peak)
    _exact_peak_nb = _numba.njit(cache=True)(_exact_peak)
    _free_peak_nb = _numba.njit(cache=True)(_free_peak)
    _kernel_1 = _numba.njit(cache=True)(_kernel_py)

    @_numba.njit(cache=True, parallel=True)
    def _kernel_nb(p, c, z, h, free, out):  # noqa: ANN001, ANN202
        """_kernel_py on two halves of the oscillators, one per core (they are independent)."""
        n_osc = c.shape[1]
        if n_osc < 16:
            _kernel_1(p, c, z, h, free, out)
            return
        half = n_osc // 2
        for part in _numba.prange(2):
            a = 0 if part == 0 else half
            b = half if part == 0 else n_osc
            _kernel_1(p, np.ascontiguousarray(c[:, a:b]), z, h, free, out[a:b])
else:  # pragma: no cover
    _hermite_peak_nb = _hermite_peak
    _exact_peak_nb = _exact_peak
    _free_peak_nb = _free_peak
    _kernel_nb = None



def response_spectrum(
    accel: np.ndarray,
    dt: float,
    periods: np.ndarray,
    damping: float = 0.05,
    *,
    free_vibration: bool = True,
    points_per_period: int = 10,
    backend: str = "auto",
) -> Spectrum:
    """Elastic response spectrum of a ground-acceleration record.

    Args:
        accel: (n,) [m/s²] ground acceleration, uniformly sampled, linear between samples.
        dt: [s] time step.
        periods: (n_T,) [s] oscillator periods, ≥ 0 (T = 0 gives the peak ground acceleration).
        damping: viscous damping ratio ζ in [0, 1).
        free_vibration: include the free vibration after the end of the record (see the
            module docstring).
        points_per_period: minimum number of (sub-)steps per oscillator period.
        backend: ``"auto"``, ``"numba"`` or ``"numpy"``.

    Returns:
        :class:`Spectrum` with sd [m], psv [m/s], psa [m/s²], each (n_T,).
    """
    a = np.ascontiguousarray(accel, dtype=np.float64)
    if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
        raise InputError("accel", f"array of shape {a.shape}", "a finite 1-D array, >= 2 samples")
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a time step > 0 s")
    T = np.atleast_1d(np.asarray(periods, dtype=np.float64))
    if T.ndim != 1 or T.size == 0 or np.any(~np.isfinite(T)) or np.any(T < 0):
        raise InputError("periods", periods, "a non-empty list of finite periods >= 0 s")
    if not (isinstance(damping, int | float) and 0.0 <= damping < 1.0):
        raise InputError("damping", damping, "a damping ratio in [0, 1)")
    if not (isinstance(points_per_period, int) and points_per_period >= 4):
        raise InputError("points_per_period", points_per_period, "an integer >= 4")
    if backend == "auto":
        backend = "numba" if HAVE_NUMBA else "numpy"
    if backend not in ("numba", "numpy") or (backend == "numba" and not HAVE_NUMBA):
        raise InputError("backend", backend, "'auto', 'numpy'" + (", 'numba'" * HAVE_NUMBA))

    pos = T > 0
    Tp = T[pos]
    z = float(damping)
    plan = spectrum_plan(Tp, float(dt), z, points_per_period)
    sd_p = peak_displacements(-a, plan, free_vibration=free_vibration, backend=backend)
    w_all = 2.0 * np.pi / Tp
    sd = np.zeros(T.size)
    psv = np.zeros(T.size)
    psa = np.full(T.size, float(np.max(np.abs(a))))
    sd[pos] = sd_p
    psv[pos] = w_all * sd_p
    psa[pos] = w_all * w_all * sd_p
    return Spectrum(T.copy(), sd, psv, psa, z, bool(free_vibration))


@dataclass(frozen=True, eq=False)
class SpectrumPlan:
    """Everything in a response spectrum that depends on the periods only, not on the record.

    ``damping``: ζ; ``groups``: one ``(m, idx, h, c)`` per number m of sub-steps per record
    step: the indices ``idx`` of the periods so integrated, the sub-step h [s] and the packed
    kernel parameters ``c`` (11, idx.size) (see :func:`_kernel_py`). Built by
    :func:`spectrum_plan`; reused when many records are measured at the same periods (the
    accelerogram generator does so).
    """

    n_periods: int
    damping: float
    groups: tuple[tuple[int, np.ndarray, float, np.ndarray], ...]


def spectrum_plan(periods: np.ndarray, dt: float, damping: float,
                  points_per_period: int = 10) -> SpectrumPlan:
    """Plan for :func:`peak_displacements` at ``periods`` (n_T,) [s] > 0, unchecked."""
    Tp = np.asarray(periods, dtype=np.float64)
    m_all = np.maximum(1, np.ceil(points_per_period * dt / Tp - 1e-9)).astype(np.int64)
    order = np.lexsort((Tp, m_all))
    groups = []
    for mi in np.unique(m_all):
        idx = order[m_all[order] == mi]
        h = dt / mi
        w = 2.0 * np.pi / Tp[idx]
        wd = w * math.sqrt(1.0 - damping * damping)
        cand = 0.9 * np.cos(np.minimum(0.5 * wd * h, 0.5 * np.pi))
        c = np.ascontiguousarray(np.vstack([*step_coefficients(w, damping, h), w, wd, cand]))
        groups.append((int(mi), idx, h, c))
    return SpectrumPlan(Tp.size, float(damping), tuple(groups))


def peak_displacements(p: np.ndarray, plan: SpectrumPlan, *, free_vibration: bool = True,
                       backend: str = "numba") -> np.ndarray:
    """Peak relative displacements (n_T,) [m] under the load ``p = -a_g`` (n,) [m/s²], unchecked.

    The core of :func:`response_spectrum`, for callers that validated their input already.
    """
    kernel = _kernel_nb if backend == "numba" and HAVE_NUMBA else _kernel_numpy
    z = plan.damping
    sd = np.empty(plan.n_periods)
    for mi, idx, h, c in plan.groups:
        # sub-steps: linear interpolation of the input is exact for piecewise-linear input
        pm = p if mi == 1 else np.interp(np.arange((p.size - 1) * mi + 1) / mi,
                                         np.arange(p.size), p)
        # after the record: the input returns linearly to zero over one (sub-)step, then the
        # free vibration is taken in closed form
        pk = np.append(pm, 0.0) if free_vibration else pm
        out = np.empty(idx.size)
        kernel(pk, c, z, h, bool(free_vibration), out)
        sd[idx] = out
    return sd
