"""The one-pass design peaks (:mod:`seisrack.analysis.design_pass`) against a brute-force
reference written here from their definition: every design quantity at every step ``q @ D``,
its max and min over time, and per upright section the (N, M) pair of gravity + seismic at the
first step of the largest |N| and of the largest |M| (``np.argmax``'s first-maximum rule). The
numba loop and the numpy twin must both match it, chunk by chunk as the tracker feeds them."""

from __future__ import annotations

import numpy as np
import pytest

from seisrack.analysis.design_pass import HAVE_NUMBA, design_pass

BACKENDS = ["numpy"] + (["numba"] if HAVE_NUMBA else [])


def _reference(q, dop, ia, im, sn, sm):  # noqa: ANN001, ANN202
    x = q @ dop  # (n_t, Σk)
    ns = sn.size
    n = x[:, ia:ia + ns] + sn
    m = x[:, im:im + ns] + sm
    cols = np.arange(ns)
    kn = np.argmax(np.abs(n), axis=0)
    km = np.argmax(np.abs(m), axis=0)
    at_n = np.array([n[kn, cols], m[kn, cols]])
    at_m = np.array([n[km, cols], m[km, cols]])
    return x.max(axis=0), x.min(axis=0), at_n, at_m


def _run(q, dop, ia, im, sn, sm, backend, chunks):  # noqa: ANN001, ANN202
    nk, ns = dop.shape[1], sn.size
    dmax, dmin = np.full(nk, -np.inf), np.full(nk, np.inf)
    at_n, at_m = np.zeros((2, ns)), np.zeros((2, ns))
    edges = np.linspace(0, q.shape[0] - 1, chunks + 1).astype(int)
    for a, b in zip(edges[:-1], edges[1:], strict=True):  # chunks share their boundary sample
        design_pass(q[a:b + 1], dop, dmax, dmin, ia, im, sn, sm, at_n, at_m, backend=backend)
    return dmax, dmin, at_n, at_m


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("chunks", [1, 3])
def test_design_pass_matches_brute_force(backend: str, chunks: int) -> None:
    rng = np.random.default_rng(7)
    r, nk, ns, n_t = 8, 29, 6, 997
    q = rng.standard_normal((n_t, r))
    dop = rng.standard_normal((r, nk))
    ia, im = 17, 23
    sn, sm = rng.standard_normal(ns) * 5.0, rng.standard_normal(ns)
    got = _run(q, dop, ia, im, sn, sm, backend, chunks)
    for g, want in zip(got, _reference(q, dop, ia, im, sn, sm), strict=True):
        np.testing.assert_allclose(g, want, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("backend", BACKENDS)
def test_design_pass_ties_take_the_first_step(backend: str) -> None:
    """Equal |N| at two steps (of opposite signs, with a different M): the first step's pair."""
    dop = np.eye(2)  # x = q: column 0 the axial force, column 1 the section moment
    q = np.array([[0.5, 9.0], [-2.0, 1.0], [1.0, 3.0], [2.0, -4.0], [0.0, 9.0]])
    dmax, dmin, at_n, at_m = _run(q, dop, 0, 1, np.zeros(1), np.zeros(1), backend, 1)
    assert at_n[:, 0].tolist() == [-2.0, 1.0]  # |N| = 2 at steps 1 and 3: step 1
    assert at_m[:, 0].tolist() == [0.5, 9.0]  # |M| = 9 at steps 0 and 4: step 0
    assert dmax.tolist() == [2.0, 9.0] and dmin.tolist() == [-2.0, -4.0]


@pytest.mark.parametrize("backend", BACKENDS)
def test_design_pass_gravity_state_decides_the_step(backend: str) -> None:
    """The largest |N| is that of gravity + seismic: a compressive gravity force picks the
    step of the most negative seismic N, not the largest |seismic N|."""
    dop = np.eye(2)
    q = np.array([[3.0, 1.0], [-2.0, 2.0]])
    _, _, at_n, _ = _run(q, dop, 0, 1, np.array([-10.0]), np.array([100.0]), backend, 1)
    assert at_n[:, 0].tolist() == [-12.0, 102.0]
