"""Result type of the event-driven reference solver (:mod:`seisrack.dynamics.reference`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["ReferenceEvent", "ReferencePhase", "ReferenceResult"]


@dataclass(frozen=True)
class ReferenceEvent:
    """A contact transition of one slider: kind in {"slip", "stick", "reverse"}."""

    time_s: float
    slider: int
    kind: str


@dataclass(frozen=True)
class ReferencePhase:
    """A time interval of constant contact state; ``direction[k]`` is 0 when slider k is stuck."""

    t_start: float
    t_end: float
    direction: tuple[int, ...]


@dataclass(frozen=True)
class ReferenceResult:
    """Reference time history sampled on a regular grid (all motion relative to the ground).

    Attributes:
        t: (n_t,) [s]
        u, v, a: (n_t, n_dof) structural displacement [m], velocity [m/s], acceleration [m/s²]
        slider_u, slider_v: (n_t, m) slider displacement [m] / velocity [m/s]
        sliding: (n_t, m) slider_u minus the support node displacement [m]
        friction: (n_t, m) horizontal force of the structure ON each slider [N]
        stuck: (n_t, m) bool
        events: transitions in time order
        phases: the constant-contact phases integrated
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    slider_u: np.ndarray
    slider_v: np.ndarray
    sliding: np.ndarray
    friction: np.ndarray
    stuck: np.ndarray
    events: list[ReferenceEvent] = field(default_factory=list)
    phases: list[ReferencePhase] = field(default_factory=list)
    status: str = "ok"

    @property
    def n_phases(self) -> int:
        """Number of constant-contact phases integrated."""
        return len(self.phases)

    def sliding_phases(self, slider: int = 0) -> int:
        """Sliding phases of one slider: each slip or reversal starts one."""
        return sum(1 for e in self.events if e.slider == slider and e.kind in ("slip", "reverse"))

    def event_times(self, slider: int = 0, kind: str | None = None) -> np.ndarray:
        """(n_events,) [s] times of one slider's events, optionally of one kind."""
        ev = [e for e in self.events if e.slider == slider]
        return np.array([e.time_s for e in ev if kind is None or e.kind == kind])
