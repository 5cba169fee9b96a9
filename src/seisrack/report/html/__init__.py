"""The engineer's HTML report of one rack and one record (issue #14 item 1).

:func:`write_html_report` writes ONE self-contained file: inline CSS, figures as base64 PNG
(matplotlib) and, when plotly is installed, interactive time histories with plotly's JavaScript
bundled in the file (static figures otherwise). It opens offline and prints on A4. This is the
engineer's report, apart from the paper's reproduction (``seisrack.paper``).
"""

from __future__ import annotations

import datetime as _dt
import os
from pathlib import Path
from typing import Any

from seisrack.errors import InputError
from seisrack.report.html.page import build_html
from seisrack.report.html.study_page import build_study_html, write_study_report

__all__ = ["build_html", "build_study_html", "write_html_report", "write_study_report"]


def check_report_path(path: str | os.PathLike[str], force: bool = False,
                      field: str = "path") -> Path:
    """Refuse an existing report without ``force`` and an unwritable place, before any work;
    create the report's folder if needed."""
    p = Path(path)
    if p.is_dir():
        raise InputError(field, str(p), "a file name for the HTML report (this is a folder)")
    if p.exists() and not force:
        raise InputError(field, str(p), "a path that does not exist yet",
                         hint="The report exists; pass force=True (--force) to overwrite it")
    parent = p.parent if str(p.parent) else Path(".")
    if parent.exists() and not parent.is_dir():
        raise InputError(field, str(p), "a path in a folder",
                         hint=f"{parent} is a file, not a folder")
    try:  # created if needed, as `seisrack run --out DIR` does
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(field, str(p), "a path in a folder that can be created",
                         hint=f"{parent}: {exc.strerror or exc}") from None
    if not os.access(parent, os.W_OK) or (p.exists() and not os.access(p, os.W_OK)):
        raise InputError(field, str(p), "a writable path",
                         hint=f"Permission denied in {parent}")
    return p


def write_atomically(p: Path, text: str) -> Path:
    """Write ``text`` to a temporary file beside ``p``, then rename it: a reader never sees a
    half-written report, and a failed write leaves what was there."""
    from seisrack.atomic import write_text

    try:
        write_text(p, text)
    except OSError as exc:
        raise InputError("path", str(p), "a writable path",
                         hint=str(exc.strerror or exc)) from None
    return p


def write_html_report(path: str | os.PathLike[str], *, spec: Any, model: Any, response: Any,
                      record: Any, summary: dict[str, Any], modal: Any = None,
                      checks: dict[str, Any] | None = None, force: bool = False,
                      design_spectrum: Any = None, rack_file: str | None = None,
                      seed: int | None = None, interactive: bool | None = None,
                      design_section: dict[str, Any] | None = None) -> Path:
    """Write the HTML report of ``response`` (a RackResponse of ``model`` under ``record``).

    summary: the dict written to summary.json (the tables show its numbers exactly);
    modal: ModalResult (modal section skipped if None); checks: the result of
    :func:`seisrack.checks.run_design_checks`; design_spectrum: EC8 spectrum drawn against the
    record's spectrum; interactive: use plotly (default: if installed); design_section: the
    keyword arguments of :func:`seisrack.report.html.design.design_section_html` (the design
    analysis and the sliding reduction), section omitted if None.
    Raises InputError if ``path`` exists (without ``force``) or cannot be written.
    """
    p = check_report_path(path, force)
    text = build_html(spec=spec, model=model, response=response, record=record,
                      summary=summary, modal=modal, checks=checks,
                      design_spectrum=design_spectrum, rack_file=rack_file, seed=seed,
                      interactive=interactive, date=_dt.datetime.now().isoformat(
                          timespec="seconds"), design_section=design_section)
    return write_atomically(p, text)
