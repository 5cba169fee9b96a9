"""Ground motion in the rack's axes: :class:`GroundMotion`, the one ground-motion type every rack
run takes — a down-aisle component, an optional cross-aisle one (3D racks), an optional vertical
one and an incidence angle.

A record pair (e.g. the two horizontal components of a PEER NGA station, ``*.AT2``) is given
as component 1 along the rack's down-aisle axis x and component 2 along its cross-aisle axis
z; an incidence angle θ turns the pair about the vertical (from x towards z), so that
x = a1 cos θ − a2 sin θ and z = a1 sin θ + a2 cos θ (a rotation of the plane: the horizontal
intensity |a| is kept at every instant). Axes as :mod:`seisrack.model.frame_model`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError
from seisrack.motion.records import Record

#: relative tolerance on equal time steps of the components
_DT_RTOL = 1e-9


@dataclass(frozen=True, eq=False)
class GroundMotion:
    """Ground acceleration [m/s²] along x (down-aisle), z (cross-aisle, or None: a motion in
    the down-aisle plane only) and y (vertical, or None), sampled at ``k dt``; ``names`` of the
    records used (down, cross, vertical), ``angle_deg`` the incidence angle applied."""

    x: np.ndarray
    z: np.ndarray | None
    v: np.ndarray | None
    dt: float
    names: tuple[str, str, str]
    angle_deg: float = 0.0

    @property
    def n(self) -> int:
        return int(self.x.size)

    @property
    def duration(self) -> float:
        return (self.n - 1) * self.dt

    @property
    def n_dir(self) -> int:
        """Horizontal directions with a component: 1 (down-aisle) or 2."""
        return 1 if self.z is None else 2

    @property
    def horizontal(self) -> tuple[np.ndarray, ...]:
        """The horizontal components by direction: (x,) or (x, z)."""
        return (self.x,) if self.z is None else (self.x, self.z)

    @property
    def name(self) -> str:
        """The record's name, or 'down / cross' names ('-' where a component is absent)."""
        if self.z is None:
            return self.names[0]
        return " / ".join([self.names[0] or "-", self.names[1] or "-"])

    def peak_horizontal(self) -> float:
        """[m/s²] largest magnitude of the horizontal acceleration vector."""
        z = 0.0 if self.z is None else self.z
        return float(np.max(np.hypot(self.x, z)))

    def padded(self, n_extra: int) -> GroundMotion:
        """The motion followed by ``n_extra`` samples of rest (free vibration)."""
        if n_extra <= 0:
            return self

        def pad(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else np.concatenate([a, np.zeros(n_extra)])

        return GroundMotion(pad(self.x), pad(self.z), pad(self.v), self.dt, self.names,
                            self.angle_deg)

    def scaled(self, factor: float) -> GroundMotion:
        """Every component (the vertical one too) multiplied by ``factor``."""

        def mul(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a * factor

        return GroundMotion(mul(self.x), mul(self.z), mul(self.v), self.dt, self.names,
                            self.angle_deg)


def combine(down: Record | None, cross: Record | None = None, vertical: Record | None = None,
            angle_deg: float = 0.0, *, fields: tuple[str, str, str] = (
                "motion", "motion_cross", "vertical")) -> GroundMotion:
    """Ground motion from component records: ``down`` along x, ``cross`` along z (either may
    be None: no motion in that direction, not both), ``vertical``; rotated by ``angle_deg``.
    With one horizontal record along x and no angle the motion has no cross-aisle component
    (``z`` None), which a 2D rack takes; anything else has one.

    The records must share their time step and length (InputError naming ``fields``, the
    caller's names of the three inputs, e.g. the command-line options).
    """
    if down is None and cross is None:
        raise InputError(fields[0], None, f"a horizontal record ({fields[0]} or {fields[1]})")
    if not (isinstance(angle_deg, int | float) and math.isfinite(angle_deg)):
        raise InputError("angle", angle_deg, "a finite incidence angle in degrees")
    ref = down if down is not None else cross
    ref_field = fields[0] if down is not None else fields[1]
    for rec, fld in ((cross, fields[1]), (vertical, fields[2])):
        if rec is None or rec is ref:
            continue
        if abs(rec.dt - ref.dt) > _DT_RTOL * ref.dt:
            raise InputError(fld, f"time step {rec.dt:g} s",
                             f"the time step of {ref_field} ({ref.dt:g} s)",
                             hint="Resample one record so that both share one time step")
        if rec.n != ref.n:
            raise InputError(fld, f"{rec.n} samples ({rec.duration:g} s)",
                             f"the length of {ref_field} ({ref.n} samples, {ref.duration:g} s)",
                             hint="The components of one ground motion must have the same "
                                  "length: trim or pad them first")
    zero = np.zeros(ref.n)
    a1 = zero if down is None else np.asarray(down.accel, dtype=float)
    a2 = zero if cross is None else np.asarray(cross.accel, dtype=float)
    th = math.radians(angle_deg)
    c, s = math.cos(th), math.sin(th)
    x = c * a1 - s * a2
    z = s * a1 + c * a2
    if cross is None and angle_deg == 0.0:
        x, z = a1.copy(), None
    v = None if vertical is None else np.asarray(vertical.accel, dtype=float).copy()
    names = (down.name if down is not None else "", cross.name if cross is not None else "",
             vertical.name if vertical is not None else "")
    return GroundMotion(x, z, v, ref.dt, names, float(angle_deg))
