"""Where a pallet can go before it falls or hits something, on a 2D or a 3D rack.

Down-aisle (both dimensions), each pallet has a free distance on either side, from its edge to
the nearest obstacle: the edge of the neighbouring pallet on the same beam, or the upright
(taken at its centreline, i.e. the bay end); an explicit ``sliding_limit`` replaces both. And
the pallets on one beam (pair) form a row between the uprights: each neighbouring pair, and each
end pallet with its upright, is a contact with a clear gap [m]. Contact ``c`` closes when
``u_x[left] − u_x[right] ≥ gap`` (the upright's sliding is 0).

Cross-aisle (3D racks), a pallet rests on the front beam (z = 0) and the rear beam (z = depth) and
overhangs them by ``o_front`` and ``o_rear``. Sliding towards the front aisle (−z) it loses the
rear beam once its sliding exceeds ``o_rear``, and falls into the front aisle; sliding towards
the rear it falls once the sliding exceeds ``o_front``. ``overhang`` is the front overhang; the
rear one follows from the pallet depth (``depth − frame depth − overhang``, equal when the
pallet is centred); with only a depth the pallet is centred; with neither, falls are not
checked (nan). A 2D rack has no cross-aisle: its fall distances are nan.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError
from seisrack.model.spec import Pallet, RackSpec

#: index of "the upright" in a down-aisle contact pair
UPRIGHT = -1


@dataclass(frozen=True)
class PalletLayout:
    """limit_neg, limit_pos: (m,) [m] free distance of each pallet towards −x / +x, both >= 0.
    fall_front, fall_rear: (m,) [m] sliding towards −z / +z at which pallet p falls (nan:
    not checked, and always on a 2D rack). contact_left, contact_right: (k,) pallet indices
    (UPRIGHT = −1) of each down-aisle contact, left at smaller x; contact_gap: (k,) [m] clear
    gap."""

    limit_neg: np.ndarray
    limit_pos: np.ndarray
    fall_front: np.ndarray
    fall_rear: np.ndarray
    contact_left: np.ndarray
    contact_right: np.ndarray
    contact_gap: np.ndarray


def pallet_layout(spec: RackSpec) -> PalletLayout:
    """Free distances, fall distances and down-aisle contacts of the pallets of ``spec``."""
    neg, pos = sliding_limits(spec)
    front, rear = _fall_distances(spec)
    left, right, gap = _contacts(spec)
    return PalletLayout(neg, pos, front, rear, left, right, gap)


def sliding_limits(spec: RackSpec) -> tuple[np.ndarray, np.ndarray]:
    """Allowed sliding of each pallet towards -x and +x [m], both >= 0 (module docstring)."""
    n = len(spec.pallets)
    neg, pos = np.zeros(n), np.zeros(n)
    shelves: dict[tuple[int, int], list[Pallet]] = {}  # pallets sharing a bay and level
    for p in spec.pallets:
        shelves.setdefault((p.bay, p.level), []).append(p)
    for i, p in enumerate(spec.pallets):
        left, right = p.position - p.width / 2, p.position + p.width / 2
        wall_l, wall_r = 0.0, spec.geometry.bays[p.bay - 1]
        for q in shelves[(p.bay, p.level)]:
            if q is p:
                continue
            if q.position < p.position:
                wall_l = max(wall_l, q.position + q.width / 2)
            elif q.position > p.position:
                wall_r = min(wall_r, q.position - q.width / 2)
        neg[i], pos[i] = max(left - wall_l, 0.0), max(wall_r - right, 0.0)
        if p.sliding_limit is not None:
            neg[i] = pos[i] = p.sliding_limit
    return neg, pos


def _fall_distances(spec: RackSpec) -> tuple[np.ndarray, np.ndarray]:
    m = len(spec.pallets)
    front, rear = np.full(m, math.nan), np.full(m, math.nan)
    if spec.geometry.depth is None:
        return front, rear
    d = float(spec.geometry.depth)
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
    return front, rear


def _contacts(spec: RackSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    left: list[int] = []
    right: list[int] = []
    gap: list[float] = []
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
    return (np.array(left, dtype=np.int64), np.array(right, dtype=np.int64),
            np.array(gap, dtype=float))
