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

from derive.runtime.arm import (
    _KBUF,
    _REVOLUTE,
    _RR_LENGTH,
    _RR_PIVOTS,
    _RR_SPLITS,
    _RR_SPURIOUS,
    _RR_SPURIOUS_COUNT,
    DOF,
    MAX_SOLUTIONS,
    _kreference,
    _ksolve,
    _rr_fill,
)
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
from derive.runtime.common import _FAR, _LOWER, _UPPER
from derive.runtime.constants import (
    _CLAMP_TOL,
    _CLUSTER_TOL,
    _FOLD_TOL,
    _FREE_TOL,
    _LEAD_TOL,
    _MERGE_TOL,
    _ROOT_IMAG_TOL,
    _RR_CLUSTER_TOL,
    _RR_COND_LIMIT,
    _RR_GOOD,
    _RR_IMAG_TOL,
    _RR_MOEBIUS,
    _RR_NEWTON_DONE,
    _RR_NEWTON_REACH,
    _RR_NEWTON_STEPS,
    _RR_NULL2_TOL,
    _RR_PAIR_TOL,
    _RR_PATH,
    _RR_RANK_TOL,
    _RR_SHIFT45,
    _SEAM,
    _SEAM_SNAP,
    _TWO_PI,
    DEDUP_TOL,
    POSE_TOL,
)
from derive.runtime.general import _RR_H45, _RR_MIX, _RR_MONOMIAL_RULES, _RR_MOTIONS


def _kpose_ok(T, i):
    """Whether T[i] is a finite rigid transform within POSE_TOL, within _FAR of the base (as
    _vpose; ik's Python solver answers a far pose with no row)."""
    for r in range(4):
        for c in range(4):
            if not math.isfinite(T[i, r, c]):
                return False
    if max(abs(T[i, 0, 3]), abs(T[i, 1, 3]), abs(T[i, 2, 3])) > _FAR:
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
    dropped); retry[i] where the scalar solver must settle pose i. qref (1, DOF): one
    reference for every pose, or (n, DOF): one per pose (a redundant arm's free values). The
    poses are split into _KPARTS ranges, solved in parallel when compiled; each pose's result
    depends on that pose alone."""
    n = T.shape[0]
    shared = _kreference(qref[0])
    each = qref.shape[0] > 1
    for part in _prange(_KPARTS):
        found = np.zeros((MAX_SOLUTIONS, DOF))
        buf = np.zeros(_KBUF)
        q = np.zeros(DOF)
        for i in range(part * n // _KPARTS, (part + 1) * n // _KPARTS):
            if not _kpose_ok(T, i):
                continue
            ref = _kreference(qref[i]) if each else shared
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
    "_keigenvalues",
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


def _kgeneral(flanges, out):
    """The general method's solutions of one pose into out (6 angles per row, at most
    out.size // 6, the first ones found where a self-motion gives more, as the Python solver
    keeps its first MAX_SOLUTIONS): their count, or -1 where the Python solver must settle
    the pose (no solution polished, or an odd number: its search). The steps of
    derive/runtime/general.py, in the same order (best split, fallback split, rescue), with
    small routines of its own instead of LAPACK."""
    limit = out.size // 6
    splits = len(flanges)
    targets = np.zeros((splits, 4, 4))
    for k in range(splits):
        flange = flanges[k]
        targets[k, 3, 3] = 1.0
        for r in range(3):
            for c in range(4):
                targets[k, r, c] = flange[4 * r + c]
            targets[k, r, 3] /= _RR_LENGTH
    count = 0
    doubt = True
    for k in range(splits):
        count, doubt = _krr_split(k, targets[k], targets[k], out, count)
        if count == limit:
            return count
        if not doubt and count % 2 == 0:
            break
    if doubt or count == 0 or count % 2:
        moved = np.zeros((4, 4))
        for m in range(_RR_MOTIONS.shape[0]):
            for k in range(splits):
                for r in range(4):
                    for c in range(4):
                        total = 0.0
                        for i in range(4):
                            total += targets[k, r, i] * _RR_MOTIONS[m, i, c]
                        moved[r, c] = total
                count, _ = _krr_split(k, targets[k], moved, out, count)
                if count == limit:
                    return count
    perturbed = False
    for k in range(splits):
        perturbed = perturbed or _krr_perturbed(k)
    if 0 < count < limit and perturbed:
        count = _krr_partners(targets[0], out, count)
    # (an odd count: the Python solver's search looks for the one missed)
    return count if count > 0 and count % 2 == 0 else -1


def _krr_perturbed(k):
    """Whether split k solves a perturbed table (the arm's own pencils are singular)."""
    fill = np.array(_RR_SPLITS[k][1])
    true = np.array(_RR_SPLITS[k][2])
    for i in range(6):
        for j in range(4):
            if fill[i, j] != true[i, j]:
                return True
    return False


def _krr_partners(F, out, count):
    """_rr_partners in the kernel: the wrist-flip partners of out's count rows, polished on
    split 0's frame, added where new until out is full; the new count."""
    limit = out.size // 6
    true = np.zeros((7, 4))
    true[:6] = np.array(_RR_SPLITS[0][2])
    true[6, 0], true[6, 1] = _RR_SPLITS[0][3]
    slider = (3 if _RR_SPLITS[0][0] else 2) if true[6, 0] != 0.0 else -1
    rows = count
    for r in range(rows):
        for first in (0, 3):
            if first <= slider < first + 3 or count == limit:
                continue
            p = out[6 * r : 6 * r + 6].copy()
            p[first] += math.pi
            p[first + 1] = -p[first + 1]
            p[first + 2] += math.pi
            q = -p[::-1] if _RR_SPLITS[0][0] else p
            if slider >= 0:
                q[2] /= _RR_LENGTH
            q, error = _krr_steps(true, F, q, False)
            if error > _RR_GOOD:
                continue
            if slider >= 0:
                q[2] *= _RR_LENGTH
            if _RR_SPLITS[0][0]:
                q = -q[::-1]
            count = _krr_add(q, out, count)
    return count


def _krr_add(q, out, count):
    """q added to out's count rows unless there already (angles modulo 2 pi, within 1e-7):
    the new count."""
    for r in range(count):
        gap = 0.0
        for j in range(6):
            gap = max(gap, abs((q[j] - out[6 * r + j] + math.pi) % _TWO_PI - math.pi))
        if gap <= 1e-7:
            return count
    out[6 * count : 6 * count + 6] = q
    return count + 1


def _krr_split(k, F, moved, out, count):
    """_rr_split in the kernel: split k's polished candidates for the target F (found from
    the pose `moved`) added to out[6 count:] where new, until out is full; (the new count,
    doubt)."""
    limit = out.size // 6
    # rows 0-5: the split's rows; row 6: its slide (1.0, theta3 where joint 3 slides)
    fill = np.zeros((7, 4))
    true = np.zeros((7, 4))
    fill[:6] = np.array(_RR_SPLITS[k][1])
    true[:6] = np.array(_RR_SPLITS[k][2])
    fill[6, 0], fill[6, 1] = _RR_SPLITS[k][3]
    true[6, 0], true[6, 1] = _RR_SPLITS[k][3]
    perturbed = _krr_perturbed(k)
    values = np.zeros(490)
    _rr_fill(
        k, moved[0, 2], moved[1, 2], moved[2, 2], moved[0, 3], moved[1, 3], moved[2, 3], values
    )
    cands = np.zeros((8 * _KRR_MAX, 6))
    extra = np.zeros(8 * _KRR_MAX, dtype=np.bool_)
    n, doubt = _krr_candidates(values, moved, fill, cands, extra, k)
    for c in range(n):
        q = cands[c].copy()
        if perturbed:
            for t in _RR_PATH:
                q, _ = _krr_steps(_krr_between(fill, true, t), F, q, False)
        q, error, damped = _krr_newton(true, F, q, extra[c])
        if damped and not perturbed and not extra[c]:
            doubt = True
        if error > _RR_GOOD:
            if not perturbed and not extra[c]:
                doubt = True
            continue
        if true[6, 0] != 0.0:  # a sliding joint 3, in the arm's lengths
            q[2] *= _RR_LENGTH
        if _RR_SPLITS[k][0]:  # the reversed chain: joint j is -q_{7-j}
            q = -q[::-1]
        count = _krr_add(q, out, count)
        if count == limit:
            return count, doubt
    return count, doubt


# the most candidates of one split: 16 eigenvalues, each with up to 3 null vectors (one, and
# two from a plane) and 2 values of theta2 (room for 8 times as many: the extras too)
_KRR_MAX = 16


def _krr_candidates(values, F, rows, out, extra, k):
    """_rr_candidates in the kernel (split k): the count of candidate joint vectors written
    to out, whether the answer is in doubt (clusters, or no usable pencil), and in extra which
    candidates come from nearly real pairs."""
    P0 = values[:126].reshape(14, 9)
    Ps = values[126:252].reshape(14, 9)
    Pc = values[252:378].reshape(14, 9)
    Q = values[378:].reshape(14, 8)
    N = _knull_left(Q)
    if N.shape[0] == 0:
        return 0, True
    # N (P0 - Pc) H45, N (2 Ps) H45, N (P0 + Pc) H45
    A6 = np.zeros((6, 9))
    B6 = np.zeros((6, 9))
    C6 = np.zeros((6, 9))
    for i in range(6):
        for m in range(9):
            a = 0.0
            b = 0.0
            c = 0.0
            for r in range(14):
                a += N[i, r] * (P0[r, m] - Pc[r, m])
                b += N[i, r] * 2.0 * Ps[r, m]
                c += N[i, r] * (P0[r, m] + Pc[r, m])
            for col in range(9):
                h = _RR_H45[m, col]
                if h != 0.0:
                    A6[i, col] += a * h
                    B6[i, col] += b * h
                    C6[i, col] += c * h
    best = math.inf
    A = np.zeros((12, 12))
    B = np.zeros((12, 12))
    C = np.zeros((12, 12))
    moebius = _RR_MOEBIUS[0]
    for candidate in _RR_MOEBIUS:
        Am, Bm, Cm = _krr_pencil(A6, B6, C6, candidate)
        ratio = _kpivot_ratio(Am)
        if ratio < best:
            A, B, C, moebius, best = Am, Bm, Cm, candidate, ratio
        if ratio < _RR_COND_LIMIT:
            break
    if not best < 1e16:
        return 0, True
    K = np.zeros((24, 24))
    for i in range(12):
        K[i, 12 + i] = 1.0
    rhs = np.zeros((12, 24))
    rhs[:, :12] = -C
    rhs[:, 12:] = -B
    if not _ksolve_into(A, rhs):
        return 0, True
    K[12:, :] = rhs
    wr, wi, ok = _keigenvalues(_kdeflated(K, k, moebius))
    if not ok:
        return 0, True
    ma, mb, mc, md = moebius
    reach = abs(F[0, 3]) + abs(F[1, 3]) + abs(F[2, 3])  # (|d3| beyond: spurious, as in Python)
    for i in range(6):
        reach += abs(rows[i, 0]) + abs(rows[i, 1])
    reals = np.zeros(24)
    n_real = 0
    extras = np.zeros(48)  # (nearly real pairs, at Re -+ Im: as in Python)
    n_extra = 0
    for i in range(wr.size):
        size = 1.0 + math.hypot(wr[i], wi[i])
        if abs(wi[i]) <= _RR_IMAG_TOL * size:
            y = wr[i]
            if rows[6, 0] == 0.0 or abs(ma * y + mb) <= reach * abs(mc * y + md):
                reals[n_real] = y
                n_real += 1
        elif _RR_IMAG_TOL * size < wi[i] <= _RR_PAIR_TOL * size:
            for y in (wr[i] - wi[i], wr[i] + wi[i]):
                if rows[6, 0] == 0.0 or abs(ma * y + mb) <= reach * abs(mc * y + md):
                    extras[n_extra] = y
                    n_extra += 1
    reals = np.sort(reals[:n_real])
    extras = np.sort(extras[:n_extra])
    doubt = False
    count = 0
    start = 0
    V = np.zeros((3, 12))
    while start < n_real + n_extra:  # the clusters of real values, then each extra value
        stop = start + 1
        is_extra = start >= n_real
        if is_extra:  # (on their own: they put nothing in doubt)
            y = extras[start - n_real]
        else:
            while stop < n_real and reals[stop] - reals[stop - 1] <= _RR_CLUSTER_TOL * (
                1.0 + abs(reals[stop])
            ):
                stop += 1
            y = reals[start:stop].mean()
        clustered = stop - start > 1
        start = stop
        if rows[6, 0] != 0.0:  # joint 3 slides: x3 is d3
            theta3 = (ma * y + mb) / (mc * y + md)
        else:
            theta3 = 2.0 * math.atan2(ma * y + mb, mc * y + md)
        S = A * (y * y) + B * y + C
        nv, plane = _knull_right(S, V)
        if clustered or plane:
            doubt = doubt or not is_extra
            if nv == 2:
                nv = 1 + _krr_unmix(V)
        for v in range(nv):
            t4 = _krr_ratio_angle(V[v], 3)
            t5 = _krr_ratio_angle(V[v], 1)
            pairs, t1a, t2a, t1b, t2b = _krr_joints12(rows, F, theta3, t4, t5)
            for p in range(pairs):
                if count == out.shape[0]:
                    return count, doubt or not is_extra
                t1 = t1a if p == 0 else t1b
                t2 = t2a if p == 0 else t2b
                out[count, 0] = t1
                out[count, 1] = t2
                out[count, 2] = theta3
                out[count, 3] = t4
                out[count, 4] = t5
                out[count, 5] = _krr_theta6(rows, F, t1, t2, theta3, t4, t5)
                extra[count] = is_extra
                count += 1
    return count, doubt


def _krr_pencil(A6, B6, C6, moebius):
    """_rr_pencil in the kernel."""
    a, b, c, d = moebius
    out = np.zeros((3, 12, 12))
    for i in range(6):
        for j in range(9):
            x, y, z = A6[i, j], B6[i, j], C6[i, j]
            values = (
                a * a * x + a * c * y + c * c * z,
                2.0 * a * b * x + (a * d + b * c) * y + 2.0 * c * d * z,
                b * b * x + b * d * y + d * d * z,
            )
            for m in range(3):
                out[m, i, j] = values[m]
                out[m, 6 + i, 3 + j] = values[m]
    return out[0], out[1], out[2]


def _kpivot_ratio(M):
    """The ratio of the largest to the smallest pivot of M's LU factorisation with partial
    pivoting: a cheap stand-in for its condition number (inf where singular)."""
    A = M.copy()
    n = A.shape[0]
    big = 0.0
    small = math.inf
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        if A[p, k] == 0.0:
            return math.inf
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        big = max(big, abs(A[k, k]))
        small = min(small, abs(A[k, k]))
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
    return big / small


def _ksolve_into(M, X):
    """X := M^-1 X by Gaussian elimination with partial pivoting; False where M is singular."""
    A = M.copy()
    n = A.shape[0]
    m = X.shape[1]
    for k in range(n):
        p = k
        for i in range(k + 1, n):
            if abs(A[i, k]) > abs(A[p, k]):
                p = i
        if A[p, k] == 0.0:
            return False
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
            for j in range(m):
                X[k, j], X[p, j] = X[p, j], X[k, j]
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            if f != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                for j in range(m):
                    X[i, j] -= f * X[k, j]
    for k in range(n - 1, -1, -1):
        for j in range(m):
            total = X[k, j]
            for i in range(k + 1, n):
                total -= A[k, i] * X[i, j]
            X[k, j] = total / A[k, k]
    return True


def _knull_left(Q):
    """Rows spanning the left null space of Q (14 x 8), six of them (fixed combinations
    where Q's rank is below 8): the last columns of the orthogonal factor of Q's QR
    factorisation with column pivoting (Householder reflections)."""
    m, n = Q.shape
    R = Q.copy()
    U = np.eye(m)
    norms = np.zeros(n)
    top = 0.0
    # (loops, not array expressions: each of those allocates a temporary, and their
    # allocations took most of this routine's time)
    for j in range(n):
        total = 0.0
        for i in range(m):
            total += R[i, j] * R[i, j]
        norms[j] = math.sqrt(total)
        top = max(top, norms[j])
    rank = 0
    v = np.zeros(m)
    for k in range(n):
        p = k
        for j in range(k + 1, n):
            if norms[j] > norms[p]:
                p = j
        if norms[p] <= _RR_RANK_TOL * max(top, 1.0):
            break
        if p != k:
            for i in range(m):
                R[i, k], R[i, p] = R[i, p], R[i, k]
            norms[k], norms[p] = norms[p], norms[k]
        # the reflection taking R[k:, k] onto the axis
        alpha = 0.0
        for i in range(k, m):
            alpha += R[i, k] * R[i, k]
        alpha = math.sqrt(alpha)
        if R[k, k] > 0.0:
            alpha = -alpha
        vv = 0.0
        for i in range(k, m):
            v[i] = R[i, k]
        v[k] -= alpha
        for i in range(k, m):
            vv += v[i] * v[i]
        if vv == 0.0:
            rank += 1
            continue
        for j in range(k, n):
            f = 0.0
            for i in range(k, m):
                f += v[i] * R[i, j]
            f = 2.0 * f / vv
            for i in range(k, m):
                R[i, j] -= f * v[i]
        for i in range(m):  # U := U H (columns of U: the orthogonal factor)
            f = 0.0
            for c in range(k, m):
                f += U[i, c] * v[c]
            f = 2.0 * f / vv
            for c in range(k, m):
                U[i, c] -= f * v[c]
        for j in range(k + 1, n):
            total = 0.0
            for i in range(k + 1, m):
                total += R[i, j] * R[i, j]
            norms[j] = math.sqrt(total)
        rank += 1
    free = m - rank
    N = np.zeros((free, m))
    for i in range(free):
        N[i, :] = U[:, rank + i]
    if free <= 6:
        return N
    out = np.zeros((6, m))
    for i in range(6):
        for r in range(free):
            out[i, :] += _RR_MIX[i, r] * N[r, :]
    return out


def _knull_right(S, V):
    """Null vectors of S (12 x 12) into V's rows by Gaussian elimination with complete
    pivoting: (their number, whether the null space looks two-dimensional). One vector from
    the smallest pivot; where the second smallest pivot is below _RR_NULL2_TOL of the
    largest, two (a basis of the plane)."""
    A = S.copy()
    n = 12
    cols = np.arange(n)
    for k in range(n):
        p, q = k, k
        big = 0.0
        for i in range(k, n):
            for j in range(k, n):
                if abs(A[i, j]) > big:
                    big, p, q = abs(A[i, j]), i, j
        if p != k:
            for j in range(n):
                A[k, j], A[p, j] = A[p, j], A[k, j]
        if q != k:
            for i in range(n):
                A[i, k], A[i, q] = A[i, q], A[i, k]
            cols[k], cols[q] = cols[q], cols[k]
        if A[k, k] == 0.0:
            continue
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
            A[i, k] = 0.0
    top = abs(A[0, 0])
    plane = abs(A[n - 2, n - 2]) <= _RR_NULL2_TOL * top
    dims = 2 if plane else 1
    for d in range(dims):
        x = np.zeros(n)
        x[n - 1 - d] = 1.0  # the free unknown(s) of the last pivots
        for k in range(n - 1 - dims, -1, -1):
            total = 0.0
            for j in range(k + 1, n):
                total += A[k, j] * x[j]
            x[k] = -total / A[k, k] if A[k, k] != 0.0 else 0.0
        for j in range(n):
            V[d, cols[j]] = x[j]
    return dims, plane


def _krr_unmix(V):
    """_rr_unmix in the kernel: the (one or two) monomial vectors of the plane of V[0] and
    V[1] written to V[1] and V[2] (V[0] stays); their number."""
    v1 = V[0].copy()
    v2 = V[1].copy()
    bp, bq, br = 0.0, 0.0, 0.0
    size = -1.0
    for rule in _RR_MONOMIAL_RULES:
        i, j, k, l = rule
        p = v1[i] * v1[j] - v1[k] * v1[l]
        q = v1[i] * v2[j] + v2[i] * v1[j] - v1[k] * v2[l] - v2[k] * v1[l]
        r = v2[i] * v2[j] - v2[k] * v2[l]
        if abs(p) + abs(q) + abs(r) > size:
            bp, bq, br, size = p, q, r, abs(p) + abs(q) + abs(r)
    root = math.sqrt(max(bq * bq - 4.0 * bp * br, 0.0))
    n = 0
    for sign in (1.0, -1.0):
        h = -bq - sign * root if bq >= 0.0 else -bq + sign * root
        if abs(bp) >= abs(br):
            u, w = h, 2.0 * bp
        else:
            u, w = 2.0 * br, h
        if abs(u) + abs(w) > 0.0:
            V[1 + n] = u * v1 + w * v2
            n += 1
    return n


def _krr_ratio_angle(v, step):
    """_rr_ratio_angles in the kernel: step 3 gives theta4, step 1 theta5 (with their
    _RR_SHIFT45)."""
    across = 0.0
    low = 0.0
    high = 0.0
    for i in range(4):
        for j in range(3):
            k = 3 * i + j
            if (step == 3 and i < 3) or (step == 1 and j < 2):
                lo, hi = v[k], v[k + step]
                across += lo * hi
                low += lo * lo
                high += hi * hi
    shift = _RR_SHIFT45[0] if step == 3 else _RR_SHIFT45[1]
    if low >= high:
        return 2.0 * math.atan2(across, low) + shift
    return 2.0 * math.atan2(high, across) + shift


def _krr_link(t, rows, i, M):
    """M := M A_i(t) (standard DH row i: d, a, cos alpha, sin alpha; row 6: the slide, where
    joint 3 (i = 2) is Rz(theta3) Tz(t) X3 with theta3 = rows[6, 1])."""
    d, a, ca, sa = rows[i, 0], rows[i, 1], rows[i, 2], rows[i, 3]
    if i == 2 and rows[6, 0] != 0.0:
        d = t
        t = rows[6, 1]
    ct, st = cos(t), sin(t)
    for r in range(4):
        m0, m1, m2 = M[r, 0], M[r, 1], M[r, 2]
        M[r, 0] = m0 * ct + m1 * st
        M[r, 1] = (-m0 * st + m1 * ct) * ca + m2 * sa
        M[r, 2] = -(-m0 * st + m1 * ct) * sa + m2 * ca
        M[r, 3] += (m0 * ct + m1 * st) * a + m2 * d


def _krr_joints12(rows, F, t3, t4, t5):
    """_rr_joints12 in the kernel: (count, t1, t2, t1', t2')."""
    M = np.eye(4)
    _krr_link(t3, rows, 2, M)
    _krr_link(t4, rows, 3, M)
    _krr_link(t5, rows, 4, M)
    d2, a2, ca2, sa2 = rows[1, 0], rows[1, 1], rows[1, 2], rows[1, 3]
    a1, ca1, sa1 = rows[0, 1], rows[0, 2], rows[0, 3]
    # (scalars, not small arrays: each array is an allocation)
    gl0, gl1, gl2 = M[0, 2], ca2 * M[1, 2] - sa2 * M[2, 2], sa2 * M[1, 2] + ca2 * M[2, 2]
    gp0 = M[0, 3] + a2
    gp1 = ca2 * M[1, 3] - sa2 * M[2, 3]
    gp2 = sa2 * M[1, 3] + ca2 * M[2, 3] + d2
    fl0, fl1, fl2 = F[0, 2], F[1, 2], F[2, 2]
    fp0, fp1, fp2 = F[0, 3], F[1, 3], F[2, 3]
    system = np.empty((4, 3))
    system[0, 0], system[0, 1], system[0, 2] = sa1 * gl1, sa1 * gl0, fl2 - ca1 * gl2
    system[1, 0], system[1, 1], system[1, 2] = sa1 * gp1, sa1 * gp0, fp2 - ca1 * gp2
    system[2, 0], system[2, 1] = 2.0 * a1 * gp0, -2.0 * a1 * gp1
    system[2, 2] = (fp0 * fp0 + fp1 * fp1 + fp2 * fp2) - (gp0 * gp0 + gp1 * gp1 + gp2 * gp2)
    system[2, 2] -= a1 * a1
    system[3, 0], system[3, 1] = a1 * gl0, -a1 * gl1
    system[3, 2] = (fl0 * fp0 + fl1 * fp1 + fl2 * fp2) - (gl0 * gp0 + gl1 * gp1 + gl2 * gp2)
    n, c2a, s2a, c2b, s2b = _kunit_solutions(system)
    t1a, t2a, t1b, t2b = 0.0, 0.0, 0.0, 0.0
    for k in range(n):
        c2 = c2a if k == 0 else c2b
        s2 = s2a if k == 0 else s2b
        wl0, wl1 = c2 * gl0 - s2 * gl1, s2 * gl0 + c2 * gl1
        wp0, wp1 = c2 * gp0 - s2 * gp1 + a1, s2 * gp0 + c2 * gp1
        wl1 = ca1 * wl1 - sa1 * gl2
        wp1 = ca1 * wp1 - sa1 * gp2
        across = wl0 * fl1 - wl1 * fl0 + wp0 * fp1 - wp1 * fp0
        along = wl0 * fl0 + wl1 * fl1 + wp0 * fp0 + wp1 * fp1
        if k == 0:
            t1a, t2a = math.atan2(across, along), math.atan2(s2, c2)
        else:
            t1b, t2b = math.atan2(across, along), math.atan2(s2, c2)
    return n, t1a, t2a, t1b, t2b


def _kunit_solutions(system):
    """_rr_unit_solutions in the kernel, from the normal equations' 2 x 2 eigenproblem:
    (count, c, s, c', s')."""
    g00, g01, g11, b0, b1 = 0.0, 0.0, 0.0, 0.0, 0.0
    for r in range(4):
        g00 += system[r, 0] * system[r, 0]
        g01 += system[r, 0] * system[r, 1]
        g11 += system[r, 1] * system[r, 1]
        b0 += system[r, 0] * system[r, 2]
        b1 += system[r, 1] * system[r, 2]
    mean = 0.5 * (g00 + g11)
    spread = math.hypot(0.5 * (g00 - g11), g01)
    big, small = mean + spread, mean - spread
    if big == 0.0:
        return 1, 1.0, 0.0, 1.0, 0.0
    if small > 1e-16 * big:  # singular values' ratio above 1e-8: one least-squares solution
        det = g00 * g11 - g01 * g01
        c = (g11 * b0 - g01 * b1) / det
        s = (g00 * b1 - g01 * b0) / det
        h = math.hypot(c, s)
        if h == 0.0:
            return 1, 1.0, 0.0, 1.0, 0.0
        return 1, c / h, s / h, c / h, s / h
    # one direction n (the large eigenvalue's eigenvector) fixed: n . (c, s) = along
    if abs(g01) > 0.0 or g00 != g11:
        angle = 0.5 * math.atan2(2.0 * g01, g00 - g11)
    else:
        angle = 0.0
    n0, n1 = cos(angle), sin(angle)
    along = (n0 * b0 + n1 * b1) / big
    along = max(-1.0, min(1.0, along))
    side = math.sqrt(1.0 - along * along)
    return (
        2,
        along * n0 - side * n1,
        along * n1 + side * n0,
        along * n0 + side * n1,
        along * n1 - side * n0,
    )


def _krr_theta6(rows, F, t1, t2, t3, t4, t5):
    """_rr_theta6 in the kernel."""
    M = np.eye(4)
    _krr_link(t1, rows, 0, M)
    _krr_link(t2, rows, 1, M)
    _krr_link(t3, rows, 2, M)
    _krr_link(t4, rows, 3, M)
    _krr_link(t5, rows, 4, M)
    r10 = M[0, 1] * F[0, 0] + M[1, 1] * F[1, 0] + M[2, 1] * F[2, 0]
    r00 = M[0, 0] * F[0, 0] + M[1, 0] * F[1, 0] + M[2, 0] * F[2, 0]
    return math.atan2(r10, r00)


def _krr_between(fill, true, t):
    """_rr_between in the kernel."""
    out = np.zeros((7, 4))
    out[6] = true[6]
    for i in range(6):
        out[i, 0] = true[i, 0] + t * (fill[i, 0] - true[i, 0])
        out[i, 1] = true[i, 1] + t * (fill[i, 1] - true[i, 1])
        ca = true[i, 2] + t * (fill[i, 2] - true[i, 2])
        sa = true[i, 3] + t * (fill[i, 3] - true[i, 3])
        h = math.hypot(ca, sa)
        out[i, 2] = ca / h
        out[i, 3] = sa / h
    return out


def _krr_newton(rows, F, q0, extra):
    """_rr_newton_many (derive/runtime/general.py) for one candidate, in the kernel."""
    q, error = _krr_steps(rows, F, q0, False)
    if error <= _RR_GOOD or extra:
        return q, error, False
    damped, damped_error = _krr_steps(rows, F, q, True)
    if damped_error < error:
        q, error = damped, damped_error
        again, again_error = _krr_steps(rows, F, q, False)
        if again_error < error:
            q, error = again, again_error
    return q, error, True


def _krr_steps(rows, F, q0, damped):
    """_rr_steps_many for one candidate, in the kernel."""
    q = q0.copy()
    best_q = q.copy()
    best = math.inf
    frames = np.zeros((7, 4, 4))
    for i in range(4):
        frames[0, i, i] = 1.0
    J = np.zeros((6, 6))
    error = np.zeros((6, 1))
    normal = np.zeros((6, 6))
    step = np.zeros((6, 1))
    for _ in range(_RR_NEWTON_STEPS + 1):
        for i in range(6):
            frames[i + 1] = frames[i]
            _krr_link(q[i], rows, i, frames[i + 1])
        E = frames[6]
        size = 0.0
        for r in range(3):
            for c in range(4):
                size = max(size, abs(F[r, c] - E[r, c]))
        if size < best:
            best = size
            best_q[:] = q
        if size <= 1e-15 or size > _RR_NEWTON_REACH:
            break
        for r in range(3):
            error[r, 0] = F[r, 3] - E[r, 3]
        # 0.5 sum_k E_k x F_k
        for r in range(3):
            a, b = (r + 1) % 3, (r + 2) % 3
            total = 0.0
            for k in range(3):
                total += E[a, k] * F[b, k] - E[b, k] * F[a, k]
            error[3 + r, 0] = 0.5 * total
        for i in range(6):
            z = frames[i][:3, 2]
            o = frames[i][:3, 3]
            dx, dy, dz = E[0, 3] - o[0], E[1, 3] - o[1], E[2, 3] - o[2]
            J[0, i] = z[1] * dz - z[2] * dy
            J[1, i] = z[2] * dx - z[0] * dz
            J[2, i] = z[0] * dy - z[1] * dx
            J[3, i], J[4, i], J[5, i] = z[0], z[1], z[2]
            if i == 2 and rows[6, 0] != 0.0:  # a sliding joint 3
                J[0, i], J[1, i], J[2, i] = z[0], z[1], z[2]
                J[3, i], J[4, i], J[5, i] = 0.0, 0.0, 0.0
        if damped:  # Levenberg-Marquardt, mu = |error|^2
            mu = 0.0
            for r in range(6):
                mu += error[r, 0] * error[r, 0]
            for r in range(6):
                step[r, 0] = 0.0
                for c in range(6):
                    normal[r, c] = 0.0
                for k in range(6):
                    step[r, 0] += J[k, r] * error[k, 0]
                    for c in range(6):
                        normal[r, c] += J[k, r] * J[k, c]
                normal[r, r] += mu
            if not _ksolve_into(normal, step):
                break
        else:
            for r in range(6):
                step[r, 0] = error[r, 0]
            if not _ksolve_into(J, step):
                break
        longest = 0.0
        for r in range(6):
            longest = max(longest, abs(step[r, 0]))
        scale = 1.0 if longest <= 0.5 else 0.5 / longest
        for i in range(6):
            q[i] += scale * step[i, 0]
        if not damped and size <= _RR_NEWTON_DONE[0] and longest <= _RR_NEWTON_DONE[1]:
            best_q[:] = q  # (as in Python: the last step, not measured)
            best = size
            break
    return best_q, best


def _kdeflated(K, k, moebius):
    """_rr_deflated in the kernel: split k's companion matrix K without its known
    eigenvalues, K[o, o] - G K[p', o] (K itself where the split has none)."""
    count = _RR_SPURIOUS_COUNT[k]
    if count == 0:
        return K
    r = count // 2
    a, b, c, d = moebius
    scale = 1.0 / (a * a + c * c)
    yr, yi = (-b * a - d * c) * scale, (d * a - b * c) * scale
    p = np.zeros(count, dtype=np.int64)
    taken = np.zeros(24, dtype=np.bool_)
    for j in range(r):
        p[j] = _RR_PIVOTS[k, j]
        p[r + j] = _RR_PIVOTS[k, j] + 12
        taken[p[j]] = True
        taken[p[r + j]] = True
    o = np.zeros(24 - count, dtype=np.int64)
    n = 0
    for i in range(24):
        if not taken[i]:
            o[n] = i
            n += 1
    # G = [Re W[o] - (yr / yi) Im W[o], Im W[o] / yi], W = [v; y+ v]
    G = np.zeros((n, count))
    for i in range(n):
        row = o[i] % 12
        for j in range(r):
            vr, vi = _RR_SPURIOUS[k, row, 2 * j], _RR_SPURIOUS[k, row, 2 * j + 1]
            if o[i] >= 12:
                vr, vi = yr * vr - yi * vi, yr * vi + yi * vr
            G[i, j] = vr - (yr / yi) * vi
            G[i, r + j] = vi / yi
    out = np.zeros((n, n))
    for i in range(n):
        for j in range(n):
            total = K[o[i], o[j]]
            for m in range(count):
                total -= G[i, m] * K[p[m], o[j]]
            out[i, j] = total
    return out


def _keigenvalues(M):
    """The eigenvalues (real parts, imaginary parts) of a real square matrix, and whether the
    iteration converged: reduction to upper Hessenberg form by Householder reflections, then
    the Francis double-shift QR iteration with deflation (Golub and Van Loan, Matrix
    Computations, algorithms 7.4.2 and 7.5.2), eigenvalues only: the reflections of the QR
    steps touch the active diagonal block alone."""
    n = M.shape[0]
    H = M.copy()
    v = np.zeros(n)
    for k in range(n - 2):
        alpha = 0.0
        for i in range(k + 1, n):
            alpha += H[i, k] * H[i, k]
        alpha = math.sqrt(alpha)
        if alpha == 0.0:
            continue
        if H[k + 1, k] > 0.0:
            alpha = -alpha
        for i in range(k + 1, n):
            v[i] = H[i, k]
        v[k + 1] -= alpha
        vv = 0.0
        for i in range(k + 1, n):
            vv += v[i] * v[i]
        if vv == 0.0:
            continue
        for j in range(k, n):  # H := P H (columns before k are zero below row k + 1)
            f = 0.0
            for i in range(k + 1, n):
                f += v[i] * H[i, j]
            f *= 2.0 / vv
            for i in range(k + 1, n):
                H[i, j] -= f * v[i]
        for i in range(n):  # H := H P
            f = 0.0
            for j in range(k + 1, n):
                f += H[i, j] * v[j]
            f *= 2.0 / vv
            for j in range(k + 1, n):
                H[i, j] -= f * v[j]
        for i in range(k + 2, n):
            H[i, k] = 0.0
    wr = np.zeros(n)
    wi = np.zeros(n)
    eps = 2.220446049250313e-16
    hi = n - 1
    iterations = 0
    while hi >= 0:
        # the active block H[lo:hi+1, lo:hi+1]: the first negligible subdiagonal entry up
        lo = hi
        while lo > 0:
            scale = abs(H[lo - 1, lo - 1]) + abs(H[lo, lo])
            if scale == 0.0:
                scale = np.abs(H[: hi + 1, : hi + 1]).max()
            if abs(H[lo, lo - 1]) <= eps * scale:
                H[lo, lo - 1] = 0.0
                break
            lo -= 1
        if lo == hi:  # one real eigenvalue
            wr[hi] = H[hi, hi]
            hi -= 1
            iterations = 0
            continue
        if lo == hi - 1:  # a 2 x 2 block: two real or a complex pair
            a, b, c, d = H[hi - 1, hi - 1], H[hi - 1, hi], H[hi, hi - 1], H[hi, hi]
            half = 0.5 * (a - d)
            disc = half * half + b * c
            mid = 0.5 * (a + d)
            if disc >= 0.0:
                root = math.sqrt(disc)
                big = mid + root if mid >= 0.0 else mid - root
                wr[hi - 1] = big
                wr[hi] = (a * d - b * c) / big if big != 0.0 else mid - root
            else:
                root = math.sqrt(-disc)
                wr[hi - 1] = wr[hi] = mid
                wi[hi - 1], wi[hi] = root, -root
            hi -= 2
            iterations = 0
            continue
        iterations += 1
        if iterations > 60:
            return wr, wi, False
        # the double shift: the eigenvalues of the trailing 2 x 2 block (exceptional shifts
        # every 10 iterations)
        if iterations % 10 == 0:
            s = abs(H[hi, hi - 1]) + abs(H[hi - 1, hi - 2])
            trace, det = 1.5 * s, s * s
        else:
            trace = H[hi - 1, hi - 1] + H[hi, hi]
            det = H[hi - 1, hi - 1] * H[hi, hi] - H[hi - 1, hi] * H[hi, hi - 1]
        x = H[lo, lo] * H[lo, lo] + H[lo, lo + 1] * H[lo + 1, lo] - trace * H[lo, lo] + det
        y = H[lo + 1, lo] * (H[lo, lo] + H[lo + 1, lo + 1] - trace)
        z = H[lo + 1, lo] * H[lo + 2, lo + 1]
        for k in range(lo, hi - 1):
            # the reflection taking (x, y, z) onto the axis, applied to rows and columns k..k+2
            alpha = math.sqrt(x * x + y * y + z * z)
            if alpha != 0.0:
                if x > 0.0:
                    alpha = -alpha
                u0, u1, u2 = x - alpha, y, z
                uu = 2.0 / (u0 * u0 + u1 * u1 + u2 * u2)  # (one division a reflection)
                first = max(lo, k - 1)
                for j in range(first, hi + 1):  # eigenvalues only: the active block
                    f = (u0 * H[k, j] + u1 * H[k + 1, j] + u2 * H[k + 2, j]) * uu
                    H[k, j] -= f * u0
                    H[k + 1, j] -= f * u1
                    H[k + 2, j] -= f * u2
                last = min(k + 3, hi)
                for i in range(lo, last + 1):
                    f = (u0 * H[i, k] + u1 * H[i, k + 1] + u2 * H[i, k + 2]) * uu
                    H[i, k] -= f * u0
                    H[i, k + 1] -= f * u1
                    H[i, k + 2] -= f * u2
                if k > lo:
                    H[k + 1, k - 1] = 0.0
                    H[k + 2, k - 1] = 0.0
            x = H[k + 1, k]
            y = H[k + 2, k]
            if k < hi - 2:
                z = H[k + 3, k]
        # the last 2-vector
        k = hi - 1
        alpha = math.sqrt(x * x + y * y)
        if alpha != 0.0:
            if x > 0.0:
                alpha = -alpha
            u0, u1 = x - alpha, y
            uu = 2.0 / (u0 * u0 + u1 * u1)
            for j in range(max(lo, k - 1), hi + 1):
                f = (u0 * H[k, j] + u1 * H[k + 1, j]) * uu
                H[k, j] -= f * u0
                H[k + 1, j] -= f * u1
            for i in range(lo, hi + 1):
                f = (u0 * H[i, k] + u1 * H[i, k + 1]) * uu
                H[i, k] -= f * u0
                H[i, k + 1] -= f * u1
            if k > lo:
                H[k + 1, k - 1] = 0.0
    return wr, wi, True
