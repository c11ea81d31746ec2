"""Position and the tool axis's angle to a base axis (IKFast's Translation{X,Y,Z}AxisAngle4D):
arms of four revolute joints whose joint 1 turns about that base axis and whose joints 2-4 are
parallel (OpenManipulator-X, a youBot or SO-ARM100 without its wrist roll, palletizers).

The task fixes the tool point p and the component t_c = e_c . u of the tool axis u along the
base axis e_c (the cosine of the cone angle), not u's direction about e_c. Derived from the
chain F = (B X0) Z1 X1 M, M = Z2 X2 Z3 X3 Z4 X4 E:

* t_c = e_c . R_F u does not depend on theta1, since joint 1 turns about e_c, and joints 2-4
  turn about parallel axes, so Z2 X2 Z3 X3 Z4 turns by one angle phi = theta2 +- theta3 +-
  theta4: t_c = A cos phi + B sin phi + C, phi from a cos + b sin = c (two values, the tool
  tilted either way). phi is solved as an auxiliary angle (the steps' joint n + 1, whose
  value is dropped).
* M moves the tool point in planes across joint 2's axis: its component along that axis is
  a constant l, so the tool point in frame 1' = (B X0 Z1 X1) has that component l:
  a cos theta1 + b sin theta1 = c (two values, the shoulder facing the point or turned away),
  and theta1 is free where the tool point is on axis 1 with l = 0.
* With phi known, the point of axis 4 (the wrist) is the tool point less Rz(phi) F t4 (t4 the
  tool point's offset from axis 4), and theta3, theta2 are the planar 2R steps (law of
  cosines, then k1, k2), theta4 the heading: Rz(theta4) = (Z2 X2 Z3 X3)_R^T Rz(phi) F.

At most 8 solutions. A five-joint arm whose joint 5 turns about the tool axis through the
tool point (a wrist roll) is solved as its first four joints, with q5 free (the caller's
value: it moves neither the point nor the axis).
"""

from __future__ import annotations

import math

import sympy as sp

from derive import symbols as sym
from derive.halfangle import linear_coeffs
from derive.methods.common import NotApplicable, chain_length, joint_outputs, joint_refs
from derive.methods.planar import heading_step, planar_steps
from derive.plan import Assign, Cs1, IkPlan, Step
from derive.tasks import AXES, arm_size, spins, tool_line
from derive.transforms import Chain, JointZ, inverse, product, rot_z, trans, x_factor, z_factor

NAME = "cone"


# a tool axis whose angle to the base axis the joints can move by less than this (its cos
# by at most CONE_FLAT) is no axis for the task: nearly along joints 2-4's axes, it leaves
# joint 4 nearly free and the angle nearly fixed (a Seeed B601's gripper z axis, 3.7e-6 rad off
# them in its URDF: every row valid, the sampled vector never among them, and a whole branch
# of theta1 missing; a new user's attack), and the next axis is tried
CONE_FLAT = 1e-3


def derive(chain: Chain, axis: int, cone: int, tol: float = 0.0) -> IkPlan:
    """The plan of the task for the tool axis `axis` (0 x, 1 y, 2 z) and the base axis `cone`
    (a five-joint arm's joint 5 taken as turning about the tool axis within tol: radians, and
    the tool point's distance from its axis over the arm's size; the plan's task_snap says
    how far, and the pipeline then refines its rows onto the arm).

    Raises:
        NotApplicable: the arm has not the structure above (the message says what differs).
    """
    n = chain.dof
    kinds = "".join(j.kind for j in chain.joints)
    snap = 0.0
    if kinds == "RRRRR":
        across, beside = _spin_gap(chain, axis)
        if not spins(chain, axis, tol):
            raise NotApplicable(
                f"joint 5 does not turn about the tool {AXES[axis]} axis through the tool "
                f"point (the axis {math.degrees(across):.3g} deg off joint 5's, the point "
                f"{beside:.3g} beside it), so it moves the point or the axis: one joint too "
                "many"
            )
        snap = max(across, beside / arm_size(chain))
    elif kinds != "RRRR":
        raise NotApplicable(
            f"needs 4 revolute joints (or 5 with joint 5 turning about the tool axis), "
            f"the arm has {kinds}"
        )
    spun = n == 5
    arm = _first_four(chain) if spun else chain
    aux = n + 1  # (the auxiliary angle phi: the steps' joint n + 1, dropped from the outputs)
    refs = joint_refs(arm)
    head = product([chain.base, x_factor(chain.twists[0])])
    along = sp.nsimplify(head[cone, 2])
    if along not in (1, -1) or any(head[cone, k] != 0 for k in (0, 1)):
        raise NotApplicable(f"joint 1's axis is not along the base {AXES[cone]} axis")
    sign = int(along)
    flips = []
    for k in (2, 3):
        twist = arm.twists[k]
        if twist.sa != 0:
            raise NotApplicable(f"axes {k} and {k + 1} are not parallel")
        flips.append(int(sp.nsimplify(twist.ca)))
    # Z2 X2 Z3 X3 Z4 = Rz(phi) F: F = Rx(pi) where one of alpha2, alpha3 is pi
    phi_signs = (1, flips[0], flips[0] * flips[1])
    flip = sp.diag(1, flips[0] * flips[1], flips[0] * flips[1])
    x1 = x_factor(arm.twists[1])
    after = product([x_factor(arm.twists[4]), arm.tool])  # X4 E
    # the tool axis's component along e_c: e_c^T R_(B X0) Rz(theta1) R_X1 Rz(phi) F R_(X4 E) u
    turned = rot_z(sym.c(aux), sym.s(aux))[:3, :3]
    tilt = (x1[:3, :3] * turned * flip * after[:3, :3])[2, axis] * sign
    ca, sa, cc = _linear(sp.expand(tilt), aux)
    swing = math.hypot(float(ca), float(sa))  # (how far the angle's cos can move)
    if swing <= CONE_FLAT:
        raise NotApplicable(
            f"the tool {AXES[axis]} axis is along joints 2-4's axes (within "
            f"{math.degrees(math.asin(min(swing, 1.0))):.2g} deg): its angle to the base "
            f"{AXES[cone]} axis does not change, and joint 4 moves neither it nor the point"
        )
    # the tool point in frame 1' (after X1) as M's: wrist W(theta2, theta3) + Rz(phi) F t4
    wrist = product(
        [
            z_factor(arm.joints[1]),
            x_factor(arm.twists[2]),
            z_factor(arm.joints[2]),
            x_factor(arm.twists[3]),
        ]
    )
    turns = _check_turn(wrist, arm.joints[3], phi_signs, flip)
    t4 = product([trans(0, 0, arm.joints[3].d), after])[:3, 3]
    lateral = sp.expand(wrist[2, 3] + (flip * t4)[2])
    if lateral.free_symbols:
        raise NotApplicable("joints 2-4 do not move the tool point in one plane")
    world = sym.world_pose()
    point = tuple(sym.named(f"p{c}") for c in "xyz")
    local = (inverse(head) * world[:, 3]).applyfunc(sp.expand)
    in1 = inverse(z_factor(arm.joints[0])) * sp.Matrix([*point, 1])  # frame 1
    in1p = (inverse(x1) * in1).applyfunc(sp.expand)  # frame 1'
    a1, b1, e1 = _linear(in1p[2] - lateral, 1)
    if a1 == 0 and b1 == 0:
        raise NotApplicable("joint 2's axis is parallel to joint 1's")
    length = chain_length(arm) + math.sqrt(float(sum(v**2 for v in t4)))
    target = (in1p[:3, 0] - turned * flip * t4).applyfunc(sp.expand)
    x, y = sym.named("x"), sym.named("y")
    cone_name = AXES[cone]
    steps: list[Step] = [
        Assign(point, tuple(local[:3]), "tool point in frame 0: (B X0)^-1 p"),
        Cs1(
            1,
            (a1, b1, -e1),
            f"theta1: the tool point's component along joint 2's axis is {sp.sstr(lateral)} "
            "whatever theta2..theta4 (they turn about parallel axes)",
            2,
            refs[0],
            scale=length**2,
        ),
        Cs1(
            aux,
            (ca, sa, world[cone, axis] - cc),
            f"phi (theta{aux} here: an angle, not a joint, dropped from the answers) = theta2 "
            f"{_signed(phi_signs[1])} theta3 {_signed(phi_signs[2])} theta4: the "
            f"tool {AXES[axis]} axis's {cone_name} component, {_in_phi(ca, sa, cc)}, is the "
            f"target's (theta1 turns about {cone_name})",
            2,
            sp.Integer(0),
            scale=1.0,
        ),
        Assign(
            (x, y), (target[0], target[1]), "axis 4 in frame 1': the tool point less Rz(phi) F t4"
        ),
    ]
    steps += planar_steps(wrist[0, 3], wrist[1, 3], 2, 3, x, y, refs, length)
    steps.append(heading_step(wrist[:3, :3], sp.eye(3), 4, refs, turned * flip))
    outputs = joint_outputs(arm)
    free: tuple[int, ...] = ()
    free_text = ""
    if spun:
        outputs = (*outputs, sym.q_ref(5))
        free = (5,)
        free_text = (
            f"q5 (its axis is the tool {AXES[axis]} axis through the tool point: it moves "
            "neither the point nor the axis, so the task leaves it free)"
        )
    return IkPlan(
        NAME,
        f"position + angle of the tool {AXES[axis]} axis to the base {cone_name} axis "
        f"(Translation{cone_name.upper()}AxisAngle4D): theta1 from the lateral offset, phi "
        "from the tilt, then the planar 2R and the heading",
        8,
        tuple(steps),
        outputs,
        details=(("cone_lateral", lateral), ("cone_tilt", sp.expand(tilt))),
        solves_for=(
            f"the tool point's position and the angle of the tool {AXES[axis]} axis to the "
            f"base {cone_name} axis"
        ),
        certify="axisangle",
        free=free,
        free_text=free_text,
        tool_axis=axis,
        virtual=(turns[0, 0], turns[1, 0]),  # (phi on a solution's branch: Rz(phi) F's column 1)
        cone=cone,
        task_snap=snap,
    )


def _linear(expr: sp.Expr, joint: int) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """(A, B, C) with expr = A cos theta_joint + B sin theta_joint + C."""
    try:
        return linear_coeffs(expr, sym.c(joint), sym.s(joint))
    except ValueError as exc:
        raise NotApplicable(f"an equation is not linear in c{joint}, s{joint}") from exc


def _signed(sign: int) -> str:
    return "+" if sign > 0 else "-"


def _check_turn(
    wrist: sp.Matrix, fourth: JointZ, signs: tuple[int, ...], flip: sp.Matrix
) -> sp.Matrix:
    """Z2 X2 Z3 X3 Z4's rotation (wrist = Z2 X2 Z3 X3), in c2..s4: Rz(theta2 + s3 theta3 +
    s4 theta4) F, checked at three sets of angles (a guard on the reading of the twists)."""
    turns = product([wrist, z_factor(fourth)])[:3, :3]
    for angles in ((0.3, -1.1, 2.0), (2.5, 0.7, -0.4), (-1.9, 3.0, 1.3)):
        subs = {}
        for k, t in zip((2, 3, 4), angles):
            subs[sym.c(k)], subs[sym.s(k)] = math.cos(t), math.sin(t)
        phi = sum(s * t for s, t in zip(signs, angles))
        want = rot_z(sp.Float(math.cos(phi)), sp.Float(math.sin(phi)))[:3, :3] * flip
        got = turns.xreplace(subs)
        if max(abs(float(got[i, j] - want[i, j])) for i in range(3) for j in range(3)) > 1e-12:
            raise NotApplicable("joints 2-4 do not turn about one axis by one angle")
    return turns


def _first_four(chain: Chain) -> Chain:
    """A five-joint arm's first four joints, joint 5 at q5 = 0 part of the tool."""
    fifth = chain.joints[4]
    c5, s5 = sym.cos_sin(fifth.offset)
    z5 = z_factor(fifth).xreplace({sym.c(5): c5, sym.s(5): s5})
    tool = product([z5, x_factor(chain.twists[5]), chain.tool])
    return Chain(chain.twists[:5], chain.joints[:4], chain.base, tool, chain.convention)


def _in_phi(ca: sp.Expr, sa: sp.Expr, cc: sp.Expr) -> str:
    """A cos(phi) + B sin(phi) + C in words."""
    cos_phi, sin_phi = sp.Symbol("cos(phi)"), sp.Symbol("sin(phi)")
    return sp.sstr(ca * cos_phi + sa * sin_phi + cc)


def _spin_gap(chain: Chain, axis: int) -> tuple[float, float]:
    """How far joint 5 is from turning about the tool axis through the tool point: the
    angle between the axes (radians) and the point's distance from joint 5's axis (0, 0
    where it does exactly)."""
    o, u = tool_line(chain, axis)
    across = math.asin(min(1.0, math.sqrt(float(u[0] ** 2 + u[1] ** 2))))
    return across, math.sqrt(float(o[0] ** 2 + o[1] ** 2))
