"""Frame drawings: the undeformed rack and its mode shapes (matplotlib, imported lazily).

Every function takes ``ax=None`` (a new figure is made) and returns the Axes; nothing calls
``show()``. Deformed shapes interpolate each element with its exact shape functions (linear
axial, cubic Hermite transverse) so a coarse mesh still draws smooth curves.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from seisrack.atomic import save_figure
from seisrack.fe.elements import rotation
from seisrack.fe.mesh import FloatArray

_N_PTS = 11  # points drawn per element


def _axes(ax: Any) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def deformed_lines(model: Any, u: FloatArray, scale: float) -> FloatArray:
    """(n_el, _N_PTS, 2) [m] element centrelines displaced by ``scale · u`` (u: (n_dof,))."""
    mesh = model.mesh
    padded = np.append(np.asarray(u, dtype=float), 0.0)
    ue = padded[mesh.element_dofs]  # (n_el, 6), restrained -> 0
    c, s = mesh.direction_cosines
    L = mesh.lengths
    ul = np.einsum("eij,ej->ei", rotation(c, s), ue)
    xi = np.linspace(0.0, 1.0, _N_PTS)
    # Hermite cubics for the transverse displacement, linear for the axial one.
    h1, h2 = 1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3
    h3, h4 = 3 * xi**2 - 2 * xi**3, -(xi**2) + xi**3
    ax_d = ul[:, [0]] * (1 - xi) + ul[:, [3]] * xi
    tr_d = (ul[:, [1]] * h1 + ul[:, [2]] * L[:, None] * h2 + ul[:, [4]] * h3
            + ul[:, [5]] * L[:, None] * h4)
    p0 = mesh.nodes[mesh.elements[:, 0]]
    base = p0[:, None, :] + (xi[None, :, None] * L[:, None, None]) * np.stack([c, s], 1)[:, None]
    dx = scale * (ax_d * c[:, None] - tr_d * s[:, None])
    dy = scale * (ax_d * s[:, None] + tr_d * c[:, None])
    return base + np.stack([dx, dy], axis=-1)


def plot_frame(model: Any, ax: Any = None, *, color: str = "0.6", show_pallets: bool = True,
               **kw: Any) -> Any:
    """Draw the undeformed frame, its supports and (optionally) the pallet nodes."""
    ax = _axes(ax)
    mesh = model.mesh
    for i, j in mesh.elements:
        ax.plot(*mesh.nodes[[i, j]].T, color=color, lw=1.5, **kw)
    base = mesh.nodes[model.base_nodes]
    ax.plot(base[:, 0], base[:, 1], "k^", ms=8, clip_on=False)
    if show_pallets and model.n_pallets:
        p = mesh.nodes[model.pallet_node[:, 0]]
        ax.plot(p[:, 0], p[:, 1], "s", color="tab:orange", ms=7, label="pallets")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return ax


def plot_mode_shape(model: Any, modal: Any, mode: int = 1, ax: Any = None, *,
                    scale: float | None = None, color: str = "tab:blue") -> Any:
    """Draw mode ``mode`` (1-based) over the undeformed frame (a 3D rack on 3D axes:
    :func:`seisrack.report.frame_plot3d.plot_mode_shape_3d`).

    ``scale=None`` sets the largest nodal translation to 15 % of the frame's size.
    """
    if model.ndm == 3:
        from seisrack.report.frame_plot3d import plot_mode_shape_3d

        return plot_mode_shape_3d(model, modal, mode, ax, scale=scale, color=color)
    ax = plot_frame(model, ax, show_pallets=False)
    phi = modal.shapes[:, mode - 1]
    mesh = model.mesh
    if scale is None:
        trans = np.abs(phi[mesh.node_dofs[:, :2][mesh.node_dofs[:, :2] >= 0]]).max()
        size = np.ptp(mesh.nodes, axis=0).max()
        scale = 0.15 * size / trans if trans > 0 else 1.0
    for pts in deformed_lines(model, phi, scale):
        ax.plot(pts[:, 0], pts[:, 1], color=color, lw=2)
    ax.set_title(f"mode {mode}: T = {modal.periods[mode - 1]:.3f} s, "
                 f"{100 * modal.mass_participation[mode - 1]:.1f} % horiz. mass")
    return ax


def modes_figure(model: Any, modal: Any, n_shapes: int = 3, *, frame: bool = False) -> Any:
    """A figure with the first ``n_shapes`` mode shapes (3D axes for a 3D rack) and, with
    ``frame`` on a plane rack, the undeformed rack first. Returns the Figure."""
    import matplotlib.pyplot as plt

    n = max(1, min(n_shapes, modal.n_modes))
    frame = frame and model.ndm == 2
    panels = n + frame
    fig = plt.figure(figsize=(4.2 * panels, 4.2 if model.ndm == 3 else 4.0))
    proj = "3d" if model.ndm == 3 else None
    if frame:
        ax = fig.add_subplot(1, panels, 1)
        plot_frame(model, ax)
        ax.set_title(model.title or "rack", fontsize=9)
    for k in range(n):
        ax = plot_mode_shape(model, modal, k + 1,
                             fig.add_subplot(1, panels, k + 1 + frame, projection=proj))
        ax.title.set_fontsize(8)
    fig.tight_layout()
    return fig


def save_modes_figure(model: Any, modal: Any, path: str | Path, n_shapes: int = 3) -> Path:
    """Write a PNG with the undeformed rack and the first ``n_shapes`` mode shapes (Agg)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = modes_figure(model, modal, n_shapes, frame=True)
    out = Path(path)
    save_figure(fig, out, dpi=120)
    plt.close(fig)
    return out
