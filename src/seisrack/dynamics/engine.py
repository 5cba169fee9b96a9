"""The stick–slip engine's one entry point, :func:`simulate`: check the inputs, choose the basis
and check the memory once, then run the scheme the sliders call for.

The structure is linear (M, C, K; dense or scipy sparse, plus optional hysteretic hinges); the
sliders are masses resting on structural DOFs with Coulomb friction (paper §II–III). Two schemes
stand behind the one front, chosen by the sliders, as a solver is chosen in diffrax:

- sliders moving along one line (:class:`~seisrack.dynamics.Sliders`, 2D racks): each contact
  phase integrated in closed form with the modes of its contact configuration ("exact") or by
  Newmark average acceleration, events located inside the step (``_run_line.py``,
  ``docs/theory/stick_slip_engine.md``);
- sliders moving in the plane (:class:`~seisrack.dynamics.PlanarSliders`, 3D racks):
  isotropic Coulomb friction, Newmark with a return map and events located inside the step
  (``planar.py``, ``docs/theory/planar_friction.md``).

Each scheme declares what it supports (:data:`SCHEME_FEATURES`); the front refuses, by name, an
argument the chosen scheme does not support.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from seisrack.dynamics import _inputs as chk
from seisrack.dynamics._blas import single_blas_thread  # noqa: F401  (re-exported)
from seisrack.dynamics._chunk import Chunk  # noqa: F401  (re-exported: on_chunk's argument)
from seisrack.dynamics._inputs import DEFAULT_CHUNK  # noqa: F401  (re-exported)
from seisrack.dynamics._run_line import run_line
from seisrack.dynamics._store import DEFAULT_MAX_MEMORY, check_memory  # noqa: F401
from seisrack.dynamics.basis import Basis, full_basis
from seisrack.dynamics.hinges import Hinges
from seisrack.dynamics.planar import run_planar_scheme
from seisrack.dynamics.results import TimeHistory
from seisrack.dynamics.run_basis import (  # noqa: F401  (constants re-exported: the engine's API)
    AUTO_FULL_MAX_DOF,
    HINGE_RITZ_BLOCKS,
    HINGE_RITZ_TOL,
    choose_basis,
)
from seisrack.dynamics.sliders import PlanarSliders, Sliders

#: what each scheme supports beyond the ground motion, for the documentation and the refusals
SCHEME_FEATURES = {
    "line": ("ground motion", "vertical motion", "applied forces", "initial state",
             "exact propagators", "Newmark", "nonlinear hinges", "velocity-dependent friction",
             "energy balance", "reduced basis", "chunks", "work counters (Newmark)"),
    "planar": ("ground motion in two directions", "vertical motion", "Newmark",
               "nonlinear hinges", "energy balance", "reduced basis", "chunks", "work counters"),
}


def modal_basis(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: N803
    """Mass-normalised eigenbasis: returns (omega², Φ) with Φᵀ M Φ = I, Φᵀ K Φ = diag(omega²)."""
    b = full_basis(M, K)
    return b.w2, b.phi


def simulate(
    M: np.ndarray,  # noqa: N803
    C: np.ndarray,  # noqa: N803
    K: np.ndarray,  # noqa: N803
    sliders: Sliders | PlanarSliders,
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
    max_events: int | None = None,
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
    sliders : masses resting on DOFs with static / dynamic friction, sliding along one line
        (:class:`Sliders`) or in the plane (:class:`PlanarSliders`).
    dt : time step [s]; excitation arrays are sampled at ``t_k = k dt`` and interpolated linearly.
    n_steps : number of steps; inferred from the excitation when omitted.
    ground_accel : [m/s²] horizontal ground acceleration, felt by the sliders too: (n_steps+1,)
        or (n_steps+1, 1) along the line (or along x in the plane), or (n_steps+1, 2) along x
        and z for planar sliders.
    influence : influence vector(s) of ``ground_accel``: (n,) or (n, 1) (default: ones, for
        sliders on a line), or (n, 2) for the two components of planar sliders (required for
        them).
    force : (n_steps+1, n) [N] applied forces (sliders on a line).
    vertical_accel : (n_steps+1,) [m/s²]; normal forces become ``m (g + a_v)`` (clipped at 0).
    vertical_influence : (n,) if given, the structure is also loaded by ``-M r_v a_v``.
    g : gravity [m/s²]. u0, v0 : (n,) initial structural state (sliders start stuck).
    backend : "auto" (numba if installed), "numba" or "python" (the pure-Python twin).
    throw : raise :class:`SolverError` on failure; otherwise return with ``status`` set.
    progress : called with the number of steps just completed, after each chunk of
        ``chunk_steps`` steps; chunking does not change the result, the contact state carries
        over exactly.
    method : sliders on a line: "exact" propagates every contact configuration with its own
        closed-form modal solution (needs classical damping in every configuration: no
        damping, C ∝ K, or no slider on the structure), "newmark" uses average-acceleration
        Newmark, "auto" (default) takes "exact" when it applies. Planar sliders: Newmark.
    basis : "full" (every mode: no truncation), "reduced" (a load-dependent Ritz basis),
        "auto" (full up to ``AUTO_FULL_MAX_DOF`` DOFs, reduced above), or a
        :class:`~seisrack.dynamics.basis.Basis`.
    save_every : keep every k-th sample of the histories (the last sample is always kept);
        ``None`` keeps only the first and last samples (peaks then come from ``on_chunk``).
    on_chunk : called with the full-rate :class:`Chunk` of each chunk of steps.
    max_memory : bytes the kept histories and buffers may use (default: half of the memory
        available now, at most 4 GiB); a larger run is refused before anything is allocated.
    hinges : rotational springs of K whose moment follows a hysteresis law
        (``docs/theory/nonlinear_hinges.md``; in the plane: §7 of
        ``docs/theory/planar_friction.md``).
    """
    inp = chk.run_inputs(M, C, K, sliders, dt=dt, n_steps=n_steps, ground_accel=ground_accel,
                         influence=influence, force=force, vertical_accel=vertical_accel,
                         vertical_influence=vertical_influence, g=g, u0=u0, v0=v0,
                         chunk_steps=chunk_steps, save_every=save_every, method=method,
                         hinges=hinges, progress=progress)
    hinges = inp.hinges
    bas = choose_basis(basis, inp.M, inp.K, sliders, inp.influences, rv=inp.rv, F=inp.F,
                       hinges=hinges)
    m = sliders.count
    columns = 4 * m + (hinges.count if hinges.nonlinear else 0) if inp.planar else (
        m + hinges.count)
    check_memory(inp.n_steps, inp.save_every, inp.chunk, bas.size, columns, max_memory)
    common = dict(dt=inp.dt, n_steps=inp.n_steps, ag=inp.ag, av=inp.av, rv=inp.rv, g=inp.g,
                  backend=backend, throw=throw, progress=progress, basis=bas,
                  save_every=inp.save_every, chunk=inp.chunk, on_chunk=on_chunk, hinges=hinges)
    if inp.planar:
        return run_planar_scheme(inp.M, inp.C, inp.K, sliders, influence=inp.influence,
                                 max_events=500_000 if max_events is None else max_events,
                                 track_energy=track_energy, **common)
    return run_line(inp.M, inp.C, inp.K, sliders, r=inp.influence, F=inp.F, q_u0=inp.u0,
                    q_v0=inp.v0, track_energy=track_energy, method=method,
                    max_events=200_000 if max_events is None else max_events, **common)
