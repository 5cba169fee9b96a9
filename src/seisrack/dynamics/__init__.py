"""Exact stick–slip dynamics of linear structures carrying sliding masses."""

from seisrack.dynamics.engine import modal_basis, simulate
from seisrack.dynamics.results import Event, TimeHistory
from seisrack.dynamics.sliders import PlanarSliders, Sliders

__all__ = ["Event", "PlanarSliders", "Sliders", "TimeHistory", "modal_basis", "simulate"]
