"""Shared rack inputs for the model / FE / CLI tests (not a test module)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PAPER_RACK = EXAMPLES / "paper_rack.toml"


def paper_dict() -> dict[str, Any]:
    with PAPER_RACK.open("rb") as fh:
        return tomllib.load(fh)


def portal_dict(*, joint: Any = 160e3, base: Any = 160e3, area_factor: float = 1.0,
                subdivisions: int = 4, bays: tuple[float, ...] = (1.8,),
                height: float = 2.0) -> dict[str, Any]:
    """An unloaded frame with the paper's sections (optionally with stiffened areas)."""
    d = paper_dict()
    d["pallets"] = []
    d["damping"] = {"kind": "none"}
    d["geometry"].update(bays=list(bays), levels=[height], subdivisions=subdivisions)
    d["connections"] = {"beam_to_upright": joint, "base": base}
    for s in d["sections"].values():
        s["A"] *= area_factor
    return d


def _set(d: dict[str, Any], path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    d = copy.deepcopy(d)
    target: Any = d
    for key in path[:-1]:
        target = target[key]
    if value is _DELETE:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return d


_DELETE = object()

# (case id, path to change, new value, substring expected in the error's field)
BAD_CASES: list[tuple[str, tuple[Any, ...], Any, str]] = [
    ("missing-E", ("material", "E"), _DELETE, "material.E"),
    ("missing-geometry", ("geometry",), _DELETE, "geometry"),
    ("missing-pallet-mass", ("pallets", 0, "mass"), _DELETE, "pallets[0].mass"),
    ("unknown-top-key", ("colour",), "blue", "colour"),
    ("unknown-geometry-key", ("geometry", "bayz"), [1.8], "geometry.bayz"),
    ("unknown-pallet-key", ("pallets", 1, "weight"), 3.0, "pallets[1].weight"),
    ("zero-mass", ("pallets", 2, "mass"), 0.0, "pallets[2].mass"),
    ("negative-mass", ("pallets", 0, "mass"), -400.0, "pallets[0].mass"),
    ("zero-area", ("sections", "beam", "A"), 0.0, "sections.beam.A"),
    ("negative-area", ("sections", "upright", "A"), -1e-4, "sections.upright.A"),
    ("zero-inertia", ("sections", "beam", "I"), 0.0, "sections.beam.I"),
    ("negative-inertia", ("sections", "upright", "I"), -4e-7, "sections.upright.I"),
    ("zero-span", ("geometry", "bays", 1), 0.0, "geometry.bays[1]"),
    ("negative-height", ("geometry", "levels", 0), -2.0, "geometry.levels[0]"),
    ("zero-E", ("material", "E"), 0.0, "material.E"),
    ("negative-density", ("material", "density"), -7850.0, "material.density"),
    ("mu-static-negative", ("pallets", 0, "mu_static"), -0.1, "pallets[0].mu_static"),
    ("mu-dynamic-negative", ("pallets", 1, "mu_dynamic"), -0.2, "pallets[1].mu_dynamic"),
    ("mu-dynamic-above-static", ("pallets", 2, "mu_dynamic"), 0.7, "pallets[2].mu_dynamic"),
    ("pallet-outside-bay-left", ("pallets", 0, "position"), 0.2, "pallets[0].position"),
    ("pallet-outside-bay-right", ("pallets", 3, "position"), 1.5, "pallets[3].position"),
    ("pallet-overlap", ("pallets", 1, "position"), 0.9, "pallets[1].position"),
    ("level-missing", ("pallets", 1, "level"), 2, "pallets[1].level"),
    ("level-zero", ("pallets", 1, "level"), 0, "pallets[1].level"),
    ("bay-missing", ("pallets", 3, "bay"), 3, "pallets[3].bay"),
    ("unknown-section", ("geometry", "beam_section"), "girder", "geometry.beam_section"),
    ("nan", ("material", "E"), float("nan"), "material.E"),
    ("inf", ("pallets", 0, "mass"), float("inf"), "pallets[0].mass"),
    ("string-number", ("material", "density"), "7850", "material.density"),
    ("bool-number", ("pallets", 0, "mu_static"), True, "pallets[0].mu_static"),
    ("float-bay", ("pallets", 0, "bay"), 1.0, "pallets[0].bay"),
    ("bays-not-array", ("geometry", "bays"), 1.8, "geometry.bays"),
    ("subdivisions-zero", ("geometry", "subdivisions"), 0, "geometry.subdivisions"),
    ("bad-spring-word", ("connections", "base"), "fixed", "connections.base"),
    ("negative-spring", ("connections", "beam_to_upright"), -1.0,
     "connections.beam_to_upright"),
    ("bad-damping-kind", ("damping", "kind"), "modal", "damping.kind"),
    ("damping-ratio-too-large", ("damping", "ratio"), 1.5, "damping.ratio"),
    ("zero-g", ("g",), 0.0, "g"),
]


def bad_dict(path: tuple[Any, ...], value: Any) -> dict[str, Any]:
    return _set(paper_dict(), path, value)


def to_toml(d: dict[str, Any]) -> str:
    """Minimal TOML writer for the rack schema (tables, arrays of tables, scalars, arrays)."""
    def val(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, str):
            return '"' + v.replace('"', '\\"') + '"'
        if isinstance(v, float):
            if v != v:
                return "nan"
            if v in (float("inf"), float("-inf")):
                return "inf" if v > 0 else "-inf"
            return repr(v)
        if isinstance(v, list):
            return "[" + ", ".join(val(x) for x in v) + "]"
        return str(v)

    lines: list[str] = []
    scalars = {k: v for k, v in d.items() if not isinstance(v, dict | list)
               or (isinstance(v, list) and not (v and isinstance(v[0], dict)))}
    lines += [f"{k} = {val(v)}" for k, v in scalars.items()]

    def table(name: str, t: dict[str, Any]) -> None:
        flat = {k: v for k, v in t.items() if not isinstance(v, dict)}
        lines.append(f"[{name}]")
        lines.extend(f"{k} = {val(v)}" for k, v in flat.items())
        for k, v in t.items():
            if isinstance(v, dict):
                table(f"{name}.{k}", v)

    for k, v in d.items():
        if isinstance(v, dict):
            table(k, v)
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                lines.append(f"[[{k}]]")
                lines.extend(f"{kk} = {val(vv)}" for kk, vv in item.items())
    return "\n".join(lines) + "\n"
