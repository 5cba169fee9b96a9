"""Expand a :class:`StudySpec` into its table of runs, each with a stable id.

Everything that can go wrong with the inputs is found here, before any run starts: a record that
cannot be read, an intensity that scaling cannot reach (a zero-PGA record, a scale factor above
``intensity.max_scale``), a record whose time step is not a multiple of the analysis step.

Determinism. A run's id is a short SHA-256 of what defines it: the rack file's content hash, the
record's name and content hash, the intensity measure and target, the friction sample, the
occupancy, the study seed and the analysis step. Friction samples and occupancy patterns are
drawn from generators seeded by ``(study seed, hash of the cell)``, never from a shared stream,
so a sample does not depend on the order of expansion nor on which runs are already stored. The
same (rack, record, occupancy, sample index) sees the same friction at every intensity level
(common random numbers: an IDA curve follows one realisation, and stripes differ only by
intensity).

3D racks. A record may be a pair of horizontal components (``records.pairs``, generated
``components = 2``), applied down-aisle and cross-aisle and turned by the incidence angle
(``[angle]``, a list or uniform samples drawn like the friction samples). A pair's intensity is
the geometric mean of its two components' (PGA or Sa(T1)), and both are scaled by the same
factor. Runs that turn the motion or use a pair need 3D racks.

IDA curves. With a stop rule (``intensity.ida.stop_when``) the run table is still the full
grid, with the same ids: the runs of one curve (:func:`curve_key`) are run in increasing order
in one task, and those above the level where the rule holds are stored with status "skipped".
"""

from __future__ import annotations

import hashlib
import json
import math
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from seisrack.errors import InputError, SeisrackError
from seisrack.motion.records import Record
from seisrack.studies.spec import IdaStop, StudySpec

RECORD_SUFFIXES = (".at2", ".csv", ".txt")


@dataclass(frozen=True)
class Run:
    """One analysis of a study: inputs only (results are rows of the store)."""

    run_id: str
    rack: str  # path as written in the study
    rack_hash: str
    record: str
    record_hash: str
    im_measure: str
    im_target: float  # [m/s²]
    scale_factor: float
    stripe: int  # index of the stripe, -1 for IDA
    mu_static: float
    mu_dynamic: float
    occupancy: float
    seed: int
    period_s: float  # T1 of the rack as loaded (NaN unless measure = "sa")
    angle_deg: float = 0.0  # incidence angle of the horizontal components [deg]
    components: int = 1  # horizontal components of the record: 1, or 2 (a pair)


@dataclass(frozen=True)
class StudyPlan:
    """The expanded study: runs, and what a worker needs to run them.

    racks: rack hash -> RackSpec (all pallets); patterns: (rack hash, occupancy) -> kept pallet
    indices; records: record hash -> the unscaled :class:`Record` of each horizontal component
    (a tuple of one, or two for a pair).
    """

    runs: tuple[Run, ...]
    racks: dict
    patterns: dict
    records: dict
    dt: float
    ida_stop: IdaStop | None = None  # the IDA stop rule (None: every level runs)


def expand(spec: StudySpec) -> list[Run]:
    """The table of runs of ``spec`` (deterministic, stable ids)."""
    return list(plan(spec).runs)


def plan(spec: StudySpec) -> StudyPlan:
    """Load racks and records, compute intensities and scale factors, draw samples."""
    from seisrack.model import load_rack

    racks = {}
    rack_keys = []
    for given, path in zip(spec.racks_as_given, spec.racks, strict=True):
        h = _hash_bytes(Path(path).read_bytes())
        racks[h] = load_rack(path)
        rack_keys.append((given, h))
    records = _load_records(spec)
    _check_dimensions(spec, racks, records)
    patterns = {}
    runs: list[Run] = []
    intensity = spec.intensity
    levels = intensity.levels
    for r_index, (given, rh) in enumerate(rack_keys):
        rack = racks[rh]
        for occ in spec.occupancy:
            kept = _pattern(len(rack.pallets), occ, spec.seed, rh)
            patterns[(rh, occ)] = kept
            period = math.nan
            if intensity.measure == "sa":
                period = _first_period(rack, kept, given)
            for name, rec_h, comps in records:
                ims = [_intensity_of(c, intensity.measure, period, intensity.damping)
                       for c in comps]
                # geometric mean of the components; a flat one is refused just below
                im0 = float(np.exp(np.mean(np.log(ims)))) if min(ims) > 0.0 else 0.0
                _check_reachable(name, comps[0], im0, levels, intensity, spec.dt, period)
                angles = (spec.rack_angles[r_index] if spec.rack_angles
                          else _angle_samples(spec, rh, rec_h, occ))
                for angle in angles:
                    for mu_s in _friction_samples(spec, rh, rec_h, occ):
                        mu_d = mu_s * spec.friction.dynamic_ratio
                        for k, target in enumerate(levels):
                            rid = run_id(rh, name, rec_h, intensity.measure, target, mu_s,
                                         mu_d, occ, spec.seed, spec.dt, angle, len(comps))
                            runs.append(Run(
                                run_id=rid, rack=given, rack_hash=rh, record=name,
                                record_hash=rec_h, im_measure=intensity.measure,
                                im_target=float(target), scale_factor=float(target / im0),
                                stripe=-1 if intensity.is_ida else k, mu_static=float(mu_s),
                                mu_dynamic=float(mu_d), occupancy=float(occ), seed=spec.seed,
                                period_s=float(period), angle_deg=float(angle),
                                components=len(comps)))
    dup = [i for i, c in Counter(r.run_id for r in runs).items() if c > 1]
    if dup:
        raise InputError("friction.values", spec.friction.values,
                         "values giving distinct runs (two runs of the study are identical)",
                         source=spec.source)
    return StudyPlan(runs=tuple(runs), racks=racks, patterns=patterns,
                     records={h: r for _, h, r in records}, dt=spec.dt,
                     ida_stop=intensity.ida_stop if intensity.is_ida else None)


def curve_key(run: Run) -> tuple:
    """The IDA curve of ``run``: (rack, occupancy, record, friction, angle); levels vary
    along it."""
    return (run.rack_hash, run.occupancy, run.record, run.record_hash, run.mu_static,
            run.mu_dynamic, run.angle_deg)


def run_id(rack_hash: str, record: str, record_hash: str, measure: str, target: float,
           mu_s: float, mu_d: float, occupancy: float, seed: int, dt: float,
           angle_deg: float = 0.0, components: int = 1) -> str:
    """16 hex digits of the SHA-256 of the defining inputs (floats by their exact repr). The
    angle and the number of components enter only when they differ from one component at
    0°, so the ids of a down-aisle study are those of earlier versions (its store resumes)."""
    parts = [rack_hash, record, record_hash, measure, repr(float(target)), repr(float(mu_s)),
             repr(float(mu_d)), repr(float(occupancy)), int(seed), repr(float(dt))]
    if angle_deg != 0.0 or components != 1:
        parts += [repr(float(angle_deg)), int(components)]
    return hashlib.sha256(json.dumps(parts).encode()).hexdigest()[:16]


def record_hash(rec: Record | tuple[Record, ...]) -> str:
    """Content hash of a record (or a pair): its samples and time step (not its name)."""
    comps = rec if isinstance(rec, tuple) else (rec,)
    h = hashlib.sha256()
    for c in comps:
        h.update(np.ascontiguousarray(c.accel, dtype="<f8").tobytes())
        h.update(repr(float(c.dt)).encode())
    return h.hexdigest()[:16]


def _hash_bytes(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()[:16]


def _seed_key(*parts: object) -> int:
    return int(hashlib.sha256(json.dumps([repr(p) for p in parts]).encode()).hexdigest()[:8], 16)


def _load_records(spec: StudySpec) -> list[tuple[str, str, tuple[Record, ...]]]:
    """(name, content hash, components) of every record of the study: one component, or a
    pair (down-aisle, cross-aisle)."""
    from seisrack.motion import generate_ec8_record, load_builtin_record, read_record

    rs = spec.records
    out: list[tuple[str, tuple[Record, ...]]] = []
    if rs.folder is not None:
        files = sorted(p for p in Path(rs.folder).iterdir()
                       if p.is_file() and p.suffix.lower() in RECORD_SUFFIXES)
        if not files:
            raise InputError("records.folder", rs.folder_as_given,
                             "a folder holding record files (" + ", ".join(RECORD_SUFFIXES) + ")",
                             source=spec.source)
        read = {}
        for f in files:
            try:
                read[f] = read_record(f, units=rs.units, dt=rs.file_dt)
            except SeisrackError as exc:
                raise InputError("records.folder", str(f), "a readable record file",
                                 source=spec.source, hint=str(exc)) from None
        if rs.pairs:
            out.extend(_pairs(read, spec))
        else:
            out.extend((r.name, (r,)) for r in read.values())
    out.extend((name, (load_builtin_record(name),)) for name in rs.builtin)
    for i, s in enumerate(rs.ec8):
        for k in range(s.count):
            name = f"ec8_t{s.type}{s.ground}_ag{s.ag:g}_d{s.duration:g}_s{s.seed + k}"
            comps = []
            for c in range(s.components):
                # a pair's second component from its own seed, far from the first ones
                seed = s.seed + k + 100_003 * c
                try:
                    comps.append(generate_ec8_record(
                        type=s.type, ground=s.ground, ag=s.ag, duration=s.duration, dt=s.dt,
                        seed=seed, name=name + ("", "_cross")[c]))
                except SeisrackError as exc:
                    raise InputError(f"records.ec8[{i}]", s, "parameters the EC8 generator "
                                     "accepts", source=spec.source, hint=str(exc)) from None
            out.append((name, tuple(comps)))
    names = Counter(n for n, _ in out)
    dup = sorted(n for n, c in names.items() if c > 1)
    if dup:
        raise InputError("records", dup, "records with distinct names (file stems, bundled "
                         "names and generated suites must not repeat)", source=spec.source)
    return [(n, record_hash(comps), comps) for n, comps in out]


def _pairs(read: dict, spec: StudySpec) -> list[tuple[str, tuple[Record, ...]]]:
    """Group a folder's records into pairs: names equal up to their last ``_``/``-`` token."""
    groups: dict[str, list] = {}
    for f, rec in read.items():
        stem = f.stem
        cut = max(stem.rfind("_"), stem.rfind("-"))
        groups.setdefault(stem[:cut] if cut > 0 else stem, []).append((f, rec))
    out = []
    for key, members in sorted(groups.items()):
        if len(members) != 2:
            raise InputError("records.pairs", [m[0].name for m in members],
                             "exactly two files per pair, whose names differ only by their "
                             "last '_' or '-' token (e.g. RSN6_X-ELC180.AT2 and "
                             "RSN6_X-ELC270.AT2)", source=spec.source)
        (fa, a), (fb, b) = sorted(members, key=lambda m: m[0].name)
        if abs(a.dt - b.dt) > 1e-9 * a.dt or a.n != b.n:
            raise InputError("records.pairs", [fa.name, fb.name],
                             "two components with the same time step and length",
                             source=spec.source, hint=f"{fa.name}: {a.n} x {a.dt:g} s, "
                             f"{fb.name}: {b.n} x {b.dt:g} s")
        out.append((key, (a, b)))
    return out


def _check_dimensions(spec: StudySpec, racks: dict, records: list) -> None:
    """Pairs of components and an incidence angle need 3D racks (the feature table). A
    warehouse's 2D rows take the motion along their down-aisle axis (the executor projects it),
    so a warehouse is not checked."""
    from seisrack.model.features import require

    if spec.warehouse is not None:
        return
    two = next((n for n, _, comps in records if len(comps) == 2), None)
    for rack in racks.values():
        if two is not None:
            require("a cross-aisle ground motion component", rack.ndm, "records",
                    f"{two} (a pair of components)")
        if spec.angle.turns:
            require("an incidence angle of the horizontal components", rack.ndm, "angle",
                    spec.angle.values or f"{spec.angle.kind} {spec.angle.low:g}-"
                    f"{spec.angle.high:g} deg")


def _pattern(n: int, occupancy: float, seed: int, rack_hash: str) -> tuple[int, ...]:
    """Indices of the pallets kept at ``occupancy``: round-half-up(occupancy·n) of them."""
    if occupancy >= 1.0:
        return tuple(range(n))
    k = min(n, math.floor(occupancy * n + 0.5))
    rng = np.random.default_rng([seed, _seed_key("occupancy", rack_hash, occupancy)])
    return tuple(sorted(int(i) for i in rng.choice(n, size=k, replace=False)))


def apply_pattern(rack, kept: tuple[int, ...]):  # noqa: ANN001, ANN201
    """The rack spec with only the pallets ``kept``."""
    from dataclasses import replace

    if len(kept) == len(rack.pallets):
        return rack
    return replace(rack, pallets=tuple(rack.pallets[i] for i in kept))


def _first_period(rack, kept: tuple[int, ...], given: str) -> float:  # noqa: ANN001
    from seisrack.fe.modal import modal_analysis
    from seisrack.model import compile_rack

    model = compile_rack(apply_pattern(rack, kept))
    return float(modal_analysis(model, n_modes=1).periods[0])


def _intensity_of(rec: Record, measure: str, period: float, damping: float) -> float:
    """[m/s²] PGA, or Sa(period, damping) of the unscaled record."""
    if measure == "pga":
        return float(np.max(np.abs(rec.accel)))
    from seisrack.motion import response_spectrum

    return float(response_spectrum(rec.accel, rec.dt, [period], damping).psa[0])


def _check_reachable(name: str, rec: Record, im0: float, levels: tuple[float, ...], intensity,
                     dt: float, period: float) -> None:  # noqa: ANN001
    from seisrack.analysis.rack import analysis_grid

    what = "PGA" if intensity.measure == "pga" else f"Sa(T1 = {period:.4g} s)"
    if not (im0 > 0.0 and math.isfinite(im0)):
        raise InputError(f"records: {name}", f"{what} = {im0:g} m/s²",
                         "a record with a non-zero intensity (scaling cannot reach the "
                         "targets)", hint="Remove this record from the study")
    top = max(levels)
    if top / im0 > intensity.max_scale:
        raise InputError("intensity", f"{top:g} m/s² on record {name} ({what} = {im0:.4g} "
                         f"m/s², scale factor {top / im0:.3g})",
                         f"targets reachable with a scale factor <= intensity.max_scale = "
                         f"{intensity.max_scale:g}",
                         hint="Lower the stripes, remove the record or raise max_scale")
    try:
        analysis_grid(rec, dt)
    except SeisrackError as exc:
        raise InputError("dt", dt, f"an analysis step dividing the time step of record {name} "
                         f"({rec.dt:g} s)", hint=str(exc)) from None


def _angle_samples(spec: StudySpec, rack_hash: str, rec_hash: str,
                   occupancy: float) -> list[float]:
    """The incidence angles of one (rack, record, occupancy) [deg]: the listed values, or
    uniform draws seeded by the cell (common to every intensity level)."""
    a = spec.angle
    if a.kind == "values":
        return list(a.values)
    out = []
    for k in range(a.samples):
        rng = np.random.default_rng(
            [spec.seed, _seed_key("angle", rack_hash, rec_hash, occupancy), k])
        out.append(float(a.low + (a.high - a.low) * rng.random()))
    return out


def _friction_samples(spec: StudySpec, rack_hash: str, rec_hash: str,
                      occupancy: float) -> list[float]:
    f = spec.friction
    if f.kind == "values":
        return list(f.values)
    out = []
    for k in range(f.samples):
        rng = np.random.default_rng(
            [spec.seed, _seed_key("friction", rack_hash, rec_hash, occupancy), k])
        out.append(sample_friction(f, float(rng.random())))
    return out


def sample_friction(f, u: float) -> float:  # noqa: ANN001
    """μ_static at probability level ``u`` in (0, 1) of the distribution (inverse CDF)."""
    from scipy.special import ndtr, ndtri

    u = min(max(u, 1e-12), 1.0 - 1e-12)
    if f.kind == "lognormal":
        return float(f.param("median") * math.exp(f.param("dispersion") * ndtri(u)))
    if f.kind == "uniform":
        return float(f.param("low") + (f.param("high") - f.param("low")) * u)
    mean, std = f.param("mean"), f.param("std")
    a, b = ndtr((f.param("low") - mean) / std), ndtr((f.param("high") - mean) / std)
    x = float(mean + std * ndtri(a + (b - a) * u))
    return min(max(x, f.param("low")), f.param("high"))
