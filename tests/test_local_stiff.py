"""The local engine on a very stiff rack of normal steel density (issue 22's first validation
item): no period-2h ringing of the stiff directions reaches the pallets' contact decisions.

Reference: event-driven rigid blocks on a rigid platform with circular Coulomb friction
(``tests/test_engine_planar._block_reference``: slip onsets by root finding on
``|a_g| = mu_s g``, sliding phases by DOP853 at rtol 1e-11 with the stop as a terminal event),
independent of seisrack's engines; a rack this stiff moves its pallets' supports with the
ground. Rack: the two-bay one-level rack of ``tests/test_rack3d_run`` with members and joints
1e5 times stiffer at normal steel density (first period about 1.5 ms), four pallets with
mu_d < mu_s; El Centro 1940 N-S down-aisle and the same record 10 s later cross-aisle, 10 s,
at the default analysis step (5 ms). Acceptance (issue 22): peak sliding within 1 %, final
positions within 1 mm, the number of slip phases within 10 % (or one phase). Measured: peaks
-0.40 %, +0.10 %, +0.04 %, -0.41 %; final positions 0.007 to 0.018 mm apart; slip phases 1, 3,
10, 1 against the blocks' 1, 3, 10, 1.
"""

from __future__ import annotations

import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from seisrack.analysis import run_rack
from seisrack.model import compile_rack, rack_from_dict
from seisrack.motion import load_builtin_record
from seisrack.motion.components import combine

sys.path.insert(0, str(Path(__file__).parent))
from test_engine_planar import _block_reference  # noqa: E402
from test_rack3d_run import _one_level  # noqa: E402

MU = [(0.30, 0.25), (0.25, 0.20), (0.20, 0.15), (0.30, 0.22)]


def _phases(u: np.ndarray) -> int:
    """Slip phases of a sampled sliding history: starts of motion after a rest."""
    moving = np.hypot(*np.diff(u, axis=0).T) > 1e-12
    return int(np.sum(moving[1:] & ~moving[:-1]) + moving[0])


def test_stiff_rack_matches_rigid_blocks_at_the_default_step():
    d = _one_level(0.3, 50e-6)
    scale = 1e5
    d["material"]["E"] *= scale
    d["connections"] = {k: v * scale for k, v in d["connections"].items()}
    d["pallets"] = [{**p, "mu_static": s, "mu_dynamic": k}
                    for p, (s, k) in zip(d["pallets"], MU, strict=True)]
    model = compile_rack(rack_from_dict(d))
    rec = load_builtin_record("elcentro_1940_ns")
    n = int(round(10.0 / rec.dt)) + 1
    x = replace(rec, accel=rec.accel[:n], name="x")
    z = replace(rec, accel=np.roll(rec.accel, -int(round(10.0 / rec.dt)))[:n], name="z")
    resp = run_rack(model, combine(x, z), engine="local")
    assert resp.dt == 0.005
    assert resp.history.energy_error() < 1e-6
    tr = np.arange(n) * rec.dt

    def ax(t):
        return np.interp(t, tr, x.accel)

    def az(t):
        return np.interp(t, tr, z.accel)

    t = resp.t
    fine = np.arange(0.0, 10.0 + 5e-4, 1e-3)
    for p, (mus, mud) in enumerate(MU):
        ref, _ = _block_reference(ax, az, mus, mud, model.g, 10.0)
        ur = ref(t)
        u = resp.pallet_sliding[:, p, :]
        peak_ref = np.hypot(ur[:, 0], ur[:, 1]).max()
        assert peak_ref > 1e-3
        peak = resp.pallet_peak_sliding()[p]
        assert abs(peak / peak_ref - 1) < 0.01, (p, peak, peak_ref)
        assert np.hypot(*(u[-1] - ur[-1])) < 1e-3, (p, u[-1], ur[-1])
        n_ref = _phases(ref(fine))
        n_eng = resp.history.sliding_phases(p)
        assert abs(n_eng - n_ref) <= max(1, 0.1 * n_ref), (p, n_eng, n_ref)
