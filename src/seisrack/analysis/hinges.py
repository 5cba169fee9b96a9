"""The rack's connections as engine hinges, and their response (issue #12).

Every beam-to-upright connector and semi-rigid base plate is a rotational spring of the
compiled model (:attr:`FrameModel.hinge_dofs`). When ``[hysteresis]`` gives one of them a
nonlinear law, the run hands them to the engine as :class:`~seisrack.dynamics.hinges.Hinges`
and reports their rotations, moments and the hysteretic energy.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.dynamics.hinges import Hinges
from seisrack.dynamics.results import TimeHistory
from seisrack.model.frame_model import BASE_PLATE, BEAM, FrameModel


@dataclass(frozen=True)
class HingeResponse:
    """Rotations and moments of the rack's nonlinear hinges (kept samples).

    labels: (n_h,) e.g. ``"connector L1 B2 left"`` (the beam of level 1, bay 2, at its left
    end) or ``"base U3"``; kind: (n_h,) "connector" / "base"; law: (n_h,) the law's name;
    rotation: (n_t, n_h) [rad]; moment: (n_t, n_h) [N·m]; yield_rotation: (n_h,) [rad]
    (``inf`` for an elastic hinge).
    """

    labels: tuple[str, ...]
    kind: tuple[str, ...]
    law: tuple[str, ...]
    rotation: np.ndarray
    moment: np.ndarray
    yield_rotation: np.ndarray
    peak_rotation: np.ndarray | None = None  # (n_h,) over every analysis step
    peak_moment: np.ndarray | None = None

    def peaks(self) -> list[dict]:
        """Per hinge: peak |rotation|, |moment| (over every analysis step when the run tracked
        them, else over the kept samples), residual rotation, ductility demand."""
        out = []
        for i, lab in enumerate(self.labels):
            th = self.rotation[:, i]
            mom = self.moment[:, i]
            peak = float(np.max(np.abs(th))) if th.size else 0.0
            if self.peak_rotation is not None:
                peak = max(peak, float(self.peak_rotation[i]))
            ty = float(self.yield_rotation[i])
            out.append({
                "hinge": lab, "kind": self.kind[i], "law": self.law[i],
                "peak_rotation_rad": peak,
                "peak_moment_Nm": max(float(np.max(np.abs(mom))) if mom.size else 0.0,
                                      0.0 if self.peak_moment is None
                                      else float(self.peak_moment[i])),
                "residual_rotation_rad": float(th[-1]) if th.size else 0.0,
                "ductility": peak / ty if np.isfinite(ty) and ty > 0 else None,
                "yielded": bool(np.isfinite(ty) and peak > ty * (1 + 1e-9)),
            })
        return out


_LAW_NAMES = {0: "elastic", 1: "elastic-plastic", 2: "bilinear", 3: "pinching"}


def rack_hinges(model: FrameModel) -> Hinges | None:
    """The model's connection springs as engine hinges, with the P-Δ of the current axial
    forces when the rack asks for it; None when every connection is elastic and the axial
    forces are the gravity ones."""
    if not model.nonlinear_hinges and model.axial_p_delta is None:
        return None
    return Hinges(model.hinge_dofs, model.hinge_k, model.hinge_law, model.hinge_par,
                  model.hinge_rotation_gravity, axial=model.axial_p_delta)


def hinge_labels(model: FrameModel) -> tuple[str, ...]:
    """A readable name per hinge: its beam (level, bay, end) or its upright (base); on a 3D
    rack also its frame, named as the design quantities name it (``-front``, ``-rear``,
    ``-R2-front``: :func:`~seisrack.fe.recovery.side_names`) and, for a base plate, the plane
    it bends in ("down-aisle": about z, "cross-aisle": about x)."""
    from seisrack.fe.recovery import side_names

    assert model.hinge_dofs is not None and model.hinge_kind is not None
    rot = model.node_dofs[:, -1]  # rotation in the down-aisle (x-y) plane: rz
    el = model.elements
    x_up = model.upright_x
    three_d = model.ndm == 3
    frame_z = np.asarray(model.frame_z if three_d and model.frame_z is not None else [0.0])
    names = side_names(frame_z.size)
    labels = []
    for (a, _b), kind, node in zip(model.hinge_dofs, model.hinge_kind, model.hinge_node,
                                   strict=True):
        col = int(np.argmin(np.abs(x_up - model.nodes[node, 0])))
        frame = names[int(np.argmin(np.abs(frame_z - model.nodes[node, 2])))] if three_d \
            else ""
        if kind == BASE_PLATE:
            plane = ""
            if three_d:
                plane = " down-aisle" if a == rot[node] else " cross-aisle"
            labels.append(f"base U{col + 1}{frame}{plane}")
            continue
        beam_nodes = np.flatnonzero(rot == a)
        hit = np.flatnonzero((model.element_kind == BEAM)
                             & (np.isin(el[:, 0], beam_nodes) | np.isin(el[:, 1], beam_nodes)))
        e = int(hit[0])
        bay, lev = int(model.element_line[e]), int(model.element_storey[e])
        labels.append(f"connector L{lev + 1} B{bay + 1}{frame} "
                      f"{'left' if col == bay else 'right'}")
    return tuple(labels)


class HingePeaks:
    """``on_chunk`` companion: peak |rotation| and |moment| of every hinge over every step
    (the kept histories may be decimated with ``save_every``)."""

    def __init__(self, hinges: Hinges, phi: np.ndarray) -> None:
        self.Q = hinges.operator(phi)  # noqa: N806
        self.theta0 = hinges.theta0
        self.rotation = np.zeros(hinges.count)
        self.moment = np.zeros(hinges.count)

    def __call__(self, chunk) -> None:  # noqa: ANN001
        th = chunk.q @ self.Q.T + self.theta0
        np.maximum(self.rotation, np.max(np.abs(th), axis=0), out=self.rotation)
        np.maximum(self.moment, np.max(np.abs(chunk.hinge_moment), axis=0), out=self.moment)


def hinge_response(model: FrameModel, hist: TimeHistory,
                   full: HingePeaks | None = None) -> HingeResponse | None:
    """The run's hinge histories (None when the run had no nonlinear hinges)."""
    if hist.hinge_operator is None or hist.hinge_moment is None \
            or hist.hinge_moment.shape[1] == 0:
        return None
    law = model.hinge_law
    assert law is not None and model.hinge_kind is not None
    return HingeResponse(
        labels=hinge_labels(model),
        kind=tuple("base" if k == BASE_PLATE else "connector" for k in model.hinge_kind),
        law=tuple(_LAW_NAMES[int(c)] for c in law),
        rotation=hist.hinge_rotation, moment=hist.hinge_moment,
        yield_rotation=np.asarray(model.hinge_yield_rotation, dtype=float),
        peak_rotation=None if full is None else full.rotation.copy(),
        peak_moment=None if full is None else full.moment.copy())


def nonlinear_connector_design(design: dict, hinges: HingeResponse) -> None:
    """Replace the elastic k·θ connector moments of a design summary (``connector_moment_Nm``,
    from the linear recovery operators) by the hinge laws' moments, in place.

    The design convention is the beam's member convention: the connector moment is
    ``side · M`` with ``side`` +1 at a beam's left end and −1 at its right end, and ``M`` the
    hinge moment (rotation = beam end minus upright). Values come from the kept samples.
    """
    entry = design.get("connector_moment_Nm")
    if not entry or not entry.get("labels"):
        return
    col = {lab: i for i, lab in enumerate(hinges.labels)}
    rows = []
    for lab in entry["labels"]:
        lev, rest = lab.split("-", 1)  # "L1-B2-left", 3D "L1-B2-front-left"
        bay, end = rest.rsplit("-", 1)
        i = col.get(f"connector {lev} {bay} {end}")
        if i is None:
            return  # not every connector is a hinge: keep the elastic entry
        rows.append((1.0 if end == "left" else -1.0) * hinges.moment[:, i])
    total = np.column_stack(rows)
    grav = total[0]
    seis = total - grav
    peak = np.max(np.abs(total), axis=0)
    k = int(np.argmax(peak))
    entry.update({
        "description": "moment of the beam-to-upright connector from its moment-rotation law "
                       "(nonlinear connectors; member convention of the beam; over the kept "
                       "samples)",
        "gravity": grav.tolist(), "seismic_max": seis.max(axis=0).tolist(),
        "seismic_min": seis.min(axis=0).tolist(), "peak_abs": peak.tolist(),
        "seismic_peak_abs": np.max(np.abs(seis), axis=0).tolist(),
        "max_abs": float(peak[k]), "max_label": entry["labels"][k],
    })
