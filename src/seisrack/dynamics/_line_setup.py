"""What the line scheme checks and builds before its kernel runs: whether the exact propagators
apply, a velocity-weakening friction the step can resolve, and the load split into patterns.
Plain functions of arrays, called by :func:`seisrack.dynamics._run_line.run_line`.
"""

from __future__ import annotations

import numpy as np

from seisrack.dynamics.sliders import Sliders
from seisrack.errors import InputError


def _check_friction_rate(sliders: Sliders, P: np.ndarray, w2: np.ndarray, cd: np.ndarray,  # noqa: N803
                         diag: bool, dt: float, gz: np.ndarray) -> None:
    """Velocity-weakening friction must be resolved by the step.

    While slider j slides, its end-of-step relative speed solves v = v₀ − α N μ(v) with
    α = dt/(2m) + (2/dt)·(P K̂⁻¹ Pᵀ)_jj (``docs/theory/nonlinear_hinges.md``). With
    μ(v) = μ_d + (μ_s − μ_d) e^(−a v) that equation has a single root only when
    α N a (μ_s − μ_d) < 1; otherwise the step is longer than the friction's weakening time and
    the discrete slide is not unique. Refused up front, with the largest rate this dt allows.
    """
    rate, dmu = sliders.friction_rate, sliders.mu_static - sliders.mu_dynamic
    kh = w2 + (2.0 / dt) * (cd if diag else 0.0) + 4.0 / dt**2
    alpha = dt / (2.0 * sliders.mass) + (2.0 / dt) * ((P**2) @ (1.0 / kh))
    n_max = sliders.mass * float(np.max(gz))
    worst = alpha * n_max * rate * dmu
    j = int(np.argmax(worst))
    if worst[j] >= 1.0:
        raise InputError(
            f"sliders.friction_rate[{j}]", float(rate[j]),
            f"a rate < {1.0 / (alpha[j] * n_max[j] * dmu[j]):.4g} s/m at dt = {dt:g} s (the "
            "step must resolve the friction's fall from mu_static to mu_dynamic)",
            hint="Reduce dt, or use a smaller friction_rate (rate -> infinity is Coulomb "
                 "friction: give friction_rate = 0 for that)")


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


def _load_patterns(phi, M, r, ag, F, av, rv):  # noqa: ANN001, ANN202, N803
    """Split the basis-coordinate load as ``p(t) = series(t) @ pat`` (one pattern per loaded
    DOF of ``F``, so the per-chunk product costs O(n_t · patterns · r))."""
    pats = [-(phi.T @ (M @ r))]
    cols = [ag]
    if F is not None:
        for d in np.flatnonzero(np.any(F != 0.0, axis=0)):
            pats.append(phi[d, :])
            cols.append(F[:, d])
    if av is not None and rv is not None:
        pats.append(-(phi.T @ (M @ rv)))
        cols.append(av)
    return np.ascontiguousarray(np.array(pats)), np.ascontiguousarray(np.column_stack(cols))
