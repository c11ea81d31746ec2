"""6R arms with three consecutive parallel axes (UR type; the blog post's arm): docs/algorithms.md,
"Three parallel axes".

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

Axes 3, 4, 5 parallel are solved on the reversed chain, where they are axes 2, 3, 4. Axes
1, 2, 3 parallel (or 4, 5, 6, on the reversed chain) have their own steps: derive_123.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure
from derive.halfangle import half_angle_poly, linear_coeffs, reduce_pairs
from derive.methods.common import (
    NotApplicable,
    angle_poly,
    chain_length,
    flange_target,
    joint_outputs,
    joint_refs,
    reversed_refs,
    typical_magnitude,
    unit_column_cs1,
    unreverse_outputs,
)
from derive.methods.planar import flange_factors, heading_step, planar_steps
from derive.plan import Assign, Cs1, Cs2, Cs2Reach, IkPlan, PolyD, Solve, Step
from derive.transforms import Chain, inverse, numbers_of, product, reverse_chain

NAME = "three-parallel"
# theta6 is free where |h| = |s5| is below 1e-10 on an exact table (h^2 below _FREE_TOL_EXACT
# = 1e-20; theta5 from entry (3,3) with its half-width atan2(sqrt(lhs_31^2 + lhs_32^2), ...),
# exact to roundings, where the entries say so: Cs1Unit), 1e-7 on a nominal one (_FREE_TOL)
SIN5_FREE = sp.Integer(1)


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """Plan for axes 2-3-4 (or 3-4-5) parallel, or why the method does not apply."""
    if chain.dof != 6:
        return f"three-parallel: needs 6 joints, the arm has {chain.dof}"
    triples = structure.parallel_triples
    kinds = "".join(j.kind for j in chain.joints)
    if any(i + 1 in triples for i in triples) and not sliding_fourth(triples, kinds):
        return (
            "three-parallel: four consecutive parallel axes (a degree of freedom is lost unless "
            "the fourth from an end slides, joint 4 of axes 1-4 or joint 3 of axes 3-6)"
        )
    refs = joint_refs(chain)
    reasons = []
    for first in (1, 4):
        if first not in triples:
            continue
        try:
            return derive_end(chain, refs, first)
        except NotApplicable as exc:
            reasons.append(str(exc))
    if not {2, 3} & set(triples):
        return "; ".join(reasons) or "three-parallel: no three consecutive axes are parallel"
    if any(j.kind != "R" for j in chain.joints):
        return "three-parallel: axes 2-4 or 3-5 parallel need six revolute joints"
    try:
        if 2 in triples:
            return derive_234(chain, sym.world_pose(), refs, "")
        if 3 in triples:
            return on_reversed(chain, derive_234, "3-5")
    except NotApplicable as exc:
        return str(exc)
    return "three-parallel: axes 2, 3, 4 (or 3, 4, 5) are not parallel"


def sliding_fourth(triples: tuple[int, ...], kinds: str) -> bool:
    """Axes 1-4 parallel with joint 4 sliding (or 3-6 with joint 3, the same on the reversed
    chain): the three turning axes move in their plane, the slider at right angles to it, and
    derive_123's case "joint 4 slides" solves them (theta5 from entry (3,3), d4 from (3,4))."""
    return ({1, 2} <= set(triples) and kinds == "RRRPRR") or (
        {3, 4} <= set(triples) and kinds == "RRPRRR"
    )


def derive_end(chain: Chain, refs: tuple[sp.Expr, ...], first: int) -> IkPlan:
    """The plan for axes 1, 2, 3 parallel (first = 1), or axes 4, 5, 6 (first = 4: the
    reversed chain, where they are axes 1, 2, 3)."""
    if first == 1:
        return derive_123(chain, sym.world_pose(), refs, "")
    return on_reversed(chain, derive_123, "4-6")


def on_reversed(chain: Chain, derive_part: Callable[..., IkPlan], axes: str) -> IkPlan:
    """derive_part's plan for the reversed chain (solved for T^-1), as the arm's joints."""
    rev = reverse_chain(chain)
    plan = derive_part(
        rev,
        inverse(sym.world_pose()),
        reversed_refs(rev),
        f"axes {axes} parallel: reversed chain (joint k is joint 7 - k, q'_k = -q_{{7-k}}), "
        "solved for T^-1; ",
    )
    return replace(plan, outputs=unreverse_outputs(plan.outputs))


def derive_123(chain: Chain, target: sp.Matrix, refs: tuple[sp.Expr, ...], prefix: str) -> IkPlan:
    """The plan for axes 1, 2, 3 parallel (all joints revolute, or joint 4 sliding).

    P = Z1 X1 Z2 X2 Z3 is planar, so the third row of the flange target 0_6T equals that of
    P X3 Z4 X4 Z5 X5 Z6, (0, 0, +-1, d) X3 Z4 X4 Z5 X5 Z6, whose entries (3,3) and (3,4) hold
    joints 4 and 5 only (Z6 turns about z and moves along it): two equations for them (a
    polynomial in tan(theta4/2) where both turn, a cos + b sin = c and a linear equation where
    one slides); theta6 from entries (3,1), (3,2); then the planar 3R (theta1, theta2 by the
    law of cosines, theta3 from the heading) from G = 0_6T (X3 Z4 X4 Z5 X5 Z6)^-1 = P.
    """
    kinds = "".join(j.kind for j in chain.joints)
    if kinds not in ("RRRRRR", "RRRPRR"):
        # (a sliding joint 5 moves within the parallel axes' plane wherever theta4 turns it
        # at right angles to them, and d5 is then free along a curve of solutions that the
        # planar three must still reach: not solved here)
        raise NotApplicable(
            "three-parallel: axes 1-3 (or 4-6) parallel need revolute joints, or one "
            "prismatic joint next to the parallel three (joint 4, or 3 of axes 4-6 "
            f"parallel); the arm's joints, from the parallel end: {kinds}"
        )
    numbers = numbers_of(chain)
    mats = [m.xreplace(numbers) for m in flange_factors(chain)]
    planar_part = product(mats[0:5])  # Z1 X1 Z2 X2 Z3
    rest = product(mats[5:])  # X3 Z4 X4 Z5 X5 Z6
    row = planar_part[2, :]
    if row.has(*(f(i) for i in (1, 2, 3) for f in (sym.c, sym.s))):
        raise NotApplicable(
            "three-parallel: the third row of Z1 X1 Z2 X2 Z3 depends on the parallel joints"
        )
    lhs = sym.flange_pose()[2, :]
    rhs = (row * rest).applyfunc(sp.expand)
    equations = [sp.expand(lhs[k] - rhs[k]) for k in range(4)]
    length = chain_length(chain)
    g = sp.Matrix(3, 4, lambda i, j: sym.named(f"G{i + 1}{j + 1}"))
    g_value = (sym.flange_pose() * inverse(rest))[:3, :].applyfunc(sp.expand)
    position = planar_part[:2, 3].applyfunc(sp.expand)
    planar = planar_steps(position[0], position[1], 1, 2, g[0, 3], g[1, 3], refs, length)
    steps: list[Step] = [flange_target(chain, target)]
    middle, case = joints45_steps(equations[2], equations[3], kinds, refs, length)
    steps += middle
    note = "G = 0_6T (X3 Z4 X4 Z5 X5 Z6)^-1 = Z1 X1 Z2 X2 Z3 (planar)"
    steps += planar_tail(equations, g, g_value, planar, refs, note)
    steps.append(heading_step(product(mats[0:4])[:3, :3], sp.eye(3), 3, refs, g[:, :3]))
    fanout = 2
    for step in middle:
        if isinstance(step, Solve):
            fanout *= step.fanout
    return IkPlan(
        NAME, prefix + "axes 1-3 parallel: " + case, fanout, tuple(steps), joint_outputs(chain)
    )


def joints45_steps(
    z_eq: sp.Expr, pos_eq: sp.Expr, kinds: str, refs: tuple[sp.Expr, ...], length: float
) -> tuple[list[Step], str]:
    """Joints 4 and 5 from entries (3,3) (z_eq) and (3,4) (pos_eq) of the invariant row, and
    the case in words."""
    c4, s4, c5, s5, u = sym.c(4), sym.s(4), sym.c(5), sym.s(5), sym.named("u")
    if "P" in kinds:
        a, b, c = linear_coeffs(z_eq, c5, s5)
        if a == 0 and b == 0:
            raise NotApplicable("three-parallel: entry (3,3) does not involve theta5")
        coeffs = tuple(sp.Poly(pos_eq, sym.d(4)).all_coeffs())
        if len(coeffs) != 2:
            raise NotApplicable("three-parallel: entry (3,4) is not linear in d4")
        steps: list[Step] = [
            Cs1(5, (a, b, -c), "theta5: entry (3,3), a c + b s = c", 2, refs[4], 1.0),
            PolyD(4, coeffs, "d4: entry (3,4), linear in d4", 1, unit=length),
        ]
        return steps, "theta5 from entry (3,3), d4 from entry (3,4)"
    entries = ((z_eq, "(3,3)"), (pos_eq, "(3,4)"))
    for k, (eq, name) in enumerate(entries):
        for one, other in ((4, 5), (5, 4)):
            if eq.has(sym.c(other), sym.s(other)) or not eq.has(sym.c(one), sym.s(one)):
                continue
            # this entry holds one joint only: it first, the other from the other entry
            rest, rest_name = entries[1 - k]
            if not rest.has(sym.c(other), sym.s(other)):
                raise NotApplicable(f"three-parallel: neither entry involves theta{other}")
            a, b, c = linear_coeffs(eq, sym.c(one), sym.s(one))
            pa, pb, pc = linear_coeffs(rest, sym.c(other), sym.s(other))
            # (free where an equation vanishes: a curve of solutions; rotation entries are
            # of size 1, translation entries of the arm's length)
            scales = (1.0, length**2) if k == 0 else (length**2, 1.0)
            steps = [
                Cs1(
                    one,
                    (a, b, -c),
                    f"theta{one}: entry {name}, a c + b s = c",
                    2,
                    refs[one - 1],
                    scales[0],
                ),
                Cs1(
                    other,
                    (pa, pb, -pc),
                    f"theta{other}: entry {rest_name}, a c + b s = c",
                    2,
                    refs[other - 1],
                    scales[1],
                ),
            ]
            return steps, f"theta{one} from entry {name}, theta{other} from entry {rest_name}"
    pa, pb, pc = linear_coeffs(pos_eq, c5, s5)
    za, zb, zc = linear_coeffs(z_eq, c5, s5)
    det = sp.expand(pa * zb - za * pb)
    if det == 0:
        raise NotApplicable("three-parallel: entries (3,3) and (3,4) are dependent in theta5")
    cos5 = -(pc * zb - pb * zc)
    sin5 = -(pa * zc - za * pc)
    equation = reduce_pairs(sp.expand(cos5**2 + sin5**2 - det**2), [(s4, c4)])
    if equation == 0:
        raise NotApplicable("three-parallel: entries (3,3) and (3,4) are dependent")
    coeffs = half_angle_poly(equation, c4, s4, u)
    steps = [
        angle_poly(
            4,
            coeffs,
            "theta4: (c5, s5) eliminated from entries (3,3), (3,4): "
            f"polynomial of degree {len(coeffs) - 1} in u = tan(theta4/2)",
            refs[3],
            typical_magnitude(coeffs, length),
        ),
        # (free where both entries vanish: theta4 puts axis 5 parallel to axes 1-3, a
        # curve of solutions; the determinant is of the size of a length, the right side's
        # square of a length's square)
        Cs2(
            5,
            (pa, pb, -pc, za, zb, -zc, sp.Float(length), sp.Float(length**2)),
            "theta5: entries (3,3) and (3,4), linear in (c5, s5)",
            1,
            refs[4],
        ),
    ]
    return steps, f"theta4 from a polynomial of degree {len(coeffs) - 1}, theta5 from both entries"


def derive_234(chain: Chain, target: sp.Matrix, refs: tuple[sp.Expr, ...], prefix: str) -> IkPlan:
    """The plan for axes 2, 3, 4 parallel (docs/algorithms.md, "Axes 2-3-4: the third row")."""
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
    length = chain_length(chain, prismatic=True)
    g = sp.Matrix(3, 4, lambda i, j: sym.named(f"G{i + 1}{j + 1}"))
    g_value = (inverse(base_part) * sym.flange_pose() * inverse(wrist_part))[:3, :]
    g_value = g_value.applyfunc(sp.expand)
    position = planar_part[:2, 3].applyfunc(sp.expand)
    planar = planar_steps(position[0], position[1], 2, 3, g[0, 3], g[1, 3], refs, length)
    steps: list[Step] = [flange_target(chain, target)]
    steps += theta1_theta5_steps(equations[3], equations[2], refs, length, lhs)
    note = "G = (Z1 X1)^-1 0_6T (X4 Z5 X5 Z6)^-1 = Z2 X2 Z3 X3 Z4 (planar)"
    steps += planar_tail(equations, g, g_value, planar, refs, note)
    before = product(mats[2:6])[:3, :3]
    steps.append(heading_step(before, sp.eye(3), 4, refs, g[:, :3]))
    outputs = joint_outputs(chain)
    case = prefix + (
        "a5 = 0: theta1 from one a cos + b sin = c equation"
        if not equations[3].has(sym.c(5), sym.s(5))
        else "a5 != 0: quartic in tan(theta1/2)"
    )
    return IkPlan(NAME, case, 8, tuple(steps), outputs)


def planar_tail(
    equations: list[sp.Expr],
    g: sp.Matrix,
    g_value: sp.Matrix,
    planar: list[Step],
    refs: tuple[sp.Expr, ...],
    note: str,
) -> list[Step]:
    """theta6 from entries (3,1), (3,2) of the invariant row, G (the planar part's target),
    then the planar steps."""
    elbow = planar[0]
    assert isinstance(elbow, Solve)
    steps = theta6_steps(equations[0], equations[1], g_value, elbow, refs)
    return [*steps, Assign(tuple(g), tuple(g_value), note), *planar]


def theta1_theta5_steps(
    pos_eq: sp.Expr,
    z6_eq: sp.Expr,
    refs: tuple[sp.Expr, ...],
    length: float,
    lhs: sp.Matrix | None = None,
) -> list[Step]:
    """theta1 and theta5 from entries (3,4) and (3,3) of the invariant equation (lhs: its
    target side, whose entries (3,1), (3,2), (3,3) are a unit vector)."""
    c1, s1, c5, s5, u = sym.c(1), sym.s(1), sym.c(5), sym.s(5), sym.named("u")
    if not pos_eq.has(c5, s5):
        a, b, c = linear_coeffs(pos_eq, c1, s1)
        if a == 0 and b == 0:
            raise NotApplicable("three-parallel: the translation entry does not involve theta1")
        a5, b5, c5_ = linear_coeffs(z6_eq, c5, s5)
        if a5 == 0 and b5 == 0:
            raise NotApplicable("three-parallel: entry (3,3) does not involve theta5")
        note = "theta5: entry (3,3) of the invariant equation"
        # (where (3,3) has no constant, its target side's (3,1), (3,2), (3,3) a unit vector:
        # the half-width from (3,1), (3,2), as a spherical wrist's from W13, W23)
        theta5 = (
            unit_column_cs1(5, a5, b5, -c5_, (lhs[0], lhs[1]), note)
            if lhs is not None and sp.expand(c5_ - lhs[2]) == 0
            else Cs1(5, (a5, b5, -c5_), note, 2)
        )
        return [
            Cs1(
                1,
                (a, b, -c),
                "theta1: translation entry (3,4) of the invariant equation, a c1 + b s1 = c",
                2,
                refs[0],
                length**2,
            ),
            theta5,
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
        angle_poly(
            1,
            coeffs,
            f"theta1: (c5, s5) eliminated from entries (3,3), (3,4): "
            f"polynomial of degree {len(coeffs) - 1} in u = tan(theta1/2)",
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
    """theta6 from entries (3,1), (3,2): h^T Rz(theta6) = m^T (docs/algorithms.md, "Axes
    2-3-4: the third row", step 3).

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
