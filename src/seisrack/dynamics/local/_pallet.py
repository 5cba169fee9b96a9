"""One pallet over one step of the local engine (source shared by the numba and the
pure-Python backends; theory: ``docs/theory/local_engine.md`` §4).

Given the support's velocity change ``y`` over the step (from the structure's trapezoidal step)
the pallet's friction impulse ``J`` is resolved on its own, with every event of its own
(slip onset, stop, stick, turn) located inside the step. The support acceleration it sees is
``a_ref(τ) − G (λ(τ) − λ_ref(τ))`` with ``a_ref = β + (τ − h/2) j`` (eq. 4.1); its relative
velocity obeys ``ṡ = W λ − c(τ)``, ``W = I/m + G``, ``c`` linear in τ (eq. 4.2).

Two components always (a 2D rack's pallet has a zero second component and no coupling to
it): the dimension is data. Vectors are passed as pairs of scalars and small arrays: this
code runs once per pallet per Newton iteration.
"""

# ruff: noqa: N803, N806  (matrix names follow the equations)

import numpy as np

try:  # injected by the loader; identity when this file is imported directly
    _JIT  # type: ignore[used-before-def]  # noqa: B018
except NameError:  # pragma: no cover

    def _JIT(f):  # type: ignore[no-redef]
        return f

    from seisrack.dynamics._planar_contact import _disc_min

#: a sliding phase is integrated in this many equal sub-steps of what is left of the step
#: (a fixed grid: a grid adapted to the turn of the direction made J(y) jump by a few % where
#: the decision to halve flipped, which stalled the step's Newton iteration)
_NSUB = 4
#: phases (stuck or sliding) inside one step beyond which the state is kept to the step's end
_MAX_PHASES = 16
#: event kinds as the shared event core (_events.py): slip, stick, reverse (turn)
_EV_SLIP = 0
_EV_STICK = 1
_EV_TURN = 2


@_JIT
def _inv2(a11, a12, a22):
    det = a11 * a22 - a12 * a12
    return a22 / det, -a12 / det, a11 / det


@_JIT
def _onset(l0x, l0z, l1x, l1z, n0, n1, mus, t0, t1):
    """Earliest τ in (t0, t1] where |ℓ0 + ℓ1 τ| rises through mus (n0 + n1 τ); -1 if none.
    At τ = t0 itself (already beyond, to 1e-12) returns t0."""
    ax = l0x + l1x * t0
    az = l0z + l1z * t0
    f0 = ax * ax + az * az - (mus * (n0 + n1 * t0)) ** 2
    cap0 = (mus * (n0 + n1 * t0)) ** 2
    if f0 > 1e-12 * cap0 + 1e-300:
        return t0
    # f(τ) = A τ² + B τ + C
    A = l1x * l1x + l1z * l1z - mus * mus * n1 * n1
    B = 2.0 * (l0x * l1x + l0z * l1z - mus * mus * n0 * n1)
    C = l0x * l0x + l0z * l0z - mus * mus * n0 * n0
    best = -1.0
    if abs(A) <= 1e-300:
        if B != 0.0:
            r = -C / B
            if t0 < r <= t1 and B > 0.0:
                best = r
        return best
    disc = B * B - 4.0 * A * C
    if disc < 0.0:
        return -1.0
    sq = np.sqrt(disc)
    q = -0.5 * (B + (sq if B >= 0.0 else -sq))
    r1 = q / A
    r2 = C / q if q != 0.0 else r1
    lo = min(r1, r2)
    hi = max(r1, r2)
    for r in (lo, hi):
        if t0 < r <= t1:
            # rising through zero: derivative 2 A r + B > 0 (or a double root: skip)
            if 2.0 * A * r + B > 0.0:
                return r
    return best


@_JIT
def _eig2(w11, w12, w22):
    """Eigenvalues (wa, wb) and the rotation (cos, sin) of the 2 × 2 SPD W."""
    if w12 == 0.0:
        return w11, w22, 1.0, 0.0
    tr = 0.5 * (w11 + w22)
    dif = 0.5 * (w11 - w22)
    rad = np.sqrt(dif * dif + w12 * w12)
    ang = 0.5 * np.arctan2(w12, dif)
    return tr + rad, tr - rad, np.cos(ang), np.sin(ang)


@_JIT
def _return_map(zx, zz, kap, wa, wb, ca, sa):
    """End velocity of a trapezoidal sliding sub-step: σ ŝ + κ W ŝ = z, |ŝ| = 1, σ >= 0,
    with W = R diag(wa, wb) Rᵀ (``_eig2``). Returns (σ, ŝx, ŝz, slides): when |(κW)⁻¹ z| <= 1
    the pallet stops inside the sub-step (σ = 0, ŝ = (κW)⁻¹ z normalised)."""
    if kap <= 0.0:
        zn = np.sqrt(zx * zx + zz * zz)
        if zn == 0.0:
            return 0.0, 1.0, 0.0, False
        return zn, zx / zn, zz / zn, True
    da = ca * zx + sa * zz
    db = -sa * zx + ca * zz
    ka = kap * wa
    kb = kap * wb
    f0 = (da / ka) ** 2 + (db / kb) ** 2
    if f0 <= 1.0:
        xa = da / ka
        xb = db / kb
        nrm = np.sqrt(f0)
        if nrm == 0.0:
            return 0.0, 1.0, 0.0, False
        return 0.0, (ca * xa - sa * xb) / nrm, (sa * xa + ca * xb) / nrm, False
    # Σ d_i² / (σ + κ w_i)² = 1 on [0, |z|]: Newton's method on φ(σ) = (Σ …)^(−1/2) − 1,
    # linear in σ when wa = wb and nearly so otherwise, from σ = |z| − Σ d_i² κ w_i / |z|²
    # (exact when wa = wb, first order otherwise); a Newton step below 1e-8 of the scale
    # leaves an error of its square, and ends the iteration. On the 150-pallet example
    # (37.5 M return maps in 20 s) the squared form with the lower bound |z| − κ max w took
    # more steps, and a residual of exactly zero at the root led it to 20–28 bisections.
    # The bracket [lo, hi] guards the steps.
    lo = 0.0
    z2 = zx * zx + zz * zz
    hi = np.sqrt(z2)
    sig = min(max(0.0, hi - (da * da * ka + db * db * kb) / z2), hi)
    scale = hi + ka + kb
    for _ in range(100):
        pa = sig + ka
        pb = sig + kb
        qa = da / pa
        qb = db / pb
        f = qa * qa + qb * qb
        if f == 1.0:
            break
        if f > 1.0:
            lo = sig
        else:
            hi = sig
        rf = 1.0 / np.sqrt(f)
        dphi = rf * rf * rf * (qa * qa / pa + qb * qb / pb)
        nxt = sig - (rf - 1.0) / dphi if dphi > 0.0 else 0.5 * (lo + hi)
        step = abs(nxt - sig)
        if step <= 1e-15 * scale or (step <= 1e-8 * scale and lo < nxt < hi):
            sig = nxt
            break
        if not (lo < nxt < hi):
            nxt = 0.5 * (lo + hi)
        sig = nxt
    xa = da / (sig + ka)
    xb = db / (sig + kb)
    nrm = np.sqrt(xa * xa + xb * xb)
    return sig, (ca * xa - sa * xb) / nrm, (sa * xa + ca * xb) / nrm, True


@_JIT
def _psi_end(sig, ex, ez, slides, pnx, pnz, pl, zx, zz, kap, wa, wb, ca, sa):
    """ψ of a sub-step's end (``_pallet_F``'s search for a stop or a turn): σ pn·ŝ / |pn|
    while it slides, (|(κW)⁻¹ z| − 1) κ √(wa wb) <= 0 once it stops."""
    if slides:
        return sig * (pnx * ex + pnz * ez) / pl
    if kap <= 0.0:
        return 0.0
    da = (ca * zx + sa * zz) / (kap * wa)
    db = (-sa * zx + ca * zz) / (kap * wb)
    return (np.sqrt(da * da + db * db) - 1.0) * kap * np.sqrt(wa * wb)


@_JIT
def _release(w11, w12, w22, cx, cz, f):
    """Force on a pallet leaving zero relative velocity: the minimiser of ½λᵀWλ − cᵀλ on the
    disc |λ| <= f (its relative acceleration Wλ − c is opposite to λ on the circle)."""
    l1, l2, _inside = _disc_min(w11, w12, w22, -cx, -cz, f)
    return l1, l2


@_JIT
def _pallet_F(bx, bz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
              ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd, ev,
              want_ev):
    """The pallet over [0, h] for the reference mean acceleration β = (bx, bz).

    Returns (Jx, Jz, stuck, s1x, s1z, d1x, d1z, Ux, Uz, lx, lz, n_ev): impulse, end state
    (relative velocity from this integration; the caller takes it from momentum), direction,
    ∫s dτ, end force and the number of events written to ``ev`` (rows: τ, kind) when
    ``want_ev``."""
    w11 = 1.0 / m + g11
    w12 = g12
    w22 = 1.0 / m + g22
    if nd == 1:
        w12 = 0.0
        w22 = 1.0 / m
    i11, i12, i22 = _inv2(w11, w12, w22)
    wa, wb, ca, sa = _eig2(w11, w12, w22)
    n1 = (N1 - N0) / h
    # a_ref(τ) = β + (τ − h/2) j ; a_g(τ) = ag0 + (ag1 − ag0) τ / h
    ar0x = bx - 0.5 * h * jx
    ar0z = bz - 0.5 * h * jz
    ag1sx = (ag1x - ag0x) / h
    ag1sz = (ag1z - ag0z) / h
    if stuck0:
        # c = (I + mG)(a_g + a_ref)
        ux0 = ag0x + ar0x
        uz0 = ag0z + ar0z
        ux1 = ag1sx + jx
        uz1 = ag1sz + jz
        c0x = ux0 + m * (g11 * ux0 + g12 * uz0)
        c0z = uz0 + m * (g12 * ux0 + g22 * uz0)
        c1x = ux1 + m * (g11 * ux1 + g12 * uz1)
        c1z = uz1 + m * (g12 * ux1 + g22 * uz1)
    else:
        # c = a_g + a_ref − mu_d N(τ) G d0
        fx = g11 * d0x + g12 * d0z
        fz = g12 * d0x + g22 * d0z
        c0x = ag0x + ar0x - mud * N0 * fx
        c0z = ag0z + ar0z - mud * N0 * fz
        c1x = ag1sx + jx - mud * n1 * fx
        c1z = ag1sz + jz - mud * n1 * fz
    if nd == 1:
        c0z = 0.0
        c1z = 0.0
    # stuck force λ = W⁻¹ c = ℓ0 + ℓ1 τ
    l0x = i11 * c0x + i12 * c0z
    l0z = i12 * c0x + i22 * c0z
    l1x = i11 * c1x + i12 * c1z
    l1z = i12 * c1x + i22 * c1z
    # the holding force the contact decisions read (onset, stick at a stop): with the
    # support's reference acceleration filtered, ã(τ) = (β_prev + β)/2 + τ (β − β_prev2)/(2h),
    # which cancels a period-2h residue of stiff directions exactly and is O(h²) for a smooth
    # one (theory §4.4); the impulse keeps the unfiltered ℓ
    f0x = l0x
    f0z = l0z
    f1x = l1x
    f1z = l1z
    if usef:
        dax = 0.5 * (bpx + bx) - ar0x
        daz = 0.5 * (bpz + bz) - ar0z
        dsx = 0.5 * (bx - bqx) / h - jx
        dsz = 0.5 * (bz - bqz) / h - jz
        if stuck0:
            # c changes by (I + mG) Δa: λ by m Δa
            f0x += m * dax
            f0z += m * daz
            f1x += m * dsx
            f1z += m * dsz
        else:
            # c changes by Δa: λ by W⁻¹ Δa
            f0x += i11 * dax + i12 * daz
            f0z += i12 * dax + i22 * daz
            f1x += i11 * dsx + i12 * dsz
            f1z += i12 * dsx + i22 * dsz
        if nd == 1:
            f0z = 0.0
            f1z = 0.0
    t = 0.0
    Jx = 0.0
    Jz = 0.0
    Ux = 0.0
    Uz = 0.0
    stuck = stuck0
    sx = s0x
    sz = s0z
    dx = d0x
    dz = d0z
    lax = 0.0
    laz = 0.0
    if not stuck:
        na = N0
        lax = -mud * na * dx
        laz = -mud * na * dz
    n_ev = 0
    n_ph = 0
    n_sub = 0
    grid = h / _NSUB
    t_rel = -1.0  # time of the last release from zero relative velocity
    hold = False  # onsets read the unfiltered force (see the stop decision below)
    while t < h:
        if stuck:
            te = h
            if n_ph <= _MAX_PHASES:
                if hold:
                    r = _onset(l0x, l0z, l1x, l1z, N0, n1, mus, t, h)
                else:
                    r = _onset(f0x, f0z, f1x, f1z, N0, n1, mus, t, h)
                if r >= 0.0:
                    te = r
            Jx += l0x * (te - t) + 0.5 * l1x * (te * te - t * t)
            Jz += l0z * (te - t) + 0.5 * l1z * (te * te - t * t)
            t = te
            if t >= h:
                break
            n_ph += 1
            n_sub = 0
            t_rel = t
            # slip: the force from the disc problem at te
            cx = c0x + c1x * t
            cz = c0z + c1z * t
            lax, laz = _release(w11, w12, w22, cx, cz, mud * (N0 + n1 * t))
            if nd == 1:
                laz = 0.0
            fn = np.sqrt(lax * lax + laz * laz)
            if fn > 0.0:
                dx = -lax / fn
                dz = -laz / fn
            stuck = False
            sx = 0.0
            sz = 0.0
            if want_ev and n_ev < ev.shape[0]:
                ev[n_ev, 0] = t
                ev[n_ev, 1] = _EV_SLIP
            n_ev += 1
            continue
        # sliding: trapezoidal sub-steps with the return map on a fixed grid of the phase
        if n_sub == 0:
            grid = (h - t) / _NSUB
        n_sub += 1
        tb = min(t + grid, h)
        if h - tb <= 1e-9 * h:
            tb = h
        stop = False
        dl = tb - t
        cax = c0x + c1x * t
        caz = c0z + c1z * t
        cbx = c0x + c1x * tb
        cbz = c0z + c1z * tb
        zx = sx + 0.5 * dl * (w11 * lax + w12 * laz - cax - cbx)
        zz = sz + 0.5 * dl * (w12 * lax + w22 * laz - caz - cbz)
        kap = 0.5 * dl * mud * (N0 + n1 * tb)
        sig, ex, ez, slides = _return_map(zx, zz, kap, wa, wb, ca, sa)
        # the direction at the start of the sub-step: a velocity that turns by more than a
        # right angle inside it passed near zero, where a stop (1D: a reversal) can hide
        pnx = sx
        pnz = sz
        if sx == 0.0 and sz == 0.0:
            pnx = dx
            pnz = dz
        if not slides or pnx * ex + pnz * ez <= 0.0:
            stop = True
        turned = False
        if stop and n_ph <= _MAX_PHASES:
            # locate the first τ where the sub-step to τ stops or turns back: the sign change
            # of ψ(τ) = σ pn·ŝ / |pn| while it slides on, (|(κW)⁻¹ z| − 1) κ √(wa wb) once it
            # stops (both zero at σ = 0), by regula falsi with Anderson–Björck scaling, at most
            # three such steps per halving of the bracket, bisection otherwise (bisection
            # alone took 38 return maps per stop, a third of the return maps of a run)
            lo = t
            hi = tb
            pl = max(np.sqrt(pnx * pnx + pnz * pnz), 1e-300)
            psl = np.sqrt(sx * sx + sz * sz)  # ψ(t): it slides along pn at speed |s|
            psh = _psi_end(sig, ex, ez, slides, pnx, pnz, pl, zx, zz, kap, wa, wb, ca, sa)
            wref = hi - lo
            n_f = 0
            side = 0
            probe = psl == 0.0
            # at most four evaluations per halving of a bracket of h/4 or less: 152 reach
            # 1e-12 h
            for _it in range(160):
                if probe:
                    # from rest (ψ(t) = 0): does it stop at once? (a release whose motion
                    # stops it, theory §4.7: then one return map, not 38)
                    mid = lo + 0.5e-12 * h
                    probe = False
                elif psl > 0.0 and psh < 0.0 and n_f < 3:
                    # kept 0.4 of the tolerance inside: once the estimate has converged, the
                    # next one lands across the root and closes the bracket
                    mid = lo + (hi - lo) * (psl / (psl - psh))
                    mid = min(max(mid, lo + 0.4e-12 * h), hi - 0.4e-12 * h)
                    if not (lo < mid < hi):
                        mid = 0.5 * (lo + hi)
                    n_f += 1
                else:
                    mid = 0.5 * (lo + hi)
                dl = mid - t
                cbx = c0x + c1x * mid
                cbz = c0z + c1z * mid
                zx = sx + 0.5 * dl * (w11 * lax + w12 * laz - cax - cbx)
                zz = sz + 0.5 * dl * (w12 * lax + w22 * laz - caz - cbz)
                kap = 0.5 * dl * mud * (N0 + n1 * mid)
                s2, ex2, ez2, sl2 = _return_map(zx, zz, kap, wa, wb, ca, sa)
                if sl2 and pnx * ex2 + pnz * ez2 > 0.0:
                    lo = mid
                    pnew = s2 * (pnx * ex2 + pnz * ez2) / pl
                    if side == -1:  # hi kept twice: scaled (Anderson–Björck)
                        sc = 1.0 - pnew / psl if psl > 0.0 else 0.5
                        psh *= sc if sc > 0.0 else 0.5
                    psl = pnew
                    side = -1
                else:
                    hi = mid
                    pnew = _psi_end(s2, ex2, ez2, sl2, pnx, pnz, pl, zx, zz, kap, wa, wb, ca,
                                    sa)
                    if side == 1:
                        sc = 1.0 - pnew / psh if psh < 0.0 else 0.5
                        psl *= sc if sc > 0.0 else 0.5
                    psh = pnew
                    side = 1
                if hi - lo <= 0.5 * wref:
                    wref = hi - lo
                    n_f = 0
                if hi - lo <= 1e-12 * h:
                    break
            tb = hi
            dl = tb - t
            cbx = c0x + c1x * tb
            cbz = c0z + c1z * tb
            zx = sx + 0.5 * dl * (w11 * lax + w12 * laz - cax - cbx)
            zz = sz + 0.5 * dl * (w12 * lax + w22 * laz - caz - cbz)
            kap = 0.5 * dl * mud * (N0 + n1 * tb)
            sig, ex, ez, slides = _return_map(zx, zz, kap, wa, wb, ca, sa)
            if slides:
                # a sharp turn without a stop: the sub-step ends here, sliding on
                stop = False
                turned = True
            else:
                sig = 0.0
        elif stop:
            # chatter guard: the pallet stops inside its return map and stays so to the end
            sig = 0.0
        nb = N0 + n1 * tb
        lbx = -mud * nb * ex
        lbz = -mud * nb * ez
        if stop:
            # the force that stops it inside the sub-step: s_b = 0 = z + (δ/2) W λ_b
            # (λ_b = −(2/δ) W⁻¹ z, on the disc up to the root's tolerance)
            if dl > 0.0:
                lbx = -2.0 / dl * (i11 * zx + i12 * zz)
                lbz = -2.0 / dl * (i12 * zx + i22 * zz)
        if nd == 1:
            lbz = 0.0
            ez = 0.0
        sbx = sig * ex
        sbz = sig * ez
        Jx += 0.5 * dl * (lax + lbx)
        Jz += 0.5 * dl * (laz + lbz)
        Ux += 0.5 * dl * (sx + sbx)
        Uz += 0.5 * dl * (sz + sbz)
        t = tb
        sx = sbx
        sz = sbz
        lax = lbx
        laz = lbz
        if sig > 0.0:
            dx = ex
            dz = ez
        if turned:
            n_ph += 1
            n_sub = 0
            if want_ev and n_ev < ev.shape[0]:
                ev[n_ev, 0] = t
                ev[n_ev, 1] = _EV_TURN
            n_ev += 1
        if not stop:
            continue
        n_ph += 1
        n_sub = 0
        if n_ph > _MAX_PHASES:
            # keep it stopped (stuck) for the rest of the step
            stuck = True
            t_left = t
            Jx += l0x * (h - t_left) + 0.5 * l1x * (h * h - t_left * t_left)
            Jz += l0z * (h - t_left) + 0.5 * l1z * (h * h - t_left * t_left)
            t = h
            break
        # decide at the stop: stuck if the holding force is within mu_s N
        hx = f0x + f1x * t
        hz = f0z + f1z * t
        cap = mus * (N0 + n1 * t)
        if t - t_rel <= 1e-9 * h:
            # released and stopped at once: the filtered holding force (which releases) and
            # the support's motion (which stops it) disagree, as with a ringing stiff
            # direction; the pallet keeps its contact, the zero-length slide is not an
            # event, and its onsets for the rest of the step read the force its motion
            # obeys (unfiltered): held to the step's end whatever its force, it was reported
            # stuck at up to 1.39 mu_s N (3D paper rack, mu 0.2, dt 5 ms; theory §4.7)
            stuck = True
            hold = True
            sx = 0.0
            sz = 0.0
            if n_ev > 0:
                n_ev -= 1
            continue
        if hx * hx + hz * hz <= cap * cap:
            stuck = True
            sx = 0.0
            sz = 0.0
            if want_ev and n_ev < ev.shape[0]:
                ev[n_ev, 0] = t
                ev[n_ev, 1] = _EV_STICK
            n_ev += 1
        else:
            cx = c0x + c1x * t
            cz = c0z + c1z * t
            lax, laz = _release(w11, w12, w22, cx, cz, mud * (N0 + n1 * t))
            if nd == 1:
                laz = 0.0
            fn = np.sqrt(lax * lax + laz * laz)
            if fn > 0.0:
                dx = -lax / fn
                dz = -laz / fn
            sx = 0.0
            sz = 0.0
            t_rel = t
            if want_ev and n_ev < ev.shape[0]:
                ev[n_ev, 0] = t
                ev[n_ev, 1] = _EV_TURN
            n_ev += 1
    if stuck:
        lx = l0x + l1x * h
        lz = l0z + l1z * h
        sx = 0.0
        sz = 0.0
    else:
        lx = lax
        lz = laz
    if nd == 1:
        Jz = 0.0
        Uz = 0.0
        lz = 0.0
    return Jx, Jz, stuck, sx, sz, dx, dz, Ux, Uz, lx, lz, n_ev


@_JIT
def _rho(bx, bz, Jx, Jz, stuck0, yx, yz, h, m, g11, g12, g22, Agx, Agz, Jrx, Jrz):
    """Residual of y = ∫a_sup: stuck reference h(I + mG)β − G J + mG A_g − y; sliding
    reference hβ − G(J − J_ref) − y."""
    if stuck0:
        rx = h * (bx + m * (g11 * bx + g12 * bz)) - (g11 * Jx + g12 * Jz) \
            + m * (g11 * Agx + g12 * Agz) - yx
        rz = h * (bz + m * (g12 * bx + g22 * bz)) - (g12 * Jx + g22 * Jz) \
            + m * (g12 * Agx + g22 * Agz) - yz
    else:
        rx = h * bx - (g11 * (Jx - Jrx) + g12 * (Jz - Jrz)) - yx
        rz = h * bz - (g12 * (Jx - Jrx) + g22 * (Jz - Jrz)) - yz
    return rx, rz


@_JIT
def _fprime(bx, bz, r, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1, ag0x, ag0z, ag1x,
            ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd, ev, vscale):
    """F'(β) by one-sided finite differences (step scaled to β)."""
    eps = 1e-7 * (abs(bx) + abs(bz) + vscale / h)
    ra = _pallet_F(bx + eps, bz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                   ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd,
                  ev, False)
    F11 = (ra[0] - r[0]) / eps
    F21 = (ra[1] - r[1]) / eps
    F12 = 0.0
    F22 = 0.0
    if nd == 2:
        rb = _pallet_F(bx, bz + eps, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                       ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd,
                  ev, False)
        F12 = (rb[0] - r[0]) / eps
        F22 = (rb[1] - r[1]) / eps
    return F11, F12, F21, F22


@_JIT
def _jrho(stuck0, h, m, g11, g12, g22, F11, F12, F21, F22, nd):
    """∂ρ/∂β = h(I + mG) − G F' (stuck reference) or h I − G F'."""
    if stuck0:
        a11 = h * (1.0 + m * g11)
        a12 = h * m * g12
        a21 = h * m * g12
        a22 = h * (1.0 + m * g22)
    else:
        a11 = h
        a12 = 0.0
        a21 = 0.0
        a22 = h
    a11 -= g11 * F11 + g12 * F21
    a12 -= g11 * F12 + g12 * F22
    a21 -= g12 * F11 + g22 * F21
    a22 -= g12 * F12 + g22 * F22
    if nd == 1:
        a12 = 0.0
        a21 = 0.0
        a22 = 1.0
    return a11, a12, a21, a22


@_JIT
def _pallet_solve(yx, yz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                  ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd,
                  ev, out, warm, want_D):
    """Impulse of the pallet for the support velocity change ``y`` (eq. 4.1–4.2, β and J
    together). Writes ``out``: [Jx, Jz, D11, D12, D21, D22, stuck, s1x, s1z, d1x, d1z, Ux, Uz,
    lx, lz, bx, bz, n_ev, iterations] (D = ∂J/∂y, written only when ``want_D``). ``warm``:
    start from the β in ``out[15:17]`` (the last solution of this pallet in this step).
    Returns True when the pallet stays stuck through the step with no event (then D = m I).

    A sliding reference first iterates β ← (y + G (J(β) − J_ref)) / h, which contracts
    unless the pallet is about to stop (J then depends strongly on β); Newton's method with a
    finite-difference Jacobian takes over when it does not."""
    Agx = 0.5 * h * (ag0x + ag1x)
    Agz = 0.5 * h * (ag0z + ag1z)
    if nd == 1:
        yz = 0.0
        Agz = 0.0
        ag0z = 0.0
        ag1z = 0.0
        jz = 0.0
        g12 = 0.0
        g22 = 0.0
    bx = yx / h
    bz = yz / h
    if stuck0:
        Jrx = 0.0
        Jrz = 0.0
        # fast path: stuck through the step (the force is m (a_g + a_ref); no G needed)
        l0x = m * (ag0x + bx - 0.5 * h * jx)
        l0z = m * (ag0z + bz - 0.5 * h * jz)
        l1x = m * ((ag1x - ag0x) / h + jx)
        l1z = m * ((ag1z - ag0z) / h + jz)
        f0x = l0x
        f0z = l0z
        f1x = l1x
        f1z = l1z
        if usef:
            f0x = m * (ag0x + 0.5 * (bpx + bx))
            f0z = m * (ag0z + 0.5 * (bpz + bz))
            f1x = m * ((ag1x - ag0x) / h + 0.5 * (bx - bqx) / h)
            f1z = m * ((ag1z - ag0z) / h + 0.5 * (bz - bqz) / h)
        if nd == 1:
            f0z = 0.0
            f1z = 0.0
        if _onset(f0x, f0z, f1x, f1z, N0, (N1 - N0) / h, mus, 0.0, h) < 0.0:
            out[0] = m * (Agx + yx)
            out[1] = m * (Agz + yz)
            out[2] = m
            out[3] = 0.0
            out[4] = 0.0
            out[5] = m if nd == 2 else 0.0
            out[6] = 1.0
            out[7] = 0.0
            out[8] = 0.0
            out[9] = d0x
            out[10] = d0z
            out[11] = 0.0
            out[12] = 0.0
            out[13] = l0x + l1x * h
            out[14] = l0z + l1z * h if nd == 2 else 0.0
            out[15] = bx
            out[16] = bz
            out[17] = 0.0
            out[18] = 0.0
            return True
    else:
        # the reference impulse: mu_d N d0 over the step
        Jrx = -mud * 0.5 * h * (N0 + N1) * d0x
        Jrz = -mud * 0.5 * h * (N0 + N1) * d0z
        if nd == 1:
            Jrz = 0.0
    if warm:
        bx = out[15]
        bz = out[16] if nd == 2 else 0.0
    vscale = h * (abs(ag0x) + abs(ag1x) + abs(ag0z) + abs(ag1z) + mus * (N0 + N1) / m) \
        + abs(yx) + abs(yz) + 1e-300
    tol = 1e-12 * vscale
    r = _pallet_F(bx, bz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                  ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd,
                  ev, False)
    rx, rz = _rho(bx, bz, r[0], r[1], stuck0, yx, yz, h, m, g11, g12, g22, Agx, Agz, Jrx, Jrz)
    nrm = abs(rx) + abs(rz)
    n_it = 0
    if not stuck0:
        # fixed point β = (y + G (J − J_ref)) / h, i.e. β ← β − B⁻¹ρ with B = h I, B then
        # updated by Broyden's rule from each step (ρ is nearly linear in β while the pallet
        # slides on: 4.2 fixed-point steps per local solve on the 150-pallet example before)
        b11 = h
        b12 = 0.0
        b21 = 0.0
        b22 = h
        for _fp in range(8):
            if nrm <= tol:
                break
            n_it += 1
            det = b11 * b22 - b12 * b21
            if abs(det) > 1e-6 * h * h:
                px = -(b22 * rx - b12 * rz) / det
                pz = -(-b21 * rx + b11 * rz) / det
            else:
                px = -rx / h
                pz = -rz / h
            if nd == 1:
                pz = 0.0
            nbx = bx + px
            nbz = bz + pz if nd == 2 else 0.0
            rn = _pallet_F(nbx, nbz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                           ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11,
                           g12, g22, nd, ev, False)
            nrx, nrz = _rho(nbx, nbz, rn[0], rn[1], stuck0, yx, yz, h, m, g11, g12, g22,
                            Agx, Agz, Jrx, Jrz)
            nn = abs(nrx) + abs(nrz)
            if nn > 0.5 * nrm:
                break  # no contraction: Newton below
            ss = px * px + pz * pz
            if ss > 0.0:
                ux = (nrx - rx - (b11 * px + b12 * pz)) / ss
                uz = (nrz - rz - (b21 * px + b22 * pz)) / ss
                b11 += ux * px
                b12 += ux * pz
                b21 += uz * px
                b22 += uz * pz
            bx = nbx
            bz = nbz
            r = rn
            rx = nrx
            rz = nrz
            nrm = nn
    # Newton on β with a finite-difference Jacobian of F, backtracking on |ρ|
    have_fp = False
    F11 = 0.0
    F12 = 0.0
    F21 = 0.0
    F22 = 0.0
    for _it in range(60):
        if nrm <= tol:
            break
        n_it += 1
        F11, F12, F21, F22 = _fprime(bx, bz, r, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud,
                                     N0, N1, ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx,
                                     bqz, usef, g11, g12, g22, nd, ev, vscale)
        have_fp = True
        a11, a12, a21, a22 = _jrho(stuck0, h, m, g11, g12, g22, F11, F12, F21, F22, nd)
        det = a11 * a22 - a12 * a21
        if det == 0.0:
            break
        px = -(a22 * rx - a12 * rz) / det
        pz = -(-a21 * rx + a11 * rz) / det
        alpha = 1.0
        for _ls in range(30):
            nbx = bx + alpha * px
            nbz = bz + alpha * pz
            rn = _pallet_F(nbx, nbz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                           ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11,
                           g12, g22, nd, ev, False)
            nrx, nrz = _rho(nbx, nbz, rn[0], rn[1], stuck0, yx, yz, h, m, g11, g12, g22,
                            Agx, Agz, Jrx, Jrz)
            nn = abs(nrx) + abs(nrz)
            if nn < nrm or nn <= tol:
                break
            alpha *= 0.5
        bx = nbx
        bz = nbz
        r = rn
        rx = nrx
        rz = nrz
        nrm = nn
        have_fp = False
    # final evaluation with the events
    r = _pallet_F(bx, bz, stuck0, s0x, s0z, d0x, d0z, h, m, mus, mud, N0, N1,
                  ag0x, ag0z, ag1x, ag1z, jx, jz, bpx, bpz, bqx, bqz, usef, g11, g12, g22, nd,
                  ev, True)
    if want_D:
        if not have_fp:
            F11, F12, F21, F22 = _fprime(bx, bz, r, stuck0, s0x, s0z, d0x, d0z, h, m, mus,
                                         mud, N0, N1, ag0x, ag0z, ag1x, ag1z, jx, jz, bpx,
                                         bpz, bqx, bqz, usef, g11, g12, g22, nd, ev, vscale)
        # D = F' Jρ⁻¹ (J as a function of y)
        a11, a12, a21, a22 = _jrho(stuck0, h, m, g11, g12, g22, F11, F12, F21, F22, nd)
        det = a11 * a22 - a12 * a21
        if det == 0.0:
            det = 1e-300
        b11 = a22 / det
        b12 = -a12 / det
        b21 = -a21 / det
        b22 = a11 / det
        out[2] = F11 * b11 + F12 * b21
        out[3] = F11 * b12 + F12 * b22
        out[4] = F21 * b11 + F22 * b21
        out[5] = F21 * b12 + F22 * b22
    out[0] = r[0]
    out[1] = r[1]
    out[6] = 1.0 if r[2] else 0.0
    out[7] = r[3]
    out[8] = r[4]
    out[9] = r[5]
    out[10] = r[6]
    out[11] = r[7]
    out[12] = r[8]
    out[13] = r[9]
    out[14] = r[10]
    out[15] = bx
    out[16] = bz
    out[17] = r[11]
    out[18] = n_it
    return False
