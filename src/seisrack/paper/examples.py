"""Validation examples 2 and 3 of the paper's §III.B, as defined in issue #3.

The paper's figures are lost, so the definitions are those of issue #3 (g = 9.81 m/s², from rest,
10 s, displacements relative to the ground):

- Example 2: ground -k1- M1 -k2- M2, M3 resting on M2 (mu_s = mu_d = mu); M1 = M2 = 1000 kg,
  M3 = 500 kg, k1 = k2 = 2e5 N/m, no damping, P(t) = 8000 sin(2 pi 0.8 t) N on M1;
  mu in {1.0, 0.5, 0.3}.
- Example 3: M1 = 50 kg with k1 = 1.2e5 N/m and c1 = 250 N·s/m to the ground, M2 = 1000 kg
  resting on M1; a_g(t) = 0.3 g sin(2 pi 1.5 t); mu in {10, 0.5, 0.3, 0.1}.

:func:`run_validation` runs the production engine (``seisrack.dynamics.simulate``) and the
independent event-driven reference (:mod:`seisrack.dynamics.reference`) and compares them.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from seisrack.dynamics.reference import simulate_reference
from seisrack.dynamics.reference_result import ReferenceResult
from seisrack.errors import InputError

__all__ = [
    "ValidationExample",
    "example2",
    "example3",
    "examples",
    "run_reference",
    "run_validation",
    "summarize",
]

log = logging.getLogger(__name__)

G = 9.81  # m/s², issue #3
DURATION = 10.0  # s


@dataclass(frozen=True)
class ValidationExample:
    """A linear structure carrying one sliding mass, with its excitation.

    ``M, C, K``: (n, n) [kg, N·s/m, N/m]; ``influence``: (n,); ``slider_dof``/``slider_mass``
    [kg]; ``mu_values``: the friction coefficients studied (mu_s = mu_d);
    ``ground_accel_fn``: a_g(t) [m/s²] or None; ``force_fn``: P(t) -> (n,) [N] or None.
    """

    name: str
    dof_names: tuple[str, ...]
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    influence: np.ndarray
    slider_dof: int
    slider_mass: float
    mu_values: tuple[float, ...]
    ground_accel_fn: Callable[[float], float] | None
    force_fn: Callable[[float], np.ndarray] | None
    duration: float = DURATION
    g: float = G

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def time_grid(self, dt: float) -> np.ndarray:
        """(n_steps + 1,) [s] regular grid over the duration."""
        n_steps = int(round(self.duration / dt))
        return np.arange(n_steps + 1) * dt

    def ground_accel(self, dt: float) -> np.ndarray | None:
        """(n_steps + 1,) [m/s²] on the grid, or None."""
        if self.ground_accel_fn is None:
            return None
        return np.array([self.ground_accel_fn(t) for t in self.time_grid(dt)])

    def force(self, dt: float) -> np.ndarray | None:
        """(n_steps + 1, n_dof) [N] on the grid, or None."""
        if self.force_fn is None:
            return None
        return np.array([self.force_fn(t) for t in self.time_grid(dt)])


def example2() -> ValidationExample:
    """Issue #3 example 2: 2 structural DOFs + M3 sliding on M2, force on M1."""
    m1 = m2 = 1000.0
    k1 = k2 = 2.0e5
    amp, f = 8000.0, 0.8
    w = 2.0 * math.pi * f

    def force_fn(t: float) -> np.ndarray:
        return np.array([amp * math.sin(w * t), 0.0])

    return ValidationExample(
        name="example2",
        dof_names=("M1", "M2"),
        M=np.diag([m1, m2]),
        C=np.zeros((2, 2)),
        K=np.array([[k1 + k2, -k2], [-k2, k2]]),
        influence=np.ones(2),
        slider_dof=1,
        slider_mass=500.0,
        mu_values=(1.0, 0.5, 0.3),
        ground_accel_fn=None,
        force_fn=force_fn,
    )


def example3() -> ValidationExample:
    """Issue #3 example 3: M1 on spring + dashpot, M2 sliding on M1, ground acceleration."""
    amp, f = 0.3 * G, 1.5
    w = 2.0 * math.pi * f

    def ag_fn(t: float) -> float:
        return amp * math.sin(w * t)

    return ValidationExample(
        name="example3",
        dof_names=("M1",),
        M=np.array([[50.0]]),
        C=np.array([[250.0]]),
        K=np.array([[1.2e5]]),
        influence=np.ones(1),
        slider_dof=0,
        slider_mass=1000.0,
        mu_values=(10.0, 0.5, 0.3, 0.1),
        ground_accel_fn=ag_fn,
        force_fn=None,
    )


def examples() -> dict[str, ValidationExample]:
    """Both examples keyed by name."""
    return {"example2": example2(), "example3": example3()}


def run_reference(ex: ValidationExample, mu: float, save_dt: float = 1e-3) -> ReferenceResult:
    """The event-driven reference solution of one example at one mu."""
    return simulate_reference(
        ex.M,
        ex.C,
        ex.K,
        [ex.slider_dof],
        [ex.slider_mass],
        mu,
        mu,
        duration=ex.duration,
        ground_accel=ex.ground_accel_fn,
        influence=ex.influence,
        force=ex.force_fn,
        g=ex.g,
        save_dt=save_dt,
    )


def _count_phases(events: Any, slider: int = 0) -> int:
    return sum(
        1
        for e in events
        if getattr(e, "slider", 0) == slider and getattr(e, "kind", "") in ("slip", "reverse")
    )


def summarize(u: np.ndarray, sliding: np.ndarray, events: Any) -> dict[str, Any]:
    """Issue #3 figures from (n_t, n_dof) displacements, (n_t,) sliding [m] and events."""
    return {
        "max_abs_displacement_m": [float(x) for x in np.max(np.abs(u), axis=0)],
        "max_abs_sliding_m": float(np.max(np.abs(sliding))),
        "sliding_phases": _count_phases(events),
        "final_sliding_m": float(sliding[-1]),
    }


_ZERO = 1e-12  # [m] below this a peak is round-off (a case that never slides)


def _rel(a: float, b: float) -> float:
    """Relative difference of ``a`` to ``b``; 0 when both are round-off around zero."""
    if abs(a) < _ZERO and abs(b) < _ZERO:
        return 0.0
    return abs(a - b) / max(abs(b), _ZERO)


def _resolve_engine(engine: Any) -> Callable[..., Any] | None:
    if engine is None or callable(engine):
        return engine
    if engine != "auto":
        raise InputError("engine", engine, '"auto", None or a callable like dynamics.simulate')
    try:
        from seisrack.dynamics import simulate  # type: ignore[attr-defined]
    except ImportError:
        log.warning("seisrack.dynamics.simulate is not available; reporting the reference only")
        return None
    return simulate


def run_engine(simulate: Callable[..., Any], ex: ValidationExample, mu: float, dt: float) -> Any:
    """Run the production engine (API of docs/dev/interfaces.md) on one example."""
    from seisrack.dynamics import Sliders  # type: ignore[attr-defined]

    t = ex.time_grid(dt)
    sl = Sliders(dof=[ex.slider_dof], mass=[ex.slider_mass], mu_static=[mu], mu_dynamic=[mu])
    return simulate(
        ex.M,
        ex.C,
        ex.K,
        sl,
        dt=dt,
        n_steps=t.size - 1,
        ground_accel=ex.ground_accel(dt),
        influence=ex.influence,
        force=ex.force(dt),
        g=ex.g,
    )


def run_validation(
    dt: float = 1e-3,
    engine: Any = "auto",
    *,
    which: tuple[str, ...] = ("example2", "example3"),
    keep_histories: bool = False,
) -> dict[str, dict[str, dict[str, Any]]]:
    """Run examples 2 and 3 with the engine and the reference; compare them.

    Returns ``{example: {str(mu): entry}}``; each entry holds the engine's
    ``max_abs_displacement_m`` (per structural DOF), ``max_abs_sliding_m``, ``sliding_phases``,
    ``final_sliding_m`` (or the reference's when no engine is available, ``source`` says which),
    plus ``reference`` (the same four from the reference solver) and ``relative_difference``.
    With ``keep_histories`` the entry also carries ``_reference`` / ``_engine`` result objects.
    """
    if not (math.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite number > 0")
    sim = _resolve_engine(engine)
    exs = examples()
    out: dict[str, dict[str, dict[str, Any]]] = {}
    for name in which:
        ex = exs[name]
        out[name] = {}
        for mu in ex.mu_values:
            ref = run_reference(ex, mu, save_dt=dt)
            ref_sum = summarize(ref.u, ref.sliding[:, 0], ref.events)
            entry: dict[str, Any]
            if sim is None:
                entry = dict(ref_sum, source="reference")
                eng = None
            else:
                eng = run_engine(sim, ex, mu, dt)
                entry = dict(summarize(eng.u, eng.sliding[:, 0], eng.events), source="engine")
                entry["status"] = getattr(eng, "status", "ok")
            entry["reference"] = ref_sum
            entry["reference_phases_integrated"] = ref.n_phases
            entry["relative_difference"] = {
                "max_abs_displacement": [
                    _rel(a, b)
                    for a, b in zip(
                        entry["max_abs_displacement_m"],
                        ref_sum["max_abs_displacement_m"],
                        strict=True,
                    )
                ],
                "max_abs_sliding": _rel(entry["max_abs_sliding_m"], ref_sum["max_abs_sliding_m"]),
                "sliding_phases_equal": entry["sliding_phases"] == ref_sum["sliding_phases"],
            }
            if keep_histories:
                entry["_reference"] = ref
                entry["_engine"] = eng
            out[name][f"{float(mu):.1f}"] = entry
    return out
