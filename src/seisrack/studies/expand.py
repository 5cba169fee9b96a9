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


@dataclass(frozen=True)
class StudyPlan:
    """The expanded study: runs, and what a worker needs to run them.

    racks: rack hash -> RackSpec (all pallets); patterns: (rack hash, occupancy) -> kept pallet
    indices; records: record hash -> unscaled :class:`Record`.
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
    for i, (given, path) in enumerate(zip(spec.racks_as_given, spec.racks, strict=True)):
        h = _hash_bytes(Path(path).read_bytes())
        racks[h] = load_rack(path)
        require_study_support(racks[h], "racks" if len(spec.racks) == 1 else f"racks[{i}]",
                              given, spec.source)
        rack_keys.append((given, h))
    records = _load_records(spec)
    patterns = {}
    runs: list[Run] = []
    intensity = spec.intensity
    levels = intensity.levels
    for given, rh in rack_keys:
        rack = racks[rh]
        for occ in spec.occupancy:
            kept = _pattern(len(rack.pallets), occ, spec.seed, rh)
            patterns[(rh, occ)] = kept
            period = math.nan
            if intensity.measure == "sa":
                period = _first_period(rack, kept, given)
            for name, rec_h, rec in records:
                im0 = _intensity_of(rec, intensity.measure, period, intensity.damping)
                _check_reachable(name, rec, im0, levels, intensity, spec.dt, period)
                for mu_s in _friction_samples(spec, rh, rec_h, occ):
                    mu_d = mu_s * spec.friction.dynamic_ratio
                    for k, target in enumerate(levels):
                        rid = run_id(rh, name, rec_h, intensity.measure, target, mu_s, mu_d,
                                     occ, spec.seed, spec.dt)
                        runs.append(Run(
                            run_id=rid, rack=given, rack_hash=rh, record=name,
                            record_hash=rec_h, im_measure=intensity.measure,
                            im_target=float(target), scale_factor=float(target / im0),
                            stripe=-1 if intensity.is_ida else k, mu_static=float(mu_s),
                            mu_dynamic=float(mu_d), occupancy=float(occ), seed=spec.seed,
                            period_s=float(period)))
    dup = [i for i, c in Counter(r.run_id for r in runs).items() if c > 1]
    if dup:
        raise InputError("friction.values", spec.friction.values,
                         "values giving distinct runs (two runs of the study are identical)",
                         source=spec.source)
    return StudyPlan(runs=tuple(runs), racks=racks, patterns=patterns,
                     records={h: r for _, h, r in records}, dt=spec.dt,
                     ida_stop=intensity.ida_stop if intensity.is_ida else None)


#: what a study cannot run yet, each with the test of a rack (spec) that needs it. One table,
#: so that lifting a limitation is deleting its row (3D studies: being built).
UNSUPPORTED = (
    ("3D racks (a [geometry] depth)", lambda rack: rack.geometry.depth is not None),
)


def require_study_support(rack, field: str, given: str, source: str | None) -> None:  # noqa: ANN001
    """Refuse, before any run, a rack that needs a feature studies do not have yet."""
    for feature, needs in UNSUPPORTED:
        if needs(rack):
            raise InputError(field, given, "a rack that studies support: studies of "
                             f"{feature} are not built yet", source=source,
                             hint="Run it with seisrack run (one record at a time) for now")


def curve_key(run: Run) -> tuple:
    """The IDA curve of ``run``: (rack, occupancy, record, friction); levels vary along it."""
    return (run.rack_hash, run.occupancy, run.record, run.record_hash, run.mu_static,
            run.mu_dynamic)


def run_id(rack_hash: str, record: str, record_hash: str, measure: str, target: float,
           mu_s: float, mu_d: float, occupancy: float, seed: int, dt: float) -> str:
    """16 hex digits of the SHA-256 of the defining inputs (floats by their exact repr)."""
    key = json.dumps([rack_hash, record, record_hash, measure, repr(float(target)),
                      repr(float(mu_s)), repr(float(mu_d)), repr(float(occupancy)), int(seed),
                      repr(float(dt))])
    return hashlib.sha256(key.encode()).hexdigest()[:16]


def record_hash(rec: Record) -> str:
    """Content hash of a record: its samples and time step (not its name)."""
    h = hashlib.sha256(np.ascontiguousarray(rec.accel, dtype="<f8").tobytes())
    h.update(repr(float(rec.dt)).encode())
    return h.hexdigest()[:16]


def _hash_bytes(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()[:16]


def _seed_key(*parts: object) -> int:
    return int(hashlib.sha256(json.dumps([repr(p) for p in parts]).encode()).hexdigest()[:8], 16)


def _load_records(spec: StudySpec) -> list[tuple[str, str, Record]]:
    from seisrack.motion import generate_ec8_record, load_builtin_record, read_record

    rs = spec.records
    out: list[Record] = []
    if rs.folder is not None:
        files = sorted(p for p in Path(rs.folder).iterdir()
                       if p.is_file() and p.suffix.lower() in RECORD_SUFFIXES)
        if not files:
            raise InputError("records.folder", rs.folder_as_given,
                             "a folder holding record files (" + ", ".join(RECORD_SUFFIXES) + ")",
                             source=spec.source)
        for f in files:
            try:
                out.append(read_record(f, units=rs.units, dt=rs.file_dt))
            except SeisrackError as exc:
                raise InputError("records.folder", str(f), "a readable record file",
                                 source=spec.source, hint=str(exc)) from None
    out.extend(load_builtin_record(name) for name in rs.builtin)
    for i, s in enumerate(rs.ec8):
        for k in range(s.count):
            name = f"ec8_t{s.type}{s.ground}_ag{s.ag:g}_d{s.duration:g}_s{s.seed + k}"
            try:
                out.append(generate_ec8_record(type=s.type, ground=s.ground, ag=s.ag,
                                               duration=s.duration, dt=s.dt, seed=s.seed + k,
                                               name=name))
            except SeisrackError as exc:
                raise InputError(f"records.ec8[{i}]", s, "parameters the EC8 generator accepts",
                                 source=spec.source, hint=str(exc)) from None
    names = Counter(r.name for r in out)
    dup = sorted(n for n, c in names.items() if c > 1)
    if dup:
        raise InputError("records", dup, "records with distinct names (file stems, bundled "
                         "names and generated suites must not repeat)", source=spec.source)
    return [(r.name, record_hash(r), r) for r in out]


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
