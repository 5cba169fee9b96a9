"""3D rack drawings: the undeformed rack and its mode shapes (matplotlib, imported lazily).

Every function takes ``ax=None`` (a new figure with a 3D Axes is made) and returns the Axes;
nothing calls ``show()``. Members are drawn as straight lines between their displaced nodes
(the mesh subdivides every member, so shapes stay readable). Axes: x down-aisle, z
cross-aisle, y up (drawn as matplotlib's vertical axis).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from seisrack.fe.mesh import FloatArray


def _axes(ax: Any) -> Any:
    if ax is None:
        import matplotlib.pyplot as plt

        fig = plt.figure()
        ax = fig.add_subplot(projection="3d")
    return ax


def _segments(model: Any) -> np.ndarray:
    m = model.mesh
    return np.concatenate([m.elements, m.trusses]) if m.trusses.size else m.elements


def displaced_nodes(model: Any, u: FloatArray, scale: float) -> FloatArray:
    """(n_node, 3) [m] node coordinates displaced by ``scale`` times the translations of u."""
    padded = np.append(np.asarray(u, dtype=float), 0.0)
    return model.mesh.nodes + scale * padded[model.mesh.node_dofs[:, :3]]


def _draw(ax: Any, X: FloatArray, segs: np.ndarray, **kw: Any) -> None:
    for i, j in segs:
        ax.plot(X[[i, j], 0], X[[i, j], 2], X[[i, j], 1], **kw)


def plot_frame_3d(model: Any, ax: Any = None, *, color: str = "0.6") -> Any:
    """Draw the undeformed 3D rack (members, bracing) and its base nodes."""
    ax = _axes(ax)
    _draw(ax, model.mesh.nodes, _segments(model), color=color, lw=1.0)
    b = model.mesh.nodes[model.base_nodes.ravel()]
    ax.plot(b[:, 0], b[:, 2], b[:, 1], "k^", ms=5, ls="none")
    ext = np.ptp(model.mesh.nodes, axis=0)
    ax.set_box_aspect((ext[0], max(ext[2], 0.2 * ext.max()), ext[1]))  # x, z, y: true shape
    ax.locator_params(axis="y", nbins=3)  # matplotlib's y is the rack's z (depth): few ticks
    ax.set_xlabel("x down-aisle [m]")
    ax.set_ylabel("z cross-aisle [m]")
    ax.set_zlabel("y [m]")
    return ax


def plot_mode_shape_3d(model: Any, modal: Any, mode: int = 1, ax: Any = None, *,
                       scale: float | None = None, color: str = "tab:blue") -> Any:
    """Draw mode ``mode`` (1-based) over the undeformed rack; ``scale=None`` sets the largest
    nodal translation to 15 % of the rack's size."""
    ax = plot_frame_3d(model, ax, color="0.8")
    phi = modal.shapes[:, mode - 1]
    nd = model.mesh.node_dofs[:, :3]
    if scale is None:
        trans = np.abs(phi[nd[nd >= 0]]).max()
        size = np.ptp(model.mesh.nodes, axis=0).max()
        scale = 0.15 * size / trans if trans > 0 else 1.0
    _draw(ax, displaced_nodes(model, phi, scale), _segments(model), color=color, lw=1.5)
    label = ""
    if getattr(modal, "direction", ()):
        label = f", {modal.direction[mode - 1]}"
    ax.set_title(f"mode {mode}: T = {modal.periods[mode - 1]:.3f} s{label}", fontsize=9)
    return ax
