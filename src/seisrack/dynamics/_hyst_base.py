"""Hysteresis laws, part 1: the parameter and state layouts (constants), the virgin state and
the bilinear law (elastic–perfectly plastic and kinematic hardening, OpenSees Steel01 without
isotropic hardening). The layouts and the laws' interface are documented in
:mod:`seisrack.dynamics._hysteresis`, which dispatches between the laws; the pinched law is in
:mod:`seisrack.dynamics._hyst_pinching`. Same source for the numba build and the Python twin
(``_kernel_numba.py`` loads this file first).
"""

import numpy as np

try:  # injected by the loader; identity when this file is imported directly
    _JIT  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover

    def _JIT(f):  # type: ignore[no-redef]
        return f


HYST_ELASTIC = 0
HYST_EPP = 1
HYST_BILINEAR = 2
HYST_PINCHING = 3
HYST_NPAR = 40
HYST_NSTATE = 24

# parameter row offsets (pinching)
HYST_P_POS_U = 3
HYST_P_POS_F = 9
HYST_P_NEG_U = 15
HYST_P_NEG_F = 21
HYST_P_KPOS = 27
HYST_P_KNEG = 28
HYST_P_PINCH = 29
# state row offsets
HYST_S_THETA = 0
HYST_S_M = 1
HYST_S_KT = 2
HYST_S_WORK = 3
HYST_S_BRANCH = 4

_HYST_DSTRAIN_ZERO = 1e-12  # Pinching4: increments below this are "no change"
_HYST_DBL_EPS = 2.220446049250313e-16  # Steel01: increments below this keep the committed state


@_JIT
def _hyst_div(a, b):
    """a / b with IEEE semantics (±inf, nan) instead of an exception on b == 0: the path
    construction compares such slopes exactly as the C++ original does."""
    if b == 0.0:
        if a == 0.0 or a != a:
            return np.nan
        return np.inf * np.copysign(1.0, a) * np.copysign(1.0, b)
    return a / b


@_JIT
def _hyst_k0(law, par):
    """Initial elastic stiffness dM/dθ at the virgin state [N·m/rad]."""
    return par[0]


@_JIT
def _hyst_init(law, par, st):
    """Virgin state row: θ = 0, M = 0, tangent k0, no work, on the elastic branch."""
    for i in range(st.shape[0]):
        st[i] = 0.0
    st[HYST_S_KT] = par[0]
    if law == HYST_PINCHING:
        st[5] = par[HYST_P_NEG_U]          # elastic branch |θ| <= u0
        st[6] = par[HYST_P_NEG_F]
        st[7] = par[HYST_P_POS_U]
        st[8] = par[HYST_P_POS_F]
        st[9] = par[HYST_P_NEG_U + 1]      # demands start at ±θ1
        st[10] = par[HYST_P_POS_U + 1]


# ---------------------------------------------------------------- bilinear (Steel01, b >= 0)

@_JIT
def _hyst_bilinear(par, st_c, i, theta):
    """Kinematic hardening between the bounding lines M = b·k·θ ± (1 − b)·My: the elastic
    predictor M_c + k·Δθ is clipped to them (Steel01 with a1 = a3 = 0). Row ``i`` of the 2D
    parameter and committed-state arrays (indexed in place: no array view per call)."""
    k = par[i, 0]
    fy = par[i, 1]
    b = par[i, 2]
    dth = theta - st_c[i, HYST_S_THETA]
    if abs(dth) <= _HYST_DBL_EPS:
        m = st_c[i, HYST_S_M]
        kt = st_c[i, HYST_S_KT]
    else:
        kh = b * k
        cap = fy * (1.0 - b)
        line = kh * theta
        m = st_c[i, HYST_S_M] + k * dth
        kt = k
        upper = line + cap
        if upper < m:
            m = upper
            kt = kh
        lower = line - cap
        if lower > m:
            m = lower
            kt = kh
    return m, kt
