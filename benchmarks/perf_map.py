"""Where a rack run spends its time, by function (docs/theory/local_engine.md §4.8).

Runs one case of ``rack_row.py`` (engine ``local`` or ``planar``) in this process, then writes
``/tmp/perf-<pid>.map``: the load address and size of every numba-compiled function of
seisrack's loaded modules, read from each
compiled library's object code (``nm``) and the address of its entry point. ``perf report``
then names the numba functions (without the map they show as ``[JIT]`` addresses). The object
code exists only for a fresh compile, so give numba an empty cache folder::

    NUMBA_CACHE_DIR=$(mktemp -d) perf record -F 500 -o perf.data \\
        python benchmarks/perf_map.py local <row.toml> 20
    perf report -i perf.data --sort dso,sym --stdio

The compile is in the profile too (``libllvmlite``, ``libpython``); the run's own CPU time is
printed. Needs Linux ``perf`` and binutils' ``nm``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numba

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rack_row  # noqa: E402


def _symbols(obj: bytes) -> list[tuple[int, int, str]]:
    with tempfile.NamedTemporaryFile(suffix=".o") as fh:
        fh.write(obj)
        fh.flush()
        out = subprocess.run(["nm", "-S", "--defined-only", fh.name], capture_output=True,
                             text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[2] in "tT":
            rows.append((int(parts[0], 16), int(parts[1], 16), parts[3]))
    return rows


def _dispatchers():  # noqa: ANN202
    seen = set()
    for name, module in list(sys.modules.items()):
        if not name.startswith("seisrack") or module is None:
            continue
        for obj in vars(module).values():
            if isinstance(obj, numba.core.registry.CPUDispatcher) and id(obj) not in seen:
                seen.add(id(obj))
                yield obj


def write_map() -> int:
    """Write this process's perf map for the numba dispatchers of seisrack's loaded modules;
    returns the number of functions mapped (0 when numba loaded them from its cache)."""
    entries = set()
    for obj in _dispatchers():
        for cres in obj.overloads.values():
            lib = cres.library
            try:
                syms = _symbols(lib._get_compiled_object())  # noqa: SLF001
            except RuntimeError:  # loaded from the cache: no object code kept
                continue
            name = cres.fndesc.mangled_name
            entry = [off for off, _size, n in syms if n == name]
            if not entry:
                continue
            base = lib.get_pointer_to_function(name) - entry[0]
            entries.update((base + off, size, n) for off, size, n in syms)
    with open(f"/tmp/perf-{os.getpid()}.map", "w", encoding="utf-8") as fh:
        for addr, size, n in sorted(entries):
            fh.write(f"{addr:x} {size:x} {n}\n")
    return len(entries)


def main() -> None:
    if len(sys.argv) != 4 or sys.argv[1] not in ("local", "planar"):
        raise SystemExit("usage: perf_map.py local|planar <row.toml> <seconds>")
    res = rack_row.run_case(sys.argv[1], sys.argv[2], float(sys.argv[3]))
    n = write_map()
    print(json.dumps({"cpu": res["cpu"], "work": res["work"], "mapped": n,
                      "map": f"/tmp/perf-{os.getpid()}.map"}))
    if n == 0:
        print("nothing mapped: numba loaded the kernel from its cache (set NUMBA_CACHE_DIR "
              "to an empty folder)", file=sys.stderr)


if __name__ == "__main__":
    main()
