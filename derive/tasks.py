"""IK tasks of arms with fewer joints than a pose needs (IKFast's IK types), reduced to the
pose and position problems the methods already solve by one virtual joint.

* "pose" (Transform6D): the whole pose; the methods' own problem.
* "position" (Translation3D): the tool point; a three-joint arm (derive/methods/position.py).
* "direction" (TranslationDirection5D): the tool point and the direction of one tool axis u
  (z by default). A virtual revolute joint about u through the tool point turns the tool frame
  about u without moving the point or u, so the arm reaches (p, d) exactly where the arm with
  the virtual joint reaches any pose of origin p and axis d: a five-joint arm's task is a
  six-joint arm's pose (Pieper, three parallel axes, the general method). Its value is
  dropped.
* "lookat" (Lookat3D): the tool axis u, from the tool point forward, passes through a point p
  (a pan-tilt head, a camera). A virtual prismatic joint along u carries a point along the ray;
  the two-joint arm looks at p where the three-joint arm's point reaches p with the virtual
  joint's value (the distance) >= 0: a position problem.

* "pointing" (Direction3D): the tool axis u along a direction d, wherever the tool point is.
  Lengths do not turn frames, so the arm with every length 0 (unmoved) has the arm's
  orientations and its tool point at the origin: its tool axis points along d exactly where
  its ray from the origin passes through the point d, a look-at of the unmoved arm whose
  target point is d (the steps read T's column u where a look-at reads its position).
* "axisangle" (Translation{X,Y,Z}AxisAngle4D): the tool point and the angle of the tool axis
  u to a base axis; no virtual joint gives it (u's direction about the base axis is a turn of
  the target about a world line, not a joint), so it has a method of its own
  (derive/methods/cone.py).

The virtual joint is the line L through the tool point o along u, written as one more DH link
after joint n (the frame of joint n after Z_n has its axis as z): the common normal of z and L
gives the twist (alpha, a), its direction phi about z and its foot delta along z (absorbed by
joint n's offset and d, so the arm's own joint values do not change), and the tool sits s along
L from the normal's foot. The extended chain's last frame has origin o and axis column u for
every value of the virtual joint (docs/algorithms.md, "Tasks").
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import sympy as sp

from derive import symbols as sym
from derive.methods.common import NotApplicable
from derive.plan import Assign, IkPlan, Solve, Step
from derive.transforms import (
    Chain,
    JointZ,
    Twist,
    arm_factors,
    product,
    trans,
    world_transform,
    x_factor,
)

TASKS = ("pose", "position", "direction", "lookat", "pointing", "axisangle")
# the tasks' numbers in the C solver (dk_match, DK_REFINE_TASK)
TASK_CODES = {"pose": 0, "position": 1, "direction": 2, "lookat": 3, "pointing": 4, "axisangle": 5}
AXES = ("x", "y", "z")

# what each task's solver is defined on, in words (the module docstring and the report)
SOLVES_FOR = {
    "direction": "the tool point's position and the direction of the tool {axis} axis",
    "lookat": "the tool {axis} axis's ray, from the tool point, through a point",
    "pointing": "the direction of the tool {axis} axis",
    "axisangle": "the tool point's position and the angle of the tool {axis} axis to the base "
    "{cone} axis",
}
# IKFast's names of the tasks
IKFAST_NAMES = {
    "pose": "Transform6D",
    "position": "Translation3D",
    "direction": "TranslationDirection5D",
    "lookat": "Lookat3D",
    "pointing": "Direction3D",
    "axisangle": "Translation{CONE}AxisAngle4D",
}


@dataclass(frozen=True)
class Task:
    """What the solver solves for.

    Attributes:
        kind: one of TASKS.
        axis: the tool axis (0 x, 1 y, 2 z) of "direction" and "lookat".
        why: how it was chosen, in words (the summary line and the report).
        fixed: the spec names the axis (else z, or the first of x, y that works).
        cone: the base axis (0 x, 1 y, 2 z) of "axisangle" (the angle of the tool axis to it).
    """

    kind: str
    axis: int = 2
    why: str = ""
    fixed: bool = False
    cone: int = 2

    @property
    def axis_name(self) -> str:
        """The tool axis's letter."""
        return AXES[self.axis]

    @property
    def virtual(self) -> bool:
        """Whether the task is solved through a virtual joint."""
        return self.kind in ("direction", "lookat", "pointing")

    def describe(self) -> str:
        """The task in words, with IKFast's name."""
        words = {
            "pose": "the full pose",
            "position": "the tool point's position",
            "direction": f"position + direction of the tool {self.axis_name} axis",
            "lookat": f"look-at: the tool {self.axis_name} axis through a point",
            "pointing": f"the direction of the tool {self.axis_name} axis only",
            "axisangle": f"position + angle of the tool {self.axis_name} axis to the base "
            f"{AXES[self.cone]} axis",
        }[self.kind]
        name = IKFAST_NAMES[self.kind].format(CONE=AXES[self.cone].upper())
        return f"{words} ({name})"


def default_task(chain: Chain) -> Task | None:
    """The task an arm's joints choose where the spec names none; None: the methods' own
    (the pose, a three-joint arm's position, a planar arm's)."""
    kinds = "".join(j.kind for j in chain.joints)
    if chain.dof == 5:
        return Task("direction", 2, "five joints: position + direction of a tool axis")
    if kinds == "RRRR":
        return Task(
            "axisangle",
            2,
            "four revolute joints: position + the angle of a tool axis to the base z axis",
        )
    if kinds == "RR" and chain.twists[1].sa != 0:
        return Task("lookat", 2, "two revolute joints, not parallel: a pan-tilt's look-at")
    return None


# rotations A with A e_z = e_axis: the virtual joint turns about the tool's chosen axis
_ALIGN = {
    0: sp.Matrix([[0, 0, 1, 0], [0, 1, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 1]]),  # Ry(90 deg)
    1: sp.Matrix([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]]),  # Rx(-90 deg)
    2: sp.eye(4),
}


def extend(chain: Chain, task: Task, tol: float = 0.0) -> Chain:
    """The chain with the task's virtual joint after joint n (module docstring; snapped as
    extend_snapped's)."""
    return extend_snapped(chain, task, tol)[0]


def extend_snapped(chain: Chain, task: Task, tol: float = 0.0) -> tuple[Chain, float]:
    """The chain with the task's virtual joint after joint n (module docstring), and how far
    snapping moved the virtual link: with tol (the structure tolerance) its twist within tol
    rad of a multiple of 90 deg and its length within tol of the arm's size of 0 are snapped
    (a URDF's noise: an SO-101's tool axis 6e-7 m off its roll axis made the quartic in
    theta1 nearly degenerate); the snap is the twist's change (rad) or the length's over the
    arm's size, the larger (0: none).

    Raises:
        NotApplicable: the virtual joint's line is joint n's axis (joint n then moves neither
            the tool point nor the axis: the task has one joint too few).
    """
    n = chain.dof
    o, u = tool_line(chain, task.axis)
    size = arm_size(chain)
    across = math.sqrt(float(u[0] ** 2 + u[1] ** 2))
    snap = 0.0
    if spins(chain, task.axis, tol):
        raise NotApplicable(
            f"the tool {task.axis_name} axis is joint {n}'s axis: joint {n} moves neither "
            "the tool point nor that axis (choose another tool axis)"
        )
    if across <= math.sin(tol):  # L parallel to joint n's axis (within tol)
        snap = max(snap, math.asin(min(across, 1.0)))
        a = sp.sqrt(sp.simplify(o[0] ** 2 + o[1] ** 2))
        cphi, sphi = sp.simplify(o[0] / a), sp.simplify(o[1] / a)
        ca = sp.Integer(1) if float(u[2]) > 0 else sp.Integer(-1)
        sa, delta = sp.Integer(0), sp.Integer(0)
        s = sp.simplify(o[2] * ca)
    else:
        sa = sp.sqrt(sp.simplify(u[0] ** 2 + u[1] ** 2))
        cphi, sphi = sp.simplify(-u[1] / sa), sp.simplify(u[0] / sa)
        ca = u[2]
        a = sp.simplify(o[0] * cphi + o[1] * sphi)
        along = sp.simplify((o[2] * u[2] - sum(oi * ui for oi, ui in zip(o, u))) / sa**2)
        delta = sp.simplify(o[2] + along * u[2])
        s = sp.simplify(-along)
        if ca != 0 and abs(float(ca)) <= math.sin(tol):  # (a right angle, within tol)
            snap = max(snap, math.asin(abs(float(ca))))
            ca, sa = sp.Integer(0), sp.Integer(1)
        if a != 0 and abs(float(a)) <= tol * size:
            snap = max(snap, abs(float(a)) / size)
            a = sp.Integer(0)
    phi = sp.atan2(sphi, cphi)
    last = chain.joints[-1]
    if last.kind == "R":
        moved = JointZ(n, "R", sp.simplify(last.offset + phi), last.theta, last.d + delta)
    else:
        moved = JointZ(n, "P", last.offset + delta, sp.simplify(last.theta + phi), last.d)
    kind = "R" if task.kind == "direction" else "P"
    zero = sp.Integer(0)
    virtual = (
        JointZ(n + 1, "R", zero, sym.theta(n + 1), zero)
        if kind == "R"
        else JointZ(n + 1, "P", zero, zero, sym.d(n + 1))
    )
    identity = Twist(sp.Integer(1), zero, zero)
    extended = Chain(
        (*chain.twists[:-1], Twist(sp.simplify(ca), sa, a), identity),
        (*chain.joints[:-1], moved, virtual),
        chain.base,
        trans(0, 0, s) * _ALIGN[task.axis].T,
        chain.convention,
    )
    return extended, snap


# an exact virtual link reaching farther than this many times the arm's size from it (a tool
# axis nearly parallel to joint n's: their common normal is far out along them) is not solved
# as it stands (choose: the snapped one is)
FAR_LINK = 10.0


def far_link(chain: Chain, extended: Chain) -> bool:
    """Whether extended's virtual link (extend_snapped's) lies far from the arm: the tool's
    distance s along the task's axis from the common normal's foot, or joint n's offset moved
    by more than FAR_LINK times the arm's size. A tool z axis 4.4e-6 rad from an SO-101's roll
    axis and 8 mm beside it put the foot 1,040 m away: the solver's target then cancelled
    1,040 m terms to millimetres, and poses with the axis along joint 1 got no row (a new
    user's find)."""
    size = arm_size(chain)
    s = abs(float(extended.tool[2, 3]))
    moved = abs(float(extended.joints[chain.dof - 1].d - chain.joints[-1].d))
    return max(s, moved) > FAR_LINK * size


def tool_line(chain: Chain, axis: int) -> tuple[list[sp.Expr], list[sp.Expr]]:
    """The tool point o and the tool axis's direction u in joint n's frame after Z_n."""
    frame = product([x_factor(chain.twists[-1]), chain.tool, _ALIGN[axis]])
    return [sp.simplify(frame[i, 3]) for i in range(3)], [
        sp.simplify(frame[i, 2]) for i in range(3)
    ]


def spins(chain: Chain, axis: int, tol: float = 0.0) -> bool:
    """Whether the tool axis's line is joint n's axis (within tol: the angle, and the tool
    point's distance over the arm's size): joint n then turns the tool about that line and
    moves neither the tool point nor the axis's direction."""
    o, u = tool_line(chain, axis)
    across = math.sqrt(float(u[0] ** 2 + u[1] ** 2))
    off = math.sqrt(float(o[0] ** 2 + o[1] ** 2))
    return across <= math.sin(tol) and off <= tol * arm_size(chain)


def axis_order(chain: Chain, tol: float) -> tuple[int, ...]:
    """The tool axes a task tries where the spec names none: z, x, y, those parallel to
    joint n's axis (within tol) but beside it last. Joint n turns such an axis about a
    parallel line, so it points the same way for every q_n and joint n serves the tool point
    only through the lever between the lines (8 mm on an SO-101's gripper frame: the task is
    ill-conditioned everywhere and lost solutions). (Joint n's own axis fails a five-joint
    arm's task and frees joint n of a longer arm: spins.)"""
    beside = {}
    for axis in (2, 0, 1):
        u = tool_line(chain, axis)[1]
        parallel = math.sqrt(float(u[0] ** 2 + u[1] ** 2)) <= math.sin(tol)
        beside[axis] = parallel and not spins(chain, axis, tol)
    return tuple(sorted(beside, key=lambda axis: beside[axis]))


def unmoved(chain: Chain) -> Chain:
    """The chain's rotations only: every a_i and d_i, and the base's and the tool's
    translations, 0. Its frames turn as the arm's do, and its tool point is the origin for
    every q (a pointing task's arm; only revolute joints turn frames)."""
    zero = sp.Integer(0)
    base, tool = sp.Matrix(chain.base), sp.Matrix(chain.tool)
    base[:3, 3] = tool[:3, 3] = sp.zeros(3, 1)
    return Chain(
        tuple(Twist(t.ca, t.sa, zero) for t in chain.twists),
        tuple(dataclasses.replace(j, d=zero) for j in chain.joints),
        base,
        tool,
        chain.convention,
    )


def pointed(step: Step, axis: int) -> Step:
    """A look-at step of the unmoved arm as the pointing task's: the target's position
    entries (the point looked at) read from its column axis (the direction)."""
    world = sym.world_pose()
    return _substitute(step, {world[r, 3]: world[r, axis] for r in range(3)})


def arm_size(chain: Chain) -> float:
    """The arm's size for the snapping of lengths: its |a| and |d| and its tool's offset."""
    size = sum(abs(float(t.a)) for t in chain.twists)
    size += sum(abs(float(j.d)) for j in chain.joints if j.kind == "R")
    size += math.sqrt(sum(float(v) ** 2 for v in chain.tool[:3, 3]))
    return size or 1.0


def lower(ik: IkPlan, chain: Chain, extended: Chain, task: Task, snap: float = 0.0) -> IkPlan:
    """The extended chain's plan as the arm's: the virtual joint's value dropped from the
    outputs (its reference value 0), certified on the task's components; snap: how far the
    virtual link was snapped (its rows are then refined onto the arm: derive/pipeline.py)."""
    n = chain.dof
    zero = {sym.q_ref(n + 1): sp.Integer(0)}
    steps = tuple(_substitute(step, zero) for step in ik.steps)
    virtual = virtual_value(extended, task)
    if task.kind == "pointing":
        steps = tuple(pointed(step, task.axis) for step in steps)
        world = sym.world_pose()
        virtual = tuple(
            e.xreplace({world[r, 3]: world[r, task.axis] for r in range(3)}) for e in virtual
        )
    free_text = ik.free_text
    if ik.free:  # (an arm of more joints than the task needs: derive/free.py)
        free_text += f" (joint {n + 1} is the task's virtual joint)"
    return dataclasses.replace(
        ik,
        steps=steps,
        outputs=ik.outputs[:n],
        free_text=free_text,
        details=tuple(sorted({**dict(ik.details), **link_details(chain, extended)}.items())),
        solves_for=SOLVES_FOR[task.kind].format(axis=task.axis_name),
        certify=task.kind,
        case={
            "direction": f"{task.describe()} as the pose of the arm with a virtual joint "
            f"{n + 1}: {ik.case}",
            "lookat": f"{task.describe()} as the position of the arm with a virtual joint "
            f"{n + 1} sliding along the axis: {ik.case}",
            "pointing": f"{task.describe()} as a look-at of the arm with every length 0 "
            f"(its tool point the origin) at the point d, a virtual joint {n + 1} sliding "
            f"along the axis: {ik.case}",
        }[task.kind],
        tool_axis=task.axis,
        relabel=relabel(chain, extended),
        virtual=virtual,
        task_snap=snap,
    )


def lower_spun(ik: IkPlan, chain: Chain, task: Task) -> IkPlan:
    """The plan of the arm's own pose as its direction task's, where joint n turns about the
    tool axis through the tool point (spins): joint n plays the virtual joint, so the steps
    solve the pose of origin p whose tool axis is d (any such pose) and joint n's value is
    the caller's, a free joint (it moves neither p nor d)."""
    n = chain.dof
    why = (
        f"q{n} (its axis is the tool {task.axis_name} axis through the tool point: it moves "
        "neither the point nor the axis, so the task leaves it free)"
    )
    return dataclasses.replace(
        ik,
        outputs=(*ik.outputs[: n - 1], sym.q_ref(n)),
        free=tuple(sorted((*ik.free, n))),
        free_text="; ".join(t for t in (ik.free_text, why) if t),
        solves_for=SOLVES_FOR[task.kind].format(axis=task.axis_name),
        certify=task.kind,
        case=f"{task.describe()} as the arm's pose, joint {n} turning about the tool "
        f"{task.axis_name} axis: {ik.case}",
        tool_axis=task.axis,
        details=tuple(sorted({**dict(ik.details), "task_spun_joint": sp.Integer(n)}.items())),
        virtual=spun_value(chain),
    )


def spun_value(chain: Chain) -> tuple[sp.Expr, ...]:
    """The steps' theta_n where joint n plays the virtual joint (lower_spun), for the report's
    worked example: with P = B X_0 Z_1 ... X_{n-1} and S = X_n E, the target's rotation is
    R_P Rz(theta_n) R_S, so (cos, sin) are entries (1,1), (2,1) of R_P^T R_W R_S^T."""
    rest = product([chain.base, *arm_factors(chain)[:-2]], expand=False)
    after = product([x_factor(chain.twists[-1]), chain.tool])
    m = rest[:3, :3].T * sym.world_pose()[:3, :3] * after[:3, :3].T
    return (m[0, 0], m[1, 0])


def virtual_value(extended: Chain, task: Task) -> tuple[sp.Expr, ...]:
    """The virtual joint's value where the extended arm reaches the target W (for the
    report's worked example): its last frame at value 0 is F_0, and F_0^-1 F = A Rz(v) A^T,
    so (cos v, sin v) are entries (1,1), (2,1) of A^T R_0^T R_W A; a slide's length is
    (p - o) . u, o and u F_0's origin and axis column."""
    n1 = extended.dof
    world = world_transform(extended, expand=False)
    target = sym.world_pose()
    if task.kind == "direction":  # (a look-at's and a pointing's: a slide)
        rest = world.xreplace({sym.c(n1): sp.Integer(1), sym.s(n1): sp.Integer(0)})
        align = _ALIGN[task.axis][:3, :3]
        m = align.T * rest[:3, :3].T * target[:3, :3] * align
        return (m[0, 0], m[1, 0])
    rest = world.xreplace({sym.d(n1): sp.Integer(0)})
    return (sum((target[i, 3] - rest[i, 3]) * rest[i, task.axis] for i in range(3)),)


def link_details(chain: Chain, extended: Chain) -> dict[str, sp.Expr]:
    """The virtual joint's link for the report: its twist (cos, sin alpha_n and a_n), joint
    n's shift in theta (or d) and in d, and the tool's distance s along the axis."""
    n = chain.dof
    twist = extended.twists[n]
    old, new = chain.joints[-1], extended.joints[-2]
    return {
        "task_cos_alpha": twist.ca,
        "task_sin_alpha": twist.sa,
        "task_a": twist.a,
        "task_relabel": relabel(chain, extended),
        "task_shift_d": sp.simplify(new.d - old.d) if old.kind == "R" else sp.Integer(0),
        "task_s": extended.tool[2, 3],
        "task_virtual_joint": sp.Integer(n + 1),
    }


def relabel(chain: Chain, extended: Chain) -> sp.Expr:
    """How much the extended chain's theta_n (d_n of a prismatic joint n) exceeds the arm's."""
    old, new = chain.joints[-1], extended.joints[-2]
    return sp.simplify(new.offset - old.offset)


def _substitute(step: Step, values: dict[sp.Symbol, sp.Integer]) -> Step:
    """One step with symbols replaced by values."""
    if isinstance(step, Assign):
        return Assign(step.targets, tuple(e.xreplace(values) for e in step.exprs), step.note)
    assert isinstance(step, Solve)
    changes: dict[str, object] = {
        "args": tuple(e.xreplace(values) for e in step.args),
        "ref": step.ref.xreplace(values),
    }
    return dataclasses.replace(step, **changes)  # type: ignore[arg-type]


@dataclass(frozen=True)
class Plane:
    """A planar arm's task in the world (IKFast's TranslationXYOrientation3D for three
    revolute joints, TranslationXY2D for two): every joint axis is along the world's z, so the
    tool's rotation is Rz(psi) R0 and, without a sliding joint, its height is fixed.

    Attributes:
        heading: whether the task has a heading (three revolute joints).
        rotation: R0, the tool's rotation at q = 0 (9 floats, row-major).
        axis: the tool axis whose angle about z from the world's x is the heading: 0 x, or 1 y
            where the tool y axis lies nearer the plane.
        zero: that axis's heading at q = 0 (rad).
        height: the tool point's z at q = 0 (every z without a sliding joint).
        slide: whether a sliding joint moves the tool along z (the caller gives z).
    """

    heading: bool
    rotation: tuple[float, ...]
    axis: int
    zero: float
    height: float
    slide: bool

    @property
    def ikfast(self) -> str:
        """IKFast's name of the task."""
        return "TranslationXYOrientation3D" if self.heading else "TranslationXY2D"


# how far from the world's z a planar arm's axes may point for its plane task (the axes of a
# spec's planar arm are exactly z, or a URDF's within its rounding)
PLANE_AXIS_TOL = 1e-9


def plane_of(
    frames: tuple[tuple[float, ...], ...], joint_types: str, method: str, certify: str
) -> Plane | None:
    """The plane task of an arm the planar method solves (frames: its exact chain, F_0 .. F_n),
    or None: another method, or the axes not along the world's z."""
    if method != "planar" or not frames:
        return None
    pose = [list(frames[0][4 * r : 4 * r + 4]) for r in range(3)]
    axis_z = abs(pose[2][2])
    if abs(axis_z - 1.0) > PLANE_AXIS_TOL:
        return None
    for f in frames[1:]:
        F = [f[4 * r : 4 * r + 4] for r in range(3)]
        pose = [
            [sum(pose[r][k] * F[k][c] for k in range(3)) + (pose[r][3] if c == 3 else 0.0)
             for c in range(4)]
            for r in range(3)
        ]  # fmt: skip
    axis = 0 if math.hypot(pose[0][0], pose[1][0]) >= math.hypot(pose[0][1], pose[1][1]) else 1
    return Plane(
        heading=certify == "pose",
        rotation=tuple(pose[r][c] for r in range(3) for c in range(3)),
        axis=axis,
        zero=math.atan2(pose[1][axis], pose[0][axis]),
        height=pose[2][3],
        slide="P" in joint_types,
    )
