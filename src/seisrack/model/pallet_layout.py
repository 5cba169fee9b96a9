"""Where a pallet can go before it falls or hits something, on a 2D or a 3D rack.

Down-aisle (both dimensions), each pallet has a free distance on either side, from its edge to
the nearest obstacle: the edge of the neighbouring pallet on the same beam, or the upright
(taken at its centreline, i.e. the bay end); an explicit ``sliding_limit`` replaces both. And
the pallets on one beam (pair) form a row between the uprights: each neighbouring pair, and each
end pallet with its upright, is a contact with a clear gap [m]. Contact ``c`` closes when
``u_x[left] − u_x[right] ≥ gap`` (the upright's sliding is 0).

Cross-aisle (3D racks), a pallet rests on the front and the rear beam of its row and overhangs
them by ``o_front`` and ``o_rear``. Sliding towards −z it loses the rear beam once its sliding
exceeds ``o_rear``, and falls; sliding towards +z it falls once the sliding exceeds
``o_front``. ``overhang`` is the front overhang; the rear one follows from the pallet depth
(``depth − frame depth − overhang``, equal when the pallet is centred); with only a depth the
pallet is centred; with neither, falls are not checked (nan). A 2D rack has no cross-aisle:
its fall distances are nan.

Where a pallet falls: a rack of one row has an aisle on either side, the *front aisle* (−z) and
the *rear aisle* (+z). A back-to-back rack (two rows joined by row spacers) has the *flue*
between its rows: row 1 falls into the front aisle or the flue, row 2 into the flue or the rear
aisle (:data:`FRONT_AISLE`, :data:`FLUE`, :data:`REAR_AISLE`; :meth:`PalletLayout.fall_side`).
The pallets of the two rows must leave the flue open: row 1's rear overhangs and row 2's front
overhangs together shorter than the spacers. A pallet sliding into the flue is taken to fall
there; that it may first meet a pallet of the other row is not modelled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from seisrack.errors import InputError
from seisrack.model.spec import Pallet, RackSpec

#: index of "the upright" in a down-aisle contact pair
UPRIGHT = -1
#: where a pallet falls, cross-aisle
FRONT_AISLE, FLUE, REAR_AISLE = "front aisle", "flue", "rear aisle"


@dataclass(frozen=True)
class PalletLayout:
    """limit_neg, limit_pos: (m,) [m] free distance of each pallet towards −x / +x, both >= 0.
    fall_front, fall_rear: (m,) [m] sliding towards −z / +z at which pallet p falls (nan:
    not checked, and always on a 2D rack). contact_left, contact_right: (k,) pallet indices
    (UPRIGHT = −1) of each down-aisle contact, left at smaller x; contact_gap: (k,) [m] clear
    gap. row: (m,) 0-based row of each pallet; n_rows: rows of the rack (2: back to back)."""

    limit_neg: np.ndarray
    limit_pos: np.ndarray
    fall_front: np.ndarray
    fall_rear: np.ndarray
    contact_left: np.ndarray
    contact_right: np.ndarray
    contact_gap: np.ndarray
    row: np.ndarray
    n_rows: int = 1

    def fall_side(self, pallet: int, sign: int) -> str:
        """Where pallet ``pallet`` falls sliding towards −z (``sign`` < 0) or +z (> 0): the
        front aisle, the flue or the rear aisle (module docstring)."""
        r = int(self.row[pallet])
        if sign < 0:
            return FRONT_AISLE if r == 0 else FLUE
        return REAR_AISLE if r == self.n_rows - 1 else FLUE


def pallet_layout(spec: RackSpec) -> PalletLayout:
    """Free distances, fall distances and down-aisle contacts of the pallets of ``spec``."""
    neg, pos = sliding_limits(spec)
    front, rear = _fall_distances(spec)
    _check_flue(spec, front, rear)
    left, right, gap = _contacts(spec)
    row = np.array([p.row - 1 for p in spec.pallets], dtype=np.int64)
    return PalletLayout(neg, pos, front, rear, left, right, gap, row, spec.geometry.rows)


def sliding_limits(spec: RackSpec) -> tuple[np.ndarray, np.ndarray]:
    """Allowed sliding of each pallet towards -x and +x [m], both >= 0 (module docstring)."""
    n = len(spec.pallets)
    neg, pos = np.zeros(n), np.zeros(n)
    shelves: dict[tuple[int, int, int], list[Pallet]] = {}  # sharing a bay, level and row
    for p in spec.pallets:
        shelves.setdefault((p.row, p.bay, p.level), []).append(p)
    for i, p in enumerate(spec.pallets):
        left, right = p.position - p.width / 2, p.position + p.width / 2
        wall_l, wall_r = 0.0, spec.geometry.bays[p.bay - 1]
        for q in shelves[(p.row, p.bay, p.level)]:
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


def _check_flue(spec: RackSpec, front: np.ndarray, rear: np.ndarray) -> None:
    """The two rows' overhangs into the flue must leave it open (module docstring)."""
    sp = spec.geometry.row_spacer
    if spec.geometry.rows < 2 or sp is None:
        return
    row = np.array([p.row for p in spec.pallets], dtype=np.int64)
    # into the flue: row 1's rear overhang (its fall distance to the front) and row 2's front
    # overhang (its fall distance to the rear)
    o1, o2 = front[row == 1], rear[row == 2]
    o1, o2 = o1[np.isfinite(o1)], o2[np.isfinite(o2)]
    into = (o1.max() if o1.size else 0.0) + (o2.max() if o2.size else 0.0)
    if into >= sp.length:
        raise InputError("geometry.row_spacer.length", sp.length,
                         f"a flue longer than the pallets' overhangs into it ({into:g} m: row "
                         "1's rear and row 2's front overhangs)", source=spec.source,
                         hint="The pallets of the two rows would overlap in the flue: "
                              "lengthen the row spacers or reduce the overhangs")


def _contacts(spec: RackSpec) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    left: list[int] = []
    right: list[int] = []
    gap: list[float] = []
    rows: dict[tuple[int, int, int], list[int]] = {}
    for i, p in enumerate(spec.pallets):
        rows.setdefault((p.row, p.level, p.bay), []).append(i)
    for (_row, _lev, bay), idx in sorted(rows.items()):
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
