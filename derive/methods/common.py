"""Steps shared by the solution methods."""

from __future__ import annotations

import sympy as sp

from derive import symbols as sym
from derive.plan import Assign, Cs1, Cs1Unit, Poly, PolyPi, Solve
from derive.transforms import Chain, inverse, product, trans, x_factor


def chain_length(chain: Chain, prismatic: bool = False, last: bool = True) -> float:
    """The scale of a method's singularity tests: the sum of the twists' |a| (the last one's
    only where last) and of the joints' constant offsets |d| (a sliding joint's too where
    prismatic), the offsets of joints whose axes are parallel summed first, with their signs
    (an axis that points back runs its offset the other way). A nominal table keeps the far
    common normal of the exact arm's nearly parallel axes, whose offsets are large and cancel:
    a calibrated UR5 URDF's d2, d3, d4 are 10.56, -3.37 and -7.07 m for a 0.11 m offset, which
    made the length 21.9 m, not 1.1, and the band in which theta1's fold spreads its seeds 0.21
    m wide: 328 seeds and 1.5 ms at poses whose wrist centre is near axis 1
    (derive/nominal.py's link_size does the same for nearly parallel axes)."""
    twists = chain.twists if last else chain.twists[:-1]
    size = sum(abs(float(t.a)) for t in twists)
    group, sign = 0.0, 1.0
    for k, joint in enumerate(chain.joints):
        if joint.kind == "R" or prismatic:
            group += sign * float(joint.d)
        twist = chain.twists[k + 1]  # (X_{k+1}: from this joint's axis to the next one's)
        if k + 1 < len(chain.joints) and twist.sa == 0:
            sign = -sign if twist.ca < 0 else sign
            continue  # (the next joint's offset joins this group)
        size += abs(group)
        group, sign = 0.0, 1.0
    return size


class NotApplicable(Exception):
    """The method does not apply to this arm; the message says why, in one line."""


def flange_target(chain: Chain, target: sp.Matrix) -> Assign:
    """0_nT from the world target: base, X_0, Tz(d1) and Tz(dn), X_n, tool moved out.

    Tz(d1) and Tz(dn) move out only for revolute end joints (they commute with Rz(theta)),
    so that the flange target has alpha_0 = a_0 = d_1 = d_n = 0 (docs/algorithms.md, "The
    flange target").
    """
    first, last = chain.joints[0], chain.joints[-1]
    head = [chain.base, x_factor(chain.twists[0])]
    tail = [x_factor(chain.twists[-1]), chain.tool]
    if first.kind == "R":
        head.append(trans(0, 0, first.d))
    if last.kind == "R":
        tail.insert(0, trans(0, 0, last.d))
    flange = product([inverse(product(head)), target, inverse(product(tail))])
    names = sym.flange_pose()
    pairs = [(names[i, j], flange[i, j]) for i in range(3) for j in range(4)]
    return Assign(
        tuple(p[0] for p in pairs),
        tuple(p[1] for p in pairs),
        "flange target 0_nT = (B X0 Tz(d1))^-1 T (Tz(dn) Xn E)^-1",
    )


def joint_outputs(chain: Chain) -> tuple[sp.Expr, ...]:
    """q_i = theta_i - offset (R) or d_i - offset (P), offsets as floats."""
    return tuple(
        (sym.theta(j.index) if j.kind == "R" else sym.d(j.index)) - _number(j.offset)
        for j in chain.joints
    )


def joint_refs(chain: Chain) -> tuple[sp.Expr, ...]:
    """theta_i (or d_i) of the reference joint values qr_i: what a free joint takes."""
    return tuple(sym.q_ref(j.index) + _number(j.offset) for j in chain.joints)


def reversed_refs(rev: Chain) -> tuple[sp.Expr, ...]:
    """Reference values for a reversed chain, whose joint k is q'_k = -q_{n+1-k}."""
    n = rev.dof
    return tuple(-sym.q_ref(n + 1 - k) + _number(rev.joints[k - 1].offset) for k in range(1, n + 1))


def unreverse_outputs(outputs: tuple[sp.Expr, ...]) -> tuple[sp.Expr, ...]:
    """The arm's q_j = -q'_{n+1-j} from a reversed chain's outputs."""
    n = len(outputs)
    return tuple(-outputs[n - 1 - j] for j in range(n))


def _number(value: sp.Expr) -> sp.Expr:
    return sp.Integer(0) if value == 0 else sp.Float(float(value), 17)


def typical_magnitude(exprs: tuple[sp.Expr, ...], length: float) -> float:
    """The largest |expr| at a typical pose: wrist centre and flange position at lengths of
    the arm's size, identity rotation. Scales the test for a polynomial vanishing identically.
    """
    pose = sym.flange_pose()
    subs = {pose[i, j]: float(i == j) for i in range(3) for j in range(3)}
    subs.update(
        {
            sym.named("px"): length / 2,
            sym.named("py"): length / 3,
            sym.named("pz"): length / 4,
            sym.named("x"): length / 2,
            sym.named("y"): length / 3,
            sym.named("z"): length / 4,
            sym.named("r"): length**2 * (1 / 4 + 1 / 9 + 1 / 16),
        }
    )
    return max(abs(float(e.xreplace(subs))) for e in exprs)


def unit_column_cs1(
    joint: int,
    a: sp.Expr,
    b: sp.Expr,
    e: sp.Expr,
    others: tuple[sp.Expr, sp.Expr],
    note: str,
    half_width: str = "atan2(sqrt(rest), e)",
) -> Solve:
    """a c + b s = e for an angle whose e is one entry of a unit vector and the two others
    entries too: where a^2 + b^2 = 1, a^2 + b^2 - e^2 is the others' squares, exact to roundings
    near the fold (a wrist nearly straight): Cs1Unit, the half-width atan2(sqrt(rest), e) (the
    lecture's Z-Y-Z theta5; half_width names it in the note); else the plain Cs1."""
    if sp.simplify(a**2 + b**2 - 1) == 0:
        rest = others[0] ** 2 + others[1] ** 2
        return Cs1Unit(joint, (a, b, e, rest), f"{note}, its half-width {half_width}", 2)
    return Cs1(joint, (a, b, e), note, 2)


def angle_poly(
    joint: int,
    coeffs: tuple[sp.Expr, ...],
    note: str,
    ref: sp.Expr,
    scale: float,
) -> Poly:
    """The step solving a polynomial in u = tan(t/2) (coefficients highest degree first): a
    quartic whose coefficients read a, b, c, -b, a, identically in the pose, is PolyPi (the
    equation is unchanged by t -> t + pi, so it is a quadratic in w = u - 1/u, and each root
    gives two angles pi apart); else Poly. Its fanout is its degree."""
    degree = len(coeffs) - 1
    if degree == 4 and all(
        sp.expand(coeffs[k] + sign * coeffs[4 - k]) == 0 for k, sign in ((0, -1), (1, 1))
    ):
        return PolyPi(
            joint,
            coeffs,
            f"{note}; unchanged by theta{joint} -> theta{joint} + pi: a quadratic in "
            f"w = u - 1/u, each root giving theta{joint} and theta{joint} + pi",
            degree,
            ref,
            scale,
        )
    return Poly(joint, coeffs, note, degree, ref, scale)
