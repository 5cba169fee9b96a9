"""Rack specification (TOML → frozen dataclasses) and its compilation to a FrameModel."""

from seisrack.model.compile import compile_rack
from seisrack.model.frame_model import BEAM, DIRECTIONS, UPRIGHT, FrameModel
from seisrack.model.load import load_rack, rack_from_dict
from seisrack.model.pallet_layout import sliding_limits
from seisrack.model.spec import (
    Connections,
    Damping,
    Geometry,
    Material,
    Pallet,
    RackSpec,
    SecondOrder,
    Section,
    with_friction,
)

__all__ = [
    "BEAM", "DIRECTIONS", "UPRIGHT", "Connections", "Damping", "FrameModel", "Geometry",
    "Material", "Pallet", "RackSpec", "SecondOrder", "Section", "compile_rack", "load_rack",
    "rack_from_dict", "sliding_limits", "with_friction",
]
