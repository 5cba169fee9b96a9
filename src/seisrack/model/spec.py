"""Rack specification: frozen dataclasses describing what the user wrote.

Specs are validated once, at the boundary (:mod:`seisrack.model.load`); code that receives a
:class:`RackSpec` may trust it. All quantities are SI (m, kg, Pa, N·m/rad).

Connection stiffnesses are floats: ``math.inf`` stands for a rigid joint and ``0.0`` for a
pinned one (the TOML words ``"rigid"`` and ``"pinned"`` map to these).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Literal

if TYPE_CHECKING:
    from seisrack.model.bracing import Bracing
    from seisrack.model.hinge_law import HingeLaw

#: Default pallet width along the beam [m] (EUR pallet, 1200 x 800 mm, long side across the beams).
DEFAULT_PALLET_WIDTH = 0.8
#: Default elements per member.
DEFAULT_SUBDIVISIONS = 4
#: Default gravity [m/s²].
DEFAULT_G = 9.81

RIGID = math.inf
PINNED = 0.0

DampingKind = Literal["stiffness", "rayleigh", "none"]
#: the stiffness in the a1 term of the damping: K_E (the elastic stiffness, OpenSees' betaKinit)
#: or K_E + K_G (with the geometric stiffness of P-Δ); the same without P-Δ
StiffnessTerm = Literal["elastic", "with_p_delta"]
STIFFNESS_TERMS = ("elastic", "with_p_delta")


@dataclass(frozen=True)
class Material:
    """Linear elastic material. ``E`` [Pa], ``density`` [kg/m³]; ``poisson`` [-] gives the
    shear modulus G = E / (2 (1 + ν)) of 3D racks (torsion)."""

    E: float
    density: float
    poisson: float = 0.3

    @property
    def G(self) -> float:  # noqa: N802
        return self.E / (2.0 * (1.0 + self.poisson))


@dataclass(frozen=True)
class Section:
    """A named cross-section: area ``A`` [m²], second moment of area ``I`` [m⁴] (in-plane).

    In a 3D rack ``I`` (alias ``Iz``) is bending in the down-aisle plane (x–y, about the
    cross-aisle axis: the 2D meaning), ``Iy`` bending in the other principal plane (cross-aisle
    for an upright, horizontal for a beam), ``J`` the St Venant torsion constant and ``Ip`` the
    polar moment of area for the torsional inertia (``None``: Iy + Iz). ``I`` is ``nan`` for a
    3D section that gives only ``A`` (bracing members, which are pin-ended bars).
    """

    name: str
    A: float
    I: float
    Iy: float | None = None
    J: float | None = None
    Ip: float | None = None


@dataclass(frozen=True)
class RowSpacer:
    """The row spacers of a back-to-back (double-entry) rack: pin-ended bars of section
    ``section`` joining the inner uprights of the two rows (rear upright of row 1, front
    upright of row 2) on every upright line, at ``heights`` [m] above the floor; ``length``
    [m] is the flue between the two inner frames (upright centrelines), the bars' length."""

    length: float
    section: str
    heights: tuple[float, ...]


@dataclass(frozen=True)
class Geometry:
    """Bays (spans, left to right) and levels (storey heights, bottom to top).

    ``beam_sections[k]`` is the section name of the beams of level ``k`` (0-based) and
    ``upright_sections[k]`` that of the uprights of storey ``k``. A 3D rack (``depth``) has one
    row of upright frames or, ``rows = 2``, two back to back joined by ``row_spacer``: row 1's
    frames at z = 0 and ``depth``, row 2's at z = depth + length and 2 depth + length.
    """

    bays: tuple[float, ...]
    levels: tuple[float, ...]
    beam_sections: tuple[str, ...]
    upright_sections: tuple[str, ...]
    subdivisions: int = DEFAULT_SUBDIVISIONS
    depth: float | None = None  # upright-frame depth [m]: a 3D rack when given
    rows: int = 1
    row_spacer: RowSpacer | None = None

    @property
    def frame_z(self) -> tuple[float, ...]:
        """z [m] of each upright frame (front to rear: 2·rows frames in 3D, (0.0,) in 2D)."""
        if self.depth is None:
            return (0.0,)
        d = float(self.depth)
        if self.rows == 1:
            return (0.0, d)
        assert self.row_spacer is not None  # the loader requires it with rows = 2
        s = float(self.row_spacer.length)
        return (0.0, d, d + s, 2 * d + s)

    @property
    def n_bays(self) -> int:
        return len(self.bays)

    @property
    def n_levels(self) -> int:
        return len(self.levels)

    @property
    def upright_x(self) -> tuple[float, ...]:
        """x of each upright [m], left to right (``n_bays + 1`` values)."""
        xs = [0.0]
        for span in self.bays:
            xs.append(xs[-1] + span)
        return tuple(xs)

    @property
    def level_y(self) -> tuple[float, ...]:
        """Elevation of each beam level [m], bottom to top."""
        ys: list[float] = []
        y = 0.0
        for h in self.levels:
            y += h
            ys.append(y)
        return tuple(ys)


@dataclass(frozen=True)
class Connections:
    """Rotational spring stiffnesses [N·m/rad]; ``inf`` = rigid, ``0`` = pinned."""

    beam_to_upright: float
    base: float
    base_cross: float | None = None  # 3D: base plate about the down-aisle axis (None: = base)

    @property
    def base_cross_k(self) -> float:
        return self.base if self.base_cross is None else self.base_cross

    @staticmethod
    def describe_value(k: float) -> str:
        if math.isinf(k):
            return "rigid"
        if k == 0.0:
            return "pinned"
        return f"{k:g} N·m/rad"


@dataclass(frozen=True)
class Damping:
    """Viscous damping of the frame.

    - ``kind="stiffness"``: C = a1·K with ratio ``ratio`` at ``period`` [s] or, when ``period`` is
      ``"first"``, at the first period of the frame with the pallets rigidly attached.
    - ``kind="rayleigh"``: C = a0·M + a1·K through the two ``(period [s], ratio)`` ``pairs``.
    - ``kind="none"``: C = 0.

    ``stiffness_term``: which K the a1 term uses when ``[second_order] p_delta`` adds the
    geometric stiffness K_G: ``"with_p_delta"`` (default) K_E + K_G, classical in the modes the
    engine integrates in (exact propagators in 2D, the diagonal planar step in 3D), or
    ``"elastic"`` K_E, the elastic stiffness of the members and connections (OpenSees'
    ``rayleigh`` with betaKinit: its initial stiffness has no geometric term; a near-critical
    rack's sway mode then gets several times the nominal ratio). Without P-Δ both are the
    same matrix. ``period = "first"`` is the first period of K_E + K_G in both.
    """

    kind: DampingKind = "none"
    ratio: float = 0.0
    period: float | Literal["first"] = "first"
    pairs: tuple[tuple[float, float], ...] = ()
    stiffness_term: StiffnessTerm = "with_p_delta"


@dataclass(frozen=True)
class SecondOrder:
    """Second-order (P-Δ) analysis of the frame under its gravity load.

    ``p_delta``: add the linear geometric stiffness K_G of the gravity axial forces to K.
    ``form``: ``"consistent"`` (cubic-Hermite geometric stiffness, P-Δ and P-δ) or
    ``"p_delta_only"`` (the chord term N/L, as OpenSees' ``geomTransf PDelta``); see
    :mod:`seisrack.fe.geometric`.
    ``axial``: which axial forces the geometric stiffness carries during the time history:
    ``"gravity"`` (default: those of the gravity load, held constant, so K stays linear) or
    ``"current"`` (gravity plus the change the motion causes, N(t) = N_g + ΔN(u(t)), as
    OpenSees' ``geomTransf PDelta`` does: an uplifting upright loses its P-Δ, a more
    compressed one gains; :mod:`seisrack.dynamics.axial`).
    """

    p_delta: bool = False
    form: Literal["consistent", "p_delta_only"] = "consistent"
    axial: Literal["gravity", "current"] = "gravity"


@dataclass(frozen=True)
class Hysteresis:
    """Moment–rotation laws of the connections (``[hysteresis]``); ``None`` keeps the linear
    spring of ``[connections]``. See :mod:`seisrack.model.hinge_law`."""

    beam_to_upright: HingeLaw | None = None
    base: HingeLaw | None = None

    @property
    def nonlinear(self) -> bool:
        return any(x is not None and x.kind != "elastic" for x in (self.beam_to_upright,
                                                                   self.base))


@dataclass(frozen=True)
class Pallet:
    """A pallet resting on the beams of one bay and level (and row, 1-based).

    ``bay``, ``level`` and ``row`` are 1-based (as in the TOML). ``position`` [m] is the pallet
    centre from the left upright of its bay; ``width`` [m] its extent along the beam.
    ``sliding_limit`` [m] is the allowed sliding on each side, or ``None`` for the free distance
    to the next obstacle.
    ``friction_rate`` [s/m]: 0 for Coulomb friction, else velocity-dependent sliding friction
    mu(v) = mu_dynamic + (mu_static - mu_dynamic) exp(-rate |v|) (see Sliders).
    """

    mass: float
    bay: int
    level: int
    position: float
    mu_static: float
    mu_dynamic: float
    width: float = DEFAULT_PALLET_WIDTH
    sliding_limit: float | None = None
    friction_rate: float = 0.0
    depth: float | None = None  # 3D racks: pallet depth cross-aisle [m]
    overhang: float | None = None  # 3D racks: overhang beyond the front and rear beams [m]
    row: int = 1  # back-to-back racks: the row (1 front, 2 rear) whose two beams it rests on


@dataclass(frozen=True)
class RackSpec:
    """A complete, validated rack description."""

    material: Material
    sections: Mapping[str, Section]
    geometry: Geometry
    connections: Connections
    damping: Damping = field(default_factory=Damping)
    pallets: tuple[Pallet, ...] = ()
    g: float = DEFAULT_G
    title: str = ""
    source: str | None = None
    second_order: SecondOrder = field(default_factory=SecondOrder)
    hysteresis: Hysteresis = field(default_factory=Hysteresis)
    bracing: Bracing | None = None  # 3D racks (geometry.depth given)

    @property
    def ndm(self) -> int:
        """The rack's dimension: 3 when ``[geometry] depth`` is given (a space frame with
        upright frames and bracing), else 2 (a plane frame)."""
        return 2 if self.geometry.depth is None else 3

    def beam_section(self, level: int) -> Section:
        """Section of the beams of 0-based ``level``."""
        return self.sections[self.geometry.beam_sections[level]]

    def upright_section(self, storey: int) -> Section:
        """Section of the uprights of 0-based ``storey``."""
        return self.sections[self.geometry.upright_sections[storey]]

    @property
    def pallet_mass_total(self) -> float:
        return float(sum(p.mass for p in self.pallets))


def with_friction(spec: RackSpec, mu_static: float, mu_dynamic: float | None = None) -> RackSpec:
    """Return a copy of ``spec`` with every pallet's friction coefficients overridden.

    ``mu_dynamic`` defaults to ``mu_static``. The values are validated like TOML input.
    """
    from seisrack.model._reader import check_friction

    mu_d = mu_static if mu_dynamic is None else mu_dynamic
    check_friction("mu_static", mu_static, "mu_dynamic", mu_d)
    pallets = tuple(
        replace(p, mu_static=float(mu_static), mu_dynamic=float(mu_d)) for p in spec.pallets
    )
    return replace(spec, pallets=pallets)
