"""Where a pallet of a 3D rack can go before it falls or hits something (issue 11, item 4).

Cross-aisle, a pallet rests on the front beam (z = 0) and the rear beam (z = depth) and
overhangs them by ``o_front`` and ``o_rear``. Sliding towards the front aisle (−z) it loses the
rear beam once its sliding exceeds ``o_rear``, and falls into the front aisle; sliding towards
the rear it falls once the sliding exceeds ``o_front``. ``overhang`` is the front overhang; the
rear one follows from the pallet depth (``depth − frame depth − overhang``, equal when the
pallet is centred); with only a depth the pallet is centred; with neither, falls are not
checked (nan).

Down-aisle, pallets on one beam pair form a row between the uprights: each neighbouring pair,
and each end pallet with its upright (taken at its centreline, as the 2D rack's fall limit),
is a contact with a clear gap [m]. Contact ``c`` closes when
``u_x[left] − u_x[right] ≥ gap`` (the upright's sliding is 0).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError
from seisrack.model.spec import RackSpec

#: index of "the upright" in a down-aisle contact pair
UPRIGHT = -1


@dataclass(frozen=True)
class PalletLayout3D:
    """fall_front, fall_rear: (m,) [m] sliding towards −z / +z at which pallet p falls (nan:
    not checked). contact_left, contact_right: (k,) pallet indices (UPRIGHT = −1) of each
    down-aisle contact, left at smaller x; contact_gap: (k,) [m] clear gap."""

    fall_front: np.ndarray
    fall_rear: np.ndarray
    contact_left: np.ndarray
    contact_right: np.ndarray
    contact_gap: np.ndarray


def pallet_layout_3d(spec: RackSpec) -> PalletLayout3D:
    """Fall distances and down-aisle contacts of the pallets of a 3D ``spec``."""
    d = float(spec.geometry.depth or 0.0)
    m = len(spec.pallets)
    front, rear = np.full(m, math.nan), np.full(m, math.nan)
    for i, p in enumerate(spec.pallets):
        o_f = p.overhang
        if p.depth is not None and o_f is None:
            if p.depth <= d:
                raise InputError(f"pallets[{i}].depth", p.depth,
                                 f"a pallet deeper than the frame ({d:g} m): it must rest on "
                                 "the front and the rear beam", source=spec.source)
            o_f = 0.5 * (p.depth - d)
        if o_f is None:
            continue
        o_r = o_f if p.depth is None else p.depth - d - o_f
        if o_r <= 0.0:
            raise InputError(f"pallets[{i}].depth", p.depth,
                             f"a depth > frame depth + overhang = {d + o_f:g} m (the pallet "
                             "must reach the rear beam)", source=spec.source)
        # towards the front aisle the rear edge leaves the rear beam, and vice versa
        front[i], rear[i] = o_r, o_f
    left, right, gap = [], [], []
    rows: dict[tuple[int, int], list[int]] = {}
    for i, p in enumerate(spec.pallets):
        rows.setdefault((p.level, p.bay), []).append(i)
    for (_lev, bay), idx in sorted(rows.items()):
        idx.sort(key=lambda i: spec.pallets[i].position)
        span = spec.geometry.bays[bay - 1]
        prev, edge = UPRIGHT, 0.0
        for i in idx:
            p = spec.pallets[i]
            left.append(prev)
            right.append(i)
            gap.append(max(p.position - p.width / 2 - edge, 0.0))
            prev, edge = i, p.position + p.width / 2
        left.append(prev)
        right.append(UPRIGHT)
        gap.append(max(span - edge, 0.0))
    return PalletLayout3D(front, rear, np.array(left, dtype=np.int64),
                          np.array(right, dtype=np.int64), np.array(gap, dtype=float))
