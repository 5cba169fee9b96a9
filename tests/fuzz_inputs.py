"""Mutated inputs for the command-line fuzz test (not a test module): the examples' rack and
study TOMLs, record files and option values, changed by a seeded ``random.Random`` so that
the cases are the same on every run and every xdist worker.

A :class:`Case` is an argv (``@/name`` stands for a file of the case's folder), the files to
write there, and its time limit. :func:`all_cases` builds them all.
"""

from __future__ import annotations

import copy
import json
import math
import random
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
SEED = 20231123

#: values that break assumptions: signs, zeros, huge and tiny, non-finite, wrong types
VALUES: tuple[Any, ...] = (
    0, -1, 1, 2, 0.5, -0.5, 1e-300, 1e300, 1e9, -1e9, 1e-9, 100_000_000, 2**63 - 1,
    math.nan, math.inf, -math.inf, "", "abc", "1.0", "rigid", "pinned", True, False, [],
    [1], [1.0, "x"], [0.0, 0.0], {}, {"count": 3, "pitch": 1.0}, {"count": 0, "pitch": 1.0},
)
#: option values (strings, as typed on a command line)
OPTION_VALUES = ("0", "-1", "1e-12", "1e12", "nan", "inf", "-inf", "1e308", "abc", "",
                 "3", "0.7", "0.01", "2", "-0.0", "1,2", "T1")


@dataclass(frozen=True)
class Case:
    name: str
    argv: tuple[str, ...]
    files: tuple[tuple[str, bytes], ...] = ()
    store: bool = False  # copy the prebuilt study store to @/store
    limit_s: float = 90.0
    slow: bool = True
    exit_1_ok: bool = False  # the command reports a FAIL verdict with exit 1
    tags: tuple[str, ...] = field(default=())


# ------------------------------------------------------------------------------ TOML writer
def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def dump_toml(d: dict[str, Any]) -> str:
    """TOML text of ``d`` (tables, arrays of tables, inline values; enough for the examples)."""
    lines: list[str] = []

    def table(t: dict[str, Any], path: list[str]) -> None:
        subs, arrays = [], []
        for k, v in t.items():
            if isinstance(v, dict) and v and all(not isinstance(x, dict) or x for x in v.values()):
                subs.append((k, v))
            elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
                arrays.append((k, v))
            else:
                lines.append(f"{json.dumps(k)} = {_value(v)}")
        for k, v in subs:
            lines.append(f"\n[{'.'.join(json.dumps(p) for p in [*path, k])}]")
            table(v, [*path, k])
        for k, items in arrays:
            for item in items:
                lines.append(f"\n[[{'.'.join(json.dumps(p) for p in [*path, k])}]]")
                table(item, [*path, k])

    table(d, [])
    return "\n".join(lines) + "\n"


def load_example(name: str) -> dict[str, Any]:
    with (EXAMPLES / name).open("rb") as fh:
        return tomllib.load(fh)


# ------------------------------------------------------------------------------ mutations
def _paths(d: Any, prefix: tuple = ()) -> list[tuple]:
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            out.append((*prefix, k))
            out += _paths(v, (*prefix, k))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            out.append((*prefix, i))
            out += _paths(v, (*prefix, i))
    return out


def _get(d: Any, path: tuple) -> Any:
    for p in path:
        d = d[p]
    return d


def mutate_tree(rng: random.Random, d: dict[str, Any], n_ops: int = 1) -> dict[str, Any]:
    """``d`` with ``n_ops`` random changes: delete, replace, scale, retype, add, list edits."""
    d = copy.deepcopy(d)
    for _ in range(n_ops):
        paths = _paths(d)
        if not paths:
            d["unknown_key"] = 1
            continue
        path = rng.choice(paths)
        parent, key = _get(d, path[:-1]), path[-1]
        value = parent[key]
        op = rng.choice(("delete", "replace", "replace", "scale", "retype", "add", "list"))
        if op == "delete":
            del parent[key]
        elif op == "replace":
            parent[key] = copy.deepcopy(rng.choice(VALUES))
        elif op == "scale" and isinstance(value, int | float) and not isinstance(value, bool):
            parent[key] = value * rng.choice((-1, 0, 1e-6, 1e-3, 10, 1e3, 1e6, 1e12))
        elif op == "retype":
            parent[key] = str(value) if not isinstance(value, dict | list) else 1.5
        elif op == "add" and isinstance(value, dict):
            value[rng.choice(("typo_key", "mass", "depth", "panel", "count"))] = rng.choice(
                VALUES[:12])
        elif op == "list" and isinstance(value, list) and value:
            kind = rng.choice(("drop", "dup", "empty"))
            if kind == "drop":
                value.pop(rng.randrange(len(value)))
            elif kind == "dup":
                value.append(copy.deepcopy(value[rng.randrange(len(value))]))
            else:
                value.clear()
        else:
            parent[key] = copy.deepcopy(rng.choice(VALUES))
    return d


def mutate_text(rng: random.Random, data: bytes) -> bytes:
    """Byte-level damage: truncation, a BOM, junk or duplicated lines, invalid UTF-8."""
    lines = data.split(b"\n")
    op = rng.choice(("truncate", "bom", "junk", "delete", "dup", "utf8", "swap", "empty"))
    if op == "truncate":
        return data[: rng.randrange(len(data) + 1)]
    if op == "bom":
        return b"\xef\xbb\xbf" + data
    if op == "junk":
        lines.insert(rng.randrange(len(lines) + 1),
                     rng.choice((b"= = =", b"[[[", b"x = ", b"\x00\x01", b"nan,nan", b"#", b"1e")))
    elif op == "delete" and len(lines) > 1:
        lines.pop(rng.randrange(len(lines)))
    elif op == "dup":
        i = rng.randrange(len(lines))
        lines.insert(i, lines[i])
    elif op == "utf8":
        return data[: len(data) // 2] + b"\xff\xfe\xc3" + data[len(data) // 2:]
    elif op == "swap" and len(lines) > 3:
        i = rng.randrange(1, len(lines) - 1)
        lines[i], lines[i + 1] = lines[i + 1], lines[i]
    elif op == "empty":
        return b""
    return b"\n".join(lines)


# ------------------------------------------------------------------------------ records
def record_csv(n: int = 401, dt: float = 0.01, amp: float = 3.0, seed: int = 0) -> bytes:
    """A short accelerogram [m/s²] with the seisrack header (time_s,accel_m_s2)."""
    rng = random.Random(seed)
    rows = ["time_s,accel_m_s2"]
    for i in range(n):
        t = i * dt
        a = amp * math.sin(2 * math.pi * 1.5 * t) * math.exp(-0.3 * t) + 0.2 * rng.uniform(-1, 1)
        rows.append(f"{t:.4f},{a:.6f}")
    return ("\n".join(rows) + "\n").encode()


def mutate_record(rng: random.Random, data: bytes) -> bytes:
    """Value-level damage to a CSV record, or byte-level damage (:func:`mutate_text`)."""
    lines = data.decode().splitlines()
    op = rng.choice(("value", "value", "time", "columns", "few", "header", "delim", "scale",
                     "zero", "bytes"))
    if op == "value":
        i = rng.randrange(1, len(lines))
        t = lines[i].split(",")[0]
        lines[i] = f"{t},{rng.choice(('nan', 'inf', '-inf', '1e300', 'abc', '', '1e-320'))}"
    elif op == "time":
        i = rng.randrange(2, len(lines))
        a = lines[i].split(",")[1]
        lines[i] = f"{rng.choice(('0', '-1', '1e9', '0.0200001', 'x'))},{a}"
    elif op == "columns":
        lines = [ln + ",1" if rng.random() < 0.5 else ln.split(",")[-1] for ln in lines]
    elif op == "few":
        lines = lines[: rng.randrange(0, 4)]
    elif op == "header":
        lines = lines[1:] if rng.random() < 0.5 else ["a;b;c", *lines[1:]]
    elif op == "delim":
        sep = rng.choice((";", "\t", " ", ", "))
        lines = [ln.replace(",", sep) for ln in lines]
    elif op == "scale":
        k = rng.choice((1e6, 1e-9, -1.0, 1e300))
        lines = [lines[0]] + [f"{ln.split(',')[0]},{float(ln.split(',')[1]) * k!r}"
                              for ln in lines[1:]]
    elif op == "zero":
        lines = [lines[0]] + [f"{ln.split(',')[0]},0.0" for ln in lines[1:]]
    else:
        return mutate_text(rng, data)
    return ("\n".join(lines) + "\n").encode()


# ------------------------------------------------------------------------------ studies
STUDY = {"title": "fuzz", "racks": ["rack.toml"], "seed": 3, "dt": 0.01,
         "records": {"folder": "records"},
         "intensity": {"measure": "pga", "stripes": [1.0, 2.0]},
         "friction": {"values": [0.3]}}


def study_files(rng: random.Random | None = None) -> list[tuple[str, bytes]]:
    """A 4-run study of the paper rack (2 records of 2 s x 2 stripes), mutated when ``rng``."""
    rack = (EXAMPLES / "paper_rack.toml").read_bytes()
    study = STUDY
    records = [record_csv(201, seed=1), record_csv(201, seed=2, amp=2.0)]
    if rng is not None:
        what = rng.choice(("study", "study", "study", "text", "rack", "record"))
        if what == "study":
            study = mutate_tree(rng, STUDY, rng.randint(1, 2))
        elif what == "text":
            return [("study.toml", mutate_text(rng, dump_toml(STUDY).encode())),
                    ("rack.toml", rack), ("records/a.csv", records[0]),
                    ("records/b.csv", records[1])]
        elif what == "rack":
            rack = dump_toml(mutate_tree(rng, load_example("paper_rack.toml"))).encode()
        else:
            records[0] = mutate_record(rng, records[0])
    return [("study.toml", dump_toml(study).encode()), ("rack.toml", rack),
            ("records/a.csv", records[0]), ("records/b.csv", records[1])]


# ------------------------------------------------------------------------------ the cases
RACKS_2D = ("paper_rack.toml", "three_level_rack.toml", "paper_rack_nonlinear.toml")
RACKS = (*RACKS_2D, "paper_rack_3d.toml")


def _rack(rng: random.Random, names: tuple[str, ...] = RACKS, *, p_text: float = 0.15
          ) -> bytes:
    name = rng.choice(names)
    if rng.random() < p_text:
        return mutate_text(rng, (EXAMPLES / name).read_bytes())
    return dump_toml(mutate_tree(rng, load_example(name), rng.randint(1, 3))).encode()


def _opt(rng: random.Random, good: str) -> str:
    return rng.choice(OPTION_VALUES) if rng.random() < 0.5 else good


def _json(rng: random.Random) -> tuple[str, ...]:
    return ("--json",) if rng.random() < 0.5 else ()


def all_cases(seed: int = SEED) -> list[Case]:
    rng = random.Random(seed)
    cases: list[Case] = []

    def add(name: str, argv: list[str], files: list[tuple[str, bytes]] = (), **kw: Any) -> None:
        cases.append(Case(f"{name}-{len([c for c in cases if c.name.startswith(name)])}",
                          tuple(argv), tuple(files), **kw))

    rec = record_csv()
    # modal: mutated racks (2D and 3D) and option values
    for i in range(40):
        argv = ["modal", "@/rack.toml", "--modes", _opt(rng, "4"), *_json(rng)]
        if rng.random() < 0.2:
            argv += ["--plot", rng.choice(("@/out/m.png", "@/out/m.xyz", "@/rack.toml"))]
        add("modal", argv, [("rack.toml", _rack(rng))], slow=i >= 12)
    # run: a mutated rack, record or option
    run_opts = (("--mu", "0.3"), ("--mu-dynamic", "0.2"), ("--dt", "0.005"),
                ("--save-every", "2"), ("--free-vibration", "1"), ("--scale-pga", "3"),
                ("--scale", "1.5"), ("--accel-filter", "20"), ("--units", "m/s2"),
                ("--motion-dt", "0.01"), ("--angle", "0"), ("--basis", "full"),
                ("--method", "newmark"))
    for i in range(60):
        what = rng.choice(("rack", "record", "option", "option"))
        rack = _rack(rng) if what == "rack" else (EXAMPLES / rng.choice(RACKS)).read_bytes()
        data = mutate_record(rng, rec) if what == "record" else rec
        argv = ["run", "@/rack.toml", "--motion", "@/rec.csv", *_json(rng)]
        for opt, good in rng.sample(run_opts, rng.randint(0, 2)):
            argv += [opt, _opt(rng, good) if what == "option" else good]
        if rng.random() < 0.25:
            argv += ["--out", "@/out/run"] + (["--no-plot"] if rng.random() < 0.5 else [])
        if rng.random() < 0.1:
            argv += ["--scale-sa", _opt(rng, "T1"), _opt(rng, "2.0")]
        add("run", argv, [("rack.toml", rack), ("rec.csv", data)], slow=i >= 15)
    # report (HTML): fewer, each is a run + figures
    for _ in range(6):
        what = rng.choice(("rack", "record", "option"))
        rack = _rack(rng, RACKS_2D) if what == "rack" else (EXAMPLES / "paper_rack.toml"
                                                            ).read_bytes()
        data = mutate_record(rng, rec) if what == "record" else rec
        argv = ["report", "@/rack.toml", "--motion", "@/rec.csv", "--modes",
                _opt(rng, "2") if what == "option" else "2", "--out",
                "@/out/rep/report.html", *_json(rng)]
        if what == "option":
            argv += rng.choice((["--ec8", "1", "C", _opt(rng, "0.3")],
                                ["--mu", _opt(rng, "0.3")], ["--scale", _opt(rng, "2")]))
        add("report", argv, [("rack.toml", rack), ("rec.csv", data)], limit_s=150.0)
    # study: a mutated study (file, rack or record) or option
    for i in range(24):
        files = study_files(rng)
        argv = ["study", "@/study.toml", "--out", "@/out/st", "--workers", "1",
                "--no-progress", *_json(rng)]
        r = rng.random()
        if r < 0.2:
            argv.append("--dry-run")
        elif r < 0.35:
            argv += ["--batch-size", _opt(rng, "2")]
        elif r < 0.45:
            argv[argv.index("--workers") + 1] = _opt(rng, "1")
        add("study", argv, files, limit_s=150.0, slow=i >= 4)
    # study summary: a prebuilt store, damaged or not, and options
    for i in range(14):
        argv = ["study", "summary", "@/store", "--boot", "10", *_json(rng)]
        opts = (("--d-slide", "0.01"), ("--shear-capacity", "5000"), ("--boot", "5"),
                ("--seed", "1"))
        for opt, good in rng.sample(opts, rng.randint(0, 2)):
            argv += [opt, _opt(rng, good)]
        argv += ["--no-plots"] if rng.random() < 0.6 else []
        if rng.random() < 0.2:
            argv += ["--report", rng.choice(("@/out/r.html", "@/store", "@/rack.toml/x.html"))]
        damage = rng.choice(("none", "none", "part", "study_json", "empty"))
        add("summary", argv, [("rack.toml", b"x"), ("damage", damage.encode())], store=True,
            slow=i >= 3)
    # export
    for i in range(14):
        argv = ["export", "opensees", "@/rack.toml", *_json(rng)]
        for opt, good in rng.sample((("--mu", "0.3"), ("--k-init", "1e8"),
                                     ("--pallets", "rigid")), rng.randint(0, 2)):
            argv += [opt, _opt(rng, good)]
        if rng.random() < 0.5:
            argv += ["--out", rng.choice(("@/out/ops.py", "@/out", "@/rack.toml"))]
        add("export", argv, [("rack.toml", _rack(rng))], slow=i >= 5)
    # motion generate / spectrum / check
    for i in range(10):
        argv = ["motion", "generate", "--ag", _opt(rng, "0.3"), "--seed", _opt(rng, "1"),
                "--duration", _opt(rng, "5"), "--dt", _opt(rng, "0.01"),
                "--count", rng.choice(("1", "2", "0", "-1", "100000000")),
                "--out", rng.choice(("@/out/g.csv", "@/out/suite", "@/rec.csv")), *_json(rng)]
        if rng.random() < 0.3:
            argv += ["--damping", _opt(rng, "0.05"), "--importance", _opt(rng, "1.0")]
        add("generate", argv, [("rec.csv", rec)], slow=i >= 3)
    for i in range(18):
        argv = ["motion", "spectrum", "@/rec.csv", *_json(rng)]
        if rng.random() < 0.5:
            argv += ["--periods", rng.choice(("0.1,0.5,1", "0,1", "-1", "nan,1", "1e9",
                                              ",".join(["0.5"] * 20000)))]
        if rng.random() < 0.3:
            argv += ["--damping", _opt(rng, "0.05")]
        if rng.random() < 0.3:
            argv += ["--units", rng.choice(("g", "m/s2", "ft", ""))]
        if rng.random() < 0.2:
            argv += ["--plot", "@/out/s.png"]
        add("spectrum", argv, [("rec.csv", mutate_record(rng, rec) if rng.random() < 0.7
                                else rec)], slow=i >= 6)
    for i in range(14):
        argv = ["motion", "check", "@/recs", "--type", rng.choice(("1", "2", "3")),
                "--ground", rng.choice(("C", "A", "Z")), "--ag", _opt(rng, "0.3"), *_json(rng)]
        argv += (["--period", _opt(rng, "0.6")] if rng.random() < 0.7 else
                 ["--rack", "@/rack.toml"])
        files = [("recs/a.csv", record_csv(1501, seed=4)), ("recs/b.csv", record_csv(1501,
                                                                                    seed=5)),
                 ("recs/c.csv", mutate_record(rng, record_csv(1501, seed=6))),
                 ("rack.toml", _rack(rng, RACKS_2D))]
        add("check", argv, files, exit_1_ok=True, slow=i >= 4)
    # sdof
    for i in range(16):
        argv = ["sdof", "--alpha", _opt(rng, "1.0"), "--mu", _opt(rng, "0.6"), "--frequency",
                _opt(rng, "1"), "--duration", _opt(rng, "5"), *_json(rng)]
        if rng.random() < 0.3:
            argv += ["--mu-dynamic", _opt(rng, "0.5"), "--g", _opt(rng, "9.81")]
        if rng.random() < 0.15:
            argv = ["sdof", "--threshold", *_json(rng)]
        if rng.random() < 0.2:
            argv += ["--plot", "@/out/sdof.png"]
        add("sdof", argv, exit_1_ok=True, slow=i >= 6)
    # validate: each valid case runs both examples (a few seconds at dt = 0.01)
    for i in range(5):
        argv = ["validate", "--dt", rng.choice(("0.01", "0", "nan", "1e-9", "100", "abc")),
                *_json(rng)]
        if rng.random() < 0.3:
            argv.append("--reference-only")
        add("validate", argv, exit_1_ok=True, limit_s=150.0, slow=i >= 2)
    # paper: mostly refused early (a bad rack, option or output folder); one full quick run
    for i in range(4):
        argv = ["paper", "--out", rng.choice(("@/out/p", "@/rack.toml")), "--quick",
                "--jobs", rng.choice(("1", "3")), *_json(rng)]
        if i > 0:
            argv += ["--rack", "@/rack.toml"]
        add("paper", argv, [("rack.toml", _rack(rng, ("paper_rack.toml",)))],
            exit_1_ok=True, limit_s=240.0)
    cases += issue_cases()
    # usage errors and unknown options on every command
    for cmd in (["modal"], ["run", "@/rack.toml"], ["report"], ["study"], ["export"],
                ["export", "opensees"], ["motion"], ["motion", "generate"], ["sdof"],
                ["validate", "--nope"], ["paper", "--jobs", "x"], ["study", "summary"]):
        add("usage", [*cmd, *_json(rng)], [("rack.toml", b"")], slow=False)
    cases += _cases_3d(random.Random(seed + 1), rec)
    return cases


# ------------------------------------------------------------------- 3D racks, design, warehouse
STUDY_3D = {"title": "fuzz 3D", "racks": ["rack3d.toml"], "seed": 3, "dt": 0.01,
            "records": {"ec8": [{"type": 1, "ground": "C", "ag": 0.3, "duration": 2.0,
                                 "count": 1, "seed": 1, "components": 2}]},
            "intensity": {"measure": "pga", "unit": "g", "stripes": [0.3]},
            "angle": {"values": [0.0, 90.0]},
            "friction": {"values": [0.3]}}
SITE = {"title": "fuzz site",
        "rows": [{"name": "A", "rack": "rack3d.toml", "count": 2, "orientation": 0.0,
                  "origin": [0.0, 0.0], "spacing": [0.0, 4.0]},
                 {"name": "B", "rack": "rack.toml", "count": 1, "orientation": 90.0,
                  "origin": [20.0, 0.0], "spacing": [-4.0, 0.0], "depth": 1.0}]}
STUDY_SITE = {**{k: v for k, v in STUDY_3D.items() if k not in ("racks", "angle")},
              "title": "fuzz warehouse", "warehouse": "site.toml"}


def _cases_3d(rng: random.Random, rec: bytes) -> list[Case]:
    """3D runs and reports (a cross-aisle record, an angle), the design analysis on 2D and 3D
    racks, 3D and warehouse studies: appended with their own random stream, so that the cases
    above keep theirs."""
    cases: list[Case] = []

    def add(name: str, argv: list[str], files=(), **kw: Any) -> None:
        n = len([c for c in cases if c.name.startswith(name + "-")])
        cases.append(Case(f"{name}-{n}", tuple(argv), tuple(files), **kw))

    rack3d = (EXAMPLES / "paper_rack_3d.toml").read_bytes()
    cross = record_csv(seed=7, amp=2.0)
    for i in range(10):  # 3D run: the rack, either record or the angle mutated
        what = rng.choice(("rack", "record", "cross", "angle"))
        files = [("rack.toml", _rack(rng, ("paper_rack_3d.toml",)) if what == "rack"
                  else rack3d), ("rec.csv", mutate_record(rng, rec) if what == "record"
                                 else rec),
                 ("cross.csv", mutate_record(rng, cross) if what == "cross" else cross)]
        argv = ["run", "@/rack.toml", "--motion", "@/rec.csv", "--motion-cross",
                "@/cross.csv", *_json(rng)]
        if what == "angle" or rng.random() < 0.3:
            argv += ["--angle", rng.choice(OPTION_VALUES) if what == "angle" else "30"]
        if rng.random() < 0.3:
            argv += ["--out", "@/out/run3d"]
        add("run3d", argv, files, slow=i >= 3)
    for i in range(3):  # 3D report
        what = rng.choice(("rack", "record", "option"))
        files = [("rack.toml", _rack(rng, ("paper_rack_3d.toml",)) if what == "rack"
                  else rack3d), ("rec.csv", mutate_record(rng, rec) if what == "record"
                                 else rec), ("cross.csv", cross)]
        argv = ["report", "@/rack.toml", "--motion", "@/rec.csv", "--motion-cross",
                "@/cross.csv", "--modes", "2", "--out", "@/out/rep3d/report.html",
                *_json(rng)]
        if what == "option":
            argv += rng.choice((["--ec8", "1", "C", _opt(rng, "0.3")],
                                ["--angle", _opt(rng, "45")], ["--mu", _opt(rng, "0.3")]))
        add("report3d", argv, files, limit_s=150.0, slow=i >= 1)
    for i in range(12):  # design analysis: 2D and 3D racks, mutated racks and options
        q = ["2", "1.5"] if rng.random() < 0.5 else ["2"]
        argv = ["design", "@/rack.toml", "--ec8", rng.choice(("1", "1", "2", "3")),
                rng.choice(("C", "C", "A", "Z")), _opt(rng, "0.3"), "--q",
                *[_opt(rng, v) for v in q], *_json(rng)]
        for opt, good in rng.sample((("--importance", "1.2"), ("--damping", "model"),
                                     ("--combination", "cqc"), ("--directions-rule", "0.30"),
                                     ("--modes", "6"), ("--factors", "e_d1=1.0"),
                                     ("--direction", "cross-aisle")), rng.randint(0, 2)):
            argv += [opt, _opt(rng, good)]
        if rng.random() < 0.15:
            argv.append("--elastic")
        add("design", argv, [("rack.toml", _rack(rng))], exit_1_ok=True, slow=i >= 4)
    paper = (EXAMPLES / "paper_rack.toml").read_bytes()
    for i in range(4):  # 3D study: record pairs and angles
        what = rng.choice(("study", "study", "rack"))
        study = mutate_tree(rng, STUDY_3D, rng.randint(1, 2)) if what == "study" else STUDY_3D
        rk = _rack(rng, ("paper_rack_3d.toml",)) if what == "rack" else rack3d
        add("study3d", ["study", "@/study.toml", "--out", "@/out/st3d", "--workers", "1",
                        "--no-progress", *_json(rng)],
            [("study.toml", dump_toml(study).encode()), ("rack3d.toml", rk)],
            limit_s=150.0, slow=i >= 1)
    for i in range(4):  # warehouse study: the study, the site or a rack mutated
        what = rng.choice(("study", "site", "site", "rack"))
        study = mutate_tree(rng, STUDY_SITE, 1) if what == "study" else STUDY_SITE
        site = mutate_tree(rng, SITE, rng.randint(1, 2)) if what == "site" else SITE
        rk = _rack(rng, ("paper_rack_3d.toml",)) if what == "rack" else rack3d
        argv = ["study", "@/study.toml", "--out", "@/out/wh", "--workers", "1",
                "--no-progress", *_json(rng)]
        if rng.random() < 0.5:
            argv.append("--dry-run")
        add("warehouse", argv, [("study.toml", dump_toml(study).encode()),
                                ("site.toml", dump_toml(site).encode()),
                                ("rack3d.toml", rk), ("rack.toml", paper)],
            limit_s=150.0, slow=i >= 1)
    return cases


def _with(name: str, **changes: Any) -> bytes:
    """An example rack with top-level tables updated (``geometry={...}`` merges)."""
    d = load_example(name)
    for key, value in changes.items():
        if isinstance(value, dict) and isinstance(d.get(key), dict):
            d[key].update(value)
        else:
            d[key] = value
    return dump_toml(d).encode()


def issue_cases() -> list[Case]:
    """The inputs of issue 23 that crashed, ran away or misled, each once (fast)."""
    rec = record_csv()
    paper = (EXAMPLES / "paper_rack.toml").read_bytes()
    heavy = paper.replace(b"mass = 400.0", b"mass = 1e9")
    big_study = dump_toml({**STUDY, "records": {"builtin": "elcentro_1940_ns"},
                           "intensity": {"ida": {"start": 0.1, "step": 0.1, "stop": 100.0}},
                           "friction": {"dist": "lognormal", "median": 0.4,
                                        "dispersion": 0.2, "samples": 2000}}).encode()
    study_3d = dump_toml({**STUDY, "racks": ["rack3d.toml"]}).encode()
    out = [
        ("modal", ["modal", "@/rack.toml"],
         [("rack.toml", _with("warehouse_rack.toml",
                              geometry={"bays": {"count": 100_000_000, "pitch": 2.7}}))]),
        ("modal", ["modal", "@/rack.toml", "--json"],
         [("rack.toml", _with("warehouse_rack.toml", geometry={"subdivisions": 100_000}))]),
        ("modal", ["modal", "@/rack.toml"],
         [("rack.toml", _with("warehouse_rack.toml", geometry={
             "bays": {"count": 2000, "pitch": 2.7}, "levels": {"count": 50, "pitch": 1.5}}))]),
        ("modal", ["modal", "@/rack.toml", "--json"],
         [("rack.toml", _with("paper_rack_3d.toml", bracing={
             "pattern": "Z", "panel": 0.0001, "horizontal_section": "brace",
             "diagonal_section": "brace"}))]),
        ("modal", ["modal", "@/rack.toml"], [("rack.toml", b"\xef\xbb\xbf" + paper)]),
        ("run", ["run", "@/rack.toml", "--builtin", "elcentro_1940_ns", "--free-vibration",
                 "1e7"], [("rack.toml", paper)]),
        ("run", ["run", "@/rack.toml", "--motion", "@/rec.csv", "--json"],
         [("rack.toml", heavy), ("rec.csv", rec)]),
        ("run", ["run", "@/rack.toml", "--motion", "@/rec.csv"],
         [("rack.toml", paper), ("rec.csv", b"\xef\xbb\xbf" + rec)]),
        ("report", ["report", "@/rack.toml", "--motion", "@/rec.csv", "--modes", "2",
                    "--out", "@/out/fresh/rep/report.html"],
         [("rack.toml", paper), ("rec.csv", rec)]),
        ("study", ["study", "@/study.toml", "--out", "@/out/st", "--json"],
         [("study.toml", big_study), ("rack.toml", paper)]),
        ("study", ["study", "@/study.toml", "--out", "@/out/st", "--no-progress"],
         [("study.toml", study_3d), ("rack3d.toml",
                                     (EXAMPLES / "paper_rack_3d.toml").read_bytes()),
          ("records/a.csv", record_csv(201))]),
        ("summary", ["study", "summary", "@/nowhere", "--json"], []),
        ("export", ["export", "opensees", "@/rack.toml", "--json"], [("rack.toml", paper)]),
        ("spectrum", ["motion", "spectrum", "@/rec.csv", "--json"],
         [("rec.csv", b"\xef\xbb\xbf" + rec)]),
    ]
    return [Case(f"issue-{name}-{i}", tuple(argv), tuple(files), slow=False)
            for i, (name, argv, files) in enumerate(out)]
