"""Granular RFT forces on the 3-segment, 4-flipper swimmer, compiled for the solver.

The elements' positions and velocities for a shape and its rate (`element_geometry`),
each element's drag (Maladen et al. 2009, smoothed sign functions) and its derivative,
and the residual and analytic Jacobian of the 3 body balances and 4 hinge balances
(`assemble`) that `sim/rft.py` solves. Units are the solver's scaled ones (see rft.py);
the packed parameters' indices ``P_*`` are laid out by `sim/kernel_params.py` from the
slots the simulator's effects declare.
"""

from __future__ import annotations

import math

from suds_exp.sim._jit import njit
from suds_exp.sim.effect_params import FlippersEffect
from suds_exp.sim.kernel_params import kernel_layout

# the packed parameters' indices, from the slots the simulator's effects declare
_SLOT = {k: i for k, (i, _) in kernel_layout().items()}
P_CS, P_CF, P_CL = _SLOT["medium.cs"], _SLOT["medium.cf"], _SLOT["medium.cl"]
P_GAMMA, P_EPS, P_MU = _SLOT["medium.gamma"], _SLOT["medium.eps"], _SLOT["medium.mu"]
P_K, P_PRELOAD, P_AMAX = _SLOT["hinges.k"], _SLOT["hinges.preload"], _SLOT["hinges.amax"]
P_TOL, P_MAXIT, P_SFLOOR = _SLOT["solver.tol"], _SLOT["solver.maxit"], _SLOT["solver.sfloor"]
P_LREF, P_SUBSTEPS = _SLOT["solver.lref"], _SLOT["solver.substeps"]
P_ASYM, P_NORMAL = _SLOT["asymmetric_drag.ratio"], _SLOT["drag_anisotropy.normal"]
P_COMPACT, P_CHINGE = _SLOT["medium_compaction.rate"], _SLOT["hinge_damping.c"]
P_FLMODE, P_FLLOCK = _SLOT["flippers.mode"], _SLOT["flippers.locked"]
P_TAU = _SLOT["body_inertia.tau"]
P_SGAIN, P_STALL, P_SDAMP = _SLOT["servo.gain"], _SLOT["servo.stall"], _SLOT["servo.damp"]
P_HFRIC = _SLOT["hinge_friction.torque"]  # flippers 1-4 from here
P_GSIG, P_GCOH = _SLOT["grain_contacts.sigma"], _SLOT["grain_contacts.coherence"]
N_PARTS = 7
HALF_MID = 0.5

FL_FREE, FL_LOCKED, FL_ABSENT = (FlippersEffect.MODES[m] for m in ("free", "locked", "absent"))
N_UNKNOWN = 7


@njit(cache=True)
def element_geometry(phi1, phi2, dphi1, dphi2, ang, body, geo):
    """Positions, axes, hinge columns and shape-driven velocities of all elements.

    body: the elements' description (el_part, el_s, half_mid, fl_seg, fl_hx, fl_hy,
    fl_side; see `run_trials`). geo: array (n_el, 9) filled with px, py, tx, ty, bx, by,
    cx, cy, hinge index (body frame, units of L_ref; b = velocity per unit hinge rate,
    c = velocity from the shape rate).
    """
    el_part, el_s, half_mid, fl_seg, fl_hx, fl_hy, fl_side = body
    c1, s1 = math.cos(phi1), math.sin(phi1)
    c2, s2 = math.cos(-phi2), math.sin(-phi2)
    for e in range(el_part.shape[0]):
        part = el_part[e]
        s = el_s[e]
        hidx = -1
        if part < 3:
            seg = part
            sx, sy = s, 0.0
            ax, ay = 1.0, 0.0
        else:
            hidx = part - 3
            seg = fl_seg[hidx]
            side = fl_side[hidx]
            a = ang[hidx]
            dx, dy = -math.cos(a), side * math.sin(a)
            sx = fl_hx[hidx] + s * dx
            sy = fl_hy[hidx] + s * dy
            ax, ay = dx, dy
        if seg == 0:
            ox, cs, sn, rate = half_mid, c1, s1, dphi1
        elif seg == 2:
            ox, cs, sn, rate = -half_mid, c2, s2, -dphi2
        else:
            ox, cs, sn, rate = 0.0, 1.0, 0.0, 0.0
        rx = cs * sx - sn * sy
        ry = sn * sx + cs * sy
        px = ox + rx
        py = ry
        geo[e, 0] = px
        geo[e, 1] = py
        geo[e, 2] = cs * ax - sn * ay
        geo[e, 3] = sn * ax + cs * ay
        # segment rotation about its joint at `rate` (rad/s per unit shape rate)
        geo[e, 6] = -rate * ry
        geo[e, 7] = rate * rx
        if hidx >= 0:
            hx = ox + cs * fl_hx[hidx] - sn * fl_hy[hidx]
            hy = sn * fl_hx[hidx] + cs * fl_hy[hidx]
            # flipper turns at -side * u relative to its segment (opening is outwards)
            w = -fl_side[hidx]
            geo[e, 4] = -w * (py - hy)
            geo[e, 5] = w * (px - hx)
        else:
            geo[e, 4] = 0.0
            geo[e, 5] = 0.0
        geo[e, 8] = hidx


@njit(cache=True, inline="always")
def _element_drag(w, vp, vn, e2, cf, cl, cs, gam, mu, rho, asym, want_j):
    """Smoothed granular RFT force on one element of weight w moving at (vp, vn) along
    its tangent and normal (scaled units; smoothing e2 = eps^2): (fpar, fper) and, if
    want_j, its derivatives (a11 = dfpar/dvp, a12 = dfpar/dvn, a21, a22) (else zeros).
    ``asym``: the element belongs to a segment, whose parallel drag is rho times larger
    sliding forward (towards the head) than backward."""
    V2 = vp * vp + vn * vn + e2
    V = math.sqrt(V2)
    Ru = math.sqrt(vp * vp + e2)
    Rw = math.sqrt(vn * vn + e2)
    p1 = vp / V
    g = vp / Ru
    sn = Rw / V
    p2 = g * (1.0 - sn)
    q = vn / V
    gq = math.sqrt(1.0 + gam * gam * q * q)
    hq = gam * q / gq
    if asym:
        # rho when sliding forward (towards the head), 1 when sliding backward
        m = 0.5 * (1.0 + rho) + 0.5 * (rho - 1.0) * g
    else:
        m = 1.0
    fpar = -w * ((cf * p1 + cl * p2) * m + mu * vp)
    fper = -w * (cs * hq + mu * vn)
    if not want_j:
        return fpar, fper, 0.0, 0.0, 0.0, 0.0
    V3 = V2 * V
    dp1_p = (vn * vn + e2) / V3
    dp1_n = -vp * vn / V3
    dg_p = e2 / (Ru * Ru * Ru)
    dsn_p = -Rw * vp / V3
    dsn_n = vn / (Rw * V) - Rw * vn / V3
    dp2_p = dg_p * (1.0 - sn) - g * dsn_p
    dp2_n = -g * dsn_n
    dq_p = -vn * vp / V3
    dq_n = (vp * vp + e2) / V3
    dh = gam / (gq * gq * gq)
    dm_p = 0.0
    if asym:
        dm_p = 0.5 * (rho - 1.0) * dg_p
    a11 = -w * ((cf * dp1_p + cl * dp2_p) * m + (cf * p1 + cl * p2) * dm_p + mu)
    a12 = -w * (cf * dp1_n + cl * dp2_n) * m
    a21 = -w * cs * dh * dq_p
    a22 = -w * (cs * dh * dq_n + mu)
    return fpar, fper, a11, a12, a21, a22


@njit(cache=True, inline="always")
def _add_element_jacobian(J, a11, a12, a21, a22, tx, ty, px, py, bxh, byh, h):
    """Add one element's part of the Jacobian: its drag derivatives (a, in its tangent /
    normal frame t = (tx, ty)) through its velocity's dependence on the body twist
    (position px, py) and on hinge h's rate (column b = (bxh, byh); h < 0: none)."""
    nx = -ty
    ny = tx
    # body-frame 2x2: M D M^T with M = [t n]
    b11 = tx * (a11 * tx + a12 * nx) + nx * (a21 * tx + a22 * nx)
    b12 = tx * (a11 * ty + a12 * ny) + nx * (a21 * ty + a22 * ny)
    b21 = ty * (a11 * tx + a12 * nx) + ny * (a21 * tx + a22 * nx)
    b22 = ty * (a11 * ty + a12 * ny) + ny * (a21 * ty + a22 * ny)
    # element velocity Jacobian rows over columns (0, 1, 2, 3+h)
    bx2 = -py
    by2 = px
    # dF/dx = D B  (2 x 4)
    d0x, d0y = b11, b21
    d1x, d1y = b12, b22
    d2x = b11 * bx2 + b12 * by2
    d2y = b21 * bx2 + b22 * by2
    dhx = b11 * bxh + b12 * byh
    dhy = b21 * bxh + b22 * byh
    # rows: B^T (dF/dx); row 2 is the torque px*fy - py*fx
    J[0, 0] += d0x
    J[0, 1] += d1x
    J[0, 2] += d2x
    J[1, 0] += d0y
    J[1, 1] += d1y
    J[1, 2] += d2y
    J[2, 0] += px * d0y - py * d0x
    J[2, 1] += px * d1y - py * d1x
    J[2, 2] += px * d2y - py * d2x
    if h >= 0:
        c = 3 + h
        J[0, c] += dhx
        J[1, c] += dhy
        J[2, c] += px * dhy - py * dhx
        J[c, 0] += bxh * d0x + byh * d0y
        J[c, 1] += bxh * d1x + byh * d1y
        J[c, 2] += bxh * d2x + byh * d2y
        J[c, c] += bxh * dhx + byh * dhy


@njit(cache=True)
def _hinge_rows(x, prm, e2, held, ang, c_hinge, R, J, want_j, qh):
    """The hinge equations' own terms: a held hinge's row becomes u = 0 (the stop takes
    the torque); a free one adds its spring, damping and smoothed Coulomb friction."""
    k = prm[P_K]
    pre = prm[P_PRELOAD]
    for i in range(4):
        c = 3 + i
        if held[i]:
            qh[i] += -k * (ang[i] + pre)
            R[c] = x[c]
            if want_j:
                for j in range(N_UNKNOWN):
                    J[c, j] = 0.0
                J[c, c] = 1.0
        else:
            # Coulomb friction, smoothed like the medium's sign functions
            u = x[c]
            fr = prm[P_HFRIC + i]
            ru = math.sqrt(u * u + e2)
            spring = -k * (ang[i] + pre) - c_hinge * u - fr * u / ru
            R[c] += spring
            qh[i] += spring
            if want_j:
                J[c, c] += -c_hinge - fr * e2 / (ru * ru * ru)


@njit(cache=True)
def assemble(x, geo, el_w, el_part, prm, eps, normal_fac, held, ang, c_hinge, R, J, want_j, qh):
    """Residual R(x) (7,) and, if want_j, Jacobian J (7, 7); qh (7,) gets the hinge
    generalised torques at the current x in 0..3 (used to release a held hinge) and the
    medium's torque about the head and tail joints on the head and tail segments with
    their flippers in 4, 5 (the load of the servos), counter-clockwise positive."""
    cs = prm[P_CS] * normal_fac
    e2 = eps * eps
    for i in range(N_UNKNOWN):
        R[i] = 0.0
        if want_j:
            for j in range(N_UNKNOWN):
                J[i, j] = 0.0
    for i in range(6):
        qh[i] = 0.0
    for e in range(el_part.shape[0]):
        w = el_w[e]
        if w == 0.0:
            continue
        px, py, tx, ty = geo[e, 0], geo[e, 1], geo[e, 2], geo[e, 3]
        h = int(geo[e, 8])
        uh = 0.0
        if h >= 0:
            uh = x[3 + h]
        vx = x[0] - x[2] * py + geo[e, 4] * uh + geo[e, 6]
        vy = x[1] + x[2] * px + geo[e, 5] * uh + geo[e, 7]
        vp = vx * tx + vy * ty
        vn = vx * -ty + vy * tx
        part = el_part[e]
        fpar, fper, a11, a12, a21, a22 = _element_drag(
            w, vp, vn, e2, prm[P_CF], prm[P_CL], cs, prm[P_GAMMA], prm[P_MU], prm[P_ASYM],
            part < 3, want_j,
        )  # fmt: skip
        fx = fpar * tx + fper * -ty
        fy = fpar * ty + fper * tx
        R[0] += fx
        R[1] += fy
        R[2] += px * fy - py * fx
        if part == 0 or part == 3 or part == 4:
            qh[4] += (px - HALF_MID) * fy - py * fx
        elif part == 2 or part == 5 or part == 6:
            qh[5] += (px + HALF_MID) * fy - py * fx
        if h >= 0:
            qq = geo[e, 4] * fx + geo[e, 5] * fy
            R[3 + h] += qq
            qh[h] += qq
        if want_j:
            _add_element_jacobian(J, a11, a12, a21, a22, tx, ty, px, py, geo[e, 4], geo[e, 5], h)
    _hinge_rows(x, prm, e2, held, ang, c_hinge, R, J, want_j, qh)
