"""Planar arms (all axes parallel) and the planar 2R/3R sub-problem other methods reuse.

The lecture's RRR example, read off derived expressions instead of typed formulas:

* geometric reading: x^2 + y^2 depends on the elbow angle only (law of cosines,
  c2 = (x^2 + y^2 - l1^2 - l2^2) / (2 l1 l2)), which gives the elbow-up / elbow-down pair;
* algebraic reading: with the elbow known, (x, y) is linear in (c1, s1):
  x = k1 c1 - k2 s1, y = k1 s1 + k2 c1, so theta1 = atan2(y, x) - atan2(k2, k1);
* the last revolute joint from the heading: Rz(theta3) = (Rz(theta1) Rz(theta2))^T R.

Prismatic joints of a planar arm move along the common axis direction, so they only change
z: each such arm has at most one, solved from the z equation, which is linear in it.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure
from derive.halfangle import linear_coeffs, reduce_pairs
from derive.methods.common import (
    NotApplicable,
    chain_length,
    flange_target,
    joint_outputs,
    joint_refs,
)
from derive.plan import Assign, Atan2, Cs1, Cs2, IkPlan, PolyD, Solve, Step
from derive.transforms import Chain, inverse, numbers_of, product, x_factor, z_factor

NAME = "planar"


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """Plan for an arm whose axes are all parallel, or why the method does not apply."""
    n = chain.dof
    if n < 2 or len(structure.parallel) != n - 1:
        return "planar: not all axes are parallel"
    revolute = [j.index for j in chain.joints if j.kind == "R"]
    prismatic = [j.index for j in chain.joints if j.kind == "P"]
    if len(revolute) not in (2, 3) or len(prismatic) > 1:
        return (
            f"planar: needs 2 or 3 revolute joints and at most one prismatic joint, "
            f"the arm has {len(revolute)} and {len(prismatic)}"
        )
    refs = joint_refs(chain)
    try:
        if len(revolute) == 2:
            return position_mode(chain, revolute, prismatic, refs)
        return pose_mode(chain, revolute, prismatic, refs)
    except NotApplicable as exc:
        return str(exc)


def flange_factors(chain: Chain) -> list[sp.Matrix]:
    """Z_1 X_1 ... X_{n-1} Z_n of the flange target of :func:`flange_target`.

    Tz(d_1) and Tz(d_n) of revolute end joints are part of the base and tool there, so they
    are left out here.
    """
    mats = []
    for j, t in zip(chain.joints, chain.twists[1:]):
        z = z_factor(j)
        if j.kind == "R" and j.index in (1, chain.dof):
            z = z_factor(replace(j, d=sp.Integer(0)))
        mats += [z, x_factor(t)]
    return mats[:-1]


def position_mode(
    chain: Chain, revolute: list[int], prismatic: list[int], refs: tuple[sp.Expr, ...]
) -> IkPlan:
    """Two revolute joints: the arm controls the tool point's position (x, y and maybe z)."""
    numbers = numbers_of(chain)
    mats = [z_factor(j) * x_factor(t) for j, t in zip(chain.joints, chain.twists[1:])]
    to_tool = product([*mats, chain.tool], expand=False)[:3, 3]
    head = product([chain.base, x_factor(chain.twists[0])])
    local = (inverse(head) * sym.world_pose()[:, 3]).applyfunc(sp.expand)
    target = tuple(sym.named(f"p{axis}") for axis in "xyz")
    steps: list[Step] = [
        Assign(
            target,
            tuple(local[:3]),
            "tool point in frame 0: (B X0)^-1 p; the arm controls a position",
        )
    ]
    position = to_tool.applyfunc(lambda e: sp.expand(e.xreplace(numbers)))
    steps += prismatic_steps(position[2], prismatic, target[2])
    steps += planar_steps(
        position[0],
        position[1],
        revolute[0],
        revolute[1],
        target[0],
        target[1],
        refs,
        chain_length(chain),
    )
    solves_for = "the tool point's x and y" + (" and z" if prismatic else "") + " in frame 0"
    return IkPlan(
        NAME,
        f"{arm_kind(chain)}: position of the tool point (law of cosines, then k1, k2)",
        2,
        tuple(steps),
        joint_outputs(chain),
        solves_for=solves_for,
        certify="position",
    )


def pose_mode(
    chain: Chain, revolute: list[int], prismatic: list[int], refs: tuple[sp.Expr, ...]
) -> IkPlan:
    """Three revolute joints: position in the plane and the heading (the lecture's x, y, phi)."""
    numbers = numbers_of(chain)
    last = revolute[2]
    mats = flange_factors(chain)
    flange = product(mats).applyfunc(lambda e: sp.expand(e.xreplace(numbers)))
    position = flange[:3, 3]
    if position[0].has(sym.c(last), sym.s(last)) or position[1].has(sym.c(last), sym.s(last)):
        raise NotApplicable("planar: the last revolute joint moves the flange in the plane")
    steps: list[Step] = [flange_target(chain, sym.world_pose())]
    steps += prismatic_steps(position[2], prismatic, sym.named("pz"))
    steps += planar_steps(
        position[0],
        position[1],
        revolute[0],
        revolute[1],
        sym.named("px"),
        sym.named("py"),
        refs,
        chain_length(chain),
    )
    at = 2 * (last - 1)
    before = product(mats[:at])[:3, :3].xreplace(numbers)
    after = product(mats[at + 1 :])[:3, :3].xreplace(numbers)
    steps.append(heading_step(before, after, last, refs))
    return IkPlan(
        NAME,
        f"{arm_kind(chain)}: position by the law of cosines and k1, k2, then the heading",
        2,
        tuple(steps),
        joint_outputs(chain),
        solves_for="x, y and the heading about z of the flange (z and the tilt must "
        "match the arm's plane)",
    )


def arm_kind(chain: Chain) -> str:
    """E.g. "planar RRR" or "planar RRPR (SCARA type)"."""
    kinds = "".join(j.kind for j in chain.joints)
    return f"planar {kinds}" + (" (SCARA type)" if "P" in kinds and len(kinds) == 4 else "")


def prismatic_steps(z_expr: sp.Expr, prismatic: list[int], z_target: sp.Symbol) -> list[Step]:
    """d_k from the z equation, linear in it (no step when the arm has no prismatic joint)."""
    if not prismatic:
        return []
    k = prismatic[0]
    coeffs = tuple(sp.Poly(sp.expand(z_expr - z_target), sym.d(k)).all_coeffs())
    if len(coeffs) != 2:
        raise NotApplicable(f"planar: z does not depend linearly on d{k}")
    return [PolyD(k, coeffs, f"d{k}: the z equation, linear in d{k}", 1)]


def planar_steps(
    x_expr: sp.Expr,
    y_expr: sp.Expr,
    a: int,
    b: int,
    x: sp.Symbol,
    y: sp.Symbol,
    refs: tuple[sp.Expr, ...],
    length: float,
) -> list[Step]:
    """theta_b from x^2 + y^2 (law of cosines), then theta_a from x and y (k1, k2).

    Args:
        x_expr, y_expr: the derived planar position, in c_a, s_a, c_b, s_b.
        a, b: the shoulder and elbow joints.
        x, y: the target's symbols.
        refs: reference values of free joints.
        length: the arm's size; theta_a is free when the target is within 1e-9 of it from
            the first axis.
    """
    scale = sp.Float(max(length, 1e-300) ** 2)
    ca, sa, cb, sb = sym.c(a), sym.s(a), sym.c(b), sym.s(b)
    radius = reduce_pairs(x_expr**2 + y_expr**2, [(sa, ca), (sb, cb)])
    if radius.has(ca, sa):
        raise NotApplicable(f"planar: x^2 + y^2 depends on theta{a}")
    ea, eb, ec = linear_coeffs(radius, cb, sb)
    if ea == 0 and eb == 0:
        raise NotApplicable(f"planar: x^2 + y^2 does not depend on theta{b}")
    xa, xb, xc = linear_coeffs(x_expr, ca, sa)
    ya, yb, yc = linear_coeffs(y_expr, ca, sa)
    k1, k2 = sym.named("k1"), sym.named("k2")
    return [
        Cs1(
            b,
            (ea, eb, x**2 + y**2 - ec),
            f"theta{b}: law of cosines, x^2 + y^2 = {sp.sstr(radius)} (elbow up / down)",
            2,
        ),
        Assign((k1, k2), (xa, -xb), f"k1, k2 with x = k1 c{a} - k2 s{a} (+ const)"),
        Cs2(
            a,
            (k1, -k2, x - xc, ya, yb, y - yc, scale, scale),
            f"theta{a}: x = k1 c{a} - k2 s{a}, y = k1 s{a} + k2 c{a}, i.e. "
            f"atan2(y, x) - atan2(k2, k1)",
            1,
            refs[a - 1],
        ),
    ]


def heading_step(
    before: sp.Matrix,
    after: sp.Matrix,
    joint: int,
    refs: tuple[sp.Expr, ...],
    target: sp.Matrix | None = None,
) -> Solve:
    """theta_joint from the rotation R = A Rz(theta) B: Rz(theta) = A^T R B^T.

    Args:
        before: A, the rotation of the chain before the joint (known by now).
        after: B, the constant rotation after it.
        joint: the joint.
        refs: reference values of free joints.
        target: R as symbols (default: the flange target's rotation r11..r33).
    """
    rotation = sym.flange_pose()[:3, :3] if target is None else target
    m = (before.T * rotation * after.T).applyfunc(sp.expand)
    return Atan2(
        joint,
        (m[1, 0], m[0, 0]),
        f"theta{joint}: heading, Rz(theta{joint}) = A^T R B^T",
        1,
        refs[joint - 1],
    )
