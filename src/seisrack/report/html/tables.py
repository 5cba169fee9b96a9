"""HTML tables of the report: each number cell carries the exact JSON value in ``data-value``
(what ``summary.json`` holds) and shows it formatted with its unit in the header."""

from __future__ import annotations

import html
import json
import math
from typing import Any

#: (summary key, header, factor to the shown unit, format) of the known per-pallet columns
PALLET_COLUMNS: list[tuple[str, str, float, str]] = [
    ("mass_kg", "mass [kg]", 1.0, "{:.1f}"),
    ("mu_static", "μ static [-]", 1.0, "{:.3f}"),
    ("mu_dynamic", "μ dynamic [-]", 1.0, "{:.3f}"),
    ("peak_sliding_m", "peak sliding [mm]", 1e3, "{:.3f}"),
    ("residual_m", "residual [mm] (x / z)", 1e3, "{:.3f}"),
    ("limit_neg_m", "free distance −x [mm]", 1e3, "{:.1f}"),
    ("limit_pos_m", "free distance +x [mm]", 1e3, "{:.1f}"),
    ("fall_utilisation", "sliding / free distance [-]", 1.0, "{:.3f}"),
]
_SKIP_PALLET = {"label", "id", "sliding_phases", "falls"}


def esc(x: Any) -> str:
    return html.escape(str(x), quote=True)


def _unit_factor(key: str) -> tuple[str, float]:
    """Shown unit of a summary key by its suffix (SI in, engineer's unit out)."""
    for suffix, unit, f in (("_m_s2", "m/s²", 1.0), ("_mm", "mm", 1.0), ("_m", "mm", 1e3),
                            ("_Nm", "kN·m", 1e-3), ("_N", "kN", 1e-3), ("_kg", "kg", 1.0),
                            ("_s", "s", 1.0), ("_rad", "rad", 1.0), ("_ratio", "-", 1.0)):
        if key.endswith(suffix):
            return unit, f
    return "-", 1.0


def header_of(key: str) -> str:
    unit, _ = _unit_factor(key)
    name = key
    for suffix in ("_m_s2", "_Nm", "_N", "_kg", "_m", "_s", "_rad"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
            break
    return f"{name.replace('_', ' ')} [{unit}]"


def _shown(value: float, factor: float, fmt: str) -> str:
    return "∞" if math.isinf(value) else ("–" if value != value else fmt.format(value * factor))


def num_cell(value: Any, factor: float = 1.0, fmt: str = "{:.4g}", key: str = "") -> str:
    """A <td> whose data-value is the exact JSON text of ``value``: a number, or a list of
    numbers (one per horizontal direction, shown "x / z")."""
    if isinstance(value, list) and value and all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        shown = " / ".join(_shown(v, factor, fmt) for v in value)
        return (f'<td class="num" data-key="{esc(key)}" data-value="{esc(json.dumps(value))}">'
                f"{shown}</td>")
    if isinstance(value, bool) or not isinstance(value, int | float):
        return f'<td data-key="{esc(key)}">{esc(value)}</td>'
    raw = json.dumps(value)
    return (f'<td class="num" data-key="{esc(key)}" data-value="{esc(raw)}">'
            f"{_shown(value, factor, fmt)}</td>")


def pallet_table(summary: dict[str, Any]) -> str:
    pallets = summary.get("pallets", [])
    extra = sorted({k for p in pallets for k, v in p.items()
                    if k not in _SKIP_PALLET and k not in {c[0] for c in PALLET_COLUMNS}
                    and isinstance(v, int | float) and not isinstance(v, bool)})
    headers = ["#", "pallet"] + [c[1] for c in PALLET_COLUMNS] + [header_of(k) for k in extra]
    rows = []
    for j, p in enumerate(pallets):
        pid = p.get("id", j + 1)
        cells = [f'<td data-key="id">{esc(pid)}</td>', f'<td>{esc(p.get("label", ""))}</td>']
        cells += [num_cell(p.get(k), f, fmt, k) if k in p else "<td>–</td>"
                  for k, _, f, fmt in PALLET_COLUMNS]
        cells += [num_cell(p[k], _unit_factor(k)[1], "{:.4g}", k) if k in p else "<td>–</td>"
                  for k in extra]
        cls = ' class="risk"' if p.get("fall_utilisation", 0) >= 1 or p.get("falls") else ""
        rows.append(f'<tr{cls} data-pallet="{j}">' + "".join(cells) + "</tr>")
    return _table_rows("table-pallets", headers, rows,
                       "Per pallet: sliding relative to the beam (peak over every analysis "
                       "step; on a 3D rack the magnitude, and each direction), residual at the "
                       "end, free distance down-aisle on each side and utilisation (>= 1: it "
                       "reached a neighbour or an upright), fall limits cross-aisle. Red rows: "
                       "at risk or falling.")


def _table_rows(table_id: str, headers: list[str], rows: list[str], caption: str) -> str:
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    return (f'<table id="{esc(table_id)}"><caption>{esc(caption)}</caption>'
            f"<thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>")


def level_table(summary: dict[str, Any], level_y: Any) -> str:
    per = summary.get("peaks", {}).get("per_level", {})
    keys = [k for k, v in per.items() if isinstance(v, list)]
    n = max((len(per[k]) for k in keys), default=0)
    headers = ["level", "height [m]"] + [header_of(k) for k in keys]
    rows = []
    for i in range(n):
        cells = [f"<td>{i + 1}</td>", f"<td>{float(level_y[i]):.3f}</td>"
                 if i < len(level_y) else "<td>–</td>"]
        cells += [num_cell(per[k][i], _unit_factor(k)[1], "{:.4g}", k) if i < len(per[k])
                  else "<td>–</td>" for k in keys]
        rows.append(f'<tr data-level="{i}">' + "".join(cells) + "</tr>")
    return _table_rows("table-levels", headers, rows,
                       "Per beam level: peaks over every analysis step (absolute acceleration, "
                       "displacement relative to the ground, total pallet-beam contact force; "
                       "down-aisle / cross-aisle on a 3D rack).")


def peaks_table(summary: dict[str, Any]) -> str:
    pk = summary.get("peaks", {})
    rows = []
    for k, v in pk.items():
        if isinstance(v, int | float) and not isinstance(v, bool):
            unit, f = _unit_factor(k)
            rows.append(f'<tr data-peak="{esc(k)}"><td>{esc(header_of(k))}</td>'
                        + num_cell(v, f, "{:.4g}", k) + "</tr>")
    return _table_rows("table-peaks", ["quantity", "peak"], rows,
                       "Peaks of the rack over every analysis step.")


def generic_tables(summary: dict[str, Any], known: set[str]) -> list[str]:
    """Tables of summary entries this report does not know (added by later versions):
    a list of dicts becomes a table, a dict of numbers a two-column table."""
    out = []
    for key, val in summary.items():
        if key in known:
            continue
        if isinstance(val, list) and val and all(isinstance(r, dict) for r in val):
            cols = [c for c in val[0] if not isinstance(val[0][c], dict | list)]
            rows = ["".join(num_cell(r.get(c), _unit_factor(c)[1], "{:.4g}", c) for c in cols)
                    for r in val]
            out.append(_table_rows(f"table-{key}", [header_of(c) for c in cols],
                                   [f"<tr>{r}</tr>" for r in rows], f"{key} (from summary.json)"))
        elif isinstance(val, dict):
            rows = [f"<tr><td>{esc(header_of(k))}</td>"
                    + num_cell(v, _unit_factor(k)[1], "{:.4g}", k) + "</tr>"
                    for k, v in val.items() if isinstance(v, int | float | str)]
            if rows:
                out.append(_table_rows(f"table-{key}", ["quantity", "value"], rows,
                                       f"{key} (from summary.json)"))
    return out
