"""Results of :func:`seisrack.dynamics.local.simulate_local`."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from seisrack.dynamics.local.basis import LocalBasis
from seisrack.dynamics.results import Event


class LocalChunk(NamedTuple):
    """Full-rate results of a chunk of steps (views: copy to keep). t (k,); q, v (k, size)
    basis coordinates (empty when not kept); sliding, velocity, friction (k, m, n_dir) [m,
    m/s, N]; stuck (k, m); energy (k, 5) [J]: input, kinetic, strain, damping, friction;
    a (k, size) the accelerations of the coordinates (central differences of v: see
    :func:`central_accelerations`). Consecutive chunks share
    their boundary sample."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    sliding: np.ndarray
    velocity: np.ndarray
    friction: np.ndarray
    stuck: np.ndarray
    energy: np.ndarray
    a: np.ndarray


def central_accelerations(v: np.ndarray, v_prev: np.ndarray | None, h: float,
                          out: np.ndarray) -> np.ndarray:
    """The accelerations reported at a chunk's samples, ``(v[n+1] - v[n-1]) / 2h`` (one-sided
    at the run's first and the chunk's last sample; ``v_prev`` the velocity before the
    chunk's first sample, None at the start): the trapezoidal rule's own end accelerations
    carry the period-2h residue of the stiff directions (as
    ``seisrack.analysis.rack.smoothed_acceleration`` on the default engine)."""
    k = v.shape[0]
    if k >= 3:
        out[1:-1] = (v[2:] - v[:-2]) / (2.0 * h)
    out[0] = (v[1] - v_prev) / (2.0 * h) if v_prev is not None else (v[1] - v[0]) / h
    out[-1] = (v[-1] - v[-2]) / h
    return out


@dataclass(frozen=True)
class LocalHistory:
    """Result of :func:`~seisrack.dynamics.local.simulate_local` (kept samples
    ``sample_index``, times ``t``).

    q, v, a: (n_t, size) basis coordinates (``u = V q``; (n_t, 0) when not kept), their
    velocities and accelerations (central differences of v); sliding,
    velocity, friction: (n_t, m, n_dir) pallet sliding [m], velocity relative to its
    supports [m/s] and the friction force on it at the sample [N]; normal (n_t, m) [N];
    stuck (n_t, m); energy: cumulative terms (n_t,) [J] "input", "kinetic", "strain",
    "damping", "friction", "hysteresis". basis: the basis' description (sizes, measured
    error); work: the solver's effort (steps, Newton iterations, factorisations, local
    solves of pallets with events or sliding, line-search evaluations).
    """

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    sliding: np.ndarray
    velocity: np.ndarray
    friction: np.ndarray
    normal: np.ndarray
    stuck: np.ndarray
    events: list[Event]
    sample_index: np.ndarray
    energy: dict[str, np.ndarray]
    local_basis: LocalBasis
    status: str = "ok"
    backend: str = "python"
    basis: dict = field(default_factory=dict)
    work: dict = field(default_factory=dict)

    def dof_response(self, dofs, kind: str = "u") -> np.ndarray:  # noqa: ANN001
        """(n_t, len(dofs)) displacement ("u") or velocity ("v") of structural DOFs."""
        src = {"u": self.q, "v": self.v}[kind]
        if src.shape[1] == 0:
            raise ValueError("the basis coordinates were not kept (keep_coordinates=False)")
        return src @ self.local_basis.rows(np.atleast_1d(dofs)).T

    def sliding_phases(self, slider: int | None = None) -> int:
        return sum(1 for e in self.events if e.kind in ("slip", "reverse")
                   and (slider is None or e.slider == slider))

    def energy_error(self) -> float:
        """Largest |input − (Δkinetic + Δstrain + damping + friction + hysteresis)| over the
        kept samples, relative to the largest input."""
        e = self.energy
        rhs = (e["kinetic"] - e["kinetic"][0]) + (e["strain"] - e["strain"][0]) \
            + e["damping"] + e["friction"] + e["hysteresis"]
        scale = max(float(np.max(np.abs(e["input"]))), 1e-300)
        return float(np.max(np.abs(e["input"] - rhs)) / scale)
