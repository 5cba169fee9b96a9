"""Result types of the paper report: a computed check, a figure and a report section."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["Check", "Figure", "Section", "fmt", "md_table", "pyplot"]


@dataclass(frozen=True)
class Check:
    """A pass/fail statement computed from the results.

    ``found`` states the numbers obtained, ``criterion`` what passing means.
    """

    section: str
    name: str
    passed: bool
    found: str
    criterion: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "section": self.section, "name": self.name, "passed": bool(self.passed),
            "found": self.found, "criterion": self.criterion,
        }


@dataclass(frozen=True)
class Figure:
    """A PNG written by the report, with its caption."""

    path: Path
    caption: str


@dataclass
class Section:
    """One section of the report.

    ``data`` is JSON-ready (numbers, lists, dicts); ``seconds`` and ``cpu_seconds`` are the wall
    and CPU time (of the process that ran it) of the computation and the figures.
    """

    key: str
    title: str
    data: dict[str, Any] = field(default_factory=dict)
    figures: list[Figure] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)
    seconds: float = 0.0
    cpu_seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "data": self.data,
            "figures": [{"file": f.path.name, "caption": f.caption} for f in self.figures],
            "checks": [c.to_dict() for c in self.checks],
            "seconds": round(self.seconds, 3),
            "cpu_seconds": round(self.cpu_seconds, 3),
        }


def fmt(x: float | None, digits: int = 3) -> str:
    """Compact number for tables: ``digits`` significant figures, ``–`` for None."""
    if x is None:
        return "–"
    return f"{x:.{digits}g}"


def md_table(header: list[str], rows: list[list[str]], align: str | None = None) -> str:
    """A GitHub-flavoured Markdown table; ``align`` is one letter (l/r/c) per column."""
    align = align or "l" + "r" * (len(header) - 1)
    sep = {"l": ":--", "r": "--:", "c": ":-:"}
    lines = [
        "| " + " | ".join(header) + " |",
        "|" + "|".join(sep[a] for a in align) + "|",
    ]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def pyplot() -> Any:
    """matplotlib.pyplot on the non-interactive Agg backend (imported lazily)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    return plt
