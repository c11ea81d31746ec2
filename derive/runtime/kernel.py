"""The compiled solver's routines: plain Python in the subset numba compiles.

With numba installed, ik and ik_batch compile them once per process and solve each pose
(ik_batch: every pose, on every core) in compiled code. They follow the Python solver step by
step, free joints included (a free joint takes its first value; the Python solver's further
values are its business). A pose they cannot settle with the closed forms (a polynomial of
another degree, a root failing the residual test, a split multiple root, a free joint whose
first value gives no solution) goes to the Python solver, so the solutions are its. Real
polynomials are solved in real arithmetic (about four times faster than the complex closed
forms the Python solver uses, which remain the fallback).
"""

from __future__ import annotations

import math
from math import cos, sin, sqrt

import numpy as np

from derive.runtime.arm import _KBUF, _REVOLUTE, DOF, MAX_SOLUTIONS, _kreference, _ksolve
from derive.runtime.closed import (
    _kangle,
    _kquadratic_real,
    _kquartic_real,
    _kwrap,
    _newton,
    _reach_first1,
    _reach_first2,
    _small_residual,
)
from derive.runtime.common import _LOWER, _UPPER
from derive.runtime.constants import (
    _CLAMP_TOL,
    _CLUSTER_TOL,
    _FOLD_TOL,
    _FREE_TOL,
    _LEAD_TOL,
    _MERGE_TOL,
    _ROOT_IMAG_TOL,
    _SEAM,
    _SEAM_SNAP,
    _TWO_PI,
    DEDUP_TOL,
    POSE_TOL,
)


def _kpose_ok(T, i):
    """Whether T[i] is a finite rigid transform within POSE_TOL (as _vpose)."""
    for r in range(4):
        for c in range(4):
            if not math.isfinite(T[i, r, c]):
                return False
    worst = max(abs(T[i, 3, 0]), abs(T[i, 3, 1]), abs(T[i, 3, 2]), abs(T[i, 3, 3] - 1.0))
    for r in range(3):
        for s in range(r, 3):
            dot = T[i, r, 0] * T[i, s, 0] + T[i, r, 1] * T[i, s, 1] + T[i, r, 2] * T[i, s, 2]
            worst = max(worst, abs(dot - 1.0) if r == s else abs(dot))
    det = (
        T[i, 0, 0] * (T[i, 1, 1] * T[i, 2, 2] - T[i, 1, 2] * T[i, 2, 1])
        - T[i, 0, 1] * (T[i, 1, 0] * T[i, 2, 2] - T[i, 1, 2] * T[i, 2, 0])
        + T[i, 0, 2] * (T[i, 1, 0] * T[i, 2, 1] - T[i, 1, 1] * T[i, 2, 0])
    )
    return worst <= POSE_TOL and det > 0.0


def _kcs1(a, b, e, scale):
    """_cs1 as (count, t0, cos t0, sin t0, t1, cos t1, sin t1, status); status 1: the angle
    is free. The cosines and sines come from a, b and e, not from cos and
    sin of the angles: they agree with them to rounding, and cost no transcendental call."""
    rho = sqrt(a * a + b * b)
    if rho * rho <= _FREE_TOL * scale:
        return 0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1 if e * e <= _FREE_TOL * scale else 0
    if rho == 0.0:
        return 0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0
    ratio = e / rho
    if abs(ratio) > 1.0 + _CLAMP_TOL:
        return 0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0
    if abs(ratio) >= 1.0 - _FOLD_TOL:
        ratio = 1.0 if ratio > 0.0 else -1.0
    base = _kangle(b, a)
    sd = sqrt((1.0 - ratio) * (1.0 + ratio))
    delta = _kangle(sd, ratio)
    cb, sb = a / rho, b / rho
    return (
        2,
        base + delta,
        cb * ratio - sb * sd,
        sb * ratio + cb * sd,
        base - delta,
        cb * ratio + sb * sd,
        sb * ratio - cb * sd,
        0,
    )


def _kcs2(a1, b1, e1, a2, b2, e2, det_scale, rhs_scale):
    """_cs2 as (t, cos t, sin t, status); status 1: the angle is free."""
    det = a1 * b2 - a2 * b1
    if abs(det) <= _FREE_TOL * det_scale or e1 * e1 + e2 * e2 <= _FREE_TOL * rhs_scale:
        return 0.0, 1.0, 0.0, 1
    # (cos t, sin t) = (x, y) / det: the direction of (x, y), reversed where det < 0
    sign = math.copysign(1.0, det)
    x, y = sign * (e1 * b2 - b1 * e2), sign * (a1 * e2 - a2 * e1)
    h = sqrt(x * x + y * y)
    if h == 0.0:
        return 0.0, 1.0, 0.0, 0
    return _kangle(y, x), x / h, y / h, 0


def _kcs1r(a, b, e, m00, m01, m02, m10, m11, m12, m20, m21, m22, lo, hi, scale, ref):
    """_cs1_reach as _kcs1 does _cs1; a free angle comes as its one first value."""
    n, t0, c0, s0, t1, c1, s1, status = _kcs1(a, b, e, scale)
    if status == 0:
        return n, t0, c0, s0, t1, c1, s1, 0
    t = _reach_first1(m00, m01, m02, m10, m11, m12, m20, m21, m22, lo, hi, ref)
    return 1, t, cos(t), sin(t), 0.0, 1.0, 0.0, 1


def _kcs2r(a1, b1, e1, a2, b2, e2, det_scale, rhs_scale, A, B, C, lo, hi, ref):
    """_cs2_reach as _kcs2 does _cs2; a free angle comes as its first value."""
    t, c, s, status = _kcs2(a1, b1, e1, a2, b2, e2, det_scale, rhs_scale)
    if status == 0:
        return t, c, s, 0
    t = _reach_first2(A, B, C, lo, hi, ref)
    return t, cos(t), sin(t), 1


def _katan2(y, x):
    """_atan2 as (t, cos t, sin t, status); status 1: the angle is free."""
    h = sqrt(x * x + y * y)
    if abs(y) + abs(x) <= 1e-12 or h == 0.0:
        return 0.0, 1.0, 0.0, 1
    return _kangle(y, x), x / h, y / h, 0


def _ksort(x, n):
    """x[:n] sorted in place (insertion sort: n is at most 4)."""
    for k in range(1, n):
        v = x[k]
        j = k - 1
        while j >= 0 and x[j] > v:
            x[j + 1] = x[j]
            j -= 1
        x[j + 1] = v


def _kroots(p, out, xs):
    """_real_roots for the closed forms (degrees 1, 2 and 4): the count of ascending roots
    written to out, or -1 where _real_roots would need numpy.roots or clusters. xs: scratch."""
    d = len(p) - 1
    size = 0.0
    for k in range(d + 1):
        size = max(size, abs(p[k]))
    if abs(p[0]) <= _LEAD_TOL * size or not (d == 1 or d == 2 or d == 4):
        return -1
    zero = complex(0.0, 0.0)
    if d == 1:
        zs = (complex(-p[1] / p[0]), zero, zero, zero)
    elif d == 2:
        z0, z1 = _kquadratic_real(p[1] / p[0], p[2] / p[0])
        zs = (z0, z1, zero, zero)
    else:
        zs = _kquartic_real(p[1] / p[0], p[2] / p[0], p[3] / p[0], p[4] / p[0])
    n = 0
    for k in range(d):
        z = zs[k]
        if abs(z.imag) <= _ROOT_IMAG_TOL * (1.0 + abs(z)):
            xs[n] = z.real
            n += 1
        elif abs(z.imag) <= _CLUSTER_TOL * (1.0 + abs(z)):
            return -1
    _ksort(xs, n)
    count = 0
    k = 0
    while k < n:
        x = xs[k]
        if k + 1 < n and xs[k + 1] - x <= _MERGE_TOL * (1.0 + abs(x)):
            x = 0.5 * (x + xs[k + 1])
            k += 1
        else:
            x = _newton(p, x)
        if not _small_residual(p, x):
            return -1
        out[count] = x
        count += 1
        k += 1
    return count


def _kpoly(coeffs, angles, free, unit, buf):
    """_poly_angles (angles) or _poly_real: the count of values written to buf[:d]; -2 where
    the polynomial vanishes (the joint is free), -1 where the closed forms do not apply.
    buf (6 d + 1 long, d the degree: _kpoly_slots) is the step's own scratch: the values stay
    there (for angles, their cos and sin at buf[4 d + 1 + k] and buf[5 d + 1 + k]) while
    later steps run."""
    d = len(coeffs) - 1
    size = 0.0
    for k in range(d + 1):
        size = max(size, abs(coeffs[k]))
    if size <= free:
        return -2
    if not (d == 1 or d == 2 or d == 4):
        return -1
    values, p, x = buf[:d], buf[d : 2 * d + 1], buf[2 * d + 1 : 3 * d + 1]
    xs = buf[3 * d + 1 : 4 * d + 1]
    if size == 0.0:
        return 0
    flip = angles and abs(coeffs[0]) < abs(coeffs[d])
    for k in range(d + 1):
        p[k] = coeffs[d - k] if flip else coeffs[k] * (1.0 if angles else unit ** (d - k))
    n = _kroots(p, x, xs)
    if n < 0:
        return -1
    count = 0
    if angles:
        # cos and sin of t = 2 atan(u) (u = 1 / v when flipped) from u itself, kept beside
        # the angles through sorting and merging
        cos_t, sin_t = buf[4 * d + 1 : 5 * d + 1], buf[5 * d + 1 : 6 * d + 1]
        for k in range(n):
            u = x[k]
            t = _kwrap(2.0 * (_kangle(1.0, u) if flip else _kangle(u, 1.0)))
            x[k] = math.pi if math.pi - abs(t) <= 1e-12 else t
            w = 1.0 / (1.0 + u * u)
            cos_t[k] = (u * u - 1.0) * w if flip else (1.0 - u * u) * w
            sin_t[k] = 2.0 * u * w
        for k in range(1, n):  # insertion sort by angle, carrying cos and sin
            t, c, s = x[k], cos_t[k], sin_t[k]
            j = k - 1
            while j >= 0 and x[j] > t:
                x[j + 1], cos_t[j + 1], sin_t[j + 1] = x[j], cos_t[j], sin_t[j]
                j -= 1
            x[j + 1], cos_t[j + 1], sin_t[j + 1] = t, c, s
        for k in range(n):
            if count == 0 or x[k] - values[count - 1] > 1e-12:
                values[count], cos_t[count], sin_t[count] = x[k], cos_t[k], sin_t[k]
                count += 1
    else:
        for k in range(n):
            if count == 0 or abs(x[k] - values[count - 1] / unit) > 1e-12 * (1.0 + abs(x[k])):
                values[count] = x[k] * unit
                count += 1
    return count


def _kdistinct(rows, m, q):
    """Whether q differs from each of rows[:m] by more than DEDUP_TOL (revolute differences
    taken modulo 2 pi), as _finish."""
    for p in range(m):
        same = True
        for j in range(DOF):
            d = abs(q[j] - rows[p, j])
            if _REVOLUTE[j] and d > math.pi:  # both in (-pi, pi]: d < 2 pi
                d = _TWO_PI - d
            if d > DEDUP_TOL:
                same = False
                break
        if same:
            return False
    return True


def _kfinish(found, count, rows, q):
    """_finish: found[:count] wrapped, without repeats, into rows; their number. q: scratch."""
    m = 0
    for r in range(count):
        for j in range(DOF):
            q[j] = found[r, j]
            if _REVOLUTE[j]:
                q[j] = _kwrap(q[j])
                if q[j] < -_SEAM:  # _seam
                    q[j] += _TWO_PI
                if abs(q[j] - math.pi) <= _SEAM_SNAP:
                    q[j] = math.pi
        if _kdistinct(rows, m, q):
            rows[m, :] = q
            m += 1
    return m


def _ksolve_pose(T, i, tol, ref, found, buf):
    """_ksolve on the pose T[i]."""
    return _ksolve(
        T[i, 0, 0],
        T[i, 0, 1],
        T[i, 0, 2],
        T[i, 0, 3],
        T[i, 1, 0],
        T[i, 1, 1],
        T[i, 1, 2],
        T[i, 1, 3],
        T[i, 2, 0],
        T[i, 2, 1],
        T[i, 2, 2],
        T[i, 2, 3],
        tol,
        ref,
        found,
        buf,
    )


def _kvariants(rows, m, ref):
    """_in_limits on rows[:m], in place: the rows inside LIMITS, each revolute joint at its
    variant q + 2 pi k nearest ref; their number."""
    count = 0
    for r in range(m):
        inside = True
        for j in range(DOF):
            x = rows[r, j]
            first = np.ceil((_LOWER[j] - x) / _TWO_PI)
            last = np.floor((_UPPER[j] - x) / _TWO_PI)
            k = 0.0
            if _REVOLUTE[j]:
                k = min(max(np.rint((ref[j] - x) / _TWO_PI), first), last)
            if not first <= k <= last:
                inside = False
                break
            rows[count, j] = x + k * _TWO_PI
        if inside:
            count += 1
    return count


def _kpick(Q, ref, w, wrap):
    """The index of the row of Q nearest ref in weighted squared distance (revolute
    differences wrapped to (-pi, pi] if wrap); the first of equals."""
    best = 0
    least = math.inf
    for r in range(Q.shape[0]):
        total = 0.0
        for j in range(DOF):
            d = Q[r, j] - ref[j]
            if wrap and _REVOLUTE[j]:
                d -= _TWO_PI * np.rint(d / _TWO_PI)
            total += w[j] * d * d
        if total < least:
            best, least = r, total
    return best


def _kone(T, tol, qref, limited):
    """ik's solutions of the pose T[0] as (rows, status): status 0 where they are settled,
    1 where the scalar solver must settle the pose, 2 where T[0] is no valid pose. limited:
    as ik's within_limits (without all_turns)."""
    rows = np.zeros((MAX_SOLUTIONS, DOF))
    if not _kpose_ok(T, 0):
        return rows[:0], 2
    found = np.zeros((MAX_SOLUTIONS, DOF))
    count = _ksolve_pose(T, 0, tol, _kreference(qref), found, np.zeros(_KBUF))
    if count < 0:
        return rows[:0], 1
    m = _kfinish(found, count, rows, np.zeros(DOF))
    if limited:
        m = _kvariants(rows, m, qref)
    return rows[:m], 0


def _kbatch(T, tol, qref, Q, valid, retry):
    """Every pose of T (n, 4, 4): solutions into Q, valid (rows in ik's order, repeats
    dropped); retry[i] where the scalar solver must settle pose i. The poses are split into
    _KPARTS ranges, solved in parallel when compiled; each pose's result depends on that pose
    alone."""
    n = T.shape[0]
    ref = _kreference(qref)
    for part in _prange(_KPARTS):
        found = np.zeros((MAX_SOLUTIONS, DOF))
        buf = np.zeros(_KBUF)
        q = np.zeros(DOF)
        for i in range(part * n // _KPARTS, (part + 1) * n // _KPARTS):
            if not _kpose_ok(T, i):
                continue
            count = _ksolve_pose(T, i, tol, ref, found, buf)
            if count < 0:
                retry[i] = True
                continue
            valid[i, : _kfinish(found, count, Q[i], q)] = True


_KPARTS = 64


# LLVM may fuse multiply-adds, reorder sums and divide by reciprocals in the kernel (about a
# fifth of its time; the results move by rounding only: the certification and every test of
# the compiled solver run on this arithmetic). nan and inf stay IEEE: poses are checked
# with isfinite, and fallbacks test for them.
_FASTMATH = {"contract", "arcp", "nsz", "reassoc"}


# except in the polynomial roots: near a multiple root they move by far more than rounding,
# and whether two roots merge must not depend on how LLVM ordered the arithmetic
_KSTRICT = (
    "_kquadratic",
    "_kcubic_largest",
    "_kquartic",
    "_kquadratic_real",
    "_kquartic_real",
    "_kroots",
    "_newton",
    "_small_residual",
)


_prange = range
