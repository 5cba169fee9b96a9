"""Hysteresis laws, part 2: the pinched four-point multilinear law of Lowes & Altoontash
(2003) without damage (OpenSees Pinching4 with its damage off), and its parameter packing.
Layouts in :mod:`seisrack.dynamics._hysteresis`; equations in ``docs/theory/hysteresis.md``.
"""


try:  # names injected by the loader when executed after ``_hyst_base.py``
    _hyst_div  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover - plain import of this file (pure-Python twin)
    from seisrack.dynamics._hyst_base import (  # noqa: F401
        _HYST_DSTRAIN_ZERO,
        _JIT,
        HYST_P_KNEG,
        HYST_P_KPOS,
        HYST_P_NEG_F,
        HYST_P_NEG_U,
        HYST_P_PINCH,
        HYST_P_POS_F,
        HYST_P_POS_U,
        HYST_S_BRANCH,
        HYST_S_KT,
        HYST_S_M,
        HYST_S_THETA,
        HYST_S_WORK,
        _hyst_div,
    )


@_JIT
def _hyst_pack_pinching(rot_p, mom_p, rot_n, mom_n, rdisp_p, rforce_p, uforce_p,
                        rdisp_n, rforce_n, uforce_n, par):
    """Fill ``par`` for the pinching law from the 4-point envelopes given as positive
    magnitudes (``rot_n``, ``mom_n`` too) and the six pinching ratios. The envelope is closed
    by a tiny elastic point u0 = 1e-4·max(θ1+, θ1-) on the stiffer initial slope and a far
    point 1e6·θ4 continuing the last segment when it rises, else rising by only 10 % (so the
    envelope never softens beyond θ4), as in OpenSees' Pinching4."""
    par[:] = 0.0
    kp = mom_p[0] / rot_p[0]
    kn = mom_n[0] / rot_n[0]
    k = kp if kp > kn else kn
    u0 = 1e-4 * rot_p[0] if rot_p[0] > rot_n[0] else 1e-4 * rot_n[0]
    par[HYST_P_POS_U] = u0
    par[HYST_P_POS_F] = u0 * k
    par[HYST_P_NEG_U] = -u0
    par[HYST_P_NEG_F] = -u0 * k
    for i in range(4):
        par[HYST_P_POS_U + 1 + i] = rot_p[i]
        par[HYST_P_POS_F + 1 + i] = mom_p[i]
        par[HYST_P_NEG_U + 1 + i] = -rot_n[i]
        par[HYST_P_NEG_F + 1 + i] = -mom_n[i]
    sp = (mom_p[3] - mom_p[2]) / (rot_p[3] - rot_p[2])
    sn = (mom_n[3] - mom_n[2]) / (rot_n[3] - rot_n[2])
    par[HYST_P_POS_U + 5] = 1e6 * rot_p[3]
    par[HYST_P_NEG_U + 5] = -1e6 * rot_n[3]
    if sp > 0.0:
        par[HYST_P_POS_F + 5] = mom_p[3] + sp * (1e6 * rot_p[3] - rot_p[3])
    else:
        par[HYST_P_POS_F + 5] = 1.1 * mom_p[3]
    if sn > 0.0:
        par[HYST_P_NEG_F + 5] = -(mom_n[3] + sn * (1e6 * rot_n[3] - rot_n[3]))
    else:
        par[HYST_P_NEG_F + 5] = -1.1 * mom_n[3]
    par[0] = k
    par[HYST_P_KPOS] = kp
    par[HYST_P_KNEG] = kn
    par[HYST_P_PINCH + 0] = rdisp_p
    par[HYST_P_PINCH + 1] = rforce_p
    par[HYST_P_PINCH + 2] = uforce_p
    par[HYST_P_PINCH + 3] = rdisp_n
    par[HYST_P_PINCH + 4] = rforce_n
    par[HYST_P_PINCH + 5] = uforce_n


# ---------------------------------------------------------------- pinching (Pinching4, no damage)

@_JIT
def _hyst_env_pos(par, u):
    """Positive envelope through the six points of ``par`` (linear extrapolation beyond both
    ends): moment and slope."""
    ou = HYST_P_POS_U
    of = HYST_P_POS_F
    j = 4
    for i in range(5):
        if u <= par[ou + i + 1]:
            j = i
            break
    s = (par[of + j + 1] - par[of + j]) / (par[ou + j + 1] - par[ou + j])
    return par[of + j] + (u - par[ou + j]) * s, s


@_JIT
def _hyst_env_neg(par, u):
    """Negative envelope (rotations and moments negative), moment and slope. Each segment is
    written from its outer end (as OpenSees does: same rounding)."""
    ou = HYST_P_NEG_U
    of = HYST_P_NEG_F
    j = 4
    for i in range(5):
        if u >= par[ou + i + 1]:
            j = i
            break
    s = (par[of + j] - par[of + j + 1]) / (par[ou + j] - par[ou + j + 1])
    return par[of + j + 1] + (u - par[ou + j + 1]) * s, s


@_JIT
def _hyst_path_eval(pu, pf, u):
    """Moment and slope on the 4-point unload–reload path ``pu``, ``pf`` (increasing ``pu``):
    the segment whose start is the last point at or left of ``u``; the end segments extend
    linearly beyond the path's ends.

    Deliberate difference from OpenSees' Pinching4: there a segment of exactly zero slope is
    replaced by the last segment extrapolated backwards (its ``k == 0`` test doubles as "no
    segment found"), which makes the moment jump, e.g. on the flat plateau of rForceP = uForceP
    = 0. Here a flat segment is flat; and a last segment of zero length (reload point on the
    target point, rDisp = rForce = 1) is skipped instead of giving 0/0."""
    j = 0
    for i in range(3):
        if u >= pu[i]:
            j = i
    if j == 2 and not pu[3] > pu[2]:
        j = 1
    s = _hyst_div(pf[j + 1] - pf[j], pu[j + 1] - pu[j])
    return pf[j] + (u - pu[j]) * s, s


@_JIT
def _hyst_path_straight(pu, pf):
    """Unload–reload path as one straight line from point 0 to point 3 (points 1, 2 at 33 % and
    67 %)."""
    du = pu[3] - pu[0]
    df = pf[3] - pf[0]
    pu[1] = pu[0] + 0.33 * du
    pu[2] = pu[0] + 0.67 * du
    pf[1] = pf[0] + 0.33 * df
    pf[2] = pf[0] + 0.67 * df


@_JIT
def _hyst_path_sanitize(pu, pf):
    """A path with a decreasing rotation or moment step becomes a straight line; a straight
    line softer than the secant to point 0 is bent through the origin."""
    check = _hyst_div(pf[0], pu[0])
    slope = 0.0
    i = 0
    while i < 3:
        if pu[i + 1] - pu[i] < 0.0 or pf[i + 1] - pf[i] < 0.0:
            _hyst_path_straight(pu, pf)
            slope = _hyst_div(pf[3] - pf[0], pu[3] - pu[0])
            i = 3
        if slope > 1e-8 and slope < check:
            pu[1] = 0.0
            pf[1] = 0.0
            pu[2] = pu[3] / 2.0
            pf[2] = pf[3] / 2.0
        i += 1


@_JIT
def _hyst_path_to_neg(par, lo_u, lo_f, hi_u, hi_f, dmin, kunload, pu, pf):
    """Path of branch 3: unloading from (hi_u, hi_f) towards the negative envelope point
    (lo_u, lo_f) at the minimum demand. Unload with ``kunload`` down to M = uForceN·(negative
    strength), pinched segment to the reload point (rDispN·lo_u, rForceN·lo_f), then reload to
    the envelope."""
    kneg = par[HYST_P_KNEG]
    rdisp = par[HYST_P_PINCH + 3]
    rforce = par[HYST_P_PINCH + 4]
    uforce = par[HYST_P_PINCH + 5]
    nf = HYST_P_NEG_F
    kmax = kunload if kunload > kneg else kneg
    pu[0] = lo_u
    pf[0] = lo_f
    pu[3] = hi_u
    pf[3] = hi_f
    if pu[0] * pu[3] < 0.0:
        pu[1] = lo_u * rdisp
        beyond3 = dmin < par[HYST_P_NEG_U + 3]
        if rforce - uforce > 1e-8:
            pf[1] = lo_f * rforce
        else:
            a = (lo_f if beyond3 else par[nf + 3]) * uforce * (1.0 + 1e-6)
            c = par[nf + 4] * (1.0 + 1e-6)
            pf[1] = a if a < c else c
        if _hyst_div(pf[1] - pf[0], pu[1] - pu[0]) > kneg:  # reload never stiffer than unload
            pu[1] = lo_u + (pf[1] - pf[0]) / kneg
        if pu[1] > pu[3]:
            _hyst_path_straight(pu, pf)
        else:
            pf[2] = uforce * (par[nf + 4] if beyond3 else par[nf + 3])
            pu[2] = hi_u - (hi_f - pf[2]) / kunload
            if pu[2] > pu[3]:
                pu[2] = pu[1] + 0.5 * (pu[3] - pu[1])
                pf[2] = pf[1] + 0.5 * (pf[3] - pf[1])
            elif _hyst_div(pf[2] - pf[1], pu[2] - pu[1]) > kmax:
                _hyst_path_straight(pu, pf)
            elif pu[2] < pu[1] or _hyst_div(pf[2] - pf[1], pu[2] - pu[1]) < 0.0:
                if pu[2] < 0.0:
                    pu[2] = pu[1] + 0.5 * (pu[3] - pu[1])
                    pf[2] = pf[1] + 0.5 * (pf[3] - pf[1])
                elif pu[1] > 0.0:
                    pu[1] = pu[0] + 0.5 * (pu[2] - pu[0])
                    pf[1] = pf[0] + 0.5 * (pf[2] - pf[0])
                else:
                    _hyst_path_split(pu, pf)
    else:
        _hyst_path_straight(pu, pf)
    _hyst_path_sanitize(pu, pf)


@_JIT
def _hyst_path_split(pu, pf):
    """Crossed inner points: put both 1 % either side of their mean moment, keeping the outer
    slopes."""
    avg = 0.5 * (pf[2] + pf[1])
    dfr = abs(avg) / 100.0
    s01 = _hyst_div(pf[1] - pf[0], pu[1] - pu[0])
    s23 = _hyst_div(pf[3] - pf[2], pu[3] - pu[2])
    pf[1] = avg - dfr
    pf[2] = avg + dfr
    pu[1] = pu[0] + _hyst_div(pf[1] - pf[0], s01)
    pu[2] = pu[3] - _hyst_div(pf[3] - pf[2], s23)


@_JIT
def _hyst_path_to_pos(par, lo_u, lo_f, hi_u, hi_f, dmax, kunload, pu, pf):
    """Path of branch 4, the mirror of :func:`_hyst_path_to_neg`: unloading from the negative
    point (lo_u, lo_f) towards the positive envelope point (hi_u, hi_f) at the maximum demand,
    with rDispP, rForceP, uForceP."""
    kpos = par[HYST_P_KPOS]
    rdisp = par[HYST_P_PINCH + 0]
    rforce = par[HYST_P_PINCH + 1]
    uforce = par[HYST_P_PINCH + 2]
    pf_ = HYST_P_POS_F
    kmax = kunload if kunload > kpos else kpos
    pu[0] = lo_u
    pf[0] = lo_f
    pu[3] = hi_u
    pf[3] = hi_f
    if pu[0] * pu[3] < 0.0:
        pu[2] = hi_u * rdisp
        beyond3 = dmax > par[HYST_P_POS_U + 3]
        if uforce == 0.0 or rforce - uforce > 1e-8:
            pf[2] = hi_f * rforce
        else:
            a = (hi_f if beyond3 else par[pf_ + 3]) * uforce * (1.0 + 1e-6)
            c = par[pf_ + 4] * (1.0 + 1e-6)
            pf[2] = a if a > c else c
        if _hyst_div(pf[3] - pf[2], pu[3] - pu[2]) > kpos:
            pu[2] = hi_u - (pf[3] - pf[2]) / kpos
        if pu[2] < pu[0]:
            _hyst_path_straight(pu, pf)
        else:
            pf[1] = uforce * (par[pf_ + 4] if beyond3 else par[pf_ + 3])
            pu[1] = lo_u + (pf[1] - lo_f) / kunload
            if pu[1] < pu[0]:
                pu[1] = pu[0] + 0.5 * (pu[2] - pu[0])
                pf[1] = pf[0] + 0.5 * (pf[2] - pf[0])
            elif _hyst_div(pf[2] - pf[1], pu[2] - pu[1]) > kmax:
                _hyst_path_straight(pu, pf)
            elif pu[2] < pu[1] or _hyst_div(pf[2] - pf[1], pu[2] - pu[1]) < 0.0:
                if pu[1] > 0.0:
                    pu[1] = pu[0] + 0.5 * (pu[2] - pu[0])
                    pf[1] = pf[0] + 0.5 * (pf[2] - pf[0])
                elif pu[2] < 0.0:
                    pu[2] = pu[1] + 0.5 * (pu[3] - pu[1])
                    pf[2] = pf[1] + 0.5 * (pf[3] - pf[1])
                else:
                    _hyst_path_split(pu, pf)
    else:
        _hyst_path_straight(pu, pf)
    _hyst_path_sanitize(pu, pf)


@_JIT
def _hyst_pinching(par, st_c, u, st_t):
    """Pinching4 without damage: branch logic (which of the five branches the trial rotation
    is on, and its end points), then the moment on that branch."""
    uc = st_c[HYST_S_THETA]
    fc = st_c[HYST_S_M]
    du = u - uc
    if abs(du) < _HYST_DSTRAIN_ZERO:
        du = 0.0
    br = int(st_c[HYST_S_BRANCH])
    lo_u = st_c[5]
    lo_f = st_c[6]
    hi_u = st_c[7]
    hi_f = st_c[8]
    dmin_c = st_c[9]
    dmax_c = st_c[10]
    dmin = dmin_c
    dmax = dmax_c
    pu0 = HYST_P_POS_U
    pf0 = HYST_P_POS_F
    nu0 = HYST_P_NEG_U
    nf0 = HYST_P_NEG_F
    to_pos = False   # switch to the positive envelope
    to_neg = False
    to_3 = False     # start a new unload-reload path towards the negative side
    to_4 = False
    reversal = du * st_c[11] <= 0.0
    if u < lo_u or u > hi_u or reversal:
        if br == 0:
            if u > hi_u:
                to_pos = True
            elif u < lo_u:
                to_neg = True
        elif br == 1 and du < 0.0:
            if uc > dmax:
                dmax = uc
            if u < dmin_c:
                to_neg = True
            else:
                to_3 = True
        elif br == 2 and du > 0.0:
            if uc < dmin:
                dmin = uc
            if u > dmax_c:
                to_pos = True
            else:
                to_4 = True
        elif br == 3:
            if u < lo_u:
                to_neg = True
            elif u > dmax_c and du > 0.0:
                to_pos = True
            elif du > 0.0:
                to_4 = True
        elif br == 4:
            if u > hi_u:
                to_pos = True
            elif u < dmin_c and du < 0.0:
                to_neg = True
            elif du < 0.0:
                to_3 = True
    if to_pos:
        br = 1
        lo_u = par[pu0]
        lo_f = par[pf0]
        hi_u = par[pu0 + 5]
        hi_f = par[pf0 + 5]
    elif to_neg:
        br = 2
        lo_u = par[nu0 + 5]
        lo_f = par[nf0 + 5]
        hi_u = par[nu0]
        hi_f = par[nf0]
    elif to_3:
        br = 3
        lo_u = dmin_c
        lo_f = _hyst_env_neg(par, dmin_c)[0]
        hi_u = uc
        hi_f = fc
    elif to_4:
        br = 4
        lo_u = uc
        lo_f = fc
        hi_u = dmax_c
        hi_f = _hyst_env_pos(par, dmax_c)[0]
    pu = st_t[12:16]
    pf = st_t[16:20]
    if br == 0:
        kt = par[0]
        m = kt * u
    elif br == 1:
        m, kt = _hyst_env_pos(par, u)
    elif br == 2:
        m, kt = _hyst_env_neg(par, u)
    elif br == 3:
        ku = par[HYST_P_KNEG] if hi_u < 0.0 else par[HYST_P_KPOS]
        _hyst_path_to_neg(par, lo_u, lo_f, hi_u, hi_f, dmin, ku, pu, pf)
        m, kt = _hyst_path_eval(pu, pf, u)
    else:
        ku = par[HYST_P_KNEG] if lo_u < 0.0 else par[HYST_P_KPOS]
        _hyst_path_to_pos(par, lo_u, lo_f, hi_u, hi_f, dmax, ku, pu, pf)
        m, kt = _hyst_path_eval(pu, pf, u)
    st_t[HYST_S_BRANCH] = br
    st_t[5] = lo_u
    st_t[6] = lo_f
    st_t[7] = hi_u
    st_t[8] = hi_f
    st_t[9] = dmin
    st_t[10] = dmax
    st_t[11] = du
    return m, kt
