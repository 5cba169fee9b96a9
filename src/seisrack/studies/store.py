"""The study store: ``study.json`` and one Parquet part file per flushed batch of rows.

Layout of ``out_dir``::

    study.json                 the study as given and the expanded run table (ids and inputs)
    runs/part-<hash>.parquet   rows of finished runs (schema :data:`SCHEMA`), one file per flush

Why Parquet (through pyarrow): it is columnar (a fragility fit reads two columns of 10⁵ rows
without touching the others), typed (float64, int64, bool, list<float64> per-pallet values:
no CSV parsing or unit guessing), compressed, and readable by any tool (pandas, polars, DuckDB,
R arrow, Spark). Appending is writing a new part file, so the driver never rewrites what is
stored. Each part is written under a temporary name in the same folder and renamed with
``os.replace`` (atomic on POSIX): a killed driver leaves complete part files only, and a
resumed study reads the run ids already stored and runs the others.

A part file that cannot be read (truncated by a full disk, damaged, or foreign: not written
by this store) is never deleted and never stops a study: :func:`check_parts` moves it to
``runs/quarantine/`` with a ``.reason.txt`` beside it, and names it; the runs it held are
then missing from the store, so a resumed study recomputes them (:func:`run_study` calls it
first). Readers that meet such a file later set it aside the same way and raise
:class:`StoreError` naming it.

:func:`read_runs` deduplicates by ``run_id`` (a run stored twice, e.g. by a driver killed
between writing a part and noticing it, counts once) and sorts by ``run_id``. A run stored both
as "skipped" (an IDA level above a stop rule's level) and as run (the rule was changed or
removed, and the level run on resume) is returned as run.

One folder holds one study. ``study.json`` is valid JSON (a value that does not exist, such as
``period_s`` of a PGA study, is ``null``; files written before held ``NaN``, which
:func:`read_study_json` still reads). :func:`write_study_json` refuses a study that does not
extend the one stored (:func:`check_extends`): its stored runs would otherwise be left without
their definition and mixed with the new study's.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from seisrack.atomic import atomic_write, write_text
from seisrack.errors import InputError, SeisrackError
from seisrack.jsonable import read_json_object, to_jsonable

#: row columns in order: (name, pyarrow type name)
COLUMNS = (
    ("run_id", "string"), ("rack", "string"), ("record", "string"), ("im_measure", "string"),
    ("im_target", "float64"), ("scale_factor", "float64"), ("stripe", "int64"),
    ("mu_static", "float64"), ("mu_dynamic", "float64"), ("occupancy", "float64"),
    ("seed", "int64"), ("status", "string"), ("error", "string"),
    ("peak_sliding_max_m", "float64"), ("pallet_peak_sliding_m", "list<float64>"),
    ("n_pallets", "int64"), ("any_fall", "bool"), ("n_fall", "int64"),
    ("base_shear_N", "float64"), ("beam_displacement_max_m", "float64"),
    ("drift_ratio_max", "float64"), ("upright_moment_connection_Nm", "float64"),
    ("wall_time_s", "float64"),
    # the sliding reduction (issue 24): this run's and its rigid-pallet companion's peaks
    ("connector_moment_Nm", "float64"), ("upright_moment_Nm", "float64"),
    ("rigid_base_shear_N", "float64"), ("rigid_connector_moment_Nm", "float64"),
    ("rigid_upright_moment_Nm", "float64"), ("rigid_alpha", "float64"),
    # 3D racks (issue 21): the incidence angle, falls into the aisles, sliding per direction
    ("angle_deg", "float64"), ("any_aisle_fall", "bool"), ("n_aisle_fall", "int64"),
    ("peak_sliding_down_aisle_max_m", "float64"), ("peak_sliding_cross_aisle_max_m", "float64"),
)
RUNS_DIR = "runs"
STUDY_JSON = "study.json"
#: where unreadable or foreign part files are moved (inside ``runs/``; never deleted)
QUARANTINE_DIR = "quarantine"
#: columns a part file must hold, with the types of :data:`COLUMNS`, to be read: what defines
#: a run and its outcome. Other columns may be missing (a store written before a column was
#: added: read as nulls) but, when present, must have their type.
REQUIRED = ("run_id", "rack", "record", "im_measure", "im_target", "scale_factor", "stripe",
            "mu_static", "mu_dynamic", "occupancy", "seed", "status", "error")


class StoreError(SeisrackError):
    """A part file of the store could not be read (it was set aside: see :func:`check_parts`)."""


@dataclass(frozen=True)
class SetAside:
    """A part file moved to ``runs/quarantine/``: where it was, where it is, and why."""

    part: str
    moved_to: str
    reason: str

    def message(self) -> str:
        return (f"part file {self.part} {self.reason}: moved to {self.moved_to} (not deleted); "
                "the runs it held are missing from the store")


def schema():  # noqa: ANN201
    """The pyarrow schema of a row table."""
    import pyarrow as pa

    types = {"string": pa.string(), "float64": pa.float64(), "int64": pa.int64(),
             "bool": pa.bool_(), "list<float64>": pa.list_(pa.float64())}
    return pa.schema([(name, types[t]) for name, t in COLUMNS])


def rows_to_table(rows: list[dict[str, Any]]):  # noqa: ANN201
    import pyarrow as pa

    sch = schema()
    return pa.table({name: pa.array([r[name] for r in rows], type=sch.field(name).type)
                     for name in sch.names}, schema=sch)


def write_part(out_dir: str | Path, rows: list[dict[str, Any]]) -> Path | None:
    """Write ``rows`` as one part file, atomically; returns its path (None if no rows)."""
    if not rows:
        return None
    import pyarrow.parquet as pq

    runs = Path(out_dir) / RUNS_DIR
    runs.mkdir(parents=True, exist_ok=True)
    digest = hashlib.sha256("\n".join(sorted(r["run_id"] for r in rows)).encode()).hexdigest()
    path = runs / f"part-{digest[:20]}.parquet"
    table = rows_to_table(rows)
    return atomic_write(path, lambda tmp: pq.write_table(table, tmp))


def part_files(out_dir: str | Path) -> list[Path]:
    runs = Path(out_dir) / RUNS_DIR
    return sorted(runs.glob("part-*.parquet")) if runs.is_dir() else []


def check_parts(out_dir: str | Path) -> list[SetAside]:
    """Check every part file (its footer, schema, and ``run_id`` / ``status`` columns) and
    move each one that cannot be read, or is foreign, to ``runs/quarantine/``.

    Returns what was set aside (empty when the store is sound). Raises :class:`StoreError`
    when a bad file cannot even be moved (e.g. a read-only folder).
    """
    import pyarrow.parquet as pq

    sch = schema()
    out = []
    for p in part_files(out_dir):
        try:
            reason = _foreign(pq.read_schema(p), sch)
            if reason is None:
                pq.read_table(p, columns=["run_id", "status"])
        except MemoryError:
            raise
        except Exception as exc:  # noqa: BLE001 - pyarrow's many errors: the file is bad
            reason = f"cannot be read ({_why(exc)})"
        if reason is not None:
            out.append(_set_aside(p, reason))
    return out


def _foreign(got: Any, sch: Any) -> str | None:
    """Why a part file's schema is not this store's (None if it is)."""
    names = set(got.names)
    missing = [c for c in REQUIRED if c not in names]
    if missing:
        return f"is not a seisrack study part (no column {', '.join(missing[:4])})"
    for f in sch:
        if f.name in names and not got.field(f.name).type.equals(f.type):
            return (f"is not a seisrack study part (column {f.name} is "
                    f"{got.field(f.name).type}, not {f.type})")
    return None


def _why(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    text = text.replace(str(exc.filename), "") if getattr(exc, "filename", None) else text
    return f"{type(exc).__name__}: {text[:200]}" if text else type(exc).__name__


def _set_aside(p: Path, reason: str) -> SetAside:
    """Move ``p`` to ``runs/quarantine/`` (a new name if taken) with a note of ``reason``."""
    q = p.parent / QUARANTINE_DIR
    dest = q / p.name
    k = 1
    while dest.exists():
        dest, k = q / f"{p.name}.{k}", k + 1
    try:
        q.mkdir(exist_ok=True)
        os.replace(p, dest)
    except OSError as exc:
        raise StoreError(f"part file {p} {reason}, and it cannot be moved aside to {q} "
                         f"({exc.strerror or exc}): move it out of {p.parent} yourself, then "
                         "run the command again (its runs are recomputed)") from None
    try:
        write_text(dest.with_name(dest.name + ".reason.txt"), f"{p}: {reason}\n")
    except OSError:  # the file itself is safe; the note is a courtesy
        pass
    return SetAside(part=str(p), moved_to=str(dest), reason=reason)


def _read_part(p: Path, **kw: Any):  # noqa: ANN202
    """``pq.read_table(p, **kw)``; a bad file is set aside and :class:`StoreError` raised."""
    import pyarrow.parquet as pq

    try:
        return pq.read_table(p, **kw)
    except MemoryError:
        raise
    except Exception as exc:  # noqa: BLE001 - pyarrow's many errors: the file is bad
        aside = _set_aside(p, f"cannot be read ({_why(exc)})")
    raise StoreError(aside.message() + "; run the study again to recompute them")


def stored_run_ids(out_dir: str | Path, *, skipped: bool = True) -> set[str]:
    """Ids of the runs already in the store (reads the ``run_id`` column only).

    skipped: False leaves out the runs stored only as "skipped" (IDA levels above a stop rule's
    level: not run).
    """
    ids: set[str] = set()
    for p in part_files(out_dir):
        if skipped:
            ids.update(_read_part(p, columns=["run_id"]).column(0).to_pylist())
            continue
        t = _read_part(p, columns=["run_id", "status"]).to_pydict()
        ids.update(i for i, st in zip(t["run_id"], t["status"], strict=True)
                   if st != "skipped")
    return ids


def read_runs(out_dir: str | Path, columns: list[str] | None = None):  # noqa: ANN201
    """Every stored run as a ``pyarrow.Table``: one row per ``run_id``, sorted by ``run_id``.

    columns: read only these (``run_id`` and ``status`` are always read); default all.
    Of a run stored twice, a row that was run is kept before a "skipped" one.
    """
    import numpy as np
    import pyarrow as pa
    import pyarrow.compute as pc

    sch = schema()
    if columns is not None:
        keep = {"run_id", "status", *columns}
        sch = pa.schema([f for f in sch if f.name in keep])
    parts = [_read_part(p, schema=sch, columns=sch.names) for p in part_files(out_dir)]
    if not parts:
        return sch.empty_table()
    table = pa.concat_tables(parts)
    skipped = pc.equal(table.column("status"), "skipped").cast(pa.int8())
    table = table.append_column("_skipped", skipped).sort_by(
        [("run_id", "ascending"), ("_skipped", "ascending")]).drop_columns(["_skipped"])
    ids = np.asarray(table.column("run_id").to_pylist(), dtype=object)
    if ids.size:
        first = np.ones(ids.size, dtype=bool)
        first[1:] = ids[1:] != ids[:-1]
        if not first.all():
            table = table.filter(pa.array(first))
    return table


def read_study_json(out_dir: str | Path) -> dict[str, Any] | None:
    """The document of ``out_dir/study.json``, or None when it is absent, unreadable or empty
    (files written before ``null`` replaced ``NaN`` are read too)."""
    return read_json_object(Path(out_dir) / STUDY_JSON)


def planned_stripes(doc: dict[str, Any] | None) -> dict[str, int] | None:
    """``run_id`` -> stripe index (-1 for IDA) of the run table of a ``study.json`` document;
    None when there is no run table (no file, an unreadable or hand-written one)."""
    try:
        return {str(r["run_id"]): int(r["stripe"]) for r in doc["runs"]} or None
    except (TypeError, KeyError, ValueError):
        return None


def check_extends(out_dir: str | Path, runs: Iterable, *, source: str | None = None) -> None:
    """Refuse (:class:`InputError` naming ``--out``) to write a study of ``runs`` into
    ``out_dir`` when a run stored there for the study of its ``study.json`` is not one of
    ``runs``: the same study (a resume) and an extension (more stripes, records, friction
    samples: every stored run keeps its inputs) pass; a changed one (another stripe level,
    record, friction, rack or step) would leave those runs without their definition and mix
    the two studies. Checked before anything is written or run.
    """
    out = Path(out_dir)
    stored = stored_run_ids(out)
    if not stored:
        return
    doc = read_study_json(out)
    planned = planned_stripes(doc)
    # runs its study.json does not list (a folder mixed before this check) are not its own
    ours = stored if planned is None else stored & planned.keys()
    lost = sorted(ours - {r.run_id for r in runs})
    if not lost:
        return
    owner = "another study"
    if planned is not None:
        owner = f"the study of {out / STUDY_JSON}" + (f" ({doc['source']})"
                                                      if doc.get("source") else "")
    raise InputError(
        "--out", str(out), "a new folder, or the folder of this study or of a study it "
        "extends (the same runs plus more stripes, records or friction samples)",
        source=source,
        hint=f"{len(lost)} of the {len(ours)} runs stored there belong to {owner} and are "
             f"not runs of this one (e.g. {_describe(out, lost[0])}): running it there would "
             "replace that definition and mix the two studies in the summary. Choose a new "
             f"folder for --out, or move {out} away; nothing was run or written")


def _describe(out: Path, run_id: str) -> str:
    """One stored run in words: its rack, record, intensity and stripe."""
    import pyarrow.compute as pc

    cols = ["rack", "record", "im_measure", "im_target", "stripe"]
    t = read_runs(out, columns=cols)
    row = t.filter(pc.equal(t.column("run_id"), run_id)).to_pylist()[0]
    where = f"stripe {row['stripe']}" if row["stripe"] >= 0 else "IDA"
    return (f"run {run_id}: rack {row['rack']}, record {row['record']}, "
            f"{row['im_measure']} = {row['im_target']:.4g} m/s², {where}")


def write_study_json(out_dir: str | Path, spec, runs: Iterable) -> Path:  # noqa: ANN001
    """``study.json``: the study file as given, the resolved inputs and the run table.

    Refuses a study that does not extend the one stored in ``out_dir`` (:func:`check_extends`).
    Non-finite values (``period_s`` of a PGA run) are written as ``null``.
    """
    from dataclasses import asdict

    runs = list(runs)
    out = Path(out_dir)
    check_extends(out, runs, source=spec.source)
    out.mkdir(parents=True, exist_ok=True)
    doc = {
        "format": "seisrack-study/1",
        "source": spec.source,
        "study_toml": spec.text,
        "title": spec.title,
        "racks": list(spec.racks_as_given),
        "dt": spec.dt,
        "seed": spec.seed,
        "intensity": {"measure": spec.intensity.measure,
                      "levels_m_s2": list(spec.intensity.levels),
                      "kind": "ida" if spec.intensity.is_ida else "stripes",
                      "ida_stop_rule": (spec.intensity.ida_stop.label
                                        if spec.intensity.ida_stop else None)},
        "runs": [asdict(r) for r in runs],
    }
    wh = getattr(spec, "warehouse", None)
    if wh is not None:
        doc["warehouse"] = {"file": spec.warehouse_as_given, "path": wh.source,
                            "title": wh.title,
                            "groups": [{"name": r.name, "rack": r.rack_as_given, "count": r.count,
                                        "orientation_deg": r.orientation_deg,
                                        "angle_deg": -float(r.orientation_deg) + 0.0,
                                        "n_pallets": r.n_pallets, "three_d": r.three_d}
                                       for r in wh.rows]}
    return write_text(out / STUDY_JSON,
                      json.dumps(to_jsonable(doc), indent=1, allow_nan=False))
