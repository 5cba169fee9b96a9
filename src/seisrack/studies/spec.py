"""The study specification: what a user writes in a study TOML, validated once at the boundary.

Every key is documented in ``docs/user/study_toml.md``. :func:`load_study` reads the file and
returns a frozen :class:`StudySpec`; every mistake a user can make in the file is an
:class:`~seisrack.errors.InputError` naming the field path (``friction.dispersion``), the value
and what is allowed. Problems that need the records or the rack (a missing file, an intensity
that cannot be reached by scaling) are found by :func:`seisrack.studies.expand.expand`, still
before any run starts.

Units: SI inside (m/s² for PGA and Sa); ``intensity.unit = "g"`` converts the stripes once here.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from seisrack.errors import FileFormatError, InputError
from seisrack.limits import MAX_RECORD_SAMPLES, MAX_SUITE_COUNT
from seisrack.model._reader import Table, check_number
from seisrack.motion.records import G

MEASURES = ("pga", "sa")
DISTRIBUTIONS = ("lognormal", "uniform", "truncnormal")
STOP_RULES = ("fall", "sliding")  # intensity.ida.stop_when
DEFAULT_DT = 0.005  # s, analysis step
DEFAULT_MAX_SCALE = 50.0  # largest scale factor accepted on a record
_TOP_KEYS = ("title", "racks", "records", "intensity", "friction", "occupancy", "dt", "seed",
             "angle", "warehouse")
#: the distributions of a sampled incidence angle
ANGLE_DISTRIBUTIONS = ("uniform",)


@dataclass(frozen=True)
class EC8Suite:
    """A generated suite of EN 1998-1 spectrum-compatible records (``[[records.ec8]]``)."""

    type: int = 1
    ground: str = "C"
    ag: float = 0.3  # [g] design ground acceleration of the target spectrum
    duration: float = 10.0  # [s]
    count: int = 7
    seed: int = 0
    dt: float = 0.01  # [s] record time step
    components: int = 1  # 2: each record is a pair of horizontal components (3D racks)


@dataclass(frozen=True)
class RecordsSpec:
    """Where the records come from: a folder of files, bundled records, generated suites.

    pairs: the folder's files are pairs of horizontal components (3D racks): files whose
    names differ only by their last ``_``- or ``-``-separated token form a pair, the first by
    name down-aisle, the second cross-aisle (PEER NGA: ``RSN6_IMPVALL.I_I-ELC180.AT2`` and
    ``...-ELC270.AT2``).
    """

    folder: str | None = None  # resolved path of the folder (AT2 / CSV / TXT files)
    folder_as_given: str | None = None
    pairs: bool = False
    units: str | None = None  # units of CSV/TXT files without a header ("g" or "m/s2")
    file_dt: float | None = None  # [s] time step of one-column files
    builtin: tuple[str, ...] = ()
    ec8: tuple[EC8Suite, ...] = ()


@dataclass(frozen=True)
class IdaStop:
    """The stop rule of an IDA curve (``intensity.ida.stop_when``).

    An IDA curve (one rack, record, friction sample and occupancy) runs its levels in
    increasing order and stops at the first level whose run is "ok" and where the rule holds:
    ``"fall"``: any pallet falls (``any_fall``); ``"sliding"``: ``peak_sliding_max_m`` >
    ``sliding_m`` [m]. The levels above are not run (status "skipped").
    """

    when: str  # "fall" or "sliding"
    sliding_m: float = math.nan  # [m] threshold of "sliding"

    @property
    def label(self) -> str:
        """The rule as written in the study file (also in the reason of a skipped run)."""
        if self.when == "sliding":
            return f'stop_when = "sliding", sliding_m = {self.sliding_m!r}'
        return f'stop_when = "{self.when}"'

    def holds(self, row: dict) -> bool:
        """Whether the rule stops the curve at the run of ``row`` (a store row)."""
        if row.get("status") != "ok":
            return False  # a failed run tells nothing: the curve goes on
        if self.when == "fall":
            return bool(row["any_fall"])
        return bool(row["peak_sliding_max_m"] > self.sliding_m)


@dataclass(frozen=True)
class IntensitySpec:
    """The intensity measure and the levels the records are scaled to.

    stripes: (n,) [m/s²] targets (multiple-stripe analysis), or ``ida`` (incremental dynamic
    analysis on a fixed grid ``start, start + step, …`` up to ``stop``), with an optional
    stop rule ``ida_stop`` (each IDA curve stops at the first level where it holds).
    """

    measure: str = "pga"  # "pga" or "sa" (Sa(T1, damping) of the rack's first mode)
    stripes: tuple[float, ...] = ()
    ida: tuple[float, ...] = ()  # [m/s²] the IDA grid, expanded
    damping: float = 0.05
    max_scale: float = DEFAULT_MAX_SCALE
    ida_stop: IdaStop | None = None

    @property
    def levels(self) -> tuple[float, ...]:
        return self.stripes or self.ida

    @property
    def is_ida(self) -> bool:
        return not self.stripes


@dataclass(frozen=True)
class FrictionSpec:
    """Friction of every pallet: a list of values, or a distribution sampled per run.

    kind: "values", "lognormal" (median, dispersion = σ of ln μ), "uniform" (low, high) or
    "truncnormal" (mean, std, low, high). ``samples``: draws per (rack, record, occupancy)
    for a distribution; ``dynamic_ratio`` = μ_dynamic / μ_static.
    """

    kind: str = "values"
    values: tuple[float, ...] = (0.4,)
    params: tuple[tuple[str, float], ...] = ()
    samples: int = 1
    dynamic_ratio: float = 1.0

    def param(self, name: str) -> float:
        return dict(self.params)[name]


@dataclass(frozen=True)
class AngleSpec:
    """The incidence angle of the horizontal components [deg] (3D racks): a list of values,
    or ``samples`` draws per (rack, record, occupancy) from a uniform distribution on
    [low, high]; every run of a draw sees the same angle at every intensity level."""

    kind: str = "values"
    values: tuple[float, ...] = (0.0,)
    low: float = 0.0
    high: float = 0.0
    samples: int = 1

    @property
    def turns(self) -> bool:
        """True when some run turns the motion (an angle other than 0)."""
        return self.kind != "values" or any(v != 0.0 for v in self.values)


@dataclass(frozen=True)
class StudySpec:
    """A validated study. ``racks`` are resolved paths; ``racks_as_given`` as in the file."""

    racks: tuple[str, ...]
    racks_as_given: tuple[str, ...]
    records: RecordsSpec
    intensity: IntensitySpec
    friction: FrictionSpec = FrictionSpec()
    occupancy: tuple[float, ...] = (1.0,)
    angle: AngleSpec = AngleSpec()
    dt: float = DEFAULT_DT
    seed: int = 0
    title: str = ""
    source: str | None = None
    text: str = ""  # the study file as given (stored in study.json)
    warehouse: Any = None  # a Warehouse (seisrack.studies.warehouse) instead of ``racks``
    warehouse_as_given: str | None = None
    #: per rack, the incidence angles [deg] of its warehouse rows (overrides ``angle``)
    rack_angles: tuple[tuple[float, ...], ...] = ()


def load_study(path: str | Path) -> StudySpec:
    """Read and validate a study TOML file (paths inside are relative to the file)."""
    p = Path(path)
    if not p.is_file():
        raise InputError("study", str(p), "an existing study TOML file")
    raw = p.read_bytes()
    try:
        text = raw.decode("utf-8-sig")  # a BOM (Windows Notepad) is fine
        data = tomllib.loads(text)
    except UnicodeDecodeError as exc:
        raise FileFormatError(str(p), f"not UTF-8 text ({exc.reason})") from None
    except tomllib.TOMLDecodeError as exc:
        raise FileFormatError(str(p), f"malformed TOML: {exc}") from None
    return study_from_dict(data, base=p.parent, source=str(p), text=text)


def study_from_dict(d: Any, *, base: str | Path = ".", source: str | None = None,
                    text: str = "") -> StudySpec:
    """Validate a parsed study document; relative paths are taken from ``base``."""
    base = Path(base)
    root = Table(d, "", source)
    title = root.string("title", "")
    if root.has("warehouse"):
        return _warehouse_study(root, d, base, source, text, title)
    racks_raw = root.raw("racks")
    racks_list = [racks_raw] if isinstance(racks_raw, str) else racks_raw
    if not isinstance(racks_list, list) or not racks_list or not all(
            isinstance(r, str) and r for r in racks_list):
        raise root.error("racks", racks_raw, "a rack TOML path or a non-empty array of paths "
                                             "(relative to the study file)")
    if len(set(racks_list)) != len(racks_list):
        raise root.error("racks", racks_raw, "distinct paths (a rack is listed twice)")
    racks = []
    for i, r in enumerate(racks_list):
        rp = (base / r) if not Path(r).is_absolute() else Path(r)
        if not rp.is_file():
            field = "racks" if isinstance(racks_raw, str) else f"racks[{i}]"
            raise InputError(field, r, f"an existing rack TOML file (looked for {rp})",
                             source=source)
        racks.append(str(rp))
    records = _records(root.table("records"), base)
    intensity = _intensity(root.table("intensity"))
    friction = _friction(root.table("friction", {"values": [0.4]}))
    occupancy = _occupancy(root.table("occupancy", {}))
    angle = _angle(root.table("angle", {}))
    dt = root.number("dt", DEFAULT_DT, positive=True, unit="s")
    seed = root.integer("seed", 0, minimum=0)
    root.finish(_TOP_KEYS)
    return StudySpec(racks=tuple(racks), racks_as_given=tuple(racks_list), records=records,
                     intensity=intensity, friction=friction, occupancy=occupancy, angle=angle,
                     dt=dt, seed=seed, title=title, source=source, text=text)


def _warehouse_study(root: Table, d: Any, base: Path, source: str | None, text: str,
                     title: str) -> StudySpec:
    """A study of every rack row of a warehouse file (``warehouse = "site.toml"`` instead of
    ``racks``): each group of rows is a rack run at its orientation (docs/user/
    warehouse_toml.md); identical rows of a group see the same ground motion."""
    from seisrack.studies.warehouse import load_warehouse

    given = root.string("warehouse")
    for key in ("racks", "angle"):
        if root.has(key):
            raise root.error(key, d[key], f"no '{key}' with 'warehouse' (the warehouse file "
                             "gives the racks and their orientations)")
    wp = base / given if not Path(given).is_absolute() else Path(given)
    if not wp.is_file():
        raise root.error("warehouse", given, f"an existing warehouse TOML file (looked for {wp})")
    wh = load_warehouse(wp)
    racks: list[str] = []  # as given in the warehouse file (labels of the runs)
    paths: dict[str, str] = {}
    angles: dict[str, list[float]] = {}
    for row in wh.rows:
        if row.rack_as_given not in angles:
            racks.append(row.rack_as_given)
            paths[row.rack_as_given] = str(Path(row.rack).resolve())
            angles[row.rack_as_given] = []
        # the motion in the rack's axes is the record pair turned by -orientation
        a = -float(row.orientation_deg) + 0.0
        if a not in angles[row.rack_as_given]:
            angles[row.rack_as_given].append(a)
    inner = {k: v for k, v in d.items() if k not in ("warehouse", "title")}
    spec = study_from_dict({**inner, "racks": [paths[r] for r in racks],
                            "title": title or wh.title}, base=base, source=source, text=text)
    from dataclasses import replace

    return replace(spec, racks_as_given=tuple(racks), warehouse=wh, warehouse_as_given=given,
                   rack_angles=tuple(tuple(angles[r]) for r in racks))


def _angle(t: Table) -> AngleSpec:
    """``[angle]``: ``values = [deg, ...]`` or ``dist = "uniform"``, ``low``, ``high``,
    ``samples`` (degrees, -360 to 360)."""
    if t.has("values") and t.has("dist"):
        raise t.error("values", t.data.get("values"), "one of 'values' (an array of angles "
                      "[deg]) or 'dist' (\"uniform\" with low, high, samples), not both")

    def degrees(v: Any, field: str) -> float:
        x = check_number(v, field, unit="deg", source=t.source)
        if not -360.0 <= x <= 360.0:
            raise InputError(field, v, "an angle in degrees, -360 to 360", source=t.source)
        return x

    if t.has("dist"):
        dist = t.string("dist")
        if dist not in ANGLE_DISTRIBUTIONS:
            raise t.error("dist", dist, ", ".join(f'"{d}"' for d in ANGLE_DISTRIBUTIONS))
        low = degrees(t.raw("low", 0.0), t.field("low"))
        high = degrees(t.raw("high"), t.field("high")) if t.has("high") else None
        if high is None or high <= low:
            raise t.error("high", t.data.get("high"), f"an angle > low ({low:g} deg)")
        samples = t.integer("samples", 1, minimum=1)
        t.finish(("dist", "low", "high", "samples"))
        return AngleSpec(kind=dist, values=(), low=low, high=high, samples=samples)
    raw = t.array("values", [0.0], min_len=1)
    vals = tuple(degrees(v, f"{t.field('values')}[{i}]") for i, v in enumerate(raw))
    if len(set(vals)) != len(vals):
        raise t.error("values", raw, "distinct angles (an angle is listed twice)")
    t.finish(("values",))
    return AngleSpec(values=vals)


def _records(t: Table, base: Path) -> RecordsSpec:
    folder = folder_given = None
    if t.has("folder"):
        folder_given = t.string("folder")
        fp = base / folder_given
        if not fp.is_dir():
            raise t.error("folder", folder_given,
                          f"an existing folder of records (looked for {fp})")
        folder = str(fp)
    units = t.string("units", None) if t.has("units") else None
    if units is not None and units not in ("g", "m/s2"):
        raise t.error("units", units, "'g' or 'm/s2'")
    file_dt = t.number("dt", positive=True, unit="s") if t.has("dt") else None
    builtin_raw = t.raw("builtin", [])
    builtin = [builtin_raw] if isinstance(builtin_raw, str) else builtin_raw
    from seisrack.motion import list_builtin_records

    known = list_builtin_records()
    if not isinstance(builtin, list):
        raise t.error("builtin", builtin_raw, "a bundled record name or an array of names")
    for i, name in enumerate(builtin):
        if name not in known:
            raise t.error(f"builtin[{i}]", name, "one of " + ", ".join(known))
    ec8_raw = t.raw("ec8", [])
    ec8_list = [ec8_raw] if isinstance(ec8_raw, dict) else ec8_raw
    if not isinstance(ec8_list, list):
        raise t.error("ec8", ec8_raw, "a table or an array of tables [[records.ec8]]")
    ec8 = tuple(_ec8(Table(e, f"{t.field('ec8')}[{i}]", t.source)) for i, e in enumerate(ec8_list))
    pairs = t.raw("pairs", False)
    if not isinstance(pairs, bool):
        raise t.error("pairs", pairs, "true or false")
    if pairs and folder is None:
        raise t.error("pairs", True, "pairs = true with a folder of record files (it groups "
                      "the folder's files into pairs of horizontal components)")
    t.finish(("folder", "units", "dt", "builtin", "ec8", "pairs"))
    if folder is None and not builtin and not ec8:
        raise t.error("<records>", {}, "at least one of folder, builtin, ec8")
    return RecordsSpec(folder=folder, folder_as_given=folder_given, pairs=pairs, units=units,
                       file_dt=file_dt, builtin=tuple(builtin), ec8=ec8)


def _ec8(t: Table) -> EC8Suite:
    typ = t.integer("type", 1, minimum=1)
    if typ not in (1, 2):
        raise t.error("type", typ, "1 or 2 (EN 1998-1 spectrum type)")
    ground = t.string("ground", "C")
    if ground not in ("A", "B", "C", "D", "E"):
        raise t.error("ground", ground, "one of A, B, C, D, E")
    s = EC8Suite(type=typ, ground=ground, ag=t.number("ag", 0.3, positive=True, unit="g"),
                 duration=t.number("duration", 10.0, positive=True, unit="s"),
                 count=t.integer("count", 7, minimum=1), seed=t.integer("seed", 0, minimum=0),
                 dt=t.number("dt", 0.01, positive=True, unit="s"),
                 components=t.integer("components", 1, minimum=1))
    if s.components > 2:
        raise t.error("components", s.components, "1 (one horizontal component) or 2 (a pair, "
                      "for 3D racks)")
    t.finish(("type", "ground", "ag", "duration", "count", "seed", "dt", "components"))
    if s.count > MAX_SUITE_COUNT:
        raise t.error("count", s.count, f"an integer from 1 to {MAX_SUITE_COUNT:,}")
    if s.duration / s.dt > MAX_RECORD_SAMPLES:
        raise t.error("duration", s.duration, f"a duration of at most {MAX_RECORD_SAMPLES:,} "
                      f"time steps ({MAX_RECORD_SAMPLES * s.dt:g} s at dt = {s.dt:g} s)")
    return s


def _intensity(t: Table) -> IntensitySpec:
    measure = t.string("measure", "pga")
    if measure not in MEASURES:
        raise t.error("measure", measure, "'pga' (peak ground acceleration) or 'sa' "
                                          "(Sa(T1) of the rack's first mode)")
    unit = t.string("unit", "m/s2")
    if unit not in ("m/s2", "g"):
        raise t.error("unit", unit, "'m/s2' (default) or 'g'")
    factor = G if unit == "g" else 1.0
    damping = t.number("damping", 0.05, nonnegative=True)
    if damping >= 1.0:
        raise t.error("damping", damping, "a damping ratio in [0, 1)")
    max_scale = t.number("max_scale", DEFAULT_MAX_SCALE, positive=True)
    for key in ("stop_when", "sliding_m"):
        if t.has(key):
            raise t.error(key, t.data[key], "no key here: a stop rule applies to IDA only and "
                          "is written in the ida table, e.g. ida = {start = 0.1, step = 0.1, "
                          f"stop = 1.0, {key} = ...}}")
    if t.has("stripes") == t.has("ida"):
        raise t.error("stripes", t.data.get("stripes"),
                      "exactly one of 'stripes' (an array of levels) or 'ida' (a table "
                      "{start, step, stop})")
    stripes: tuple[float, ...] = ()
    ida: tuple[float, ...] = ()
    ida_stop = None
    if t.has("stripes"):
        raw = t.array("stripes")
        if not raw:
            raise t.error("stripes", raw, f"a non-empty array of intensity levels > 0 [{unit}]")
        stripes = tuple(factor * check_number(v, f"{t.field('stripes')}[{i}]", positive=True,
                                              unit=unit, source=t.source)
                        for i, v in enumerate(raw))
        if len(set(stripes)) != len(stripes):
            raise t.error("stripes", raw, "distinct levels (a level is listed twice)")
    else:
        it = t.table("ida")
        start = it.number("start", positive=True, unit=unit)
        step = it.number("step", positive=True, unit=unit)
        stop = it.number("stop", positive=True, unit=unit)
        ida_stop = _ida_stop(it)
        it.finish(("start", "step", "stop", "stop_when", "sliding_m"))
        if stop < start:
            raise it.error("stop", stop, f"a level >= start ({start:g} {unit})")
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > 1000:
            raise it.error("step", step, "a step giving at most 1000 IDA levels")
        ida = tuple(factor * (start + k * step) for k in range(n))
    t.finish(("measure", "unit", "stripes", "ida", "damping", "max_scale"))
    return IntensitySpec(measure=measure, stripes=stripes, ida=ida, damping=damping,
                         max_scale=max_scale, ida_stop=ida_stop)


def _ida_stop(it: Table) -> IdaStop | None:
    """The stop rule of ``intensity.ida`` (None without ``stop_when``)."""
    if not it.has("stop_when"):
        if it.has("sliding_m"):
            raise it.error("sliding_m", it.data["sliding_m"], "no sliding_m without "
                           'stop_when = "sliding" (the threshold of the sliding stop rule)')
        return None
    when = it.string("stop_when")
    if when not in STOP_RULES:
        raise it.error("stop_when", when, '"fall" (stop at the first level where a pallet '
                       'falls) or "sliding" (stop when the peak sliding exceeds sliding_m)')
    if when == "fall":
        if it.has("sliding_m"):
            raise it.error("sliding_m", it.data["sliding_m"],
                           'no sliding_m with stop_when = "fall" (it is the threshold of '
                           'stop_when = "sliding")')
        return IdaStop(when)
    if not it.has("sliding_m"):
        raise it.error("sliding_m", None, 'a sliding threshold > 0 [m] with stop_when = '
                       '"sliding"')
    return IdaStop(when, it.number("sliding_m", positive=True, unit="m"))


def _friction(t: Table) -> FrictionSpec:
    ratio = t.number("dynamic_ratio", 1.0, positive=True)
    if ratio > 1.0:
        raise t.error("dynamic_ratio", ratio, "a ratio mu_dynamic / mu_static in (0, 1]")
    if t.has("values") == t.has("dist"):
        raise t.error("values", t.data.get("values"),
                      "exactly one of 'values' (an array of mu_static) or 'dist' "
                      f"({', '.join(DISTRIBUTIONS)})")
    if t.has("values"):
        raw = t.array("values", min_len=1)
        vals = tuple(check_number(v, f"{t.field('values')}[{i}]", positive=True,
                                  source=t.source) for i, v in enumerate(raw))
        t.finish(("values", "dynamic_ratio"))
        return FrictionSpec(kind="values", values=vals, dynamic_ratio=ratio)
    dist = t.string("dist")
    samples = t.integer("samples", 1, minimum=1)
    if dist == "lognormal":
        params = {"median": t.number("median", positive=True),
                  "dispersion": t.number("dispersion", positive=True)}
        keys = ("median", "dispersion")
    elif dist == "uniform":
        params = {"low": t.number("low", positive=True), "high": t.number("high", positive=True)}
        if params["high"] <= params["low"]:
            raise t.error("high", params["high"], f"a value > low ({params['low']:g})")
        keys = ("low", "high")
    elif dist == "truncnormal":
        params = {"mean": t.number("mean", positive=True), "std": t.number("std", positive=True),
                  "low": t.number("low", positive=True), "high": t.number("high", positive=True)}
        if params["high"] <= params["low"]:
            raise t.error("high", params["high"], f"a value > low ({params['low']:g})")
        keys = ("mean", "std", "low", "high")
        from scipy.special import ndtr

        mass = ndtr((params["high"] - params["mean"]) / params["std"]) - ndtr(
            (params["low"] - params["mean"]) / params["std"])
        if not mass > 1e-9:
            raise t.error("low", params["low"], "an interval [low, high] holding some "
                          f"probability of the normal(mean {params['mean']:g}, std "
                          f"{params['std']:g}) distribution")
    else:
        raise t.error("dist", dist, ", ".join(DISTRIBUTIONS))
    t.finish(("dist", "samples", "dynamic_ratio") + keys)
    return FrictionSpec(kind=dist, values=(), params=tuple(params.items()), samples=samples,
                        dynamic_ratio=ratio)


def _occupancy(t: Table) -> tuple[float, ...]:
    raw = t.array("fractions", [1.0], min_len=1)
    out = tuple(check_number(v, f"{t.field('fractions')}[{i}]", positive=True, source=t.source)
                for i, v in enumerate(raw))
    for i, v in enumerate(out):
        if v > 1.0:
            raise InputError(f"{t.field('fractions')}[{i}]", v, "a fraction in (0, 1]",
                             source=t.source)
    t.finish(("fractions",))
    return out
