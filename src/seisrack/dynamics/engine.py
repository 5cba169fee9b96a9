"""Entry point of the stick–slip engine: validate, choose a basis, integrate in chunks.

The structure is linear (M, C, K; dense or scipy sparse); the sliders are masses resting on
structural DOFs with Coulomb friction (paper §II–III; law as in issue #3). The structure is
written in a mass-orthonormal basis (every mode, or a reduced Ritz basis for large structures,
:mod:`seisrack.dynamics.basis`). Each contact phase is integrated either in closed form with the
modes of its contact configuration ("exact", when damping is classical in every configuration)
or by Newmark average acceleration, with exact event location inside the step, so a step never
"fails to converge". See ``docs/theory/stick_slip_engine.md``.
"""

from __future__ import annotations

import functools
import logging
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from threadpoolctl import ThreadpoolController

from seisrack.dynamics import _inputs as chk
from seisrack.dynamics._setup import (  # noqa: F401  (constants re-exported: the engine's API)
    AUTO_FULL_MAX_DOF,
    DEFAULT_MAX_MEMORY,
    HINGE_RITZ_BLOCKS,
    HINGE_RITZ_TOL,
    _check_friction_rate,
    _check_memory,
    _choose_basis,
    _exact_unsupported,
    _kept_samples,
    _load_patterns,
    _stiffness_proportional,
)
from seisrack.dynamics._store import Buffers as _Buffers
from seisrack.dynamics._store import Kept as _Kept
from seisrack.dynamics.basis import Basis, full_basis
from seisrack.dynamics.hinges import Hinges, energy_split, no_hinges
from seisrack.dynamics.kernels import get_kernel
from seisrack.dynamics.results import EVENT_KINDS, Event, TimeHistory
from seisrack.dynamics.sliders import Sliders
from seisrack.errors import InputError, SolverError

_LOG = logging.getLogger(__name__)

#: cap on sub-steps (event splits) inside one time step; slip-onset chatter with mu_d = mu_s
#: can produce dozens of micro-events in one step on multi-pallet racks
_MAX_SUBSTEPS = 512
#: steps integrated per kernel call (bounded working memory; the state carries over exactly)
DEFAULT_CHUNK = 20_000

_STATUS = {
    0: "ok",
    1: "event buffer overflow (increase max_events)",
    2: "too many events inside one step (reduce dt)",
    3: "non-finite response (check the input)",
    4: "equilibrium iterations (hinges, velocity-dependent friction) did not converge "
       "(reduce dt)",
}


class Chunk(NamedTuple):
    """Full-rate results of one chunk of steps, handed to ``on_chunk`` (views: copy to keep).

    t: (k,) [s]; q, qd, qdd: (k, r) basis coordinates; slider_u, slider_v, friction: (k, m);
    stuck: (k, m) bool; hinge_moment: (k, n_h) [N·m] (n_h = 0 without nonlinear hinges).
    Consecutive chunks share their boundary sample.
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    slider_u: np.ndarray
    slider_v: np.ndarray
    friction: np.ndarray
    stuck: np.ndarray
    hinge_moment: np.ndarray


def modal_basis(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """Mass-normalised eigenbasis: returns (omega², Φ) with Φᵀ M Φ = I, Φᵀ K Φ = diag(omega²)."""
    b = full_basis(M, K)
    return b.w2, b.phi


def simulate(
    M: np.ndarray,  # noqa: N803
    C: np.ndarray,  # noqa: N803
    K: np.ndarray,  # noqa: N803
    sliders: Sliders,
    *,
    dt: float,
    n_steps: int | None = None,
    ground_accel: np.ndarray | None = None,
    influence: np.ndarray | None = None,
    force: np.ndarray | None = None,
    vertical_accel: np.ndarray | None = None,
    vertical_influence: np.ndarray | None = None,
    g: float = 9.81,
    u0: np.ndarray | None = None,
    v0: np.ndarray | None = None,
    backend: str = "auto",
    track_energy: bool = True,
    max_events: int = 200_000,
    throw: bool = True,
    progress: Callable[[int], None] | None = None,
    chunk_steps: int | None = None,
    method: str = "auto",
    basis: str | Basis = "auto",
    save_every: int | None = 1,
    on_chunk: Callable[[Chunk], None] | None = None,
    max_memory: float | None = None,
    hinges: Hinges | None = None,
) -> TimeHistory:
    """Time history of a linear structure carrying masses that may stick or slide.

    Parameters
    ----------
    M, C, K : (n, n) structural mass [kg], damping [N·s/m], stiffness [N/m], dense arrays or
        scipy sparse matrices. ``M`` excludes the sliders' horizontal masses (they are the
        sliders).
    sliders : masses resting on DOFs with static / dynamic friction.
    dt : time step [s]; excitation arrays are sampled at ``t_k = k dt`` and interpolated linearly.
    n_steps : number of steps; inferred from the excitation when omitted.
    ground_accel : (n_steps+1,) [m/s²] horizontal ground acceleration (sliders feel it too).
    influence : (n,) influence vector of ``ground_accel`` (default: ones).
    force : (n_steps+1, n) [N] applied forces.
    vertical_accel : (n_steps+1,) [m/s²]; normal forces become ``m (g + a_v)`` (clipped at 0).
    vertical_influence : (n,) if given, the structure is also loaded by ``-M r_v a_v``.
    g : gravity [m/s²]. u0, v0 : (n,) initial structural state (sliders start stuck).
    backend : "auto" (numba if installed), "numba" or "python" (the pure-Python twin).
    throw : raise :class:`SolverError` on failure; otherwise return with ``status`` set.
    progress : called with the number of steps just completed, after each chunk of
        ``chunk_steps`` steps (default 2000 when ``progress`` is given, else 20000); chunking
        does not change the result, the contact state carries over exactly.
    method : "exact" propagates every contact configuration with its own closed-form modal
        solution (exact between events for loads linear inside a step; needs classical damping
        in every configuration: no damping, C ∝ K, or no slider on the structure), "newmark"
        uses average-acceleration Newmark, "auto" (default) takes "exact" when it applies.
    basis : "full" (every mode: no truncation), "reduced" (Ritz basis of
        :func:`~seisrack.dynamics.basis.reduced_basis` with its default cut-off), "auto"
        (full up to ``AUTO_FULL_MAX_DOF`` DOFs, reduced above), or a
        :class:`~seisrack.dynamics.basis.Basis`.
    save_every : keep every k-th sample of the histories (the last sample is always kept);
        ``None`` keeps only the first and last samples (peaks then come from ``on_chunk``).
    on_chunk : called with the full-rate :class:`Chunk` of each chunk of steps (for peaks or
        streaming without keeping the histories).
    max_memory : bytes the kept histories and buffers may use (default: half of the memory
        available now, at most 4 GiB); a larger run is refused before anything is allocated.
    hinges : rotational springs of K whose moment follows a hysteresis law
        (:class:`~seisrack.dynamics.hinges.Hinges`); with a nonlinear law, or sliders with
        velocity-dependent friction, the run takes the Newmark path with equilibrium
        iterations inside the step (``docs/theory/nonlinear_hinges.md``).
    """
    M = chk.square("M", M, None)
    n = M.shape[0]
    C = chk.square("C", C, n)
    K = chk.square("K", K, n)
    chk.check_symmetric("M", M)
    chk.check_symmetric("K", K)
    if not isinstance(sliders, Sliders):
        raise InputError("sliders", type(sliders).__name__, "a seisrack.dynamics.Sliders")
    if not (isinstance(dt, int | float) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    if not (np.isfinite(g) and g > 0):
        raise InputError("g", g, "a finite gravity > 0 m/s²")
    if np.any(sliders.dof < -1) or np.any(sliders.dof >= n):
        bad = sliders.dof[(sliders.dof < -1) | (sliders.dof >= n)]
        raise InputError(
            "sliders.dof", bad.tolist(), f"DOF indices in [0, {n - 1}], or -1 (rests on the ground)"
        )
    lengths = [
        np.shape(x)[0]
        for x in (ground_accel, force, vertical_accel)
        if x is not None and np.ndim(x) >= 1
    ]
    if n_steps is None:
        if not lengths:
            raise InputError("n_steps", None, "a number of steps when no excitation is given")
        n_steps = lengths[0] - 1
    if int(n_steps) != n_steps or n_steps < 1:
        raise InputError("n_steps", n_steps, "an integer >= 1")
    n_steps = int(n_steps)
    n_t = n_steps + 1
    ag = np.zeros(n_t) if ground_accel is None else chk.series("ground_accel", ground_accel, (n_t,))
    r = np.ones(n) if influence is None else chk.series("influence", influence, (n,))
    F = None if force is None else chk.series("force", force, (n_t, n))
    av = None if vertical_accel is None else chk.series("vertical_accel", vertical_accel, (n_t,))
    rv = None
    if av is not None and vertical_influence is not None:
        rv = chk.series("vertical_influence", vertical_influence, (n,))
    q_u0 = np.zeros(n) if u0 is None else chk.series("u0", u0, (n,))
    q_v0 = np.zeros(n) if v0 is None else chk.series("v0", v0, (n,))
    if chunk_steps is not None:
        chk.positive_int("chunk_steps", chunk_steps)
    if save_every is not None:
        save_every = chk.positive_int("save_every", save_every)
    if method not in ("auto", "exact", "newmark"):
        raise InputError("method", method, '"auto", "exact" or "newmark"')
    m = sliders.count
    if hinges is None:
        hinges = no_hinges()
    if not isinstance(hinges, Hinges):
        raise InputError("hinges", type(hinges).__name__, "a seisrack.dynamics.hinges.Hinges")
    hinges.check(n)
    nonlinear = hinges.nonlinear or sliders.velocity_dependent
    chunk = int(chunk_steps or (2000 if progress is not None else DEFAULT_CHUNK))
    chunk = min(chunk, n_steps)

    bas = _choose_basis(basis, M, K, sliders, r, rv, F, hinges)
    phi, w2 = bas.phi, bas.w2
    nb = w2.shape[0]
    n_keep = _kept_samples(n_steps, save_every)
    _check_memory(n_keep, chunk, nb, m + hinges.count, n_t, max_memory)

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
    mass = chk.writable(sliders.mass)
    mus = chk.writable(sliders.mu_static)
    mud = chk.writable(sliders.mu_dynamic)
    P = chk.writable(P)
    w2c = chk.writable(w2)
    ag = chk.writable(ag)
    pat = chk.writable(pat)

    nh = hinges.count if hinges.nonlinear else 0
    Q = hinges.operator(phi)[:nh]
    hst = hinges.initial_state()[:nh]
    # writable: a read-only array (a compiled model's) is another numba specialisation
    h_k, h_law, h_par, h_th0 = (chk.writable(a[:nh]) for a in
                                (hinges.k, hinges.law, hinges.par, hinges.theta0))
    rate = np.where(sliders.mu_static > sliders.mu_dynamic, sliders.friction_rate, 0.0)
    buf = _Buffers(chunk + 1, nb, m, nh)
    keep = _Kept(n_keep, nb, m, track_energy, nh)
    ev_time = np.empty(max_events + 1)
    ev_slider = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    w_state = np.zeros(m)
    wd_state = np.zeros(m)
    stuck_state = np.ones(m, dtype=np.bool_)
    sig_state = np.ones(m)
    e_state = np.zeros(4)
    status, n_ev, n_sub, n_cfg = 0, 0, 0, 0
    if use_exact:
        a1 = _stiffness_proportional(w2, cd)
        cache_size = int(np.clip(2.0e8 / (8.0 * (2 * nb * nb + nb * pat.shape[0] + 6 * nb + m)),
                                 4, 64))
    qs, qds = q0, qd0
    start = 0
    # The kernel's algebra is small (r x r): a threaded BLAS only adds spinning threads, which
    # made runs 5-10x slower on a loaded 2-core machine (measured on the warehouse rack).
    limiter = _blas_controller().limit(limits=1, user_api="blas")
    try:
        while start < n_steps:
            stop = min(start + chunk, n_steps)
            rows = slice(start, stop + 1)
            k = stop - start + 1
            ser = np.ascontiguousarray(series[rows])
            pext = np.ascontiguousarray(ser @ pat)
            N = np.ascontiguousarray(np.clip(np.outer(gz[rows], mass), 0.0, None))
            ev = (ev_time[n_ev:], ev_slider[n_ev:], ev_kind[n_ev:])
            left = max(int(max_events) - n_ev, 0)
            outs = buf.views(k)
            if use_exact:
                st, ne, ns, nc = kern.run_kernel_exact(
                    w2c, cd, a1, not bool(np.any(on_structure)), P, mass, mus, mud, float(dt),
                    ag[rows], pext, pat, ser, N, qs, qds,
                    start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                    start * float(dt), bool(track_energy), left, _MAX_SUBSTEPS, cache_size,
                    *outs[:8], *ev,
                )
                n_cfg += int(nc)
            else:
                st, ne, ns = kern.run_kernel(
                    w2c, cd, Cq, diag, P, mass, mus, mud, rate, Q, h_th0, h_k, h_law, h_par, hst,
                    float(dt), ag[rows], pext, N, qs, qds,
                    start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                    start * float(dt), bool(track_energy), left, _MAX_SUBSTEPS, *outs, *ev,
                )
            n_ev += int(ne)
            n_sub += int(ns)
            status = int(st)
            t_chunk = np.arange(start, stop + 1) * dt
            if on_chunk is not None:
                on_chunk(Chunk(t_chunk, *outs[:7], outs[8]))
            keep.take(start, stop, n_steps, save_every, outs, N)
            qs, qds = outs[0][k - 1].copy(), outs[1][k - 1].copy()
            if status != 0:
                break
            if progress is not None:
                progress(stop - start)
            start = stop
    finally:
        limiter.restore_original_limits()

    status_text = _STATUS.get(int(status), f"status {status}")
    if status != 0:
        msg = f"stick-slip integration stopped: {status_text}"
        if throw:
            raise SolverError(msg)
        _LOG.warning(msg)
    n_keep_ev = min(int(n_ev), max_events)
    events = [
        Event(float(ev_time[k]), int(ev_slider[k]), EVENT_KINDS[int(ev_kind[k])])
        for k in range(n_keep_ev)
    ]
    kq, kqd, kqdd, kw, kwd, klam, kst, ken, khm, kN, kidx = keep.result()
    energy = {}
    if track_energy:
        names = ("input", "kinetic", "strain", "damping", "friction")
        energy = {nm: ken[:, c].copy() for c, nm in enumerate(names)}
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
        sliding=kw - kq @ P.T,
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
    )


_CONTROLLER: list[ThreadpoolController] = []


def single_blas_thread(func: Callable) -> Callable:
    """Decorator: run ``func`` with one BLAS thread (the controller is inspected once per
    process). The rack's post-processing is small dense algebra too: with a second, spinning
    OpenBLAS thread the nonlinear paper rack's run took twice the CPU (56 ms against 28)."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        with _blas_controller().limit(limits=1, user_api="blas"):
            return func(*args, **kwargs)

    return wrapper


def _blas_controller() -> ThreadpoolController:
    """One inspection of the loaded BLAS libraries per process (it reads /proc/self/maps:
    about 1 ms, too much to repeat on every run of a study)."""
    if not _CONTROLLER:
        _CONTROLLER.append(ThreadpoolController())
    return _CONTROLLER[0]
