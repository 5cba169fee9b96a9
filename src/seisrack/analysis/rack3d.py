"""Earthquake time history of a 3D rack with pallets sliding in the plane: :func:`run_rack_3d`.

Glue from a compiled :class:`~seisrack.model.frame_model3d.FrameModel3D` and a
:class:`~seisrack.motion.components.GroundMotion3D` (down-aisle, cross-aisle and vertical
components) to the planar stick–slip engine (:func:`seisrack.dynamics.planar.simulate_planar`),
and back to what a rack engineer reads: each pallet's peak sliding down-aisle, cross-aisle and
in magnitude, the pallets that fall into the aisles and when, the down-aisle impacts, and the
peak displacement of every beam level in both directions. Peaks, falls and impacts are taken
over every step, whatever ``save_every`` keeps.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from seisrack.analysis.pallet_contacts import ContactTracker, Fall, Impact, describe_contact
from seisrack.analysis.rack import _resample, analysis_grid
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.engine import single_blas_thread
from seisrack.dynamics.planar import (
    PlanarChunk,
    PlanarHistory,
    PlanarSliders,
    planar_basis,
    simulate_planar,
)
from seisrack.errors import InputError
from seisrack.model.frame_model3d import FrameModel3D
from seisrack.motion.components import GroundMotion3D

_BASES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class RackResponse3D:
    """Result of :func:`run_rack_3d` (SI units; pallet indices 0-based here, 1-based in
    summaries; ``pallet_level`` and ``pallet_bay`` are 1-based, as in the TOML).

    history: the engine's kept samples; t: their times [s]. ground: (n_t, 3) ground
    acceleration x, z, vertical at those times [m/s²].
    peak_sliding: (m, 3) [m] peak |sliding| down-aisle (x), cross-aisle (z) and in magnitude,
    over every step (a pallet's values after its fall time are not physical: the model keeps
    it on its beams); residual: (m, 2) [m] sliding at the last step.
    level_peak: (n_level, 2) [m] peak mean displacement of each beam level, x and z.
    falls, impacts: first occurrences (see :mod:`seisrack.analysis.pallet_contacts`).
    """

    history: PlanarHistory
    t: np.ndarray
    ground: np.ndarray
    motion_name: str
    angle_deg: float
    dt: float
    pallet_level: np.ndarray
    pallet_bay: np.ndarray
    peak_sliding: np.ndarray
    residual: np.ndarray
    level_peak: np.ndarray
    level_y: np.ndarray
    fall_front: np.ndarray
    fall_rear: np.ndarray
    falls: list[Fall]
    impacts: list[Impact]

    @property
    def n_pallets(self) -> int:
        return int(self.peak_sliding.shape[0])

    @property
    def sliding(self) -> np.ndarray:
        """(n_t, m, 2) [m] kept sliding histories (x, z)."""
        return self.history.sliding

    def pallet_peaks(self) -> list[dict[str, Any]]:
        out = []
        fall_at = {f.pallet: f for f in self.falls}
        for p in range(self.n_pallets):
            f = fall_at.get(p)
            out.append({
                "pallet": p + 1, "level": int(self.pallet_level[p]),
                "bay": int(self.pallet_bay[p]),
                "peak_sliding_down_aisle_m": float(self.peak_sliding[p, 0]),
                "peak_sliding_cross_aisle_m": float(self.peak_sliding[p, 1]),
                "peak_sliding_m": float(self.peak_sliding[p, 2]),
                "residual_down_aisle_m": float(self.residual[p, 0]),
                "residual_cross_aisle_m": float(self.residual[p, 1]),
                "fall_limit_front_m": _num(self.fall_front[p]),
                "fall_limit_rear_m": _num(self.fall_rear[p]),
                "falls": None if f is None else {"time_s": f.time_s, "side": f.side},
            })
        return out

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary: counts, falls by level, peaks in both directions, impacts."""
        levels = sorted({int(v) for v in self.pallet_level})
        by_level = {str(lv): sum(1 for f in self.falls if self.pallet_level[f.pallet] == lv)
                    for lv in levels}
        checked = int(np.sum(np.isfinite(self.fall_front)))
        ev = self.history.events
        return {
            "dimension": "3D",
            "record": self.motion_name,
            "angle_deg": self.angle_deg,
            "dt_s": self.dt,
            "duration_s": float(self.t[-1]) if self.t.size else 0.0,
            "status": self.history.status,
            "n_pallets": self.n_pallets,
            "pallets_checked_for_falls": checked,
            "pallets_falling": len(self.falls),
            "falls_by_level": by_level,
            "falls": [{"pallet": f.pallet + 1, "level": int(self.pallet_level[f.pallet]),
                       "bay": int(self.pallet_bay[f.pallet]), "time_s": f.time_s,
                       "side": f.side} for f in self.falls],
            "impacts": [{"contact": describe_contact(i), "time_s": i.time_s,
                         "closing_speed_m_s": i.speed_m_s} for i in self.impacts],
            "peak_sliding_down_aisle_m": _max(self.peak_sliding[:, 0]),
            "peak_sliding_cross_aisle_m": _max(self.peak_sliding[:, 1]),
            "peak_sliding_m": _max(self.peak_sliding[:, 2]),
            "level_peak_displacement_m": [
                {"level": i + 1, "height_m": float(self.level_y[i]),
                 "down_aisle": float(self.level_peak[i, 0]),
                 "cross_aisle": float(self.level_peak[i, 1])}
                for i in range(self.level_peak.shape[0])],
            "events": {"slip": sum(e.kind == "slip" for e in ev),
                       "stick": sum(e.kind == "stick" for e in ev),
                       "turn": sum(e.kind == "reverse" for e in ev)},
            "basis": self.history.basis,
            "notes": ([] if not self.falls else [
                "the model keeps a fallen pallet on its beams: its peaks and residual after "
                "the fall time are not physical"]) + ([] if not self.impacts else [
                "impacts are first contacts; the pallets are not stopped by them in the model"]),
            "pallets": self.pallet_peaks(),
        }


def _num(x: float) -> float | None:
    return None if not math.isfinite(float(x)) else float(x)


def _max(a: np.ndarray) -> float:
    return float(np.max(a)) if a.size else 0.0


def _level_operator(model: FrameModel3D, phi: np.ndarray, dofs: tuple) -> np.ndarray:
    return np.array([phi[np.asarray(d), :].mean(axis=0) if len(d) else np.zeros(phi.shape[1])
                     for d in dofs])


@single_blas_thread
def run_rack_3d(
    model: FrameModel3D,
    motion: GroundMotion3D,
    *,
    dt: float | None = None,
    free_vibration: float = 0.0,
    backend: str = "auto",
    basis: str | Basis = "auto",
    save_every: int | None = 1,
    progress: Callable[[int], None] | None = None,
    throw: bool = True,
    max_memory: float | None = None,
) -> RackResponse3D:
    """Time history of the 3D rack ``model`` under ``motion``.

    dt: analysis step [s], a whole divisor of ``motion.dt`` (default: the largest ≤ 5 ms).
    free_vibration: seconds of rest appended after the record. basis: "auto" (a load-dependent
    Ritz basis above 50 DOFs), "full", "reduced" or a Basis. Other arguments as
    :func:`seisrack.analysis.run_rack`.
    """
    if not getattr(model, "is_3d", False):
        raise InputError("model", type(model).__name__, "a compiled 3D rack (geometry.depth)",
                         hint="Use seisrack.analysis.run_rack for a 2D rack")
    if not isinstance(motion, GroundMotion3D):
        raise InputError("motion", type(motion).__name__,
                         "a GroundMotion3D (seisrack.motion.components.combine)")
    if not (isinstance(free_vibration, int | float) and math.isfinite(free_vibration)
            and free_vibration >= 0):
        raise InputError("free_vibration", free_vibration, "a duration >= 0 s")
    k = analysis_grid(motion, dt)  # type: ignore[arg-type]
    mot = motion.padded(int(round(free_vibration / motion.dt)))
    step = mot.dt / k
    ax, az = _resample(mot.x, k), _resample(mot.z, k)
    av = None if mot.v is None else _resample(mot.v, k)
    sliders = PlanarSliders(model.pallet_dof_x, model.pallet_dof_z, model.pallet_mass,
                            model.pallet_mu_static, model.pallet_mu_dynamic)
    M, C, K = model.M_sparse, model.C_sparse, model.K_sparse
    if isinstance(basis, str) and basis != "full":
        key = (basis, av is not None)
        cache = _BASES.setdefault(model, {})
        if key not in cache:
            loads = [M @ model.r_x, M @ model.r_z] + ([M @ model.r_y] if av is not None else [])
            cache[key] = planar_basis(M, K, sliders, np.column_stack(loads), basis)
        basis = cache[key]
    lay = model.layout
    tracker = ContactTracker(lay, sliders.count)
    n_lev = len(model.level_dofs_x)
    level_peak = np.zeros((n_lev, 2))
    ops: list[np.ndarray] = []

    def on_chunk(ch: PlanarChunk) -> None:
        tracker.update(ch.t, ch.sliding, ch.velocity)
        for c in range(2):
            if n_lev:
                np.maximum(level_peak[:, c], np.abs(ch.q @ ops[c].T).max(axis=0),
                           out=level_peak[:, c])

    if not isinstance(basis, Basis):  # "full": built by the engine; operators need phi first
        basis = planar_basis(M, K, sliders, np.ones((M.shape[0], 1)), basis)
    ops[:] = [_level_operator(model, basis.phi, model.level_dofs_x),
              _level_operator(model, basis.phi, model.level_dofs_z)]
    hist = simulate_planar(
        M, C, K, sliders, dt=step, ground_x=ax, ground_z=az, influence_x=model.r_x,
        influence_z=model.r_z, vertical_accel=av,
        vertical_influence=None if av is None else model.r_y, g=model.g, basis=basis,
        backend=backend, save_every=save_every, on_chunk=on_chunk, progress=progress,
        throw=throw, max_memory=max_memory)
    idx = hist.sample_index
    ground = np.column_stack([ax[idx], az[idx], np.zeros(idx.size) if av is None else av[idx]])
    return RackResponse3D(
        history=hist, t=hist.t, ground=ground, motion_name=motion.name,
        angle_deg=motion.angle_deg, dt=step, pallet_level=np.asarray(model.pallet_level),
        pallet_bay=np.asarray(model.pallet_bay), peak_sliding=tracker.peak.copy(),
        residual=hist.sliding[-1].copy() if hist.sliding.shape[1] else np.zeros((0, 2)),
        level_peak=level_peak, level_y=np.asarray(model.level_y),
        fall_front=lay.fall_front.copy(), fall_rear=lay.fall_rear.copy(), falls=tracker.falls(),
        impacts=tracker.impacts())
