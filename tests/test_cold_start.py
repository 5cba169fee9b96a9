"""Cold start: after ``make install`` (``python -m seisrack._warmup``) no CLI path compiles again.

numba caches each compiled specialisation on disk; a second process that meets argument types
the warm-up did not build (read-only arrays from a compiled model, a vertical record, Newmark,
the rigid companion, nonlinear connections) would compile for 30-70 s. This test runs those
paths in a fresh process and reads numba's own dispatcher statistics: every kernel call must be
a cache hit and none a cache miss (a miss is a compilation). Reference: numba's
``Dispatcher.stats`` (cache_hits, cache_misses) — https://numba.readthedocs.io, "Notes on
caching".
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

pytest.importorskip("numba")

SCRIPT = r"""
import json, dataclasses
import numpy as np
from seisrack._warmup import warmup
from seisrack.cli import main
from seisrack.analysis import run_rack
from seisrack.model import compile_rack, load_rack
from seisrack.model.spec import with_friction
from seisrack.motion.records import load_builtin_record
import seisrack.dynamics._kernel_numba as kn

rec = load_builtin_record("elcentro_1940_ns")
rec = dataclasses.replace(rec, accel=rec.accel[:300])
model = compile_rack(with_friction(load_rack("examples/paper_rack.toml"), 0.3))
run_rack(model, rec)
run_rack(model, rec, method="newmark", rigid_companion=True)
run_rack(model, rec, vertical=dataclasses.replace(rec, accel=0.3 * rec.accel),
         save_every=None)
big = compile_rack(with_friction(load_rack("examples/three_level_rack.toml"), 0.2))
run_rack(big, rec)
nonlinear = compile_rack(with_friction(load_rack("examples/paper_rack_nonlinear.toml"), 0.3))
run_rack(nonlinear, rec)
main(["run", "examples/paper_rack_nonlinear.toml", "--builtin", "elcentro_1940_ns", "--json"])
main(["run", "examples/paper_rack.toml", "--builtin", "elcentro_1940_ns", "--mu", "0.3",
      "--json"])
out = {}
for name in ("run_kernel", "run_kernel_exact"):
    st = getattr(kn, name).stats
    out[name] = {"hits": sum(st.cache_hits.values()), "misses": sum(st.cache_misses.values())}
print("STATS" + json.dumps(out))
"""


@pytest.mark.slow
def test_second_process_does_not_compile(tmp_path):
    # make sure the cache exists (make install does this; a no-op when it is warm)
    subprocess.run([sys.executable, "-m", "seisrack._warmup"], check=True, capture_output=True)
    res = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True,
                         check=True, cwd=str(_repo()))
    line = next(ln for ln in res.stdout.splitlines() if ln.startswith("STATS"))
    stats = json.loads(line[5:])
    for name, st in stats.items():
        assert st["misses"] == 0, f"{name} compiled in a second process: {st}"
        assert st["hits"] >= 1, f"{name} was not loaded from the cache: {st}"


def _repo():  # noqa: ANN202
    from pathlib import Path

    return Path(__file__).resolve().parents[1]
