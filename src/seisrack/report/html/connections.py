"""The "Connections" section of the HTML report: the nonlinear connections of the run
(``summary["hinges"]``, :meth:`RackResponse.hinge_summary`) as a table and their
moment–rotation loops. Absent for a rack whose connections are all elastic."""

from __future__ import annotations

from typing import Any

from seisrack.report.html import figures as F
from seisrack.report.html.tables import _table_rows, esc, num_cell

#: (summary key, header, factor to the shown unit, format) of the hinge table's number columns
HINGE_COLUMNS: list[tuple[str, str, float, str]] = [
    ("peak_rotation_rad", "peak |rotation| [mrad]", 1e3, "{:.2f}"),
    ("peak_moment_Nm", "peak |moment| [kN·m]", 1e-3, "{:.3f}"),
    ("residual_rotation_rad", "residual rotation [mrad]", 1e3, "{:.2f}"),
    ("ductility", "ductility [-]", 1.0, "{:.2f}"),
]


def hinge_table(hinges: dict[str, Any]) -> str:
    """One row per hinge; each number cell holds the exact summary.json value."""
    headers = ["hinge", "kind", "law"] + [c[1] for c in HINGE_COLUMNS] + ["yielded"]
    rows = []
    for i, r in enumerate(hinges.get("hinges", [])):
        cells = [f'<td data-key="hinge">{esc(r["hinge"])}</td>',
                 f'<td data-key="kind">{esc(r["kind"])}</td>',
                 f'<td data-key="law">{esc(r["law"])}</td>']
        cells += [num_cell(r.get(k), f, fmt, k) if r.get(k) is not None
                  else f'<td data-key="{esc(k)}">–</td>' for k, _, f, fmt in HINGE_COLUMNS]
        cells.append(f'<td data-key="yielded">{"YIELDED" if r["yielded"] else "no"}</td>')
        rows.append(f'<tr data-hinge="{i}">' + "".join(cells) + "</tr>")
    return _table_rows("table-hinges", headers, rows,
                       "Per connection hinge (beam-to-upright connector: level, bay, end; base "
                       "plate: upright): peak |rotation| and |moment| over the kept samples, "
                       "rotation at the end of the record, ductility = peak rotation / yield "
                       "rotation (– for an elastic hinge). Rotations from the zero-moment "
                       "state, gravity included.")


def hinge_overview(hinges: dict[str, Any], energy: dict[str, Any]) -> str:
    """A sentence: how many yielded, the largest ductility, the hysteretic energy."""
    parts = [f"{hinges['yielded']} of {hinges['count']} connection hinges yielded"]
    if hinges.get("peak_ductility") is not None:
        parts.append(f"largest ductility demand {hinges['peak_ductility']:.2f} at "
                     f"{hinges['peak_ductility_hinge']}")
    hyst, e_in = hinges.get("hysteretic_energy_J"), (energy or {}).get("input")
    if hyst is not None:
        share = f" ({100 * hyst / e_in:.1f} % of the input energy)" if e_in else ""
        parts.append(f"hysteretic energy dissipated by the connections {hyst:.4g} J{share}")
    return ('<p class="hinge-overview" data-key="hinges">' + esc("; ".join(parts)) + ".</p>")


def connections_html(summary: dict[str, Any], response: Any) -> str:
    """The section body: overview, hinge table and the loops figure ('' without hinges)."""
    hinges = summary.get("hinges")
    if not hinges:
        return ""
    out = [hinge_overview(hinges, summary.get("energy_J") or {}), hinge_table(hinges)]
    out.append("<p><small>The design operators' connector moment (k·θ, elastic) is not the "
               "connector's moment once it yields; the moments above are those of the hinge "
               "law.</small></p>")
    if getattr(response, "hinges", None) is not None:
        from seisrack.report.hinge_plot import hinge_loops_figure

        fig = hinge_loops_figure(response.hinges)
        cap = ("Moment [kN·m] against rotation [mrad] of the most-demanded beam-to-upright "
               "connectors and base plates (kept samples); dashed: yield moment of a yielded "
               "elastic-plastic hinge.")
        out.append(f'<figure id="fig-hinge-loops"><img src="{F.png_data_uri(fig)}" '
                   f'alt="{esc(cap)}"><figcaption>{esc(cap)}</figcaption></figure>')
    return "".join(out)
