"""Rack earthquake time histories: FrameModel + Record -> stick–slip engine -> rack results."""

from seisrack.analysis.rack import RackResponse, analysis_grid, run_rack

__all__ = ["RackResponse", "analysis_grid", "run_rack"]
