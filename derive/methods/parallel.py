"""6R arms with three consecutive parallel axes (UR type; the blog post's arm), ALGORITHMS.md s. 3.

With axes 2, 3, 4 parallel, P = Z2 X2 Z3 X3 Z4 is planar: its third row (0, 0, +-1, d)
does not depend on theta2..theta4. So the third row of M = (Z1 X1)^-1 0_6T equals the third row
of P X4 Z5 X5 Z6, which involves theta1 (left) and theta5, theta6 (right) only. The blog post's
steps follow, each read off derived expressions:

1. theta1 from the translation entry, e.g. -s1 px + c1 py = d2 (a cos + b sin = c, two roots);
   with a5 != 0 that entry also holds theta5 and the two entries (3,3) and (3,4) are eliminated
   into a quartic in tan(theta1/2);
2. theta5 from entry (3,3), e.g. c5 = -s1 r13 + c1 r23 (two roots);
3. theta6 from entries (3,1), (3,2): h^T Rz(theta6) = m^T; free when h vanishes (theta5 = 0);
4. the planar 3R for theta2, theta3, theta4 from G = M (X4 Z5 X5 Z6)^-1 = P.

Axes 3, 4, 5 parallel are solved on the reversed chain, where they are axes 2, 3, 4.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure
from derive.halfangle import half_angle_poly, linear_coeffs, reduce_pairs
from derive.methods.common import (
    NotApplicable,
    flange_target,
    joint_outputs,
    joint_refs,
    reversed_refs,
    typical_magnitude,
    unreverse_outputs,
)
from derive.methods.planar import flange_factors, heading_step, planar_steps
from derive.plan import Assign, Cs1, Cs2, Cs2Reach, IkPlan, Poly, Solve, Step
from derive.transforms import Chain, inverse, numbers_of, product, reverse_chain

NAME = "three-parallel"
# theta5 comes from acos of entry (3,3), accurate to ~1e-8 near 0 and pi: |h| below 1e-7
# (h^2 below _FREE_TOL = 1e-14) is treated as the singular wrist, where theta6 is free.
SIN5_FREE = sp.Integer(1)


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """Plan for axes 2-3-4 (or 3-4-5) parallel, or why the method does not apply."""
    if chain.dof != 6:
        return f"three-parallel: needs 6 joints, the arm has {chain.dof}"
    if any(j.kind != "R" for j in chain.joints):
        return "three-parallel: needs six revolute joints"
    triples = structure.parallel_triples
    if any(i + 1 in triples for i in triples):
        return "three-parallel: four consecutive parallel axes (a degree of freedom is lost)"
    refs = joint_refs(chain)
    try:
        if 2 in triples:
            return derive_234(chain, sym.world_pose(), refs, "")
        if 3 in triples:
            rev = reverse_chain(chain)
            plan = derive_234(
                rev,
                inverse(sym.world_pose()),
                reversed_refs(rev),
                "axes 3-5 parallel: reversed chain (joint k is joint 7 - k, "
                "q'_k = -q_{7-k}), solved for T^-1; ",
            )
            return replace(plan, outputs=unreverse_outputs(plan.outputs))
    except NotApplicable as exc:
        return str(exc)
    return "three-parallel: axes 2, 3, 4 (or 3, 4, 5) are not parallel"


def derive_234(chain: Chain, target: sp.Matrix, refs: tuple[sp.Expr, ...], prefix: str) -> IkPlan:
    """The plan for axes 2, 3, 4 parallel (section 3.1-3.4)."""
    numbers = numbers_of(chain)
    mats = [m.xreplace(numbers) for m in flange_factors(chain)]
    base_part = product(mats[0:2])  # Z1 X1
    planar_part = product(mats[2:7])  # Z2 X2 Z3 X3 Z4
    wrist_part = product(mats[7:])  # X4 Z5 X5 Z6
    row = planar_part[2, :]
    if row.has(*(f(i) for i in (2, 3, 4) for f in (sym.c, sym.s))):
        raise NotApplicable(
            "three-parallel: the third row of Z2 X2 Z3 X3 Z4 depends on the parallel joints"
        )
    lhs = (inverse(base_part) * sym.flange_pose())[2, :].applyfunc(sp.expand)
    rhs = (row * wrist_part).applyfunc(sp.expand)
    equations = [sp.expand(lhs[k] - rhs[k]) for k in range(4)]
    length = sum(abs(float(t.a)) for t in chain.twists) + sum(abs(float(j.d)) for j in chain.joints)
    g = sp.Matrix(3, 4, lambda i, j: sym.named(f"G{i + 1}{j + 1}"))
    g_value = (inverse(base_part) * sym.flange_pose() * inverse(wrist_part))[:3, :]
    g_value = g_value.applyfunc(sp.expand)
    position = planar_part[:2, 3].applyfunc(sp.expand)
    planar = planar_steps(position[0], position[1], 2, 3, g[0, 3], g[1, 3], refs, length)
    steps: list[Step] = [flange_target(chain, target)]
    steps += theta1_theta5_steps(equations[3], equations[2], refs, length)
    first_planar = planar[0]
    assert isinstance(first_planar, Solve)
    steps += theta6_steps(equations[0], equations[1], g_value, first_planar, refs)
    steps.append(
        Assign(
            tuple(g),
            tuple(g_value),
            "G = (Z1 X1)^-1 0_6T (X4 Z5 X5 Z6)^-1 = Z2 X2 Z3 X3 Z4 (planar)",
        )
    )
    steps += planar
    before = product(mats[2:6])[:3, :3]
    steps.append(heading_step(before, sp.eye(3), 4, refs, g[:, :3]))
    outputs = joint_outputs(chain)
    case = prefix + (
        "a5 = 0: theta1 from one a cos + b sin = c equation"
        if not equations[3].has(sym.c(5), sym.s(5))
        else "a5 != 0: quartic in tan(theta1/2)"
    )
    return IkPlan(NAME, case, 8, tuple(steps), outputs)


def theta1_theta5_steps(
    pos_eq: sp.Expr, z6_eq: sp.Expr, refs: tuple[sp.Expr, ...], length: float
) -> list[Step]:
    """theta1 and theta5 from entries (3,4) and (3,3) of the invariant equation."""
    c1, s1, c5, s5, u = sym.c(1), sym.s(1), sym.c(5), sym.s(5), sym.named("u")
    if not pos_eq.has(c5, s5):
        a, b, c = linear_coeffs(pos_eq, c1, s1)
        if a == 0 and b == 0:
            raise NotApplicable("three-parallel: the translation entry does not involve theta1")
        a5, b5, c5_ = linear_coeffs(z6_eq, c5, s5)
        if a5 == 0 and b5 == 0:
            raise NotApplicable("three-parallel: entry (3,3) does not involve theta5")
        return [
            Cs1(
                1,
                (a, b, -c),
                "theta1: translation entry (3,4) of the invariant equation, a c1 + b s1 = c",
                2,
                refs[0],
                length**2,
            ),
            Cs1(5, (a5, b5, -c5_), "theta5: entry (3,3) of the invariant equation", 2),
        ]
    pa, pb, pc = linear_coeffs(pos_eq, c5, s5)
    za, zb, zc = linear_coeffs(z6_eq, c5, s5)
    if any(e.has(c1, s1) for e in (pa, pb, za, zb)):
        raise NotApplicable("three-parallel: theta5's coefficients depend on theta1")
    det = sp.expand(pa * zb - za * pb)
    if det == 0:
        raise NotApplicable("three-parallel: entries (3,3) and (3,4) are dependent in theta5")
    cos5 = -(pc * zb - pb * zc)
    sin5 = -(pa * zc - za * pc)
    equation = reduce_pairs(cos5**2 + sin5**2 - det**2, [(s1, c1)])
    coeffs = half_angle_poly(equation, c1, s1, u)
    return [
        Poly(
            1,
            coeffs,
            f"theta1: (c5, s5) eliminated from entries (3,3), (3,4): "
            f"polynomial of degree {len(coeffs) - 1} in u = tan(theta1/2)",
            len(coeffs) - 1,
            refs[0],
            typical_magnitude(coeffs, length),
        ),
        Cs2(
            5,
            (pa, pb, -pc, za, zb, -zc, sp.Integer(0), sp.Integer(0)),
            "theta5: entries (3,3) and (3,4), linear in (c5, s5)",
            1,
        ),
    ]


def theta6_steps(
    e1: sp.Expr, e2: sp.Expr, g_value: sp.Matrix, elbow: Solve, refs: tuple[sp.Expr, ...]
) -> list[Step]:
    """theta6 from entries (3,1), (3,2): h^T Rz(theta6) = m^T (section 3.3).

    Where h vanishes (z6 parallel to axes 2-4, e.g. theta5 = 0) theta6 is free, but not every
    value works: theta6 turns the wrist offset about the parallel axes and so moves the planar
    3R's target. The squared radius of that target is A + B c6 + C s6 (its values at theta6 = 0,
    90 and 180 deg give A, B, C); the free theta6 is q_ref's if that radius is reachable by
    the elbow, else the value nearest it that puts the radius mid-range.
    """
    c6, s6 = sym.c(6), sym.s(6)
    a1, b1, r1 = linear_coeffs(e1, c6, s6)
    a2, b2, r2 = linear_coeffs(e2, c6, s6)
    radius = g_value[0, 3] ** 2 + g_value[1, 3] ** 2
    at = [radius.xreplace({c6: cv, s6: sv}) for cv, sv in ((1, 0), (0, 1), (-1, 0))]
    names = tuple(sym.named(n) for n in ("rad0", "rad90", "rad180"))
    bound = radius_range(elbow, (sym.named("G14"), sym.named("G24")))
    rad_a = (names[0] + names[2]) / 2
    return [
        Assign(names, tuple(at), "squared radius of the planar target at theta6 = 0, 90, 180 deg"),
        Cs2Reach(
            6,
            (
                a1,
                b1,
                -r1,
                a2,
                b2,
                -r2,
                SIN5_FREE,
                sp.Integer(0),
                rad_a,
                names[0] - rad_a,
                names[1] - rad_a,
                *bound,
            ),
            "theta6: entries (3,1), (3,2), h^T Rz(theta6) = m^T; free when h vanishes, then "
            "chosen so that the planar 3R can reach",
            1,
            refs[5],
        ),
    ]


def radius_range(elbow: Solve, target: tuple[sp.Symbol, sp.Symbol]) -> tuple[sp.Expr, sp.Expr]:
    """The range of x^2 + y^2 the planar 2R reaches, from its law-of-cosines step.

    The step solves ea c + eb s = x^2 + y^2 - ec, so x^2 + y^2 = ec +- sqrt(ea^2 + eb^2) at most.
    """
    ea, eb, rhs = elbow.args
    ec = -rhs.xreplace({target[0]: 0, target[1]: 0})
    spread = sp.sqrt(ea**2 + eb**2)
    return sp.Float(float(ec - spread)), sp.Float(float(ec + spread))
