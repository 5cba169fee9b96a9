"""numba-compiled build of ``_hyst_base.py``, ``_hyst_pinching.py``, ``_hysteresis.py``,
``_events.py``, ``_linalg.py``, ``_contact.py``, ``_kernel_hinge.py``, ``_kernel.py``,
``_exact_modes.py``, ``_exact_config.py`` and ``_kernel_exact.py`` (the same sources,
executed in this order with ``_JIT = njit`` in one namespace).

numba's on-disk cache keys each function on the timestamp of *its own* source file, while a
compiled caller embeds the code of the callees it uses from the other files: after an edit of
``_exact_modes.py`` alone, ``run_kernel_exact`` would load from the cache with the old callees.
So the sources are concatenated into one file named by the hash of their content
(``__pycache__/_kernels_<hash>.py``, or the temporary folder when the package is read-only),
and compiled from there: any edit of any of them gives a new file and a fresh cache.
"""

import hashlib
import tempfile
from pathlib import Path

import numba

#: "numpy" error model: a float division by zero gives inf / nan (caught as a non-finite
#: state) instead of raising; without the raise paths numba can drop the reference counting
#: of a leaf function's array arguments (an atomic increment and decrement each per call)
_OPTIONS = {"cache": True, "error_model": "numpy"}
_JIT = numba.njit(**_OPTIONS)
_NAMES = ("_hyst_base.py", "_hyst_pinching.py", "_hysteresis.py", "_events.py", "_linalg.py",
          "_contact.py", "_kernel_hinge.py", "_kernel.py", "_exact_modes.py", "_exact_config.py",
          "_kernel_exact.py")


def _combined_source() -> Path:
    here = Path(__file__).parent
    parts = [f"# ---- {n}\n" + here.joinpath(n).read_text(encoding="utf-8") for n in _NAMES]
    # the options are part of the hashed text: numba's cache does not key on them
    text = f"# numba.njit options: {_OPTIONS}\n" + "\n".join(parts)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    for folder in (here / "__pycache__", Path(tempfile.gettempdir()) / "seisrack-kernels"):
        path = folder / f"_kernels_{digest}.py"
        try:
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                folder.mkdir(parents=True, exist_ok=True)
                tmp = path.with_suffix(f".{id(text)}.tmp")
                tmp.write_text(text, encoding="utf-8")
                tmp.replace(path)
            return path
        except OSError:
            continue
    raise OSError("seisrack: no writable place for the compiled kernels' source")


_SRC = _combined_source()
exec(compile(_SRC.read_text(encoding="utf-8"), str(_SRC), "exec"))  # noqa: S102
