"""Compiled quasi-static granular RFT solver of the 3-segment, 4-flipper swimmer.

Internal units: lengths in units of L_ref (the middle segment length), velocities in
units of L_ref * s, where s = sqrt(|d(phi)/dt|^2 + floor^2) is the shape-rate scale of
the step (rad/s); forces in units of sigma * depth_ref * L_ref (N), torques of that
times L_ref (N mm). RFT forces are homogeneous of degree 0 in velocity once the
smoothing scale is proportional to s, so the problem is solved "at unit shape rate" and
the solution rescaled by s: the model is exactly rate independent unless hinge damping
(which is multiplied by s) or body inertia are on.

Unknowns of every step x = (vx, vy, wz, u1..u4): body twist in the body frame and the
four hinge opening rates. Equations: 3 force/torque balances on the whole robot and 4
torque balances at the hinges (medium + spring [+ damping]); a hinge resting on a stop
with the net torque pushing into it is held (u = 0, the stop takes the torque), which is
decided by a small active-set loop. Solved by damped Newton with an analytic Jacobian,
warm-started from the previous step (body twist extrapolated linearly) and with a capped
step; Levenberg-Marquardt and continuation on the smoothing scale only when Newton fails.
Each step solves at the midpoint of the joint path (phi interpolated linearly between
samples, d(phi)/dt the secant), flipper angles predicted half a step ahead; the pose is
advanced with the SE(2) exponential of the twist.

The forces and their Jacobian are `sim/forces.py`'s; this module solves and steps them.
Per-trial parameters come in a vector `prm` (indices P_*, the slots that
`suds_exp.sim.effect_params` declares), packed by `suds_exp.sim.mechanics.pack_params`
in the scaled units above; body inertia relaxes the
twist towards the quasi-static one with factor 1 - exp(-h / tau) per step.
"""

from __future__ import annotations

import math

import numpy as np

from suds_exp.sim._jit import njit, prange
from suds_exp.sim.forces import (
    FL_ABSENT,
    FL_FREE,
    N_PARTS,
    N_UNKNOWN,
    P_AMAX,
    P_CHINGE,
    P_COMPACT,
    P_EPS,
    P_FLLOCK,
    P_FLMODE,
    P_GCOH,
    P_GSIG,
    P_HFRIC,
    P_LREF,
    P_MAXIT,
    P_NORMAL,
    P_SDAMP,
    P_SFLOOR,
    P_SGAIN,
    P_STALL,
    P_SUBSTEPS,
    P_TAU,
    P_TOL,
    assemble,
    element_geometry,
)

# joint rate below which a servo loaded by the beans counts as stuck (rad/s)
SERVO_STICK_RATE = 0.05
# time constant (s) over which a servo's load follows the medium's torque
SERVO_LOAD_TAU = 0.03
# Newton step caps in scaled units (velocity / (L_ref * shape rate), hinge rate / shape rate)
STEP_BODY = 0.1
STEP_HINGE = 1.0


@njit(cache=True)
def _lin_solve(A, b, out):
    """Solve A out = b (7x7) by Gaussian elimination with partial pivoting; False if singular."""
    n = b.shape[0]
    M = A.copy()
    r = b.copy()
    for col in range(n):
        piv = col
        best = abs(M[col, col])
        for i in range(col + 1, n):
            if abs(M[i, col]) > best:
                best = abs(M[i, col])
                piv = i
        if best < 1e-300:
            return False
        if piv != col:
            for j in range(n):
                tmp = M[col, j]
                M[col, j] = M[piv, j]
                M[piv, j] = tmp
            tmp = r[col]
            r[col] = r[piv]
            r[piv] = tmp
        inv = 1.0 / M[col, col]
        for i in range(col + 1, n):
            f = M[i, col] * inv
            if f != 0.0:
                for j in range(col, n):
                    M[i, j] -= f * M[col, j]
                r[i] -= f * r[col]
    for i in range(n - 1, -1, -1):
        acc = r[i]
        for j in range(i + 1, n):
            acc -= M[i, j] * out[j]
        out[i] = acc / M[i, i]
    return True


@njit(cache=True)
def _norm(v):
    acc = 0.0
    for i in range(v.shape[0]):
        acc += v[i] * v[i]
    return math.sqrt(acc)


@njit(cache=True)
def _assemble(x, fixed, eps, R, J, want_j, qh):
    """`assemble` at x and smoothing scale eps; ``fixed`` holds what stays put during a
    solve, (geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge)."""
    geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge = fixed
    assemble(x, geo, el_w, el_part, prm, eps, normal_fac, held, ang, c_hinge, R, J, want_j, qh)


@njit(cache=True)
def _newton(x, fixed, eps, tol, max_iter, work):
    """Damped Newton from x (modified in place). Returns (residual norm, iterations).

    Trial points are assembled with their Jacobian, so an accepted full step costs one
    assembly."""
    R, Rt, dx, xt, qh = work[0], work[1], work[2], work[3], work[4]
    J = np.empty((N_UNKNOWN, N_UNKNOWN))
    Jt = np.empty((N_UNKNOWN, N_UNKNOWN))
    _assemble(x, fixed, eps, R, J, True, qh)
    nr = _norm(R)
    it = 0
    while nr > tol and it < max_iter:
        it += 1
        for i in range(N_UNKNOWN):
            Rt[i] = -R[i]
        if not _lin_solve(J, Rt, dx):
            return nr, it
        # trust region: the saturating law makes full Newton steps from the far side of
        # a stick transition land far away, so cap the step (scaled units)
        ratio = 0.0
        for i in range(N_UNKNOWN):
            lim = STEP_BODY if i < 3 else STEP_HINGE
            ratio = max(ratio, abs(dx[i]) / lim)
        if ratio > 1.0:
            for i in range(N_UNKNOWN):
                dx[i] /= ratio
        t = 1.0
        accepted = False
        while t > 1e-3:
            for i in range(N_UNKNOWN):
                xt[i] = x[i] + t * dx[i]
            _assemble(xt, fixed, eps, Rt, Jt, t == 1.0, qh)
            nt = _norm(Rt)
            if nt <= (1.0 - 1e-4 * t) * nr:
                accepted = True
                break
            t *= 0.25
        if not accepted:
            # stalled at a kink of the smoothed law: the caller continues on eps
            _assemble(x, fixed, eps, R, J, True, qh)
            return nr, it
        for i in range(N_UNKNOWN):
            x[i] = xt[i]
        if t == 1.0:
            for i in range(N_UNKNOWN):
                R[i] = Rt[i]
                for j in range(N_UNKNOWN):
                    J[i, j] = Jt[i, j]
        else:
            _assemble(x, fixed, eps, R, J, True, qh)
        nr = _norm(R)
    return nr, it


@njit(cache=True)
def _lm(x, fixed, eps, tol, max_iter, work):
    """Levenberg-Marquardt on |R|^2 from x (in place): slower than Newton but does not
    stall on the plateaus of the saturating law. Returns (residual norm, iterations)."""
    R, Rt, dx, xt, qh = work[0], work[1], work[2], work[3], work[4]
    J = np.empty((N_UNKNOWN, N_UNKNOWN))
    Jd = np.empty((N_UNKNOWN, N_UNKNOWN))
    A = np.empty((N_UNKNOWN, N_UNKNOWN))
    g = np.empty(N_UNKNOWN)
    _assemble(x, fixed, eps, R, J, True, qh)
    nr = _norm(R)
    lam = 1e-6
    it = 0
    while nr > tol and it < max_iter:
        it += 1
        for i in range(N_UNKNOWN):
            acc = 0.0
            for k in range(N_UNKNOWN):
                acc += J[k, i] * R[k]
            g[i] = -acc
            for j in range(N_UNKNOWN):
                acc = 0.0
                for k in range(N_UNKNOWN):
                    acc += J[k, i] * J[k, j]
                A[i, j] = acc
        improved = False
        while lam < 1e12:
            for i in range(N_UNKNOWN):
                for j in range(N_UNKNOWN):
                    Jd[i, j] = A[i, j]
                Jd[i, i] += lam * (A[i, i] + 1e-12)
            if _lin_solve(Jd, g, dx):
                for i in range(N_UNKNOWN):
                    xt[i] = x[i] + dx[i]
                _assemble(xt, fixed, eps, Rt, J, False, qh)
                nt = _norm(Rt)
                if nt < nr:
                    improved = True
                    break
            lam *= 4.0
        if not improved:
            break
        lam = max(lam / 5.0, 1e-9)
        for i in range(N_UNKNOWN):
            x[i] = xt[i]
        _assemble(x, fixed, eps, R, J, True, qh)
        nr = _norm(R)
    return nr, it


@njit(cache=True)
def _solve_step(x, geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge, work):
    """Quasi-static solve at unit shape rate: Newton, then continuation if it fails.

    Returns (residual norm, newton iterations, used_continuation)."""
    eps = prm[P_EPS]
    tol = prm[P_TOL]
    max_iter = int(prm[P_MAXIT])
    fixed = (geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge)
    x0 = work[5]
    for i in range(N_UNKNOWN):
        x0[i] = x[i]
    nr, it = _newton(x, fixed, eps, tol, max_iter, work)
    if nr <= tol:
        return nr, it, False
    total = it
    nr, it = _lm(x, fixed, eps, tol, 4 * max_iter, work)
    total += it
    if nr <= tol:
        return nr, total, True
    # continuation on the smoothing scale: solve a smoother problem first, from the
    # warm start, then from rest, then from rest in finer steps; keep the best solution
    best = nr
    xbest = x.copy()
    for attempt in range(3):
        for i in range(N_UNKNOWN):
            x[i] = x0[i] if attempt == 0 else 0.0
        factor = 3.1622776601683795 if attempt < 2 else 1.5
        mult = 1000.0
        while mult > 0.9:
            nr, it = _newton(x, fixed, eps * mult, tol, max_iter, work)
            total += it
            if nr > tol:
                nr, it = _lm(x, fixed, eps * mult, tol, 4 * max_iter, work)
                total += it
            mult /= factor
        if nr < best:
            best = nr
            for i in range(N_UNKNOWN):
                xbest[i] = x[i]
        if nr <= tol:
            break
    if best < nr:
        for i in range(N_UNKNOWN):
            x[i] = xbest[i]
        nr = best
    return nr, total, True


@njit(cache=True)
def _solve_with_stops(x, geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge, work):
    """Solve, then hold hinges pushing into a stop and release held ones pulled away."""
    amax = prm[P_AMAX]
    mode = int(prm[P_FLMODE])
    qh = work[4]
    nr, it, cont = 0.0, 0, False
    for _ in range(6):
        nr, i2, c2 = _solve_step(x, geo, el_w, el_part, prm, normal_fac, held, ang, c_hinge, work)
        it += i2
        cont = cont or c2
        if mode != FL_FREE:
            break
        changed = False
        for i in range(4):
            at_closed = ang[i] <= 1e-9
            at_open = ang[i] >= amax - 1e-9
            if held[i]:
                # qh = generalised torque on the held hinge; the stop can only push
                # the hinge's friction holds it on the stop until the torque beats it
                fr = prm[P_HFRIC + i]
                if (
                    (at_closed and qh[i] > fr)
                    or (at_open and qh[i] < -fr)
                    or not (at_closed or at_open)
                ):
                    held[i] = False
                    changed = True
            else:
                u = x[3 + i]
                if (at_closed and u < 0.0) or (at_open and u > 0.0):
                    held[i] = True
                    x[3 + i] = 0.0
                    changed = True
        if not changed:
            break
    return nr, it, cont


@njit(cache=True)
def _servo_rate(err, load, h, p):
    """Joint rate (rad/s) of a servo with position error ``err`` (rad, command at the
    step's end minus the joint) against the size ``load`` (scaled) of the medium's
    torque on the segment over the last steps.

    Solves damp * v = clip(gain * (err - h v), +-stall) + load_v(v), implicit in the
    error (stable at any gain), where the beans' torque resists the motion like dry
    friction: load_v = -|load| v / sqrt(v^2 + v0^2) (stuck while the drive is weaker).
    The left minus right side grows with v, so bisection on [-v_max, v_max] finds it."""
    gain = p[P_SGAIN]
    stall = p[P_STALL]
    damp = p[P_SDAMP]
    mag = abs(load)
    vmax = (stall + mag) / damp + 1.0
    lo, hi = -vmax, vmax
    for _ in range(48):
        v = 0.5 * (lo + hi)
        drive = gain * (err - h * v)
        if drive > stall:
            drive = stall
        elif drive < -stall:
            drive = -stall
        f = damp * v + mag * v / math.sqrt(v * v + SERVO_STICK_RATE * SERVO_STICK_RATE) - drive
        if f > 0.0:
            hi = v
        else:
            lo = v
    return 0.5 * (lo + hi)


@njit(cache=True)
def _field(modes, lo, hi, wx_, wy_):
    """Sum of the random Fourier modes lo..hi-1 of the bed at world point (wx_, wy_) mm."""
    g = 0.0
    for m in range(lo, hi):
        g += modes[m, 3] * math.cos(modes[m, 0] * wx_ + modes[m, 1] * wy_ + modes[m, 2])
    return g


@njit(cache=True)
def _bed_weights(w_eff, geo, bed_k, scale, half_var, has_bed, X, Y, TH, lref, w_bed):
    """Each element's drag weight on the trial's bed, into ``w_bed`` (n_el,): ``w_eff``
    times the packing ``scale``, the immersion factor of the bed's depth field (second
    half of the modes ``bed_k``, see bed.py) at the body origin (X, Y mm) and the local
    resistance field (first half) at the element's world position (``geo`` in units of
    lref, heading TH rad). ``half_var``: half the log variances (local, depth)."""
    n_el = w_eff.shape[0]
    if not has_bed:
        for e in range(n_el):
            w_bed[e] = w_eff[e]
        return
    nm = bed_k.shape[0] // 2
    hv_local, hv_depth = half_var
    if hv_depth > 0.0:
        scale = scale * math.exp(_field(bed_k, nm, 2 * nm, X, Y) - hv_depth)
    if hv_local == 0.0:
        # no local field to evaluate
        for e in range(n_el):
            w_bed[e] = w_eff[e] * scale
        return
    cth = math.cos(TH)
    sth = math.sin(TH)
    for e in range(n_el):
        if w_eff[e] == 0.0:
            continue
        wx_ = X + lref * (cth * geo[e, 0] - sth * geo[e, 1])
        wy_ = Y + lref * (sth * geo[e, 0] + cth * geo[e, 1])
        w_bed[e] = w_eff[e] * scale * math.exp(_field(bed_k, 0, nm, wx_, wy_) - hv_local)


@njit(cache=True)
def _grain_weights(w_bed, el_part, grain_k, slip, p):
    """Multiply each element's drag weight by its grain-contact factor
    exp(sig z - sig^2 / 2) (mean 1): z mixes its part's and its own unit Gaussian process
    of slip distance, each a sum of random Fourier modes ``grain_k`` (n_el + N_PARTS,
    n_modes, 2: wavenumber per scaled length, phase) at the process's slip ``slip``."""
    sig = p[P_GSIG]
    coh = p[P_GCOH]
    a = math.sqrt(coh)
    b = math.sqrt(1.0 - coh)
    n_el = el_part.shape[0]
    amp = math.sqrt(2.0 / grain_k.shape[1])
    for e in range(n_el):
        q = n_el + el_part[e]
        ze = 0.0
        zq = 0.0
        for m in range(grain_k.shape[1]):
            ze += math.cos(grain_k[e, m, 0] * slip[e] + grain_k[e, m, 1])
            zq += math.cos(grain_k[q, m, 0] * slip[q] + grain_k[q, m, 1])
        z = amp * (a * zq + b * ze)
        w_bed[e] *= math.exp(sig * z - 0.5 * sig * sig)


@njit(cache=True)
def _grain_slip(x, geo, el_part, w_bed, sh, slip):
    """Add each element's slip through the medium over the step to ``slip`` (scaled
    lengths; sh = shape rate x step, so the slip is the scaled speed times sh and does not
    depend on how fast the shape changes); a part slips by its elements' mean."""
    n_el = el_part.shape[0]
    part_slip = np.zeros(N_PARTS)
    part_n = np.zeros(N_PARTS)
    for e in range(n_el):
        if w_bed[e] == 0.0:
            continue
        h = int(geo[e, 8])
        uh = 0.0
        if h >= 0:
            uh = x[3 + h]
        vx = x[0] - x[2] * geo[e, 1] + geo[e, 4] * uh + geo[e, 6]
        vy = x[1] + x[2] * geo[e, 0] + geo[e, 5] * uh + geo[e, 7]
        ds = math.sqrt(vx * vx + vy * vy) * sh
        slip[e] += ds
        part_slip[el_part[e]] += ds
        part_n[el_part[e]] += 1.0
    for q in range(N_PARTS):
        if part_n[q] > 0.0:
            slip[n_el + q] += part_slip[q] / part_n[q]


@njit(cache=True)
def _se2_step(X, Y, TH, wx, wy, wt):
    """Move the world pose (X, Y mm, TH rad) by the SE(2) exponential of the body-frame
    displacement (wx, wy mm, wt rad); returns the new pose and the distance moved (mm)."""
    if abs(wt) > 1e-9:
        sa = math.sin(wt) / wt
        ca = (1.0 - math.cos(wt)) / wt
    else:
        sa = 1.0 - wt * wt / 6.0
        ca = 0.5 * wt
    lx = sa * wx - ca * wy
    ly = ca * wx + sa * wy
    cth = math.cos(TH)
    sth = math.sin(TH)
    return (
        X + (cth * lx - sth * ly),
        Y + (sth * lx + cth * ly),
        TH + wt,
        math.sqrt(wx * wx + wy * wy),
    )


@njit(cache=True)
def _advance_flippers(x, s, h, amax, held, ang, uprev):
    """Free flippers over one step h (s): rates x[3:7] * s (rad/s; zero while held on a
    stop), angles clipped to the stops [0, amax]; updates ang, uprev and held."""
    for i in range(4):
        u = x[3 + i] * s
        if held[i]:
            u = 0.0
        ang[i] = min(max(ang[i] + h * u, 0.0), amax)
        uprev[i] = u
        held[i] = held[i] and (ang[i] <= 1e-9 or ang[i] >= amax - 1e-9)


@njit(cache=True)
def _start_trial(p, el_w, el_part, ang0_k, w_eff, ang, held, uprev, x, xlast):
    """A trial's initial state: element weights ``w_eff`` (flippers removed when absent),
    flipper angles ``ang`` (rad; free ones clipped to the stops, else the locked opening),
    whether each is ``held`` on a stop, zero flipper rates ``uprev`` and solver guesses."""
    amax = p[P_AMAX]
    mode = int(p[P_FLMODE])
    for e in range(el_w.shape[0]):
        w_eff[e] = el_w[e]
        if el_part[e] >= 3 and mode == FL_ABSENT:
            w_eff[e] = 0.0
    for i in range(4):
        if mode == FL_FREE:
            ang[i] = min(max(ang0_k[i], 0.0), amax)
        else:
            ang[i] = p[P_FLLOCK]
        held[i] = mode != FL_FREE or ang[i] <= 1e-9 or ang[i] >= amax - 1e-9
        uprev[i] = 0.0
    for i in range(x.shape[0]):
        x[i] = 0.0
        xlast[i] = 0.0


@njit(cache=True)
def _flipper_midpoints(ang, uprev, held, h, amax, mode, amid):
    """The flipper angles (rad) at the middle of a step h (s), into ``amid``: free ones
    moved half a step at their last rate within the stops; held or locked ones stay."""
    for i in range(4):
        amid[i] = min(max(ang[i] + 0.5 * h * uprev[i], 0.0), amax)
        if mode != FL_FREE:
            amid[i] = ang[i]
        if held[i] and mode == FL_FREE:
            amid[i] = ang[i]


@njit(cache=True)
def _bed_half_var(bed_k):
    """Half the variances of the bed fields' logs (bed.py) from their modes ``bed_k``:
    (local resistance field, depth field)."""
    nm = bed_k.shape[0] // 2
    local = 0.0
    depth = 0.0
    for m in range(nm):
        local += 0.25 * bed_k[m, 3] * bed_k[m, 3]
        depth += 0.25 * bed_k[nm + m, 3] * bed_k[nm + m, 3]
    return local, depth


@njit(cache=True)
def _joint_substep(phi_k, f, fa, fb, servo, r1, r2, load1, load2, h, p):
    """The joint angles (rad) at the start (a1, a2) and end (b1, b2) of the substep from
    fraction ``fa`` to ``fb`` of frame interval f: the given path, or with a servo the
    joints' own motion towards the command under load; returns them and the servo state
    (r1, r2: the joints where the substep ends)."""
    a1 = phi_k[f, 0] + fa * (phi_k[f + 1, 0] - phi_k[f, 0])
    a2 = phi_k[f, 1] + fa * (phi_k[f + 1, 1] - phi_k[f, 1])
    b1 = phi_k[f, 0] + fb * (phi_k[f + 1, 0] - phi_k[f, 0])
    b2 = phi_k[f, 1] + fb * (phi_k[f + 1, 1] - phi_k[f, 1])
    if servo:
        # b = command at the step's end; the joints move from where they are
        a1, a2 = r1, r2
        b1 = r1 + h * _servo_rate(b1 - r1, load1, h, p)
        b2 = r2 + h * _servo_rate(b2 - r2, load2, h, p)
        r1, r2 = b1, b2
    return a1, a2, b1, b2, r1, r2


@njit(cache=True)
def _predict_twist(x, xlast):
    """Linear predictor of the body twist x[0:3] from the last two solves (xlast: the
    one before), the Newton solve's start."""
    for i in range(3):
        xo = x[i]
        x[i] = 2.0 * x[i] - xlast[i]
        xlast[i] = xo


@njit(cache=True)
def _relax_and_move(x, s, lref, relax, h, v0, v1, v2, X, Y, TH, dist):
    """The twist (v0, v1 mm/s, v2 rad/s) relaxed towards the solve's x (scaled by the
    shape rate s) with factor ``relax`` (1: quasi-static), and the pose (X, Y mm, TH rad)
    and distance travelled (in L_ref) moved by it over h s."""
    qs0 = x[0] * s * lref
    qs1 = x[1] * s * lref
    qs2 = x[2] * s
    v0 += relax * (qs0 - v0)
    v1 += relax * (qs1 - v1)
    v2 += relax * (qs2 - v2)
    X, Y, TH, moved = _se2_step(X, Y, TH, v0 * h, v1 * h, v2 * h)
    return v0, v1, v2, X, Y, TH, dist + moved / lref


@njit(cache=True)
def _record_frame(k, i, X, Y, TH, ang, rmax, j1, j2, pose, ang_out, resid, phi_out):
    """Write frame i of trial k: pose, flipper angles, residual and joint angles."""
    pose[k, i, 0] = X
    pose[k, i, 1] = Y
    pose[k, i, 2] = TH
    for j in range(4):
        ang_out[k, i, j] = ang[j]
    resid[k, i] = rmax
    phi_out[k, i, 0] = j1
    phi_out[k, i, 1] = j2


@njit(cache=True)
def _substep(phi_k, f, fa, fb, p, state, trial, body, buf, bed_k, grain_k):
    """One substep of trial interval f, from fraction ``fa`` to ``fb`` of it: the joints
    move (`_joint_substep`), the balance of forces is solved at the midpoint, the twist
    relaxes and the pose moves, free flippers advance.

    state: (r1, r2, load1, load2, v0, v1, v2, X, Y, TH, dist), the servo joints (rad),
    their loads (scaled), the twist (mm/s, rad/s), the pose (mm, rad) and the distance
    travelled (L_ref); trial: (h s, load low-pass factor, relax factor, half the bed's
    log variance, packing scale); buf: the work arrays of `run_trials`. Returns the new
    state and the solve's (scaled residual, iterations, whether continuation was used).
    """
    r1, r2, load1, load2, v0, v1, v2, X, Y, TH, dist = state
    h, lp, relax, half_var, bed_scale = trial
    geo, work, x, xlast, held, ang, amid, uprev, w_eff, w_bed, slip = buf
    lref, amax, mode = p[P_LREF], p[P_AMAX], int(p[P_FLMODE])
    servo = p[P_SGAIN] > 0.0
    grains = p[P_GSIG] > 0.0
    a1, a2, b1, b2, r1, r2 = _joint_substep(phi_k, f, fa, fb, servo, r1, r2, load1, load2, h, p)
    d1 = (b1 - a1) / h
    d2 = (b2 - a2) / h
    s = math.sqrt(d1 * d1 + d2 * d2 + p[P_SFLOOR] * p[P_SFLOOR])
    _flipper_midpoints(ang, uprev, held, h, amax, mode, amid)
    element_geometry(0.5 * (a1 + b1), 0.5 * (a2 + b2), d1 / s, d2 / s, amid, body, geo)
    has_bed = half_var[0] > 0.0 or half_var[1] > 0.0 or bed_scale != 1.0
    _bed_weights(w_eff, geo, bed_k, bed_scale, half_var, has_bed, X, Y, TH, lref, w_bed)
    if grains:
        _grain_weights(w_bed, body[0], grain_k, slip, p)
    _predict_twist(x, xlast)
    normal_fac = p[P_NORMAL] * (1.0 + p[P_COMPACT] * dist)
    nr, it, cont = _solve_with_stops(
        x, geo, w_bed, body[0], p, normal_fac, held, amid, p[P_CHINGE] * s, work
    )
    # the servos feel the medium's torque of this step at the next ones, low-passed: an
    # unfiltered one-step-late load makes the joint chatter (its size depends on the
    # rates it sets)
    load1 += lp * (abs(work[4, 4]) - load1)
    load2 += lp * (abs(work[4, 5]) - load2)
    v0, v1, v2, X, Y, TH, dist = _relax_and_move(x, s, lref, relax, h, v0, v1, v2, X, Y, TH, dist)
    if grains:
        _grain_slip(x, geo, body[0], w_bed, s * h, slip)
    if mode == FL_FREE:
        _advance_flippers(x, s, h, amax, held, ang, uprev)
    return (r1, r2, load1, load2, v0, v1, v2, X, Y, TH, dist), nr, it, cont


@njit(cache=True)
def _trial_buffers(n_el):
    """The work arrays of one trial's integration (`_substep`'s ``buf``)."""
    geo, work = np.empty((n_el, 9)), np.zeros((6, N_UNKNOWN))
    x, xlast = np.zeros(N_UNKNOWN), np.zeros(N_UNKNOWN)
    held, ang, amid, uprev = np.zeros(4, dtype=np.bool_), np.zeros(4), np.zeros(4), np.zeros(4)
    w_eff, w_bed = np.empty(n_el), np.empty(n_el)
    slip = np.zeros(n_el + N_PARTS)
    return (geo, work, x, xlast, held, ang, amid, uprev, w_eff, w_bed, slip)


@njit(cache=True)
def _frame_interval(phi_k, f, nsub, p, state, trial, body, buf, bed_k, grain_k):
    """The ``nsub`` substeps of frame interval f: the new state, the interval's mean twist
    (m0, m1 mm/s, m2 rad/s), the largest scaled residual, iterations and continuations."""
    sum0, sum1, sum2 = 0.0, 0.0, 0.0
    rmax = 0.0
    iters, n_cont = 0, 0
    for sub in range(nsub):
        state, nr, it, cont = _substep(
            phi_k, f, sub / nsub, (sub + 1) / nsub, p, state, trial, body, buf, bed_k, grain_k
        )
        iters += it
        if cont:
            n_cont += 1
        if nr > rmax:
            rmax = nr
        sum0 += state[4]
        sum1 += state[5]
        sum2 += state[6]
    return state, sum0 / nsub, sum1 / nsub, sum2 / nsub, rmax, iters, n_cont


@njit(cache=True)
def _run_trial(k, phi, nf, pose0, ang0, p, el_w, body, dt, bed_k, bed_scale, grain_k, out):
    """Integrate trial k (``nf`` frames) into row k of the outputs ``out`` (pose, vel,
    ang_out, phi_out, resid, iters, n_cont; see `run_trials`), with its own work arrays."""
    pose, vel, ang_out, phi_out, resid, iters, n_cont = out
    el_part = body[0]
    buf = _trial_buffers(el_part.shape[0])
    x, xlast, held, ang, uprev, w_eff = buf[2], buf[3], buf[4], buf[5], buf[7], buf[8]
    nsub = int(p[P_SUBSTEPS])
    h = dt / nsub
    relax = 1.0 if p[P_TAU] <= 0.0 else 1.0 - math.exp(-h / p[P_TAU])
    trial = (h, 1.0 - math.exp(-h / SERVO_LOAD_TAU), relax, _bed_half_var(bed_k), bed_scale)
    _start_trial(p, el_w, el_part, ang0, w_eff, ang, held, uprev, x, xlast)
    servo = p[P_SGAIN] > 0.0
    r1, r2 = phi[k, 0, 0], phi[k, 0, 1]
    X, Y, TH = pose0[0], pose0[1], pose0[2]
    state = (r1, r2, 0.0, 0.0, 0.0, 0.0, 0.0, X, Y, TH, 0.0)
    iters[k] = 0
    n_cont[k] = 0
    _record_frame(k, 0, X, Y, TH, ang, 0.0, r1, r2, pose, ang_out, resid, phi_out)
    last0, last1, last2 = 0.0, 0.0, 0.0
    for f in range(nf - 1):
        state, m0, m1, m2, rmax, it, nc = _frame_interval(
            phi[k], f, nsub, p, state, trial, body, buf, bed_k, grain_k
        )
        iters[k] += it
        n_cont[k] += nc
        # the twist centred on frame f: mean of the frame intervals either side
        vel[k, f, 0] = m0 if f == 0 else 0.5 * (last0 + m0)
        vel[k, f, 1] = m1 if f == 0 else 0.5 * (last1 + m1)
        vel[k, f, 2] = m2 if f == 0 else 0.5 * (last2 + m2)
        last0, last1, last2 = m0, m1, m2
        j1 = state[0] if servo else phi[k, f + 1, 0]
        j2 = state[1] if servo else phi[k, f + 1, 1]
        X, Y, TH = state[7], state[8], state[9]
        _record_frame(k, f + 1, X, Y, TH, ang, rmax, j1, j2, pose, ang_out, resid, phi_out)
    # the last frame keeps the last interval's twist (none for a one-frame trial)
    if nf >= 1:
        vel[k, nf - 1, 0] = last0
        vel[k, nf - 1, 1] = last1
        vel[k, nf - 1, 2] = last2


@njit(cache=True, parallel=True)
def run_trials(
    phi,
    n_steps,
    pose0,
    ang0,
    prm,
    el_part,
    el_s,
    el_w,
    half_mid,
    fl_seg,
    fl_hx,
    fl_hy,
    fl_side,
    dt,
    bed,
    bed_scale,
    grains,
    pose,
    vel,
    ang_out,
    phi_out,
    resid,
    iters,
    n_cont,
):
    """Integrate prescribed joint trajectories for a batch of trials.

    phi: (n_trials, n_frames, 2) rad, sampled every dt s; n_steps[k] frames used by
    trial k: the joint angles, or the servo command when prm[k, P_SGAIN] > 0. pose0
    (n_trials, 3) mm, rad; ang0 (n_trials, 4) rad; prm (n_trials, n_params); bed
    (n_trials, n_modes, 4) random Fourier modes of the bed (kx, ky in 1/mm, phase,
    amplitude; see bed.py) and bed_scale (n_trials,) its trial factor; grains (n_trials,
    n_el + N_PARTS, n_modes, 2) the grain contacts' random modes in slip distance (see
    bed.py; used when prm[k, P_GSIG] > 0). Outputs (filled):
    phi_out (n_trials, n_frames, 2) realised joint angles (rad); pose (n_trials,
    n_frames, 3) world x, y (mm), theta;
    vel (n_trials, n_frames, 3) body twist vx, vy (mm/s), wz (rad/s), centred on the
    frames; ang_out (n_trials, n_frames, 4); resid (n_trials, n_frames) max scaled
    residual of the solves ending at each frame; iters, n_cont (n_trials,) totals.

    Trials are independent (each has its own work arrays), so they run in parallel on
    numba's threads; each trial's arithmetic, and so its result, is the same whatever
    the number of threads.
    """
    body = (el_part, el_s, half_mid, fl_seg, fl_hx, fl_hy, fl_side)
    out = (pose, vel, ang_out, phi_out, resid, iters, n_cont)
    for k in prange(phi.shape[0]):
        # k as int64: prange's index is unsigned, and numba compiled _run_trial (and what it
        # calls with k) once for each integer type, about 1 s of every fresh install
        _run_trial(
            np.int64(k), phi, n_steps[k], pose0[k], ang0[k], prm[k], el_w, body, dt, bed[k],
            bed_scale[k], grains[k], out,
        )  # fmt: skip


@njit(cache=True)
def solve_twists(
    phis, dphis, prm, el_part, el_s, el_w, half_mid, fl_seg, fl_hx, fl_hy, fl_side, out, res
):
    """Quasi-static body twists at fixed shapes with flippers held (local connection).

    phis (n, 2) rad, dphis (n, 2) rad/s; out (n, 3) gets vx, vy (mm/s), wz (rad/s);
    res (n,) the scaled residual. Each solve starts from rest (no warm start), so results
    do not depend on the order of points.
    """
    n_el = el_part.shape[0]
    geo = np.empty((n_el, 9))
    work = np.zeros((6, N_UNKNOWN))
    x = np.zeros(N_UNKNOWN)
    held = np.ones(4, dtype=np.bool_)
    ang = np.zeros(4)
    lref = prm[P_LREF]
    w_eff = el_w.copy()
    mode = int(prm[P_FLMODE])
    for e in range(n_el):
        if el_part[e] >= 3 and mode == FL_ABSENT:
            w_eff[e] = 0.0
    for i in range(4):
        ang[i] = prm[P_FLLOCK]
    body = (el_part, el_s, half_mid, fl_seg, fl_hx, fl_hy, fl_side)
    for n in range(phis.shape[0]):
        d1, d2 = dphis[n, 0], dphis[n, 1]
        s = math.sqrt(d1 * d1 + d2 * d2 + prm[P_SFLOOR] * prm[P_SFLOOR])
        element_geometry(phis[n, 0], phis[n, 1], d1 / s, d2 / s, ang, body, geo)
        for i in range(N_UNKNOWN):
            x[i] = 0.0
        nr, _, _ = _solve_step(x, geo, w_eff, el_part, prm, prm[P_NORMAL], held, ang, 0.0, work)
        out[n, 0] = x[0] * s * lref
        out[n, 1] = x[1] * s * lref
        out[n, 2] = x[2] * s
        res[n] = nr
