"""The compiled one-pass peaks of a chunk (:mod:`seisrack.analysis.chunk_pass`, used by
:class:`~seisrack.analysis.peaks.PeakTracker` when numba is installed) against the tracker's
numpy path, the independent reference written array by array from the definitions (level
displacement and absolute acceleration, central differences of the velocities for Newmark,
base shear K (u + a1 v), base and connection moments, level sums of friction, sliding), on 2D
and 3D shapes, fed in chunks that share their boundary sample as the engine does; and the
full-rate histories kept for the response against the same products over the whole run."""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.analysis import chunk_pass
from seisrack.analysis.operators import RackOperators
from seisrack.analysis.peaks import PeakTracker, connection_moment
from seisrack.dynamics._chunk import Chunk

pytestmark = pytest.mark.skipif(not chunk_pass.HAVE_NUMBA, reason="numba is not installed")

H = 0.005


def _ops(rng, r: int, nd: int, nl: int, nu: int) -> RackOperators:  # noqa: ANN001
    def m(k: int) -> np.ndarray:
        return rng.standard_normal((r, k))
    return RackOperators(level=tuple(m(nl) for _ in range(nd)), shear=m(nd),
                         base_moment=tuple(m(nu) for _ in range(nd)),
                         below=tuple(m(nu * nl) for _ in range(nd)),
                         above=tuple(m(nu * nl) for _ in range(nd)), a1=1e-3, n_upright=nu,
                         n_level=nl)


def _feed(tr: PeakTracker, q, qd, qdd, fr, sl, n_chunks: int) -> None:  # noqa: ANN001
    n_t = q.shape[0]
    edges = np.linspace(0, n_t - 1, n_chunks + 1).astype(int)
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        rows = slice(a, b + 1)
        tr(Chunk(np.arange(a, b + 1) * H, q[rows], qd[rows], qdd[rows], fr[rows],
                 np.zeros(fr[rows].shape[:2], dtype=bool), sliding=sl[rows]))


@pytest.mark.parametrize(("nd", "smooth", "n_chunks"),
                         [(1, False, 1), (1, True, 3), (2, True, 1), (2, False, 4)])
def test_compiled_pass_matches_numpy_path(nd: int, smooth: bool, n_chunks: int) -> None:
    rng = np.random.default_rng(3 + nd + 2 * smooth + n_chunks)
    r, nl, nu, m, n_t = 6, 3, 4, 5, 400
    ops = _ops(rng, r, nd, nl, nu)
    lv = np.array([0, 2, 2, 1, 0])
    ag = rng.standard_normal((n_t, nd))
    q, qd, qdd = (rng.standard_normal((n_t, r)) for _ in range(3))
    shape = (n_t, m, nd) if nd == 2 else (n_t, m)
    fr, sl = rng.standard_normal(shape), rng.standard_normal(shape)
    out = {}
    for backend in ("numpy", "numba"):
        tr = PeakTracker(ops, lv, ag, H, smooth=smooth, keep_accel=True, design=False,
                         keep_series=True, backend=backend)
        _feed(tr, q, qd, qdd, fr, sl, n_chunks)
        out[backend] = (tr.result(), tr.level_acceleration(), tr)
    want, got = out["numpy"][0], out["numba"][0]
    assert want.keys() == got.keys()
    for key in want:
        np.testing.assert_allclose(got[key], want[key], rtol=1e-13, atol=1e-12, err_msg=key)
    np.testing.assert_allclose(out["numba"][1], out["numpy"][1], rtol=1e-13, atol=1e-12)

    series = out["numba"][2].series()
    assert out["numpy"][2].series() is None  # only the compiled pass keeps them
    per_dir = lambda ops_d, x: np.stack([x @ o for o in ops_d], axis=-1)  # noqa: E731
    np.testing.assert_allclose(series["disp"], per_dir(ops.level, q), rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(series["acc_raw"], per_dir(ops.level, qdd) + ag[:, None, :],
                               rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(series["shear"], q @ ops.shear + ops.a1 * (qd @ ops.shear),
                               rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(series["base"], per_dir(ops.base_moment, q), rtol=1e-13,
                               atol=1e-12)
    conn = np.stack([connection_moment((q @ ops.below[d]).reshape(n_t, nu, nl),
                                       (q @ ops.above[d]).reshape(n_t, nu, nl))
                     for d in range(nd)], axis=-1)
    np.testing.assert_allclose(series["conn"], conn, rtol=1e-13, atol=1e-12)
    assert series["acc"] is not None and series["acc"].shape == (n_t, nl, nd)


def test_nan_propagates_as_numpy() -> None:
    """A non-finite step makes the peaks NaN, as np.maximum does on the numpy path (whose
    upright moments, taken with Python's max, are left out: a non-finite run has failed)."""
    rng = np.random.default_rng(0)
    ops = _ops(rng, 4, 1, 1, 2)
    q = rng.standard_normal((50, 4))
    q[20, 1] = np.nan
    fr = rng.standard_normal((50, 2))
    res = {}
    for backend in ("numpy", "numba"):
        tr = PeakTracker(ops, np.array([0, 0]), np.zeros((50, 1)), H, smooth=False,
                         design=False, backend=backend)
        _feed(tr, q, q, q, fr, fr, 1)
        res[backend] = tr.result()
    for key in ("beam_displacement", "beam_acceleration", "base_shear"):
        assert np.isnan(res["numpy"][key]).all() == np.isnan(res["numba"][key]).all(), key
