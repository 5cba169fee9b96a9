"""Validation of the lognormal fragility fits against Baker (2015).

Source: J. W. Baker (2015), "Efficient analytical fragility function fitting using dynamic
structural analysis", Earthquake Spectra 31(1), 579-599. The fragility function is
P(C | IM = x) = Phi(ln(x/theta)/beta) (Eq. 1); on multiple stripes theta and beta maximise the
binomial likelihood of the observed counts (Eq. 11); on IDA they are the mean and standard
deviation of ln IM at first exceedance (method of moments).

Checks:
- closed forms: two stripes with exactly lognormal fractions are interpolated exactly (two
  equations, two unknowns); a single stripe is maximal on the ridge Phi(ln(x/theta)/beta) = z/n;
  all-or-nothing stripes give the step; the analytic gradient vanishes at the optimum and the
  analytic Hessian matches finite differences of the log-likelihood;
- recovery: synthetic binomial stripes from known (theta, beta), 60 seeds; the Wald intervals
  from the observed information cover the truth at a rate consistent with 95 %;
- the bootstrap band contains the estimate; the IDA moments match numpy.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import special, stats

from seisrack.errors import InputError
from seisrack.studies import fragility as fr


def test_two_exact_stripes_are_interpolated():
    theta, beta = 2.3, 0.35
    x = np.array([1.7, 3.1])
    p = special.ndtr(np.log(x / theta) / beta)
    n = np.array([1000, 1000])
    # choose counts that are exact: n * p need not be an integer, so use the solved fractions
    k = np.round(n * p)
    fit = fr.fit_fragility(x, n, k)
    # closed form: Phi^-1(k/n) = (ln x - ln theta)/beta at both stripes
    z = special.ndtri(k / n)
    beta_cf = (np.log(x[1]) - np.log(x[0])) / (z[1] - z[0])
    theta_cf = math.exp(np.log(x[0]) - beta_cf * z[0])
    assert fit.status == "ok"
    assert fit.theta == pytest.approx(theta_cf, rel=1e-8)
    assert fit.beta == pytest.approx(beta_cf, rel=1e-8)
    assert fit.theta == pytest.approx(theta, rel=0.02)
    assert fit.beta == pytest.approx(beta, rel=0.05)


def test_single_stripe_lies_on_the_ridge():
    fit = fr.fit_fragility([1.2], [20], [7])
    assert fit.status == "underdetermined"
    assert special.ndtr(math.log(1.2 / fit.theta) / fit.beta) == pytest.approx(7 / 20, abs=1e-6)
    # the likelihood there equals the binomial maximum at the observed fraction
    assert fit.loglik == pytest.approx(stats.binom.logpmf(7, 20, 7 / 20), abs=1e-8)


def test_all_or_nothing_and_empty_cases():
    sep = fr.fit_fragility([1, 2, 4], [10, 10, 10], [0, 10, 10])
    assert sep.status == "separated" and sep.beta == 0.0
    assert sep.theta == pytest.approx(math.sqrt(2.0))
    quasi = fr.fit_fragility([1, 2, 4], [10, 10, 10], [0, 4, 10])
    assert quasi.status == "separated" and quasi.theta == pytest.approx(2.0)
    # one mixed stripe at the top (or bottom) of all-nothing (all-exceed) stripes: a step there
    top = fr.fit_fragility([1, 2, 4], [24, 24, 24], [0, 0, 11])
    assert top.status == "separated" and top.theta == pytest.approx(4.0)
    assert top.loglik == pytest.approx(stats.binom.logpmf(11, 24, 11 / 24))
    bottom = fr.fit_fragility([1, 2, 4], [24, 24, 24], [5, 24, 24])
    assert bottom.status == "separated" and bottom.theta == pytest.approx(1.0)
    # ... but not when the all-nothing stripe lies above the mixed one (non-monotone)
    assert fr.fit_fragility([1, 2, 4], [24, 24, 24], [0, 11, 0]).status != "separated"
    assert fr.fit_fragility([1, 2], [5, 5], [0, 0]).status == "no_exceedance"
    assert fr.fit_fragility([1, 2], [5, 5], [5, 5]).status == "all_exceed"
    assert fr.fit_fragility([1, 2], [0, 0], [0, 0]).status == "no_data"
    # a stripe with 0 exceedances and one with all, around a mixed stripe: interior optimum
    fit = fr.fit_fragility([1, 2, 3, 4], [10, 10, 10, 10], [0, 3, 8, 10])
    assert fit.status == "ok" and 2.0 < fit.theta < 3.0 and 0 < fit.beta < 1


@pytest.mark.parametrize(
    ("im", "n", "k"),
    [([0.0, 1.0], [5, 5], [1, 2]), ([1.0, 2.0], [5, 5], [6, 2]), ([1.0], [5, 5], [1, 2])],
)
def test_bad_input(im, n, k):
    with pytest.raises(InputError):
        fr.fit_fragility(im, n, k)


def test_gradient_zero_and_hessian_matches_finite_differences():
    x = np.array([0.5, 1.0, 1.5, 2.0, 3.0])
    n = np.array([30, 30, 30, 30, 30])
    k = np.array([1, 8, 15, 21, 28])
    fit = fr.fit_fragility(x, n, k)
    u, v = math.log(fit.theta), math.log(fit.beta)
    lx = np.log(x)
    g, h = fr._derivatives(u, v, lx, n.astype(float), k.astype(float))
    assert np.max(np.abs(g)) < 1e-7

    def ll(a, b):
        return fr._loglik(a, b, lx, n.astype(float), k.astype(float))

    e = 1e-4
    huu = (ll(u + e, v) - 2 * ll(u, v) + ll(u - e, v)) / e**2
    hvv = (ll(u, v + e) - 2 * ll(u, v) + ll(u, v - e)) / e**2
    huv = (ll(u + e, v + e) - ll(u + e, v - e) - ll(u - e, v + e) + ll(u - e, v - e)) / (4 * e**2)
    np.testing.assert_allclose(h, [[huu, huv], [huv, hvv]], rtol=1e-4)
    # the optimum is a maximum: nudging either parameter lowers the likelihood
    for du, dv in [(1e-3, 0), (-1e-3, 0), (0, 1e-3), (0, -1e-3)]:
        assert ll(u + du, v + dv) < fit.loglik
    p_fit = fr.fragility_curve(x, fit.theta, fit.beta)
    assert fit.loglik == pytest.approx(np.sum(stats.binom.logpmf(k, n, p_fit)))


def test_recovery_within_standard_errors():
    """60 synthetic studies; Wald 95 % intervals on ln theta and beta cover the truth."""
    theta, beta = 1.8, 0.45  # [m/s²], [-]
    x = theta * np.exp(beta * np.array([-1.5, -0.75, 0.0, 0.75, 1.5]))
    n = np.full(x.size, 40)
    p = fr.fragility_curve(x, theta, beta)
    cover_t = cover_b = 0
    reps = 60
    z_t = []
    for seed in range(reps):
        k = np.random.default_rng(seed).binomial(n, p)
        fit = fr.fit_fragility(x, n, k)
        assert fit.status == "ok"
        assert np.isfinite(fit.se_ln_theta) and np.isfinite(fit.se_beta)
        zt = (math.log(fit.theta) - math.log(theta)) / fit.se_ln_theta
        # beta on the log scale, where the likelihood is close to quadratic
        zb = (math.log(fit.beta) - math.log(beta)) / (fit.se_beta / fit.beta)
        z_t.append(zt)
        cover_t += abs(zt) < 1.96
        cover_b += abs(zb) < 1.96
        # each estimate within 4.5 standard errors (about 1 in 150,000 per fit if normal)
        assert abs(zt) < 4.5 and abs(zb) < 4.5
    # Binomial(60, 0.95): P(cover <= 51) ~ 0.6 %; a wrong SE (e.g. halved) gives ~ 40/60
    assert cover_t >= 52 and cover_b >= 52
    # the estimator of ln theta is close to unbiased: mean z within 3/sqrt(reps)
    assert abs(np.mean(z_t)) < 3 / math.sqrt(reps)


def test_bootstrap_band_contains_estimate():
    x = np.array([0.8, 1.2, 1.8, 2.7])
    n = np.array([25, 25, 25, 25])
    k = np.array([2, 7, 15, 22])
    fit = fr.fit_fragility(x, n, k)
    thetas, betas = fr.bootstrap_fragility(x, n, k, n_boot=150, seed=3)
    assert thetas.shape == (150,) and np.all(np.isfinite(thetas))
    t_lo, t_hi = np.percentile(thetas, [5, 95])
    b_lo, b_hi = np.percentile(betas, [5, 95])
    assert t_lo < fit.theta < t_hi and b_lo < fit.beta < b_hi
    # the bootstrap spread agrees with the observed-information SE within a factor 1.5
    sd = np.std(np.log(thetas))
    assert fit.se_ln_theta / 1.5 < sd < 1.5 * fit.se_ln_theta
    grid = np.geomspace(0.5, 4.0, 30)
    lo, hi = fr.fragility_band(grid, thetas, betas)
    curve = fr.fragility_curve(grid, fit.theta, fit.beta)
    assert np.all(lo <= curve + 1e-12) and np.all(curve <= hi + 1e-12)
    assert np.all(hi - lo > 0)
    # same seed, same resamples
    t2, _ = fr.bootstrap_fragility(x, n, k, n_boot=150, seed=3)
    np.testing.assert_array_equal(thetas, t2)


def test_ida_moments_and_capacity():
    c = np.array([1.1, 2.0, 1.6, 0.9, 1.4, 2.5, 1.2])
    fit = fr.fit_ida_fragility(c)
    assert fit.status == "ida_moments"
    assert fit.theta == pytest.approx(math.exp(np.mean(np.log(c))))
    assert fit.beta == pytest.approx(np.std(np.log(c), ddof=1))
    cens = fr.fit_ida_fragility(np.append(c, np.inf))
    assert cens.status == "ida_censored" and cens.theta == pytest.approx(fit.theta)
    # crossing interpolated linearly between steps; 0/1 response -> midpoint
    assert fr.ida_capacity([1, 2, 3], [0.01, 0.03, 0.07], 0.05) == pytest.approx(2.5)
    assert fr.ida_capacity([1, 2, 3], [0, 0, 1], 0.5) == pytest.approx(2.5)
    assert fr.ida_capacity([1, 2, 3], [0, 0, 0], 0.5) == math.inf
    assert fr.ida_capacity([1, 2, 3], [1, 1, 1], 0.5) == 1.0
