"""Moment–rotation hysteresis laws of the rotational hinges (work in progress stub)."""

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
HYST_NPAR = 32
HYST_NSTATE = 24


@_JIT
def _hyst_k0(law, par):
    return par[0]


@_JIT
def _hyst_init(law, par, st):
    st[:] = 0.0
    st[2] = par[0]


@_JIT
def _hyst_trial(law, par, st_c, theta, st_t):
    st_t[:] = st_c
    k = par[0]
    st_t[0] = theta
    st_t[1] = k * theta
    st_t[2] = k
    return k * theta, k


_HYST_UNUSED = np.zeros(1)
