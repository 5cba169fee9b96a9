"""Falls and impacts of the pallets, tracked over every step of a run (geometry:
:mod:`seisrack.model.pallet_layout`).

A pallet of a 3D rack *falls* cross-aisle the first time its sliding passes its fall distance
towards −z or +z: into the front aisle, the flue of a back-to-back rack or the rear aisle
(:meth:`~seisrack.model.pallet_layout.PalletLayout.fall_side`). A down-aisle *impact* is the
first time a gap closes between two neighbouring pallets, or between an end pallet and its
upright; it is reported with its closing speed. Crossing times are interpolated linearly
between samples. The run does not follow a pallet beyond either event (it stays on its beams in
the model), so what happens to a pallet after its fall or impact is not physical: the tracker
reports first occurrences only.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from seisrack.model.pallet_layout import FLUE, UPRIGHT, PalletLayout


@dataclass(frozen=True)
class Fall:
    """Pallet ``pallet`` (0-based) falls at ``time_s`` into ``side``: "front aisle" (−z),
    "flue" (between the rows of a back-to-back rack) or "rear aisle" (+z)."""

    pallet: int
    time_s: float
    side: str

    @property
    def into_aisle(self) -> bool:
        """True for a fall into either aisle (the falls that hurt people), False into the
        flue."""
        return self.side != FLUE


@dataclass(frozen=True)
class Impact:
    """First contact down-aisle: pallet ``left`` (at smaller x) against ``right`` (either may be
    UPRIGHT = −1) at ``time_s`` with closing speed ``speed_m_s`` (> 0)."""

    left: int
    right: int
    time_s: float
    speed_m_s: float


def _first_crossing(f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each column of ``f`` (k, c) that reaches f >= 0: its first row and the fraction of
    the previous interval at which it crosses (linear)."""
    hit = f >= 0.0
    cols = np.flatnonzero(hit.any(axis=0))
    rows = hit[:, cols].argmax(axis=0)
    pos = rows.astype(float)
    ok = rows > 0
    f0 = f[rows[ok] - 1, cols[ok]]
    f1 = f[rows[ok], cols[ok]]
    den = np.where(f1 - f0 > 0, f1 - f0, 1.0)
    pos[ok] = rows[ok] - 1 + np.clip(-f0 / den, 0.0, 1.0)
    return cols, pos


class ContactTracker:
    """Falls (3D racks) and down-aisle impacts over the chunks of a run (an ``on_chunk``
    callback)."""

    def __init__(self, layout: PalletLayout, n_pallets: int) -> None:
        self.layout = layout
        m = n_pallets
        self.fall_time = np.full(m, np.nan)
        self.fall_side = np.zeros(m, dtype=np.int64)  # -1 front, +1 rear
        k = layout.contact_gap.size
        self.impact_time = np.full(k, np.nan)
        self.impact_speed = np.full(k, np.nan)

    def __call__(self, chunk) -> None:  # noqa: ANN001
        """One chunk of the engine (``on_chunk``); the sliding velocity is asked only where an
        impact happens (on a line it costs a product with the basis)."""
        line = chunk.sliding.ndim == 2  # sliders on a line: down-aisle only

        def velocity() -> np.ndarray:
            return chunk.sliding_v[:, :, None] if line else chunk.sliding_v

        self.update(chunk.t, chunk.sliding[:, :, None] if line else chunk.sliding, velocity)

    def update(self, t: np.ndarray, u: np.ndarray, v) -> None:  # noqa: ANN001
        """One chunk: times (k,), sliding (k, m, n_dir) and the sliding velocity (the same
        shape, or a callable giving it)."""
        if u.shape[1] == 0:
            return
        lay = self.layout
        open_ = np.flatnonzero(np.isnan(self.fall_time) & np.isfinite(lay.fall_front))
        if open_.size:
            uz = u[:, open_, 1]
            for sign, limit in ((-1, lay.fall_front), (1, lay.fall_rear)):
                cols, rows = _first_crossing(sign * uz - limit[open_])
                for c, r in zip(cols, rows, strict=True):
                    p = open_[c]
                    tr = float(np.interp(r, np.arange(t.size), t))
                    if np.isnan(self.fall_time[p]) or tr < self.fall_time[p]:
                        self.fall_time[p] = tr
                        self.fall_side[p] = sign
        todo = np.flatnonzero(np.isnan(self.impact_time))
        if todo.size:
            # a closure u_left - u_right - gap is at most max u_left - min u_right - gap (the
            # rounding is monotone: no crossing is missed): only those contacts are followed
            # (first over every pallet at once; per column, not np.max(axis=0), which is
            # ~7x slower on an (n_t, few) array)
            ux = u[:, :, 0]
            if max(float(ux.max()), 0.0) - min(float(ux.min()), 0.0) < float(
                    lay.contact_gap[todo].min()):
                todo = todo[:0]
            else:
                cols = range(ux.shape[1])
                hi = np.array([ux[:, j].max() for j in cols] + [0.0])  # last: UPRIGHT, at rest
                lo = np.array([ux[:, j].min() for j in cols] + [0.0])
                todo = todo[hi[lay.contact_left[todo]] - lo[lay.contact_right[todo]]
                            - lay.contact_gap[todo] >= 0.0]
        if todo.size:
            ux = np.zeros((t.size, u.shape[1] + 1))
            ux[:, :-1] = u[:, :, 0]  # column -1 (UPRIGHT) stays 0
            left, right = lay.contact_left[todo], lay.contact_right[todo]
            close = ux[:, left] - ux[:, right] - lay.contact_gap[todo]
            cols, rows = _first_crossing(close)
            if cols.size == 0:
                return
            vx = np.zeros_like(ux)
            vx[:, :-1] = (v() if callable(v) else v)[:, :, 0]
            speed = vx[:, left] - vx[:, right]
            grid = np.arange(t.size)
            for c, r in zip(cols, rows, strict=True):
                self.impact_time[todo[c]] = float(np.interp(r, grid, t))
                self.impact_speed[todo[c]] = float(np.interp(r, grid, speed[:, c]))

    def falls(self) -> list[Fall]:
        idx = np.flatnonzero(np.isfinite(self.fall_time))
        out = [Fall(int(p), float(self.fall_time[p]),
                    self.layout.fall_side(int(p), int(self.fall_side[p]))) for p in idx]
        return sorted(out, key=lambda f: f.time_s)

    def impacts(self) -> list[Impact]:
        lay = self.layout
        idx = np.flatnonzero(np.isfinite(self.impact_time))
        out = [Impact(int(lay.contact_left[c]), int(lay.contact_right[c]),
                      float(self.impact_time[c]), float(self.impact_speed[c])) for c in idx]
        return sorted(out, key=lambda i: i.time_s)


def describe_contact(impact: Impact) -> str:
    """'pallet 3 / pallet 4', 'upright / pallet 1' (1-based pallet numbers)."""
    def name(i: int) -> str:
        return "upright" if i == UPRIGHT else f"pallet {i + 1}"
    return f"{name(impact.left)} / {name(impact.right)}"
