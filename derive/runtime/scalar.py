"""The Python solver's step routines: the values of one joint, as a tuple (a _Free tuple when
the pose leaves the joint free, whose values the solver tries in turn)."""

from __future__ import annotations

import math
import threading
from math import acos, atan2, cos, sin, sqrt

import numpy as np

from derive.runtime.arm import _SEED_TOL, IK_COMPONENTS, REACH, TOOL_AXIS
from derive.runtime.closed import (
    _kquadratic,
    _kquartic,
    _newton,
    _reach_first1,
    _reach_first2,
    _small_residual,
    _two_roots,
)
from derive.runtime.common import _wrap
from derive.runtime.constants import (
    _AIM_POLISH,
    _BRANCH_FOLD,
    _CLAMP_ABS,
    _CLAMP_TOL,
    _CLUSTER_TOL,
    _FOLD_NEAR,
    _FOLD_SEEDS,
    _FOLD_SPREAD,
    _FOLD_TOL,
    _FOLD_WIDTH,
    _FREE_STEPS,
    _FREE_TOL,
    _FREE_TOL_EXACT,
    _FREE_TOL_LOOSE,
    _LEAD_TOL,
    _MERGE_TOL,
    _ROOT_IMAG_TOL,
    _SEED_BAND,
    _SPREAD_COUNT,
    _SPREAD_WIDTH,
    _TWO_PI,
    _WRIST_NEAR,
    _WRIST_SPREAD,
    _WRIST_WIDTH,
)


class _Loose(threading.local):
    """Per thread: on, whether the solver is seeding ik_approximate (then an equation that
    misses is solved at its boundary, and a complex root gives its real part); near, whether
    it is taking ik's second pass, where the first gave no row (derive/runtime/api.py,
    _solve; C's dk_solve with loose): then _cs1 solves at its boundary where it misses, a
    free joint takes q_ref's value only, and on a nominal table neither _cs1 nor
    _wrist_spread adds seeds round a fold, and the seeds are refined only where their pose
    error is within _SEED_TOL, and kept where certified (refine.py, _seed); rough, where ik
    solves a pose (_solve), the rows kept within tol that polishing left beyond _LOOSE_TOL
    (_keep), dropped where the pose has other rows."""

    on = False
    near = False
    rough: list | None = None


_LOOSE = _Loose()


class _Free(tuple):
    """The values a free joint tries, first the preferred one, then 5 degree steps out from
    it in both directions. The solver stops at the first value that gives a certified
    solution: a later joint may not reach from every value (a wrist whose twists are not
    +-90 deg reaches only part of the orientations)."""


class _Spread(list):
    """A nominal table's angle that its equation fixes only roughly (_wrist_spread): [t], and
    the values the solver adds (widen) where t gave no row: t -+ u, t -+ 2 u, then the rest of
    _SPREAD_COUNT all round from t."""

    def __init__(self, first: float, more: tuple[float, ...]) -> None:
        super().__init__((first,))
        self.more = more

    def widen(self) -> None:
        """Add the other values (once)."""
        self.extend(self.more)
        self.more = ()


def _seed_miss(up: float) -> float:
    """How far beyond 1 a nominal table's acos argument still seeds the refinement onto the
    exact arm: _SEED_TOL, or the uncertainty _SEED_TOL / up that the steps before it leave
    (up: the least of their conditions, _cs1_sig and _cs2_sig: an angle solved near a
    singular configuration carries the table's difference amplified), at most _SEED_BAND;
    0 on an exact table."""
    if not _SEED_TOL:
        return 0.0
    if up * _SEED_BAND <= _SEED_TOL:
        return _SEED_BAND
    return max(_SEED_TOL, _SEED_TOL / up)


def _cs1_sig(a: float, b: float, e: float, scale: float) -> float:
    """The condition of a cos t + b sin t = e (printed for a later step's _seed_miss):
    sqrt(a^2 + b^2 - e^2) over the equation's scale, the table's difference over it being the
    uncertainty of its angles (0 at a fold or beyond; infinite without a scale)."""
    if scale <= 0.0:
        return math.inf
    return sqrt(max(a * a + b * b - e * e, 0.0) / scale)


def _cs2_sig(a1: float, b1: float, a2: float, b2: float, det_scale: float) -> float:
    """The condition of a two-equation step (_cs2; printed for a later step's _seed_miss):
    sqrt(|det| / det_scale), as _wrist_spread's (infinite without a scale)."""
    if det_scale <= 0.0:
        return math.inf
    return sqrt(abs(a1 * b2 - a2 * b1) / det_scale)


# beyond this acos argument a nominal table's values are near their fold (constants.py)
_FOLD_AT = min(_FOLD_NEAR, 1.0 - _FOLD_WIDTH * _SEED_TOL)


def _ray_gap(e, t, axis):
    """The distance of the point t's position from the ray of e's tool axis (0 x, 1 y, 2 z)
    from e's origin (a pose's 12 top entries each): the look-at task's miss."""
    v = (t[3] - e[3], t[7] - e[7], t[11] - e[11])
    u = (e[axis], e[4 + axis], e[8 + axis])
    along = v[0] * u[0] + v[1] * u[1] + v[2] * u[2]
    if along < 0.0:
        return math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return max(abs(v[0] - along * u[0]), abs(v[1] - along * u[1]), abs(v[2] - along * u[2]))


def _aims_at(e, t, tol):
    """Whether e's ray (the look-at task's: IK_COMPONENTS "lookat", TOOL_AXIS) passes t's
    point within tol or _AIM_POLISH radians, its miss over the point's distance along it (at
    least REACH): a point many reaches away is missed by the angles' errors times that
    distance, beyond tol * REACH, and such a row is polished before it is certified (_keep).
    False for every other task."""
    if IK_COMPONENTS != "lookat":
        return False
    v = (t[3] - e[3], t[7] - e[7], t[11] - e[11])
    along = v[0] * e[TOOL_AXIS] + v[1] * e[4 + TOOL_AXIS] + v[2] * e[8 + TOOL_AXIS]
    return along > 0.0 and _ray_gap(e, t, TOOL_AXIS) <= max(tol, _AIM_POLISH) * max(along, REACH)


def _free(t: float) -> _Free:
    if _LOOSE.near:  # (ik's second pass: noise near a boundary, not a search of the free values)
        return _Free([t])
    return _Free([t + step for step in _FREE_STEPS])


def _cs1x(
    a: float, b: float, e: float, rest: float, scale: float, ref: float, up: float = math.inf
) -> tuple[float, ...]:
    """_cs1 where rest = a^2 + b^2 - e^2 is given as a sum of squares, exact to roundings
    (derive/plan.py Cs1Unit): the values atan2(b, a) +- atan2(sqrt(rest), e). On a nominal
    table (_SEED_TOL > 0) rest is not read: there a wrist nearly straight is within the arm's
    difference of straight, and the snapped double root's free joint, held and refined onto
    the exact arm, finds its rows where an exact theta5 gave a theta6 the difference had moved
    (a UR5e URDF at q5 = 1e-7: 6 of 40 sampled vectors missed, none with acos's)."""
    return _cs1(a, b, e, scale, ref, rest, up)


def _cs1(
    a: float,
    b: float,
    e: float,
    scale: float = 0.0,
    ref: float = 0.0,
    rest: float = -1.0,
    up: float = math.inf,
) -> tuple[float, ...]:
    """Angles t with a cos t + b sin t = e: atan2(b, a) +- acos(e / sqrt(a^2 + b^2)), the
    acos argument clamped when it exceeds 1 by at most _CLAMP_TOL, or |e| exceeds
    sqrt(a^2 + b^2) by at most _CLAMP_ABS sqrt(scale) (and _seed_miss(up), up the least
    condition of the steps before it: a nominal table's
    equation seeds the refinement onto the exact arm at its boundary, as it does where
    |e| exceeds sqrt(a^2 + b^2) by at most _SEED_TOL sqrt(scale): the table's difference moves
    e by about that, which near a singular configuration, a and b small, is far beyond
    _SEED_BAND of the ratio: a hextilt arm's 0.0008 over 0.0092, 9%; where
    sqrt(a^2 + b^2) itself is within _SPREAD_WIDTH _SEED_TOL sqrt(scale), as where two links
    of nearly equal length fold back, _FOLD_SPREAD seeds all round; where the argument is
    near +-1, seeds either side of the fold, _FOLD_SEEDS), and taken as +-1 within _FOLD_TOL
    below (the double root).

    When a^2 + b^2 is at most _FREE_TOL * scale (_FREE_TOL_EXACT on an exact table: the
    wrist centre 1e-9 from axis 1 has its theta1) and e^2 at most _FREE_TOL * scale, the
    equation holds for every t (the angle is free; e.g. the wrist centre on axis 1):
    _free(ref); so it is where a^2 + b^2 is within _FREE_TOL * scale and no t solves it (an
    earlier joint's double root, snapped, leaves e 3e-11 off). Where rest >= 0 (a^2 + b^2 -
    e^2 as a sum of squares: _cs1x), the half-width is atan2(sqrt(rest), e), exact to
    roundings at the fold, where acos's is not.
    """
    rho = sqrt(a * a + b * b)
    small = rho * rho <= _FREE_TOL * scale
    free = small if _SEED_TOL else rho * rho <= _FREE_TOL_EXACT * scale
    loose = _LOOSE.on or _LOOSE.near  # (ik_approximate's seeds, or ik's second pass)
    if free or (small and abs(e) > rho * (1.0 + _CLAMP_TOL)):  # (loose: any seed)
        # (a nominal table's e within its difference of 0 too: an exact elbow folded back
        # whose wrist centre is 1.3e-7 from the shoulder's, where the nominal table's
        # nearest is 1.37e-7, had theta3 clamped to the fold, theta2's a and b 0 and e 1.3e-7:
        # a 7-decimal iiwa 7 URDF got no row there; a new user's find, helper 53)
        near = e * e <= _FREE_TOL * scale or abs(e) <= _SEED_TOL * sqrt(scale)
        return _free(ref) if near or loose else ()
    if rho == 0.0:
        return (ref,) if loose else ()
    if rho <= _SPREAD_WIDTH * _SEED_TOL * sqrt(scale) and not loose:
        return _all_round(atan2(b, a), _FOLD_SPREAD)  # (a nominal fold)
    ratio = e / rho
    if (
        abs(ratio) > 1.0 + _CLAMP_TOL + _seed_miss(up)
        and abs(e) - rho > max(_SEED_TOL, _CLAMP_ABS) * sqrt(scale)
        and not loose
    ):
        return ()
    base = atan2(b, a)
    if rest >= 0.0 and not _SEED_TOL:  # (a nominal table's fold keeps acos's: see _cs1x)
        delta = atan2(sqrt(rest), e)
    elif abs(ratio) >= 1.0 - _FOLD_TOL:
        delta = 0.0 if ratio > 0.0 else math.pi
    else:
        delta = acos(ratio)
    if _SEED_TOL and not loose and abs(ratio) > _FOLD_AT:
        fold = base if ratio > 0.0 else base + math.pi  # (a nominal fold: seeds either side)
        sides = tuple(fold + s * d for d in _FOLD_SEEDS for s in (1.0, -1.0))
        if delta in (0.0, math.pi):  # (the double root once, not twice)
            return (base + delta, *sides)
        return (base + delta, base - delta, *sides)
    return (base + delta, base - delta)


def _cs1_reach(
    a: float,
    b: float,
    e: float,
    m00: float,
    m01: float,
    m02: float,
    m10: float,
    m11: float,
    m12: float,
    m20: float,
    m21: float,
    m22: float,
    lo: float,
    hi: float,
    scale: float,
    ref: float,
    up: float = math.inf,
) -> tuple[float, ...]:
    """As _cs1; a free t starts at the first value _reach_first1 finds (the next joint must
    still let the wrist reach)."""
    rho = sqrt(a * a + b * b)
    free = _FREE_TOL if _SEED_TOL else _FREE_TOL_EXACT
    if rho * rho > free * scale or e * e > _FREE_TOL * scale:
        return _cs1(a, b, e, scale, ref, -1.0, up)
    return _free(_reach_first1(m00, m01, m02, m10, m11, m12, m20, m21, m22, lo, hi, ref))


def _cs2(
    a1: float,
    b1: float,
    e1: float,
    a2: float,
    b2: float,
    e2: float,
    det_scale: float,
    rhs_scale: float,
    ref: float,
) -> tuple[float, ...] | _Spread:
    """The angle t with a1 c + b1 s = e1 and a2 c + b2 s = e2; ref where t is free.

    t is free when the system is singular or, for a consistent system, when its right-hand
    side vanishes (then so does the determinant, up to the errors of earlier joints).
    """
    det = a1 * b2 - a2 * b1
    free = _cs2_free_tol()
    if abs(det) <= free * det_scale or e1 * e1 + e2 * e2 <= free * rhs_scale:
        return _free(ref)
    t = atan2((a1 * e2 - a2 * e1) / det, (e1 * b2 - b1 * e2) / det)
    return _wrist_spread(t, det, det_scale)


def _cs2_free_tol() -> float:
    """Below this times its scale a two-equation step's determinant (or its right-hand side's
    square) leaves its angle free: _FREE_TOL on a nominal table, _FREE_TOL_EXACT on an exact
    one, _FREE_TOL_LOOSE in ik's second pass."""
    if _LOOSE.near:
        return _FREE_TOL_LOOSE
    return _FREE_TOL if _SEED_TOL else _FREE_TOL_EXACT


def _wrist_spread(t: float, det: float, det_scale: float) -> tuple[float, ...] | _Spread:
    """(t,), or on a nominal table where the system is nearly singular (sqrt(|det| /
    det_scale) within _WRIST_WIDTH _SEED_TOL: the wrist nearly straight, where the arm's
    difference moves t anywhere) t and _SPREAD_COUNT - 1 more seeds all round, as _cs1's
    nominal fold (a calibrated UR5 at q5 = 1.5e-4 got t 0.77 rad off and no row); where it is
    less singular but the difference still moves t by u = _WRIST_SPREAD _SEED_TOL / sqrt(|det|
    / det_scale) >= _WRIST_NEAR, [t] as a _Spread, widened by t -+ u and t -+ 2 u where t
    gives no row (a seed that does not converge costs ~20 Newton steps: a calibrated KR6's
    C ik took 35% longer with all five always), and by the rest of _SPREAD_COUNT all round:
    u is the difference's effect times one, and a UR5 calibrated by 0.05 deg (s5 6.6e-3,
    sigma_min 1.5e-3) had theta6 0.86 rad from t, 5 u, and lost a branch's two rows (a
    reviewer's find, helper 77)."""
    loose = _LOOSE.on or _LOOSE.near
    if not _SEED_TOL or loose or det_scale <= 0.0:  # (a scale of 0: a system never free)
        return (t,)
    if abs(det) <= (_WRIST_WIDTH * _SEED_TOL) ** 2 * det_scale:
        return _all_round(t)
    u = _WRIST_SPREAD * _SEED_TOL / sqrt(abs(det) / det_scale)
    if u >= _WRIST_NEAR:
        return _Spread(t, (t - u, t + u, t - 2.0 * u, t + 2.0 * u, *_all_round(t)[1:]))
    return (t,)


def _all_round(first: float, count: int = _SPREAD_COUNT) -> tuple[float, ...]:
    """count seeds all round from first: a nominal table's angle that its equations fix
    only roughly."""
    return tuple(first + _TWO_PI * k / count for k in range(count))


def _cs2_reach(
    a1: float,
    b1: float,
    e1: float,
    a2: float,
    b2: float,
    e2: float,
    det_scale: float,
    rhs_scale: float,
    A: float,
    B: float,
    C: float,
    lo: float,
    hi: float,
    ref: float,
) -> tuple[float, ...] | _Spread:
    """As _cs2; a free t starts at _reach_first2's value (reachability of later joints)."""
    det = a1 * b2 - a2 * b1
    free = _cs2_free_tol()
    if abs(det) > free * det_scale and e1 * e1 + e2 * e2 > free * rhs_scale:
        t = atan2((a1 * e2 - a2 * e1) / det, (e1 * b2 - b1 * e2) / det)
        return _wrist_spread(t, det, det_scale)
    return _free(_reach_first2(A, B, C, lo, hi, ref))


def _atan2(y: float, x: float, ref: float) -> tuple[float, ...]:
    """atan2(y, x), or ref when both vanish (the angle is free)."""
    if abs(y) + abs(x) <= 1e-12:
        return _free(ref)
    return (atan2(y, x),)


def _poly_real(
    coeffs: tuple[float, ...] | np.ndarray, ref: float = 0.0, free: float = 0.0, unit: float = 1.0
) -> tuple[float, ...] | list[float]:
    """Real roots of the polynomial (highest degree first), polished, ascending, distinct;
    (ref,) when every coefficient is at most `free` (the polynomial vanishes: d is free).

    The roots are found for x / unit, unit being the arm's length, so that coefficients of a
    polynomial in a length are compared at their proper scale (a constant leading coefficient
    is small beside r^2 in metres squared to the fourth, yet never negligible).
    """
    c = [float(x) for x in coeffs]
    scale = max(abs(x) for x in c)
    if scale <= free:
        return (ref,)
    if scale == 0.0:
        return ()
    n = len(c) - 1
    c = [x * unit ** (n - k) for k, x in enumerate(c)]
    scale = max(abs(x) for x in c)
    while len(c) > 1 and abs(c[0]) <= _LEAD_TOL * scale:
        c.pop(0)
    if len(c) < 2:
        return ()
    roots = sorted(_real_roots(c))
    out: list[float] = []
    for x in roots:
        if not out or abs(x - out[-1]) > 1e-12 * (1.0 + abs(x)):
            out.append(x)
    return [x * unit for x in out]


def _poly_angles(
    coeffs: tuple[float, ...] | np.ndarray, ref: float = 0.0, free: float = 0.0
) -> tuple[float, ...] | list[float]:
    """Angles t whose u = tan(t/2) is a real root of the polynomial (highest degree first).

    The polynomial is solved in u, or in v = 1/u when its last coefficient is the larger
    end, so that a vanishing leading coefficient (a root at u = infinity, t = pi;
    docs/algorithms.md, "Polynomials in u = tan(t/2) and the root at t = pi") is an ordinary
    root v = 0. When both ends vanish (below _LEAD_TOL of the largest coefficient) the
    leading one is deflated as its exact root. Angles are wrapped to
    (-pi, pi] (within 1e-12 of +-pi: pi), sorted, and equal ones (1e-12) merged. Near-double
    roots come out as complex pairs with a small imaginary part; they are accepted and
    polished. Every candidate is certified by forward kinematics afterwards, so a spurious
    angle costs time, never correctness.
    When every coefficient is at most `free` the polynomial vanishes identically: the angle
    is free: _free(ref).
    """
    c = [float(x) for x in coeffs]
    size = max(abs(x) for x in c)
    if size <= free:
        return _free(ref)
    if size == 0.0:
        return ()
    flip = abs(c[0]) < abs(c[-1])
    if flip:
        c.reverse()
    angles = []
    while len(c) > 1 and abs(c[0]) <= _LEAD_TOL * size:
        # both ends vanish (roots at u = 0 and u = infinity): the one at this end is exact
        c.pop(0)
        angles.append(0.0 if flip else math.pi)
    for x in _real_roots(c) if len(c) > 1 else ():
        angles.append(_wrap_snap(2.0 * atan2(1.0, x) if flip else 2.0 * math.atan(x)))
    return _sorted_angles(angles)


def _sorted_angles(angles: list[float]) -> list[float]:
    """The angles sorted, each within 1e-12 of the one before dropped."""
    angles.sort()
    out: list[float] = []
    for t in angles:
        if not out or t - out[-1] > 1e-12:
            out.append(t)
    return out


def _poly_angles_pi(
    coeffs: tuple[float, ...] | np.ndarray, ref: float = 0.0, free: float = 0.0
) -> tuple[float, ...] | list[float]:
    """_poly_angles of a quartic t -> t + pi leaves unchanged, coefficients a, b, c, -b, a
    (derive/plan.py PolyPi): divided by u^2 it is a w^2 + b w + (c + 2a) = 0 in
    w = u - 1/u = -2 cot t, and each real w gives u = (w +- sqrt(w^2 + 4)) / 2, whose angles
    are t and t + pi: two square roots where the quartic takes Ferrari's formulas (an SO-100's
    theta1). Where the polynomial is free, or a is within _LEAD_TOL of vanishing (a root near
    t = 0 or pi, where _poly_angles deflates it exactly), _poly_angles.
    """
    c = [float(x) for x in coeffs]
    size = max(abs(x) for x in c)
    if size <= free or abs(c[0]) <= _LEAD_TOL * size:
        return _poly_angles(coeffs, ref, free)
    angles = []
    for w in _real_roots([c[0], c[1], c[2] + 2.0 * c[0]]):
        u = 0.5 * (w + math.copysign(sqrt(w * w + 4.0), w))
        t = _wrap_snap(2.0 * math.atan(u))
        angles += [t, _wrap_snap(t - math.pi if t > 0.0 else t + math.pi)]
    return _sorted_angles(angles)


def _wrap_snap(t: float) -> float:
    t = _wrap(t)
    return math.pi if math.pi - abs(t) <= 1e-12 else t


def _real_roots(p: list[float]) -> list[float]:
    """Real roots of p (highest degree first, p[0] != 0), Newton-polished.

    Closed forms for degrees 1, 2 and 4 (Ferrari); the companion matrix (numpy.roots) for
    other degrees and whenever a closed-form root fails the residual test.
    """
    d = len(p) - 1
    lead = p[0]
    if d == 1:
        return [-p[1] / lead]
    if d == 2:
        zs = _kquadratic(p[1] / lead, p[2] / lead)
    elif d == 4:
        zs = _kquartic(p[1] / lead, p[2] / lead, p[3] / lead, p[4] / lead)
    else:
        zs = None
    if zs is not None:
        roots = _accept(p, zs)
        if roots is not None:
            return roots
    return _accept(p, np.roots(p).tolist(), check=False) or []


def _accept(p: list[float], zs: list[complex], check: bool = True) -> list[float] | None:
    """Polished real parts of the near-real zs; None if one fails the residual test, or
    (check) if a complex one does: Ferrari's formulas for a quartic whose leading coefficient is
    1e-9 of the largest (both ends nearly vanish: a FANUC LR Mate's shoulder and elbow 1e-8
    from -90 and 0 deg) gave one real root right and three wrong, complex, and lost six of
    eight rows; the companion matrix then finds all four.

    A double root comes out split, as a complex pair or as two reals about sqrt(eps) apart;
    roots closer than _MERGE_TOL give their mean, which is accurate, unless the mean is
    farther from a root than rounding splits one (_SPLIT_TOL): two roots that close can be
    two, and are kept (a finger's knee within 1e-6 of folded back: 1/u's roots 1e-7 to 5e-7
    apart, and 76 of 200 such positions got no row from the mean alone; with the mean as well,
    its row at the fold, within 1e-13 of the pose, took the place of a root's at dedup). A root of
    multiplicity k splits by about eps^(1/k) (1e-4 for k = 4) into a cluster, not all real,
    whose mean is accurate too: such a cluster within _CLUSTER_TOL gives its mean. Merged
    roots and cluster means are not Newton-polished: at a multiple root p and p' both
    vanish, and Newton's step is rounding noise divided by rounding noise (it moved a double
    root by 3.5e-5).
    """
    xs = []
    split = False
    for z in zs:
        z = complex(z)
        if abs(z.imag) <= _ROOT_IMAG_TOL * (1.0 + abs(z)):
            xs.append((z.real, True))
            continue
        if check and not _small_residual(p, z):  # (a closed form's complex root, wrong)
            return None
        if abs(z.imag) <= _CLUSTER_TOL * (1.0 + abs(z)):
            split = True
    if split:
        xs = [
            (z.real, simple)
            for z, simple in _clusters([complex(z) for z in zs])
            if abs(z.imag) <= _ROOT_IMAG_TOL * (1.0 + abs(z))
        ]
    xs.sort()
    out = []
    k = 0
    while k < len(xs):
        x, simple = xs[k]
        if k + 1 < len(xs) and xs[k + 1][0] - x <= _MERGE_TOL * (1.0 + abs(x)):
            y = xs[k + 1][0]
            k += 1
            if _two_roots(p, 0.5 * (x + y)):  # (two roots, not one split by rounding: both)
                if check and not (_small_residual(p, x) and _small_residual(p, y)):
                    return None
                out += [x, y]
                k += 1
                continue
            x = 0.5 * (x + y)
        elif simple:
            x = _newton(p, x)
        if check and not _small_residual(p, x):
            return None
        out.append(x)
        k += 1
    if _SEED_TOL or _LOOSE.on:  # a nominal table's near-double root, split by the arm's
        # difference (or any complex root, seeding ik_approximate or ik's second pass: a thin
        # reach, as a Kinova Gen3 position task's, its tip 0.175 mm from the last solved
        # axis, leaves poses near its edge an imaginary pair 0.041-0.062 from real in u,
        # beyond this window's 0.039; _seed drops the seeds beyond _SEED_TOL of the pose)
        near = math.inf if _LOOSE.on or _LOOSE.near else math.sqrt(_SEED_TOL)
        for z in map(complex, zs):
            if _ROOT_IMAG_TOL * (1.0 + abs(z)) < z.imag <= near * (1.0 + abs(z)):
                out.append(z.real)
                if not _LOOSE.on:  # (and either side of the fold, as _cs1's _FOLD_SEEDS: a
                    # half-angle's u or 1/u, turned by +-_FOLD_SEEDS[0] / 2)
                    w = math.atan(z.real)
                    out += [math.tan(w + s * 0.5 * _FOLD_SEEDS[0]) for s in (1.0, -1.0)]
    return out


def _clusters(zs: list[complex]) -> list[tuple[complex, bool]]:
    """zs with each cluster of nearby roots that are not all real replaced by its mean, as
    (root, whether it is a simple root rather than a cluster's mean)."""
    out = []
    left = list(zs)
    while left:
        z = left.pop(0)
        group = [z] + [w for w in left if abs(w - z) <= _CLUSTER_TOL * (1.0 + abs(z))]
        if len(group) > 1 and any(abs(w.imag) > _ROOT_IMAG_TOL * (1.0 + abs(w)) for w in group):
            left = [w for w in left if all(w is not g for g in group)]
            out.append((sum(group) / len(group), False))
        else:
            out.append((z, True))
    return out


# Branches. A step that gives several values of its joint gives them as the roots of one
# equation f(t) = 0; the sign of f'(t) at a root labels it, and it changes only where two
# roots meet (f' = 0: a fold, a singular configuration). So a solution's signs, one per such
# step, stay the same along a path that crosses no fold: they name its branch (shoulder,
# elbow, wrist configuration) whatever the distances (branch(T, q) in motion.py).


def _cs1_branch(a: float, b: float, t: float) -> int:
    """The branch of t among the values of a cos t + b sin t = e: +1 for atan2(b, a) + acos,
    -1 for - acos (the sign of -f'(t) = a sin t - b cos t), 0 at the fold, where they meet."""
    slope = a * sin(t) - b * cos(t)
    if abs(slope) <= _BRANCH_FOLD * sqrt(a * a + b * b):
        return 0
    return 1 if slope > 0.0 else -1


def _poly_branch(coeffs: tuple[float, ...], t: float) -> int:
    """The branch of the root t of a polynomial in u = tan(t/2) (coefficients highest degree
    first): the sign of dH/dt, H(t) = cos(t/2)^n p(tan(t/2)) (smooth through t = pi, where u
    is infinite), 0 at a fold (a double root). t is wrapped first: H changes sign by a turn
    of t where n is odd."""
    n = len(coeffs) - 1
    t = _wrap(t)
    c, s = cos(t / 2.0), sin(t / 2.0)
    slope = 0.0
    for k, a in enumerate(coeffs):  # (a u^m, m = n - k: a s^m c^(n - m) in H)
        m = n - k
        if m:
            slope += a * m * s ** (m - 1) * c ** (n - m + 1)
        if n - m:
            slope -= a * (n - m) * s ** (m + 1) * c ** (n - m - 1)
    if abs(slope) <= _BRANCH_FOLD * n * sum(abs(a) for a in coeffs):
        return 0
    return 1 if slope > 0.0 else -1


def _polyd_branch(coeffs: tuple[float, ...], d: float) -> int:
    """The branch of the root d of a polynomial in d (coefficients highest degree first): the
    sign of p'(d), 0 at a fold (a double root)."""
    n = len(coeffs) - 1
    terms = [a * (n - k) * d ** (n - k - 1) for k, a in enumerate(coeffs[:-1])]
    slope = sum(terms)
    if abs(slope) <= _BRANCH_FOLD * sum(abs(x) for x in terms):
        return 0
    return 1 if slope > 0.0 else -1
