"""Semi-analytical, event-driven reference solver for a linear structure carrying sliding masses.

Independent of the production time stepper (shares no code with it). Between contact
transitions the system is linear with a fixed contact state (the paper's §III.A, phases 1 and 2):

- a **stuck** slider moves with its node, so its mass is condensed onto that node's diagonal and
  the friction it needs is ``F = m (a_node + a_g)``;
- a **sliding** slider receives the constant force ``F = -d mu_d N`` (``d`` the sign of its
  velocity relative to the node, ``N = m (g + a_v(t))``) and the structure receives ``-F``.

Each phase is integrated by DOP853 with tight tolerances and dense output. Event functions stop
a phase when a stuck slider's required friction reaches ``mu_s N`` (stick -> slip), or when a
sliding slider's relative velocity returns to zero. At every transition the new contact state is
decided at the acceleration level: all sliders at zero relative velocity are tried stuck, and
the one whose required force exceeds ``mu_s N`` the most is released (in the direction opposite
to its required force) until every stuck slider satisfies ``|F| <= mu_s N``.

Equations of motion (relative to the ground, ``r`` the influence vector, ``e_j`` unit vectors)::

    M u'' + C u' + K u = P(t) - M r a_g(t) - sum_k F_k e_j(k)
    m_k (w_k'' + a_g(t)) = F_k

A slider with ``dof = -1`` rests directly on the ground (prescribed-support mode, the §II SDOF).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from seisrack.dynamics.reference_result import ReferenceEvent, ReferencePhase, ReferenceResult
from seisrack.errors import InputError, SolverError

__all__ = ["simulate_reference"]

log = logging.getLogger(__name__)

ScalarFn = Callable[[float], float]
VectorFn = Callable[[float], np.ndarray]

_TINY_PHASE = 1e-12  # [s] phases shorter than this count towards the chattering guard


def _as_square(name: str, A: np.ndarray, n: int) -> np.ndarray:
    A = np.asarray(A, dtype=float)
    if A.shape != (n, n):
        raise InputError(name, A.shape, f"shape ({n}, {n})")
    if not np.all(np.isfinite(A)):
        raise InputError(name, "non-finite entries", "finite values")
    return A


def _as_vec(name: str, x: Sequence[float] | np.ndarray | float, m: int) -> np.ndarray:
    arr = np.broadcast_to(np.asarray(x, dtype=float), (m,)).copy()
    if not np.all(np.isfinite(arr)):
        raise InputError(name, arr.tolist(), "finite values")
    return arr


class _Problem:
    """Validated data and the phase right-hand side (arrays only, no workflow)."""

    def __init__(
        self,
        M: np.ndarray,
        C: np.ndarray,
        K: np.ndarray,
        dof: np.ndarray,
        mass: np.ndarray,
        mu_s: np.ndarray,
        mu_d: np.ndarray,
        ground_accel: ScalarFn | None,
        influence: np.ndarray,
        force: VectorFn | None,
        vertical_accel: ScalarFn | None,
        g: float,
    ) -> None:
        self.M, self.C, self.K = M, C, K
        self.n, self.m = M.shape[0], dof.size
        self.dof, self.mass, self.mu_s, self.mu_d = dof, mass, mu_s, mu_d
        self.ag = ground_accel
        self.r = influence
        self.force = force
        self.av = vertical_accel
        self.g = g
        self.on_ground = dof < 0
        self.node = np.where(self.on_ground, 0, dof)  # safe index; masked where on the ground
        self.Mr = M @ influence

    # excitation -------------------------------------------------------------------------
    def a_g(self, t: float) -> float:
        return 0.0 if self.ag is None else float(self.ag(t))

    def normal(self, t: float) -> np.ndarray:
        av = 0.0 if self.av is None else float(self.av(t))
        return self.mass * (self.g + av)

    def load(self, t: float) -> np.ndarray:
        p = -self.Mr * self.a_g(t)
        if self.force is not None:
            p = p + np.asarray(self.force(t), dtype=float)
        return p

    # phase operators ------------------------------------------------------------------------
    def factor(self, direction: np.ndarray) -> _PhaseOps:
        """Affine operators of one contact state (the structure is linear within a phase)."""
        n, m = self.n, self.m
        stuck = direction == 0
        Meff = self.M.copy()
        for k in np.flatnonzero(stuck & ~self.on_ground):
            Meff[self.dof[k], self.dof[k]] += self.mass[k]
        Minv = np.linalg.inv(Meff) if n else np.zeros((0, 0))
        # a = Au u + Av v + ea a_g + Bp P + en (g + a_v)
        Au, Av, Bp = -Minv @ self.K, -Minv @ self.C, Minv
        load_ag = -self.Mr.copy()
        load_n = np.zeros(n)
        for k in range(m):
            if self.on_ground[k]:
                continue
            j = self.dof[k]
            if stuck[k]:
                load_ag[j] -= self.mass[k]
            else:  # the structure receives -F = +d mu_d m (g + a_v)  (Eq. 3)
                load_n[j] += direction[k] * self.mu_d[k] * self.mass[k]
        ea, en = Minv @ load_ag, Minv @ load_n
        # F = Fu u + Fv v + fa a_g + Fp P + fn (g + a_v)
        Fu, Fv, Fp = np.zeros((m, n)), np.zeros((m, n)), np.zeros((m, n))
        fa, fn = np.zeros(m), np.zeros(m)
        for k in range(m):
            if stuck[k]:
                fa[k] = self.mass[k]
                if not self.on_ground[k]:
                    j = self.dof[k]
                    mk = self.mass[k]
                    Fu[k], Fv[k], Fp[k] = mk * Au[j], mk * Av[j], mk * Minv[j]
                    fa[k] += self.mass[k] * ea[j]
                    fn[k] = self.mass[k] * en[j]
            else:
                fn[k] = -direction[k] * self.mu_d[k] * self.mass[k]
        return _PhaseOps(Au, Av, Bp, ea, en, Fu, Fv, Fp, fa, fn, stuck)

    def accelerations(
        self, t: float, u: np.ndarray, v: np.ndarray, direction: np.ndarray, ops: _PhaseOps
    ) -> tuple[np.ndarray, np.ndarray]:
        """Structural acceleration (n,) and slider friction (m,) in a given contact state."""
        ag = self.a_g(t)
        gn = self.g + (0.0 if self.av is None else float(self.av(t)))
        a = ops.Au @ u + ops.Av @ v + ops.ea * ag + ops.en * gn
        F = ops.Fu @ u + ops.Fv @ v + ops.fa * ag + ops.fn * gn
        if self.force is not None:
            P = np.asarray(self.force(t), dtype=float)
            a = a + ops.Bp @ P
            F = F + ops.Fp @ P
        return a, F


@dataclass(frozen=True)
class _PhaseOps:
    Au: np.ndarray
    Av: np.ndarray
    Bp: np.ndarray
    ea: np.ndarray
    en: np.ndarray
    Fu: np.ndarray
    Fv: np.ndarray
    Fp: np.ndarray
    fa: np.ndarray
    fn: np.ndarray
    stuck: np.ndarray


def simulate_reference(
    M: np.ndarray,
    C: np.ndarray | None,
    K: np.ndarray | None,
    slider_dof: Sequence[int] | np.ndarray,
    slider_mass: Sequence[float] | np.ndarray,
    mu_static: Sequence[float] | np.ndarray | float,
    mu_dynamic: Sequence[float] | np.ndarray | float | None = None,
    *,
    duration: float,
    ground_accel: ScalarFn | None = None,
    influence: Sequence[float] | np.ndarray | None = None,
    force: VectorFn | None = None,
    vertical_accel: ScalarFn | None = None,
    g: float = 9.81,
    save_dt: float = 1e-3,
    rtol: float = 1e-11,
    atol: float = 1e-14,
    max_step: float = 0.01,
    max_phases: int = 200_000,
) -> ReferenceResult:
    """Event-driven exact-switching solution; see the module docstring for the model.

    Args:
        M, C, K: (n, n) structural mass [kg], damping [N·s/m], stiffness [N/m] (free DOFs).
        slider_dof: (m,) int DOF each slider rests on (-1: directly on the ground).
        slider_mass: (m,) [kg]; mu_static, mu_dynamic: (m,) or scalars, 0 <= mu_d <= mu_s.
        duration: [s], from rest at t = 0, all sliders stuck.
        ground_accel: a_g(t) [m/s²] callable or None; influence: (n,) (default ones).
        force: P(t) -> (n,) [N] callable or None; vertical_accel: a_v(t) [m/s²] or None.
        save_dt: output grid step [s]; rtol, atol, max_step: DOP853 settings.
    """
    M = np.atleast_2d(np.asarray(M, dtype=float)) if np.size(M) else np.zeros((0, 0))
    n = M.shape[0]
    M = _as_square("M", M, n)
    C = np.zeros((n, n)) if C is None or np.size(C) == 0 else _as_square("C", C, n)
    K = np.zeros((n, n)) if K is None or np.size(K) == 0 else _as_square("K", K, n)
    dof = np.atleast_1d(np.asarray(slider_dof, dtype=int))
    m = dof.size
    if np.any(dof >= n) or np.any(dof < -1):
        raise InputError("slider_dof", dof.tolist(), f"integers in [-1, {n - 1}]")
    mass = _as_vec("slider_mass", slider_mass, m)
    if np.any(mass <= 0):
        raise InputError("slider_mass", mass.tolist(), "> 0")
    mu_s = _as_vec("mu_static", mu_static, m)
    mu_d = mu_s.copy() if mu_dynamic is None else _as_vec("mu_dynamic", mu_dynamic, m)
    if np.any(mu_s < 0):
        raise InputError("mu_static", mu_s.tolist(), ">= 0")
    if np.any(mu_d < 0):
        raise InputError("mu_dynamic", mu_d.tolist(), ">= 0")
    if np.any(mu_d > mu_s):
        raise InputError("mu_dynamic", mu_d.tolist(), "mu_dynamic <= mu_static")
    r = np.ones(n) if influence is None else _as_vec("influence", influence, n)
    for name, val in (("duration", duration), ("save_dt", save_dt), ("g", g)):
        if not (math.isfinite(val) and val > 0):
            raise InputError(name, val, "a finite number > 0")
    if n and np.any(np.linalg.eigvalsh(0.5 * (M + M.T)) <= 0):
        raise InputError("M", "not positive definite", "a symmetric positive definite mass matrix")

    prob = _Problem(M, C, K, dof, mass, mu_s, mu_d, ground_accel, r, force, vertical_accel, g)
    n_grid = int(math.floor(duration / save_dt + 1e-9)) + 1
    t_grid = np.arange(n_grid) * save_dt
    out_u = np.zeros((n_grid, n))
    out_v = np.zeros((n_grid, n))
    out_a = np.zeros((n_grid, n))
    out_w = np.zeros((n_grid, m))
    out_wd = np.zeros((n_grid, m))
    out_F = np.zeros((n_grid, m))
    out_stuck = np.zeros((n_grid, m), dtype=bool)

    events: list[ReferenceEvent] = []
    phases: list[ReferencePhase] = []
    y = np.zeros(2 * n + 2 * m)
    t0 = 0.0
    direction = np.zeros(m, dtype=int)
    offset = np.zeros(m)  # stuck sliders: w - u_node
    next_grid = 0
    tiny_count = 0
    forced: set[int] = set()  # stuck sliders whose bound event just fired

    def node_uv(yv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        u, v = yv[:n], yv[n : 2 * n]
        un = np.where(prob.on_ground, 0.0, u[prob.node] if n else 0.0)
        vn = np.where(prob.on_ground, 0.0, v[prob.node] if n else 0.0)
        return un, vn

    def release_overloaded(t: float, yv: np.ndarray, trial: np.ndarray) -> np.ndarray:
        """Acceleration-level decision for the sliders at zero relative velocity in ``trial``:
        release, one at a time, the one whose needed force exceeds mu_s N the most (sliders in
        ``forced`` first), until the others can stay stuck. Updates and returns ``trial``."""
        zero_vel = trial == 0
        for _ in range(m + 1):
            lu_t = prob.factor(trial)
            _, F = prob.accelerations(t, yv[:n], yv[n : 2 * n], trial, lu_t)
            N = prob.normal(t)
            cand = np.flatnonzero(zero_vel & (trial == 0))
            if cand.size == 0:
                break
            ratio = np.abs(F[cand]) / np.maximum(mu_s[cand] * N[cand], 1e-300)
            ratio = np.where(np.isin(cand, list(forced)), np.inf, ratio)
            worst = int(np.argmax(ratio))
            if ratio[worst] <= 1.0 + 1e-10:
                break
            k = int(cand[worst])
            trial[k] = -1 if F[k] > 0 else 1  # slides against the force it needed (Eq. 2)
            forced.discard(k)
        return trial

    while t0 < duration - 1e-13:
        # -- decide the contact state at t0 (acceleration level) ------------------------------
        was = direction.copy()
        trial = release_overloaded(t0, y, direction.copy())
        forced.clear()
        for k in range(m):
            if was[k] == 0 and trial[k] != 0:
                events.append(ReferenceEvent(t0, k, "slip"))
        direction = trial
        # stuck sliders: freeze their offset; newly sliding ones start at zero relative velocity
        un, vn = node_uv(y)
        for k in range(m):
            if direction[k] == 0:
                offset[k] = y[2 * n + k] - un[k]
                y[2 * n + m + k] = vn[k]
        lu = prob.factor(direction)
        dir_f = direction.astype(float)
        stuck_mask = direction == 0

        def rhs(t: float, yv: np.ndarray, dir_f=dir_f, lu=lu, stuck_mask=stuck_mask) -> np.ndarray:
            u, v = yv[:n], yv[n : 2 * n]
            a, F = prob.accelerations(t, u, v, dir_f, lu)
            a_node = np.where(prob.on_ground, 0.0, a[prob.node] if n else 0.0)
            wdd = np.where(stuck_mask, a_node, F / mass - prob.a_g(t))
            wd = yv[2 * n + m :]
            return np.concatenate([v, a, wd, wdd])

        ev_funcs = []
        for k in range(m):
            if direction[k] == 0:
                for sgn in (1.0, -1.0):

                    def ev(t: float, yv: np.ndarray, k=k, sgn=sgn, dir_f=dir_f, lu=lu) -> float:
                        _, F = prob.accelerations(t, yv[:n], yv[n : 2 * n], dir_f, lu)
                        return float(mu_s[k] * prob.normal(t)[k] - sgn * F[k])

                    ev.terminal = True  # type: ignore[attr-defined]
                    ev.direction = -1  # type: ignore[attr-defined]
                    ev_funcs.append((ev, k, "bound"))
            else:

                def evv(t: float, yv: np.ndarray, k=k, d=float(direction[k])) -> float:
                    vn_k = 0.0 if prob.on_ground[k] else yv[n + prob.node[k]]
                    return d * (yv[2 * n + m + k] - vn_k)

                evv.terminal = True  # type: ignore[attr-defined]
                evv.direction = -1  # type: ignore[attr-defined]
                ev_funcs.append((evv, k, "velocity"))

        sol = solve_ivp(
            rhs,
            (t0, duration),
            y,
            method="DOP853",
            rtol=rtol,
            atol=atol,
            max_step=max_step,
            dense_output=True,
            events=[e[0] for e in ev_funcs] or None,
        )
        if sol.status < 0:
            raise SolverError(f"reference integration failed at t={t0:.6g} s: {sol.message}")
        t1 = float(sol.t[-1])
        # -- sample the grid inside [t0, t1] -----------------------------------------------------
        last = n_grid if sol.status == 0 else int(np.searchsorted(t_grid, t1, side="right"))
        idx = np.arange(next_grid, last)
        if idx.size:
            Y = sol.sol(t_grid[idx]).T
            for row, i in zip(Y, idx, strict=True):
                a, F = prob.accelerations(t_grid[i], row[:n], row[n : 2 * n], dir_f, lu)
                out_u[i], out_v[i], out_a[i] = row[:n], row[n : 2 * n], a
                un_i, _ = node_uv(row)
                out_w[i] = np.where(stuck_mask, un_i + offset, row[2 * n : 2 * n + m])
                out_wd[i] = row[2 * n + m :]
                out_F[i] = F
                out_stuck[i] = stuck_mask
            next_grid = last
        phases.append(ReferencePhase(t0, t1, tuple(int(d) for d in direction)))
        if len(phases) > max_phases:
            raise SolverError(f"more than {max_phases} contact phases; the contact state chatters")
        tiny_count = tiny_count + 1 if t1 - t0 < _TINY_PHASE else 0
        if tiny_count > 50:
            raise SolverError(f"contact state chatters near t={t1:.9g} s (zero-length phases)")
        y = sol.y[:, -1].copy()
        # stuck sliders: restore the exact constraint (no drift of the integrated copy)
        un, vn = node_uv(y)
        for k in range(m):
            if direction[k] == 0:
                y[2 * n + k] = un[k] + offset[k]
                y[2 * n + m + k] = vn[k]
        if sol.status == 0:
            break
        t0 = t1
        # which event(s) fired?
        new_dir = direction.copy()
        fired_vel: list[int] = []
        for i_ev, (_, k, kind) in enumerate(ev_funcs):
            if sol.t_events[i_ev].size:
                if kind == "bound":
                    forced.add(k)
                else:
                    fired_vel.append(k)
        for k in fired_vel:
            # relative velocity is zero: candidate to stick (decided at the top of the loop)
            vn_k = node_uv(y)[1][k]
            y[2 * n + m + k] = vn_k
            new_dir[k] = 0
        # decide now for velocity events, to label stick vs reverse
        if fired_vel:
            trial = release_overloaded(t0, y, new_dir.copy())
            for k in fired_vel:
                if trial[k] == 0:
                    events.append(ReferenceEvent(t0, k, "stick"))
                elif trial[k] == -direction[k]:
                    events.append(ReferenceEvent(t0, k, "reverse"))
                # same direction again: a tangency, sliding simply continues (no event)
            for k in range(m):
                if direction[k] == 0 and trial[k] != 0:
                    events.append(ReferenceEvent(t0, k, "slip"))
            direction = trial
            forced.clear()
            # the top of the loop now re-runs the (idempotent) decision with nothing forced
        else:
            direction = new_dir

    sliding = out_w - np.where(prob.on_ground[None, :], 0.0, out_u[:, prob.node] if n else 0.0)
    events.sort(key=lambda e: (e.time_s, e.slider))
    return ReferenceResult(
        t=t_grid,
        u=out_u,
        v=out_v,
        a=out_a,
        slider_u=out_w,
        slider_v=out_wd,
        sliding=sliding,
        friction=out_F,
        stuck=out_stuck,
        events=events,
        phases=phases,
    )
