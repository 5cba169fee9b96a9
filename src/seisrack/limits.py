"""Sizes estimated before work starts (issue 23): racks, modal analyses, runs, records.

Every command estimates what it is about to ask of the machine from its inputs alone, before
it allocates anything, and refuses what cannot fit with an :class:`~seisrack.errors.InputError`
that names the field to change, the estimate and the limit. The limits are the named constants
below, each with the reason for its value; the cost models are calibrated on this project's
measurements (2 shared cores; the figures are beside each constant) and are meant to be
right within a factor of a few: enough to tell a typo (``--free-vibration 1e7``,
``bays = {count = 100000000}``) from a large but sensible job.

Memory budgets are a fraction of the memory *available now* (``MemAvailable``), because a
machine is shared: a run that needs more than half of what is free is refused.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

from seisrack.errors import InputError

# ---------------------------------------------------------------------------- racks
#: Largest ``count`` of a ``{count = n, pitch = h}`` table (bays or levels). Real racks have at
#: most a few hundred bays in a row and some 40 beam levels; 10,000 is far above both, and the
#: check comes before the n lengths are built (a typo of 100,000,000 would take 800 MB).
MAX_COUNT = 10_000
#: Largest ``geometry.subdivisions``. The default 4 already converges the first modes of a
#: member to about 1e-4 (tests/test_fe_beam_frequencies.py: fourth order); 100 leaves room for
#: studies of mesh convergence.
MAX_SUBDIVISIONS = 100
#: Most panel points on one upright (3D bracing). A 0.1 m panel on a 30 m upright gives 300;
#: beyond, the ``panel`` is almost surely a unit error (mm for m).
MAX_PANEL_POINTS = 1_000
#: [m] closest two heights on an upright may be without sharing a node: row spacers, bracing
#: panel points. Bolted parts sit in the upright's perforations, about 50 mm apart, and the
#: model ignores joint eccentricities of that size; nearer heights are one joint, and the short
#: upright element between two nodes (bending stiffness ~ 1/L³) makes the stiffness near
#: singular: measured 0.1 mm apart (the "mechanism" check of the bracing fails), 1 mm (a damping
#: matrix asymmetric by round-off), while 0.05 m is at most (L / 0.05)³ stiffer than an element
#: of length L (2.7e4 for a 1.5 m storey in one element), far from both. Storey divisions (mesh
#: nodes) need only a quarter of a division when that is less: the short element is then at
#: most 4³ = 64 times stiffer than its division.
MIN_NODE_GAP = 0.05
#: Most degrees of freedom of a rack. Measured here: compiling a 247,021-DOF rack and its
#: first 6 modes took 8 s and 360 MB; a 102,381-DOF rack with 12,000 pallets 35 s and 360 MB.
#: The largest example is 3,481 DOFs (2D) and the 5 x 10 warehouse rack 3D about 10,000.
MAX_RACK_DOFS = 300_000
#: [B] memory per DOF of a compiled rack with its modal analysis (measured 1.1 kB, see above)
BYTES_PER_DOF = 1_500
#: [s] compile time per DOF, and per DOF and pallet (measured, see above)
COMPILE_S_PER_DOF = 3.5e-5
COMPILE_S_PER_DOF_PALLET = 2.0e-8

# ---------------------------------------------------------------------------- runs
#: Fraction of the memory available now that one command may plan to use.
MEMORY_FRACTION = 0.5
#: [B] ceiling of that budget whatever the machine: the engine's own ceiling
#: (``seisrack.dynamics._store.DEFAULT_MAX_MEMORY``), which it would apply later anyway.
MEMORY_CEILING = 4 * 2**30
#: Most samples of a record (generated, or padded with free vibration): 10 million samples
#: (28 h at 0.01 s) are 80 MB per array; longer is a unit error (ms for s).
MAX_RECORD_SAMPLES = 10_000_000
#: [s] longest single time history accepted (estimated): a day of computing is a study's job
#: (split it) or a typo.
MAX_RUN_SECONDS = 24 * 3600.0
#: [s] a run estimated longer than this announces its estimate on stderr before it starts
ANNOUNCE_S = 30.0
#: Largest reduced (Ritz) basis assumed by the estimates above 50 DOFs: the 2D engine builds at
#: most 40 Ritz vectors plus the pallets' (README, "Cost of a new contact configuration"); the
#: 3D planar engine used 86-144 on the 5 x 10 warehouse rack (docs/theory/planar_friction.md).
BASIS_ESTIMATE = 150
#: The 3D planar engine's Ritz basis grows with the pallets (40 vectors with 4, 86 with 150) up
#: to its cap (``dynamics.basis.DEFAULT_MAX_SIZE``; the 40 x 8 row with 960 pallets reaches it)
BASIS_ESTIMATE_3D_MAX = 200
#: [s] cost per analysis step: a fixed part, per pallet, per basis vector. Measured under El
#: Centro (7,988 steps, numba, 2 shared cores): paper rack 6.6 µs/step, 3-level rack 19 µs,
#: paper rack nonlinear 17 µs, warehouse rack (400 pallets, mu 0.1) 1,071 µs; 3D paper rack
#: 50 µs, 3D warehouse rack (150 pallets) 1,440 µs (planar contact costs more per pallet).
#: A 3D pallet costs more the larger the basis: its events factorise the (r, r) Newton matrix.
#: Measured on 20 s of the EC8 pair (5 ms): the 150-pallet example (r = 86) 1.9 ms a step, the
#: 40 x 8 row (960 pallets, r = 200) 25.5 ms a step, i.e. 13-27 µs a pallet, about 1.45e-7 r.
STEP_S = 5.0e-6
STEP_S_PER_PALLET = 2.5e-6  # 2D
STEP_S_PER_PALLET_BASIS_3D = 1.45e-7
STEP_S_PER_BASIS = 2.0e-8
#: [s] the Ritz basis's preparation per n_dof x (load patterns)²: its Gram matrix and the
#: patterns' static responses (40 x 8 row, 20,836 DOFs, 1,923 patterns: 14 s)
PREP_S_PER_NK2 = 2.0e-10
#: [s] the local engine (``--engine local``) per pallet and analysis step: its cost grows with
#: the pallets and the rack's length, not with a global basis. Measured on 20 s of the EC8 pair
#: at 5 ms (4,000 steps, ``benchmarks/results/rack_row.md``, 2026-11-28): 10 x 5 (150 pallets)
#: 49.6 s, 20 x 5 117 s, 40 x 5 258 s, 20 x 12 310 s, 40 x 8 (960 pallets) 401 s, 80 x 5
#: (1,200) 709 s: 83 to 148 µs a pallet-step, 105-108 µs on the 40 x 5, 40 x 8 and 20 x 12 rows.
#: On a line (2D) a pallet has one direction: the 2D warehouse example (400 pallets) 6.2 s
LOCAL_STEP_S_PER_PALLET = 1.1e-4
LOCAL_STEP_S_PER_PALLET_2D = 4.0e-6
#: [s] the local basis's preparation per DOF (40 x 8 row, 20,836 DOFs: 3.1 s)
LOCAL_PREP_S_PER_DOF = 1.5e-4

# ---------------------------------------------------------------------------- modal analysis
#: Most modes a command computes: far more than any participation criterion needs (EN 1998-1
#: §4.3.3.3.1: 90 % of the mass), and the dense solver's memory grows with n².
MAX_MODES = 1_000


def available_memory() -> float:
    """[B] memory available now (``MemAvailable`` on Linux), or inf if unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return math.inf


def memory_budget() -> float:
    """[B] what one command may plan to use: a fraction of what is free, capped."""
    return min(MEMORY_FRACTION * available_memory(), MEMORY_CEILING)


def fmt_bytes(n: float) -> str:
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"


def fmt_seconds(s: float) -> str:
    if s >= 86400 * 365:
        return f"{s / (86400 * 365):.3g} years"
    if s >= 86400:
        return f"{s / 86400:.3g} days"
    if s >= 3600:
        return f"{s / 3600:.3g} h"
    if s >= 60:
        return f"{s / 60:.3g} min"
    return f"{s:.2g} s"


# ---------------------------------------------------------------------------- racks
@dataclass(frozen=True)
class RackSize:
    """Estimated size of a rack before it is meshed (DOFs split by what makes them)."""

    uprights: int
    beams: int
    bracing: int
    pallets: int
    n_pallets: int

    @property
    def dofs(self) -> int:
        return self.uprights + self.beams + self.bracing + self.pallets

    @property
    def memory(self) -> float:
        return self.dofs * BYTES_PER_DOF

    @property
    def seconds(self) -> float:
        return self.dofs * (COMPILE_S_PER_DOF + COMPILE_S_PER_DOF_PALLET * self.n_pallets)


def rack_size(n_bays: int, n_levels: int, subdivisions: int, n_pallets: int, *,
              three_d: bool = False, panel_points: int = 0, rows: int = 1) -> RackSize:
    """DOFs of a rack from its counts (the meshers' rules, see ``model/rack_mesh*.py``).

    2D: 3 DOFs per node; each upright has ``subdivisions`` nodes per storey, each beam
    ``subdivisions - 1`` inner nodes and its two end rotations, each pallet off a station one
    node. 3D: 6 DOFs per node, a front and a rear frame, upright nodes at the union of the
    subdivision and the panel heights (counted as their sum: an upper bound); a back-to-back
    rack (``rows`` = 2) has two of each frame; spacers off those heights add theirs, counted
    by the caller among ``panel_points`` (``model.load._check_size``).
    """
    lines = n_bays + 1
    if not three_d:
        return RackSize(uprights=3 * lines * n_levels * subdivisions + lines,
                        beams=n_levels * n_bays * (3 * (subdivisions - 1) + 2), bracing=0,
                        pallets=3 * n_pallets, n_pallets=n_pallets)
    return RackSize(uprights=2 * rows * lines * (6 * n_levels * subdivisions + 2),
                    beams=2 * rows * n_levels * n_bays * (6 * (subdivisions - 1) + 2),
                    bracing=2 * rows * lines * 6 * panel_points, pallets=12 * n_pallets,
                    n_pallets=n_pallets)


def check_rack_size(size: RackSize, *, n_bays: int, n_levels: int, subdivisions: int,
                    default_subdivisions: int, panel: Any = None, source: str | None = None
                    ) -> None:
    """Refuse a rack above :data:`MAX_RACK_DOFS`, naming what makes it large (the
    subdivisions when the rack would fit with ``default_subdivisions``, the model's default)."""
    if size.dofs <= MAX_RACK_DOFS:
        return
    parts = {"bracing.panel": size.bracing, "pallets": size.pallets,
             "frame": size.uprights + size.beams}
    culprit = max(parts, key=parts.get)
    if culprit == "frame":
        lighter = rack_size(n_bays, n_levels, default_subdivisions, 0).dofs
        if subdivisions > default_subdivisions and lighter <= MAX_RACK_DOFS:
            field, value = "geometry.subdivisions", subdivisions
        elif n_bays >= n_levels:
            field, value = "geometry.bays", f"{n_bays} bays"
        else:
            field, value = "geometry.levels", f"{n_levels} levels"
    elif culprit == "pallets":
        field, value = "pallets", f"{size.n_pallets} pallets"
    else:
        field, value = "bracing.panel", panel
    raise InputError(
        field, value, f"a rack of at most {MAX_RACK_DOFS:,} degrees of freedom",
        source=source,
        hint=f"This one ({n_bays} bays x {n_levels} levels, {subdivisions} subdivisions"
             f"{f', {size.n_pallets} pallets' if size.n_pallets else ''}) has about "
             f"{size.dofs:,} DOFs and would need about {fmt_bytes(size.memory)} and "
             f"{fmt_seconds(size.seconds)} just to build; model a part of it (a few bays "
             "of the row behave alike), or use fewer subdivisions")


# ---------------------------------------------------------------------------- modal analysis
def modal_bytes(n_dof: int, n_modes: int | None) -> float:
    """[B] memory of a modal analysis (the solver ``method="auto"`` picks)."""
    from seisrack.fe.eigen import choose_method

    if choose_method(n_dof, n_modes) == "dense":
        return 4.0 * 8.0 * n_dof**2  # K, M, the eigenvectors and LAPACK's work, (n, n) each
    return 8.0 * n_dof * (4 * (n_modes or 1) + 20) + n_dof * BYTES_PER_DOF  # Lanczos vectors


def check_modes(n_modes: int, n_dof: int, field: str = "--modes") -> None:
    """Refuse a number of modes above :data:`MAX_MODES` or beyond the memory budget."""
    if n_modes > MAX_MODES:
        raise InputError(field, n_modes, f"an integer from 1 to {MAX_MODES:,}")
    need, budget = modal_bytes(n_dof, min(n_modes, n_dof)), memory_budget()
    if need > budget:
        fits = max(1, int(0.1 * n_dof))
        raise InputError(field, n_modes, f"a number of modes whose analysis fits in "
                         f"{fmt_bytes(budget)} (half of the free memory, at most "
                         f"{fmt_bytes(MEMORY_CEILING)})",
                         hint=f"{n_modes} modes of {n_dof:,} DOFs need the dense solver and "
                              f"about {fmt_bytes(need)}; up to {fits:,} modes use the sparse "
                              "one")


# ---------------------------------------------------------------------------- runs
@dataclass(frozen=True)
class RunEstimate:
    """What a time history will take, estimated before anything is allocated."""

    n_steps: int  # analysis steps
    n_keep: int  # kept samples of the histories
    memory: float  # [B]
    seconds: float  # [s], one core
    series_memory: float  # [B] the part that does not depend on --save-every
    prep_memory: float = 0.0  # [B] the Ritz basis's preparation, freed before the run

    def describe(self) -> str:
        return (f"{self.n_steps:,} analysis steps, about {fmt_bytes(self.memory)} and "
                f"{fmt_seconds(self.seconds)}")


def estimate_run(*, n_record: int, k: int, n_pad: int, n_dof: int, n_pallets: int,
                 n_levels: int, save_every: int | None, vertical: bool = False,
                 three_d: bool = False, n_design: int = 0,
                 engine: str = "default") -> RunEstimate:
    """Estimate a time history of ``n_record`` record samples (``k`` analysis steps each),
    ``n_pad`` samples of free vibration, on a rack of ``n_dof`` DOFs and ``n_pallets``.

    Memory: the ground series at both rates (the record padded, its resampled copy and the
    engine's load series: about 4 arrays of the analysis length, 6 with a vertical record),
    the full-rate level accelerations of the filtered peak (at most
    ``analysis.peaks.FULL_RATE_ACCEL_MAX`` values), and per kept sample the basis coordinates
    (3 arrays), the pallets' states (6) and the level results (10). ``n_design``: the design
    histories per kept sample that the run's writer adds (:func:`design_items`; 0 when nothing
    is written): they, and the written dataset's copy of every history with them, count
    too. Above 50 DOFs the Ritz basis's preparation (the static responses of the load
    patterns, (n_dof, p), and their Gram matrix, p = one pattern per pallet and direction) is
    freed before the run: the larger of the two counts. ``engine`` "local" (``--engine
    local``) builds no such basis: its time is its own per pallet and step
    (``LOCAL_STEP_S_PER_PALLET``) and its basis's preparation per DOF.
    """
    ritz = engine != "local"
    n_steps = max(0, (n_record - 1 + n_pad) * k)
    n_t = n_steps + 1
    nb = n_dof if n_dof <= 50 else min(n_dof, BASIS_ESTIMATE)
    if three_d and n_dof > 50:  # the planar Ritz basis: 40 (4 pallets), 86 (150), capped 200
        nb = int(min(n_dof, BASIS_ESTIMATE_3D_MAX, 40 + 0.3 * n_pallets))
    n_keep = 2 if save_every is None else n_steps // max(1, save_every) + 2
    series = 8.0 * ((n_record + n_pad) * 2 + n_t * (6 if vertical else 4)
                    + min(n_t * n_levels, 10_000_000))
    per_sample = 3 * nb + 6 * n_pallets * (2 if three_d else 1) + 10 * n_levels + 10
    if n_design:  # written: the design histories, then the dataset (every history once more)
        per_sample = per_sample + 2 * (per_sample + n_design)
    n_pat = (2 if three_d else 1) * n_pallets + 3 if ritz and n_dof > 50 else 0
    prep = 8.0 * (n_dof * n_pat + 3 * n_pat * n_pat)
    memory = max(series + 8.0 * n_keep * per_sample, prep)  # prep is freed before the run
    per_pallet = (STEP_S_PER_PALLET_BASIS_3D * max(nb, 62) if three_d
                  else STEP_S_PER_PALLET)
    per_step = STEP_S + per_pallet * n_pallets + STEP_S_PER_BASIS * nb
    seconds = n_steps * per_step + PREP_S_PER_NK2 * n_dof * n_pat * n_pat
    if not ritz:
        per_pallet = LOCAL_STEP_S_PER_PALLET if three_d else LOCAL_STEP_S_PER_PALLET_2D
        seconds = n_steps * (STEP_S + per_pallet * n_pallets) + LOCAL_PREP_S_PER_DOF * n_dof
    return RunEstimate(n_steps=n_steps, n_keep=n_keep, memory=memory,
                       seconds=seconds, series_memory=series, prep_memory=prep)


def design_items(*, n_bays: int, n_levels: int, n_sides: int, three_d: bool) -> int:
    """Design histories a run's ``timehistory.nc`` holds per kept sample: beam-end moments and
    shears and connector moments and rotations (two ends of each beam, each bay, level and
    frame), upright axial force and moments (two in 3D) at every level's section and the base,
    upright moments per level and direction, and the drifts."""
    ends = 2 * n_bays * n_levels * n_sides
    uprights = (n_bays + 1) * n_sides
    n_dir = 2 if three_d else 1
    return (4 * ends + (3 if three_d else 2) * uprights * (n_levels + 1)
            + uprights * (n_levels + 1) * n_dir + n_levels * n_dir)


def check_run(est: RunEstimate, *, n_record: int, n_pad: int, save_every: int | None,
              budget: float | None = None) -> None:
    """Refuse a run whose memory or time is out of reach, naming the option to change."""
    budget = memory_budget() if budget is None else budget
    longest = "--free-vibration" if n_pad > n_record else "--motion"
    if n_record + n_pad > MAX_RECORD_SAMPLES:
        raise InputError(longest, f"{n_record + n_pad:,} record samples",
                         f"a run of at most {MAX_RECORD_SAMPLES:,} record samples (record "
                         "and free vibration)", hint=f"This run would be {est.describe()}")
    if est.series_memory > budget:
        steps_per_sample = est.n_steps / max(1, n_record - 1 + n_pad)
        raise InputError("--dt" if steps_per_sample > 1 else longest,
                         f"{est.n_steps:,} analysis steps",
                         f"a run whose load series fit in {fmt_bytes(budget)} (half of the "
                         f"free memory, at most {fmt_bytes(MEMORY_CEILING)})",
                         hint=f"This run would be {est.describe()}; use a larger --dt or a "
                              "shorter record or free vibration")
    if est.prep_memory > budget:
        raise InputError("rack", f"{fmt_bytes(est.prep_memory)} for the static responses of its "
                         "Ritz basis's load patterns (one per pallet and direction)",
                         f"a rack whose basis preparation fits in {fmt_bytes(budget)}",
                         hint="Use --engine local (a basis built slice by slice), or split the "
                              "rack into shorter rows")
    if est.memory > budget:
        per_sample = (est.memory - est.series_memory) / max(est.n_keep, 1)  # prep fits: histories
        fits = max(1, int((budget - est.series_memory) / max(per_sample, 1.0)))
        every = max(2, math.ceil(est.n_steps / fits))
        raise InputError("--save-every", save_every, f"a value that keeps the histories "
                         f"within {fmt_bytes(budget)} (e.g. --save-every {every})",
                         hint=f"This run would be {est.describe()}")
    if est.seconds > MAX_RUN_SECONDS:
        field = "--free-vibration" if n_pad > n_record else "--dt"
        raise InputError(field, f"{est.n_steps:,} analysis steps",
                         f"a run estimated within {fmt_seconds(MAX_RUN_SECONDS)}",
                         hint=f"This run would be {est.describe()}; use a shorter record "
                              "or free vibration, or a larger --dt")


# ---------------------------------------------------------------------------- studies
#: Most runs of a study without ``--yes``. ``study.json`` lists every run (about 400 B each),
#: the driver holds the run table (about 1 kB a run) and expansion takes about 0.1 ms a run
#: (measured on 20,000 runs): 100,000 runs are 40 MB, 100 MB and 10 s. The example study has
#: 72 runs; a large fragility study some 10,000.
MAX_STUDY_RUNS = 100_000
#: [s] longest study (estimated wall time on its workers) without ``--yes``
MAX_STUDY_SECONDS = 24 * 3600.0
#: Most records of one generated EC8 suite (``[[records.ec8]] count``): EN 1998-1 §3.2.3.1.2
#: asks for 3 (or 7 for means); 1,000 is far above any suite.
MAX_SUITE_COUNT = 1_000
