"""The scheme for sliders moving along one line (2D racks, :class:`~seisrack.dynamics.Sliders`):
the chunk loop around the exact and the Newmark kernels (``_kernel_exact.py``, ``_kernel.py``),
called by :func:`seisrack.dynamics.simulate` once the inputs are checked. Theory:
``docs/theory/stick_slip_engine.md``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from seisrack.dynamics._blas import one_blas_thread
from seisrack.dynamics._chunk import Chunk
from seisrack.dynamics._line_setup import (
    _check_friction_rate,
    _exact_unsupported,
    _load_patterns,
    _stiffness_proportional,
)
from seisrack.dynamics._store import Buffers as _Buffers
from seisrack.dynamics._store import Kept as _Kept
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.hinges import Hinges, energy_split
from seisrack.dynamics.kernels import get_kernel, writable
from seisrack.dynamics.results import TimeHistory, recorded_events, run_status
from seisrack.dynamics.sliders import Sliders
from seisrack.errors import InputError

_LOG = logging.getLogger(__name__)

#: cap on sub-steps (event splits) inside one time step; slip-onset chatter with mu_d = mu_s
#: can produce dozens of micro-events in one step on multi-pallet racks
_MAX_SUBSTEPS = 512

#: steps taken by Bathe's composite scheme after each event on the Newmark path (the rest of
#: the event's step and the next one; ``_kernel_stage.py``): L-stable, so the jump of the
#: contact forces leaves no period-2h residue in the directions too stiff for the step. 0
#: keeps the trapezoidal rule throughout (the scheme before; tests compare the two)
COMPOSITE_STEPS = 2

_STATUS = {
    0: "ok",
    1: "event buffer overflow (increase max_events)",
    2: "too many events inside one step (reduce dt)",
    3: "non-finite response (check the input)",
    4: "equilibrium iterations (hinges, velocity-dependent friction) did not converge "
       "(reduce dt)",
}


def run_line(M, C, K, sliders: Sliders, *, dt: float, n_steps: int, ag: np.ndarray,  # noqa: ANN001, N803
             r: np.ndarray, F: np.ndarray | None, av: np.ndarray | None,  # noqa: N803
             rv: np.ndarray | None, g: float, q_u0: np.ndarray, q_v0: np.ndarray,
             backend: str, track_energy: bool, max_events: int, throw: bool,
             progress: Callable[[int], None] | None, chunk: int, method: str,
             basis: Basis, save_every: int | None,
             on_chunk: Callable[[Chunk], None] | None, hinges: Hinges) -> TimeHistory:
    """Integrate the checked inputs of :func:`seisrack.dynamics.simulate` (see there)."""
    n_t = n_steps + 1
    m = sliders.count
    nonlinear = hinges.nonlinear or sliders.velocity_dependent
    bas = basis
    phi, w2 = bas.phi, bas.w2
    nb = w2.shape[0]

    cq = phi.T @ (C @ phi)
    off = cq - np.diag(np.diag(cq))
    diag = bool(np.max(np.abs(off)) <= 1e-10 * max(np.max(np.abs(np.diag(cq))), 1e-300))
    cd = np.diag(cq).copy() if diag else np.zeros(nb)
    Cq = np.zeros((1, 1)) if diag else np.ascontiguousarray(cq)
    # load split p(t) = series(t) @ pat in basis coordinates (few patterns when possible)
    pat, series = _load_patterns(phi, M, r, ag, F, av, rv)
    gz = g + (av if av is not None else np.zeros(n_t))
    on_structure = sliders.dof >= 0
    P = np.zeros((m, nb))  # maps basis coordinates to each slider's support (zero: on the ground)
    P[on_structure] = phi[sliders.dof[on_structure], :]
    q0 = phi.T @ (M @ q_u0)  # Φ is M-orthonormal: q = Φᵀ M u
    qd0 = phi.T @ (M @ q_v0)

    if sliders.velocity_dependent:
        _check_friction_rate(sliders, P, w2, cd, diag, float(dt), gz)
    why_not = _exact_unsupported(w2, cd, diag, sliders.dof) or (
        "nonlinear hinges or velocity-dependent friction need equilibrium iterations"
        if nonlinear else "")
    if method == "exact" and why_not:
        raise InputError("method", method, f'"newmark" or "auto" here: {why_not}')
    use_exact = method != "newmark" and not why_not
    kern = get_kernel(backend, "exact" if use_exact else "newmark")
    used = "numba" if kern.__name__.endswith("_numba") else "python"
    mass = writable(sliders.mass)
    mus = writable(sliders.mu_static)
    mud = writable(sliders.mu_dynamic)
    P = writable(P)
    w2c = writable(w2)
    ag = writable(ag)
    pat = writable(pat)

    nh = hinges.count if hinges.nonlinear else 0
    Q = hinges.operator(phi)[:nh]
    hst = hinges.initial_state()[:nh]
    # writable: a read-only array (a compiled model's) is another numba specialisation
    h_k, h_law, h_par, h_th0 = (writable(a[:nh]) for a in
                                (hinges.k, hinges.law, hinges.par, hinges.theta0))
    rate = np.where(sliders.mu_static > sliders.mu_dynamic, sliders.friction_rate, 0.0)
    buf = _Buffers(chunk + 1, nb, m, nh)
    keep = _Kept(n_steps, save_every, nb, m, track_energy, nh)
    ev_time = np.empty(max_events + 1)
    ev_slider = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    w_state = np.zeros(m)
    wd_state = np.zeros(m)
    stuck_state = np.ones(m, dtype=np.bool_)
    sig_state = np.ones(m)
    e_state = np.zeros(6)
    stats = np.zeros(4, dtype=np.int64)  # the Newmark kernel's work counters
    status, n_ev, n_sub, n_cfg = 0, 0, 0, 0
    if use_exact:
        a1 = _stiffness_proportional(w2, cd)
        cache_size = int(np.clip(2.0e8 / (8.0 * (2 * nb * nb + nb * pat.shape[0] + 6 * nb + m)),
                                 4, 64))
    qs, qds = q0, qd0
    start = 0
    chunk_seen = None  # the last Chunk handed to on_chunk
    with one_blas_thread():
        while start < n_steps:
            stop = min(start + chunk, n_steps)
            rows = slice(start, stop + 1)
            k = stop - start + 1
            ser = np.ascontiguousarray(series[rows])
            N = np.multiply.outer(gz[rows], mass)  # np.outer, clipped in place: one array
            np.clip(N, 0.0, None, out=N)
            ev = (ev_time[n_ev:], ev_slider[n_ev:], ev_kind[n_ev:])
            left = max(int(max_events) - n_ev, 0)
            outs = buf.views(k)
            if use_exact:
                st, ne, ns, nc = kern.run_kernel_exact(
                    w2c, cd, a1, not bool(np.any(on_structure)), P, mass, mus, mud, float(dt),
                    ag[rows], pat, ser, N, qs, qds,
                    start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                    start * float(dt), bool(track_energy), left, _MAX_SUBSTEPS, cache_size,
                    *outs[:8], *ev,
                )
                n_cfg += int(nc)
            else:
                st, ne, ns = kern.run_kernel(
                    w2c, cd, Cq, diag, P, mass, mus, mud, rate, Q, h_th0, h_k, h_law, h_par, hst,
                    float(dt), ag[rows], np.ascontiguousarray(ser @ pat), N, qs, qds,
                    start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                    start * float(dt), bool(track_energy), left, _MAX_SUBSTEPS,
                    COMPOSITE_STEPS, *outs, *ev, stats,
                )
            n_ev += int(ne)
            n_sub += int(ns)
            status = int(st)
            t_chunk = np.arange(start, stop + 1) * dt
            if on_chunk is not None:
                chunk_seen = Chunk(t_chunk, outs[0], outs[1], outs[2], outs[5], outs[6],
                                   hinge_moment=outs[8], slider_u=outs[3], slider_v=outs[4],
                                   P=P)
                on_chunk(chunk_seen)
            keep.take(start, stop, n_steps, save_every, outs, N)
            qs, qds = outs[0][k - 1].copy(), outs[1][k - 1].copy()
            if status != 0:
                break
            if progress is not None:
                progress(stop - start)
            start = stop

    status_text = run_status(status, _STATUS, "stick-slip integration", throw, _LOG)
    events = recorded_events(ev_time, ev_slider, ev_kind, min(int(n_ev), max_events))
    kq, kqd, kqdd, kw, kwd, klam, kst, ken, khm, kN, kidx = keep.result()
    if chunk_seen is not None and _same(kq, chunk_seen.q) and _same(kw, chunk_seen.slider_u):
        sliding = chunk_seen.sliding  # the one chunk kept whole: the same product, once
    else:
        sliding = kw - kq @ P.T
    energy = {}
    if track_energy:
        names = ("input", "kinetic", "strain", "damping", "friction")
        energy = {nm: ken[:, c].copy() for c, nm in enumerate(names)}
        if not use_exact:
            energy["algorithmic"] = ken[:, 5].copy()
        if nh:
            energy["strain"], energy["hysteresis"] = energy_split(
                energy["strain"], kq, w2, kq @ Q.T + h_th0, khm, h_k, h_th0,
                hinges.initial_moment()[:nh])
    return TimeHistory(
        t=kidx * dt,
        q=kq,
        qd=kqd,
        qdd=kqdd,
        phi=phi,
        slider_u=kw,
        slider_v=kwd,
        sliding=sliding,
        friction=klam,
        normal=kN,
        stuck=kst,
        slider_dof=sliders.dof.copy(),
        events=events,
        energy=energy,
        status=status_text,
        backend=used,
        n_substeps=int(n_sub),
        method="exact" if use_exact else "newmark",
        n_configurations=int(n_cfg),
        basis=bas.describe(),
        sample_index=kidx,
        hinge_moment=khm,
        hinge_operator=Q,
        hinge_rotation0=h_th0,
        work={} if use_exact else dict(zip(
            ("trials", "newton_iterations", "factorisations", "location_trials"),
            (int(x) for x in stats), strict=True)),
    )


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    """``a`` and ``b`` view the very same memory, element for element."""
    return (a.shape == b.shape and a.strides == b.strides and a.dtype == b.dtype
            and a.__array_interface__["data"][0] == b.__array_interface__["data"][0])
