"""Paper report §IV: the paper's rack under an EC8 accelerogram, computations only.

The rack of Fig. 13 / Table 1 (``examples/paper_rack.toml``) is run with g = 10 m/s², the value
the paper's Table 2 implies (its forces are exactly μ·1600·10 N). The ground motion is a
synthetic EC8 Type 1, ground C, 0.3 g, 15 s accelerogram with a fixed seed: the paper's GOSCA
record cannot be recovered, so the physics is reproduced, not the digits.

Figures are in :mod:`seisrack.paper.rack_plot`, checks in
:mod:`seisrack.paper.checks`, Markdown in :mod:`seisrack.paper.rack_md`.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Mapping
from concurrent.futures import Future
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from seisrack.analysis import RackResponse, run_rack
from seisrack.errors import InputError
from seisrack.fe.modal import ModalResult, modal_analysis
from seisrack.model import RackSpec, compile_rack, load_rack, with_friction
from seisrack.motion import (
    EC8Spectrum,
    Record,
    check_ec8_suite,
    ec8_spectrum,
    generate_ec8_record,
    response_spectrum,
)
from seisrack.paper import values as pv

__all__ = [
    "RackRun", "RackStudy", "find_paper_rack", "make_record", "run_rack_study", "study_summary",
    "suite_size", "table_row",
]

log = logging.getLogger(__name__)

SEED = 2008  # the paper's year; any fixed seed reproduces the same record
RECORD = {"type": 1, "ground": "C", "ag": 0.3, "duration": 15.0, "dt": 0.005}
RIGID_MU = 1.0e3  # friction no record can overcome: pallets held rigidly
SENSITIVITY_DAMPING = 0.05  # the damping of the paper's target spectrum (Fig. 15b)
ONSET_BRACKET = (0.1, 2.5)


@dataclass
class RackRun:
    """The four μ runs of one (record, damping) pair plus the rigid-pallet run."""

    label: str
    record: Record
    damping_ratio: float
    se_t1: float  # record's pseudo-acceleration at T1 with the structure's damping [m/s²]
    rigid: RackResponse
    runs: dict[float, RackResponse]

    @property
    def g(self) -> float:
        return self.rigid.g

    @property
    def onset_mu(self) -> float:
        """μ below which some pallet slides: the largest |F_j| / (m_j g) with pallets held."""
        f = np.max(np.abs(self.rigid.pallet_friction), axis=0)
        return float(np.max(f / (self.rigid.pallet_mass * self.g)))

    @property
    def alpha_rigid(self) -> float:
        """Peak beam acceleration with pallets held, over g (the simplified rule's alpha)."""
        return float(np.max(np.abs(self.rigid.beam_acceleration)) / self.g)


@dataclass
class RackStudy:
    """Everything §IV computes (arrays kept for the figures)."""

    spec: RackSpec
    modal: ModalResult
    damping_ratio: float
    target: EC8Spectrum
    periods: np.ndarray
    psa_5: np.ndarray
    psa_struct: np.ndarray
    main: RackRun
    sensitivity: RackRun | None
    suite: list[RackRun]
    suite_check: dict[str, Any]
    onset_bisection: dict[str, Any]
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def t1(self) -> float:
        return float(self.modal.periods[0])


def find_paper_rack(path: str | Path | None = None) -> Path:
    """The paper rack's TOML: ``path``, else ``examples/paper_rack.toml`` (here or in the repo)."""
    if path is not None:
        p = Path(path)
        if not p.is_file():
            raise InputError("--rack", str(path), "an existing rack TOML file")
        if load_rack(p).geometry.depth is not None:
            raise InputError("--rack", str(path), "a 2D rack file: §IV is the paper's plane "
                             "frame, its checks compare one direction", hint="For a 3D rack "
                             "use seisrack run or seisrack report")
        return p
    here = Path(__file__).resolve()
    for cand in (Path("examples/paper_rack.toml"), here.parents[3] / "examples/paper_rack.toml"):
        if cand.is_file():
            return cand
    raise InputError("--rack", None, "the paper rack TOML",
                     hint="Run from the seisrack checkout or pass --rack examples/paper_rack.toml")


def modal_damping(model: Any, omega: float) -> float:
    """Damping ratio of a mode at omega [rad/s] for C = a0 M + a1 K (Chopra Eq. 11.4.9)."""
    a0, a1 = model.damping_coefficients
    return float(a0 / (2.0 * omega) + a1 * omega / 2.0)


def _run_set(spec: RackSpec, record: Record, t1: float, label: str,
             mus: tuple[float, ...]) -> RackRun:
    rigid_model = compile_rack(with_friction(spec, RIGID_MU))
    zeta = modal_damping(rigid_model, 2.0 * math.pi / t1)
    se = float(response_spectrum(record.accel, record.dt, np.array([t1]), zeta).psa[0])
    rigid = run_rack(rigid_model, record, rigid_companion=False, basis="full")
    runs = {mu: run_rack(compile_rack(with_friction(spec, mu)), record,
                         rigid_companion=False, basis="full")
            for mu in mus}
    return RackRun(label, record, zeta, se, rigid, runs)


def _bisect_onset(spec: RackSpec, record: Record, n_iter: int) -> dict[str, Any]:
    """Onset of sliding by bisection on μ: slides below, sticks above (one run per step)."""
    lo, hi = ONSET_BRACKET
    runs = 0
    for _ in range(n_iter):
        mid = 0.5 * (lo + hi)
        r = run_rack(compile_rack(with_friction(spec, mid)), record, rigid_companion=False,
                     basis="full")
        runs += 1
        if r.sliding_occurred():
            lo = mid
        else:
            hi = mid
    return {"low": lo, "high": hi, "estimate": 0.5 * (lo + hi), "runs": runs,
            "bracket": list(ONSET_BRACKET)}


def table_row(r: RackResponse) -> dict[str, Any]:
    """Table 2 quantities of one run: peaks of beam displacement [m], beam acceleration [m/s²],
    total contact force [N] and pallet sliding [mm] (largest over the pallets)."""
    p = r.peaks()
    slide = r.pallet_peak_sliding()
    return {
        "disp_m": p["beam_displacement_m"],
        "acc_m_s2": p["beam_acceleration_m_s2"],
        "force_N": p["total_friction_force_N"],
        "sliding_mm": 1e3 * float(slide.max(initial=0.0)),
        "sliding_spread_mm": 1e3 * float(np.ptp(slide)) if slide.size else 0.0,
        "residual_mm": 1e3 * float(np.max(np.abs(r.pallet_residual()), initial=0.0)),
        "slid": r.sliding_occurred(),
        "cap_N": float(np.sum(r.pallet_mu_dynamic * r.pallet_mass) * r.g),
    }


def suite_size(quick: bool) -> int:
    """Number of records in the EC8 suite (EN 1998-1 asks for at least 3; the paper used 1)."""
    return 3 if quick else 7


def make_record(seed: int = SEED) -> Record:
    """The study's accelerogram for ``seed`` (EC8 Type 1, ground C, 0.3 g, 15 s, 5 ms)."""
    return generate_ec8_record(seed=seed, **RECORD)  # type: ignore[arg-type]


def run_rack_study(*, quick: bool = False, rack: str | Path | None = None,
                   n_suite: int | None = None,
                   pending: Mapping[int, Future[Record]] | None = None) -> RackStudy:
    """Run §IV: modal analysis, record and spectra, Table 2 runs, onset, suite.

    pending: records of the suite already being generated elsewhere, by seed (the others are
    generated here, while those complete).
    """
    pending = pending or {}
    secs: dict[str, float] = {}
    t0 = time.perf_counter()
    spec = replace(load_rack(find_paper_rack(rack)), g=pv.TABLE2_G)
    modal = modal_analysis(compile_rack(spec))
    t1 = float(modal.periods[0])
    target = ec8_spectrum(RECORD["type"], RECORD["ground"], RECORD["ag"])
    record = make_record(SEED)
    periods = np.geomspace(0.02, 4.0, 90 if quick else 160)
    secs["modal_and_record"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    main = _run_set(spec, record, t1, "main", pv.MU_VALUES)
    psa_5 = response_spectrum(record.accel, record.dt, periods, 0.05).psa
    psa_s = response_spectrum(record.accel, record.dt, periods, main.damping_ratio).psa
    sens = None
    if (not quick and spec.damping.kind == "stiffness"
            and abs(spec.damping.ratio - SENSITIVITY_DAMPING) > 1e-9):
        spec5 = replace(spec, damping=replace(spec.damping, ratio=SENSITIVITY_DAMPING))
        sens = _run_set(spec5, record, t1, f"zeta={SENSITIVITY_DAMPING:g}", pv.MU_VALUES)
    secs["table2_runs"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    bis = _bisect_onset(spec, record, 5 if quick else 7)
    secs["onset_bisection"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    n = n_suite if n_suite is not None else suite_size(quick)
    seeds = [SEED + i for i in range(1, n)]
    # the records generated here first, those pending elsewhere last
    local = {s: make_record(s) for s in seeds if s not in pending}
    records = [record] + [local[s] if s in local else pending[s].result() for s in seeds]
    suite = [main] + [_run_set(spec, rec, t1, f"record {i + 2}", pv.MU_VALUES)
                      for i, rec in enumerate(records[1:])]
    rep = check_ec8_suite(records, target, t1)
    suite_check = {"passed": rep.passed, "checks": [vars(i) for i in rep.items]}
    secs["suite"] = time.perf_counter() - t0
    return RackStudy(
        spec=spec, modal=modal, damping_ratio=main.damping_ratio, target=target,
        periods=periods, psa_5=psa_5, psa_struct=psa_s, main=main, sensitivity=sens,
        suite=suite, suite_check=suite_check, onset_bisection=bis, seconds=secs,
    )


def _mean_sd(x: list[float]) -> dict[str, float]:
    a = np.asarray(x, dtype=float)
    return {"mean": float(a.mean()), "sd": float(a.std(ddof=1)) if a.size > 1 else 0.0}


def study_summary(st: RackStudy) -> dict[str, Any]:
    """JSON-ready numbers of §IV (the Markdown tables are built from these)."""
    def run_set(rs: RackRun) -> dict[str, Any]:
        return {
            "damping_ratio": rs.damping_ratio, "se_t1_m_s2": rs.se_t1,
            "se_t1_over_g": rs.se_t1 / rs.g, "onset_mu": rs.onset_mu,
            "alpha_rigid": rs.alpha_rigid, "rigid": table_row(rs.rigid),
            "rows": {f"{mu:.2f}": table_row(r) for mu, r in rs.runs.items()},
        }

    cols = ("disp_m", "acc_m_s2", "force_N", "sliding_mm")
    suite_rows = {}
    for mu in pv.MU_VALUES:
        rows = [table_row(rs.runs[mu]) for rs in st.suite]
        suite_rows[f"{mu:.2f}"] = {c: _mean_sd([r[c] for r in rows]) for c in cols}
        suite_rows[f"{mu:.2f}"]["n_sliding"] = sum(r["slid"] for r in rows)
    rec = st.main.record
    return {
        "g_m_s2": st.main.g,
        "rack": st.spec.source, "title": st.spec.title,
        "pallet_mass_kg": st.spec.pallet_mass_total,
        "modal": {"t1_s": st.t1, "participation": float(st.modal.mass_participation[0]),
                  "paper_t1_s": pv.T1_S, "paper_participation": pv.PARTICIPATION},
        "damping": {"kind": st.spec.damping.kind, "ratio_mode1": st.damping_ratio},
        "record": {"seed": SEED, **RECORD, "pga_m_s2": rec.pga,
                   "target_pga_m_s2": st.target.pga, "name": rec.name,
                   "max_spectral_misfit": rec.meta.get("max_misfit") if rec.meta else None,
                   "se_t1_5pct_m_s2": float(response_spectrum(
                       rec.accel, rec.dt, np.array([st.t1]), 0.05).psa[0]),
                   "target_se_t1_m_s2": float(st.target.psa(st.t1)[0])},
        "main": run_set(st.main),
        "sensitivity": run_set(st.sensitivity) if st.sensitivity else None,
        "onset_bisection": st.onset_bisection,
        "suite": {"n_records": len(st.suite), "seeds": [SEED + i for i in range(len(st.suite))],
                  "ec8_check": st.suite_check, "rows": suite_rows,
                  "onsets": [rs.onset_mu for rs in st.suite],
                  "se_t1_over_g": [rs.se_t1 / rs.g for rs in st.suite]},
        "seconds": st.seconds,
    }
