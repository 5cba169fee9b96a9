"""Lateral stiffness of a semi-rigid single-bay portal vs the slope-deflection hand formula.

Source: the derivation in ``docs/theory/portal_stiffness.md`` (slope-deflection, e.g. Hibbeler,
*Structural Analysis*, ch. 10). The FE frame is compiled from a rack spec, so the test covers the
connection modelling of ``compile_rack``: beam-end rotational springs, base springs, and the
rigid and pinned limits.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rack_inputs import portal_dict
from seisrack.model import compile_rack, rack_from_dict

E, I_B, I_C, H, SPAN = 210e9, 93.8e-8, 41.3e-8, 2.0, 1.8


def hand_stiffness(k_j: float, k_b: float) -> float:
    c = E * I_C / H
    k_t = 0.0 if k_j == 0 else 1.0 / (1.0 / k_j + SPAN / (6 * E * I_B))
    if math.isinf(k_b):  # limit k_b -> inf of the general formula
        return 24 * c * (c + k_t) / (H**2 * (4 * c + k_t))
    return 24 * c * (c * (k_b + k_t) + k_b * k_t) / (H**2 * ((4 * c + k_b) * (4 * c + k_t)
                                                            - 4 * c**2))


def fe_stiffness(joint, base, area_factor=1e4, subdivisions=4) -> float:
    model = compile_rack(rack_from_dict(portal_dict(joint=joint, base=base,
                                                    area_factor=area_factor,
                                                    subdivisions=subdivisions)))
    P = np.zeros(model.n_dof)
    top = model.node_dofs[model.level_nodes[:, 0], 0]
    P[top[0]] = 1000.0
    u = np.linalg.solve(model.K, P)
    return 1000.0 / u[top].mean()


CASES = [(160e3, 160e3), ("rigid", 160e3), (160e3, "rigid"), ("rigid", "rigid"),
         ("pinned", "rigid"), ("rigid", "pinned"), (50e3, 400e3)]


def _k(v) -> float:
    return {"rigid": math.inf, "pinned": 0.0}.get(v, v) if isinstance(v, str) else float(v)


@pytest.mark.parametrize(("joint", "base"), CASES, ids=[f"{j}-{b}" for j, b in CASES])
def test_portal_lateral_stiffness_matches_hand_formula(joint, base):
    assert fe_stiffness(joint, base) == pytest.approx(hand_stiffness(_k(joint), _k(base)),
                                                      rel=1e-6)


def test_independent_of_subdivisions():
    assert fe_stiffness(160e3, 160e3, subdivisions=1) == pytest.approx(
        fe_stiffness(160e3, 160e3, subdivisions=7), rel=1e-7)


def test_axial_flexibility_is_a_small_softening():
    k_real = fe_stiffness(160e3, 160e3, area_factor=1.0)
    k_hand = hand_stiffness(160e3, 160e3)
    assert 0.99 * k_hand < k_real < k_hand

