"""Validation examples 2 and 3 (paper §III.B, definitions of issue #3) through run_validation.

Uses the reference solver only (engine=None), so it is independent of the production engine; the
engine comparison belongs to the engine's own tests.
"""

from __future__ import annotations

from seisrack.paper.examples import example2, example3, run_validation


def test_example_data_shapes():
    ex2, ex3 = example2(), example3()
    assert ex2.M.shape == (2, 2) and ex2.slider_dof == 1 and ex2.mu_values == (1.0, 0.5, 0.3)
    assert ex3.M.shape == (1, 1) and ex3.mu_values == (10.0, 0.5, 0.3, 0.1)
    assert ex2.force(1e-3).shape == (10001, 2) and ex2.ground_accel(1e-3) is None
    assert ex3.ground_accel(1e-3).shape == (10001,) and ex3.force(1e-3) is None


def test_run_validation_reference_entries():
    res = run_validation(dt=2e-3, engine=None, which=("example3",))
    assert list(res["example3"]) == ["10.0", "0.5", "0.3", "0.1"]
    peaks = [res["example3"][k]["max_abs_displacement_m"][0] for k in ("10.0", "0.5", "0.3", "0.1")]
    # paper Fig. 12b: sliding of M2 limits the displacement of M1, more so for smaller mu
    assert peaks == sorted(peaks, reverse=True)
    e = res["example3"]["0.5"]
    assert e["sliding_phases"] > 0 and e["relative_difference"]["max_abs_sliding"] == 0.0
    assert set(e) >= {"max_abs_displacement_m", "max_abs_sliding_m", "sliding_phases",
                      "final_sliding_m", "reference", "relative_difference"}
