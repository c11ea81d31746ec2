"""The runtime's routines tested directly: the scalar, vectorised and compiled variants of each
step routine against each other, on random inputs and on the edges where they could part
(double roots, a vanishing leading coefficient, |e| just above sqrt(a^2 + b^2), signed zeros,
inf and nan)."""

from __future__ import annotations

import math
import types

import numpy as np
import pytest

from derive.runtime import closed, constants, kernel, scalar, vector

RNG = np.random.default_rng(7)


def kernel_functions() -> dict[str, types.FunctionType]:
    """The kernel routines as numba compiles them (copies in one namespace, as _build_kernels
    does in a generated module), or as Python where numba is not installed."""
    names: dict[str, object] = {}
    for module in (constants, closed, scalar, vector, kernel):
        names.update({k: v for k, v in vars(module).items() if not k.startswith("__")})
    try:
        import numba
    except ImportError:
        return {k: v for k, v in names.items() if isinstance(v, types.FunctionType)}
    wanted = ("_kcs1", "_kcs2", "_katan2", "_kpoly", "_kroots", "_kangle", "_kwrap")
    wanted += ("_kquadratic", "_kcubic_largest", "_kquartic", "_kquadratic_real")
    wanted += ("_kquartic_real", "_ksort", "_newton", "_small_residual")
    for name in wanted:
        python = names[name]
        assert isinstance(python, types.FunctionType)
        copy = types.FunctionType(python.__code__, names, python.__name__, python.__defaults__)
        names[name] = numba.njit(cache=False, error_model="numpy")(copy)
    return {k: names[k] for k in wanted}  # type: ignore[misc]


@pytest.fixture(scope="module")
def compiled():
    return kernel_functions()


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


def test_cs1_scalar_vector_and_compiled_agree(compiled):
    cases = cs1_inputs()
    A, B, E = (np.array(c) for c in zip(*cases))
    like = np.zeros((len(cases), 1))
    with np.errstate(all="ignore"):
        values, ok, free = vector._vcs1(A[:, None], B[:, None], E[:, None], 1.0, 0.0, 1, like)
    for k, (a, b, e) in enumerate(cases):
        with np.errstate(all="ignore"):
            expected = scalar._cs1(a, b, e, 1.0, 0.0)
        vec = [float(v) for v, o in zip(values[k], ok[k]) if o]
        n, t0, c0, s0, t1, c1, s1, status = compiled["_kcs1"](a, b, e, 1.0)
        if isinstance(expected, scalar._Free):
            assert free[k, 0] and status == 1 and vec == [expected[0]], (a, b, e)
            continue
        assert status == 0 and not free[k].any(), (a, b, e)
        # nan in, nan out: the scalar and compiled routines give nan angles, the vectorised
        # one invalid slots; certification drops both
        expected = finite(expected)
        comp = finite([t0, t1][:n])
        assert same_angles(finite(vec), expected) and same_angles(comp, expected), (a, b, e)
        for t, c, s in ((t0, c0, s0), (t1, c1, s1))[:n]:
            if math.isfinite(t) and all(map(math.isfinite, (a, b, e))):
                assert abs(c - math.cos(t)) <= 1e-12 and abs(s - math.sin(t)) <= 1e-12
        for t in expected:  # and the values solve the equation (clamped: up to the clamp)
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


def test_atan2_and_cs2_variants_agree(compiled):
    like = np.zeros((1,))
    for y, x in [*RNG.normal(size=(50, 2)), (0.0, 0.0), (-0.0, -0.0), (1e-13, 0.0), (0.0, -1.0)]:
        y, x = float(y), float(x)
        expected = scalar._atan2(y, x, 0.5)
        value, _, free = vector._vatan2(np.array(y), np.array(x), 0.5, 0, like)
        t, c, s, status = compiled["_katan2"](y, x)
        if isinstance(expected, scalar._Free):
            assert status == 1 and bool(free[0]) and float(value[0]) == 0.5
        else:
            assert (
                status == 0
                and same_angles([t], expected)
                and same_angles([float(value[0])], expected)
            )
            assert abs(c - math.cos(t)) <= 1e-12 and abs(s - math.sin(t)) <= 1e-12
    for row in RNG.normal(size=(50, 6)):
        args = (*map(float, row), 1.0, 1.0)
        expected = scalar._cs2(*args, 0.0)
        value, _, _ = vector._vcs2(*(np.array(a) for a in args), 0.0, 0, like)
        t, c, s, status = compiled["_kcs2"](*args)
        assert (
            status == 0 and same_angles([t], expected) and same_angles([float(value[0])], expected)
        )


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


def test_poly_angles_scalar_vector_and_compiled_agree(compiled):
    polys = polynomials()
    for p in polys:
        expected = scalar._poly_angles(p, 0.0, 0.0)
        coeffs = tuple(np.array([c]) for c in p)
        x, ok, free = vector._vpoly(coeffs, 1, np.zeros((1, 1)), True, 0.0, 0.0)
        vec = [float(v) for v, o in zip(x[0], ok[0]) if o]
        buf = np.zeros(6 * (len(p) - 1) + 1)
        n = compiled["_kpoly"](np.array(p), True, 0.0, 1.0, buf)
        if isinstance(expected, scalar._Free):
            assert n == -2 and bool(free[0, 0]), p
            continue
        assert same_angles(vec, expected, 1e-9), (p, vec, expected)
        if n >= 0:  # -1: the compiled solver leaves the pose to the Python one
            assert same_angles(list(buf[:n]), expected, 1e-9), (p, buf[:n], expected)
            d = len(p) - 1
            for k in range(n):
                assert abs(buf[4 * d + 1 + k] - math.cos(buf[k])) <= 1e-9
                assert abs(buf[5 * d + 1 + k] - math.sin(buf[k])) <= 1e-9
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


def test_quartic_closed_forms_agree_with_the_companion_matrix(compiled):
    for p in RNG.normal(size=(300, 5)):
        p = p / p[0]
        reference = sorted(np.roots(p), key=lambda z: (z.real, z.imag))
        for roots in (
            closed._kquartic(*(complex(x) for x in p[1:])),
            compiled["_kquartic_real"](*p[1:]),
            tuple(np.array(vector._vquartic(*(np.array([complex(x)]) for x in p[1:])))[:, 0]),
        ):
            # each root near one of the other's (conjugate pairs come in either order)
            distance = np.abs(np.subtract.outer(np.array(roots), np.array(reference)))
            assert distance.min(axis=0).max() <= 1e-8 and distance.min(axis=1).max() <= 1e-8


@pytest.mark.parametrize("x", [0.0, -0.0, 1.0, -1.0, 1e-300, -1e300, math.inf, -math.inf, math.nan])
@pytest.mark.parametrize("y", [0.0, -0.0, 1.0, -1.0, 3.5, math.inf, math.nan])
def test_kangle_is_atan2_to_a_few_ulp(compiled, x, y):
    got, want = compiled["_kangle"](y, x), math.atan2(y, x)
    if math.isnan(want):
        assert math.isnan(got)
    else:
        assert got == pytest.approx(want, abs=4e-16) and math.copysign(1, got) == math.copysign(
            1, want
        )


def test_kangle_on_random_points(compiled):
    for y, x in RNG.normal(size=(2000, 2)) * 10.0 ** RNG.integers(-5, 5, size=(2000, 1)):
        assert abs(compiled["_kangle"](y, x) - math.atan2(y, x)) <= 1e-15 * 4
