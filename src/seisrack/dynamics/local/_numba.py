"""numba-compiled build of the local engine's kernel sources: the planar engine's disc
problem (``_planar_contact.py`` with what it imports) and ``_btd.py``, ``_pallet.py``,
``_kernel.py``, compiled as one hash-named file (:mod:`seisrack.dynamics._numba_build`)."""

from seisrack.dynamics._numba_build import JIT as _JIT  # noqa: F401  (used by the sources)
from seisrack.dynamics._numba_build import combined_source

_SRC = combined_source(("_events.py", "_lapack.py", "_planar_step.py",
                        "_planar_contact.py", "local/_blas.py", "local/_btd.py", "local/_pallet.py",
                        "local/_kernel.py"), "_local")
exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
