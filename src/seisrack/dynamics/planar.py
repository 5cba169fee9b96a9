"""Pallets sliding in the horizontal plane with isotropic Coulomb friction on a linear
structure: :class:`PlanarSliders` and :func:`simulate_planar` (theory:
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
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from seisrack.dynamics import _inputs as chk
from seisrack.dynamics._setup import _check_memory, _kept_samples, given_or_full_basis
from seisrack.dynamics.basis import Basis, reduced_basis
from seisrack.dynamics.engine import _blas_controller
from seisrack.dynamics.kernels import numba_available
from seisrack.dynamics.results import EVENT_KINDS, Event
from seisrack.errors import InputError, SolverError

_LOG = logging.getLogger(__name__)

_MAX_SUBSTEPS = 512
#: Ritz basis of a 3D rack: compression tolerance and size up to which Krylov blocks are added
#: (tests/test_rack3d_run.py: against the 2D rack on every mode; on the 5 x 10 warehouse rack
#: 0.1 keeps 86 vectors, peaks within 0.5 % of 3e-2 (144 vectors) and 3.4 times faster:
#: benchmarks/results/rack3d.md)
PLANAR_RITZ_TOL = 1e-1
PLANAR_RITZ_TARGET = 40
DEFAULT_CHUNK = 5000
_STATUS = {
    0: "ok",
    1: "event buffer overflow (increase max_events)",
    2: "too many events inside one step (reduce dt)",
    3: "non-finite response (check the input)",
    4: "the step matrix is not positive definite (check M, K, C)",
    5: "the sliding directions did not converge inside a step (reduce dt)",
}


@dataclass(frozen=True)
class PlanarSliders:
    """Pallets resting on structural nodes, free to slide in the horizontal plane.

    dof_x, dof_z: (m, k) int, the x (down-aisle) and z (cross-aisle) translation DOFs of the
        ``k`` points each pallet rests on (-1: the ground, a rigid support moving with it); the
        pallet's support motion is their mean and its friction force is shared equally.
    mass [kg], mu_static, mu_dynamic (0 <= mu_d <= mu_s): (m,) or scalars.
    """

    dof_x: np.ndarray
    dof_z: np.ndarray
    mass: np.ndarray
    mu_static: np.ndarray
    mu_dynamic: np.ndarray

    def __init__(self, dof_x, dof_z, mass, mu_static, mu_dynamic=None) -> None:  # noqa: ANN001
        dx = np.asarray(dof_x)
        dz = np.asarray(dof_z)
        if dx.ndim == 1:
            dx = dx[:, None]
        if dz.ndim == 1:
            dz = dz[:, None]
        if dx.ndim != 2 or dx.shape != dz.shape:
            raise InputError("sliders.dof_z", f"shape {dz.shape}",
                             f"the shape of dof_x {dx.shape}: (pallets, supports)")
        for name, a in (("dof_x", dx), ("dof_z", dz)):
            if a.size and not np.all(np.equal(np.mod(a, 1), 0)):
                raise InputError(f"sliders.{name}", a.tolist(), "integer DOF indices")
        m = dx.shape[0]

        def _arr(name: str, val) -> np.ndarray:  # noqa: ANN001
            a = np.asarray(val, dtype=float)
            if a.ndim == 0:
                a = np.full(m, float(a))
            if a.shape != (m,) or not np.all(np.isfinite(a)):
                raise InputError(f"sliders.{name}", val, f"a finite scalar or {m} values")
            return a

        mass_a = _arr("mass", mass)
        mus = _arr("mu_static", mu_static)
        mud = mus.copy() if mu_dynamic is None else _arr("mu_dynamic", mu_dynamic)
        if np.any(mass_a <= 0):
            raise InputError("sliders.mass", mass_a.tolist(), "masses > 0 kg")
        if np.any(mus < 0) or np.any(mud < 0):
            raise InputError("sliders.mu", [mus.tolist(), mud.tolist()],
                             "friction coefficients >= 0")
        if np.any(mud > mus):
            j = int(np.argmax(mud > mus))
            raise InputError(f"sliders.mu_dynamic[{j}]", float(mud[j]),
                             f"a value <= mu_static ({mus[j]:g})")
        object.__setattr__(self, "dof_x", dx.astype(np.int64))
        object.__setattr__(self, "dof_z", dz.astype(np.int64))
        object.__setattr__(self, "mass", mass_a)
        object.__setattr__(self, "mu_static", mus)
        object.__setattr__(self, "mu_dynamic", mud)

    @property
    def count(self) -> int:
        return int(self.mass.shape[0])

    def support_matrix(self, phi: np.ndarray) -> np.ndarray:
        """(2m, r): rows 2p (x) and 2p+1 (z) give pallet p's support motion from ``q``."""
        m, k = self.dof_x.shape
        P = np.zeros((2 * m, phi.shape[1]))
        for c, dofs in enumerate((self.dof_x, self.dof_z)):
            for s in range(k):
                on = dofs[:, s] >= 0
                P[2 * np.flatnonzero(on) + c] += phi[dofs[on, s], :] / k
        return P


class PlanarChunk(NamedTuple):
    """Full-rate results of a chunk of steps (views: copy to keep). t (k,); q, qd, qdd (k, r);
    sliding, velocity, friction (k, m, 2) [m, m/s, N] relative to the supports (x, z);
    stuck (k, m). Consecutive chunks share their boundary sample."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    sliding: np.ndarray
    velocity: np.ndarray
    friction: np.ndarray
    stuck: np.ndarray


@dataclass(frozen=True)
class PlanarHistory:
    """Result of :func:`simulate_planar` (kept samples ``sample_index``, times ``t``).

    q, qd, qdd: (n_t, r) basis coordinates (``u = q @ phi.T``); sliding, velocity, friction:
    (n_t, m, 2) pallet sliding displacement [m], velocity [m/s] relative to its supports and
    friction force on it [N], components (x, z); normal (n_t, m) [N]; stuck (n_t, m).
    ``work``: the solver's effort (trial steps, Newton iterations, Cholesky factorisations,
    trials spent locating events).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    phi: np.ndarray
    sliding: np.ndarray
    velocity: np.ndarray
    friction: np.ndarray
    normal: np.ndarray
    stuck: np.ndarray
    events: list[Event]
    sample_index: np.ndarray
    status: str = "ok"
    backend: str = "python"
    n_substeps: int = 0
    basis: dict = field(default_factory=dict)
    work: dict = field(default_factory=dict)

    def dof_response(self, dofs: np.ndarray, kind: str = "u") -> np.ndarray:
        """(n_t, len(dofs)) displacement ("u"), velocity ("v") or acceleration ("a")."""
        src = {"u": self.q, "v": self.qd, "a": self.qdd}[kind]
        return src @ self.phi[np.asarray(dofs), :].T


def _kernel(backend: str):  # noqa: ANN202
    if backend == "auto":
        backend = "numba" if numba_available() else "python"
    if backend == "numba":
        if not numba_available():
            raise InputError("backend", backend, '"python" (numba is not installed)')
        from seisrack.dynamics import _planar_numba as mod
    elif backend == "python":
        from seisrack.dynamics import _kernel_planar as mod
    else:
        raise InputError("backend", backend, '"auto", "numba" or "python"')
    return mod, backend


def planar_basis(M, K, sliders: PlanarSliders, loads: np.ndarray,  # noqa: ANN001, N803
                 basis: str | Basis = "auto", **ritz) -> Basis:
    """Every mode up to ``AUTO_FULL_MAX_DOF`` DOFs (or ``basis="full"``), else a
    load-dependent Ritz basis from the ground loads ``loads`` (n, k) and each pallet's friction
    force pattern in x and in z (shared by its supports), pallets rigidly attached. ``ritz``:
    options of :func:`~seisrack.dynamics.basis.reduced_basis` (defaults
    ``PLANAR_RITZ_TOL``, ``PLANAR_RITZ_TARGET``)."""
    n = M.shape[0]
    chosen = given_or_full_basis(basis, M, K)
    if chosen is not None:
        return chosen
    m, k = sliders.dof_x.shape
    pat = np.zeros((n, 2 * m))
    for c, dofs in enumerate((sliders.dof_x, sliders.dof_z)):
        for s in range(k):
            on = dofs[:, s] >= 0
            np.add.at(pat, (dofs[on, s], 2 * np.flatnonzero(on) + c), 1.0 / k)
    pat = pat[:, np.any(pat != 0.0, axis=0)]
    dofs = np.concatenate([sliders.dof_x.ravel(), sliders.dof_z.ravel()])
    mass = np.tile(np.repeat(sliders.mass / k, k), 2)
    opts = {"tol": PLANAR_RITZ_TOL, "target_size": PLANAR_RITZ_TARGET, **ritz}
    return reduced_basis(M, K, dofs, mass, np.column_stack([np.asarray(loads).reshape(n, -1),
                                                            pat]), unit_loads=False, **opts)


def simulate_planar(
    M, C, K, sliders: PlanarSliders, *,  # noqa: ANN001, N803
    dt: float,
    ground_x: np.ndarray | None = None,
    ground_z: np.ndarray | None = None,
    influence_x: np.ndarray | None = None,
    influence_z: np.ndarray | None = None,
    vertical_accel: np.ndarray | None = None,
    vertical_influence: np.ndarray | None = None,
    g: float = 9.81,
    n_steps: int | None = None,
    basis: str | Basis = "auto",
    backend: str = "auto",
    save_every: int | None = 1,
    chunk_steps: int | None = None,
    on_chunk: Callable[[PlanarChunk], None] | None = None,
    progress: Callable[[int], None] | None = None,
    max_events: int = 500_000,
    max_memory: float | None = None,
    throw: bool = True,
) -> PlanarHistory:
    """Time history of a linear structure (M, C, K: dense or sparse, the structure's own mass
    without the pallets' horizontal masses) carrying pallets that stick or slide in the plane.

    ground_x, ground_z: (n_steps+1,) [m/s²] ground accelerations along x and z (linear between
    samples), with influence vectors ``influence_x``, ``influence_z`` (required when the
    component is given); vertical_accel: normal forces m (g + a_v) (clipped at 0) and, with
    ``vertical_influence``, the load -M r_v a_v. Damping must be classical in the basis
    (Rayleigh or modal). The other arguments are those of :func:`seisrack.dynamics.simulate`.
    """
    M = chk.square("M", M, None)
    n = M.shape[0]
    C = chk.square("C", C, n)
    K = chk.square("K", K, n)
    if not isinstance(sliders, PlanarSliders):
        raise InputError("sliders", type(sliders).__name__, "a PlanarSliders")
    for name, d in (("dof_x", sliders.dof_x), ("dof_z", sliders.dof_z)):
        if np.any(d < -1) or np.any(d >= n):
            raise InputError(f"sliders.{name}", d[(d < -1) | (d >= n)].tolist(),
                             f"DOF indices in [0, {n - 1}] or -1 (the ground)")
    if not (isinstance(dt, int | float) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    if not (np.isfinite(g) and g > 0):
        raise InputError("g", g, "a finite gravity > 0 m/s²")
    given = [np.shape(x)[0] for x in (ground_x, ground_z, vertical_accel) if x is not None]
    if n_steps is None:
        if not given:
            raise InputError("n_steps", None, "a number of steps when no excitation is given")
        n_steps = given[0] - 1
    n_steps = chk.positive_int("n_steps", n_steps)
    n_t = n_steps + 1
    zero = np.zeros(n_t)
    agx = zero if ground_x is None else chk.series("ground_x", ground_x, (n_t,))
    agz = zero if ground_z is None else chk.series("ground_z", ground_z, (n_t,))
    av = None if vertical_accel is None else chk.series("vertical_accel", vertical_accel, (n_t,))
    loads, series = [], []
    for name, a, r in (("influence_x", ground_x, influence_x),
                       ("influence_z", ground_z, influence_z),
                       ("vertical_influence", vertical_accel, vertical_influence)):
        if a is None or (r is None and name == "vertical_influence"):
            continue
        if r is None:
            raise InputError(name, None, f"an (n,) influence vector for the given {name[10:]}"
                             " ground component")
        loads.append(M @ chk.series(name, r, (n,)))
        series.append(np.asarray(a, dtype=float))
    if save_every is not None:
        save_every = chk.positive_int("save_every", save_every)
    chunk = min(int(chunk_steps or (1000 if progress is not None else DEFAULT_CHUNK)), n_steps)
    m = sliders.count

    pat_phys = np.column_stack(loads) if loads else np.zeros((n, 0))
    bas = planar_basis(M, K, sliders, pat_phys if loads else np.ones((n, 1)), basis)
    phi, w2 = bas.phi, bas.w2
    nb = w2.shape[0]
    n_keep = _kept_samples(n_steps, save_every)
    _check_memory(n_keep, chunk, nb, 4 * m, n_t, max_memory)
    cq = phi.T @ (C @ phi)
    off = cq - np.diag(np.diag(cq))
    if np.max(np.abs(off), initial=0.0) > 1e-8 * max(np.max(np.abs(np.diag(cq))), 1e-300):
        raise InputError("C", "non-classical damping",
                         "damping that is diagonal in the modes (Rayleigh or modal) for the "
                         "planar engine")
    cd = np.ascontiguousarray(np.diag(cq))
    pat = -(phi.T @ pat_phys)  # (nb, k): modal load per unit of each series
    ser = np.column_stack(series) if series else np.zeros((n_t, 0))
    gz = g + (av if av is not None else zero)
    P = sliders.support_matrix(phi)
    mod, used = _kernel(backend)

    mass, mus, mud = (chk.writable(a) for a in (sliders.mass, sliders.mu_static,
                                                  sliders.mu_dynamic))
    kd = chk.writable(w2)
    T_state = np.zeros((3, nb))
    S_state = np.zeros((6, 2 * m))
    stuck = np.ones(m, dtype=np.bool_)
    dirn = np.zeros(2 * m)
    S = np.zeros((nb + 2, nb))  # the stuck pallets' mass and first moments (_s_update)
    A = np.zeros((nb, nb))  # the last factorised Newton matrix, kept across chunks
    fac = np.full(1, -1.0)  # its step length (-1: none)
    ev_time = np.empty(max_events + 1)
    ev_pallet = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    bufs = (np.empty((chunk + 1, nb)), np.empty((chunk + 1, nb)), np.empty((chunk + 1, nb)),
            np.empty((chunk + 1, 2 * m)), np.empty((chunk + 1, 2 * m)),
            np.empty((chunk + 1, 2 * m)), np.empty((chunk + 1, m), dtype=np.bool_))
    keep_idx = _keep_index(n_steps, save_every)
    kept = [np.empty((keep_idx.size,) + b.shape[1:], dtype=b.dtype) for b in bufs]
    kept_N = np.empty((keep_idx.size, m))
    status, n_ev, n_sub, start = 0, 0, 0, 0
    stats = np.zeros(4, dtype=np.int64)
    limiter = _blas_controller().limit(limits=1, user_api="blas")
    try:
        while start < n_steps:
            stop = min(start + chunk, n_steps)
            rows = slice(start, stop + 1)
            k = stop - start + 1
            pext = np.ascontiguousarray(ser[rows] @ pat.T)
            N = np.ascontiguousarray(np.clip(np.outer(gz[rows], mass), 0.0, None))
            outs = tuple(b[:k] for b in bufs)
            left = max(int(max_events) - n_ev, 0)
            st, ne, ns, kd_done = mod.run_planar(
                kd, cd, P, mass, mus, mud, float(dt), np.ascontiguousarray(agx[rows]),
                np.ascontiguousarray(agz[rows]), pext, N, start > 0, T_state, S_state,
                stuck, dirn, S, A, fac, start * float(dt), left, _MAX_SUBSTEPS, *outs,
                ev_time[n_ev:], ev_pallet[n_ev:], ev_kind[n_ev:], stats)
            n_ev += int(ne)
            n_sub += int(ns)
            status = int(st)
            t_chunk = np.arange(start, stop + 1) * dt
            if on_chunk is not None:
                on_chunk(PlanarChunk(t_chunk, outs[0], outs[1], outs[2],
                                     outs[3].reshape(k, m, 2), outs[4].reshape(k, m, 2),
                                     outs[5].reshape(k, m, 2), outs[6]))
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
    finally:
        limiter.restore_original_limits()
    status_text = _STATUS.get(status, f"status {status}")
    if status != 0:
        msg = f"planar stick–slip engine stopped: {status_text}"
        if throw:
            raise SolverError(msg)
        _LOG.warning(msg)
    n_rec = min(n_ev, max_events)
    events = [Event(float(ev_time[i]), int(ev_pallet[i]), EVENT_KINDS[int(ev_kind[i])])
              for i in range(n_rec)]
    kq, kqd, kqdd, ku, kv, kl, ks = kept
    return PlanarHistory(
        t=keep_idx * dt, q=kq, qd=kqd, qdd=kqdd, phi=phi, sliding=ku.reshape(-1, m, 2),
        velocity=kv.reshape(-1, m, 2), friction=kl.reshape(-1, m, 2), normal=kept_N,
        stuck=ks, events=events, sample_index=keep_idx, status=status_text, backend=used,
        n_substeps=n_sub, basis=bas.describe(),
        work=dict(zip(("trials", "newton_iterations", "factorisations", "location_trials"),
                      (int(x) for x in stats), strict=True)))


def _keep_index(n_steps: int, save_every: int | None) -> np.ndarray:
    if save_every is None:
        return np.array([0, n_steps])
    idx = np.arange(0, n_steps + 1, save_every)
    if idx[-1] != n_steps:
        idx = np.append(idx, n_steps)
    return idx
