"""Combination of modal maxima (EN 1998-1 §4.3.3.3.2) and of directions (§4.3.3.5.1).

Modes: SRSS, E = sqrt(Σ_k E_k²) (Eq 4.16), when every pair of relevant modes is independent,
T_j <= 0.9·T_i (§4.3.3.3.2(2)-(3)); otherwise the Complete Quadratic Combination
E = sqrt(Σ_i Σ_j E_i ρ_ij E_j) (§4.3.3.3.2(3), "more accurate procedures") with the correlation
coefficient of Der Kiureghian (1981) for modal damping ratios ζ_i, ζ_j and r = ω_i/ω_j::

    ρ_ij = 8·sqrt(ζ_i ζ_j)·(ζ_i + r ζ_j)·r^1.5
           / ((1 − r²)² + 4 ζ_i ζ_j r (1 + r²) + 4 (ζ_i² + ζ_j²) r²)

(Chopra, *Dynamics of Structures*, 4th ed., Eq 13.7.10 for ζ_i = ζ_j; ρ_ii = 1).

Directions: the SRSS of the two horizontal components (§4.3.3.5.1(2)b), or the 0.30 rule
E = max(|E_x| + 0.30·|E_y|, 0.30·|E_x| + |E_y|) (§4.3.3.5.1(3), Eqs 4.18-4.19).
"""

from __future__ import annotations

import numpy as np

from seisrack.errors import InputError

MODAL_RULES = ("auto", "srss", "cqc")
DIRECTION_RULES = ("srss", "0.30")


def der_kiureghian_rho(omega: np.ndarray, zeta: np.ndarray | float) -> np.ndarray:
    """(n, n) CQC correlation coefficients of modes with circular frequencies ``omega`` (n,)
    [rad/s] and damping ratios ``zeta`` (n,) or a scalar [-]."""
    w = np.asarray(omega, dtype=float)
    z = np.broadcast_to(np.asarray(zeta, dtype=float), w.shape)
    r = w[:, None] / w[None, :]
    zi, zj = z[:, None], z[None, :]
    num = 8.0 * np.sqrt(zi * zj) * (zi + r * zj) * r**1.5
    den = (1.0 - r**2) ** 2 + 4.0 * zi * zj * r * (1.0 + r**2) + 4.0 * (zi**2 + zj**2) * r**2
    return num / den


def srss(modal: np.ndarray) -> np.ndarray:
    """(k,) SRSS over the modes of ``modal`` (k, n_modes), Eq (4.16)."""
    return np.sqrt(np.sum(np.asarray(modal, dtype=float) ** 2, axis=-1))


def cqc(modal: np.ndarray, rho: np.ndarray) -> np.ndarray:
    """(k,) CQC of ``modal`` (k, n_modes) with correlation ``rho`` (n_modes, n_modes)."""
    m = np.asarray(modal, dtype=float)
    s = np.einsum("ki,ij,kj->k", m, rho, m)
    return np.sqrt(np.maximum(s, 0.0))  # round-off may leave -1e-16 for a zero response


def choose_rule(periods: np.ndarray, relevant: np.ndarray, ratio: float = 0.9,
                rule: str = "auto") -> tuple[str, str]:
    """("srss" or "cqc", why): EN 1998-1 §4.3.3.3.2 for the modes with ``periods`` (n,) [s],
    of which ``relevant`` (n,) bool are the relevant ones."""
    if rule not in MODAL_RULES:
        raise InputError("combination", rule, ", ".join(MODAL_RULES))
    T = np.sort(np.asarray(periods, dtype=float)[np.asarray(relevant, dtype=bool)])[::-1]
    if T.size < 2:
        closest = "one relevant mode"
        separated = True
    else:
        q = T[1:] / T[:-1]  # T_j / T_i of consecutive relevant modes, T_j < T_i
        k = int(np.argmax(q))
        separated = bool(q[k] <= ratio)
        closest = (f"closest relevant pair T = {T[k]:.4g} s and {T[k + 1]:.4g} s, "
                   f"T_j/T_i = {q[k]:.3f}")
    if rule == "srss":
        return "srss", f"SRSS as asked ({closest}; EN 1998-1 §4.3.3.3.2(2) asks T_j/T_i <= " \
                       f"{ratio:g} for independent modes)"
    if rule == "cqc":
        return "cqc", f"CQC as asked ({closest})"
    if separated:
        return "srss", (f"SRSS: the relevant modes are independent, T_j <= {ratio:g}·T_i "
                        f"(EN 1998-1 §4.3.3.3.2(2)-(3); {closest})")
    return "cqc", (f"CQC: relevant modes are not independent, T_j > {ratio:g}·T_i "
                   f"(EN 1998-1 §4.3.3.3.2(3); {closest})")


def combine_modes(modal: np.ndarray, rule: str, rho: np.ndarray) -> np.ndarray:
    """(k,) combination of ``modal`` (k, n_modes) by ``rule`` ("srss" or "cqc")."""
    return srss(modal) if rule == "srss" else cqc(modal, rho)


def combine_directions(values: list[np.ndarray], rule: str = "srss", factor: float = 0.30
                       ) -> np.ndarray:
    """Combination of the responses to each horizontal component (§4.3.3.5.1).

    values: one (k,) array of non-negative combined maxima per direction (1 or 2).
    rule: "srss" (§4.3.3.5.1(2)b) or "0.30" (Eqs 4.18-4.19 with ``factor``).
    """
    if rule not in DIRECTION_RULES:
        raise InputError("directions rule", rule, ", ".join(DIRECTION_RULES))
    v = [np.abs(np.asarray(a, dtype=float)) for a in values]
    if len(v) == 1:
        return v[0]
    if len(v) != 2:
        raise InputError("directions", len(v), "one or two horizontal directions")
    if rule == "srss":
        return np.sqrt(v[0] ** 2 + v[1] ** 2)
    return np.maximum(v[0] + factor * v[1], factor * v[0] + v[1])
