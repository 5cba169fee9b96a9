"""Moment–rotation hysteresis law of a rotational hinge (beam-to-upright connector, base plate):
the frozen spec, its TOML parsing and validation, and its packing into the numeric parameter
row of :mod:`seisrack.dynamics._hysteresis`.

A law is written under ``[hysteresis.beam_to_upright]`` or ``[hysteresis.base]``; the key ``law``
selects the kind. The elastic stiffness of the hinge is the connection's stiffness from
``[connections]`` (N·m/rad), passed in as ``k_elastic``::

    [hysteresis.beam_to_upright]
    law = "bilinear"           # "elastic" | "elastic-plastic" | "bilinear" | "pinching"
    yield_moment = 4.0e3       # N·m
    hardening_ratio = 0.02     # post-yield / elastic stiffness, 0 <= b < 1

    [hysteresis.base]
    law = "pinching"
    envelope_rotation = [0.01, 0.03, 0.06, 0.10]       # rad, strictly increasing
    envelope_moment = [1.0e3, 1.8e3, 2.2e3, 2.3e3]      # N·m, M1/θ1 = [connections] stiffness
    # negative_envelope_rotation / negative_envelope_moment: magnitudes, default = mirror
    reload_rotation_ratio = 0.3    # rDisp
    reload_moment_ratio = 0.2      # rForce
    unload_moment_ratio = 0.05     # uForce
    # negative_reload_rotation_ratio, ... : default = the positive values

Every field is in SI units. See ``docs/theory/hysteresis.md``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import Any, Literal

import numpy as np

from seisrack.errors import InputError
from seisrack.model._reader import Table, check_number

HingeLawKind = Literal["elastic", "elastic-plastic", "bilinear", "pinching"]

#: law codes, equal to ``HYST_ELASTIC``, ``HYST_EPP``, ``HYST_BILINEAR``, ``HYST_PINCHING`` of
#: :mod:`seisrack.dynamics._hysteresis` (not imported here, so that the model layer does not load
#: the dynamics package; a test checks the equality)
LAW_CODES: dict[str, int] = {
    "elastic": 0,
    "elastic-plastic": 1,
    "bilinear": 2,
    "pinching": 3,
}

_RATIOS = ("reload_rotation_ratio", "reload_moment_ratio", "unload_moment_ratio")
_NEG_RATIOS = tuple(f"negative_{r}" for r in _RATIOS)
_ENVELOPE = ("envelope_rotation", "envelope_moment", "negative_envelope_rotation",
             "negative_envelope_moment")

#: the keys a TOML table may hold for each law (besides ``law``; ``stiffness`` is optional and
#: must then agree with ``[connections]``)
LAW_KEYS: dict[str, tuple[str, ...]] = {
    "elastic": ("stiffness",),
    "elastic-plastic": ("stiffness", "yield_moment"),
    "bilinear": ("stiffness", "yield_moment", "hardening_ratio"),
    "pinching": ("stiffness", *_ENVELOPE, *_RATIOS, *_NEG_RATIOS),
}

#: relative tolerance of the agreement between the pinching envelope's initial slope M1/θ1 (or
#: a ``stiffness`` key) and the connection stiffness of ``[connections]``
STIFFNESS_RTOL = 1e-3


@dataclass(frozen=True)
class HingeLaw:
    """One moment–rotation law (SI units).

    - ``elastic``: M = k·θ.
    - ``elastic-plastic``: elastic–perfectly plastic, k and ``yield_moment`` (symmetric).
    - ``bilinear``: kinematic hardening, k, ``yield_moment`` and ``hardening_ratio`` b (the
      post-yield stiffness is b·k).
    - ``pinching``: 4-point multilinear envelope per sign (``envelope_rotation`` [rad],
      ``envelope_moment`` [N·m], the negative side as positive magnitudes, default the mirror)
      with pinched unload/reload: ``reload_rotation_ratio`` (rDisp), ``reload_moment_ratio``
      (rForce), ``unload_moment_ratio`` (uForce), each per sign; the stiffness is M1/θ1.
    """

    kind: HingeLawKind
    stiffness: float
    yield_moment: float | None = None
    hardening_ratio: float = 0.0
    envelope_rotation: tuple[float, ...] = ()
    envelope_moment: tuple[float, ...] = ()
    negative_envelope_rotation: tuple[float, ...] | None = None
    negative_envelope_moment: tuple[float, ...] | None = None
    reload_rotation_ratio: float = 0.0
    reload_moment_ratio: float = 0.0
    unload_moment_ratio: float = 0.0
    negative_reload_rotation_ratio: float | None = None
    negative_reload_moment_ratio: float | None = None
    negative_unload_moment_ratio: float | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for name in ("envelope_rotation", "envelope_moment", "negative_envelope_rotation",
                     "negative_envelope_moment"):
            value = getattr(self, name)
            if value is not None and not isinstance(value, tuple):
                set_(self, name, tuple(value))
        if self.kind == "pinching":
            if self.negative_envelope_rotation is None:
                set_(self, "negative_envelope_rotation", self.envelope_rotation)
            if self.negative_envelope_moment is None:
                set_(self, "negative_envelope_moment", self.envelope_moment)
            for pos, neg in zip(_RATIOS, _NEG_RATIOS, strict=True):
                if getattr(self, neg) is None:
                    set_(self, neg, getattr(self, pos))
        _validate({f.name: getattr(self, f.name) for f in fields(self)}, "HingeLaw", None)

    # ------------------------------------------------------------------ derived values
    @property
    def code(self) -> int:
        """The law's code in :mod:`seisrack.dynamics._hysteresis` (``HYST_*``)."""
        return LAW_CODES[self.kind]

    @property
    def yield_rotation(self) -> float:
        """Rotation at the end of the initial elastic branch [rad]: My/k (EPP, bilinear), θ1 of
        the positive envelope (pinching), ``inf`` (elastic)."""
        if self.kind in ("elastic-plastic", "bilinear"):
            assert self.yield_moment is not None
            return self.yield_moment / self.stiffness
        if self.kind == "pinching":
            return self.envelope_rotation[0]
        return math.inf

    def describe(self) -> str:
        """One line for reports."""
        k = f"k = {self.stiffness:.4g} N·m/rad"
        if self.kind == "elastic":
            return f"elastic, {k}"
        if self.kind == "elastic-plastic":
            return (f"elastic-perfectly plastic, {k}, My = {self.yield_moment:.4g} N·m "
                    f"(θy = {self.yield_rotation:.4g} rad)")
        if self.kind == "bilinear":
            return (f"bilinear kinematic hardening, {k}, My = {self.yield_moment:.4g} N·m "
                    f"(θy = {self.yield_rotation:.4g} rad), b = {self.hardening_ratio:.4g}")
        env = ", ".join(f"({t:.4g}, {m:.4g})" for t, m in
                        zip(self.envelope_rotation, self.envelope_moment, strict=True))
        sym = (self.negative_envelope_rotation == self.envelope_rotation
               and self.negative_envelope_moment == self.envelope_moment)
        return (f"pinching (Pinching4, no damage), {k}, envelope (rad, N·m) {env}"
                f"{'' if sym else ' (asymmetric)'}, rDisp/rForce/uForce = "
                f"{self.reload_rotation_ratio:.3g}/{self.reload_moment_ratio:.3g}/"
                f"{self.unload_moment_ratio:.3g}")

    def pack(self) -> tuple[int, np.ndarray]:
        """(law code, parameter row float64[HYST_NPAR]) for the numeric kernels."""
        from seisrack.dynamics._hysteresis import HYST_NPAR, _hyst_pack_pinching

        par = np.zeros(HYST_NPAR)
        par[0] = self.stiffness
        if self.kind in ("elastic-plastic", "bilinear"):
            assert self.yield_moment is not None
            par[1] = self.yield_moment
            par[2] = self.hardening_ratio if self.kind == "bilinear" else 0.0
        elif self.kind == "pinching":
            assert self.negative_envelope_rotation is not None
            assert self.negative_envelope_moment is not None
            _hyst_pack_pinching(
                np.array(self.envelope_rotation, dtype=float),
                np.array(self.envelope_moment, dtype=float),
                np.array(self.negative_envelope_rotation, dtype=float),
                np.array(self.negative_envelope_moment, dtype=float),
                self.reload_rotation_ratio, self.reload_moment_ratio, self.unload_moment_ratio,
                float(self.negative_reload_rotation_ratio),  # type: ignore[arg-type]
                float(self.negative_reload_moment_ratio),  # type: ignore[arg-type]
                float(self.negative_unload_moment_ratio),  # type: ignore[arg-type]
                par,
            )
        return self.code, par


# ---------------------------------------------------------------------- validation

def _err(field: str, name: str, value: Any, allowed: str, hint: str | None = None,
         source: str | None = None) -> InputError:
    return InputError(f"{field}.{name}", value, allowed, hint=hint, source=source)


def _validate(v: Mapping[str, Any], field: str, source: str | None) -> None:
    """Check a complete set of :class:`HingeLaw` values; errors name ``field.<key>``."""
    kind = v["kind"]
    if kind not in LAW_CODES:
        raise InputError(f"{field}.law", kind, "one of " + ", ".join(f'"{k}"' for k in LAW_CODES),
                         source=source)
    k = v["stiffness"]
    check_number(k, f"{field}.stiffness", unit="N·m/rad", source=source)
    if math.isinf(k) or k <= 0.0:
        raise _err(field, "stiffness", k, "a finite elastic stiffness > 0 [N·m/rad]",
                   "A hysteresis law needs a deformable connection: a rigid (inf) or pinned "
                   "(0) connection cannot carry a moment-rotation law", source)
    if kind in ("elastic-plastic", "bilinear"):
        my = v["yield_moment"]
        if my is None:
            raise _err(field, "yield_moment", None, "a value (required for this law) [N·m]",
                       source=source)
        check_number(my, f"{field}.yield_moment", positive=True, unit="N·m", source=source)
    if kind == "bilinear":
        b = check_number(v["hardening_ratio"], f"{field}.hardening_ratio", unit="-",
                         source=source)
        if not 0.0 <= b < 1.0:
            raise _err(field, "hardening_ratio", b, "0 <= b < 1 (post-yield / elastic stiffness)",
                       "b < 0 is a softening branch, b >= 1 a post-yield stiffness as large as "
                       "or larger than the elastic one", source)
    if kind != "pinching":
        return
    for side, rot_key, mom_key in (("positive", "envelope_rotation", "envelope_moment"),
                                   ("negative", "negative_envelope_rotation",
                                    "negative_envelope_moment")):
        rot, mom = v[rot_key], v[mom_key]
        for key, arr, unit in ((rot_key, rot, "rad"), (mom_key, mom, "N·m")):
            if arr is None or len(arr) != 4:
                raise _err(field, key, None if arr is None else list(arr),
                           f"an array of 4 numbers [{unit}]", source=source)
            for i, x in enumerate(arr):
                check_number(x, f"{field}.{key}[{i}]", positive=True, unit=unit, source=source)
        if not all(b > a for a, b in zip(rot[:-1], rot[1:], strict=True)):
            raise _err(field, rot_key, list(rot),
                       "4 strictly increasing positive rotations [rad] (θ1 < θ2 < θ3 < θ4)",
                       source=source)
        slope = mom[0] / rot[0]
        if abs(slope - k) > STIFFNESS_RTOL * k:
            raise _err(field, mom_key, list(mom),
                       f"an initial slope M1/θ1 within {STIFFNESS_RTOL:.1%} of the connection "
                       f"stiffness {k:.6g} N·m/rad",
                       f"The {side} envelope starts with M1/θ1 = {mom[0]:.6g}/{rot[0]:.6g} = "
                       f"{slope:.6g} N·m/rad but the connection stiffness is {k:.6g} N·m/rad; "
                       "make them agree (the elastic stiffness is set once, in [connections])",
                       source)
    for key in (*_RATIOS, *_NEG_RATIOS):
        x = check_number(v[key], f"{field}.{key}", unit="-", source=source)
        if not 0.0 <= x <= 1.0:
            raise _err(field, key, x, "a ratio in [0, 1]", source=source)


def _number_list(t: Table, key: str, unit: str) -> tuple[float, ...]:
    arr = t.array(key)
    return tuple(check_number(x, f"{t.field(key)}[{i}]", positive=True, unit=unit,
                              source=t.source) for i, x in enumerate(arr))


def parse_hinge_law(d: Mapping[str, Any], field: str, k_elastic: float | None,
                    source: str | None = None) -> HingeLaw:
    """Read and validate one ``[hysteresis.*]`` table.

    ``field`` is the table's dotted path (``"hysteresis.beam_to_upright"``), used in the error
    messages; ``k_elastic`` the connection's elastic stiffness from ``[connections]`` [N·m/rad]
    (``None`` when there is none: a ``stiffness`` key is then required, except for pinching where
    M1/θ1 is the stiffness). Raises :class:`~seisrack.errors.InputError` naming the field, the
    value and what is allowed.
    """
    t = Table(d, field, source)
    kind = t.string("law")
    if kind not in LAW_KEYS:
        raise t.error("law", kind, "one of " + ", ".join(f'"{k}"' for k in LAW_KEYS))
    allowed = LAW_KEYS[kind]
    for key in t.data:
        if key != "law" and key not in allowed:
            raise t.error(key, t.data[key], f"for law = \"{kind}\" the keys: law, "
                          + ", ".join(allowed), hint="Check the spelling of the key, or the law")
    if k_elastic is not None:
        kc = float(k_elastic)
        if not kc > 0.0 or math.isinf(kc):
            what = ("rigid (inf)" if kc == math.inf else "pinned (0)" if kc == 0.0
                    else "not a positive number")
            raise t.error("law", kind, "no hysteresis law: the connection is "
                          f"{what} in [connections] (stiffness {kc:g} N·m/rad)",
                          hint="A moment-rotation law needs a finite, positive connection "
                          "stiffness in [connections]; remove this table or give one")
    else:
        kc = None

    vals: dict[str, Any] = {"kind": kind}
    k_key = t.number("stiffness", None, positive=True, unit="N·m/rad") if t.has("stiffness") \
        else None
    if k_key is not None and kc is not None and abs(k_key - kc) > STIFFNESS_RTOL * kc:
        raise t.error("stiffness", k_key, f"the connection stiffness {kc:.6g} N·m/rad of "
                      f"[connections] (within {STIFFNESS_RTOL:.1%})",
                      hint="Give the elastic stiffness once, in [connections]")
    k = kc if kc is not None else k_key

    if kind in ("elastic-plastic", "bilinear"):
        vals["yield_moment"] = t.number("yield_moment", positive=True, unit="N·m")
    if kind == "bilinear":
        b = t.number("hardening_ratio", unit="-")
        if not 0.0 <= b < 1.0:
            raise t.error("hardening_ratio", b, "0 <= b < 1 (post-yield / elastic stiffness)",
                          hint="b < 0 is a softening branch; b >= 1 is a post-yield stiffness "
                          "as large as or larger than the elastic one")
        vals["hardening_ratio"] = b
    if kind == "pinching":
        vals["envelope_rotation"] = _number_list(t, "envelope_rotation", "rad")
        vals["envelope_moment"] = _number_list(t, "envelope_moment", "N·m")
        has_nr, has_nm = t.has("negative_envelope_rotation"), t.has("negative_envelope_moment")
        if has_nr != has_nm:
            missing = "negative_envelope_moment" if has_nr else "negative_envelope_rotation"
            other = "negative_envelope_rotation" if has_nm else "negative_envelope_moment"
            raise t.error(missing, None, f"an array of 4 numbers, given together with {other}",
                          hint="Give both negative envelope arrays or neither (mirror)")
        if has_nr:
            vals["negative_envelope_rotation"] = _number_list(t, "negative_envelope_rotation",
                                                              "rad")
            vals["negative_envelope_moment"] = _number_list(t, "negative_envelope_moment", "N·m")
        else:
            vals["negative_envelope_rotation"] = vals["envelope_rotation"]
            vals["negative_envelope_moment"] = vals["envelope_moment"]
        for pos, neg in zip(_RATIOS, _NEG_RATIOS, strict=True):
            vals[pos] = t.number(pos, unit="-")
            vals[neg] = t.number(neg, unit="-") if t.has(neg) else vals[pos]
        if k is None:
            k = vals["envelope_moment"][0] / vals["envelope_rotation"][0]
    if k is None:
        raise t.error("stiffness", None, "a value [N·m/rad] (or a connection stiffness in "
                      "[connections])")
    vals["stiffness"] = k
    full = {f.name: vals.get(f.name, f.default) for f in fields(HingeLaw)}
    _validate(full, field, source)
    t.finish(("law", *allowed))
    return HingeLaw(**vals)
