"""Closed forms of the Python solver (the C solver has its own: derive/c/runtime.c):
roots of quadratics and quartics, a fast atan2, wrapping, Newton steps, and the searches for
a free joint's first value."""

from __future__ import annotations

import cmath
import math
from math import atan2, cos, sin, sqrt

import numpy as np

from derive.runtime.constants import _FREE_STEPS, _OMEGA, _RESIDUAL_TOL, _SPLIT_TOL, _TWO_PI


def _reach_first1(m00, m01, m02, m10, m11, m12, m20, m21, m22, lo, hi, ref):
    """The first value of a free t, in 5 degree steps out from ref, at which some t' keeps
    W = (m00 + m01 c + m02 s) + (m10 + m11 c + m12 s) c' + (m20 + m21 c + m22 s) s' in
    [lo, hi] (c, s of t and c', s' of t': the next joint must still let the wrist reach);
    ref if there is none."""
    for step in _FREE_STEPS:
        t = ref + step
        c, s = cos(t), sin(t)
        A = m00 + m01 * c + m02 * s
        B = m10 + m11 * c + m12 * s
        C = m20 + m21 * c + m22 * s
        r = sqrt(B * B + C * C)
        if A - r <= hi and A + r >= lo:
            return t
    return ref


def _reach_first2(A, B, C, lo, hi, ref):
    """The first value of a free t: ref if it keeps A + B cos t + C sin t in [lo, hi], else
    the nearer to ref of the two t at which it is mid-range."""
    rho = sqrt(B * B + C * C)
    if lo <= A + B * cos(ref) + C * sin(ref) <= hi or rho == 0.0:
        return ref
    base = _kangle(C, B)
    ratio = max(-1.0, min(1.0, (0.5 * (lo + hi) - A) / rho))
    delta = _kangle(sqrt((1.0 - ratio) * (1.0 + ratio)), ratio)
    if abs(_kwrap(base - delta - ref)) < abs(_kwrap(base + delta - ref)):
        return base - delta
    return base + delta


# _kangle's segments: t = min(|x|, |y|) / max(|x|, |y|) in [0, 1] falls in segment
# k = int(8 t + 0.5); its angle is _ANGLE_AT[k] + atan(r), r = tan of the offset from it
# (|r| <= 0.0625), from the series r - r^3/3 + ... - r^15/15 (truncated below 1e-19 of r)
_ANGLE_AT = np.array(
    [0.0]
    + [
        (math.atan((k - 0.5) / 8.0) + math.atan(min(1.0, (k + 0.5) / 8.0))) / 2.0
        for k in range(1, 9)
    ]
)


_TAN_AT = np.tan(_ANGLE_AT)


def _kangle(y: float, x: float) -> float:
    """atan2(y, x) to within a few units in the last place, about twice as fast as the
    library's (which rounds correctly): the octant, one of nine segments of it, and an odd
    series. Zeros, infinities and nan go to the library's."""
    ax, ay = abs(x), abs(y)
    steep = ay > ax
    num, den = (ax, ay) if steep else (ay, ax)
    if not (0.0 < den < math.inf and num <= den):
        return atan2(y, x)
    t = num / den
    k = int(8.0 * t + 0.5)
    c = _TAN_AT[k]
    r = (t - c) / (1.0 + t * c)
    r2 = r * r
    a = _ANGLE_AT[k] + (
        r
        + r
        * r2
        * (
            -1.0 / 3.0
            + r2
            * (
                1.0 / 5.0
                + r2
                * (
                    -1.0 / 7.0
                    + r2 * (1.0 / 9.0 + r2 * (-1.0 / 11.0 + r2 * (1.0 / 13.0 + r2 * (-1.0 / 15.0))))
                )
            )
        )
    )
    if steep:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return math.copysign(a, y)


def _kwrap(t: float) -> float:
    """t wrapped to (-pi, pi]."""
    if -math.pi < t <= math.pi:
        return t
    w = t - _TWO_PI * math.floor(t / _TWO_PI + 0.5)
    return w + _TWO_PI if w <= -math.pi else w


def _kquadratic(b, c):
    """Both roots of x^2 + b x + c (complex b, c allowed), without cancellation."""
    t = cmath.sqrt(b * b - 4.0 * c)
    if (b.conjugate() * t).real < 0.0:
        t = -t
    q = -0.5 * (b + t)
    if q == 0:
        return q, q
    return q, c / q


def _kcubic_largest(a2, a1, a0):
    """The root of largest modulus of m^3 + a2 m^2 + a1 m + a0 (Cardano, complex)."""
    P = a1 - a2 * a2 / 3.0
    Q = 2.0 * a2 * a2 * a2 / 27.0 - a2 * a1 / 3.0 + a0
    w = cmath.sqrt(Q * Q / 4.0 + P * P * P / 27.0)
    u3 = -Q / 2.0 + w
    if abs(u3) < abs(-Q / 2.0 - w):
        u3 = -Q / 2.0 - w
    if u3 == 0:
        return -a2 / 3.0
    u = u3 ** (1.0 / 3.0)
    best = u - P / (3.0 * u) - a2 / 3.0
    for uk in (u * _OMEGA[1], u * _OMEGA[2]):
        m = uk - P / (3.0 * uk) - a2 / 3.0
        if abs(m) > abs(best):
            best = m
    return best


def _kquartic(B, C, D, E):
    """The four roots of x^4 + B x^3 + C x^2 + D x + E (Ferrari, complex arithmetic)."""
    a = B / 4.0
    p = C - 6.0 * a * a
    q = D - 2.0 * a * C + 8.0 * a * a * a
    r = E - a * D + a * a * C - 3.0 * a * a * a * a
    m = _kcubic_largest(p, p * p / 4.0 - r, -q * q / 8.0)
    s = cmath.sqrt(2.0 * m)
    if s == 0:
        t = cmath.sqrt(p * p - 4.0 * r)
        y1, y2 = cmath.sqrt((-p + t) / 2.0), cmath.sqrt((-p - t) / 2.0)
        return y1 - a, -y1 - a, y2 - a, -y2 - a
    h = q / (2.0 * s)
    y1, y2 = _kquadratic(-s, p / 2.0 + m + h)
    y3, y4 = _kquadratic(s, p / 2.0 + m - h)
    return y1 - a, y2 - a, y3 - a, y4 - a


def _small_residual(p: list[float] | np.ndarray, x: complex) -> bool:
    """p(x) is negligible against the size of its terms, or Newton's step from x is (x real,
    or complex: a closed form's complex root is checked too, _accept)."""
    value: complex = 0.0
    slope: complex = 0.0
    size = 0.0
    ax = abs(x)
    for k in p:
        slope = slope * x + value
        value = value * x + k
        size = size * ax + abs(k)
    return abs(value) <= _RESIDUAL_TOL * size or abs(value) <= _RESIDUAL_TOL * (1.0 + ax) * abs(
        slope
    )


def _two_roots(p: list[float] | np.ndarray, x: float) -> bool:
    """Whether the mean x of two close roots of p leaves p above _SPLIT_TOL of its largest
    coefficient: two roots, not a double root split by rounding."""
    value = 0.0
    for k in p:
        value = value * x + k
    return abs(value) > _SPLIT_TOL * max(abs(k) for k in p)


def _newton(c: list[float] | np.ndarray, x: float) -> float:
    """Two Newton steps on the polynomial c (highest degree first), skipped if unstable."""
    for _ in range(2):
        p = dp = 0.0
        for k in c:
            dp = dp * x + p
            p = p * x + k
        if dp == 0.0:
            break
        step = p / dp
        if not math.isfinite(step) or abs(step) > 1e-3 * (1.0 + abs(x)):
            break
        x -= step
    return x
