"""Validation of rack input at the boundary: one test per kind of bad input (issue #2).

Each case changes one field of the paper rack and checks that an InputError names the field
path, the value received and what is allowed.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from rack_inputs import BAD_CASES, PAPER_RACK, bad_dict, paper_dict, portal_dict
from seisrack.errors import FileFormatError, InputError
from seisrack.model import compile_rack, load_rack, rack_from_dict, with_friction


@pytest.mark.parametrize(("path", "value", "field"), [c[1:] for c in BAD_CASES],
                         ids=[c[0] for c in BAD_CASES])
def test_bad_input_names_field(path, value, field):
    with pytest.raises(InputError) as info:
        rack_from_dict(bad_dict(path, value), source="rack.toml")
    err = info.value
    assert field in err.field
    msg = str(err)
    assert field in msg and "allowed" in msg and "rack.toml" in msg
    assert "\n" not in msg


def test_paper_rack_is_valid():
    spec = load_rack(PAPER_RACK)
    assert spec.geometry.bays == (1.8, 1.8)
    assert spec.geometry.levels == (2.0,)
    assert len(spec.pallets) == 4
    assert spec.connections.base == 160e3
    assert spec.g == 9.81
    assert spec.sections["beam"].I == pytest.approx(93.8e-8)


def test_malformed_toml_reports_line(tmp_path: Path):
    p = tmp_path / "bad.toml"
    p.write_text('title = "x"\n[material]\nE = 210e9\ndensity = = 7850\n')
    with pytest.raises(FileFormatError) as info:
        load_rack(p)
    assert info.value.line == 4
    assert "line 4" in str(info.value) and "malformed TOML" in str(info.value)


def test_dynamic_above_static_message_names_limit():
    with pytest.raises(InputError, match=r"mu_dynamic.*0\.7.*<= .*mu_static"):
        rack_from_dict(bad_dict(("pallets", 0, "mu_dynamic"), 0.7))


def test_pallet_outside_bay_message_gives_range():
    with pytest.raises(InputError, match=r"\[0\.4, 1\.4\]"):
        rack_from_dict(bad_dict(("pallets", 0, "position"), 1.6))


def test_pallet_wider_than_bay():
    d = bad_dict(("pallets", 0, "width"), 2.0)
    with pytest.raises(InputError, match="no wider than its bay"):
        rack_from_dict(d)


def test_level_that_does_not_exist_message():
    with pytest.raises(InputError, match=r"from 1 to 1 .*1 beam level"):
        rack_from_dict(bad_dict(("pallets", 0, "level"), 3))


def test_section_list_length_checked():
    d = bad_dict(("geometry", "upright_section"), ["upright", "upright"])
    with pytest.raises(InputError, match="geometry.upright_section"):
        rack_from_dict(d)


def test_rigid_and_pinned_words():
    spec = rack_from_dict(portal_dict(joint="rigid", base="pinned"))
    assert math.isinf(spec.connections.beam_to_upright)
    assert spec.connections.base == 0.0


def test_pinned_everywhere_is_a_mechanism():
    spec = rack_from_dict(portal_dict(joint="pinned", base="pinned"))
    with pytest.raises(InputError, match="mechanism"):
        compile_rack(spec)


def test_rayleigh_pairs_validated():
    d = paper_dict()
    d["damping"] = {"kind": "rayleigh", "pairs": [[0.5, 0.02]]}
    with pytest.raises(InputError, match="damping.pairs"):
        rack_from_dict(d)
    d["damping"] = {"kind": "rayleigh", "pairs": [[0.5, 0.02], [0.1, -0.02]]}
    with pytest.raises(InputError, match=r"damping.pairs\[1\]\[1\]"):
        rack_from_dict(d)


def test_optional_keys_default():
    d = paper_dict()
    del d["g"], d["damping"], d["geometry"]["subdivisions"]
    spec = rack_from_dict(d)
    assert spec.g == 9.81 and spec.damping.kind == "none" and spec.geometry.subdivisions == 4
    assert spec.pallets[0].width == 0.8 and spec.pallets[0].sliding_limit is None


def test_with_friction_overrides_and_validates():
    spec = load_rack(PAPER_RACK)
    s2 = with_friction(spec, 0.3, 0.25)
    assert all(p.mu_static == 0.3 and p.mu_dynamic == 0.25 for p in s2.pallets)
    assert all(p.mu_static == 0.6 for p in spec.pallets)  # original untouched (frozen)
    assert with_friction(spec, 0.8).pallets[0].mu_dynamic == 0.8
    with pytest.raises(InputError, match="mu_dynamic"):
        with_friction(spec, 0.3, 0.4)
    with pytest.raises(InputError, match="mu_static"):
        with_friction(spec, -0.1)
