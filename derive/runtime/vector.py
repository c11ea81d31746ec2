"""The numpy batch solver's step routines: each Solve step's values along an array axis of
their own, so that broadcasting does the branching (rows the closed forms cannot settle go to
the scalar routines one by one)."""

from __future__ import annotations

import math

import numpy as np

from derive.runtime.arm import _REVOLUTE
from derive.runtime.common import _FAR, _PERIODS, _real
from derive.runtime.constants import (
    _CLAMP_TOL,
    _CLUSTER_TOL,
    _FOLD_TOL,
    _FREE_TOL,
    _LEAD_TOL,
    _MERGE_TOL,
    _OMEGA,
    _RESIDUAL_TOL,
    _ROOT_IMAG_TOL,
    _SEAM,
    _SEAM_SNAP,
    _TWO_PI,
    DEDUP_TOL,
    POSE_TOL,
)
from derive.runtime.scalar import _cs1_reach, _Free, _poly_angles, _poly_real


def _vnew_axis(values, ok, like, axis, free=False):
    """Broadcast a step's result (no branching) to the shape of `like`: values, validity and
    where the joint was free."""
    values, ok, free, _ = np.broadcast_arrays(values, ok, free, like)
    return values, ok, free


def _vcs1(a, b, e, scale, ref, axis, like):
    """Vectorised _cs1: two values along `axis` (+acos, then -acos), their validity and where
    the joint was free (ref as the first value, the second invalid)."""
    a, b, e, ref, _ = np.broadcast_arrays(a, b, e, ref, like)
    rho = np.sqrt(a * a + b * b)
    small = rho * rho <= _FREE_TOL * scale
    free = small & (e * e <= _FREE_TOL * scale)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = e / rho
    ok = ~small & (rho > 0.0) & (np.abs(ratio) <= 1.0 + _CLAMP_TOL)
    base = np.arctan2(b, a)
    ratio = np.where(ok, ratio, 0.0)
    fold = np.abs(ratio) >= 1.0 - _FOLD_TOL
    delta = np.where(
        fold, np.where(ratio > 0.0, 0.0, math.pi), np.arccos(np.clip(ratio, -1.0, 1.0))
    )
    return (
        np.concatenate((np.where(free, ref, base + delta), base - delta), axis),
        np.concatenate((ok | free, ok), axis),
        np.concatenate((free, np.zeros_like(free)), axis),
    )


def _vcs1_reach(
    a, b, e, m00, m01, m02, m10, m11, m12, m20, m21, m22, lo, hi, scale, ref, axis, like
):
    """Vectorised _cs1_reach: _vcs1, with the (rare) free rows settled by the scalar routine."""
    values, ok, free = _vcs1(a, b, e, scale, ref, axis, like)
    args = np.broadcast_arrays(a, b, e, m00, m01, m02, m10, m11, m12, m20, m21, m22, ref, like)
    for index in zip(*np.nonzero(free)):
        a0, b0, e0, n00, n01, n02, n10, n11, n12, n20, n21, n22, r0 = (
            float(x[index]) for x in args[:13]
        )
        values[index] = _cs1_reach(
            a0, b0, e0, n00, n01, n02, n10, n11, n12, n20, n21, n22, lo, hi, scale, r0
        )[0]
    return values, ok, free


def _vcs2(a1, b1, e1, a2, b2, e2, det_scale, rhs_scale, ref, axis, like):
    """Vectorised _cs2 (one value; ref where the angle is free)."""
    det = a1 * b2 - a2 * b1
    free = (np.abs(det) <= _FREE_TOL * det_scale) | (e1 * e1 + e2 * e2 <= _FREE_TOL * rhs_scale)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.arctan2((a1 * e2 - a2 * e1) / det, (e1 * b2 - b1 * e2) / det)
    return _vnew_axis(np.where(free, ref, value), True, like, axis, free)


def _vcs2_reach(a1, b1, e1, a2, b2, e2, det_scale, rhs_scale, A, B, C, lo, hi, ref, axis, like):
    """Vectorised _cs2_reach."""
    det = a1 * b2 - a2 * b1
    free = (np.abs(det) <= _FREE_TOL * det_scale) | (e1 * e1 + e2 * e2 <= _FREE_TOL * rhs_scale)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = np.arctan2((a1 * e2 - a2 * e1) / det, (e1 * b2 - b1 * e2) / det)
        radius = A + B * np.cos(ref) + C * np.sin(ref)
        rho = np.sqrt(B * B + C * C)
        delta = np.arccos(np.clip((0.5 * (lo + hi) - A) / rho, -1.0, 1.0))
    base = np.arctan2(C, B)
    plus, minus = base + delta, base - delta
    nearer = np.where(np.abs(_vwrap(plus - ref)) <= np.abs(_vwrap(minus - ref)), plus, minus)
    keep_ref = ((lo <= radius) & (radius <= hi)) | (rho == 0.0)
    chosen = np.where(keep_ref, ref, nearer)
    return _vnew_axis(np.where(free, chosen, value), True, like, axis, free)


def _vatan2(y, x, ref, axis, like):
    """Vectorised _atan2."""
    free = np.abs(y) + np.abs(x) <= 1e-12
    return _vnew_axis(np.where(free, ref, np.arctan2(y, x)), True, like, axis, free)


def _vwrap(t):
    """Angles wrapped to (-pi, pi] (as _wrap: a value rounding to -pi becomes pi)."""
    w = t - _TWO_PI * np.round(t / _TWO_PI)
    return np.where(w <= -math.pi, w + _TWO_PI, w)


def _vroots(p):
    """Real roots of the rows of p (m, d+1), p[:, 0] != 0, as _real_roots does per row.

    Returns (roots (m, d), valid (m, d), fallback (m,)): rows marked fallback (other degrees,
    a leading coefficient below _LEAD_TOL, a closed-form root failing the residual test, a
    multiple root split into a cluster) are to be solved by the scalar routine.
    """
    m, d = p.shape[0], p.shape[1] - 1
    lead = p[:, 0]
    fallback = np.abs(lead) <= _LEAD_TOL * np.abs(p).max(axis=1)
    mon = p[:, 1:] / np.where(fallback, 1.0, lead)[:, None]
    if d == 2:
        zs = np.stack(_vquadratic(mon[:, 0].astype(complex), mon[:, 1].astype(complex)), axis=1)
    elif d == 4:
        zs = np.stack(_vquartic(*(mon[:, k].astype(complex) for k in range(4))), axis=1)
    elif d == 1:
        zs = (-mon[:, :1]).astype(complex)
    else:
        return np.zeros((m, d)), np.zeros((m, d), bool), np.ones(m, bool)
    with np.errstate(all="ignore"):
        ok = np.abs(zs.imag) <= _ROOT_IMAG_TOL * (1.0 + np.abs(zs))
        # a split multiple root (imaginary parts up to _CLUSTER_TOL): the scalar routine
        fallback |= (~ok & (np.abs(zs.imag) <= _CLUSTER_TOL * (1.0 + np.abs(zs)))).any(axis=1)
        x = np.where(ok, zs.real, np.inf)
        x.sort(axis=1)
        ok = np.isfinite(x)
        head = np.zeros_like(ok)
        consumed = np.zeros_like(ok)
        for k in range(d - 1):
            pair = (
                ok[:, k]
                & ok[:, k + 1]
                & ~consumed[:, k]
                & (x[:, k + 1] - x[:, k] <= _MERGE_TOL * (1.0 + np.abs(x[:, k])))
            )
            x[:, k] = np.where(pair, 0.5 * (x[:, k] + x[:, k + 1]), x[:, k])
            head[:, k] |= pair
            consumed[:, k + 1] |= pair
        ok &= ~consumed
        x = np.where(ok, x, 0.0)
        x = np.where(ok & ~head, _vnewton(p, x), x)
        value = np.zeros_like(x)
        size = np.zeros_like(x)
        slope = np.zeros_like(x)
        ax = np.abs(x)
        for k in range(d + 1):
            slope = slope * x + value
            value = value * x + p[:, k : k + 1]
            size = size * ax + np.abs(p[:, k : k + 1])
        small = (np.abs(value) <= _RESIDUAL_TOL * size) | (
            np.abs(value) <= _RESIDUAL_TOL * (1.0 + ax) * np.abs(slope)
        )
        bad = ok & ~small
    fallback |= bad.any(axis=1)
    return x, ok, fallback


def _vnewton(p, x):
    """Two guarded Newton steps on the rows' polynomials, elementwise."""
    with np.errstate(all="ignore"):
        for _ in range(2):
            val = np.zeros_like(x)
            der = np.zeros_like(x)
            for k in range(p.shape[1]):
                der = der * x + val
                val = val * x + p[:, k : k + 1]
            step = val / der
            good = np.isfinite(step) & (np.abs(step) <= 1e-3 * (1.0 + np.abs(x)))
            x = np.where(good, x - step, x)
    return x


def _vquadratic(b, c):
    """Both roots of x^2 + b x + c (complex arrays), as _kquadratic."""
    t = np.sqrt(b * b - 4.0 * c)
    t = np.where((np.conj(b) * t).real < 0.0, -t, t)
    q = -0.5 * (b + t)
    with np.errstate(all="ignore"):
        other = np.where(q == 0, q, c / q)
    return q, other


def _vcubic_largest(a2, a1, a0):
    """The root of largest modulus of m^3 + a2 m^2 + a1 m + a0, as _kcubic_largest."""
    P = a1 - a2 * a2 / 3.0
    Q = 2.0 * a2**3 / 27.0 - a2 * a1 / 3.0 + a0
    w = np.sqrt(Q * Q / 4.0 + P**3 / 27.0)
    u3 = np.where(np.abs(-Q / 2.0 + w) < np.abs(-Q / 2.0 - w), -Q / 2.0 - w, -Q / 2.0 + w)
    zero = u3 == 0
    u = np.where(zero, 1.0, u3) ** (1.0 / 3.0)
    best = np.zeros(u.shape, dtype=complex)
    best_abs = np.full(u.shape, -1.0)
    for w_k in _OMEGA:
        uk = u * w_k
        mk = uk - P / (3.0 * uk) - a2 / 3.0
        better = np.abs(mk) > best_abs
        best = np.where(better, mk, best)
        best_abs = np.where(better, np.abs(mk), best_abs)
    return np.where(zero, -a2 / 3.0, best)


def _vquartic(B, C, D, E):
    """The four roots of x^4 + B x^3 + C x^2 + D x + E (complex arrays), as _kquartic."""
    a = B / 4.0
    p = C - 6.0 * a * a
    q = D - 2.0 * a * C + 8.0 * a**3
    r = E - a * D + a * a * C - 3.0 * a**4
    with np.errstate(all="ignore"):
        m = _vcubic_largest(p, p * p / 4.0 - r, -q * q / 8.0)
        s = np.sqrt(2.0 * m)
        zero = s == 0
        h = np.where(zero, 0.0, q / np.where(zero, 1.0, 2.0 * s))
        y1, y2 = _vquadratic(-s, p / 2.0 + m + h)
        y3, y4 = _vquadratic(s, p / 2.0 + m - h)
        t = np.sqrt(p * p - 4.0 * r)
        b1, b2 = np.sqrt((-p + t) / 2.0), np.sqrt((-p - t) / 2.0)
    y1, y2, y3, y4 = (
        np.where(zero, alt, y) for y, alt in ((y1, b1), (y2, -b1), (y3, b2), (y4, -b2))
    )
    return y1 - a, y2 - a, y3 - a, y4 - a


def _vpoly(coeffs, axis, like, angles, ref=0.0, free=0.0, unit=1.0):
    """Vectorised _poly_angles (angles=True) or _poly_real: values along `axis`, validity and
    where the joint was free.

    Rows the closed forms cannot settle are solved by the scalar routine, one by one.
    """
    cs = np.broadcast_arrays(*coeffs, like)[:-1]
    shape = cs[0].shape
    raw = np.stack([np.asarray(x, dtype=float).ravel() for x in cs], axis=1)
    m, d = raw.shape[0], raw.shape[1] - 1
    if angles:
        c = raw
        flip = np.abs(c[:, 0]) < np.abs(c[:, -1])
        p = np.where(flip[:, None], c[:, ::-1], c)
    else:
        c = raw * unit ** np.arange(d, -1, -1.0)  # the polynomial in x / unit, as _poly_real
        flip = np.zeros(m, bool)
        p = c
    x, ok, fallback = _vroots(p)
    if not angles:
        fallback |= np.abs(c[:, 0]) <= _LEAD_TOL * np.abs(c).max(axis=1)
    if angles:
        with np.errstate(all="ignore"):
            t = np.where(flip[:, None], 2.0 * np.arctan2(1.0, x), 2.0 * np.arctan(x))
        t = _vwrap(t)
        t = np.where(math.pi - np.abs(t) <= 1e-12, math.pi, t)
        t = np.where(ok, t, np.inf)
        t.sort(axis=1)
        ok = np.isfinite(t)
        with np.errstate(invalid="ignore"):
            ok[:, 1:] &= ~(t[:, 1:] - t[:, :-1] <= 1e-12)
        order = np.argsort(~ok, axis=1, kind="stable")
        x = np.take_along_axis(np.where(ok, t, 0.0), order, axis=1)
        ok = np.take_along_axis(ok, order, axis=1)
    else:
        close = np.zeros_like(ok)
        close[:, 1:] = (
            ok[:, 1:] & ok[:, :-1] & (x[:, 1:] - x[:, :-1] <= 1e-12 * (1.0 + np.abs(x[:, 1:])))
        )
        ok &= ~close
        order = np.argsort(~ok, axis=1, kind="stable")
        x = np.take_along_axis(x, order, axis=1) * unit
        ok = np.take_along_axis(ok, order, axis=1)
    scale = np.abs(raw).max(axis=1)
    ok &= (scale > 0.0)[:, None]
    vanishing = scale <= free
    fallback |= vanishing
    refs = np.broadcast_to(ref, shape).ravel()
    freed = np.zeros_like(ok)
    for i in np.flatnonzero(fallback & ((scale > 0.0) | vanishing)):
        if angles:
            values = _poly_angles(raw[i], float(refs[i]), free)
        else:
            values = _poly_real(raw[i], float(refs[i]), free, unit)
        x[i] = 0.0
        ok[i] = False
        if values.__class__ is _Free:
            values = values[:1]
            freed[i, 0] = True
        x[i, : len(values)] = values
        ok[i, : len(values)] = True
    inner = shape[:axis] + shape[axis + 1 :]
    x, ok, freed = (np.moveaxis(v.reshape((*inner, d)), -1, axis) for v in (x, ok, freed))
    return x, ok, freed


def _vpose(T):
    """Per-row validity of poses (N, 4, 4) and the poses with invalid rows replaced (a pose
    farther than _FAR is out of reach: no valid slot, as an invalid one)."""
    T = _real(T, "T")
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise ValueError(f"T must have shape (N, 4, 4), got {T.shape}")
    flat = T.reshape(-1, 16)
    with np.errstate(invalid="ignore", over="ignore"):
        (a0, a1, a2, _, b0, b1, b2, _, c0, c1, c2, _, z0, z1, z2, z3) = flat.T
        worst = np.abs(a0 * a0 + a1 * a1 + a2 * a2 - 1.0)
        for dot in (
            b0 * b0 + b1 * b1 + b2 * b2 - 1.0,
            c0 * c0 + c1 * c1 + c2 * c2 - 1.0,
            a0 * b0 + a1 * b1 + a2 * b2,
            a0 * c0 + a1 * c1 + a2 * c2,
            b0 * c0 + b1 * c1 + b2 * c2,
            z0,
            z1,
            z2,
            z3 - 1.0,
        ):
            worst = np.maximum(worst, np.abs(dot))
        det = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0)
        near = np.abs(flat[:, [3, 7, 11]]).max(axis=1) <= _FAR
        good = (worst <= POSE_TOL) & (det > 0.0) & np.isfinite(flat).all(axis=1) & near
    if good.all():
        return T, good
    return np.where(good[:, None, None], T, np.eye(4)), good


def _vfinish(Q, valid):
    """Wrap revolute values (as _finish: pi at the seam) and drop repeats within each pose
    (vectorised).

    Pairs are compared on their last joint first; only the few rows where that agrees are
    compared in full.
    """
    count = Q.shape[1]
    rev = np.array(_REVOLUTE)
    Q = Q.copy()
    W = _vwrap(Q[:, :, rev])
    W = np.where(W < -_SEAM, W + _TWO_PI, W)  # _seam, vectorised
    Q[:, :, rev] = np.where(np.abs(W - math.pi) <= _SEAM_SNAP, math.pi, W)
    ok = valid.copy()
    period = _PERIODS[-1]
    for j in range(1, count):
        for i in range(j):
            last = np.abs(Q[:, j, -1] - Q[:, i, -1])
            if period != math.inf:
                last = np.minimum(last, _TWO_PI - last)
            rows = np.flatnonzero(ok[:, i] & ok[:, j] & (last <= DEDUP_TOL))
            if rows.size == 0:
                continue
            d = np.abs(Q[rows, j, :] - Q[rows, i, :])
            d[:, rev] = np.minimum(d[:, rev], _TWO_PI - d[:, rev])
            ok[rows[d.max(axis=1) <= DEDUP_TOL], j] = False
    # the kept slots first, in order (as the compiled kernel writes them)
    order = np.argsort(~ok, axis=1, kind="stable")
    ok = np.take_along_axis(ok, order, axis=1)
    Q = np.take_along_axis(Q, order[:, :, None], axis=1)
    return np.where(ok[:, :, None], Q, 0.0), ok


def _vdefer(n, dof):
    """_ik_candidates's result sending all n poses to the scalar solver (no branch values)."""
    return np.zeros((n, 1, dof)), np.zeros((n, 1), dtype=bool), np.ones(n, dtype=bool)


def _vshape(value, shape):
    """A free joint's reference value: one number for every pose as it is, an array of one
    value per pose shaped like the poses' axis (shape)."""
    return value if np.ndim(value) == 0 else np.reshape(value, shape)
