"""The scheme for pallets sliding in the horizontal plane with isotropic Coulomb friction on a
linear structure (3D racks): :class:`PlanarSliders`, their Ritz basis, and the chunk loop
around the planar kernel, called by :func:`seisrack.dynamics.simulate` (theory:
``docs/theory/planar_friction.md``; kernel: ``_kernel_planar.py``).

The friction force opposes the relative sliding velocity *vector* (magnitude mu_d N while
sliding) and a stuck pallet holds while the horizontal force that keeps it stuck has a
magnitude ≤ mu_s N, so sliding in one direction leaves less resistance in the other. With
motion along one axis only, the results are those of the 1D engine
(:func:`seisrack.dynamics.simulate`, Newmark path).
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from seisrack.dynamics._blas import one_blas_thread
from seisrack.dynamics._chunk import Chunk
from seisrack.dynamics._quasi_static import QuasiStatic, rides_stiff, stiff_directions
from seisrack.dynamics._store import keep_index
from seisrack.dynamics.axial import no_axial
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.hinges import Hinges, energy_split, no_hinges
from seisrack.dynamics.kernels import scheme_kernel, writable_all
from seisrack.dynamics.results import STEP_STATUS, TimeHistory, recorded_events, run_status
from seisrack.dynamics.sliders import PlanarSliders
from seisrack.errors import InputError

_LOG = logging.getLogger(__name__)

_MAX_SUBSTEPS = 512
_STATUS = {
    **STEP_STATUS,
    2: "too many events inside one step (reduce dt)",
    5: "the sliding directions did not converge inside a step (reduce dt)",
    6: "the P-Δ of the current axial forces did not settle inside a step (reduce dt)",
}


def _kernel(backend: str):  # noqa: ANN202
    return scheme_kernel(backend, "seisrack.dynamics._planar_numba",
                         "seisrack.dynamics._kernel_planar")


def run_planar_scheme(
    M, C, K, sliders: PlanarSliders, *,  # noqa: ANN001, N803
    dt: float,
    n_steps: int,
    ag: np.ndarray,
    influence: np.ndarray,
    av: np.ndarray | None,
    rv: np.ndarray | None,
    g: float,
    basis: Basis,
    backend: str,
    save_every: int | None,
    chunk: int,
    on_chunk: Callable[[Chunk], None] | None,
    progress: Callable[[int], None] | None,
    max_events: int,
    throw: bool,
    hinges: Hinges | None = None,
    track_energy: bool = True,
) -> TimeHistory:
    """Integrate the checked inputs of :func:`seisrack.dynamics.simulate` for sliders in the
    plane: ``ag`` (n_t, 2) ground accelerations along x and z with their influence vectors
    ``influence`` (n, 2) (a zero column: no load in that direction), ``av``/``rv`` the
    vertical motion. Damping: any symmetric C, taken as Φᵀ C Φ in the basis (its off-diagonal
    part costs an (r, r) product per Newton iteration; none when it is diagonal). ``hinges``:
    rotational springs of K whose moment follows a hysteresis law (§7 of the theory page).
    ``track_energy=False``: no energy terms (``energy`` empty), a little faster."""
    if hinges is None:
        hinges = no_hinges()
    n = M.shape[0]
    n_t = n_steps + 1
    loads, series = [], []
    for c in range(2):
        if np.any(influence[:, c] != 0.0):
            loads.append(M @ influence[:, c])
            series.append(ag[:, c])
    if av is not None and rv is not None:
        loads.append(M @ rv)
        series.append(av)
    m = sliders.count

    pat_phys = np.column_stack(loads) if loads else np.zeros((n, 0))
    bas = basis
    phi, w2 = bas.phi, bas.w2
    nb = w2.shape[0]
    nh = hinges.count if hinges.nonlinear else 0
    cd, Co = _reduced_damping(phi, C)
    pat = -(phi.T @ pat_phys)  # (nb, k): modal load per unit of each series
    ser = np.column_stack(series) if series else np.zeros((n_t, 0))
    gz = g + (av if av is not None else np.zeros(n_t))
    P = sliders.support_matrix(phi)
    Q = hinges.operator(phi)[:nh]
    hst = hinges.initial_state()[:nh]
    mod, used = _kernel(backend)
    # the directions too stiff for the step are held quasi-statically (_quasi_static.py): the
    # kernel integrates the others
    integrated = bool(nh) or Co.size > 0 or hinges.axial is not None
    qs = QuasiStatic(stiff_directions(w2, P, sliders.mass, dt, integrated), pat, P, w2, dt)
    # where every direction is integrated and the rack is too stiff for the step, every step
    # is composite (_planar_stage.py): L-stable, so the stiff directions carry no period-2h
    # residue into the stuck pallets' forces
    comp_steps = n_steps + 1 if integrated and rides_stiff(w2, P, sliders.mass, dt) else 0
    dyn = qs.dyn
    nk = nb - qs.count
    # writable: a read-only array (a compiled model's) is another numba specialisation
    mass, mus, mud, kd, cdk, Pk, h_k, h_law, h_par, h_th0 = writable_all(
        sliders.mass, sliders.mu_static, sliders.mu_dynamic, w2[dyn], cd[dyn],
        np.ascontiguousarray(P[:, dyn]),  # a column mask gives Fortran order
        *(a[:nh] for a in (hinges.k, hinges.law, hinges.par, hinges.theta0)))
    patk = pat[dyn]
    agx, agz = np.ascontiguousarray(ag[:, 0]), np.ascontiguousarray(ag[:, 1])

    T_state = np.zeros((3, nk))
    S_state = np.zeros((6, 2 * m))
    stuck = np.ones(m, dtype=np.bool_)
    dirn = np.zeros(2 * m)
    S = np.zeros((nk + 2, nk))  # the stuck pallets' mass and first moments (_s_update)
    A = np.zeros((nk, nk))  # the last factorised Newton matrix, kept across chunks
    fac = np.full(1, -1.0)  # its step length (-1: none)
    HW = np.zeros((4, nh))
    ax = no_axial(nk) if hinges.axial is None else hinges.axial.reduced(phi)
    e_state = np.zeros(7)
    ev_time = np.empty(max_events + 1)
    ev_pallet = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    bufs = (np.empty((chunk + 1, nk)), np.empty((chunk + 1, nk)), np.empty((chunk + 1, nk)),
            np.empty((chunk + 1, 2 * m)), np.empty((chunk + 1, 2 * m)),
            np.empty((chunk + 1, 2 * m)), np.empty((chunk + 1, m), dtype=np.bool_),
            np.empty((chunk + 1, nh)), np.empty((chunk + 1, 7 if track_energy else 0)))
    full = tuple(np.empty((chunk + 1, nb)) for _ in range(3)) if qs.count else ()
    keep_idx = keep_index(n_steps, save_every)
    kept = [np.empty((keep_idx.size,) + b.shape[1:], dtype=b.dtype)
            for b in (*full, *bufs[len(full):])]
    kept_N = np.empty((keep_idx.size, m))
    status, n_ev, n_sub, start = 0, 0, 0, 0
    stats = np.zeros(4, dtype=np.int64)
    with one_blas_thread():
        while start < n_steps:
            stop = min(start + chunk, n_steps)
            rows = slice(start, stop + 1)
            k = stop - start + 1
            pext = np.ascontiguousarray(ser[rows] @ patk.T)
            N = np.ascontiguousarray(np.clip(np.outer(gz[rows], mass), 0.0, None))
            outs = tuple(b[:k] for b in bufs)
            left = max(int(max_events) - n_ev, 0)
            st, ne, ns, kd_done = mod.run_planar(
                kd, cdk, Co, Pk, mass, mus, mud, float(dt), agx[rows], agz[rows], pext, N,
                start > 0, T_state, S_state, stuck, dirn, S, A, fac, start * float(dt), left,
                _MAX_SUBSTEPS, *outs[:7], ev_time[n_ev:], ev_pallet[n_ev:], ev_kind[n_ev:],
                stats, Q, h_th0, h_k, h_law, h_par, hst, HW, e_state, outs[7], outs[8], *ax,
                comp_steps)
            n_ev += int(ne)
            n_sub += int(ns)
            status = int(st)
            if status != 0:  # only the rows up to the last completed step hold a state
                k = min(k, int(kd_done) + 1)
                stop = start + k - 1
                rows = slice(start, stop + 1)
                outs = tuple(o[:k] for o in outs)
                N = N[:k]
            if qs.count:
                fk = tuple(f[:k] for f in full)
                qs.fill(ser[rows], outs[5], outs[:3], fk,
                        outs[8] if track_energy else None)
                outs = (*fk, *outs[3:])
            t_chunk = np.arange(start, stop + 1) * dt
            if on_chunk is not None:
                on_chunk(Chunk(t_chunk, outs[0], outs[1], outs[2], outs[5].reshape(k, m, 2),
                               outs[6], hinge_moment=outs[7], sliding=outs[3].reshape(k, m, 2),
                               sliding_v=outs[4].reshape(k, m, 2)))
            sel = (keep_idx >= start) & (keep_idx <= stop)
            for dst, src in zip(kept, outs, strict=True):
                dst[sel] = src[keep_idx[sel] - start]
            kept_N[sel] = N[keep_idx[sel] - start]
            if status != 0:
                # keep what was computed: the samples up to the last completed step
                last = start + int(kd_done)
                keep_n = int(np.searchsorted(keep_idx, last, side="right"))
                keep_idx = keep_idx[:keep_n]
                kept = [a[:keep_n] for a in kept]
                kept_N = kept_N[:keep_n]
                break
            if progress is not None:
                progress(stop - start)
            start = stop
    status_text = run_status(status, _STATUS, "planar stick–slip engine", throw, _LOG)
    events = recorded_events(ev_time, ev_pallet, ev_kind, min(n_ev, max_events))
    kq, kqd, kqdd, ku, kv, kl, ks, khm, ken = kept
    energy = {nm: ken[:, c].copy() for c, nm in
              enumerate(("input", "kinetic", "strain", "damping", "friction"))
              } if track_energy else {}
    if track_energy and comp_steps:
        energy["algorithmic"] = ken[:, 6].copy()
    if track_energy and hinges.axial is not None:  # its work apart: not a strain energy
        energy["p_delta"] = ken[:, 5].copy()
        energy["strain"] -= energy["p_delta"]
    if nh and track_energy:
        energy["strain"], energy["hysteresis"] = energy_split(
            energy["strain"], kq, w2, kq @ Q.T + h_th0, khm, h_k, h_th0,
            hinges.initial_moment()[:nh])
    return TimeHistory(
        t=keep_idx * dt, q=kq, qd=kqd, qdd=kqdd, phi=phi, slider_u=None, slider_v=None,
        sliding=ku.reshape(len(ku), m, 2), sliding_v=kv.reshape(len(kv), m, 2),
        friction=kl.reshape(len(kl), m, 2), normal=kept_N, stuck=ks, energy=energy,
        slider_dof=sliders.dof_x.copy(), events=events, status=status_text, backend=used,
        n_substeps=n_sub, method="newmark",
        basis={**bas.describe(), "quasi_static": qs.count}, sample_index=keep_idx,
        work=dict(zip(("trials", "newton_iterations", "factorisations", "location_trials"),
                      (int(x) for x in stats), strict=True)),
        hinge_moment=khm, hinge_operator=Q, hinge_rotation0=h_th0)


def _reduced_damping(phi: np.ndarray, C) -> tuple[np.ndarray, np.ndarray]:  # noqa: ANN001, N803
    """(cd, Co): the diagonal of Φᵀ C Φ and its off-diagonal part, or an empty (0, 0) ``Co``
    when that part is round-off (classical damping: Rayleigh in the modes of K). InputError
    for a C that is not symmetric (the step's Newton matrix must be)."""
    cq = phi.T @ (C @ phi)
    scale = max(np.max(np.abs(cq), initial=0.0), 1e-300)
    if np.max(np.abs(cq - cq.T), initial=0.0) > 1e-8 * scale:
        raise InputError("C", "a damping matrix that is not symmetric",
                         "a symmetric damping matrix C for the planar engine")
    cq = 0.5 * (cq + cq.T)
    cd = np.ascontiguousarray(np.diag(cq))
    off = cq - np.diag(cd)
    if np.max(np.abs(off), initial=0.0) <= 1e-8 * max(np.max(np.abs(cd), initial=0.0), 1e-300):
        return cd, np.zeros((0, 0))
    return cd, np.ascontiguousarray(off)
