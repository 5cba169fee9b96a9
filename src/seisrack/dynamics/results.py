"""Result of a stick–slip time history (never written back onto specs or models)."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from seisrack.errors import SolverError

EVENT_KINDS = ("slip", "stick", "reverse")
#: status codes that the planar and local kernels share (each adds its own)
STEP_STATUS = {
    0: "ok",
    1: "event buffer overflow (increase max_events)",
    3: "non-finite response (check the input)",
    4: "the step matrix is not positive definite (check M, K, C)",
}


@dataclass(frozen=True)
class Event:
    """A contact transition: ``kind`` in {"slip", "stick", "reverse"} of slider ``slider``."""

    time_s: float
    slider: int
    kind: str


def run_status(status: int, names: dict[int, str], what: str, throw: bool, log) -> str:  # noqa: ANN001
    """The text of a kernel's final ``status`` (``names``); a stopped run raises
    :class:`~seisrack.errors.SolverError` ("``what`` stopped: ...") when ``throw``, else the
    message goes to ``log`` as a warning and the run returns what it has."""
    text = names.get(int(status), f"status {status}")
    if status != 0:
        msg = f"{what} stopped: {text}"
        if throw:
            raise SolverError(msg)
        log.warning(msg)
    return text


def recorded_events(time: np.ndarray, slider: np.ndarray, kind: np.ndarray, n: int,
                    *, by_time: bool = False) -> list[Event]:
    """The first ``n`` events of a kernel's buffers (``by_time``: sorted by time, stably, for a
    kernel that records them out of order)."""
    idx = np.argsort(time[:n], kind="stable") if by_time else slice(0, n)
    # whole columns to Python numbers at once (indexing element by element cost ~1 µs each)
    return [Event(t, s, EVENT_KINDS[k]) for t, s, k in zip(
        time[idx].tolist(), slider[idx].tolist(), kind[idx].tolist(), strict=True)]


@dataclass(frozen=True)
class TimeHistory:
    """Time history of a structure carrying sliders; all motion relative to the ground.

    t: (n_t,) [s]; u, v, a: (n_t, n_dof) [m, m/s, m/s²] structural DOFs, computed on first
    access from the modal coordinates ``q, qd, qdd`` and the mass-normalised basis ``phi``
    (``u = q @ phi.T``); use :meth:`dof_response` for a few DOFs only.
    Sliders moving along one line (:class:`~seisrack.dynamics.Sliders`) have one value per
    slider, sliders moving in the plane (:class:`~seisrack.dynamics.PlanarSliders`) a
    trailing axis of two components (x, z): the shapes below are ``(n_t, m)`` or
    ``(n_t, m, 2)``.
    slider_u, slider_v: slider displacement / velocity relative to the ground [m, m/s]
    (sliders on a line; None in the plane);
    sliding: [m] slider displacement relative to its support; sliding_v: [m/s] its velocity
    (stored by the planar scheme, else :attr:`sliding_velocity` computes it);
    friction: [N] horizontal force of the structure on each slider;
    normal: (n_t, m) [N] normal force; stuck: (n_t, m) bool;
    energy: cumulative arrays (n_t,) [J]: input, kinetic, strain, damping, friction, and with
    nonlinear hinges "hysteresis" (their dissipated work; "strain" is then the recoverable part);
    with the P-Δ of the current axial forces "p_delta" (the work of that force, which is not
    the gradient of a potential: :mod:`seisrack.dynamics.axial`); on the Newmark path of a line
    "algorithmic": what the L-stable composite steps after events take out of the stiff
    directions' residue (``dynamics/_kernel_stage.py``; zero on the trapezoidal steps);
    hinge_moment: (n_t, n_h) [N·m] and :attr:`hinge_rotation` of the nonlinear hinges.
    Here ``n_t`` counts the *kept* samples: with ``simulate(save_every=k)`` they are the steps
    listed in ``sample_index`` (every k-th and the last), at times ``t``. ``basis`` describes
    the basis ``phi`` (full, or reduced with its cut-off), see :mod:`seisrack.dynamics.basis`.
    ``work``: the kernel's work counters (the Newmark kernels': trial steps, Newton
    iterations, factorisations, location trials; empty for the exact kernel).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    phi: np.ndarray
    slider_u: np.ndarray | None
    slider_v: np.ndarray | None
    sliding: np.ndarray
    friction: np.ndarray
    normal: np.ndarray
    stuck: np.ndarray
    slider_dof: np.ndarray
    events: list[Event]
    energy: dict[str, np.ndarray] = field(default_factory=dict)
    status: str = "ok"
    backend: str = "python"
    n_substeps: int = 0
    method: str = "newmark"
    n_configurations: int = 0
    basis: dict = field(default_factory=dict)
    sample_index: np.ndarray | None = None
    hinge_moment: np.ndarray | None = None
    hinge_operator: np.ndarray | None = None
    hinge_rotation0: np.ndarray | None = None
    sliding_v: np.ndarray | None = None
    work: dict = field(default_factory=dict)

    @property
    def planar(self) -> bool:
        """True for sliders moving in the plane (a trailing axis of 2 components)."""
        return self.sliding.ndim == 3

    @property
    def hinge_rotation(self) -> np.ndarray | None:
        """(n_t, n_h) [rad] rotation of each nonlinear hinge, from its zero-moment state (the
        state the run starts from has ``hinge_rotation0``); None without hinges."""
        if self.hinge_operator is None:
            return None
        th0 = 0.0 if self.hinge_rotation0 is None else self.hinge_rotation0
        return self.q @ self.hinge_operator.T + th0

    @cached_property
    def u(self) -> np.ndarray:
        return self.q @ self.phi.T

    @cached_property
    def v(self) -> np.ndarray:
        return self.qd @ self.phi.T

    @cached_property
    def a(self) -> np.ndarray:
        return self.qdd @ self.phi.T

    def dof_response(self, dofs, kind: str = "u") -> np.ndarray:  # noqa: ANN001
        """(n_t, len(dofs)) displacement ("u"), velocity ("v") or acceleration ("a")."""
        src = {"u": self.q, "v": self.qd, "a": self.qdd}[kind]
        return src @ self.phi[np.atleast_1d(dofs), :].T

    @property
    def sliding_velocity(self) -> np.ndarray:
        """[m/s] slider velocity relative to its support, the shape of :attr:`sliding`."""
        if self.sliding_v is not None:
            return self.sliding_v
        support = np.zeros_like(self.slider_v)
        on = self.slider_dof >= 0
        support[:, on] = self.dof_response(self.slider_dof[on], "v")
        return self.slider_v - support

    def sliding_phases(self, slider: int | None = None) -> int:
        """Count sliding phases (a reversal starts a new phase), for one or all sliders."""
        return sum(
            1
            for e in self.events
            if e.kind in ("slip", "reverse") and (slider is None or e.slider == slider)
        )

    def energy_error(self) -> float:
        """Relative residual of input = kinetic + strain + damping + friction (from t = 0); nan
        when the run tracked no energy."""
        if not self.energy:
            return float("nan")
        e = self.energy
        lhs = e["input"]
        rhs = (
            (e["kinetic"] - e["kinetic"][0])
            + (e["strain"] - e["strain"][0])
            + e["damping"]
            + e["friction"]
            + e.get("hysteresis", 0.0)
            + e.get("p_delta", 0.0)
            + e.get("algorithmic", 0.0)
        )
        scale = max(
            float(np.max(np.abs(e["input"]))),
            float(np.max(e["kinetic"])),
            float(np.max(e["strain"])),
            float(np.max(np.abs(e["damping"]))) + float(np.max(np.abs(e["friction"])))
            + float(np.max(np.abs(e.get("hysteresis", 0.0))))
            + float(np.max(np.abs(e.get("p_delta", 0.0))))
            + float(np.max(np.abs(e.get("algorithmic", 0.0)))),
            1e-300,
        )
        return float(np.max(np.abs(lhs - rhs)) / scale)
