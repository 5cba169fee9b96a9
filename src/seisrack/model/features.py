"""What is built for which rack dimension: one table, and the refusals that name the feature.

A 2D (plane) rack and a 3D (space) rack are the same kind of thing and take the same path; a
capability that exists for one dimension only is listed here, and asking for it on the other
raises an :class:`~seisrack.errors.InputError` that names the feature and the field that asked
for it ("velocity-dependent friction is not built for 3D racks yet"), never a type check.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from seisrack.errors import InputError

#: feature -> the rack dimensions it is built for
FEATURES: dict[str, tuple[int, ...]] = {
    "nonlinear connections ([hysteresis])": (2, 3),
    "velocity-dependent friction (friction_rate)": (2,),
    "exact modal propagators (method exact)": (2,),
    "a cross-aisle ground motion component": (3,),
    "an incidence angle of the horizontal components": (3,),
    "P-Δ of the current axial forces ([second_order] axial)": (3,),
}


#: engine of the time history -> what it does not do (yet); the default engine does everything
#: :data:`FEATURES` lists for the rack's dimension
ENGINE_LACKS: dict[str, tuple[str, ...]] = {
    "local": (
        "nonlinear connections ([hysteresis])",
        "velocity-dependent friction (friction_rate)",
        "P-Δ of the current axial forces ([second_order] axial)",
        "a choice of time integration (method)",
        "a choice of structure basis (basis)",
    ),
}


def require_engine(feature: str, engine: str, field: str, value: Any, *,
                   source: str | None = None) -> None:
    """InputError on ``field`` when ``engine`` lacks ``feature`` (:data:`ENGINE_LACKS`)."""
    if feature not in ENGINE_LACKS.get(engine, ()):
        return
    raise InputError(field, value, f"the default engine: {feature} is not built in the "
                     f"{engine} engine yet", source=source,
                     hint=f"Run without engine {engine!r} (the default engine has it)")


def built_for(feature: str, ndm: int) -> bool:
    """Whether ``feature`` (a key of :data:`FEATURES`) is built for a ``ndm``-D rack."""
    return ndm in FEATURES[feature]


def require(feature: str, ndm: int, field: str, value: Any, *, source: str | None = None
            ) -> None:
    """InputError on ``field`` unless ``feature`` is built for a ``ndm``-D rack."""
    if built_for(feature, ndm):
        return
    dims = " and ".join(f"{d}D" for d in FEATURES[feature])
    raise InputError(field, value, f"a {dims} rack: {feature} is not built for {ndm}D racks"
                     + (" yet" if ndm == 3 else ""), source=source)


def check_features(spec: Any) -> None:
    """Refuse, before any work, what the rack file asks for and its dimension does not have,
    and check that a 3D rack's sections carry what a space frame needs."""
    ndm = spec.ndm
    src = spec.source
    if spec.hysteresis.nonlinear:
        require("nonlinear connections ([hysteresis])", ndm, "hysteresis", "nonlinear law",
                source=src)
    rates = [i for i, p in enumerate(spec.pallets) if p.friction_rate]
    if rates:
        require("velocity-dependent friction (friction_rate)", ndm,
                f"pallets[{rates[0]}].friction_rate", spec.pallets[rates[0]].friction_rate,
                source=src)
    if spec.second_order.axial == "current":
        require("P-Δ of the current axial forces ([second_order] axial)", ndm,
                "second_order.axial", "current", source=src)
    if ndm == 3:
        _check_sections_3d(spec)


def _check_sections_3d(spec: Any) -> None:
    geo = spec.geometry
    for name in sorted(set(geo.beam_sections) | set(geo.upright_sections)):
        s = spec.sections[name]
        for key, value in (("I", s.I), ("Iy", s.Iy), ("J", s.J)):
            if value is None or math.isnan(value):
                what = {"I": "I (or Iz): bending in the down-aisle plane",
                        "Iy": "Iy: bending in the other principal plane (cross-aisle for an "
                              "upright, horizontal for a beam)",
                        "J": "J: St Venant torsion constant"}[key]
                raise InputError(f"sections.{name}.{key}", None, f"a value > 0 [m⁴] ({what})",
                                 source=spec.source, hint="A 3D rack needs I (or Iz), Iy and J "
                                 "for every beam and upright section")


#: the engines of :func:`seisrack.analysis.run_rack`
ENGINES = ("default", "local")


def check_engine(engine: str, model: Any, *, method: str = "auto",
                 basis: object = "auto", cli: bool = False) -> None:
    """Refuse, by name, what ``engine`` does not do for ``model`` (``cli``: name the
    command's options)."""
    opt = "--" if cli else ""
    if engine not in ENGINES:
        raise InputError(f"{opt}engine", engine, " or ".join(f'"{e}"' for e in ENGINES))
    if method == "exact":
        require("exact modal propagators (method exact)", model.ndm, "method", method)
        if non_classical_damping(model):
            raise InputError(
                "method", method, '"newmark" or "auto" for this rack',
                hint="With P-Δ, damping a1·K_E ([damping] stiffness_term = \"elastic\") is "
                     "not classical in the modes of K_E + K_G, which the exact "
                     "propagators need. Use method \"auto\" (Newmark here), or "
                     "stiffness_term = \"with_p_delta\" (a1·(K_E + K_G)) for exact propagators")
    if engine == "default":
        return
    if model.nonlinear_hinges:
        require_engine("nonlinear connections ([hysteresis])", engine, "hysteresis",
                       "a nonlinear law")
    if model.axial_p_delta is not None:
        require_engine("P-Δ of the current axial forces ([second_order] axial)", engine,
                       "second_order.axial", "current")
    rates = np.flatnonzero(np.asarray(model.pallet_friction_rate) != 0)
    if rates.size:
        j = int(rates[0])
        require_engine("velocity-dependent friction (friction_rate)", engine,
                       f"friction_rate of pallet {j + 1}", float(model.pallet_friction_rate[j]))
    if method != "auto":
        require_engine("a choice of time integration (method)", engine, f"{opt}method",
                       method)
    if not (isinstance(basis, str) and basis == "auto"):
        require_engine("a choice of structure basis (basis)", engine, f"{opt}basis",
                       basis if isinstance(basis, str) else type(basis).__name__)


def non_classical_damping(model: Any) -> bool:
    """True when the rack's C is not diagonal in the modes of its K: C = a0·M + a1·K_E with
    P-Δ in K ([damping] ``stiffness_term = "elastic"``). The exact propagators then do not
    apply and the engine takes Newmark."""
    return (model.critical_load_factor is not None and model.damping_coefficients[1] != 0.0
            and model.damping_stiffness_term == "elastic")


def takes_newmark(model: Any, engine: str, method: str) -> bool:
    """Whether the run of ``model`` integrates by Newmark: the default engine does for sliders
    in the plane (3D racks), and on a line when asked, with nonlinear hinges or
    velocity-weakening friction, or when the damping has a mass term (pallets on the rack)
    or is not classical (:func:`non_classical_damping`); the local engine is a scheme of its
    own (its accelerations are already central differences of its velocities)."""
    if engine != "default":
        return False
    weakening = (np.asarray(model.pallet_friction_rate) > 0.0) & (
        np.asarray(model.pallet_mu_static) > np.asarray(model.pallet_mu_dynamic))
    return (model.n_dir != 1 or method == "newmark" or bool(model.nonlinear_hinges)
            or bool(np.any(weakening)) or (method == "auto" and (
                (model.damping_coefficients[0] != 0.0 and model.n_pallets > 0)
                or non_classical_damping(model))))
