"""The tool point's position for a spatial arm of three joints (IKFast's Translation3D):
Pieper's position part (lecture, Pieper -1..-5) with the tool point as the "wrist centre".

A 6R arm's wrist centre is 3P_4org = X_3 Tz(d_4) in frame 3: (a_3, -s(alpha_3) d_4,
c(alpha_3) d_4). A three-joint arm's tool point p = (p_x, p_y, p_z) in frame 3 (the
translation of X_3 E) is such a point for a_3 = p_x, d_4 = sqrt(p_y^2 + p_z^2) and alpha_3 =
atan2(-p_y, p_z); with these numbers f(theta3), g(theta2, theta3), k1..k4, the case's
polynomial in u = tan(theta3/2) and the steps for theta2 and theta1 are derived exactly as for
a 6R arm (derive/methods/pieper.py, position_equations). The target is the tool point in the
frame of joint 1 without d_1: (B X_0 Tz(d_1))^-1 p. Every solution is certified on the tool
point's position (the arm controls no orientation).
"""

from __future__ import annotations

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure
from derive.methods.common import NotApplicable, chain_length, joint_outputs, joint_refs
from derive.methods.pieper import position_equations
from derive.plan import Assign, IkPlan, Step
from derive.transforms import Chain, inverse, numbers_of, product, trans, x_factor

NAME = "position"


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """The position plan of a three-joint spatial arm, or why the method does not apply."""
    if chain.dof != 3:
        return f"position: needs 3 joints (the tool point's position), the arm has {chain.dof}"
    kinds = "".join(j.kind for j in chain.joints)
    if kinds not in ("RRR", "RRP"):
        return f"position: joints {kinds}; supported: RRR, RRP (a prismatic joint 3 only)"
    if 1 in structure.parallel_triples:
        return "position: all axes parallel (the planar method's arm)"
    numbers = numbers_of(chain)
    point = product([x_factor(chain.twists[-1]), chain.tool])[:3, 3]
    px, py, pz = (sp.expand(v.xreplace(numbers)) for v in point)
    moved: list[Step] = []
    typical: dict[sp.Symbol, sp.Expr] = {}
    length = chain_length(chain, last=False)
    if any(v.free_symbols for v in (px, py, pz)):
        # free joints after joint 3 move the tool point in frame 3 (derive/free.py): the
        # solver computes it from their values first, and from it the wrist centre's a3, d4
        # and alpha3 as below. alpha3 enters the equations only as d4 cos(alpha3) = p_z and
        # d4 sin(alpha3) = -p_y (SymPy cancels d4 / d4), so that d4 = 0 (the point on the x
        # axis of frame 3 at those values, any alpha3 right) divides nothing: an Allegro
        # finger's straight pose, its default free value, raised ZeroDivisionError
        names = tuple(sym.named(f"tool3{axis}") for axis in "xyz")
        d4 = sym.named("tool3d4")
        moved += [
            Assign(names, (px, py, pz), "the tool point in frame 3, moved by the free joints"),
            Assign((d4,), (sp.sqrt(names[1] ** 2 + names[2] ** 2),), "... as a3, d4 and alpha3"),
        ]
        numbers[sym.link_a(3)], numbers[sym.d(4)] = names[0], d4
        numbers[sym.cos_alpha(3)], numbers[sym.sin_alpha(3)] = names[2] / d4, -names[1] / d4
        mapping = {"tool_point_in_frame_3": sp.Matrix([px, py, pz])}
        free_values = {s: sp.S.Zero for v in (px, py, pz) for s in v.free_symbols}
        free_values |= {s: sp.S.One for s in free_values if s.name.startswith("cfree")}
        point0 = [v.xreplace(free_values) for v in (px, py, pz)]
        typical = dict(zip(names, point0))
        typical[d4] = sp.sqrt(point0[1] ** 2 + point0[2] ** 2)
        length += _farthest(px, py, pz)
    else:
        d4 = sp.sqrt(py**2 + pz**2)
        ca, sa = (pz / d4, -py / d4) if d4 != 0 else (sp.S.One, sp.S.Zero)  # (alpha3)
        numbers[sym.link_a(3)] = px
        numbers[sym.cos_alpha(3)], numbers[sym.sin_alpha(3)] = ca, sa
        numbers[sym.d(4)] = d4
        mapping = {"tool_point_a3": px, "tool_point_d4": d4}
        mapping |= {"tool_point_cos_alpha3": ca, "tool_point_sin_alpha3": sa}
        length += abs(float(px)) + float(d4)
    try:
        # (an arm with every length 0, a pointing task's, moves its point on the unit sphere:
        # derive/tasks.py; 1 is its size)
        position = position_equations(
            numbers, length or 1.0, joint_refs(chain), kinds[2] == "P", typical
        )
    except NotApplicable as exc:
        return str(exc).replace("Pieper", "position", 1).replace("wrist centre", "tool point")
    head = [chain.base, x_factor(chain.twists[0])]
    if chain.joints[0].kind == "R":
        head.append(trans(0, 0, chain.joints[0].d))
    local = (inverse(product(head)) * sym.world_pose()[:, 3]).applyfunc(sp.expand)
    steps: list[Step] = [
        Assign(
            tuple(sym.named(f"p{axis}") for axis in "xyz"),
            tuple(local[:3]),
            "tool point in frame 1 without d1: (B X0 Tz(d1))^-1 p; the arm controls a position",
        ),
        *moved,
        *position.steps,
    ]
    return IkPlan(
        method=NAME,
        case=f"tool point as Pieper's wrist centre: {position.case}",
        max_solutions=position.fanout,
        steps=tuple(steps),
        outputs=joint_outputs(chain),
        details=tuple(sorted({**position.details, **mapping}.items())),
        solves_for="the tool point's position",
        certify="position",
    )


def _farthest(*point: sp.Expr) -> float:
    """The farthest a tool point that free joints move (expressions in their cos and sin, or
    d) lies from frame 3's origin, bounded by the sum of its terms' sizes."""
    total = 0.0
    for v in point:
        if not v.free_symbols:
            total += abs(float(v))
            continue
        total += sum(abs(float(c)) for c in sp.Poly(v, *sorted(v.free_symbols, key=str)).coeffs())
    return total
