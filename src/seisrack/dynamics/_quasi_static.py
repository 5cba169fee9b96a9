"""The basis directions too stiff for the step, held quasi-statically in the planar scheme
(theory: ``docs/theory/planar_friction.md`` §9).

The trapezoidal rule leaves a direction with ``ω dt ≫ 1`` an undamped period-2dt residue
(amplification → −1, whatever its damping), which a stuck pallet reads in its support's end
acceleration: its holding force jitters from step to step and slips start early. In a basis
that is mass-orthonormal and stiffness-diagonal, with classical damping and a linear
structure, such a direction ``i`` is coupled to the others only through the pallets (their
forces, and their mass while they are stuck: :func:`stiff_directions` checks that the held
directions do not carry it), and its response to loads whose content lies far below ``ω_i``
is static: ``ω_i² q_i = f_i − (Pᵀλ)_i``, with the ground
load ``f_i`` and the pallets' friction forces ``λ``. The kernel integrates the other
directions with the pallets; the pallets ride on them only (a stiff direction's motion is
``O(λ / ω²)``); the stiff coordinates are then recovered per step from the loads and the
friction forces the kernel returns. Their inertia and damping are dropped (accelerations 0,
velocities the backward differences of the recovered coordinates).

Energy, exactly (the trapezoidal work of a load on a coordinate linear in it is the change of
its strain energy): the ground loads' work on the stiff coordinates joins ``input``, their
strain energy ``strain``, and the friction forces' work on them ``friction`` (the pallets'
relative motion includes their supports' stiff part: the friction term is ``−∫λ·(ẇ − P q̇)``
over every direction), so the balance closes as the kernel's does.
"""

from __future__ import annotations

import hashlib

import numpy as np
import scipy.linalg

#: a direction is a candidate when its frequency with every pallet stuck on it, times dt,
#: exceeds this: the trapezoidal rule's frequency is 45 % low at ω dt = 4 (it is
#: 2 atan(ω dt / 2) / dt), and the static response errs by (Ω/ω)² for a load at Ω, 4 % for a
#: 25 Hz ground motion at dt 5 ms
QUASI_STATIC_OMEGA_DT = 4.0
#: the candidates are held quasi-statically only while the frequencies of the rack with every
#: pallet stuck that the step resolves (ω dt < 1) move by less than this fraction of the
#: trapezoidal rule's own frequency error at each, (ω dt)² / 12: a pallet couples the
#: directions it rests on through its mass, which a held direction no longer carries
QUASI_STATIC_SHIFT = 0.1
_CACHE: dict = {}


#: A rack whose lowest frequency with every pallet stuck, times the step, exceeds this (fewer
#: than 2π steps per period) rides stiff (:func:`rides_stiff`). At 4 (the threshold above) the
#: stiff rack of ``tests/test_planar_stiff.py`` with hinges (first period 1.48 ms) went back
#: to the trapezoidal rule below dt = 0.94 ms and rang there: peaks +70 % and +91 % against
#: the rigid blocks, 91-200 slip phases against 1-10, at 0.625 and 0.3125 ms; with composite
#: steps within 0.5 % (docs/theory/planar_friction.md §10)
RIDES_STIFF_OMEGA_DT = 1.0


def rides_stiff(w2: np.ndarray, P: np.ndarray, mass: np.ndarray, dt: float) -> bool:  # noqa: N803
    """Whether the rack with every pallet stuck on it is too stiff for the step: its lowest
    frequency (``diag(ω²)`` against the mass ``I + Pᵀ m P`` of the mass-orthonormal basis)
    times ``dt`` exceeds ``RIDES_STIFF_OMEGA_DT``: the step does not resolve its fundamental,
    and the directions that carry the pallets are stiffer still. Where the kernel integrates
    every direction (hinges, P-Δ, coupling damping: no direction can be held quasi-statically)
    it then takes composite steps throughout (``_planar_stage.py``)."""
    r = w2.shape[0]
    if r == 0:
        return False
    m2 = np.repeat(np.asarray(mass, dtype=float), 2)
    A = np.eye(r) + P.T @ (m2[:, None] * P)
    low = scipy.linalg.eigh(np.diag(np.asarray(w2, dtype=float)), A, eigvals_only=True,
                            subset_by_index=[0, 0])[0]
    return bool(low * dt * dt > RIDES_STIFF_OMEGA_DT**2)


def stiff_directions(w2: np.ndarray, P: np.ndarray, mass: np.ndarray, dt: float,  # noqa: N803
                     coupled: bool) -> np.ndarray:
    """(r,) bool: the directions held quasi-statically. Candidates: the directions whose
    frequency with every pallet stuck on them, the Rayleigh quotient ``ω² / (1 + Σ m_p
    |P_p|²)`` of the mass-orthonormal direction (the pallets are most of a rack's mass), times
    ``dt`` exceeds ``QUASI_STATIC_OMEGA_DT``. Of those, the stiffest ``k``, with ``k`` the
    largest whose removal keeps the resolved frequencies of the rack with every pallet stuck
    within ``QUASI_STATIC_SHIFT`` of the trapezoidal rule's error (bisection: removing a
    direction's inertia only raises the frequencies). None when ``coupled``: nonlinear hinges,
    P-Δ of the current axial forces or damping that couples the directions. ``P`` (2m, r): the
    pallets' support rows; ``mass`` (m,). Cached per (ω², P, masses, dt)."""
    r = w2.shape[0]
    if coupled or r == 0:
        return np.zeros(r, dtype=np.bool_)
    w2 = np.asarray(w2, dtype=float)
    m2 = np.repeat(np.asarray(mass, dtype=float), 2)
    digest = hashlib.blake2b(digest_size=16)
    for a in (w2, m2, np.ascontiguousarray(P, dtype=float)):
        digest.update(a.tobytes())
    key = (float(dt), QUASI_STATIC_OMEGA_DT, QUASI_STATIC_SHIFT, P.shape, digest.digest())
    hit = _CACHE.get(key)
    if hit is not None:
        return hit.copy()
    carried = m2 @ (P * P)
    weff2 = w2 / (1.0 + carried)
    cand = np.flatnonzero(weff2 * dt * dt > QUASI_STATIC_OMEGA_DT**2)
    out = np.zeros(r, dtype=np.bool_)
    if cand.size:
        order = cand[np.argsort(-weff2[cand], kind="stable")]
        A = np.eye(r) + P.T @ (m2[:, None] * P)
        ref = scipy.linalg.eigh(np.diag(w2), A, eigvals_only=True)
        ref = ref[ref * dt * dt < 1.0]
        tol = QUASI_STATIC_SHIFT * ref * dt * dt / 12.0 * 2.0  # on ω²: twice that on ω

        def fits(k: int) -> bool:
            keep = np.ones(r, dtype=np.bool_)
            keep[order[:k]] = False
            if ref.size == 0:
                return True
            got = scipy.linalg.eigh(np.diag(w2[keep]), A[np.ix_(keep, keep)],
                                    eigvals_only=True, subset_by_index=[0, ref.size - 1])
            return bool(np.all(np.abs(got / ref - 1.0) <= tol))

        lo, hi = 0, order.size  # fits(lo) holds; find the largest k that fits
        if fits(hi):
            lo = hi
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if fits(mid):
                lo = mid
            else:
                hi = mid
        out[order[:lo]] = True
    if len(_CACHE) >= 32:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = out
    return out.copy()


class QuasiStatic:
    """Recovers the stiff coordinates of each chunk and their energy terms.

    stiff: (r,) bool mask; pat: (r, k) load per unit of each series; P: (2m, r) the pallets'
    support rows; w2: (r,) ω²; dt: the step."""

    def __init__(self, stiff: np.ndarray, pat: np.ndarray, P: np.ndarray, w2: np.ndarray,  # noqa: N803
                 dt: float) -> None:
        self.stiff = stiff
        self.dyn = ~stiff
        self.count = int(stiff.sum())
        self.pat = np.ascontiguousarray(pat[stiff])
        self.P = np.ascontiguousarray(P[:, stiff])
        self.w2 = w2[stiff]
        self.dt = dt
        self.qd_last = np.zeros(self.count)  # the last velocity (the chunk boundary's)
        self.e_last = np.zeros(2)  # cumulative input and friction work at the boundary

    def fill(self, ser: np.ndarray, friction: np.ndarray, dyn: tuple[np.ndarray, ...],
             full: tuple[np.ndarray, ...], energy: np.ndarray | None) -> None:
        """Write a chunk's full coordinates ``full`` (q, qd, qdd; (k, r)) from the kernel's
        ``dyn`` (its directions) and the recovered stiff ones; add their terms to ``energy``
        (k, 5+) [input, kinetic, strain, damping, friction, ...] when given. ``ser`` (k, c):
        the chunk's load series; ``friction`` (k, 2m): the force on each pallet."""
        d, s = self.dyn, self.stiff
        for dst, src in zip(full, dyn, strict=True):
            dst[:, d] = src
        f_ext = ser @ self.pat.T  # (k, n_s)
        f_fr = friction @ self.P  # λ · P: the pallets' share, loads −Pᵀλ
        q = (f_ext - f_fr) / self.w2
        full[0][:, s] = q
        qd = np.empty_like(q)
        qd[0] = self.qd_last
        qd[1:] = np.diff(q, axis=0) / self.dt
        full[1][:, s] = qd
        full[2][:, s] = 0.0
        self.qd_last = qd[-1].copy()
        if energy is None:
            return
        dq = np.diff(q, axis=0)
        work_in = np.concatenate([[0.0], np.cumsum(
            np.einsum("ij,ij->i", 0.5 * (f_ext[1:] + f_ext[:-1]), dq))])
        work_fr = np.concatenate([[0.0], np.cumsum(
            np.einsum("ij,ij->i", 0.5 * (f_fr[1:] + f_fr[:-1]), dq))])
        energy[:, 0] += self.e_last[0] + work_in
        energy[:, 2] += 0.5 * np.einsum("ij,j,ij->i", q, self.w2, q)
        energy[:, 4] += self.e_last[1] + work_fr
        self.e_last = np.array([self.e_last[0] + work_in[-1], self.e_last[1] + work_fr[-1]])
