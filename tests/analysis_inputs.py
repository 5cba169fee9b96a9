"""Shared inputs for the rack time-history tests (not a test module).

The record is the strong-motion part (first 5 s, PGA 0.313 g at 2.1 s) of the bundled El Centro
1940 N-S accelerogram (real, public domain; seisrack/data/records/PROVENANCE.md), so the tests
do not depend on the synthesiser and stay fast. With it the paper rack (examples/paper_rack.toml,
paper §IV Table 1; T1 = 0.65 s) reaches alpha = peak beam acceleration / g ~ 0.7, so pallets with
mu = 0.3–0.6 slide, as in the paper's Fig. 16.
"""

from __future__ import annotations

from functools import cache

from rack_inputs import PAPER_RACK, paper_dict
from seisrack.model import compile_rack, load_rack, rack_from_dict, with_friction
from seisrack.motion import Record, load_builtin_record, write_record_csv

#: the horizontal record of the tests: El Centro 1940 N-S, 0-5 s, dt = 10 ms
RECORD_NAME = "elcentro_1940_ns"


@cache
def short_record(duration: float = 5.0, scale: float = 1.0) -> Record:
    """The first ``duration`` seconds of El Centro 1940 N-S, times ``scale`` [m/s²]."""
    full = load_builtin_record(RECORD_NAME)
    n = int(round(duration / full.dt)) + 1
    return Record(scale * full.accel[:n], full.dt, name=f"{RECORD_NAME}_0-{duration:g}s",
                  provenance=full.provenance)


@cache
def paper_model(mu: float, mu_dynamic: float | None = None):  # noqa: ANN201
    """The paper rack with every pallet at (mu, mu_dynamic)."""
    return compile_rack(with_friction(load_rack(PAPER_RACK), mu, mu_dynamic))


def model_from(d: dict):  # noqa: ANN201
    return compile_rack(rack_from_dict(d))


def paper_with(mu: float, **changes) -> dict:  # noqa: ANN003
    """paper_dict() with every pallet at mu and top-level tables replaced by ``changes``."""
    d = paper_dict()
    for p in d["pallets"]:
        p["mu_static"] = p["mu_dynamic"] = mu
    d.update(changes)
    return d


def record_csv(path, record: Record | None = None):  # noqa: ANN001, ANN201
    return write_record_csv(record or short_record(), path)
