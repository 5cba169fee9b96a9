"""Validation of the engine's inputs (arrays dense or scipy sparse), at the boundary:
:func:`run_inputs` checks every argument of :func:`seisrack.dynamics.simulate` in one place."""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from seisrack.dynamics.hinges import Hinges, no_hinges
from seisrack.dynamics.sliders import PlanarSliders, Sliders
from seisrack.errors import InputError


def square(name: str, mat: object, n: int | None):  # noqa: ANN201
    """A finite square matrix, dense ``ndarray`` or CSR; ``n`` fixes its size."""
    if sp.issparse(mat):
        a = sp.csr_matrix(mat, dtype=float)
        data = a.data
    else:
        a = np.asarray(mat, dtype=float)
        if a.ndim == 0 and n == 1:
            a = a.reshape(1, 1)
        data = a
    if a.ndim != 2 or a.shape[0] != a.shape[1]:
        raise InputError(name, f"array of shape {a.shape}", "a square matrix")
    if n is not None and a.shape[0] != n:
        raise InputError(name, f"shape {a.shape}", f"shape ({n}, {n}) like M")
    if not np.all(np.isfinite(data)):
        raise InputError(name, "non-finite entries", "finite numbers")
    return a


def check_symmetric(name: str, a) -> None:  # noqa: ANN001
    if sp.issparse(a) and a.shape[0] <= 300:  # small: dense is exact and ~50x faster
        a = a.toarray()
    scale = max(float(abs(a).max()) if a.shape[0] else 0.0, 1e-300)
    if sp.issparse(a):
        asym = float(abs(a - a.T).max()) if a.nnz else 0.0
        ok = asym <= 1e-10 * scale
    else:
        ok = np.allclose(a, a.T, rtol=1e-10, atol=1e-12 * scale)
    if not ok:
        raise InputError(name, "non-symmetric matrix", "a symmetric matrix")


#: locked matrices already checked: id -> (weak reference to the matrix given, the checked
#: matrix, checked for symmetry too); an entry goes with its matrix
_CHECKED: dict[int, tuple[weakref.ref, object, bool]] = {}


def _locked(mat: object) -> bool:
    """A matrix locked read-only: an ndarray, or a sparse matrix whose data, indices and index
    pointers all are (a compiled model's, locked by
    :func:`seisrack.model.frame_model.read_only`); its entries are taken as unchanging."""
    if sp.issparse(mat):
        parts = [getattr(mat, p, None) for p in ("data", "indices", "indptr")]
        return all(isinstance(p, np.ndarray) and not p.flags.writeable for p in parts)
    return isinstance(mat, np.ndarray) and not mat.flags.writeable


def checked_square(name: str, mat: object, n: int | None):  # noqa: ANN201
    """:func:`square` of ``mat``, once per locked matrix: a prepared rack hands the engine its
    compiled model's read-only M, C, K on every run (checking them again cost ~0.4 ms of the
    paper rack's run, issue 21)."""
    hit = _CHECKED.get(id(mat))
    if hit is not None and hit[0]() is mat:
        a = hit[1]
        if n is not None and a.shape[0] != n:
            raise InputError(name, f"shape {a.shape}", f"shape ({n}, {n}) like M")
        return a
    a = square(name, mat, n)
    if _locked(mat):
        key = id(mat)
        try:
            ref = weakref.ref(mat, lambda _, k=key: _CHECKED.pop(k, None))
        except TypeError:  # pragma: no cover - a type without weak references: not kept
            return a
        _CHECKED[key] = (ref, a, False)
    return a


def checked_symmetric(name: str, mat: object, a: object) -> None:
    """:func:`check_symmetric` of ``a = checked_square(name, mat, ...)``, once per locked
    matrix."""
    hit = _CHECKED.get(id(mat))
    if hit is not None and hit[0]() is mat and hit[1] is a:
        if not hit[2]:
            check_symmetric(name, a)
            _CHECKED[id(mat)] = (hit[0], a, True)
        return
    check_symmetric(name, a)


def series(name: str, val: object, shape: tuple[int, ...]) -> np.ndarray:
    a = np.asarray(val, dtype=float)
    if a.shape != shape:
        raise InputError(name, f"array of shape {a.shape}", f"shape {shape}")
    if not np.all(np.isfinite(a)):
        bad = int(np.argmax(~np.isfinite(a.ravel())))
        raise InputError(name, f"non-finite value at flat index {bad}", "finite numbers")
    return a


def positive_int(name: str, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
        raise InputError(name, value, "an integer >= 1")
    return int(value)


#: steps integrated per kernel call (bounded working memory; the state carries over exactly)
DEFAULT_CHUNK = 20_000
#: what the planar scheme does not support (argument -> what it is)
PLANAR_UNSUPPORTED = {
    "force": "applied forces",
    "u0": "an initial displacement",
    "v0": "an initial velocity",
    "method": "the exact modal propagators",
}


@dataclass(frozen=True)
class RunInputs:
    """The checked arguments of :func:`seisrack.dynamics.simulate`, in the shapes its schemes
    take: ``ag`` (n_t,) along the line or (n_t, 2) along x and z in the plane, ``influence``
    the matching (n,) or (n, 2), ``chunk`` the steps per kernel call."""

    M: object
    C: object
    K: object
    planar: bool
    dt: float
    g: float
    n_steps: int
    ag: np.ndarray
    influence: np.ndarray
    av: np.ndarray | None
    rv: np.ndarray | None
    F: np.ndarray | None
    u0: np.ndarray | None
    v0: np.ndarray | None
    chunk: int
    save_every: int | None
    hinges: Hinges

    @property
    def influences(self) -> list[np.ndarray]:
        """The influence vector of each horizontal ground component."""
        r = self.influence
        return [r[:, c] for c in range(r.shape[1])] if r.ndim == 2 else [r]


def run_inputs(M, C, K, sliders, *, dt, n_steps, ground_accel, influence, force,  # noqa: ANN001, C901, N803
               vertical_accel, vertical_influence, g, u0, v0, chunk_steps, save_every, method,
               hinges, progress) -> RunInputs:
    """Every argument of :func:`seisrack.dynamics.simulate` checked, in one place (see there
    for their meaning); bad input raises :class:`InputError` naming the argument."""
    m_in, k_in = M, K
    M = checked_square("M", M, None)
    n = M.shape[0]
    C = checked_square("C", C, n)
    K = checked_square("K", K, n)
    checked_symmetric("M", m_in, M)
    checked_symmetric("K", k_in, K)
    planar = isinstance(sliders, PlanarSliders)
    if not (planar or isinstance(sliders, Sliders)):
        raise InputError("sliders", type(sliders).__name__,
                         "seisrack.dynamics.Sliders or seisrack.dynamics.PlanarSliders")
    if not (isinstance(dt, int | float) and np.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    if not (np.isfinite(g) and g > 0):
        raise InputError("g", g, "a finite gravity > 0 m/s²")
    sliders.check_dofs(n)
    lengths = [np.shape(x)[0] for x in (ground_accel, force, vertical_accel)
               if x is not None and np.ndim(x) >= 1]
    if n_steps is None:
        if not lengths:
            raise InputError("n_steps", None, "a number of steps when no excitation is given")
        n_steps = lengths[0] - 1
    if isinstance(n_steps, bool) or int(n_steps) != n_steps or n_steps < 1:
        raise InputError("n_steps", n_steps, "an integer >= 1")
    n_steps = int(n_steps)
    n_t = n_steps + 1
    av = None if vertical_accel is None else series("vertical_accel", vertical_accel, (n_t,))
    rv = None
    if av is not None and vertical_influence is not None:
        rv = series("vertical_influence", vertical_influence, (n,))
    if chunk_steps is not None:
        positive_int("chunk_steps", chunk_steps)
    if save_every is not None:
        save_every = positive_int("save_every", save_every)
    if method not in ("auto", "exact", "newmark"):
        raise InputError("method", method, '"auto", "exact" or "newmark"')
    if hinges is None:
        hinges = no_hinges()
    if not isinstance(hinges, Hinges):
        raise InputError("hinges", type(hinges).__name__, "a seisrack.dynamics.hinges.Hinges")
    hinges.check(n)
    if hinges.axial is not None and not planar:
        raise InputError("hinges.axial", "the P-Δ of the current axial forces",
                         "None for sliders on a line: it is built in the planar scheme only "
                         "(sliders in the plane, 3D racks)")
    if planar:
        given = {"force": force, "u0": u0, "v0": v0,
                 "method": method if method == "exact" else None}
        for name, value in given.items():
            if value is not None:
                raise InputError(name, value if name == "method" else "given",
                                 f"not given for sliders in the plane: the planar scheme has "
                                 f"no {PLANAR_UNSUPPORTED[name]}")
        ag, r = _planar_ground(ground_accel, influence, n, n_t)
        F = q_u0 = q_v0 = None
        chunk = int(chunk_steps or (1000 if progress is not None else 5000))
    else:
        ag = np.zeros(n_t) if ground_accel is None else series(
            "ground_accel", _one_column(ground_accel), (n_t,))
        r = np.ones(n) if influence is None else series("influence", _one_column(influence),
                                                        (n,))
        F = None if force is None else series("force", force, (n_t, n))
        q_u0 = np.zeros(n) if u0 is None else series("u0", u0, (n,))
        q_v0 = np.zeros(n) if v0 is None else series("v0", v0, (n,))
        chunk = int(chunk_steps or (2000 if progress is not None else DEFAULT_CHUNK))
    return RunInputs(M=M, C=C, K=K, planar=planar, dt=float(dt), g=float(g), n_steps=n_steps,
                     ag=ag, influence=r, av=av, rv=rv, F=F, u0=q_u0, v0=q_v0,
                     chunk=min(chunk, n_steps), save_every=save_every, hinges=hinges)


def _one_column(a):  # noqa: ANN001, ANN202
    """A (k, 1) array as (k,): sliders on a line take one ground component."""
    a = np.asarray(a)
    return a[:, 0] if a.ndim == 2 and a.shape[1] == 1 else a


def _planar_ground(ground_accel, influence, n: int, n_t: int  # noqa: ANN001
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(n_t, 2) ground accelerations x, z and (n, 2) influence vectors of planar sliders."""
    if ground_accel is None:
        return np.zeros((n_t, 2)), np.zeros((n, 2))
    a = np.asarray(ground_accel, dtype=float)
    if a.ndim == 1:
        a = np.column_stack([a, np.zeros_like(a)])
    a = series("ground_accel", a, (n_t, 2))
    if influence is None:
        raise InputError("influence", None, "(n, 2) influence vectors of the x and z ground "
                         "components for sliders in the plane")
    r = np.asarray(influence, dtype=float)
    if r.ndim == 1:
        r = np.column_stack([r, np.zeros_like(r)])
    return a, series("influence", r, (n, 2))
