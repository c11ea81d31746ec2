"""Pieper's solution for 6R arms whose last three axes meet in a point (lecture, Pieper -1..-7).

The derivation follows the lecture step by step, first in general symbolic form (a_i,
alpha_i, d_i as symbols), then with the arm's numbers substituted:

1. Base, X_0 and Tz(d_1) go into the base, Tz(d_6) and X_6 into the tool, so that the
   flange target 0_6T = (B X_0 Tz(d1))^-1 T (Tz(d6) X_6 E)^-1 has alpha_0 = a_0 = d_1 = d_6 = 0
   (docs/algorithms.md, "The flange target"). Its position is the wrist centre 0P_4org.
2. f(theta3) = 2_3T 3P_4org, g(theta2, theta3) = 1_2T f, (x, y, z) = 0_1T g.
3. r = x^2 + y^2 + z^2 = 2 a1 (k1 c2 + k2 s2) + k3 and z = s(alpha1) (k1 s2 - k2 c2) + k4;
   k1..k4 are read off these derived expressions (and checked against the lecture's
   definitions k1 = f1, k2 = -f2).
4. The case: a1 = 0 gives r = k3; s(alpha1) = 0 gives z = k4; otherwise the ellipse
   (r - k3)^2 / (4 a1^2) + (z - k4)^2 / s(alpha1)^2 = k1^2 + k2^2. With u = tan(theta3/2) this is
   a polynomial in u (quadratic, quadratic, quartic).
5. theta2 from the r and z equations (one root in the general case, two otherwise), theta1 from
   x and y, then the wrist W = (0_3R Rx(alpha3))^T 0_6R = Rz(theta4) Rx(alpha4) Rz(theta5)
   Rx(alpha5) Rz(theta6), solved for the arm's actual twists (Z-Y-Z is the special case).
"""

from __future__ import annotations

from dataclasses import replace
from functools import lru_cache

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure, is_zero
from derive.halfangle import half_angle_poly, linear_coeffs, reduce_pairs
from derive.methods.common import (
    NotApplicable,
    chain_length,
    flange_target,
    joint_outputs,
    joint_refs,
    reversed_refs,
    typical_magnitude,
    unit_column_cs1,
    unreverse_outputs,
)
from derive.plan import (
    Assign,
    Atan2,
    Cs1,
    Cs1Reach,
    Cs1Unit,
    Cs2,
    Cs2Reach,
    IkPlan,
    Poly,
    PolyD,
    Solve,
    Step,
)
from derive.transforms import (
    Chain,
    general_joint,
    general_pairs,
    general_twist,
    inverse,
    numbers_of,
    product,
    reverse_chain,
    rot_x,
    rot_z,
    trans,
    x_factor,
    z_factor,
)

NAME = "pieper"


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """Pieper plan for the chain, or a one-line reason why the method does not apply.

    Axes 4, 5, 6 meeting in a point are solved directly; axes 1, 2, 3 meeting in a point by
    solving the reversed chain for T^-1 (docs/algorithms.md, "Axes 1-2-3 meeting: the
    reversed chain").
    """
    if chain.dof != 6:
        return f"Pieper: needs 6 joints, the arm has {chain.dof}"
    refs = joint_refs(chain)
    if 4 in structure.concurrent:
        return derive_wrist_last(chain, sym.world_pose(), refs, "")
    if 1 in structure.concurrent:
        rev = reverse_chain(chain)
        plan = derive_wrist_last(
            rev,
            inverse(sym.world_pose()),
            reversed_refs(rev),
            "axes 1-3 meet: reversed chain (joint k is joint 7 - k, "
            "q'_k = -q_{7-k}), solved for T^-1; ",
        )
        if isinstance(plan, str):
            return plan
        return replace(plan, outputs=unreverse_outputs(plan.outputs))
    return "Pieper: neither axes 4, 5, 6 nor axes 1, 2, 3 meet in a point"


def derive_wrist_last(
    chain: Chain, target: sp.Matrix, refs: tuple[sp.Expr, ...], prefix: str
) -> IkPlan | str:
    """Pieper plan for a chain whose axes 4, 5, 6 meet in a point.

    Args:
        chain: the (possibly reversed) chain.
        target: the world target as an expression in w11..wz (T, or T^-1 when reversed).
        refs: per joint, the reference angle (or length) a free joint takes.
        prefix: text put before the case (how the chain was obtained).
    """
    kinds = "".join(j.kind for j in chain.joints)
    if kinds not in ("RRRRRR", "RRPRRR"):
        return "Pieper: prismatic joints are supported at position 3 of the position chain only"
    numbers = numbers_of(chain)
    length = chain_length(chain)
    try:
        position = position_equations(numbers, max(length, 1e-300), refs, kinds[2] == "P")
    except NotApplicable as exc:
        return str(exc)
    wrist = wrist_equations(numbers, refs)
    steps = [flange_target(chain, target), *reach_guided(position.steps, wrist), *wrist]
    outputs = joint_outputs(chain)
    return IkPlan(
        method=NAME,
        case=prefix + position.case,
        max_solutions=position.fanout * 2,
        steps=tuple(steps),
        outputs=outputs,
        details=tuple(sorted(position.details.items())),
    )


class PositionResult:
    """The position part: steps for theta3, theta2, theta1, the case, and report facts."""

    def __init__(self, steps: list[Step], case: str, fanout: int, details: dict) -> None:
        self.steps = steps
        self.case = case
        self.fanout = fanout
        self.details = details


def general_f_g() -> tuple[sp.Matrix, sp.Matrix]:
    """f = 2_3T 3P_4org and g = 1_2T f in general symbolic form (lecture, Pieper -2, -3)."""
    p4 = x_factor(general_twist(3)) * trans(0, 0, sym.d(4))
    f = (x_factor(general_twist(2)) * z_factor(general_joint(3)) * p4)[:, 3]
    g = x_factor(general_twist(1)) * z_factor(general_joint(2)) * f
    return f[:3, :].applyfunc(sp.expand), g[:3, :].applyfunc(sp.expand)


@lru_cache(maxsize=1)
def k_functions() -> dict[str, sp.Expr]:
    """k1..k4 read off the derived r and z (lecture, Pieper -3, -4), general form.

    Raises:
        AssertionError: the derived r or z does not have the lecture's form.
    """
    f, g = general_f_g()
    a1, sa1, c2, s2 = sym.link_a(1), sym.sin_alpha(1), sym.c(2), sym.s(2)
    r = reduce_pairs(g.dot(g), general_pairs(range(1, 4)))
    rc, rs, k3 = linear_coeffs(r, c2, s2)
    zc, zs, k4 = linear_coeffs(g[2], c2, s2)
    k1, k2 = sp.cancel(rc / (2 * a1)), sp.cancel(rs / (2 * a1))
    assert sp.expand(zs - sa1 * k1) == 0 and sp.expand(zc + sa1 * k2) == 0
    assert sp.expand(k1 - f[0]) == 0 and sp.expand(k2 + f[1]) == 0
    return {
        "f1": f[0],
        "f2": f[1],
        "f3": f[2],
        "g1": g[0],
        "g2": g[1],
        "g3": g[2],
        "k1": k1,
        "k2": k2,
        "k3": k3,
        "k4": k4,
    }


def _axis_distance_rest(
    a: sp.Expr, b: sp.Expr, e: sp.Expr, k3: sp.Expr, length: float, prismatic3: bool
) -> sp.Expr | None:
    """x^2 + y^2 where it is a^2 + b^2 - e^2 of theta2's a c2 + b s2 = e once joint 3 solves
    the a1 = 0 case's equation r = k3 (r = x^2 + y^2 + z^2), as on an arm whose wrist
    centre has no offset along axis 2 (its coefficients agree to 1e-12 of the arm's size
    squared), else None. Near the wrist centre on axis 1 the two values of theta2 meet (a
    fold), and acos(e / sqrt(a^2 + b^2)) rounds to 0 the half-width that the distance gives:
    6e-10 of the reach away, theta2 came back on the fold, theta1 free (q_ref's) and the rows
    6e-10 off the pose (a new user's attack on robosuite's Spot arm)."""
    x, y, z = (sym.named(n) for n in ("x", "y", "z"))
    gap = sp.expand(a**2 + b**2 - e**2 - (k3 - z**2))  # (x^2 + y^2 = r - z^2 = k3 - z^2)
    if not prismatic3:
        gap = sp.expand(reduce_pairs(gap, [(sym.s(3), sym.c(3))]))
    if gap.free_symbols:
        coeffs = sp.Poly(gap, *sorted(gap.free_symbols, key=str)).coeffs()
    else:
        coeffs = [gap]
    if all(abs(float(c)) <= 1e-12 * length**2 for c in coeffs):
        return x**2 + y**2
    return None


def position_equations(
    numbers: dict,
    length: float,
    refs: tuple[sp.Expr, ...],
    prismatic3: bool,
    typical: dict | None = None,
) -> PositionResult:
    """Joint 3 from the case's polynomial, then theta2, then theta1 (lecture, Pieper -4, -5).

    Args:
        numbers: the arm's numbers for the general symbols.
        length: the arm's size (sum of |a_i| and |d_i|), which scales the singularity tests.
        refs: reference values of the joints, for free joints.
        prismatic3: joint 3 is prismatic: the lecture's "theta_i or d_i"; f is affine in d3 and
            the case's equation is a polynomial in d3 (docs/algorithms.md, "A prismatic
            joint 3").
        typical: values of symbols among the numbers that the solver computes (a tool point
            that free joints move: derive/methods/position.py) at a typical configuration,
            for the polynomial's scale.
    """
    general = k_functions()
    spec = {name: sp.expand(e.xreplace(numbers)) for name, e in general.items()}
    a1, sa1 = numbers[sym.link_a(1)], numbers[sym.sin_alpha(1)]
    r, z, u = sym.named("r"), sym.named("z"), sym.named("u")
    c2, s2, c3, s3 = sym.c(2), sym.s(2), sym.c(3), sym.s(3)
    k1, k2, k3, k4 = (spec[k] for k in ("k1", "k2", "k3", "k4"))
    r_eq = 2 * a1 * (k1 * c2 + k2 * s2) + k3 - r
    z_eq = sa1 * (k1 * s2 - k2 * c2) + k4 - z
    var = "d3" if prismatic3 else "u = tan(theta3/2)"
    if is_zero(a1, 1e-12) and is_zero(sa1, 1e-12):
        raise AssertionError("axes 1 and 2 coincide; classification should have refused")
    if is_zero(a1, 1e-12):
        case, equation, theta2_eq = "a1 = 0: r = k3", k3 - r, z_eq
    elif is_zero(sa1, 1e-12):
        case, equation, theta2_eq = "sin(alpha1) = 0: z = k4", k4 - z, r_eq
    else:
        case = "general: (r - k3)^2/(4 a1^2) + (z - k4)^2/s(alpha1)^2 = k1^2 + k2^2"
        equation = (
            sa1**2 * (r - k3) ** 2
            + 4 * a1**2 * (z - k4) ** 2
            - 4 * a1**2 * sa1**2 * (k1**2 + k2**2)
        )
        theta2_eq = None
    if prismatic3:
        equation = sp.expand(equation)
        coeffs = tuple(sp.Poly(equation, sym.d(3)).all_coeffs())
        kind: type[Solve] = PolyD
    else:
        equation = reduce_pairs(equation, [(s3, c3)])
        coeffs = half_angle_poly(equation, c3, s3, u)
        kind = Poly
    degree = len(coeffs) - 1
    if degree < 1:
        raise NotApplicable(
            f"Pieper: the {case.split(':')[0]} case's equation does not involve "
            "joint 3, so the wrist centre cannot move in 3D (degenerate arm)"
        )
    case = f"{case}, degree {degree} in {var}"
    details = {
        **{f"general_{k}": v for k, v in general.items()},
        **dict(spec.items()),
        "joint3_equation": equation,
    }
    name = "d3" if prismatic3 else "theta3"
    steps: list[Step] = [
        Assign(
            (sym.named("x"), sym.named("y"), z, r),
            (
                sym.named("px"),
                sym.named("py"),
                sym.named("pz"),
                sym.named("px") ** 2 + sym.named("py") ** 2 + sym.named("pz") ** 2,
            ),
            "wrist centre (x, y, z) = 0P_4org and r = x^2 + y^2 + z^2",
        ),
        kind(
            3,
            coeffs,
            f"{name}: Pieper {case.split(':')[0]} case, polynomial "
            f"of degree {degree} in {var}; free when it vanishes identically",
            degree,
            refs[2],
            typical_magnitude(tuple(c.xreplace(typical or {}) for c in coeffs), length),
            # (d3 is as long as the wrist centre is far, and a look-at's point can be any
            # distance along its ray: a head's axes 3 mm apart lost every point 1 m away
            # when its quartic's leading coefficient, scaled by the arm's length alone,
            # fell below _LEAD_TOL of the largest: a new user's attack on a GR3 head)
            length + sp.sqrt(r) if prismatic3 else 1.0,
        ),
    ]
    if theta2_eq is None:
        ra, rb, rc = linear_coeffs(r_eq, c2, s2)
        za, zb, zc = linear_coeffs(z_eq, c2, s2)
        scale = abs(float(2 * a1 * sa1)) * length**2
        steps.append(
            Cs2(
                2,
                (ra, rb, -rc, za, zb, -zc, sp.Float(scale), sp.Integer(0)),
                "theta2: r and z equations, linear in (c2, s2)",
                1,
                refs[1],
            )
        )
        fan2 = 1
    else:
        ta, tb, tc = linear_coeffs(theta2_eq, c2, s2)
        size = length if is_zero(a1, 1e-12) else 2 * abs(float(a1)) * length
        note = (
            "theta2: a c2 + b s2 = c by the half-angle method; free when the equation "
            "vanishes identically"
        )
        rest = None
        if is_zero(a1, 1e-12):  # (the identity reads the a1 = 0 case's joint 3 equation)
            rest = _axis_distance_rest(ta, tb, -tc, k3, length, prismatic3)
        if rest is not None:
            note += (
                ", its half-width atan2(sqrt(x^2 + y^2), c): a^2 + b^2 - c^2 is the wrist "
                "centre's squared distance from axis 1"
            )
            steps.append(Cs1Unit(2, (ta, tb, -tc, rest), note, 2, refs[1], size**2))
        else:
            steps.append(Cs1(2, (ta, tb, -tc), note, 2, refs[1], size**2))
        fan2 = 2
    g1, g2 = spec["g1"], spec["g2"]
    steps.append(
        Assign(
            (sym.named("g1"), sym.named("g2")), (g1, g2), "g1(theta2, theta3), g2(theta2, theta3)"
        )
    )
    gs1, gs2 = sym.named("g1"), sym.named("g2")
    steps.append(
        Cs2(
            1,
            (
                gs1,
                -gs2,
                sym.named("x"),
                gs2,
                gs1,
                sym.named("y"),
                sp.Float(length**2),
                sp.Float(length**2),
            ),
            "theta1: x = c1 g1 - s1 g2, y = s1 g1 + c1 g2; free with the wrist centre on axis 1",
            1,
            refs[0],
        )
    )
    return PositionResult(steps, case, degree * fan2, details)


def reach_guided(position: list[Step], wrist: list[Step]) -> list[Step]:
    """The position steps, theta1 chosen so the wrist can reach W33 when theta1 is free.

    A wrist whose twists are not both +-90 deg reaches W33 only in [e5 - rho5, e5 + rho5]
    (W33 = a5 c5 + b5 s5 + e5). With the wrist centre on axis 1, theta1 is free; a value at
    which W33, linear in (c1, s1), lies outside that range would leave no wrist solution,
    so theta1 then keeps W33 inside it (the ``cs2r`` kind). With the wrist centre also on
    axis 2, theta2 is free too and is chosen so that some theta1 can (``cs1r``; W33 is
    bilinear in (c1, s1) and (c2, s2)). Orthogonal wrists reach every W33 and keep the plain
    kinds.
    """
    w_assign, theta5 = wrist[0], wrist[1]
    assert isinstance(w_assign, Assign) and isinstance(theta5, Solve)
    a5, b5, e5 = theta5.args[:3]  # (a Cs1Unit's fourth, rest, is not read here)
    e5 = -(e5 - sym.named("W33"))
    rho = sp.sqrt(a5**2 + b5**2)
    lo, hi = float(e5 - rho), float(e5 + rho)
    if lo <= -1.0 + 1e-12 and hi >= 1.0 - 1e-12:
        return position
    w33 = sp.expand(w_assign.exprs[8])
    wa, wb, we = linear_coeffs(w33, sym.c(1), sym.s(1))
    grid = [linear_coeffs(w, sym.c(2), sym.s(2)) for w in (we, wa, wb)]
    m = tuple(e for c, s, rest in grid for e in (rest, c, s))
    bounds = (sp.Float(lo), sp.Float(hi))
    out = []
    for step in position:
        if isinstance(step, Solve) and step.joint == 1 and step.kind == "cs2":
            step = step.as_kind(
                Cs2Reach,
                args=(*step.args, we, wa, wb, *bounds),
                note=step.note + "; then chosen so that the wrist reaches W33",
            )
        elif isinstance(step, Solve) and step.joint == 2 and step.kind == "cs1":
            step = step.as_kind(  # (a Cs1Unit's rest is dropped: Cs1Reach solves by acos)
                Cs1Reach,
                args=(*step.args[:3], *m, *bounds),
                note=step.note + "; then chosen so that a theta1 lets the wrist reach W33",
            )
        out.append(step)
    return out


def wrist_equations(numbers: dict, refs: tuple[sp.Expr, ...]) -> list[Step]:
    """theta5, theta4, theta6 from W = Rz(t4) Rx(alpha4) Rz(t5) Rx(alpha5) Rz(t6)
    (docs/algorithms.md, "The wrist as Z-Y-Z Euler angles")."""
    rot03 = product(
        [
            (z_factor(general_joint(i)) * x_factor(general_twist(i))).xreplace(numbers)
            for i in (1, 2, 3)
        ],
        expand=False,
    )[:3, :3]
    flange = sym.flange_pose()[:3, :3]
    w_names = sp.Matrix(3, 3, lambda i, j: sym.named(f"W{i + 1}{j + 1}"))
    w_value = rot03.T * flange
    c4, s4, c5, s5 = sym.c(4), sym.s(4), sym.c(5), sym.s(5)
    inner = (
        rot_x(sym.cos_alpha(4), sym.sin_alpha(4))
        * rot_z(c5, s5)
        * rot_x(sym.cos_alpha(5), sym.sin_alpha(5))
    )[:3, :3].xreplace(numbers)
    v = inner[:, 2].applyfunc(sp.expand)
    a5, b5, e5 = linear_coeffs(v[2], c5, s5)
    m = (inner.T * rot_z(c4, s4)[:3, :3].T * w_names).applyfunc(sp.expand)
    v1, v2 = sym.named("v1"), sym.named("v2")
    w13, w23, w33 = sym.named("W13"), sym.named("W23"), sym.named("W33")
    note = "theta5: W33 = e3^T Rx(alpha4) Rz(theta5) Rx(alpha5) e3"
    # (twists of +-90 deg: W33 = a5 c5 + b5 s5 on a unit circle, of the unit column (W13, W23,
    # W33): the lecture's atan2(+-sqrt(W13^2 + W23^2), W33))
    theta5 = (
        unit_column_cs1(
            5,
            a5,
            b5,
            w33,
            (w13, w23),
            note,
            "atan2(sqrt(W13^2 + W23^2), W33) (the Z-Y-Z Euler angle's)",
        )
        if e5 == 0
        else Cs1(5, (a5, b5, w33 - e5), note, 2)
    )
    return [
        Assign(
            tuple(w_names),
            tuple(w_value),
            "wrist W = (0_3R Rx(alpha3))^T 0_6R = Rz(t4) Rx(alpha4) Rz(t5) Rx(alpha5) Rz(t6)",
        ),
        theta5,
        Assign((v1, v2), (v[0], v[1]), "v = Rx(alpha4) Rz(theta5) Rx(alpha5) e3"),
        Cs2(
            4,
            (v1, -v2, sym.named("W13"), v2, v1, sym.named("W23"), sp.Integer(1), sp.Integer(1)),
            "theta4: (W13, W23) = Rz(theta4) (v1, v2); free at a singular wrist",
            1,
            refs[3],
        ),
        Atan2(
            6,
            (m[1, 0], m[0, 0]),
            "theta6: Rz(theta6) = (Rx(alpha4) Rz(theta5) Rx(alpha5))^T Rz(theta4)^T W",
            1,
            refs[5],
        ),
    ]
