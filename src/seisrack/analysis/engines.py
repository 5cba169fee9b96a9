"""One run of a prepared rack on its engine, :func:`simulate_rack`: the default engine
(:func:`seisrack.dynamics.simulate`, the line or the planar scheme) or the local engine (issue 22,
``docs/theory/local_engine.md``, ``run_rack(model, motion, engine="local")``), each returned as
the :class:`~seisrack.dynamics.results.TimeHistory` the rest of the path reads (peaks, falls,
writer, report). The local engine's chunks are handed on as the usual
:class:`~seisrack.dynamics._chunk.Chunk`; its reported accelerations are the central
differences of the velocities, ``(v[n+1] - v[n-1]) / 2h`` (the trapezoidal rule's own end
accelerations carry the period-2h residue of the stiff directions:
:func:`seisrack.dynamics.local.result.central_accelerations`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from seisrack.analysis.prepare import RIGID_MU, PreparedRun
from seisrack.dynamics import PlanarSliders, Sliders
from seisrack.dynamics._chunk import Chunk
from seisrack.dynamics.engine import simulate
from seisrack.dynamics.local.sliders import LocalSliders
from seisrack.dynamics.results import TimeHistory
from seisrack.errors import InputError
from seisrack.model.frame_model import FrameModel


def simulate_rack(model: FrameModel, prepared: PreparedRun, ag: np.ndarray,
                  av: np.ndarray | None, h: float, *, method: str = "auto",
                  backend: str = "auto", throw: bool = True,
                  on_chunk: Callable[[Chunk], None] | None = None,
                  progress: Callable[[int], None] | None = None, save_every: int | None = 1,
                  track_energy: bool = True, max_memory: float | None = None,
                  companion: Callable[[Chunk], None] | None = None) -> TimeHistory:
    """The run of ``model`` on the engine it was prepared for: ``ag`` (n_t, n_dir) [m/s²] the
    horizontal ground accelerations on the analysis grid (step ``h``), ``av`` the vertical one
    or None. ``companion``: the ``on_chunk`` of a second run with every pallet rigidly held
    (friction :data:`~seisrack.analysis.prepare.RIGID_MU`, peaks only, the main run's
    method), made when the rack carries pallets. Returns the main run's history."""
    kw = dict(max_memory=max_memory, throw=throw, backend=backend)
    rigid = companion is not None and model.n_pallets > 0
    if prepared.engine == "local":
        hist = simulate_rack_local(model, prepared, ag, av, h, on_chunk=on_chunk,
                                   progress=progress, save_every=save_every, **kw)
        if rigid:
            simulate_rack_local(model, prepared, ag, av, h, mu=RIGID_MU, on_chunk=companion,
                                save_every=None, **kw)
        return hist
    hist = simulate_rack_default(model, prepared, ag, av, h, on_chunk=on_chunk,
                                 progress=progress, save_every=save_every, method=method,
                                 track_energy=track_energy, **kw)
    if rigid:  # the main run's method, no energy
        simulate_rack_default(model, prepared, ag, av, h, mu=RIGID_MU, on_chunk=companion,
                              save_every=None, track_energy=False,
                              method="exact" if hist.method == "exact" else method, **kw)
    return hist


def run_sliders(prepared: PreparedRun, model: FrameModel, mu: float | None = None
                ) -> Sliders | PlanarSliders | LocalSliders:
    """The prepared pallets with the run's friction: ``model``'s (a study's runs differ in
    their friction only), or ``mu`` for every coefficient (the rigid companion, Coulomb)."""
    kw = dict(mu_static=model.pallet_mu_static if mu is None else mu,
              mu_dynamic=model.pallet_mu_dynamic if mu is None else mu)
    if isinstance(prepared.sliders, Sliders):
        kw["friction_rate"] = model.pallet_friction_rate if mu is None else 0.0
    return replace(prepared.sliders, **kw)


def simulate_rack_default(model: FrameModel, prepared: PreparedRun, ag: np.ndarray,
                          av: np.ndarray | None, h: float, *, mu: float | None = None,
                          on_chunk: Callable[[Chunk], None] | None = None,
                          progress: Callable[[int], None] | None = None,
                          save_every: int | None = 1, track_energy: bool = True,
                          method: str = "auto", max_memory: float | None = None,
                          throw: bool = True, backend: str = "auto") -> TimeHistory:
    """One run of the default engine (:func:`seisrack.dynamics.simulate`) on ``model``, its
    pallets' friction ``mu`` as in :func:`run_sliders`; arguments as :func:`simulate_rack`."""
    sliders = run_sliders(prepared, model, mu)
    try:
        return simulate(
            model.M_sparse, model.C_sparse, model.K_sparse, sliders,
            dt=h, ground_accel=ag, influence=np.column_stack(model.influence),
            vertical_accel=av, vertical_influence=None if av is None else model.r_y, g=model.g,
            basis=prepared.basis, hinges=prepared.hinges, track_energy=track_energy,
            method=method, on_chunk=on_chunk, progress=progress, save_every=save_every,
            max_memory=max_memory, throw=throw, backend=backend)
    except InputError as exc:
        if not exc.field.startswith("sliders.friction_rate["):
            raise
        j = int(exc.field.split("[")[1].rstrip("]"))
        raise InputError(
            f"friction_rate of pallet {j + 1} (level {model.pallet_level[j] + 1})",
            exc.value, exc.allowed, source=getattr(model, "title", None) or None,
            hint=exc.hint) from None


def simulate_rack_local(model: FrameModel, prepared: PreparedRun, ag: np.ndarray,
                        av: np.ndarray | None, h: float, *, mu: float | None = None,
                        on_chunk: Callable[[Chunk], None] | None = None,
                        progress: Callable[[int], None] | None = None,
                        save_every: int | None = 1, max_memory: float | None = None,
                        throw: bool = True, backend: str = "auto") -> TimeHistory:
    """One run of the local engine on ``model``, its pallets' friction ``mu`` as in
    :func:`run_sliders`; arguments as :func:`simulate_rack`."""
    from seisrack.dynamics.local.scheme import run_local_scheme

    sliders = run_sliders(prepared, model, mu)
    line = model.n_dir == 1
    sq = (lambda a: a[..., 0]) if line else (lambda a: a)  # noqa: E731

    def chunk_cb(ch) -> None:  # noqa: ANN001
        on_chunk(Chunk(ch.t, ch.q, ch.v, ch.a, sq(ch.friction), ch.stuck,
                       sliding=sq(ch.sliding), sliding_v=sq(ch.velocity)))

    hist = run_local_scheme(
        model.M_sparse, sliders, prepared.basis, dt=h, ag=ag,
        r=np.array(model.influence), av=av, rv=None if av is None else model.r_y, g=model.g,
        save_every=save_every, on_chunk=None if on_chunk is None else chunk_cb,
        progress=progress, max_memory=max_memory, throw=throw, backend=backend)
    d = np.asarray(model.pallet_dofs)
    return TimeHistory(
        t=hist.t, q=hist.q, qd=hist.v, qdd=hist.a, phi=prepared.basis.phi,
        slider_u=None, slider_v=None, sliding=sq(hist.sliding), friction=sq(hist.friction),
        normal=hist.normal, stuck=hist.stuck, slider_dof=d[:, 0, 0] if line else d[:, :, 0],
        events=hist.events, energy=hist.energy, status=hist.status, backend=hist.backend,
        method="local", basis=hist.basis, sample_index=hist.sample_index,
        sliding_v=sq(hist.velocity), work=hist.work)
