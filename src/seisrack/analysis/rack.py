"""Earthquake time history of a rack with sliding pallets (paper §IV): :func:`run_rack`, one
path for a 2D and a 3D rack.

Glue from a compiled :class:`~seisrack.model.frame_model.FrameModel` and a ground motion (a
:class:`~seisrack.motion.records.Record` along the down-aisle axis, or a
:class:`~seisrack.motion.components.GroundMotion` with a cross-aisle component, a vertical one
and an incidence angle) to the stick–slip engine, and from the engine's
:class:`~seisrack.dynamics.results.TimeHistory` to the quantities a rack engineer reads: beam
level displacement and acceleration, pallet–beam contact force, base shear, upright moments,
design quantities, each pallet's sliding against its free distances, falls into the aisles and
down-aisle impacts. Peaks are taken over every step, whatever ``save_every`` keeps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from seisrack.analysis.engines import simulate_rack
from seisrack.analysis.hinges import HingePeaks, hinge_response
from seisrack.analysis.pallet_contacts import ContactTracker
from seisrack.analysis.peaks import (  # noqa: F401  (lowpass re-exported)
    ACCEL_FILTER_ORDER,
    PeakTracker,
    connection_moment,
    level_sum,
    lowpass,
    with_direction,
)
from seisrack.analysis.prepare import (  # noqa: F401  (RIGID_MU re-exported)
    RIGID_MU,
    PreparedRun,
    checked_prepared,
    prepare_run,
)
from seisrack.analysis.response import (  # noqa: F401  (re-exported: the rack API)
    ACCEL_FILTER_HZ,
    ACCEL_FILTER_MIN_HZ,
    SLIDING_TOL_M,
    RackResponse,
)
from seisrack.dynamics import TimeHistory
from seisrack.dynamics.basis import Basis
from seisrack.dynamics.engine import single_blas_thread
from seisrack.errors import InputError, SolverError
from seisrack.model.features import (  # noqa: F401  (non_classical_damping re-exported)
    check_engine,
    non_classical_damping,
    require,
    takes_newmark,
)
from seisrack.model.frame_model import FrameModel
from seisrack.motion.components import (  # noqa: F401  (DEFAULT_MAX_DT re-exported)
    DEFAULT_MAX_DT,
    GroundMotion,
    analysis_grid,
    combine,
    resample,
)
from seisrack.motion.records import Record


def ground_motion(model: FrameModel, motion: Record | GroundMotion,
                  vertical: Record | None = None) -> GroundMotion:
    """``motion`` as the :class:`GroundMotion` the rack takes: a record is its down-aisle
    component (with ``vertical``); a cross-aisle component needs a 3D rack."""
    if isinstance(motion, Record):
        if motion.accel.size < 3:
            raise InputError("record", f"{motion.accel.size} samples",
                             "a record of at least 3 samples")
        motion = combine(motion, None, vertical, fields=("record", "cross", "vertical"))
    elif isinstance(motion, GroundMotion):
        if vertical is not None:
            raise InputError("vertical", vertical.name, "None: the vertical component of a "
                             "GroundMotion is its own (seisrack.motion.components.combine)")
        if motion.n < 3:
            raise InputError("motion", f"{motion.n} samples", "a motion of at least 3 samples")
    else:
        raise InputError("record", type(motion).__name__,
                         "a seisrack Record or GroundMotion (seisrack.motion.components.combine)")
    if motion.z is not None:
        require("a cross-aisle ground motion component", model.ndm, "motion", motion.name)
    return motion


@single_blas_thread
def run_rack(
    model: FrameModel,
    motion: Record | GroundMotion,
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
    prepared: PreparedRun | None = None,
    engine: str = "default",
) -> RackResponse:
    """Time history of ``model`` (2D or 3D) under the ground motion ``motion``.

    motion: a :class:`Record` (the down-aisle component; ``vertical`` optionally gives the
        vertical one, same dt and length: the pallets' normal forces become m (g + a_v) and the
        structure is loaded vertically) or a :class:`GroundMotion` (down-aisle, cross-aisle on
        a 3D rack, vertical, incidence angle).
    dt: analysis step [s], a whole divisor of the motion's step (default: the largest such
        step ≤ 5 ms).
    free_vibration: seconds of zero ground motion appended after the record.
    rigid_companion: also run the rack with rigidly held pallets, so that the simplified
        check's alpha is the designer's (rigid) one; off by default (it costs a second run),
        and without it the check gives no verdict.
    progress: called with the number of analysis steps just completed, an increment (as
        ``tqdm.update`` expects), after each chunk of steps of the main run.
    method: time integration of :func:`seisrack.dynamics.simulate` ("auto", "exact" or
        "newmark"); basis: its ``basis`` ("auto": every mode up to 50 DOFs, a reduced
        load-dependent Ritz basis above), ignored when ``prepared`` is given.
    save_every: keep every k-th sample of the histories (``None``: first and last only, for
        studies); peaks are always taken over every step. max_memory: bytes the histories may
        take (default half of the available memory, at most 4 GiB); a longer run is refused
        up front.
    accel_filter_hz: [Hz] cut-off of the zero-phase low-pass filter of the reported floor
        accelerations (``beam_acceleration_filtered``; the raw ``beam_acceleration`` is kept),
        applied to the full-rate level accelerations whatever ``save_every`` is.
    prepared: :func:`~seisrack.analysis.prepare.prepare_run` of this model's structure, made
        once by a caller that runs it many times (a study); default: prepared (and cached)
        here.
    engine: "default" (the engines above) or "local" (opt-in, issue 22: a local basis and
        each pallet's events resolved inside the step, cost linear in the rack's length;
        linear connections and Coulomb friction only, ``method`` and ``basis`` left "auto";
        :mod:`seisrack.analysis.engines`).
    """
    if not (isinstance(accel_filter_hz, int | float) and math.isfinite(accel_filter_hz)
            and accel_filter_hz >= ACCEL_FILTER_MIN_HZ):
        raise InputError("accel_filter_hz", accel_filter_hz,
                         f"a frequency >= {ACCEL_FILTER_MIN_HZ:g} Hz")
    if not (isinstance(free_vibration, int | float) and math.isfinite(free_vibration)
            and free_vibration >= 0):
        raise InputError("free_vibration", free_vibration, "a duration >= 0 s")
    mot = ground_motion(model, motion, vertical)
    check_engine(engine, model, method=method, basis=basis)
    # Newmark's period-2h acceleration residue is smoothed (smoothed_acceleration)
    newmark = takes_newmark(model, engine, method)
    k = analysis_grid(mot, dt)
    h = mot.dt / k
    mot = mot.padded(int(round(free_vibration / mot.dt)))
    ag, av = mot.on_grid(k, model.n_dir)
    if prepared is not None:
        checked_prepared(prepared, model, engine)
    else:
        prepared = prepare_run(model, basis=basis, vertical=av is not None, engine=engine)
    ops = prepared.ops
    # the connections' response is reported when some law is nonlinear (the hinges may carry
    # only the P-Δ of the current axial forces)
    hinges = prepared.hinges if prepared.hinges is not None and prepared.hinges.nonlinear \
        else None
    tracker = PeakTracker(ops, model.pallet_level, ag, h, smooth=newmark, keep_accel=True,
                          design=True, keep_series=save_every == 1)
    rig = PeakTracker(ops, model.pallet_level, ag, h, smooth=False, design=False) if (
        rigid_companion and model.n_pallets) else None
    contacts = ContactTracker(model.layout, model.n_pallets)
    hpk = None if hinges is None else HingePeaks(hinges, prepared.basis.phi)

    def on_chunk(chunk) -> None:  # noqa: ANN001
        tracker(chunk)
        contacts(chunk)
        if hpk is not None:
            hpk(chunk)

    hist = simulate_rack(model, prepared, ag, av, h, method=method, backend=backend, throw=throw,
                         on_chunk=on_chunk, progress=progress, save_every=save_every,
                         track_energy=track_energy, max_memory=max_memory, companion=rig)
    if engine == "default" and (hist.method == "newmark") != newmark:  # pragma: no cover
        raise SolverError(f"run_rack expected the {'newmark' if newmark else 'exact'} "
                          f"method but the engine used {hist.method}")
    peaks = tracker.result()
    rigid_peak = None if rig is None else rig.result()["beam_acceleration_magnitude"]
    acc_full = tracker.level_acceleration()
    acc_filt = None if acc_full is None else lowpass(acc_full, h, accel_filter_hz)
    peaks["beam_acceleration_filtered"] = (
        None if acc_filt is None else np.abs(acc_filt).max(axis=0))
    force = level_sum(with_direction(hist.friction, hist.planar), model.pallet_level,
                      ops.n_level)
    resp = _response(model, mot, hist, ag, av, h, rigid_peak, ops, peaks, force,
                     (tuple(contacts.impacts()), tuple(contacts.falls())), tracker.series())
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    squeeze = (lambda a: a[..., 0]) if model.n_dir == 1 else (lambda a: a)  # noqa: E731
    return replace(resp, acceleration_filter_hz=float(accel_filter_hz),
                   beam_acceleration_filtered=None if acc_filt is None
                   else squeeze(acc_filt[idx]),
                   hinges=None if hinges is None else hinge_response(model, hist, hpk))


def smoothed_acceleration(v: np.ndarray, a: np.ndarray, h: float) -> np.ndarray:
    """Acceleration reported at grid points: ``(v[n+1] - v[n-1]) / (2 h)`` (``a`` at the ends).

    Average-acceleration Newmark is not L-stable: after every stick/slip event (a jump of the
    friction forces) the very stiff, heavily over-damped modes of the frame (beam axial modes,
    excited by the pallets' horizontal forces) keep a non-decaying component of period 2h in the
    *accelerations*, while displacements and velocities stay accurate. Since
    ``(v[n+1] - v[n-1]) / (2h) = (a[n-1] + 2 a[n] + a[n+1]) / 4`` for this scheme, the central
    difference removes that period-2h component exactly and is second-order accurate elsewhere;
    a physical acceleration jump at an event is spread over one step on each side.
    v, a: (n_t, ...) relative velocity and acceleration; returns the shape of ``a``.
    """
    out = np.array(a, dtype=float, copy=True)
    if v.shape[0] >= 3:
        out[1:-1] = (v[2:] - v[:-2]) / (2.0 * h)
    return out


def _histories(hist: TimeHistory, ops, agk: np.ndarray, h: float,  # noqa: ANN001
               contiguous: bool) -> tuple[np.ndarray, ...]:
    """Level displacement, accelerations (reported, raw), base shear, upright base and
    connection moments at the kept samples, (n_t, ..., n_dir) each, from the basis
    coordinates."""
    nd = agk.shape[1]

    def per_dir(ops_d: tuple, x: np.ndarray) -> np.ndarray:
        return np.stack([x @ o for o in ops_d], axis=-1)

    disp = per_dir(ops.level, hist.q)
    vel = per_dir(ops.level, hist.qd)
    acc_raw = per_dir(ops.level, hist.qdd) + agk[:, None, :]
    if hist.method == "newmark" and contiguous:
        acc = smoothed_acceleration(vel, acc_raw - agk[:, None, :], h) + agk[:, None, :]
    else:  # exact propagators leave no period-2h residue; decimated samples are not smoothed
        acc = acc_raw
    # Support reactions include the stiffness-proportional damping forces (C = a0 M + a1 K):
    # the member forces are K (u + a1 v); the a0 M v part acts on the masses, not the supports.
    base_shear = hist.q @ ops.shear + ops.a1 * (hist.qd @ ops.shear)
    shape = (hist.q.shape[0], ops.n_upright, ops.n_level)
    mom_base = per_dir(ops.base_moment, hist.q)
    conn = np.stack([connection_moment((hist.q @ ops.below[d]).reshape(shape),
                                       (hist.q @ ops.above[d]).reshape(shape))
                     for d in range(nd)], axis=-1)
    return disp, acc, acc_raw, base_shear, mom_base, conn


def _response(model: FrameModel, mot: GroundMotion, hist: TimeHistory, ag: np.ndarray,
              av: np.ndarray | None, h: float, rigid_peak: np.ndarray | None, ops,  # noqa: ANN001
              peaks: dict, force: np.ndarray, impacts_falls: tuple,
              series: dict | None = None) -> RackResponse:
    """The response of the run ``hist``. ``series``: the tracker's full-rate histories
    (:meth:`~seisrack.analysis.peaks.PeakTracker.series`), taken as they are when every step
    was kept instead of being formed again from the basis coordinates."""
    idx = hist.sample_index if hist.sample_index is not None else np.arange(hist.t.shape[0])
    nd = model.n_dir
    agk = ag[idx]  # (n_t, n_dir)
    contiguous = idx.shape[0] == ag.shape[0]
    if contiguous and series is not None and series["disp"].shape[0] == idx.shape[0]:
        disp, acc_raw, acc = series["disp"], series["acc_raw"], series["acc"]
        if hist.method != "newmark":  # see below: the same values (a + ag), kept once
            acc = acc_raw
        base_shear, mom_base, conn = series["shear"], series["base"], series["conn"]
    else:
        disp, acc, acc_raw, base_shear, mom_base, conn = _histories(hist, ops, agk, h,
                                                                    contiguous)
    sq = (lambda a: a[..., 0]) if nd == 1 else (lambda a: a)  # noqa: E731
    lay = model.layout
    impacts, falls = impacts_falls
    return RackResponse(
        t=hist.t, ground_accel=sq(agk), beam_displacement=sq(disp), beam_acceleration=sq(acc),
        beam_acceleration_raw=sq(acc_raw), contact_force=sq(force), base_shear=sq(base_shear),
        upright_moment_base=sq(mom_base), upright_moment_connection=sq(conn),
        pallet_sliding=hist.sliding, pallet_friction=hist.friction,
        pallet_level=np.asarray(model.pallet_level), pallet_x=np.asarray(model.pallet_x),
        pallet_mass=np.asarray(model.pallet_mass, dtype=float),
        pallet_mu_static=np.asarray(model.pallet_mu_static, dtype=float),
        pallet_mu_dynamic=np.asarray(model.pallet_mu_dynamic, dtype=float),
        pallet_limit_neg=np.asarray(lay.limit_neg), pallet_limit_pos=np.asarray(lay.limit_pos),
        events=hist.events, energy=hist.energy, g=float(model.g), dt=h,
        record_name=mot.name, status=hist.status, history=hist,
        rigid_beam_acceleration_peak=rigid_peak, full_peaks=peaks,
        pallet_bay=np.asarray(model.pallet_bay), operators=ops,
        directions=model.directions, pallet_slot=np.asarray(model.pallet_slot),
        vertical_accel=None if av is None else av[idx], angle_deg=mot.angle_deg,
        level_y=np.asarray(model.level_y), fall_front=np.asarray(lay.fall_front),
        fall_rear=np.asarray(lay.fall_rear), falls=falls, impacts=impacts,
        pallet_row=np.asarray(model.pallet_row) if model.n_rows > 1 else None,
    )
