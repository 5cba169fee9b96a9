"""numba-compiled build of the hysteresis laws (``_hyst_base.py``, ``_hyst_pinching.py``,
``_hysteresis.py``), ``_events.py``, ``_lapack.py``, ``_planar_hinges.py``,
``_planar_step.py``, ``_planar_axial.py``, ``_planar_stage.py``, ``_planar_contact.py``,
``_planar_events.py`` and
``_kernel_planar.py``
(the planar stick–slip kernel with the shared event core), compiled apart from the 2D kernels
so that neither recompiles when the other changes (:mod:`seisrack.dynamics._numba_build`)."""

from seisrack.dynamics._numba_build import JIT as _JIT  # noqa: F401  (used by the sources)
from seisrack.dynamics._numba_build import combined_source

_SRC = combined_source(("_hyst_base.py", "_hyst_pinching.py", "_hysteresis.py", "_events.py",
                        "_lapack.py", "_planar_hinges.py", "_planar_step.py",
                        "_planar_axial.py", "_planar_stage.py", "_planar_contact.py",
                        "_planar_events.py",
                        "_kernel_planar.py"),
                       "_planar")
exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
