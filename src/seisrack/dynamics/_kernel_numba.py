"""numba-compiled build of ``_hyst_base.py``, ``_hyst_pinching.py``, ``_hysteresis.py``,
``_events.py``, ``_lapack.py``, ``_linalg.py``, ``_contact.py``, ``_kernel_hinge.py``,
``_kernel_stage.py``, ``_kernel.py``, ``_exact_modes.py``, ``_exact_config.py`` and
``_kernel_exact.py`` (the same
sources, executed in this order with ``_JIT = njit`` in one namespace; see
:mod:`seisrack.dynamics._numba_build` for why they are compiled from one hash-named file).
"""

from seisrack.dynamics._numba_build import JIT as _JIT  # noqa: F401  (used by the sources)
from seisrack.dynamics._numba_build import combined_source

_NAMES = ("_hyst_base.py", "_hyst_pinching.py", "_hysteresis.py", "_events.py", "_lapack.py",
          "_linalg.py", "_contact.py", "_kernel_hinge.py", "_kernel_stage.py", "_kernel.py",
          "_exact_modes.py", "_exact_config.py", "_kernel_exact.py")

_SRC = combined_source(_NAMES, "_kernels")
exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
