"""Base shear from the support reactions equals the global horizontal equilibrium of the rack.

Pre-multiplying the structure's equation of motion (docs/theory/stick_slip_engine.md §1)
``M ü + C u̇ + K u = -M r a_g - Σ_j e_dj λ_j`` by the horizontal influence vector r (a rigid
horizontal translation, which strains nothing: the support reactions of ``K u`` sum to
``-rᵀ K u``) and with Rayleigh damping ``C = a0 M + a1 K`` gives

    base shear = rᵀ K (u + a1 u̇) = -( rᵀ M (ü + r a_g) + a0 rᵀ M u̇ + Σ_j λ_j ),

i.e. the shear the uprights carry into the supports (elastic + stiffness-proportional damping
forces, what ``RackResponse.base_shear`` recovers from ``base_reactions``) balances the inertia of
the frame, the mass-proportional damping force (which acts on the masses, not through the
members) and the friction forces of the pallets (Chopra, *Dynamics of Structures*, §9.4 / §13.1:
base shear as the sum of the equivalent static forces). A sign or damping term missed in the
recovery shows up as an O(1) relative error.
"""

from __future__ import annotations

import numpy as np
import pytest

from analysis_inputs import model_from, paper_with, short_record
from seisrack.analysis import run_rack


@pytest.mark.parametrize(("mu", "damping"), [
    (0.4, {"kind": "rayleigh", "pairs": [[0.65, 0.05], [0.05, 0.05]]}),
    (0.4, {"kind": "stiffness", "ratio": 0.02, "period": "first"}),  # the paper rack's
    (50.0, {"kind": "rayleigh", "pairs": [[0.65, 0.02], [0.1, 0.02]]}),
])
def test_base_shear_equals_global_equilibrium(mu, damping):
    model = model_from(paper_with(mu, damping=damping))
    resp = run_rack(model, short_record(), rigid_companion=False, basis="full")
    h = resp.history
    a0 = float(model.damping_coefficients[0])
    mr = model.M @ model.r_x
    inertia = (h.a + np.outer(resp.ground_accel, model.r_x)) @ mr
    equilibrium = -(inertia + a0 * (h.v @ mr) + h.friction.sum(axis=1))
    scale = np.max(np.abs(resp.base_shear))
    assert scale > 1e3  # N: not vacuous
    err = np.max(np.abs(resp.base_shear - equilibrium)) / scale
    assert err < 1e-6, err
    # with 1600 kg of pallets on ~40 kg of steel the base shear is essentially the contact
    # force (paper §IV.B: "this contact force may be considered as the total inertial force")
    ratio = np.max(np.abs(resp.base_shear)) / resp.peaks()["total_friction_force_N"]
    assert 0.9 < ratio < 1.3
