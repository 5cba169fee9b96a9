"""OpenSees ``uniaxialMaterial`` equivalent of a hinge's moment–rotation law.

:func:`opensees_uniaxial` returns the argument list of ``ops.uniaxialMaterial(*args)`` (also the
words of the Tcl command) that reproduces a :class:`~seisrack.model.hinge_law.HingeLaw`:

- ``elastic``         → ``Elastic(tag, k)``
- ``elastic-plastic`` → ``ElasticPP(tag, k, My/k)`` (identical to ``Steel01(My, k, 0)``)
- ``bilinear``        → ``Steel01(tag, My, k, b)`` with the default a1..a4 = 0, 1, 0, 1 (no
  isotropic hardening)
- ``pinching``        → ``Pinching4`` with the 16 envelope values, the six pinching ratios and
  all damage switched off: gK1..gK4, gKLim, gD1..gD4, gDLim, gF1..gF4, gFLim = 0, gE = 10,
  dmgType ``"energy"`` (with every damage index 0, gE only enters an energy capacity that is
  never used).

These were checked against OpenSeesPy's own materials (``tests/test_hysteresis_laws.py``).
Pure Python: openseespy is not needed to build the lists.
"""

from __future__ import annotations

from seisrack.model.hinge_law import HingeLaw

#: gE passed to Pinching4 (any value > 0 does: with all damage indices 0 it has no effect)
PINCHING4_GAMMA_E = 10.0


def opensees_uniaxial(law: HingeLaw, tag: int) -> list:
    """Arguments of ``ops.uniaxialMaterial`` for ``law`` under material tag ``tag``."""
    k = float(law.stiffness)
    if law.kind == "elastic":
        return ["Elastic", int(tag), k]
    if law.kind == "elastic-plastic":
        assert law.yield_moment is not None
        return ["ElasticPP", int(tag), k, float(law.yield_moment) / k]
    if law.kind == "bilinear":
        assert law.yield_moment is not None
        return ["Steel01", int(tag), float(law.yield_moment), k, float(law.hardening_ratio)]
    if law.kind == "pinching":
        assert law.negative_envelope_rotation is not None
        assert law.negative_envelope_moment is not None
        args: list = ["Pinching4", int(tag)]
        for rot, mom in zip(law.envelope_rotation, law.envelope_moment, strict=True):
            args += [float(mom), float(rot)]
        for rot, mom in zip(law.negative_envelope_rotation, law.negative_envelope_moment,
                            strict=True):
            args += [-float(mom), -float(rot)]
        args += [float(law.reload_rotation_ratio), float(law.reload_moment_ratio),
                 float(law.unload_moment_ratio),
                 float(law.negative_reload_rotation_ratio),  # type: ignore[arg-type]
                 float(law.negative_reload_moment_ratio),  # type: ignore[arg-type]
                 float(law.negative_unload_moment_ratio)]  # type: ignore[arg-type]
        args += [0.0] * 15  # gK1..gK4, gKLim, gD1..gD4, gDLim, gF1..gF4, gFLim
        args += [PINCHING4_GAMMA_E, "energy"]
        return args
    raise ValueError(f"unknown hinge law kind {law.kind!r}")  # pragma: no cover
