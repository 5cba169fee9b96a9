"""The stick–slip engine's one entry point, :func:`simulate`: check the inputs, then run the scheme
the sliders call for.

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
from seisrack.dynamics._run_line import run_line
from seisrack.dynamics._setup import (  # noqa: F401  (constants re-exported: the engine's API)
    AUTO_FULL_MAX_DOF,
    DEFAULT_MAX_MEMORY,
    HINGE_RITZ_BLOCKS,
    HINGE_RITZ_TOL,
)
from seisrack.dynamics.basis import Basis, full_basis
from seisrack.dynamics.hinges import Hinges, no_hinges
from seisrack.dynamics.planar import run_planar_scheme
from seisrack.dynamics.results import TimeHistory
from seisrack.dynamics.sliders import PlanarSliders, Sliders
from seisrack.errors import InputError

#: steps integrated per kernel call (bounded working memory; the state carries over exactly)
DEFAULT_CHUNK = 20_000
#: what the planar scheme does not support (argument -> what it is)
_PLANAR_UNSUPPORTED = {
    "force": "applied forces",
    "u0": "an initial displacement",
    "v0": "an initial velocity",
    "method": "the exact modal propagators",
}
#: what each scheme supports beyond the ground motion, for the documentation and the refusals
SCHEME_FEATURES = {
    "line": ("ground motion", "vertical motion", "applied forces", "initial state",
             "exact propagators", "Newmark", "nonlinear hinges", "velocity-dependent friction",
             "energy balance", "reduced basis", "chunks"),
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
    M = chk.square("M", M, None)
    n = M.shape[0]
    C = chk.square("C", C, n)
    K = chk.square("K", K, n)
    chk.check_symmetric("M", M)
    chk.check_symmetric("K", K)
    planar = isinstance(sliders, PlanarSliders)
    if not (planar or isinstance(sliders, Sliders)):
        raise InputError("sliders", type(sliders).__name__,
                         "seisrack.dynamics.Sliders or seisrack.dynamics.PlanarSliders")
    if not (isinstance(dt, int | float) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    if not (np.isfinite(g) and g > 0):
        raise InputError("g", g, "a finite gravity > 0 m/s²")
    sliders.check_dofs(n)
    lengths = [np.shape(x)[0] for x in (ground_accel, force, vertical_accel)
               if x is not None and np.ndim(x) >= 1]
    if n_steps is None:
        if not lengths:
            raise InputError("n_steps", None, "a number of steps when no excitation is given")
        n_steps = lengths[0] - 1
    if isinstance(n_steps, bool) or int(n_steps) != n_steps or n_steps < 1:
        raise InputError("n_steps", n_steps, "an integer >= 1")
    n_steps = int(n_steps)
    n_t = n_steps + 1
    av = None if vertical_accel is None else chk.series("vertical_accel", vertical_accel, (n_t,))
    rv = None
    if av is not None and vertical_influence is not None:
        rv = chk.series("vertical_influence", vertical_influence, (n,))
    if chunk_steps is not None:
        chk.positive_int("chunk_steps", chunk_steps)
    if save_every is not None:
        save_every = chk.positive_int("save_every", save_every)
    if method not in ("auto", "exact", "newmark"):
        raise InputError("method", method, '"auto", "exact" or "newmark"')
    if hinges is None:
        hinges = no_hinges()
    if not isinstance(hinges, Hinges):
        raise InputError("hinges", type(hinges).__name__, "a seisrack.dynamics.hinges.Hinges")
    hinges.check(n)
    common = dict(dt=float(dt), n_steps=n_steps, av=av, rv=rv, g=float(g), backend=backend,
                  throw=throw, progress=progress, basis=basis, save_every=save_every,
                  on_chunk=on_chunk, max_memory=max_memory)
    if planar:
        given = {"force": force, "u0": u0, "v0": v0,
                 "method": method if method == "exact" else None}
        for name, value in given.items():
            if value is not None:
                raise InputError(name, value if name == "method" else "given",
                                 f"not given for sliders in the plane: the planar scheme has "
                                 f"no {_PLANAR_UNSUPPORTED[name]}")
        ag, infl = _planar_ground(ground_accel, influence, n, n_t)
        chunk = min(int(chunk_steps or (1000 if progress is not None else 5000)), n_steps)
        return run_planar_scheme(M, C, K, sliders, ag=ag, influence=infl, chunk=chunk,
                                 max_events=500_000 if max_events is None else max_events,
                                 hinges=hinges, track_energy=track_energy, **common)
    ag = np.zeros(n_t) if ground_accel is None else chk.series(
        "ground_accel", _one_column(ground_accel), (n_t,))
    r = np.ones(n) if influence is None else chk.series("influence", _one_column(influence),
                                                        (n,))
    F = None if force is None else chk.series("force", force, (n_t, n))
    q_u0 = np.zeros(n) if u0 is None else chk.series("u0", u0, (n,))
    q_v0 = np.zeros(n) if v0 is None else chk.series("v0", v0, (n,))
    chunk = min(int(chunk_steps or (2000 if progress is not None else DEFAULT_CHUNK)), n_steps)
    return run_line(M, C, K, sliders, ag=ag, r=r, F=F, q_u0=q_u0, q_v0=q_v0,
                    track_energy=track_energy, chunk=chunk, method=method,
                    max_events=200_000 if max_events is None else max_events, hinges=hinges,
                    **common)


def _one_column(a):  # noqa: ANN001, ANN202
    """A (k, 1) array as (k,): sliders on a line take one ground component."""
    a = np.asarray(a)
    return a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a


def _planar_ground(ground_accel, influence, n: int, n_t: int  # noqa: ANN001
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(n_t, 2) ground accelerations x, z and (n, 2) influence vectors of planar sliders."""
    if ground_accel is None:
        return np.zeros((n_t, 2)), np.zeros((n, 2))
    a = np.asarray(ground_accel, dtype=float)
    if a.ndim == 1:
        a = np.column_stack([a, np.zeros_like(a)])
    a = chk.series("ground_accel", a, (n_t, 2))
    if influence is None:
        raise InputError("influence", None, "(n, 2) influence vectors of the x and z ground "
                         "components for sliders in the plane")
    r = np.asarray(influence, dtype=float)
    if r.ndim == 1:
        r = np.column_stack([r, np.zeros_like(r)])
    return a, chk.series("influence", r, (n, 2))
