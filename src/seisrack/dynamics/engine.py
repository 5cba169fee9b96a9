"""Entry point of the stick–slip engine: validate, transform to modal coordinates, integrate.

The structure is linear (M, C, K); the sliders are masses resting on structural DOFs with
Coulomb friction (paper §II–III; law as in issue #3). Each contact phase is integrated either in
closed form with the modes of its contact configuration ("exact", when damping is classical in
every configuration) or by Newmark average acceleration, with exact event location inside the
step, so a step never "fails to converge". See ``docs/theory/stick_slip_engine.md``.
"""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np
import scipy.linalg

from seisrack.dynamics.kernels import get_kernel
from seisrack.dynamics.results import EVENT_KINDS, Event, TimeHistory
from seisrack.dynamics.sliders import Sliders
from seisrack.errors import InputError, SolverError

_LOG = logging.getLogger(__name__)

#: cap on sub-steps (event splits) inside one time step; slip-onset chatter with mu_d = mu_s
#: can produce dozens of micro-events in one step on multi-pallet racks
_MAX_SUBSTEPS = 512

_STATUS = {
    0: "ok",
    1: "event buffer overflow (increase max_events)",
    2: "too many events inside one step (reduce dt)",
    3: "non-finite response (check the input)",
}


def _square(name: str, mat: object, n: int | None) -> np.ndarray:
    a = np.asarray(mat, dtype=float)
    if a.ndim == 0 and n == 1:
        a = a.reshape(1, 1)
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise InputError(name, f"array of shape {a.shape}", "a square matrix")
    if n is not None and a.shape[0] != n:
        raise InputError(name, f"shape {a.shape}", f"shape ({n}, {n}) like M")
    if not np.all(np.isfinite(a)):
        raise InputError(name, "non-finite entries", "finite numbers")
    return a


def _series(name: str, val: object, shape: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(val, dtype=float)
    if a.shape != shape:
        raise InputError(name, f"array of shape {a.shape}", f"shape {shape}")
    if not np.all(np.isfinite(a)):
        bad = int(np.argmax(~np.isfinite(a.ravel())))
        raise InputError(name, f"non-finite value at flat index {bad}", "finite numbers")
    return a


def modal_basis(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """Mass-normalised eigenbasis: returns (omega², Φ) with Φᵀ M Φ = I, Φᵀ K Φ = diag(omega²)."""
    try:
        w2, phi = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError as exc:
        raise InputError(
            "M", "not positive definite", "a symmetric positive-definite mass matrix",
            hint="Every DOF needs mass (use a consistent mass matrix for rotations)",
        ) from exc
    scale = max(float(np.max(np.abs(w2))), 1e-300)
    if np.min(w2) < -1e-9 * scale:
        raise InputError(
            "K", f"negative eigenvalue {np.min(w2):.3g}", "a positive semi-definite stiffness"
        )
    return np.clip(w2, 0.0, None), phi


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
) -> TimeHistory:
    """Time history of a linear structure carrying masses that may stick or slide.

    Parameters
    ----------
    M, C, K : (n, n) structural mass [kg], damping [N·s/m], stiffness [N/m]. ``M`` excludes the
        sliders' horizontal masses (they are the sliders).
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
        ``chunk_steps`` steps (default 2000 when ``progress`` is given); chunking does not change
        the result, the contact state carries over exactly.
    method : "exact" propagates every contact configuration with its own closed-form modal
        solution (exact between events for loads linear inside a step; needs classical damping
        in every configuration: no damping, C ∝ K, or no slider on the structure), "newmark"
        uses average-acceleration Newmark, "auto" (default) takes "exact" when it applies.
    """
    M = _square("M", M, None)
    n = M.shape[0]
    C = _square("C", C, n)
    K = _square("K", K, n)
    if not np.allclose(M, M.T, rtol=1e-10, atol=1e-12 * np.max(np.abs(M))):
        raise InputError("M", "non-symmetric matrix", "a symmetric matrix")
    if not np.allclose(K, K.T, rtol=1e-10, atol=1e-12 * max(np.max(np.abs(K)), 1e-300)):
        raise InputError("K", "non-symmetric matrix", "a symmetric matrix")
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
    ag = np.zeros(n_t) if ground_accel is None else _series("ground_accel", ground_accel, (n_t,))
    r = np.ones(n) if influence is None else _series("influence", influence, (n,))
    F = None if force is None else _series("force", force, (n_t, n))
    av = None if vertical_accel is None else _series("vertical_accel", vertical_accel, (n_t,))
    q_u0 = np.zeros(n) if u0 is None else _series("u0", u0, (n,))
    q_v0 = np.zeros(n) if v0 is None else _series("v0", v0, (n,))

    w2, phi = modal_basis(M, K)
    cq = phi.T @ C @ phi
    off = cq - np.diag(np.diag(cq))
    diag = bool(np.max(np.abs(off)) <= 1e-10 * max(np.max(np.abs(np.diag(cq))), 1e-300))
    cd = np.diag(cq).copy() if diag else np.zeros(n)  # writable: one numba specialisation
    Cq = np.zeros((1, 1)) if diag else np.ascontiguousarray(cq)
    gamma = phi.T @ (M @ r)
    pext = -np.outer(ag, gamma)
    if F is not None:
        pext += F @ phi
    if av is not None and vertical_influence is not None:
        rv = _series("vertical_influence", vertical_influence, (n,))
        pext -= np.outer(av, phi.T @ (M @ rv))
    m = sliders.count
    gz = g + (av if av is not None else np.zeros(n_t))
    N = np.clip(np.outer(gz, sliders.mass), 0.0, None)
    # P maps modal coordinates to each slider's support motion (a zero row: rests on the ground)
    on_structure = sliders.dof >= 0
    P = np.zeros((m, n))
    P[on_structure] = phi[sliders.dof[on_structure], :]
    # Φ is M-orthonormal: q = Φᵀ M u
    q0 = phi.T @ (M @ q_u0)
    qd0 = phi.T @ (M @ q_v0)

    if chunk_steps is not None and (int(chunk_steps) != chunk_steps or chunk_steps < 1):
        raise InputError("chunk_steps", chunk_steps, "an integer >= 1")
    if method not in ("auto", "exact", "newmark"):
        raise InputError("method", method, '"auto", "exact" or "newmark"')
    why_not = _exact_unsupported(w2, cd, diag, sliders.dof)
    if method == "exact" and why_not:
        raise InputError("method", method, f'"newmark" or "auto" here: {why_not}')
    use_exact = method != "newmark" and not why_not
    kern = get_kernel(backend, "exact" if use_exact else "newmark")
    used = "numba" if kern.__name__.endswith("_numba") else "python"
    out_q = np.empty((n_t, n))
    out_qd = np.empty((n_t, n))
    out_qdd = np.empty((n_t, n))
    out_w = np.empty((n_t, m))
    out_wd = np.empty((n_t, m))
    out_lam = np.empty((n_t, m))
    out_stuck = np.empty((n_t, m), dtype=np.bool_)
    out_energy = np.zeros((n_t, 5))
    ev_time = np.empty(max_events + 1)
    ev_slider = np.empty(max_events + 1, dtype=np.int64)
    ev_kind = np.empty(max_events + 1, dtype=np.int64)
    w2c = np.ascontiguousarray(w2)
    ag = np.ascontiguousarray(ag)
    pext = np.ascontiguousarray(pext)
    N = np.ascontiguousarray(N)
    w_state = np.zeros(m)
    wd_state = np.zeros(m)
    stuck_state = np.ones(m, dtype=np.bool_)
    sig_state = np.ones(m)
    e_state = np.zeros(3)
    chunk = n_steps if chunk_steps is None and progress is None else int(chunk_steps or 2000)
    status, n_ev, n_sub, n_cfg = 0, 0, 0, 0
    if use_exact:
        a1 = _stiffness_proportional(w2, cd)
        rv_in = None if vertical_influence is None else np.asarray(vertical_influence, float)
        pat, series = _load_patterns(n, ag, gamma, F, phi, av, rv_in, M, pext)
        cache_size = int(np.clip(2.0e8 / (8.0 * (3 * n * n + n * m + 16 * n + 1)), 4, 64))
    start = 0
    while start < n_steps:
        stop = min(start + chunk, n_steps)
        rows = slice(start, stop + 1)
        qs = q0 if start == 0 else out_q[start].copy()
        qds = qd0 if start == 0 else out_qd[start].copy()
        if use_exact:
            st, ne, ns, nc = kern.run_kernel_exact(
                w2c, cd, a1, not bool(np.any(sliders.dof >= 0)), P, sliders.mass,
                sliders.mu_static, sliders.mu_dynamic, float(dt), ag[rows], pext[rows], pat,
                series[rows], N[rows], qs, qds,
                start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                start * float(dt), bool(track_energy), max(int(max_events) - n_ev, 0),
                _MAX_SUBSTEPS, cache_size,
                out_q[rows], out_qd[rows], out_qdd[rows], out_w[rows], out_wd[rows],
                out_lam[rows], out_stuck[rows], out_energy[rows],
                ev_time[n_ev:], ev_slider[n_ev:], ev_kind[n_ev:],
            )
            n_cfg += int(nc)
        else:
            st, ne, ns = kern.run_kernel(
                w2c, cd, Cq, diag, P, sliders.mass, sliders.mu_static, sliders.mu_dynamic,
                float(dt), ag[rows], pext[rows], N[rows], qs, qds,
                start > 0, w_state, wd_state, stuck_state, sig_state, e_state,
                start * float(dt), bool(track_energy), max(int(max_events) - n_ev, 0),
                _MAX_SUBSTEPS, out_q[rows], out_qd[rows], out_qdd[rows], out_w[rows],
                out_wd[rows], out_lam[rows], out_stuck[rows], out_energy[rows],
                ev_time[n_ev:], ev_slider[n_ev:], ev_kind[n_ev:],
            )
        n_ev += int(ne)
        n_sub += int(ns)
        status = int(st)
        if status != 0:
            break
        if progress is not None:
            progress(stop - start)
        start = stop
    status_text = _STATUS.get(int(status), f"status {status}")
    if status != 0:
        msg = f"stick-slip integration stopped: {status_text}"
        if throw:
            raise SolverError(msg)
        _LOG.warning(msg)
    n_keep = min(int(n_ev), max_events)
    events = [
        Event(float(ev_time[k]), int(ev_slider[k]), EVENT_KINDS[int(ev_kind[k])])
        for k in range(n_keep)
    ]
    energy = {}
    if track_energy:
        energy = {
            "input": out_energy[:, 0].copy(),
            "kinetic": out_energy[:, 1].copy(),
            "strain": out_energy[:, 2].copy(),
            "damping": out_energy[:, 3].copy(),
            "friction": out_energy[:, 4].copy(),
        }
    return TimeHistory(
        t=np.arange(n_t) * dt,
        q=out_q,
        qd=out_qd,
        qdd=out_qdd,
        phi=phi,
        slider_u=out_w,
        slider_v=out_wd,
        sliding=out_w - out_q @ P.T,
        friction=out_lam,
        normal=N,
        stuck=out_stuck,
        slider_dof=sliders.dof.copy(),
        events=events,
        energy=energy,
        status=status_text,
        backend=used,
        n_substeps=int(n_sub),
        method="exact" if use_exact else "newmark",
        n_configurations=int(n_cfg),
    )


def _stiffness_proportional(w2: np.ndarray, cd: np.ndarray) -> float:
    """a1 with cd = a1 w2 (least squares over the modes)."""
    den = float(np.dot(w2, w2))
    return float(np.dot(cd, w2) / den) if den > 0.0 else 0.0


def _exact_unsupported(w2: np.ndarray, cd: np.ndarray, diag: bool, dof: np.ndarray) -> str:
    """Why the exact propagator does not apply here ('' when it does)."""
    if not diag:
        return "the damping is not classical (Φᵀ C Φ is not diagonal)"
    if w2.size and float(np.min(w2)) <= 1e-12 * float(np.max(w2)):
        return "the structure has a zero-frequency (rigid-body) mode"
    if np.any(dof >= 0):
        a1 = _stiffness_proportional(w2, cd)
        scale = max(float(np.max(np.abs(cd))), 1e-300)
        if float(np.max(np.abs(cd - a1 * w2))) > 1e-8 * scale:
            return (
                "damping with a mass-proportional or modal part is not classical once sliders "
                "stick to the structure (exact needs C = 0 or C ∝ K)"
            )
    return ""


def _load_patterns(n, ag, gamma, F, phi, av, rv, M, pext):  # noqa: ANN001, ANN202, N803
    """Split the modal load as ``pext = series @ pat`` with few patterns when possible."""
    pats = [-gamma]
    cols = [ag]
    if F is not None:
        loaded = np.flatnonzero(np.any(F != 0.0, axis=0))
        if loaded.size > max(n // 2, 1):
            return np.eye(n), np.ascontiguousarray(pext)
        for d in loaded:
            pats.append(phi[d, :])
            cols.append(F[:, d])
    if av is not None and rv is not None:
        pats.append(-(phi.T @ (M @ rv)))
        cols.append(av)
    return np.ascontiguousarray(np.array(pats)), np.ascontiguousarray(np.column_stack(cols))
