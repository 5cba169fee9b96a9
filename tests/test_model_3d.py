"""3D rack model: equivalence with the 2D model down-aisle, and bad input.

Down-aisle equivalence. In a 3D rack whose front and rear frames are identical, a down-aisle
mode moves both frames alike in their own planes; the pin-ended bracing bars lie in the
cross-aisle planes and have no stiffness along x, so they enter only through their mass. The 2D
model of the same rack is one plane frame carrying both frames: every member's A and I and
every connector and base stiffness doubled (as ``examples/warehouse_rack.toml`` explains), the
same pallets. The two must give the same down-aisle periods up to the bracing's mass, kept
small here (50 mm² bars, 18 kg for Z, about 1 % of the moving mass in x, stiff enough that
the first cross-aisle period is below half the first down-aisle one). Measured: within 0.16 %
(Z), 0.23 % (X).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.fe.modal import modal_analysis
from seisrack.model import compile_rack, rack_from_dict
from seisrack.model.frame_model import FrameModel

TOL = 0.005

UPRIGHT = {"A": 488.9e-6, "I": 41.3e-8, "Iy": 25.0e-8, "J": 0.065e-8}
BEAM = {"A": 605.8e-6, "I": 93.8e-8, "Iy": 22.0e-8, "J": 46.0e-8}


def rack_3d(pattern="Z", **over) -> dict:
    pallets = [{"mass": 400.0, "bay": b, "level": lev, "position": x, "mu_static": 0.4,
                "mu_dynamic": 0.4} for lev in (1, 2) for b in (1, 2) for x in (0.45, 1.35)]
    d = {"material": {"E": 210e9, "density": 7850.0},
         "sections": {"upright": dict(UPRIGHT), "beam": dict(BEAM), "brace": {"A": 50e-6}},
         "geometry": {"bays": [1.8, 1.8], "levels": [1.5, 1.5], "beam_section": "beam",
                      "upright_section": "upright", "subdivisions": 4, "depth": 1.1},
         "connections": {"beam_to_upright": 160e3, "base": 160e3},
         "bracing": {"pattern": pattern, "panel": 0.5, "horizontal_section": "brace",
                     "diagonal_section": "brace"},
         "pallets": pallets}
    for k, v in over.items():
        d[k] = v
    return d


def equivalent_2d(d3: dict) -> dict:
    """The same rack as one plane frame standing for the front and the rear frame together."""
    d = copy.deepcopy(d3)
    del d["geometry"]["depth"], d["bracing"]
    d["sections"] = {n: {"A": 2 * s["A"], "I": 2 * s["I"]} for n, s in d["sections"].items()
                     if n != "brace"}
    d["connections"] = {k: 2 * v for k, v in d["connections"].items()}
    return d


def _down_aisle(periods, part, min_part=0.01):
    return np.asarray(periods)[np.asarray(part) > min_part]


@pytest.mark.parametrize("pattern", ["Z", "X"])
def test_down_aisle_periods_equal_the_2d_model(pattern):
    d3 = rack_3d(pattern)
    m3 = compile_rack(rack_from_dict(d3))
    m2 = compile_rack(rack_from_dict(equivalent_2d(d3)))
    assert type(m3) is type(m2) is FrameModel
    r3, r2 = modal_analysis(m3, 30), modal_analysis(m2, 12)
    t3 = r3.periods[np.array(r3.direction) == "down-aisle"]
    t2 = _down_aisle(r2.periods, r2.mass_participation)
    n = min(len(t2), len(t3))
    assert n >= 2
    err = np.abs(t3[:n] / t2[:n] - 1.0)
    print(pattern, t3[:n], t2[:n], err)
    assert np.all(err < TOL), err
    # the frames are much stiffer cross-aisle than down-aisle
    first_cross = r3.periods[list(r3.direction).index("cross-aisle")]
    assert first_cross < 0.5 * t3[0]


def test_participation_sums_and_classes():
    m = compile_rack(rack_from_dict(rack_3d()))
    r = modal_analysis(m, None)
    assert r.mass_participation.sum() == pytest.approx(1.0, rel=1e-8)
    assert r.mass_participation_z.sum() == pytest.approx(1.0, rel=1e-8)
    assert r.participation_theta.sum() == pytest.approx(1.0, rel=1e-8)
    assert r.direction[0] == "down-aisle"
    assert {"cross-aisle", "torsional"} <= set(r.direction[:12])


def test_pallet_mass_half_on_each_beam():
    m = compile_rack(rack_from_dict(rack_3d()))
    Mt, M = m.total_mass_sparse(), m.M_sparse
    assert m.r_x @ (Mt - M) @ m.r_x == pytest.approx(m.pallet_mass.sum())
    assert m.r_z @ (Mt - M) @ m.r_z == pytest.approx(m.pallet_mass.sum())
    front, rear = m.nodes[m.pallet_node[:, 0]], m.nodes[m.pallet_node[:, 1]]
    assert np.allclose(front[:, 2], 0.0) and np.allclose(rear[:, 2], 1.1)
    assert np.allclose(front[:, :2], rear[:, :2])


def test_without_depth_stays_2d():
    d = equivalent_2d(rack_3d())
    assert isinstance(compile_rack(rack_from_dict(d)), FrameModel)


def _bad(mutate) -> dict:
    d = rack_3d()
    mutate(d)
    return d


BAD = [
    ("mechanism", lambda d: (d["bracing"].update(pattern=[["F0", "R0"], ["F4", "R4"]]),
                             d["connections"].update(base_cross="pinned")), "bracing.pattern"),
    ("unknown pattern", lambda d: d["bracing"].update(pattern="W"), "bracing.pattern"),
    ("bad member", lambda d: d["bracing"].update(pattern=[["F0", "F1"]]), "bracing.pattern[0]"),
    ("member index", lambda d: d["bracing"].update(pattern=[["F0", "R9"]]),
     "bracing.pattern[0]"),
    ("panel above top", lambda d: d["bracing"].update(panel=[0.0, 4.0]), "bracing.panel"),
    # panel points 0.1 mm apart, or a 0.1 mm sliver under the top (3 m uprights), made nodes
    # that close that the stability check called the bracing a mechanism
    ("panel points too close", lambda d: d["bracing"].update(panel=[0.0, 1.5, 1.5001, 3.0]),
     "bracing.panel[2]"),
    ("panel sliver at the top", lambda d: d["bracing"].update(panel=0.7499), "bracing.panel"),
    ("missing section", lambda d: d["bracing"].pop("diagonal_section"),
     "bracing.diagonal_section"),
    ("missing bracing", lambda d: d.pop("bracing"), "bracing"),
    ("overhang >= depth", lambda d: d["pallets"][0].update(depth=1.2, overhang=1.2),
     "pallets[0].overhang"),
    ("pallet too deep", lambda d: d["pallets"][0].update(depth=1.3, overhang=0.05),
     "pallets[0].depth"),
    ("negative overhang", lambda d: d["pallets"][0].update(overhang=-0.01),
     "pallets[0].overhang"),
    ("missing Iy", lambda d: d["sections"]["upright"].pop("Iy"), "sections.upright.Iy"),
    ("missing J", lambda d: d["sections"]["beam"].pop("J"), "sections.beam.J"),
    ("missing I", lambda d: d["sections"]["beam"].pop("I"), "sections.beam.I"),
    ("I and Iz differ", lambda d: d["sections"]["beam"].update(Iz=1e-7), "sections.beam.Iz"),
    ("poisson", lambda d: d["material"].update(poisson=0.6), "material.poisson"),
    ("loading overhang", lambda d: (d.pop("pallets"), d.update(loading={
        "pallets_per_bay": 2, "mass": 400.0, "mu_static": 0.3, "mu_dynamic": 0.3,
        "depth": 1.2, "overhang": 0.01})), "loading.depth"),
    ("spine bays", lambda d: d["bracing"].update(spine=True, spine_section="brace",
                                                 spine_bays=[3]), "bracing.spine_bays"),
]


@pytest.mark.parametrize(("name", "mutate", "field"), BAD, ids=[b[0] for b in BAD])
def test_bad_input_names_the_field(name, mutate, field):
    with pytest.raises(InputError) as exc:
        compile_rack(rack_from_dict(_bad(mutate)))
    assert exc.value.field == field, str(exc.value)


@pytest.mark.parametrize("panel", [[0.0, 1.5, 1.55, 3.0], 0.73])
def test_panel_points_at_the_gap_bound_build(panel):
    """0.05 m between panel points, and a last panel of 0.08 m under the top, are accepted."""
    d = rack_3d()
    d["bracing"]["panel"] = panel
    assert compile_rack(rack_from_dict(d)).n_dof > 0


def test_2d_rack_refuses_3d_keys():
    d = equivalent_2d(rack_3d())
    d["bracing"] = {"pattern": "Z"}
    with pytest.raises(InputError, match="bracing"):
        rack_from_dict(d)
    d = equivalent_2d(rack_3d())
    d["pallets"][0]["depth"] = 1.2
    with pytest.raises(InputError) as exc:
        rack_from_dict(d)
    assert exc.value.field == "pallets[0].depth"


def test_one_model_type_whose_dimension_is_data():
    """A 2D and a 3D rack compile to the same FrameModel; the shapes carry the dimension."""
    m3 = compile_rack(rack_from_dict(rack_3d()))
    m2 = compile_rack(rack_from_dict(equivalent_2d(rack_3d())))
    assert (m2.ndm, m2.n_dir, m2.pallet_dofs.shape[1:], m2.mesh.ndf) == (2, 1, (1, 1), 3)
    assert (m3.ndm, m3.n_dir, m3.pallet_dofs.shape[1:], m3.mesh.ndf) == (3, 2, (2, 2), 6)
    assert m2.r_z is None and m3.r_z is not None
    assert m3.directions == ("down-aisle", "cross-aisle")
    assert len(m3.level_dofs) == 2 and len(m2.level_dofs) == 1
    # two upright columns per line in 3D (front and rear), one in 2D
    assert m3.n_column == 2 * m2.n_column


def test_a_feature_not_built_for_3d_is_refused_by_name():
    d = rack_3d()
    d["pallets"][0]["friction_rate"] = 5.0
    with pytest.raises(InputError, match="velocity-dependent friction") as exc:
        compile_rack(rack_from_dict(d))
    assert "3D racks" in str(exc.value) and exc.value.field == "pallets[0].friction_rate"


def test_nonlinear_connections_are_built_for_3d():
    d = rack_3d()
    d["hysteresis"] = {"beam_to_upright": {"law": "elastic-plastic", "yield_moment": 2500.0},
                       "base": {"law": "elastic-plastic", "yield_moment": 3000.0}}
    m = compile_rack(rack_from_dict(d))
    assert m.nonlinear_hinges
    # connectors in down-aisle bending (2 frames x 2 levels x 2 bays x 2 ends) and base
    # plates about both axes (2 x 3 uprights x 2)
    kinds = np.asarray(m.hinge_kind)
    assert (kinds == 0).sum() == 16 and (kinds == 1).sum() == 12
    # a cross-aisle base stiffness of its own has no law: refused, naming the key
    d["connections"]["base_cross"] = 80e3
    with pytest.raises(InputError) as exc:
        compile_rack(rack_from_dict(d))
    assert exc.value.field == "connections.base_cross"


def test_spine_and_loading_footprint():
    d = rack_3d()
    d["bracing"].update(spine=True, spine_section="brace", spine_bays=[1], spine_levels=[1])
    d.pop("pallets")
    d["loading"] = {"pallets_per_bay": 2, "width": 0.8, "mass": 400.0, "mu_static": 0.3,
                    "mu_dynamic": 0.3, "depth": 1.2, "overhang": 0.05}
    spec = rack_from_dict(d)
    assert all(p.depth == 1.2 and p.overhang == 0.05 for p in spec.pallets)
    m = compile_rack(spec)
    assert (m.truss_kind == 3).sum() == 1
    assert np.all(m.pallet_overhang == 0.05)
