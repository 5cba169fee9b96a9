"""Rack earthquake time histories: FrameModel + ground motion -> stick–slip engine -> rack
results, one path for 2D and 3D racks."""

from seisrack.analysis.prepare import PreparedRun, prepare_run
from seisrack.analysis.rack import RackResponse, analysis_grid, run_rack

__all__ = ["PreparedRun", "RackResponse", "analysis_grid", "prepare_run", "run_rack"]
