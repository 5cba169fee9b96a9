"""2D or 3D: the guard for what only the 2D rack supports yet (the engineer's report,
studies, exports, the 2D time history API), shared by the 3D spec, mesh and compiled model."""

from __future__ import annotations

from seisrack.errors import InputError

RUN_3D_MESSAGE = ("3D racks support seisrack modal and seisrack run for now; the engineer's "
                  "report, studies and the OpenSees export are 2D-only")


def require_2d(spec_or_model: object, field: str = "geometry.depth",
               depth: float | None = None) -> None:
    """Raise InputError for a 3D rack (spec, compiled model or, with ``depth``, its mesh)
    where only 2D is supported, e.g. at the top of a time history (``seisrack run``)."""
    is_3d = depth is not None or getattr(spec_or_model, "is_3d", False)
    if is_3d:
        if depth is None:
            depth = getattr(spec_or_model, "depth", None)
        if depth is None:
            depth = spec_or_model.geometry.depth  # type: ignore[attr-defined]
        raise InputError(field, depth, "a 2D rack (no [geometry] depth) for this command "
                         "(reports, studies, exports)", hint=RUN_3D_MESSAGE)
