"""The modal response spectrum analysis of a rack (EN 1998-1 §4.3.3.3, EN 16681 unit loads).

Steps (docs/user/design_analysis.md):

1. Modes of the rack with the unit loads' horizontal mass scaled by E_D1·E_D3 (the pallets
   otherwise rigidly attached): K φ = ω² M φ, mass-normalised; Γ_d = φᵀ M r_d per direction.
2. Per direction d and mode k: S_a,k from the spectrum times E_D2(d); modal displacement
   u_k = φ_k Γ_d,k S_a,k / ω_k² (Chopra §13.8).
3. Every quantity is ``op.T @ u_k`` for its named operator (:mod:`.operators`), combined over
   the modes by SRSS or CQC (:mod:`.combination`, §4.3.3.3.2), then over the directions
   (§4.3.3.5.1).
4. Displacements d_s = q·d_e (§4.3.4); θ = P_tot·d_r/(V_tot·h) per storey (§4.4.2.2, Eq 4.28)
   with the 1/(1 − θ) amplification; member design values |G| + E with G the static state
   under gravity alone.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace
from typing import Any

import numpy as np

from seisrack.checks.drift import sensitivity_theta, storey_gravity_loads, theta_verdict
from seisrack.design.combination import (
    DIRECTION_RULES,
    choose_rule,
    combine_directions,
    combine_modes,
    der_kiureghian_rho,
)
from seisrack.design.factors import FACTOR_SOURCES, DesignFactors
from seisrack.design.operators import (
    AXIS,
    NamedOperator,
    directions_of,
    influence,
    member_operators,
    storey_heights,
    storey_operators,
)
from seisrack.design.result import DesignResult, Quantity, StoreyCheck
from seisrack.errors import InputError
from seisrack.fe.eigen import modal_from_matrices
from seisrack.fe.stability import symmetric_lu

#: modes computed first when not told (doubled until 90 % of the mass, up to MAX_MODES)
DEFAULT_MODES = 30
MAX_MODES = 480


def design_mass(model: Any, factor: float) -> Any:
    """(n_dof, n_dof) CSR mass: the structure plus ``factor`` × the unit loads' horizontal
    mass (``total_mass_sparse()`` holds them fully, ``M_sparse`` not at all)."""
    full = model.total_mass_sparse()
    if factor == 1.0:
        return full
    return (model.M_sparse + factor * (full - model.M_sparse)).tocsr()


def modal_damping(model: Any, omega: np.ndarray, damping: float | str,
                  phi: np.ndarray | None = None) -> np.ndarray:
    """(n,) damping ratio of each mode: ``damping`` for all, or ``"model"``: the rack's own,
    ζ_k = φ_kᵀ C φ_k / (2 ω_k) for mass-normalised φ (the diagonal of the modal damping
    matrix; Chopra §11.5). C = a0·M + a1·K acts on the structure's mass (``C_sparse``), as in
    the time history, so the unit loads' horizontal mass carries no mass-proportional damping.
    """
    if isinstance(damping, str):
        if damping != "model":
            raise InputError("damping", damping, "a damping ratio in (0, 1) or 'model'")
        C = getattr(model, "C_sparse", None)
        if C is None or phi is None:
            a0, a1 = model.damping_coefficients
            return a0 / (2.0 * omega) + a1 * omega / 2.0
        return np.einsum("ik,ik->k", phi, np.asarray(C @ phi)) / (2.0 * omega)
    if not (isinstance(damping, int | float) and 0 < damping < 1):
        raise InputError("damping", damping, "a damping ratio in (0, 1) or 'model'")
    return np.full(omega.shape, float(damping))


def spectral_accelerations(spectrum: Any, periods: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """(n,) [m/s²] S_a at ``periods``; an elastic EN 1998-1 spectrum is taken at each mode's
    damping (η of Eq 3.6), any other spectrum as it is."""
    from seisrack.motion.ec8 import EC8Spectrum

    if isinstance(spectrum, EC8Spectrum):
        return np.array([float(replace(spectrum, damping=float(z)).psa(t)[0])
                         for t, z in zip(periods, zeta, strict=True)])
    return np.asarray(spectrum.psa(periods), dtype=float)


def _spectra(spectrum: Any, directions: tuple[str, ...]) -> dict[str, Any]:
    if isinstance(spectrum, Mapping):
        missing = [d for d in directions if d not in spectrum]
        if missing:
            raise InputError("spectrum", sorted(spectrum), f"a spectrum for {missing[0]}")
        return {d: spectrum[d] for d in directions}
    return {d: spectrum for d in directions}


def _directions(model: Any, directions: Any) -> tuple[str, ...]:
    have = directions_of(model)
    if directions is None:
        return have
    ds = (directions,) if isinstance(directions, str) else tuple(directions)
    for d in ds:
        if d not in have:
            raise InputError("direction", d, " or ".join(have)
                             + ("" if len(have) > 1 else " (a 2D rack has no cross-aisle)"))
    if not ds or len(set(ds)) != len(ds):
        raise InputError("direction", directions, "one or two distinct directions")
    return ds


def design_analysis(model: Any, spectrum: Any, *, factors: DesignFactors | None = None,
                    directions: Any = None, n_modes: int | None = None,
                    modal_rule: str = "auto", direction_rule: str = "srss",
                    damping: float | str | None = None,
                    operators: list[NamedOperator] | None = None) -> DesignResult:
    """Modal response spectrum analysis of ``model`` (a 2D or 3D compiled rack).

    spectrum: a spectrum object (``psa(periods)`` [m/s²]; its ``q`` attribute, 1 if absent,
        gives d_s = q·d_e), or a mapping direction -> spectrum (a q per direction).
        :func:`seisrack.design.design_spectrum` gives EN 1998-1 §3.2.2.5's S_d with q;
        :func:`seisrack.motion.ec8_spectrum` the elastic S_e (taken at each mode's damping).
    factors: :class:`DesignFactors` (default values with their sources).
    directions: "down-aisle" and/or "cross-aisle" (3D); default all of the rack's.
    n_modes: modes computed; default: 30, doubled until they hold ``factors.mass_target``
        of the mass in every direction (up to 480). The result notes when they hold less.
    modal_rule: "auto" (SRSS if the relevant modes are well separated, else CQC), "srss", "cqc".
    direction_rule: "srss" or "0.30" (EN 1998-1 §4.3.3.5.1).
    damping: ratio of every mode for CQC and an elastic spectrum (default
        ``factors.damping``), or "model" for the rack's own damping per mode
        (:func:`modal_damping`).
    operators: the named operators to evaluate (default: the storey operators of every
        direction of the rack and its member operators, :mod:`seisrack.design.operators`).
    """
    f = factors or DesignFactors()
    dirs = _directions(model, directions)
    if direction_rule not in DIRECTION_RULES:
        raise InputError("direction_rule", direction_rule, ", ".join(DIRECTION_RULES))
    spectra = _spectra(spectrum, dirs)
    if n_modes is not None and (isinstance(n_modes, bool) or not isinstance(n_modes, int)
                                or n_modes < 1):
        raise InputError("n_modes", n_modes, "an integer >= 1")
    M = design_mass(model, f.mass_factor)
    r = {d: influence(model, d) for d in dirs}
    modes = _modes(model, M, r, dirs, n_modes, f.mass_target)
    phi, omega, periods = modes.shapes, modes.omega, modes.periods
    zeta = modal_damping(model, omega, f.damping if damping is None else damping, phi)
    rho = der_kiureghian_rho(omega, zeta)
    gam = {d: phi.T @ (M @ r[d]) for d in dirs}
    m_eff = {d: gam[d] ** 2 for d in dirs}
    m_tot = {d: float(r[d] @ (M @ r[d])) for d in dirs}

    notes: list[str] = []
    if operators is None:
        ops: list[NamedOperator] = []
        for d in directions_of(model):
            ops += storey_operators(model, d)
        members, why = member_operators(model)
        ops += members
        if why:
            notes.append(why)
    else:
        ops = list(operators)

    sa, rules, reasons, q = {}, {}, {}, {}
    per_dir: dict[str, dict[str, np.ndarray]] = {op.name: {} for op in ops}
    for d in dirs:
        sp_ = spectra[d]
        q[d] = float(getattr(sp_, "q", 1.0))
        sa[d] = f.e_d2(d) * spectral_accelerations(sp_, periods, zeta)
        share = m_eff[d] / m_tot[d]
        relevant = share >= f.relevant_mass
        if not relevant.any():
            relevant = share >= share.max()
        rules[d], reasons[d] = choose_rule(periods, relevant, f.well_separated, modal_rule)
        cum = float(share.sum())
        if cum < f.mass_target:
            notes.append(f"{d}: the {periods.size} modes computed hold {100 * cum:.1f} % of "
                         f"the mass, less than the {100 * f.mass_target:g} % of EN 1998-1 "
                         "§4.3.3.3.1(3); compute more modes (n_modes)")
        U = phi * (gam[d] * sa[d] / omega**2)[None, :]  # (n_dof, n_modes) [m, rad]
        for op in ops:
            modal = np.asarray(op.op.T @ U)  # (k, n_modes)
            per_dir[op.name][d] = combine_modes(modal, rules[d], rho)

    if len(dirs) == 1:
        drule, dtext = "single", f"one direction ({dirs[0]})"
    else:
        drule = direction_rule
        dtext = ("SRSS of the two horizontal components, EN 1998-1 §4.3.3.5.1(2)b"
                 if drule == "srss" else
                 f"E_x + {f.combination_030:g} E_z and {f.combination_030:g} E_x + E_z, the "
                 "larger, EN 1998-1 §4.3.3.5.1(3) Eqs (4.18)-(4.19)")
    u0 = _gravity_state(model) if any(op.kind == "member" for op in ops) else None
    quantities: dict[str, Quantity] = {}
    for op in ops:
        seismic = combine_directions([per_dir[op.name][d] for d in dirs], direction_rule,
                                     f.combination_030)
        grav = design = None
        if op.kind == "member":
            grav = np.asarray(u0 @ op.op).ravel()
            design = np.abs(grav) + seismic
        quantities[op.name] = Quantity(op.name, op.unit, op.description, op.kind, op.labels,
                                       per_dir[op.name], seismic, grav, design)
    _level_forces(quantities, directions_of(model))
    storeys = {d: _storey_check(model, quantities, d, q[d], f) for d in dirs
               if f"drift_{AXIS[d]}" in quantities and f"storey_shear_{AXIS[d]}" in quantities}
    return DesignResult(
        three_d=model.ndm == 3, directions=dirs, periods=periods,
        omega=omega, damping=zeta, effective_mass=m_eff, total_mass=m_tot,
        spectra={d: getattr(spectra[d], "name", "spectrum") for d in dirs}, q=q, sa=sa,
        modal_rule=rules, modal_rule_reason=reasons, direction_rule=drule,
        direction_rule_text=dtext, quantities=quantities, storeys=storeys,
        factors=f.as_dict(), factor_sources=dict(FACTOR_SOURCES), mass_factor=f.mass_factor,
        notes=tuple(notes))


def _modes(model: Any, M: Any, r: dict[str, np.ndarray], dirs: tuple[str, ...],
           n_modes: int | None, target: float) -> Any:
    """The modes: ``n_modes`` of them, or (None) from ``DEFAULT_MODES`` up, doubled until
    they hold ``target`` of the mass in every direction (at most ``MAX_MODES``, or all)."""
    n = model.n_dof
    k = min(n, n_modes or DEFAULT_MODES)
    while True:
        modes = modal_from_matrices(model.K_sparse, M, r[dirs[0]], model.r_y,
                                    None if k >= n - 1 else k)
        if n_modes is not None or k >= min(n - 1, MAX_MODES):
            return modes
        phi = modes.shapes
        if all(float(np.sum((phi.T @ (M @ r[d])) ** 2)) >= target * float(r[d] @ (M @ r[d]))
               for d in dirs):
            return modes
        k = min(2 * k, MAX_MODES, n)


def _gravity_state(model: Any) -> np.ndarray:
    """(n_dof,) [m, rad] static displacements under gravity alone: K u = −g M r_y (M holds the
    members and the unit loads' vertical mass)."""
    return np.atleast_1d(symmetric_lu(model.K_sparse).solve(
        -model.g * (model.M_sparse @ model.r_y)))


def _level_forces(quantities: dict[str, Quantity], all_dirs: tuple[str, ...]) -> None:
    """Level forces F_l = V_l − V_(l+1), from the combined storey shears (a level force is the
    difference of two storey shears only for one mode; for the combination the difference of
    the combined values is what a designer applies as equivalent level forces)."""
    for d in all_dirs:
        ax = AXIS[d]
        if f"storey_shear_{ax}" not in quantities:
            continue
        v = quantities[f"storey_shear_{ax}"]
        lab = tuple(f"L{i + 1}" for i in range(v.seismic.size))
        by = {e: np.r_[a[:-1] - a[1:], a[-1:]] for e, a in v.by_direction.items()}
        s = v.seismic
        quantities[f"level_force_{ax}"] = Quantity(
            f"level_force_{ax}", "N", f"equivalent level force {d}: storey shear below the "
            "level minus storey shear above", "level", lab, by, np.r_[s[:-1] - s[1:], s[-1:]])


def _storey_check(model: Any, quantities: dict[str, Quantity], direction: str, q: float,
                  f: DesignFactors) -> StoreyCheck:
    ax = AXIS[direction]
    h = storey_heights(model)
    P = storey_gravity_loads(model)
    d_e = quantities[f"drift_{ax}"].seismic
    d_s = q * d_e  # EN 1998-1 §4.3.4, Eq (4.23) with q_d = q
    V = quantities[f"storey_shear_{ax}"].seismic
    theta = np.array([sensitivity_theta(P[s], d_s[s], V[s], h[s]) for s in range(h.size)])
    verdicts, ok = [], True
    amp = np.ones_like(theta)
    for s, t in enumerate(theta):
        text, good = theta_verdict(float(t), f)
        verdicts.append(text)
        ok &= good
        if t > f.theta_ignore:
            amp[s] = 1.0 / (1.0 - t) if t < 1 else math.inf
    return StoreyCheck(direction, q, h, P, d_e, d_s, V, theta, amp, tuple(verdicts), bool(ok))
