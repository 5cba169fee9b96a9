"""A stick–slip engine whose work per step grows linearly with the length of the structure
(issue 22; theory: ``docs/theory/local_engine.md``): a local basis with block-tridiagonal
reduced matrices, the trapezoidal rule in impulse form, and each pallet's contact events
resolved on its own inside the global step."""

from seisrack.dynamics.local.basis import LocalBasis, local_basis, measure_error
from seisrack.dynamics.local.sliders import LocalSliders

__all__ = ["LocalBasis", "LocalSliders", "local_basis", "measure_error"]
