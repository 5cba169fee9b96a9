"""What every run of one compiled rack shares, prepared once: :func:`prepare_run`.

The basis the engine integrates in (default engine:
:func:`seisrack.dynamics.run_basis.choose_basis`, every mode of a small rack, a load-dependent
Ritz basis of a large one; local engine: :func:`seisrack.dynamics.local.racks.rack_basis`, with
its measured error), the recovery and design operators projected onto it
(:mod:`seisrack.analysis.operators`), the rack's hinges and its pallets as the engine's sliders
(:func:`rack_sliders`, built once: a run only sets their friction). A study runs one model
under many records and frictions: it prepares once and hands the :class:`PreparedRun` to every
:func:`~seisrack.analysis.run_rack`. Friction does not enter what is prepared, so a run may use
a model whose pallet friction differs from the prepared one's.
"""

from __future__ import annotations

import dataclasses
import weakref
from dataclasses import dataclass

import numpy as np

from seisrack.analysis.hinges import rack_hinges
from seisrack.analysis.operators import RackOperators, rack_operators
from seisrack.dynamics import PlanarSliders, Sliders
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.hinges import Hinges
from seisrack.dynamics.local.sliders import LocalSliders
from seisrack.dynamics.run_basis import choose_basis
from seisrack.errors import InputError
from seisrack.model.frame_model import FrameModel

#: friction coefficient of the companion run with rigidly held pallets
RIGID_MU = 1.0e6


@dataclass(frozen=True)
class PreparedRun:
    """The shared part of the runs of one rack (arrays read-only).

    basis: the engine's basis; ops: the rack operators projected onto it; hinges: the rack's
    nonlinear hinges (None when every connection is elastic); sliders: the pallets as the
    engine's sliders (:func:`rack_sliders`, with the prepared model's friction: each run sets
    its own, :func:`seisrack.analysis.engines.run_sliders`); vertical: whether the basis holds
    the vertical load (runs with a vertical component); n_dof: the model's size (checked);
    engine: the engine the basis is for ("default" or "local").
    """

    basis: Basis
    ops: RackOperators
    hinges: Hinges | None
    sliders: Sliders | PlanarSliders | LocalSliders
    vertical: bool
    n_dof: int
    engine: str = "default"

    def __post_init__(self) -> None:
        _locked(self)  # shared by every run of the model


def rack_sliders(model: FrameModel,
                 engine: str = "default") -> Sliders | PlanarSliders | LocalSliders:
    """The pallets of ``model`` as ``engine``'s sliders, with the model's friction: along a
    line when the rack has one horizontal direction (their supports' down-aisle DOF), in the
    plane when it has two (their front and rear supports' x and z DOFs); the local engine's
    take every support and direction."""
    mus, mud, d = model.pallet_mu_static, model.pallet_mu_dynamic, model.pallet_dofs
    if engine == "local":
        return LocalSliders(np.asarray(d), model.pallet_mass, mus, mud)
    if model.n_dir == 1:
        return Sliders(d[:, 0, 0], model.pallet_mass, mus, mud, model.pallet_friction_rate)
    return PlanarSliders(d[:, :, 0], d[:, :, 1], model.pallet_mass, mus, mud)


#: per compiled model (weakly held: dropped with the model), its prepared runs
_MODEL_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def model_cache(model: FrameModel) -> dict:
    """The prepared runs of ``model`` by key (weakly held: dropped with the model; a fresh
    dict for an object that cannot be weakly referenced, so nothing is kept)."""
    try:
        return _MODEL_CACHE.setdefault(model, {})
    except TypeError:
        return {}


def prepare_run(model: FrameModel, *, basis: str | Basis = "auto", vertical: bool = False,
                design: bool = True, engine: str = "default") -> PreparedRun:
    """The :class:`PreparedRun` of ``model`` for ``engine`` (cached per model for a named
    basis: a compiled model is immutable, so the cache cannot go stale). The local engine
    takes its own basis (``basis`` left "auto")."""
    given = isinstance(basis, Basis)
    if not given and basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if engine not in ("default", "local"):
        raise InputError("engine", engine, '"default" or "local"')
    cache = {} if given else model_cache(model)
    key = (engine, None if given else basis, bool(vertical), bool(design))
    hit = cache.get(key)
    if hit is None:
        hinges, sliders = None, rack_sliders(model, engine)
        if engine == "local":
            from seisrack.dynamics.local.racks import rack_basis

            bas = rack_basis(model, sliders, vertical=vertical)
        else:
            hinges = rack_hinges(model)
            bas = choose_basis(basis, model.M_sparse, model.K_sparse, sliders, model.influence,
                               rv=model.r_y if vertical else None, hinges=hinges)
        hit = cache[key] = PreparedRun(basis=bas,
                                       ops=rack_operators(model, bas.phi, design=design),
                                       hinges=hinges, sliders=sliders, vertical=vertical,
                                       n_dof=model.n_dof, engine=engine)
    return hit


def checked_prepared(prepared: PreparedRun, model: FrameModel, engine: str) -> PreparedRun:
    """``prepared`` if it was prepared for ``model``'s size, its pallets' masses and for
    ``engine``."""
    if not isinstance(prepared, PreparedRun):
        raise InputError("prepared", type(prepared).__name__,
                         "a seisrack.analysis.PreparedRun (prepare_run(model))")
    if prepared.n_dof != model.n_dof:
        raise InputError("prepared", f"a prepared run of {prepared.n_dof} DOFs",
                         f"prepare_run(model) of this model ({model.n_dof} DOFs)")
    if not np.array_equal(prepared.sliders.mass, model.pallet_mass):
        raise InputError("prepared", f"a prepared run of {prepared.sliders.count} pallets "
                         f"({float(np.sum(prepared.sliders.mass)):g} kg)",
                         f"prepare_run(model) of this model's {model.n_pallets} pallets "
                         f"({float(np.sum(model.pallet_mass)):g} kg)")
    if prepared.engine != engine:
        raise InputError("prepared", f"a run prepared for the {prepared.engine} engine",
                         f'prepare_run(model, engine="{engine}") for engine="{engine}"')
    return prepared


def _locked(obj):  # noqa: ANN001, ANN202
    """``obj`` with its arrays (through dataclass fields, tuples and dict values, recursively)
    made read-only, since it is shared by every run of a model (returned as is)."""

    def lock(x) -> None:  # noqa: ANN001
        if isinstance(x, np.ndarray):
            x.flags.writeable = False
        elif isinstance(x, dict | tuple):
            for v in (x.values() if isinstance(x, dict) else x):
                lock(v)
        elif dataclasses.is_dataclass(x) and not isinstance(x, type):
            for f in dataclasses.fields(x):
                lock(getattr(x, f.name))

    lock(obj)
    return obj
