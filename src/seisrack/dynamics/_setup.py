"""Preparing a run of the engine: the basis, the load patterns, and the checks done before
anything is allocated (memory, the exact kernel's applicability, a friction law the step can
resolve). Plain functions of arrays, called by :func:`seisrack.dynamics.engine.simulate`.
"""

from __future__ import annotations

import os

import numpy as np

from seisrack.dynamics.basis import Basis, full_basis
from seisrack.dynamics.sliders import Sliders
from seisrack.errors import InputError

#: with ``basis="auto"``, structures up to this many DOFs keep every mode
AUTO_FULL_MAX_DOF = 50
#: with nonlinear hinges the Ritz basis also starts from a unit moment at every hinge (the
#: static response to the hinges' correction forces), with this many Krylov blocks and this
#: compression tolerance (a yielding hinge needs its own directions: at 3e-2 they are merged
#: and peak hinge rotations are 5 % off); on the paper rack with pallets sliding and hinges
#: yielding, 16 vectors keep the peaks within 1e-4 of the full basis
#: (tests/test_engine_hinges.py)
HINGE_RITZ_BLOCKS = 2
HINGE_RITZ_TOL = 1e-3
#: default cap on what one run's kept histories and buffers may take [bytes]
DEFAULT_MAX_MEMORY = 4 * 2**30


def given_or_full_basis(basis, M, K) -> Basis | None:  # noqa: ANN001, N803
    """The caller's Basis (checked), every mode for ``"full"`` (or ``"auto"`` up to
    ``AUTO_FULL_MAX_DOF`` DOFs), or None when a reduced basis is to be built."""
    n = M.shape[0]
    if isinstance(basis, Basis):
        if basis.phi.shape[0] != n:
            raise InputError("basis", f"phi of shape {basis.phi.shape}", f"phi with {n} rows")
        return basis
    if basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if basis == "full" or (basis == "auto" and n <= AUTO_FULL_MAX_DOF):
        return full_basis(M, K)
    return None


def _kept_samples(n_steps: int, save_every: int | None) -> int:
    if save_every is None:
        return 2
    return n_steps // save_every + 1 + (1 if n_steps % save_every else 0)


def memory_budget(max_memory: float | None) -> float | None:
    """Bytes one run may take: ``max_memory`` if given, else half of the memory free now and
    at most :data:`DEFAULT_MAX_MEMORY` (studies run several at once; ask for more with
    ``max_memory=``); None where the free memory cannot be read."""
    if max_memory is not None:
        return max_memory
    try:
        avail = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return None
    return min(0.5 * avail, DEFAULT_MAX_MEMORY)


def _check_memory(n_keep: int, chunk: int, nb: int, m: int, n_t: int,
                  max_memory: float | None) -> None:
    """Refuse a run whose histories and buffers would not fit, before allocating them."""
    per_row = 8 * (3 * nb + 4 * m + 5) + m
    need = n_keep * (per_row + 8 * m) + (chunk + 1) * (per_row + 8 * (nb + 2 * m)) + 8 * 4 * n_t
    max_memory = memory_budget(max_memory)
    if max_memory is None:  # pragma: no cover - non-POSIX: the free memory is unknown
        return
    if need > max_memory:
        raise InputError(
            "n_steps", f"{n_t - 1} steps keeping {n_keep} samples of {nb} coordinates and "
            f"{m} sliders ({need / 2**30:.2f} GiB)",
            f"a run that fits in {max_memory / 2**30:.2f} GiB",
            hint="Keep fewer samples (save_every=k, or None with on_chunk for peaks only)",
        )


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
