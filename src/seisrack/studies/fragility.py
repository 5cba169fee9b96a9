"""Lognormal fragility functions from multiple stripes (maximum likelihood) and from IDA.

A fragility function gives the probability that a damage state C is reached or exceeded at an
intensity IM = x. It is taken lognormal (Baker 2015, Eq. 1)::

    P(C | IM = x) = Phi( ln(x / theta) / beta )

with median ``theta`` [IM units] and dispersion ``beta`` [-].

*Multiple stripes.* At stripe j (intensity x_j) z_j of n_j runs exceed. Each count is binomial,
and the parameters maximise the product of the binomial probabilities over the stripes (Baker
2015, "Efficient analytical fragility function fitting using dynamic structural analysis",
Earthquake Spectra 31(1), 579-599, Eq. 11). The optimiser works on (ln theta, ln beta), which
keeps both positive, and starts from the probit least-squares line through the observed
fractions. Standard errors come from the observed information (the analytic Hessian of the
log-likelihood at the optimum).

*IDA.* With one IM of first exceedance per record, the lognormal is fitted by the method of
moments on ln IM (Baker 2015, section on IDA): ln theta = mean, beta = sample standard
deviation.

The derivations are in ``docs/theory/fragility.md``. Everything here is a plain function of
arrays; nothing reads files.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize, special

from seisrack.errors import InputError
from seisrack.lognormal import fragility_curve

__all__ = [
    "FragilityFit",
    "bootstrap_fragility",
    "bootstrap_ida_fragility",
    "fit_fragility",
    "fit_ida_fragility",
    "fragility_band",
    "fragility_curve",
    "ida_capacity",
    "log_likelihood",
]

# Bounds on beta for the optimiser: below 1e-3 the curve is a step for any practical IM grid.
_BETA_MIN = 1e-3
_BETA_MAX = 20.0


@dataclass(frozen=True)
class FragilityFit:
    """A fitted lognormal fragility function.

    ``theta`` [IM units] and ``beta`` [-] are NaN when the data cannot define them (status
    ``"no_exceedance"``, ``"all_exceed"``, ``"no_data"``). ``status`` is one of

    - ``"ok"``: interior maximum, standard errors from the observed information;
    - ``"separated"``: every stripe is all-or-nothing and the fractions are monotone, the MLE is a
      step (beta -> 0); theta is the geometric mean of the two IMs around the step, beta = 0;
    - ``"underdetermined"``: a single stripe carries information, the likelihood is maximal along
      the ridge ln(x/theta)/beta = Phi^-1(z/n); the point returned lies on that ridge;
    - ``"no_exceedance"`` / ``"all_exceed"`` / ``"no_data"``: nothing to fit;
    - ``"ida_moments"`` / ``"ida_censored"``: method of moments on IDA capacities (the second
      when some records never exceeded and were left out);
    - ``"failed"``: the optimiser did not converge (the last iterate is reported).
    """

    theta: float
    beta: float
    loglik: float
    n_stripes: int
    status: str
    n_runs: int = 0
    se_ln_theta: float = math.nan
    se_beta: float = math.nan
    method: str = "mle"

    @property
    def ok(self) -> bool:
        return self.status in ("ok", "separated", "ida_moments", "ida_censored")


def _validate(im, n_total, n_exceed) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    x = np.asarray(im, dtype=float).ravel()
    n = np.asarray(n_total, dtype=float).ravel()
    k = np.asarray(n_exceed, dtype=float).ravel()
    if not (x.shape == n.shape == k.shape):
        raise InputError("im/n_total/n_exceed", (x.size, n.size, k.size), "arrays of equal length")
    if np.any(~np.isfinite(x)) or np.any(x <= 0):
        raise InputError("im", x.tolist(), "finite intensities > 0")
    if np.any(n < 0) or np.any(k < 0) or np.any(k > n) or np.any(n != np.round(n)):
        raise InputError("n_exceed", k.tolist(), "integers with 0 <= n_exceed <= n_total")
    keep = n > 0  # an empty stripe carries no information
    return x[keep], n[keep], k[keep]


def log_likelihood(theta: float, beta: float, im, n_total, n_exceed) -> float:
    """Binomial log-likelihood of the stripes (Baker 2015, Eq. 11), constant term included."""
    x, n, k = _validate(im, n_total, n_exceed)
    return float(_loglik(math.log(theta), math.log(beta), np.log(x), n, k))


def _log_binom(n: np.ndarray, k: np.ndarray) -> float:
    gl = special.gammaln
    return float(np.sum(gl(n + 1) - gl(k + 1) - gl(n - k + 1)))


def _loglik(u: float, v: float, lx: np.ndarray, n: np.ndarray, k: np.ndarray) -> float:
    z = (lx - u) * math.exp(-v)
    # log_ndtr keeps the tails accurate where Phi underflows.
    ll = k * special.log_ndtr(z) + (n - k) * special.log_ndtr(-z)
    return _log_binom(n, k) + float(np.sum(ll))


def _mills(z: np.ndarray) -> np.ndarray:
    """phi(z) / Phi(z), computed in logs so it stays finite for z << 0."""
    return np.exp(-0.5 * z * z - 0.5 * math.log(2 * math.pi) - special.log_ndtr(z))


def _derivatives(u: float, v: float, lx, n, k) -> tuple[np.ndarray, np.ndarray]:
    """Gradient and Hessian of the log-likelihood in (u, v) = (ln theta, ln beta)."""
    beta = math.exp(v)
    z = (lx - u) / beta
    lp, lm = _mills(z), _mills(-z)
    a = k * lp - (n - k) * lm  # d l / dz
    b = -k * lp * (z + lp) - (n - k) * lm * (-z + lm)  # d2 l / dz2
    # z = (ln x - u) e^-v:  dz/du = -1/beta, dz/dv = -z, d2z/dudv = 1/beta, d2z/dv2 = z.
    g = np.array([np.sum(-a / beta), np.sum(-a * z)])
    huu = np.sum(b) / beta**2
    huv = np.sum(b * z / beta + a / beta)
    hvv = np.sum(b * z * z + a * z)
    return g, np.array([[huu, huv], [huv, hvv]])


def _start(lx: np.ndarray, n: np.ndarray, k: np.ndarray) -> tuple[float, float]:
    """Probit least squares through the (continuity-corrected) fractions."""
    p = (k + 0.5) / (n + 1.0)
    zt = special.ndtri(p)
    if lx.size >= 2 and np.ptp(lx) > 0:
        slope, icpt = np.polyfit(lx, zt, 1)
        if slope > 1.0 / _BETA_MAX:
            beta = float(np.clip(1.0 / slope, 0.05, 2.0))
            return float(-icpt / slope), math.log(beta)
    # weighted centre of the data, beta 0.4 (a typical record-to-record dispersion)
    return float(np.sum(n * lx) / np.sum(n)), math.log(0.4)


def _separated(x, n, k) -> float | None:
    """Where the likelihood supremum is a step (beta -> 0), its location, else None.

    That happens when the stripes with no exceedance all lie below the stripes where every run
    exceeds, and the mixed stripes (if any) share one IM between the two groups: the step then
    sits at that IM (theta -> x_mid with ln(x_mid/theta)/beta = Phi^-1(z/n) fixed), or, with no
    mixed stripe, anywhere in the gap (the geometric mean of the two IMs around it is returned).
    One of the two groups may be empty when there is a mixed stripe.
    """
    frac = k / n
    zero, one = x[frac == 0], x[frac == 1]
    mid = np.unique(x[(frac > 0) & (frac < 1)])
    if mid.size > 1:
        return None
    if mid.size == 1:
        if zero.size + one.size == 0:
            return None  # one informative stripe only: a ridge, not a step
        below = zero.size == 0 or zero.max() < mid[0]
        above = one.size == 0 or one.min() > mid[0]
        return float(mid[0]) if below and above else None
    if zero.size and one.size and zero.max() < one.min():
        return math.sqrt(float(zero.max()) * float(one.min()))
    return None


def _clip(u: float, v: float, bounds) -> tuple[float, float]:
    return (min(max(u, bounds[0][0]), bounds[0][1]), min(max(v, bounds[1][0]), bounds[1][1]))


def _newton(u: float, v: float, lx, n, k, bounds, max_iter: int = 100
            ) -> tuple[float, float, bool]:
    """Damped Newton ascent on the log-likelihood with a backtracking line search.

    Where the Hessian is not negative definite the step is the gradient scaled by the largest
    curvature magnitude, so each accepted step increases the likelihood.
    """
    f = _loglik(u, v, lx, n, k)
    for _ in range(max_iter):
        g, h = _derivatives(u, v, lx, n, k)
        if not np.all(np.isfinite(g)) or not np.all(np.isfinite(h)):
            return u, v, False
        w, q = np.linalg.eigh(h)
        if w.max() < 0:
            step = -np.linalg.solve(h, g)
        else:
            step = g / max(np.abs(w).max(), 1.0)
        t = 1.0
        while t > 1e-10:
            un, vn = _clip(u + t * step[0], v + t * step[1], bounds)
            fn = _loglik(un, vn, lx, n, k)
            if fn >= f - 1e-12 * abs(f):
                break
            t *= 0.5
        else:
            return u, v, bool(np.max(np.abs(g)) < 1e-8 * max(1.0, float(n.sum())))
        moved = max(abs(un - u), abs(vn - v))
        u, v, f = un, vn, fn
        if moved < 1e-11:
            return u, v, bool(w.max() < 0 or v <= bounds[1][0] + 1e-12)
    return u, v, False


def _lbfgs(u0: float, v0: float, lx, n, k, bounds) -> tuple[float, float]:
    def fun(p):
        g, _ = _derivatives(p[0], p[1], lx, n, k)
        return -_loglik(p[0], p[1], lx, n, k), -g

    res = optimize.minimize(fun, [u0, v0], jac=True, method="L-BFGS-B", bounds=bounds,
                            options={"ftol": 1e-14, "gtol": 1e-10, "maxiter": 500})
    return float(res.x[0]), float(res.x[1])


def fit_fragility(im, n_total, n_exceed) -> FragilityFit:
    """Maximum-likelihood lognormal fragility on multiple stripes (Baker 2015, Eq. 11).

    im: (m,) stripe intensities [IM units, e.g. m/s²]; n_total: (m,) runs per stripe;
    n_exceed: (m,) runs that reached the damage state. Stripes with n_total = 0 are ignored.
    """
    x, n, k = _validate(im, n_total, n_exceed)
    m, n_runs = int(x.size), int(n.sum())
    if m == 0:
        return FragilityFit(math.nan, math.nan, math.nan, 0, "no_data", 0)
    if np.all(k == 0):
        return FragilityFit(math.nan, math.nan, 0.0, m, "no_exceedance", n_runs)
    if np.all(k == n):
        return FragilityFit(math.nan, math.nan, 0.0, m, "all_exceed", n_runs)
    step = _separated(x, n, k)
    if step is not None:
        mx = (k > 0) & (k < n)  # the supremum: mixed stripes at their observed fraction
        p = k[mx] / n[mx]
        kk, nn = k[mx], n[mx]
        sup = _log_binom(nn, kk) + float(np.sum(kk * np.log(p) + (nn - kk) * np.log1p(-p)))
        return FragilityFit(step, 0.0, sup, m, "separated", n_runs)
    lx = np.log(x)
    mixed = int(np.count_nonzero((k > 0) & (k < n)))
    u0, v0 = _start(lx, n, k)

    bounds = ((lx.min() - 10.0, lx.max() + 10.0), (math.log(_BETA_MIN), math.log(_BETA_MAX)))
    u, v, converged = _newton(u0, v0, lx, n, k, bounds)
    if not converged:  # rare: fall back on a bounded quasi-Newton search, then polish
        u, v = _lbfgs(u0, v0, lx, n, k, bounds)
        u, v, converged = _newton(u, v, lx, n, k, bounds)
    theta, beta = math.exp(u), math.exp(v)
    loglik = _loglik(u, v, lx, n, k)
    g, h = _derivatives(u, v, lx, n, k)
    se_u = se_b = math.nan
    try:
        cov = np.linalg.inv(-h)
        if cov[0, 0] > 0 and cov[1, 1] > 0:
            se_u = math.sqrt(cov[0, 0])
            se_b = beta * math.sqrt(cov[1, 1])  # delta method: d beta = beta d(ln beta)
    except np.linalg.LinAlgError:
        pass
    if m == 1 or (mixed == 1 and m == mixed):
        status = "underdetermined"
        se_u = se_b = math.nan
    elif v <= bounds[1][0] + 1e-6:
        # quasi-separation: the supremum is a step at theta (beta -> 0)
        status, beta, se_u, se_b = "separated", 0.0, math.nan, math.nan
    elif not converged and np.max(np.abs(g)) > 1e-6 * max(1.0, n_runs):
        status = "failed"
    else:
        status = "ok"
    return FragilityFit(theta, beta, loglik, m, status, n_runs, se_u, se_b, "mle")


def bootstrap_fragility(im, n_total, n_exceed, n_boot: int = 200, seed: int = 0
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Bootstrap (theta, beta): the runs of each stripe resampled with replacement.

    Resampling n_j binary outcomes of which z_j exceed is a Binomial(n_j, z_j/n_j) draw, so the
    counts are drawn directly. Resamples that cannot be fitted (e.g. no exceedance at all)
    give NaN. Returns thetas, betas: (n_boot,).
    """
    x, n, k = _validate(im, n_total, n_exceed)
    rng = np.random.default_rng(seed)
    thetas = np.full(int(n_boot), np.nan)
    betas = np.full(int(n_boot), np.nan)
    if x.size == 0:
        return thetas, betas
    p = k / n
    for b in range(int(n_boot)):
        kb = rng.binomial(n.astype(np.int64), p)
        fit = fit_fragility(x, n, kb)
        if fit.status in ("ok", "separated"):
            thetas[b], betas[b] = fit.theta, fit.beta
    return thetas, betas


def fragility_band(x, thetas, betas, q: tuple[float, float] = (5.0, 95.0)
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Pointwise percentiles ``q`` [%] of Phi(ln(x/theta_b)/beta_b) over bootstrap samples."""
    x = np.asarray(x, dtype=float)
    t = np.asarray(thetas, dtype=float)
    b = np.asarray(betas, dtype=float)
    good = np.isfinite(t) & np.isfinite(b) & (t > 0) & (b >= 0)
    if not np.any(good):
        nan = np.full(x.shape, np.nan)
        return nan, nan.copy()
    curves = np.stack([fragility_curve(x, ti, bi) for ti, bi in zip(t[good], b[good], strict=True)])
    lo, hi = np.percentile(curves, q, axis=0)
    return lo, hi


def ida_capacity(im, edp, threshold: float) -> float:
    """IM at which one IDA curve first exceeds ``threshold`` (inf if it never does).

    im: (s,) increasing intensities of the record's steps; edp: (s,) response at each step.
    The crossing is interpolated linearly in (IM, EDP) between the last step below and the
    first above the threshold; for a 0/1 response (a fall) with threshold 0.5 that is the
    midpoint of the two steps.
    """
    x = np.asarray(im, dtype=float)
    y = np.asarray(edp, dtype=float)
    order = np.argsort(x)
    x, y = x[order], y[order]
    above = np.flatnonzero(y > threshold)
    if above.size == 0:
        return math.inf
    i = int(above[0])
    if i == 0:
        return float(x[0])
    x0, x1, y0, y1 = x[i - 1], x[i], y[i - 1], y[i]
    return float(x0 + (threshold - y0) * (x1 - x0) / (y1 - y0))


def fit_ida_fragility(im_capacity) -> FragilityFit:
    """Method-of-moments lognormal on IDA capacities (Baker 2015, IDA section).

    im_capacity: (r,) IM of first exceedance per record [IM units]; records that never
    exceeded (inf or NaN) are left out and the status says ``"ida_censored"``.
    """
    c = np.asarray(im_capacity, dtype=float).ravel()
    finite = c[np.isfinite(c) & (c > 0)]
    r = int(c.size)
    if finite.size == 0:
        return FragilityFit(math.nan, math.nan, math.nan, 0, "no_exceedance", r, method="ida")
    ln = np.log(finite)
    theta = float(np.exp(ln.mean()))  # mean of ln IM_c
    beta = float(ln.std(ddof=1)) if finite.size >= 2 else math.nan  # sample std of ln IM_c
    status = "ida_moments" if finite.size == r else "ida_censored"
    se_u = beta / math.sqrt(finite.size) if finite.size >= 2 else math.nan
    se_b = beta / math.sqrt(2.0 * (finite.size - 1)) if finite.size >= 2 else math.nan
    return FragilityFit(theta, beta, math.nan, int(finite.size), status, r, se_u, se_b, "ida")


def bootstrap_ida_fragility(im_capacity, n_boot: int = 200, seed: int = 0
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Bootstrap of :func:`fit_ida_fragility`: the records resampled with replacement.

    Returns thetas, betas: (n_boot,), NaN where a resample has fewer than two finite capacities.
    """
    c = np.asarray(im_capacity, dtype=float).ravel()
    rng = np.random.default_rng(seed)
    thetas = np.full(int(n_boot), np.nan)
    betas = np.full(int(n_boot), np.nan)
    if c.size == 0:
        return thetas, betas
    for b in range(int(n_boot)):
        fit = fit_ida_fragility(c[rng.integers(0, c.size, c.size)])
        if fit.n_stripes >= 2:
            thetas[b], betas[b] = fit.theta, fit.beta
    return thetas, betas
