"""EN 1998-1:2004 elastic spectra against the standard's values.

Source: EN 1998-1:2004, §3.2.2.2 Eqs. (3.2)–(3.5) and Tables 3.2 (Type 1) and 3.3 (Type 2) for the
horizontal spectrum; Eq. (3.6) for η; §3.2.1(3) a_g = γ_I·a_gR; §3.2.2.3 Eqs. (3.8)–(3.11) and
Table 3.4 for the vertical spectrum. The table values are typed here from the standard, not from
the module under test.
"""

import numpy as np
import pytest

from seisrack.errors import InputError
from seisrack.motion import G, ec8_spectrum

# (type, ground): S, TB, TC, TD — EN 1998-1 Table 3.2 / Table 3.3
TABLE = {
    (1, "A"): (1.00, 0.15, 0.4, 2.0),
    (1, "B"): (1.20, 0.15, 0.5, 2.0),
    (1, "C"): (1.15, 0.20, 0.6, 2.0),
    (1, "D"): (1.35, 0.20, 0.8, 2.0),
    (1, "E"): (1.40, 0.15, 0.5, 2.0),
    (2, "A"): (1.00, 0.05, 0.25, 1.2),
    (2, "B"): (1.35, 0.05, 0.25, 1.2),
    (2, "C"): (1.50, 0.10, 0.25, 1.2),
    (2, "D"): (1.80, 0.10, 0.30, 1.2),
    (2, "E"): (1.60, 0.05, 0.25, 1.2),
}


@pytest.mark.parametrize(("kind", "ground"), sorted(TABLE))
def test_horizontal_spectrum_table_values(kind: int, ground: str) -> None:
    S, TB, TC, TD = TABLE[(kind, ground)]
    ag = 0.25
    sp = ec8_spectrum(kind, ground, ag)
    a = ag * G
    T = np.array([0.0, TB / 2, TB, (TB + TC) / 2, TC, (TC + TD) / 2, TD, 3.0, 4.0])
    expected = [
        a * S,  # T = 0: a_g S
        a * S * (1 + 0.5 * (2.5 - 1)),  # Eq. 3.2 at TB/2, η = 1
        a * S * 2.5,
        a * S * 2.5,  # plateau, Eq. 3.3
        a * S * 2.5,
        a * S * 2.5 * TC / ((TC + TD) / 2),  # Eq. 3.4
        a * S * 2.5 * TC / TD,
        a * S * 2.5 * TC * TD / 9.0,  # Eq. 3.5
        a * S * 2.5 * TC * TD / 16.0,
    ]
    np.testing.assert_allclose(sp.psa(T), expected, rtol=1e-12)
    assert sp.pga == pytest.approx(a * S)


def test_damping_correction_and_importance() -> None:
    # Eq. 3.6: ξ = 10 % -> η = sqrt(10/15); ξ = 30 % -> 0.5345 -> floor 0.55
    sp10 = ec8_spectrum(1, "C", 0.3, damping=0.10, importance=1.2)
    assert sp10.eta == pytest.approx(np.sqrt(10 / 15))
    assert sp10.psa(0.4)[0] == pytest.approx(0.3 * 1.2 * G * 1.15 * 2.5 * np.sqrt(10 / 15))
    assert ec8_spectrum(1, "C", 0.3, damping=0.30).eta == 0.55
    assert ec8_spectrum(1, "C", 0.3, damping=0.05).eta == pytest.approx(1.0)


@pytest.mark.parametrize(("kind", "ratio"), [(1, 0.90), (2, 0.45)])
def test_vertical_spectrum_table_3_4(kind: int, ratio: float) -> None:
    sp = ec8_spectrum(kind, "C", 0.3, direction="vertical")
    avg = ratio * 0.3 * G
    T = np.array([0.0, 0.025, 0.1, 0.5, 2.0])
    expected = [avg, avg * (1 + 0.5 * 2.0), avg * 3.0, avg * 3.0 * 0.15 / 0.5,
                avg * 3.0 * 0.15 * 1.0 / 4.0]
    np.testing.assert_allclose(sp.psa(T), expected, rtol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"type": 3}, "type"), ({"ground": "S1"}, "ground"), ({"ag": -0.1}, "ag"),
     ({"damping": 1.5}, "damping"), ({"direction": "up"}, "direction")],
)
def test_bad_input_names_the_field(kwargs: dict, field: str) -> None:
    args = {"type": 1, "ground": "C", "ag": 0.3} | kwargs
    t, g, a = args.pop("type"), args.pop("ground"), args.pop("ag")
    with pytest.raises(InputError) as exc:
        ec8_spectrum(t, g, a, **args)
    assert exc.value.field == field
