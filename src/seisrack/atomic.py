"""Writing files so that a reader never sees half of one (issue 23).

Every writer of seisrack writes to a hidden temporary file in the target's own folder and
renames it over the target with :func:`os.replace` (atomic on POSIX and Windows within one
file system). If anything fails on the way (a full disk, a read-only folder, an exception in
the writer, Ctrl-C) the temporary file is removed and the target is left as it was. An
:class:`OSError` is re-raised naming the *target* path (not the temporary name), so the
command-line boundary can tell the user which file could not be written and why.

The temporary name keeps the target's suffix (``.fig.png.1234.tmp.png``) because some writers
(matplotlib's ``savefig``, ``numpy.savetxt``) choose the format from it.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

__all__ = ["atomic_write", "save_figure", "temporary_sibling", "write_bytes", "write_text"]

#: prefix and marker of the temporary files (hidden; ``*.tmp*`` in every listing)
TMP_MARK = ".tmp"


def temporary_sibling(path: str | os.PathLike[str]) -> Path:
    """The temporary name used for ``path`` by this process (same folder, hidden)."""
    p = Path(path)
    return p.with_name(f".{p.name}.{os.getpid()}{TMP_MARK}{p.suffix}")


def atomic_write(path: str | os.PathLike[str], write: Callable[[Path], Any]) -> Path:
    """Call ``write(tmp)`` on a temporary sibling of ``path``, then rename it to ``path``.

    On any exception the temporary file is removed and the target is untouched; an
    :class:`OSError` is re-raised with ``filename`` set to ``path``. Returns ``Path(path)``.
    """
    target = Path(path)
    tmp = temporary_sibling(target)
    try:
        write(tmp)
        os.replace(tmp, target)
    except OSError as exc:
        _remove(tmp)
        if exc.filename in (None, str(tmp), tmp):
            raise OSError(exc.errno, exc.strerror or str(exc), str(target)) from None
        raise
    except BaseException:
        _remove(tmp)
        raise
    return target


def write_text(path: str | os.PathLike[str], text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"))


def write_bytes(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    return atomic_write(path, lambda p: p.write_bytes(data))


def save_figure(fig: Any, path: str | os.PathLike[str], **kwargs: Any) -> Path:
    """``fig.savefig(path, **kwargs)``, atomically (the format from the suffix of ``path``)."""
    fmt = kwargs.pop("format", None) or (Path(path).suffix.lstrip(".").lower() or "png")
    known = fig.canvas.get_supported_filetypes()
    if fmt not in known:
        from seisrack.errors import InputError

        raise InputError("figure file", str(path), "a file name ending in "
                         + ", ".join(f".{k}" for k in sorted(known)))
    return atomic_write(path, lambda p: fig.savefig(p, format=fmt, **kwargs))


def _remove(tmp: Path) -> None:
    try:
        tmp.unlink()
    except FileNotFoundError:
        pass
    except OSError:  # pragma: no cover - nothing more can be done; the name is hidden
        pass
