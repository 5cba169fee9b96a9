"""Risk per year (seisrack.studies.risk), issue 24 item 3.

References:
- closed form for a lognormal fragility (median θ, dispersion β) on a power-law hazard
  H(x) = k0·x^(−k): λ = k0·θ^(−k)·exp(k²β²/2) — C. A. Cornell, F. Jalayer, R. O. Hamburger,
  D. A. Foutch (2002), "Probabilistic basis for 2000 SAC FEMA steel moment frame guidelines",
  J. Struct. Eng. 128(4), Eq 10; F. Jalayer (2003), PhD thesis, Stanford;
- closed form for a hazard curved in log-log, H = k0·exp(−k1 ln x − k2 ln² x) (the
  second-order fit of D. Vamvatsikos (2013), Earthquake Engng Struct. Dyn. 42(8)):
  λ = k0·√p·exp(p(μ − k1β²)²/(2β²) − μ²/(2β²)), p = 1/(1 + 2 k2 β²), μ = ln θ
  (derived in docs/theory/hazard_integration.md; it reduces to Cornell's for k2 = 0);
- an independent brute-force quadrature (scipy.integrate.quad of H·f).
Convergence in the number of points of a tabulated curve (log-log interpolation): second order
in the spacing, measured here (slope of log error on log spacing 1.99-2.00).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, stats

from seisrack.errors import InputError
from seisrack.motion import G
from seisrack.studies.risk import (
    FEMA_P58_RACK,
    annual_rate,
    hazard_curve,
    load_hazard_curve,
    power_law_rate,
)


def test_power_law_closed_form() -> None:
    k0, k, theta, beta = 2e-4, 2.7, 3.5, 0.45
    for n in (2, 7, 40):
        x = np.geomspace(0.02, 40.0, n)
        got = annual_rate(hazard_curve(x, k0 * x ** (-k)), theta, beta)
        assert got["annual_rate"] == pytest.approx(power_law_rate(k0, k, theta, beta),
                                                   rel=1e-12)
    lam = power_law_rate(k0, k, theta, beta)
    assert lam == pytest.approx(k0 * theta ** (-k) * math.exp(k * k * beta * beta / 2))
    assert got["p50"] == pytest.approx(1 - math.exp(-50 * lam), rel=1e-12)
    # independent quadrature of H(x) f(x) dx, in u = ln x over ±12 β
    mu = math.log(theta)
    quad, _ = integrate.quad(lambda u: k0 * math.exp(-k * u) * stats.norm.pdf(u, mu, beta),
                             mu - 12 * beta, mu + 12 * beta, limit=200)
    assert quad == pytest.approx(lam, rel=1e-8)


def _curved(k0: float, k1: float, k2: float, theta: float, beta: float) -> float:
    mu = math.log(theta)
    p = 1.0 / (1.0 + 2.0 * k2 * beta**2)
    return k0 * math.sqrt(p) * math.exp(p * (mu - k1 * beta**2) ** 2 / (2 * beta**2)
                                        - mu**2 / (2 * beta**2))


def test_tabulated_curve_converges_at_second_order() -> None:
    k0, k1, k2, theta, beta = 1e-3, 2.0, 0.2, 4.0, 0.4
    exact = _curved(k0, k1, k2, theta, beta)
    # the closed form against brute-force quadrature (it reduces to Cornell's for k2 = 0)
    def haz(t: float) -> float:
        return k0 * math.exp(-k1 * math.log(t) - k2 * math.log(t) ** 2)

    mu = math.log(theta)
    quad, _ = integrate.quad(lambda u: haz(math.exp(u)) * stats.norm.pdf(u, mu, beta),
                             mu - 12 * beta, mu + 12 * beta, limit=200)
    assert quad == pytest.approx(exact, rel=1e-8)
    assert _curved(k0, k1, 0.0, theta, beta) == pytest.approx(power_law_rate(k0, k1, theta,
                                                                             beta))
    errs, hs = [], []
    for n in (9, 17, 33, 65, 129):
        x = np.geomspace(0.05, 150.0, n)
        got = annual_rate(hazard_curve(x, [haz(t) for t in x]), theta, beta)
        errs.append(abs(got["annual_rate"] / exact - 1))
        hs.append(math.log(x[1] / x[0]))
        assert got["extrapolated_share"] < 1e-6  # the table covers the integrand
    order = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 1.9 < order < 2.1, (order, errs)
    assert errs[-1] < 2e-4


def test_step_fragility_and_fema_reference() -> None:
    x = np.array([0.5, 1.0, 2.0, 4.0, 8.0])
    h = np.array([1e-1, 3e-2, 8e-3, 1.5e-3, 2e-4])
    cur = hazard_curve(x, h)
    # beta = 0: the fragility is a step at theta, lambda = H(theta)
    assert annual_rate(cur, 2.0, 0.0)["annual_rate"] == pytest.approx(8e-3, rel=1e-12)
    assert annual_rate(cur, 2.0, 1e-6)["annual_rate"] == pytest.approx(8e-3, rel=1e-4)
    assert FEMA_P58_RACK["theta_m_s2"] == pytest.approx(0.42 * 9.80665)
    assert FEMA_P58_RACK["beta"] == 0.40


def _write(tmp: Path, rows: str, measure: str = "pga", units: str = "g") -> Path:
    p = tmp / "hazard.csv"
    p.write_text(f"# measure = {measure}\n# units = {units}\n# source = test\n"
                 f"im,annual_frequency\n{rows}")
    return p


def test_load_and_units(tmp_path: Path) -> None:
    cur = load_hazard_curve(_write(tmp_path, "0.1,1e-2\n0.2,3e-3\n0.4,5e-4\n"), "pga")
    np.testing.assert_allclose(cur.im, np.array([0.1, 0.2, 0.4]) * G)
    assert cur.units_given == "g" and cur.source == "test"
    cur2 = load_hazard_curve(_write(tmp_path, "98.0665,1e-2\n196.133,3e-3\n", units="gal"))
    np.testing.assert_allclose(cur2.im, [0.980665, 1.96133])


@pytest.mark.parametrize(("rows", "kw", "field", "allowed"), [
    ("0.1,1e-2\n0.2,2e-2\n", {}, "annual_frequency", "decreasing"),
    ("0.1,1e-2\n0.2,0\n", {}, "annual_frequency", "> 0"),
    ("0.1,1e-2\n-0.2,1e-3\n", {}, "im", "> 0"),
    ("0.2,1e-2\n0.1,1e-3\n", {}, "im", "increasing"),
    ("0.1,1e-2\n", {}, "points", "at least 2"),
    ("0.1,1e-2\n0.2,1e-3\n", {"units": "ft/s2"}, "units", "acceleration unit"),
    ("0.1,1e-2\n0.2,1e-3\n", {"units": "s"}, "units", "acceleration unit"),
    ("0.1,1e-2\n0.2,1e-3\n", {"measure": "sa"}, "measure", "pga"),
])
def test_bad_hazard_curves(tmp_path: Path, rows: str, kw: dict, field: str,
                           allowed: str) -> None:
    with pytest.raises(InputError) as exc:
        load_hazard_curve(_write(tmp_path, rows, **kw), "pga")
    assert exc.value.field.endswith(field)
    assert allowed in exc.value.allowed


def test_bad_file_layout(tmp_path: Path) -> None:
    p = tmp_path / "h.csv"
    p.write_text("# units = g\nim,annual_frequency\n0.1,1e-2\n0.2,1e-3\n")
    with pytest.raises(InputError, match="measure"):
        load_hazard_curve(p)
    p.write_text("# measure = pga\n# units = g\nx,y\n0.1,1e-2\n")
    with pytest.raises(InputError, match="header"):
        load_hazard_curve(p)
    p.write_text("# measure = pga\n# units = g\nim,annual_frequency\n0.1,abc\n")
    with pytest.raises(InputError, match="line 4"):
        load_hazard_curve(p)
    with pytest.raises(InputError, match="existing"):
        load_hazard_curve(tmp_path / "missing.csv")


def _store(tmp: Path) -> Path:
    """A stored study (the layout of ``seisrack study --out``) with 4 PGA stripes of 10 runs,
    1, 3, 7 and 9 of which slide more than 5 cm: a fragility the MLE fits (status ok)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows = []
    for j, (im, k) in enumerate(zip((1.0, 2.0, 3.0, 4.0), (1, 3, 7, 9), strict=True)):
        for i in range(10):
            rows.append({"run_id": f"r{j}{i:02d}", "rack": "rack.toml", "record": f"rec{i}",
                         "im_measure": "pga", "im_target": im, "scale_factor": 1.0,
                         "stripe": j, "mu_static": 0.4, "mu_dynamic": 0.4, "occupancy": 1.0,
                         "seed": 1, "status": "ok", "error": "",
                         "peak_sliding_max_m": 0.1 if i < k else 0.0,
                         "pallet_peak_sliding_m": [0.0], "n_pallets": 1, "any_fall": i < k - 2,
                         "n_fall": int(i < k - 2), "base_shear_N": 1e3 * im,
                         "beam_displacement_max_m": 0.01, "drift_ratio_max": 0.005,
                         "upright_moment_connection_Nm": 100.0, "wall_time_s": 0.1})
    (tmp / "runs").mkdir(parents=True)
    pq.write_table(pa.table({k: [r[k] for r in rows] for k in rows[0]}),
                   tmp / "runs" / "part-000.parquet")
    return tmp


def test_study_summary_with_hazard(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    """``study summary --hazard``: λ of each fitted fragility equals annual_rate on the same
    curve (and its P50), the figure is written, a wrong measure is refused (exit 2)."""
    from seisrack.studies.summary import summary_main

    out = _store(tmp_path / "study")
    haz = _write(tmp_path, "0.05,5e-2\n0.1,1.5e-2\n0.2,3e-3\n0.4,4e-4\n0.8,3e-5\n")
    assert summary_main([str(out), "--boot", "0", "--hazard", str(haz), "--json"]) == 0
    s = json.loads(capsys.readouterr().out)
    risk = s["risk"]
    cur = load_hazard_curve(haz)
    fitted = [f for f in risk["fragilities"] if f["annual_rate"] is not None]
    assert {f["name"] for f in fitted} == {"sliding>0.05m", "any_fall"}
    for f in fitted:
        assert f["annual_rate"] == pytest.approx(
            annual_rate(cur, f["theta_m_s2"], f["beta"])["annual_rate"], rel=1e-12)
        assert f["p50"] == pytest.approx(1 - math.exp(-50 * f["annual_rate"]), rel=1e-12)
    # falls need a stronger shaking than 5 cm of sliding: a rarer event
    by = {f["name"]: f["annual_rate"] for f in fitted}
    assert by["any_fall"] < by["sliding>0.05m"]
    assert risk["reference"]["name"].startswith("FEMA P-58")
    assert Path(s["files"]["risk_png"]).read_bytes()[:4] == b"\x89PNG"
    assert summary_main([str(out), "--boot", "0", "--hazard", str(haz)]) == 0
    assert "risk per year" in capsys.readouterr().out
    bad = _write(tmp_path, "0.05,5e-2\n0.1,1.5e-2\n", measure="sa")
    assert summary_main([str(out), "--boot", "0", "--hazard", str(bad), "--json"]) == 2
    err = json.loads(capsys.readouterr().out)["error"]  # under --json, the error is JSON
    assert "measure" in err["field"]
