"""The Python solver's step routines tested directly, on random inputs and on their edges
(double roots, a vanishing leading coefficient, |e| just above sqrt(a^2 + b^2), signed zeros,
inf and nan). The C solver's routines are held to the same answers through whole solvers
(tests/test_c.py, test_batch.py)."""

from __future__ import annotations

import math

import numpy as np

from derive.runtime import closed, scalar

RNG = np.random.default_rng(7)


def cs1_inputs() -> list[tuple[float, float, float]]:
    """(a, b, e): random, and the edges of a cos + b sin = e."""
    cases = [tuple(x) for x in RNG.normal(size=(200, 3))]
    for a, b in RNG.normal(size=(20, 2)):
        rho = math.hypot(a, b)
        for factor in (1.0, -1.0, 1 - 1e-15, 1 + 1e-15, 1 + 1e-8, 1 + 1e-6, 1 - 1e-9):
            cases.append((a, b, factor * rho))
    cases += [(0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (-0.0, 0.0, 0.0), (1.0, -0.0, 1.0)]
    cases += [(0.0, -0.0, -0.0), (math.inf, 1.0, 0.5), (math.nan, 1.0, 0.5), (1.0, 1.0, math.nan)]
    return cases


def same_angles(a, b, tol=1e-12) -> bool:
    a, b = sorted(a), sorted(b)
    return len(a) == len(b) and all(
        abs(math.remainder(x - y, 2 * math.pi)) <= tol for x, y in zip(a, b)
    )


def test_cs1_solves_its_equation_on_random_inputs_and_edges():
    for a, b, e in cs1_inputs():
        with np.errstate(all="ignore"):
            expected = scalar._cs1(a, b, e, 1.0, 0.0)
        if isinstance(expected, scalar._Free):
            assert a == b == e == 0.0 and expected[0] == 0.0, (a, b, e)
            continue
        assert len(expected) in (0, 2), (a, b, e)
        for t in finite(expected):  # the values solve the equation (clamped: up to the clamp)
            rho = math.hypot(a, b)
            assert abs(a * math.cos(t) + b * math.sin(t) - e) <= 1e-7 * max(rho, 1.0)


def finite(values) -> list[float]:
    return [float(t) for t in values if math.isfinite(t)]


def test_cs1_edges_by_name():
    rho = 5.0
    assert scalar._cs1(3.0, 4.0, rho * (1 + 1e-8)) != ()  # within the clamp: one double root
    assert scalar._cs1(3.0, 4.0, rho * (1 + 1e-6)) == ()  # beyond it: none
    t0, t1 = scalar._cs1(3.0, 4.0, rho * (1 - 1e-15))  # the fold: the exact double root
    assert t0 == t1 == math.atan2(4.0, 3.0)
    assert isinstance(scalar._cs1(0.0, 0.0, 0.0, 1.0, 0.25), scalar._Free)
    assert scalar._cs1(0.0, 0.0, 1.0, 1.0) == ()


def test_atan2_and_cs2():
    for y, x in [*RNG.normal(size=(50, 2)), (0.0, 0.0), (-0.0, -0.0), (1e-13, 0.0), (0.0, -1.0)]:
        y, x = float(y), float(x)
        expected = scalar._atan2(y, x, 0.5)
        if isinstance(expected, scalar._Free):
            assert expected[0] == 0.5 and math.hypot(x, y) < 1e-12
        else:
            assert same_angles(expected, [math.atan2(y, x)])
    for row in RNG.normal(size=(50, 5)):
        a1, b1, a2, b2, t0 = map(float, row)
        e1 = a1 * math.cos(t0) + b1 * math.sin(t0)
        e2 = a2 * math.cos(t0) + b2 * math.sin(t0)
        assert same_angles(scalar._cs2(a1, b1, e1, a2, b2, e2, 1.0, 1.0, 0.0), [t0], 1e-9)


def polynomials() -> list[list[float]]:
    """Quartics and quadratics: random, with double roots, with a root at u = inf (leading
    coefficient 0), with both ends vanishing, and one that vanishes identically."""
    out = [list(p) for p in RNG.normal(size=(100, 5))] + [list(p) for p in RNG.normal(size=(30, 3))]
    for r in RNG.normal(size=(20, 3)):
        out.append(list(np.poly([r[0], r[0], r[1], r[2]])))  # a double root
        out.append(list(np.poly([r[0], r[0], r[1], r[1]])))  # two double roots
        out.append([0.0, *np.poly([r[0], r[1], r[2]])])  # u = inf: t = pi
    out.append([0.0, 1.0, -3.0, 2.0, 0.0])  # roots at u = inf and u = 0
    out.append([-0.0, 0.0, 1.0, 0.0, -1.0])
    out.append([0.0, 0.0, 0.0, 0.0, 0.0])
    return out


def test_poly_angles_are_roots_in_the_half_angle():
    for p in polynomials():
        expected = scalar._poly_angles(p, 0.0, 0.0)
        if isinstance(expected, scalar._Free):
            assert not any(p), p
            continue
        for t in expected:  # each angle is a root of the polynomial in u = tan(t/2)
            c, s = math.cos(t / 2), math.sin(t / 2)
            d = len(p) - 1
            value = sum(k * s ** (d - i) * c**i for i, k in enumerate(p))
            assert abs(value) <= 1e-6 * max(map(abs, p)), (p, t)


def test_double_roots_come_once_and_exact():
    for r in RNG.normal(size=(20, 2)):
        p = list(np.poly([r[0], r[0], r[1], r[1] + 5.0]))
        angles = scalar._poly_angles(p)
        wanted = sorted(2 * math.atan(x) for x in (r[0], r[1], r[1] + 5.0))
        assert same_angles(angles, wanted, 1e-7), (angles, wanted)


def test_quartic_closed_form_agrees_with_the_companion_matrix():
    for p in RNG.normal(size=(300, 5)):
        p = p / p[0]
        reference = sorted(np.roots(p), key=lambda z: (z.real, z.imag))
        for roots in (closed._kquartic(*(complex(x) for x in p[1:])),):
            # each root near one of the other's (conjugate pairs come in either order)
            distance = np.abs(np.subtract.outer(np.array(roots), np.array(reference)))
            assert distance.min(axis=0).max() <= 1e-8 and distance.min(axis=1).max() <= 1e-8


def test_branch_signs_are_constant_along_each_branch_and_opposite_across():
    """a cos t + b sin t = e, swept so that its - acos value passes through t = pi: the
    branch of each value is the same all along, as the equation (_cs1_branch) and as its
    half-angle quadratic (c + a) u^2 - 2 b u + (c - a) (_poly_branch, smooth where u is
    infinite), and the two values have opposite signs; at the fold (e = rho) both are 0."""
    a, b = 0.3, -0.4
    rho = math.hypot(a, b)
    seen: dict[int, set[int]] = {1: set(), -1: set()}
    for e in np.linspace(-0.49, 0.49, 301):
        base, delta = math.atan2(b, a), math.acos(e / rho)
        quadratic = (e + a, -2.0 * b, e - a)
        for sign in (1, -1):
            t = base + sign * delta
            assert scalar._cs1_branch(a, b, t) == sign
            seen[sign].add(scalar._poly_branch(quadratic, t))
            seen[sign].add(scalar._poly_branch(quadratic, t + 2.0 * math.pi))
    (plus,), (minus,) = seen[1], seen[-1]
    assert plus == -minus != 0
    assert scalar._cs1_branch(a, b, math.atan2(b, a)) == 0
    assert scalar._poly_branch((1.0, -2.0, 1.0), math.pi / 2.0) == 0  # ((u - 1)^2 at u = 1)
    assert scalar._polyd_branch((1.0, 0.0, -4.0), 2.0) == 1  # (d^2 - 4 rising at d = 2)
    assert scalar._polyd_branch((1.0, 0.0, -4.0), -2.0) == -1
