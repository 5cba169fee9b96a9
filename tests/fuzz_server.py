"""Fork server of the command-line fuzz test (not a test module; run as a script).

Why a server: the cases run ``seisrack.cli.main`` in forked children (cheap: the modules and
the numba kernels are loaded once), but a process that has already run a parallel numba
kernel (the response spectra, on OpenMP threads) must not fork: the child is then terminated
by the OpenMP runtime as soon as it runs one. A pytest worker may have run any test before;
this server is a fresh process that loads what the cases need, runs nothing parallel itself,
and forks one child per case.

Protocol: one JSON request per line on stdin, ``{"argv": [...], "folder": ..., "limit_s":
...}``; one JSON reply per line on stdout, ``{"code", "out", "err", "seconds"}``, or
``{"timed_out": true}`` / ``{"crashed": status}``. The child runs in its own process group
(killed whole after the case, so pool workers cannot outlive it), with its address space
limited to :data:`EXTRA_ADDRESS_SPACE` beyond the server's.
"""

from __future__ import annotations

import io
import json
import os
import resource
import select
import signal
import sys
import time
import traceback
from pathlib import Path

#: address space of a case's process beyond the server's (a runaway is refused by the size
#: estimates long before; this only keeps a miss from taking the machine down)
EXTRA_ADDRESS_SPACE = 6 * 2**30


def warm() -> None:
    """Load what the cases use (numba kernels from their cache, matplotlib, pyarrow) once, so
    every forked case inherits it. Not the response spectra: their kernels start OpenMP
    threads, after which this process could not fork safely."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401
    import numpy as np
    import pyarrow.parquet  # noqa: F401

    import seisrack.cli  # noqa: F401
    from seisrack.analysis import run_rack
    from seisrack.model import compile_rack, load_rack
    from seisrack.motion import Record
    from seisrack.motion.components import combine

    root = Path(__file__).resolve().parents[1] / "examples"
    rec = Record(np.sin(np.arange(101) * 0.1) * 3.0, 0.01, name="warm")
    for name in ("paper_rack.toml", "paper_rack_nonlinear.toml", "three_level_rack.toml"):
        run_rack(compile_rack(load_rack(root / name)), rec)
    run_rack(compile_rack(load_rack(root / "paper_rack_3d.toml")), combine(rec, rec, None, 0.0))


def _vm_size() -> int:
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmSize:"):
                return int(line.split()[1]) * 1024
    return 0


def _child(argv: list[str], folder: str, w: int) -> None:  # pragma: no cover - in the fork
    code, out, err = 99, io.StringIO(), io.StringIO()
    try:
        os.setpgid(0, 0)
        os.chdir(folder)
        if sys.platform.startswith("linux"):
            limit = _vm_size() + EXTRA_ADDRESS_SPACE
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        sys.stdin = io.StringIO()
        sys.stdout, sys.stderr = out, err
        from seisrack.cli import main

        try:
            code = main(argv)
        except SystemExit as exc:  # argparse
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    except BaseException:  # noqa: BLE001 - reported as a crash of the command
        err.write(traceback.format_exc())
        code = 98
    try:
        data = json.dumps({"code": code, "out": out.getvalue(),
                           "err": err.getvalue()}).encode()
        while data:
            data = data[os.write(w, data):]
    finally:
        os._exit(0)


def run_case(argv: list[str], folder: str, limit_s: float) -> dict:
    r, w = os.pipe()
    sys.stdout.flush()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(r)
        _child(argv, folder, w)
    os.close(w)
    chunks, t0, timed_out = [], time.monotonic(), False
    while True:
        left = limit_s - (time.monotonic() - t0)
        if left <= 0:
            timed_out = True
            break
        ready, _, _ = select.select([r], [], [], min(left, 1.0))
        if ready:
            chunk = os.read(r, 1 << 16)
            if not chunk:
                break
            chunks.append(chunk)
    os.close(r)
    if timed_out:
        _kill_group(pid)
    _, status = os.waitpid(pid, 0)
    _kill_group(pid)  # the case's process group (pool workers): nothing may outlive it
    seconds = time.monotonic() - t0
    if timed_out:
        return {"timed_out": True, "seconds": seconds}
    raw = b"".join(chunks)
    if not raw:
        return {"crashed": status, "seconds": seconds}
    res = json.loads(raw)
    res["seconds"] = seconds
    return res


def _kill_group(pid: int) -> None:
    try:
        os.killpg(pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def main() -> None:
    warm()
    out = sys.stdout
    sys.stdout = sys.stderr  # anything printed by the cases' setup stays off the protocol
    print(json.dumps({"ready": True}), file=out, flush=True)
    for line in sys.stdin:
        req = json.loads(line)
        res = run_case(req["argv"], req["folder"], float(req["limit_s"]))
        print(json.dumps(res), file=out, flush=True)


if __name__ == "__main__":
    main()
