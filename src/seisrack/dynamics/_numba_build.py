"""Compile a group of kernel sources with numba, as one file named by the hash of their text.

numba's on-disk cache keys each function on the timestamp of *its own* source file, while a
compiled caller embeds the code of the callees it uses from the other files: after an edit of
one callee's file alone, a caller would load from the cache with the old callee. So the sources
of a group are concatenated into one file named by the hash of their content
(``__pycache__/<stem>_<hash>.py``, or the temporary folder when the package is read-only) and
compiled from there: any edit of any of them gives a new file and a fresh cache.
"""

import hashlib
import tempfile
from pathlib import Path

import numba

#: "numpy" error model: a float division by zero gives inf / nan (caught as a non-finite
#: state) instead of raising; without the raise paths numba can drop the reference counting
#: of a leaf function's array arguments (an atomic increment and decrement each per call)
OPTIONS = {"cache": True, "error_model": "numpy"}
JIT = numba.njit(**OPTIONS)


def combined_source(names: tuple[str, ...], stem: str) -> Path:
    """Path of the concatenated, hash-named source of the files ``names`` of this package."""
    here = Path(__file__).parent
    parts = [f"# ---- {n}\n" + here.joinpath(n).read_text(encoding="utf-8") for n in names]
    # the options are part of the hashed text: numba's cache does not key on them
    text = f"# numba.njit options: {OPTIONS}\n" + "\n".join(parts)
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]
    for folder in (here / "__pycache__", Path(tempfile.gettempdir()) / "seisrack-kernels"):
        path = folder / f"{stem}_{digest}.py"
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
