"""``[hysteresis.*]`` tables: parsing, validation messages (field, value, what is allowed),
packing and the OpenSees material arguments of :class:`seisrack.model.hinge_law.HingeLaw`."""

from __future__ import annotations

import math

import numpy as np
import pytest

from seisrack.dynamics import _hysteresis as H
from seisrack.errors import InputError
from seisrack.export.opensees_materials import opensees_uniaxial
from seisrack.model.hinge_law import HingeLaw, parse_hinge_law

F = "hysteresis.beam_to_upright"
K = 1.0e5  # N·m/rad

PINCH = {
    "law": "pinching",
    "envelope_rotation": [0.01, 0.03, 0.06, 0.10],
    "envelope_moment": [1.0e3, 1.8e3, 2.2e3, 2.3e3],
    "reload_rotation_ratio": 0.3,
    "reload_moment_ratio": 0.2,
    "unload_moment_ratio": 0.05,
}
BILIN = {"law": "bilinear", "yield_moment": 4.0e3, "hardening_ratio": 0.02}


def _err(d, k=K, field=F) -> InputError:
    with pytest.raises(InputError) as info:
        parse_hinge_law(d, field, k)
    return info.value


def _names(e: InputError, key: str, value) -> None:
    msg = str(e)
    assert e.field == f"{F}.{key}", msg
    assert repr(value) in msg or str(value) in msg, msg
    assert "allowed" in msg and e.allowed


# ---------------------------------------------------------------------------- valid input

def test_valid_laws():
    el = parse_hinge_law({"law": "elastic"}, F, K)
    assert el.kind == "elastic" and el.stiffness == K and math.isinf(el.yield_rotation)
    epp = parse_hinge_law({"law": "elastic-plastic", "yield_moment": 2e3}, F, K)
    assert epp.yield_rotation == pytest.approx(0.02)
    bl = parse_hinge_law(BILIN, F, K)
    assert bl.hardening_ratio == 0.02 and bl.yield_moment == 4e3
    pin = parse_hinge_law(PINCH, F, K)
    assert pin.negative_envelope_rotation == pin.envelope_rotation
    assert pin.negative_envelope_moment == pin.envelope_moment
    assert pin.negative_reload_rotation_ratio == 0.3
    assert pin.negative_unload_moment_ratio == 0.05
    assert pin.yield_rotation == 0.01
    for law in (el, epp, bl, pin):
        assert law.describe()
    # integers are numbers; M1/θ1 within 0.1 % of the connection stiffness is accepted
    d = dict(PINCH, envelope_moment=[1000, 1800, 2200, 2300])
    assert parse_hinge_law(d, F, K * 1.0009).stiffness == K * 1.0009


def test_pinching_without_connection_stiffness_uses_initial_slope():
    assert parse_hinge_law(PINCH, F, None).stiffness == pytest.approx(1e5)
    assert parse_hinge_law(dict(BILIN, stiffness=3e4), F, None).stiffness == 3e4


def test_asymmetric_pinching_and_negative_ratios():
    d = dict(PINCH, negative_envelope_rotation=[0.012, 0.035, 0.07, 0.12],
             negative_envelope_moment=[1.2e3, 1.9e3, 2.1e3, 1.9e3],
             negative_reload_rotation_ratio=0.45, negative_reload_moment_ratio=0.1,
             negative_unload_moment_ratio=0.0)
    law = parse_hinge_law(d, F, K)
    code, par = law.pack()
    assert code == H.HYST_PINCHING and par.shape == (H.HYST_NPAR,)
    np.testing.assert_array_equal(par[H.HYST_P_NEG_U + 1:H.HYST_P_NEG_U + 5],
                                  [-0.012, -0.035, -0.07, -0.12])
    np.testing.assert_array_equal(par[H.HYST_P_NEG_F + 1:H.HYST_P_NEG_F + 5],
                                  [-1.2e3, -1.9e3, -2.1e3, -1.9e3])
    np.testing.assert_array_equal(par[H.HYST_P_PINCH:H.HYST_P_PINCH + 6],
                                  [0.3, 0.2, 0.05, 0.45, 0.1, 0.0])


def test_pack_layout():
    code, par = parse_hinge_law(BILIN, F, K).pack()
    assert code == H.HYST_BILINEAR and (par[0], par[1], par[2]) == (K, 4e3, 0.02)
    code, par = parse_hinge_law({"law": "elastic-plastic", "yield_moment": 2e3}, F, K).pack()
    assert code == H.HYST_EPP and (par[0], par[1], par[2]) == (K, 2e3, 0.0)
    code, par = parse_hinge_law({"law": "elastic"}, F, K).pack()
    assert code == H.HYST_ELASTIC and par[0] == K and not par[1:].any()


def test_opensees_arguments():
    assert opensees_uniaxial(parse_hinge_law({"law": "elastic"}, F, K), 7) == ["Elastic", 7, K]
    assert opensees_uniaxial(parse_hinge_law({"law": "elastic-plastic", "yield_moment": 2e3},
                                             F, K), 3) == ["ElasticPP", 3, K, 0.02]
    assert opensees_uniaxial(parse_hinge_law(BILIN, F, K), 2) == ["Steel01", 2, 4e3, K, 0.02]
    args = opensees_uniaxial(parse_hinge_law(PINCH, F, K), 5)
    assert args[:2] == ["Pinching4", 5] and len(args) == 2 + 16 + 6 + 15 + 2
    assert args[2:10] == [1e3, 0.01, 1.8e3, 0.03, 2.2e3, 0.06, 2.3e3, 0.1]
    assert args[10:18] == [-1e3, -0.01, -1.8e3, -0.03, -2.2e3, -0.06, -2.3e3, -0.1]
    assert args[18:24] == [0.3, 0.2, 0.05, 0.3, 0.2, 0.05]
    assert args[24:39] == [0.0] * 15 and args[-1] == "energy"


# ---------------------------------------------------------------------------- bad input

def test_unknown_law():
    e = _err({"law": "takeda"})
    _names(e, "law", "takeda")
    assert "elastic-plastic" in str(e) and "pinching" in str(e)


def test_missing_law():
    e = _err({"yield_moment": 1.0})
    assert e.field == f"{F}.law"


@pytest.mark.parametrize("d,key", [
    ({"law": "elastic", "yield_moment": 1e3}, "yield_moment"),
    (dict(BILIN, yeld_moment=1.0), "yeld_moment"),
    (dict(PINCH, hardening_ratio=0.1), "hardening_ratio"),
])
def test_unknown_keys_list_the_allowed_ones(d, key):
    e = _err(d)
    _names(e, key, d[key])
    assert "law" in e.allowed
    assert ("envelope_rotation" in e.allowed) == (d["law"] == "pinching")


@pytest.mark.parametrize("my", [0.0, -5.0, 0])
def test_yield_moment_not_positive(my):
    _names(_err(dict(BILIN, yield_moment=my)), "yield_moment", my)
    _names(_err({"law": "elastic-plastic", "yield_moment": my}), "yield_moment", my)


def test_yield_moment_missing():
    e = _err({"law": "elastic-plastic"})
    assert e.field == f"{F}.yield_moment" and "required" in str(e)


@pytest.mark.parametrize("b", [-0.01, 1.0, 1.5])
def test_hardening_ratio_out_of_range(b):
    e = _err(dict(BILIN, hardening_ratio=b))
    _names(e, "hardening_ratio", b)
    assert "0 <= b < 1" in str(e) and "post-yield stiffness" in str(e)


@pytest.mark.parametrize("key", [
    "reload_rotation_ratio", "reload_moment_ratio", "unload_moment_ratio",
    "negative_reload_rotation_ratio", "negative_reload_moment_ratio",
    "negative_unload_moment_ratio"])
@pytest.mark.parametrize("value", [-0.1, 1.2])
def test_pinching_factor_outside_unit_interval(key, value):
    e = _err(dict(PINCH, **{key: value}))
    _names(e, key, value)
    assert "[0, 1]" in str(e)


@pytest.mark.parametrize("rot", [[0.01, 0.03, 0.03, 0.1], [0.01, 0.05, 0.03, 0.1],
                                 [0.03, 0.01, 0.06, 0.1]])
def test_envelope_rotations_not_increasing(rot):
    d = dict(PINCH, envelope_rotation=rot,
             envelope_moment=[rot[0] * K, 1.8e3, 2.2e3, 2.3e3])
    e = _err(d)
    _names(e, "envelope_rotation", rot)
    assert "strictly increasing" in str(e)


@pytest.mark.parametrize("i,value", [(0, 0.0), (2, -0.06)])
def test_envelope_rotation_not_positive(i, value):
    rot = [0.01, 0.03, 0.06, 0.10]
    rot[i] = value
    e = _err(dict(PINCH, envelope_rotation=rot))
    assert e.field == f"{F}.envelope_rotation[{i}]" and str(value) in str(e)


@pytest.mark.parametrize("i,value", [(1, 0.0), (3, -2.3e3)])
def test_envelope_moment_not_positive(i, value):
    mom = [1.0e3, 1.8e3, 2.2e3, 2.3e3]
    mom[i] = value
    e = _err(dict(PINCH, envelope_moment=mom))
    assert e.field == f"{F}.envelope_moment[{i}]" and str(value) in str(e)


def test_negative_envelope_checked_too():
    d = dict(PINCH, negative_envelope_rotation=[0.01, 0.03, 0.02, 0.1],
             negative_envelope_moment=[1e3, 1.8e3, 2.2e3, 2.3e3])
    _names(_err(d), "negative_envelope_rotation", [0.01, 0.03, 0.02, 0.1])
    d = dict(PINCH, negative_envelope_rotation=[0.01, 0.03, 0.06, 0.1])
    e = _err(d)
    assert e.field == f"{F}.negative_envelope_moment" and "neither" in str(e)


def test_envelope_wrong_length():
    e = _err(dict(PINCH, envelope_rotation=[0.01, 0.03, 0.06]))
    _names(e, "envelope_rotation", [0.01, 0.03, 0.06])
    assert "4 numbers" in str(e)


def test_pinching_initial_slope_must_match_connection():
    e = _err(PINCH, k=2.0e5)
    _names(e, "envelope_moment", [1.0e3, 1.8e3, 2.2e3, 2.3e3])
    msg = str(e)
    assert "100000" in msg and "200000" in msg and "0.1%" in msg
    d = dict(PINCH, negative_envelope_rotation=[0.01, 0.03, 0.06, 0.1],
             negative_envelope_moment=[1.1e3, 1.8e3, 2.2e3, 2.3e3])
    e = _err(d)
    assert e.field == f"{F}.negative_envelope_moment" and "negative envelope" in str(e)


def test_stiffness_key_must_match_connection():
    e = _err(dict(BILIN, stiffness=2e5))
    _names(e, "stiffness", 2e5)
    assert "100000" in str(e)


def test_no_stiffness_anywhere():
    e = _err(BILIN, k=None)
    assert e.field == f"{F}.stiffness"


@pytest.mark.parametrize("k,word", [(math.inf, "rigid"), (0.0, "pinned")])
@pytest.mark.parametrize("d", [BILIN, PINCH, {"law": "elastic"}])
def test_rigid_or_pinned_connection_with_a_law(k, word, d):
    e = _err(d, k=k)
    _names(e, "law", d["law"])
    assert word in str(e) and "[connections]" in str(e)


@pytest.mark.parametrize("key,value", [("yield_moment", math.nan), ("yield_moment", math.inf),
                                       ("hardening_ratio", math.nan)])
def test_non_finite_numbers(key, value):
    e = _err(dict(BILIN, **{key: value}))
    assert e.field == f"{F}.{key}" and "finite" in str(e) and str(value) in str(e)


def test_non_finite_in_arrays_and_ratios():
    e = _err(dict(PINCH, envelope_moment=[1e3, math.inf, 2.2e3, 2.3e3]))
    assert e.field == f"{F}.envelope_moment[1]" and "finite" in str(e)
    e = _err(dict(PINCH, unload_moment_ratio=math.nan))
    assert e.field == f"{F}.unload_moment_ratio" and "finite" in str(e)


@pytest.mark.parametrize("key,value", [("yield_moment", "4 kNm"), ("yield_moment", True),
                                       ("hardening_ratio", [0.1])])
def test_wrong_types(key, value):
    e = _err(dict(BILIN, **{key: value}))
    assert e.field == f"{F}.{key}" and "number" in str(e)


def test_field_prefix_is_used():
    e = _err({"law": "elastic-plastic", "yield_moment": -1.0}, field="hysteresis.base")
    assert e.field == "hysteresis.base.yield_moment"


def test_direct_construction_is_validated():
    with pytest.raises(InputError, match="hardening_ratio"):
        HingeLaw("bilinear", K, yield_moment=1e3, hardening_ratio=1.0)
    with pytest.raises(InputError, match="stiffness"):
        HingeLaw("elastic", math.inf)
    with pytest.raises(InputError, match="law"):
        HingeLaw("plastic", K)  # type: ignore[arg-type]
