"""Earthquake time history of a rack with sliding pallets (paper §IV): :func:`run_rack`.

Glue from a compiled :class:`~seisrack.model.frame_model.FrameModel` and a ground-motion
:class:`~seisrack.motion.records.Record` to the stick–slip engine, and from the engine's
:class:`~seisrack.dynamics.results.TimeHistory` to the quantities a rack engineer reads:
beam-level displacement and acceleration, total pallet–beam contact force, base shear, upright
moments, and each pallet's sliding against its fall limit.
"""

from __future__ import annotations

import functools
import math
import weakref
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from seisrack.analysis.hinges import HingePeaks, hinge_response, rack_hinges
from seisrack.analysis.peaks import (
    PeakTracker,
    RackOperators,
    connection_moment,
    level_sum,
    rack_operators,
)
from seisrack.analysis.response import (  # noqa: F401  (re-exported: the rack API)
    ACCEL_FILTER_HZ,
    ACCEL_FILTER_ORDER,
    SLIDING_TOL_M,
    RackResponse,
)
from seisrack.dynamics import Sliders, TimeHistory, simulate
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.engine import single_blas_thread
from seisrack.dynamics.hinges import Hinges
from seisrack.errors import InputError, SolverError
from seisrack.model.frame_model import FrameModel
from seisrack.motion.records import Record

#: default upper bound of the analysis time step [s]
DEFAULT_MAX_DT = 0.005
#: friction coefficient used for the companion run with rigidly held pallets
RIGID_MU = 1.0e6


def analysis_grid(record: Record, dt: float | None, max_dt: float = DEFAULT_MAX_DT) -> int:
    """Number of analysis steps per record step (the analysis dt is ``record.dt / k``)."""
    if dt is None:
        return max(1, math.ceil(record.dt / max_dt - 1e-9))
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise InputError("dt", dt, "a finite time step > 0 s")
    ratio = record.dt / dt
    k = round(ratio)
    if k < 1 or abs(ratio - k) > 1e-6 * max(ratio, 1.0):
        raise InputError(
            "dt", dt,
            f"the record's time step {record.dt:g} s divided by a whole number "
            f"(e.g. {record.dt:g}, {record.dt / 2:g}, {record.dt / 4:g} s)",
        )
    return int(k)


def _resample(a: np.ndarray, k: int) -> np.ndarray:
    """Linear interpolation of a record onto ``k`` sub-steps per record step (exact for the
    piecewise-linear excitation the engine assumes)."""
    if k == 1:
        return np.asarray(a, dtype=float)
    n = a.size
    x = np.arange((n - 1) * k + 1) / k
    return np.interp(x, np.arange(n), a)


@single_blas_thread
def run_rack(
    model: FrameModel,
    record: Record,
    *,
    dt: float | None = None,
    vertical: Record | None = None,
    free_vibration: float = 0.0,
    backend: str = "auto",
    rigid_companion: bool = False,
    progress: Callable[[int], None] | None = None,
    throw: bool = True,
    method: str = "auto",
    basis: str | Basis = "auto",
    save_every: int | None = 1,
    track_energy: bool = True,
    max_memory: float | None = None,
    accel_filter_hz: float = ACCEL_FILTER_HZ,
    operators: RackOperators | None = None,
) -> RackResponse:
    """Time history of ``model`` under the horizontal ground acceleration ``record``.

    dt: analysis step [s], a whole divisor of ``record.dt`` (default: the largest such step
        ≤ 5 ms). vertical: optional vertical ground acceleration (same dt and length); the
        pallets' normal forces become m (g + a_v) and the structure is loaded vertically.
    free_vibration: seconds of zero ground motion appended after the record.
    rigid_companion: also run the rack with rigidly held pallets, so that the simplified
        check's alpha is the designer's (rigid) one; off by default (it costs a second run):
        the check then uses this run's beam accelerations.
    progress: called with the number of analysis steps just completed, an increment (as
        ``tqdm.update`` expects), after each chunk of steps of the main run.
    method: time integration of :func:`seisrack.dynamics.simulate` ("auto", "exact" or
        "newmark"); basis: its ``basis`` ("auto": every mode up to 50 DOFs, a reduced
        load-dependent Ritz basis above).
    save_every: keep every k-th sample of the histories (``None``: first and last only, for
        studies); peaks are always taken over every step. max_memory: bytes the histories may
        take (default half of the available memory, at most 4 GiB); a longer run is refused
        up front.
    accel_filter_hz: [Hz] cut-off of the zero-phase low-pass filter of the reported floor
        accelerations (``beam_acceleration_filtered``; the raw ``beam_acceleration`` is kept),
        applied to the full-rate level accelerations whatever ``save_every`` is.
    operators: ``rack_operators(model, basis.phi)`` computed once by a caller that runs the
        same model many times (a study), with ``basis`` given too; default: built here.
    """
    if not (isinstance(accel_filter_hz, int | float) and math.isfinite(accel_filter_hz)
            and accel_filter_hz > 0):
        raise InputError("accel_filter_hz", accel_filter_hz, "a frequency > 0 Hz")
    if not isinstance(record, Record):
        raise InputError("record", type(record).__name__, "a seisrack.motion.Record")
    if record.accel.size < 3:
        raise InputError(
            "record", f"{record.accel.size} samples", "a record of at least 3 samples"
        )
    if not (math.isfinite(free_vibration) and free_vibration >= 0):
        raise InputError("free_vibration", free_vibration, "a duration >= 0 s")
    k = analysis_grid(record, dt)
    h = record.dt / k
    ag_rec = np.asarray(record.accel, dtype=float)
    av_rec = None
    if vertical is not None:
        if abs(vertical.dt - record.dt) > 1e-9 * record.dt:
            raise InputError(
                "vertical.dt", vertical.dt, f"the horizontal record's time step {record.dt:g} s"
            )
        if vertical.accel.size != record.accel.size:
            raise InputError(
                "vertical", f"{vertical.accel.size} samples",
                f"the horizontal record's length ({record.accel.size} samples)",
            )
        av_rec = np.asarray(vertical.accel, dtype=float)
    n_pad = int(round(free_vibration / record.dt))
    if n_pad:
        ag_rec = np.concatenate([ag_rec, np.zeros(n_pad)])
        if av_rec is not None:
            av_rec = np.concatenate([av_rec, np.zeros(n_pad)])
    ag = _resample(ag_rec, k)
    av = None if av_rec is None else _resample(av_rec, k)
    sliders = Sliders(
        model.pallet_dof, model.pallet_mass, model.pallet_mu_static, model.pallet_mu_dynamic,
        0.0 if model.pallet_friction_rate is None else model.pallet_friction_rate,
    )
    hinges = rack_hinges(model)
    mats = (model.M_sparse, model.C_sparse, model.K_sparse)
    common = dict(dt=h, ground_accel=ag, influence=model.r_x, vertical_accel=av,
                  vertical_influence=None if av is None else model.r_y, g=model.g,
                  backend=backend, throw=throw, method=method)
    # the basis is built once and shared with the companion run (and with the next runs of
    # the same model: see _model_cache)
    cache = _model_cache(model)
    if isinstance(basis, Basis):
        bas, ops_key = basis, None
    else:
        if basis not in ("auto", "full", "reduced"):
            raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
        key = ("basis", basis, av is not None)
        bas = cache.get(key)
        if bas is None:
            bas = cache[key] = _locked(rack_basis(model, sliders, basis, av, hinges))
        ops_key = ("operators", *key[1:])
    pallet_level = cache.get("pallet_level")
    if pallet_level is None:
        level_of_dof = {int(d): lv for lv, dofs in enumerate(model.level_dofs) for d in dofs}
        pallet_level = cache["pallet_level"] = _locked(
            np.array([level_of_dof[int(d)] for d in model.pallet_dof], dtype=int))
    P = bas.phi[model.pallet_dof, :]  # (m, r) support of each pallet
    if operators is None:
        ops = None if ops_key is None else cache.get(ops_key)
        if ops is None:
            ops = _locked(rack_operators(model, bas.phi))
            if ops_key is not None:
                cache[ops_key] = ops
    elif operators.level.shape[0] != bas.phi.shape[1]:
        raise InputError("operators", f"operators for a basis of {operators.level.shape[0]}",
                         f"rack_operators(model, basis.phi) of this basis ({bas.size} vectors)")
    else:
        ops = operators
    # Newmark's period-2h acceleration residue is smoothed (smoothed_acceleration); the
    # engine takes Newmark for a rack exactly when asked or when the damping has a mass term
    newmark = method == "newmark" or hinges is not None or sliders.velocity_dependent or (
        method == "auto" and model.damping_coefficients[0] != 0.0 and model.n_pallets > 0)
    tracker = PeakTracker(ops, P, pallet_level, ag, h, smooth=newmark, keep_accel=True,
                          design=True)
    hpk = None if hinges is None else HingePeaks(hinges, bas.phi)

    def on_chunk(chunk) -> None:  # noqa: ANN001
        tracker(chunk)
        if hpk is not None:
            hpk(chunk)

    try:
        hist = simulate(*mats, sliders, **common, progress=progress, basis=bas,
                        save_every=save_every, on_chunk=on_chunk, track_energy=track_energy,
                        max_memory=max_memory, hinges=hinges)
    except InputError as exc:
        if not exc.field.startswith("sliders.friction_rate["):
            raise
        j = int(exc.field.split("[")[1].rstrip("]"))
        raise InputError(f"friction_rate of pallet {j + 1} (level {pallet_level[j] + 1})",
                         exc.value, exc.allowed, source=getattr(model, "title", None) or None,
                         hint=exc.hint) from None
    if (hist.method == "newmark") != newmark:  # pragma: no cover - guards the rule above
        raise SolverError(f"run_rack expected the {'newmark' if newmark else 'exact'} "
                          f"method but the engine used {hist.method}")
    peaks = tracker.result()
    acc_full = tracker.level_acceleration()
    acc_filt = None if acc_full is None else lowpass(acc_full, h, accel_filter_hz)
    peaks["beam_acceleration_filtered"] = (
        None if acc_filt is None else np.abs(acc_filt).max(axis=0))
    rigid_peak = None
    if rigid_companion and model.n_pallets:
        rig = PeakTracker(ops, P, pallet_level, ag, h, smooth=False, design=False)
        rigid_sl = Sliders(model.pallet_dof, model.pallet_mass, RIGID_MU, RIGID_MU)
        common["method"] = "exact" if hist.method == "exact" else method
        simulate(*mats, rigid_sl, **common, basis=bas, save_every=None, on_chunk=rig,
                 track_energy=False, hinges=hinges)
        rigid_peak = rig.result()["beam_acceleration"]
    resp = _response(model, hist, ag, h, record.name, rigid_peak, ops, pallet_level, peaks)
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    return replace(resp, acceleration_filter_hz=float(accel_filter_hz),
                   beam_acceleration_filtered=None if acc_filt is None else acc_filt[idx],
                   hinges=hinge_response(model, hist, hpk))


#: per compiled model (weakly held: dropped with the model), what every run of it rebuilds
#: otherwise: the basis, the recovery and design operators in it, the pallets' levels. A
#: FrameModel is immutable (frozen, its arrays locked), so these cannot go stale.
_MODEL_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _model_cache(model: FrameModel) -> dict:
    try:
        return _MODEL_CACHE.setdefault(model, {})
    except TypeError:  # not weakly referenceable (a stand-in object): nothing is kept
        return {}


def _locked(obj):  # noqa: ANN001, ANN202
    """``obj`` with its arrays (through dataclass fields and dict values, recursively) made
    read-only, since it is shared by every run of a model (returned as is)."""
    import dataclasses

    def lock(x) -> None:  # noqa: ANN001
        if isinstance(x, np.ndarray):
            x.flags.writeable = False
        elif isinstance(x, dict):
            for v in x.values():
                lock(v)
        elif dataclasses.is_dataclass(x) and not isinstance(x, type):
            for f in dataclasses.fields(x):
                v = getattr(x, f.name)
                if isinstance(v, np.ndarray | dict) or dataclasses.is_dataclass(v):
                    lock(v)

    lock(obj)
    return obj


def lowpass(a: np.ndarray, h: float, fc: float, order: int = ACCEL_FILTER_ORDER) -> np.ndarray:
    """Zero-phase Butterworth low-pass of ``a: (n_t, k)`` sampled every ``h`` [s] at ``fc`` [Hz].

    ``scipy.signal.sosfiltfilt`` (forward and backward: no phase shift, so peaks stay at their
    time; the magnitude response is the square of the order-``order`` filter's, -6 dB at fc).
    A cut-off at or above the Nyquist frequency returns ``a`` unchanged.
    """
    from scipy.signal import sosfiltfilt

    a = np.asarray(a, dtype=float)
    if fc >= 0.5 / h or a.shape[0] < 2:
        return a.copy()
    sos = _butter_sos(int(order), float(fc), float(h)).copy()  # scipy wants it writable
    pad = min(3 * (2 * sos.shape[0] + 1), a.shape[0] - 1)
    return sosfiltfilt(sos, a, axis=0, padlen=pad)


@functools.lru_cache(maxsize=32)
def _butter_sos(order: int, fc: float, h: float) -> np.ndarray:
    """Butterworth second-order sections (designed once per (order, fc, h): ~1 ms each)."""
    from scipy.signal import butter

    return butter(order, fc, btype="low", fs=1.0 / h, output="sos")


def pallet_bays(model: FrameModel) -> np.ndarray:
    """(m,) 0-based bay of each pallet, from its node's x between the uprights."""
    x = np.asarray(model.nodes[model.pallet_node, 0], dtype=float)
    ux = np.asarray(model.upright_x, dtype=float)
    return np.clip(np.searchsorted(ux, x, side="right") - 1, 0, max(ux.size - 2, 0))


def rack_basis(model: FrameModel, sliders: Sliders, basis: str, av=None,  # noqa: ANN001
               hinges: Hinges | None = None) -> Basis:
    """The run's basis: every mode up to the engine's ``AUTO_FULL_MAX_DOF``, else the
    load-dependent Ritz basis of the ground load, the pallets and (with nonlinear hinges, then
    ``HINGE_RITZ_BLOCKS`` blocks) unit moments at the hinges."""
    from seisrack.dynamics.basis import full_basis, reduced_basis
    from seisrack.dynamics.engine import AUTO_FULL_MAX_DOF, HINGE_RITZ_BLOCKS, HINGE_RITZ_TOL

    if basis not in ("auto", "full", "reduced"):
        raise InputError("basis", basis, '"auto", "full", "reduced" or a seisrack Basis')
    if basis == "full" or (basis == "auto" and model.n_dof <= AUTO_FULL_MAX_DOF):
        return full_basis(model.M_sparse, model.K_sparse)
    loads = [model.total_mass_sparse() @ model.r_x]
    if av is not None:
        loads.append(model.M_sparse @ model.r_y)
    if hinges is not None:
        loads.append(hinges.load_vectors(model.n_dof)[:, hinges.law != 0])
        return reduced_basis(model.M_sparse, model.K_sparse, sliders.dof, sliders.mass,
                             np.column_stack(loads), blocks=HINGE_RITZ_BLOCKS,
                             tol=HINGE_RITZ_TOL)
    return reduced_basis(model.M_sparse, model.K_sparse, sliders.dof, sliders.mass,
                         np.column_stack(loads))


def smoothed_acceleration(v: np.ndarray, a: np.ndarray, h: float) -> np.ndarray:
    """Acceleration reported at grid points: ``(v[n+1] - v[n-1]) / (2 h)`` (``a`` at the ends).

    Average-acceleration Newmark is not L-stable: after every stick/slip event (a jump of the
    friction forces) the very stiff, heavily over-damped modes of the frame (beam axial modes,
    excited by the pallets' horizontal forces) keep a non-decaying component of period 2h in the
    *accelerations*, while displacements and velocities stay accurate. Since
    ``(v[n+1] - v[n-1]) / (2h) = (a[n-1] + 2 a[n] + a[n+1]) / 4`` for this scheme, the central
    difference removes that period-2h component exactly and is second-order accurate elsewhere;
    a physical acceleration jump at an event is spread over one step on each side.
    v, a: (n_t, k) relative velocity and acceleration; returns (n_t, k).
    """
    out = np.array(a, dtype=float, copy=True)
    if v.shape[0] >= 3:
        out[1:-1] = (v[2:] - v[:-2]) / (2.0 * h)
    return out


def _response(
    model: FrameModel, hist: TimeHistory, ag: np.ndarray, h: float, name: str,
    rigid_peak: np.ndarray | None, ops, pallet_level: np.ndarray, peaks: dict,  # noqa: ANN001
) -> RackResponse:
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    agk = ag[idx]
    disp = hist.q @ ops.level
    vel = hist.qd @ ops.level
    acc_raw = hist.qdd @ ops.level + agk[:, None]
    contiguous = idx.shape[0] == ag.shape[0]
    if hist.method == "newmark" and contiguous:
        acc = smoothed_acceleration(vel, acc_raw - agk[:, None], h) + agk[:, None]
    else:  # exact propagators leave no period-2h residue; decimated samples are not smoothed
        acc = acc_raw
    n_level = len(model.level_dofs)
    force = level_sum(hist.friction, pallet_level, n_level)
    # Support reactions include the stiffness-proportional damping forces (C = a0 M + a1 K):
    # the member forces are K (u + a1 v); the a0 M v part acts on the masses, not the supports.
    base_shear = hist.q @ ops.shear + ops.a1 * (hist.qd @ ops.shear)
    n_t = idx.shape[0]
    mom_base = hist.q @ ops.base_moment
    shape = (n_t, ops.n_upright, ops.n_level)
    conn = connection_moment((hist.q @ ops.below).reshape(shape),
                             (hist.q @ ops.above).reshape(shape))
    return RackResponse(
        t=hist.t,
        ground_accel=agk,
        beam_displacement=disp,
        beam_acceleration=acc,
        beam_acceleration_raw=acc_raw,
        contact_force=force,
        base_shear=base_shear,
        upright_moment_base=mom_base,
        upright_moment_connection=conn,
        pallet_sliding=hist.sliding,
        pallet_friction=hist.friction,
        pallet_level=pallet_level,
        pallet_x=np.asarray(model.nodes[model.pallet_node, 0], dtype=float),
        pallet_mass=np.asarray(model.pallet_mass, dtype=float),
        pallet_mu_static=np.asarray(model.pallet_mu_static, dtype=float),
        pallet_mu_dynamic=np.asarray(model.pallet_mu_dynamic, dtype=float),
        pallet_limit_neg=np.asarray(model.pallet_limit_neg, dtype=float),
        pallet_limit_pos=np.asarray(model.pallet_limit_pos, dtype=float),
        events=hist.events,
        energy=hist.energy,
        g=float(model.g),
        dt=h,
        record_name=name,
        status=hist.status,
        history=hist,
        rigid_beam_acceleration_peak=rigid_peak,
        full_peaks=peaks,
        pallet_bay=pallet_bays(model),
        operators=ops,
    )
