"""spec -> structure -> method -> plan: the one place that chooses a solution method."""

from __future__ import annotations

import dataclasses
import math

import sympy as sp

from derive import free, jacobian, tasks
from derive import symbols as sym
from derive.classify import Structure, classify
from derive.methods import cone, general, parallel, pieper, planar, position
from derive.methods.common import NotApplicable
from derive.nominal import (
    STRUCTURE_TOL,
    Nominal,
    chain_frames,
    deviation,
    frames_factors,
    frames_pose,
    link_size,
    nominal,
)
from derive.plan import ArmInfo, Correction, IkPlan, Plan
from derive.spec import ArmSpec, SpecError
from derive.transforms import (
    Chain,
    arm_factors,
    chain_from_spec,
    frame_matrix,
    link_transform,
    world_transform,
)

# Tried in order; each returns a plan, or a one-line reason why it does not apply.
METHODS = {
    pieper.NAME: pieper.derive,
    parallel.NAME: parallel.derive,
    planar.NAME: planar.derive,
    position.NAME: position.derive,
    general.NAME: general.derive,
}


def build_plan(spec: ArmSpec, method: str | None = None) -> Plan:
    """Derive everything the generated module and the report need for one arm; with method
    (a key of METHODS; default the spec's [ik] method), that method only (the general one
    also solves special arms: the tests compare it with the closed forms).

    The closed forms are tried on the arm's own table, then on its nominal table
    (derive/nominal.py: the structure parameters within the spec's structure_tol of a
    special value snapped), whose answers the module refines onto the arm's; the general
    method last, on the arm's own table."""
    chain = chain_from_spec(spec)
    structure = classify(chain)
    method = method or spec.method
    if method is not None and method not in METHODS:
        raise ValueError(f"no method {method!r}; methods: {', '.join(METHODS)}")
    names = (method,) if method else tuple(METHODS)
    closed = tuple(name for name in names if name != general.NAME)
    # the exact geometry: the spec's [exact] frames (a URDF's), else its table's
    frames = spec.exact if spec.exact is not None else chain_frames(chain)
    task = task_of(spec, chain)
    tol = STRUCTURE_TOL if spec.structure_tol is None else spec.structure_tol
    ik, refusal = choose(chain, structure, spec.free, closed, task, tol, method)
    correction = None
    facts = structure.describe(chain.dof)
    far = ""  # (a nominal table too far from the arm to refine from)
    if ik is None and closed:
        near = nominal(spec, tol)
        if near.changes:
            near_chain = chain_from_spec(near.spec)
            near_structure = classify(near_chain)
            near_ik, _ = choose(near_chain, near_structure, spec.free, closed, task, tol, method)
            if near_ik is not None:
                fix = make_correction(near, near_chain, frames, arm_info(spec, chain).reach)
                if fix.deviation <= NOMINAL_MAX:
                    ik, refusal, correction = near_ik, "", fix
                    facts = tuple(
                        f"{fact} (nominal table)" for fact in near_structure.describe(chain.dof)
                    )
                else:  # (snapping that far changes the arm: its seeds would not reach)
                    far = refusal = (
                        f"the table within structure_tol {tol:g} of a special one moves the "
                        f"arm by {fix.deviation:.3g} (at most {NOMINAL_MAX:g} is refined)"
                    )
    if ik is None and task is not None and task.kind == "axisangle" and task.why != NAMED:
        # (the joints chose the angle task, and neither the table nor a nominal one near it
        # has its closed form, as a humanoid's shoulder and elbow: the tool point's position,
        # one joint free)
        ik, alone = choose(chain, structure, spec.free, closed, POSITION_INSTEAD, tol)
        if ik is not None:
            task, refusal = POSITION_INSTEAD, ""
        elif alone:
            refusal = f"{refusal}; the tool point's position: {alone}"
    if ik is None and general.NAME in names:
        ik, why = choose(chain, structure, spec.free, (general.NAME,), task, tol, method)
        reasons = [r for r in (refusal, why) if r]
        if ik is not None and far:  # (the summary says why the nominal one was not used)
            facts = (*facts, far)
        refusal = "; ".join(dict.fromkeys(reasons)) if ik is None else ""
    if correction is None and spec.exact is not None:
        # the table is the nominal one of the [exact] frames (a URDF's, snapped)
        correction = make_correction(
            Nominal(spec, (), 0.0), chain, frames, arm_info(spec, chain).reach
        )
        if correction.deviation > NOMINAL_MAX:
            raise SpecError(
                f"{spec.source}: exact.frames: the arm they describe differs from the table's "
                f"by {correction.deviation:.3g} in forward kinematics (allowed {NOMINAL_MAX:g}:"
                " rotation entries, positions over the reach); the table must describe the "
                "same arm (were rows, [base] or [tool] edited after derive import-urdf? import "
                "the URDF again, or delete [exact])"
            )
        if correction.deviation <= EXACT_ENOUGH or ik is None:
            correction = None
        else:
            facts = tuple(f"{fact} (nominal table)" for fact in facts)
    if ik is not None and ik.task_snap > 0.0:
        if correction is None:  # (the table is exact; its task's virtual link is not)
            facts = tuple(f"{fact} (nominal table)" for fact in facts)
        correction = snapped_task(correction, ik, arm_info(spec, chain).dh, tol)
    if (
        correction is not None
        and ik is not None
        and ik.certify == "pose"
        and chain.dof - len(ik.free) == 6
        and ik.max_solutions < GENERAL_MOST
    ):
        # the exact arm is a general 6R one: more solutions than its nominal's where they are
        # close (a calibrated PUMA has 11 with its elbow folded back, its wrist centre near
        # axis 2), at most 16
        ik = dataclasses.replace(ik, max_solutions=GENERAL_MOST)
    if task is not None and (ik is None or ik.certify == task.kind):
        shown = task if ik is None else dataclasses.replace(task, axis=ik.tool_axis)
        why = task.why
        if ik is not None and ik.tool_axis != 2 and not task.fixed:
            # (the closed forms try every axis before the general method does: a new user's
            # Shadow thumb got its tool y axis by a closed form though the general method
            # solves z, which "the first that works" did not say)
            order = (
                f"tool z, x, y axes, those parallel to joint {chain.dof}'s axis but beside it last"
            )
            if ik.method == general.NAME:
                why += f" (of the {order}, no closed form solves one; the general method's first:"
            else:
                why += f" (the first of the {order}, that a closed form solves:"
            why += f" {shown.axis_name})"
        facts = (*facts, f"task: {shown.describe()}: {why}")
    pose = world_transform(chain, expand=False)
    # (the pose's factors, and where its joints' are: the Jacobian's, derive/jacobian.py)
    factors = [chain.base, *arm_factors(chain), chain.tool]
    joints = [2 + 2 * k for k in range(chain.dof)]
    if spec.exact is not None:
        pose = frames_pose(spec.exact, chain)
        factors = frames_factors(spec.exact, chain)
        joints = [1 + 2 * k for k in range(chain.dof)]
    # (exact frames, dense: the module computes the Jacobian from the chain at run time)
    velocity = (
        None if spec.exact is not None else jacobian.geometric(factors, joints, spec.joint_types)
    )
    joint_defs = joint_definitions(chain)
    if ik is not None and ik.relabel != 0:
        pose, joint_defs = relabelled(pose, joint_defs, chain, ik.relabel)
        if velocity is not None:
            velocity = in_steps_variable(velocity, chain, ik.relabel)
    return Plan(
        arm=arm_info(spec, chain),
        structure=facts,
        fk_pose=pose,
        jacobian=velocity,
        links=tuple(link_transform(chain, i) for i in range(1, chain.dof + 1)),
        joint_defs=joint_defs,
        ik=ik,
        refusal=refusal,
        correction=correction,
        frames=frames,
    )


# a task's `why` where the spec names it
NAMED = "named ([ik] task, or --task)"
# the task of four revolute joints where the angle task does not apply (choose)
POSITION_INSTEAD = tasks.Task(
    "position",
    2,
    "four revolute joints, the angle of a tool axis to a base axis not solved in closed form "
    "for them (--task axisangle says why): the tool point's position, one joint free",
)


def task_of(spec: ArmSpec, chain: Chain) -> tasks.Task | None:
    """The task the spec names, or the one its joints choose (derive/tasks.py); None: the
    methods' own problem (a pose, a three-joint arm's position).

    Raises:
        SpecError: the task does not fit the arm's joints.
    """
    n, kinds = spec.dof, spec.joint_types
    where = f"{spec.source}: ik.task"
    if spec.task is None:
        task = tasks.default_task(chain)
    elif spec.task == "pose":
        if n < 6:
            raise SpecError(f'{where}: "pose" needs at least 6 joints, the arm has {n}')
        task = None
    elif spec.task == "position":
        if n < 3:
            raise SpecError(f'{where}: "position" needs at least 3 joints, the arm has {n}')
        # (more than 3: the others are free joints, three solved for the tool point; 3: the
        # position method, not the planar one a planar arm's joints would choose)
        task = tasks.Task("position", 2, NAMED)
    elif spec.task == "direction":
        if n < 5:
            raise SpecError(f'{where}: "direction" needs at least 5 joints, the arm has {n}')
        task = tasks.Task("direction", 2, NAMED)
    elif spec.task == "axisangle":
        if n not in (4, 5):
            raise SpecError(
                f'{where}: "axisangle" needs 4 joints (or 5, the last a wrist roll about the '
                f"tool axis), the arm has {n}"
            )
        task = tasks.Task("axisangle", 2, NAMED)
    else:
        if kinds != "RR":
            raise SpecError(f'{where}: "{spec.task}" needs 2 revolute joints, the arm has {kinds}')
        task = tasks.Task(spec.task, 2, NAMED)
    if spec.tool_axis is not None:
        if task is None:
            raise SpecError(
                f'{spec.source}: ik.tool_axis: only the "direction", "lookat", "pointing" and '
                '"axisangle" tasks have a tool axis'
            )
        task = dataclasses.replace(task, axis=tasks.AXES.index(spec.tool_axis), fixed=True)
    if spec.base_axis is not None:
        if task is None or task.kind != "axisangle":
            raise SpecError(f'{spec.source}: ik.base_axis: only the "axisangle" task has one')
        task = dataclasses.replace(task, cone=tasks.AXES.index(spec.base_axis))
    return task


def choose(
    chain: Chain,
    structure: Structure,
    named: tuple[int, ...] | None,
    names: tuple[str, ...],
    task: tasks.Task | None = None,
    tol: float = STRUCTURE_TOL,
    method: str | None = None,
) -> tuple[IkPlan | None, str]:
    """The first of the named methods that solves the chain (an arm of more than 6 joints:
    with free joints; a task's arm: extended by its virtual joint, about the task's tool axis,
    else about the first of z, x, y that works), or None and why none does."""
    if task is not None and task.kind == "position":  # (three joints solve the tool point,
        # the others free)
        solvers = tuple(n for n in names if n == position.NAME)
        if chain.dof == 3:
            return choose_method(chain, structure, solvers) if solvers else (None, "")
        return choose_free(chain, named, solvers, size=3)
    if task is not None and task.kind == "axisangle":
        return choose_cone(chain, structure, named, names, task, tol, method)
    if task is not None and task.virtual:
        reasons = []
        if task.why != NAMED:  # (the joints chose it: a method of the arm's own comes first)
            ik, why = choose(chain, structure, named, names)
            if ik is not None:
                return ik, why
        n = chain.dof
        for axis in (task.axis,) if task.fixed else tasks.axis_order(chain, tol):
            aimed = dataclasses.replace(task, axis=axis)
            if task.kind == "direction" and n > 5 and tasks.spins(chain, axis, tol):
                # joint n turns about the tool axis: it is the virtual joint, and free
                if named is not None and n not in named:
                    reasons.append(
                        f"tool {tasks.AXES[axis]} axis: it is joint {n}'s axis, so q{n} is "
                        f"free, and [ik] free names {', '.join(f'q{i}' for i in named)}"
                    )
                    continue
                rest = None if named is None else tuple(i for i in named if i != n)
                ik, why = choose_pose(chain, structure, rest or None, names, n)
                if ik is not None:
                    return tasks.lower_spun(ik, chain, aimed), ""
                if why:
                    reasons.append(f"tool {tasks.AXES[axis]} axis: {why}")
                continue
            # (a pointing task: a look-at of the arm with every length 0, at the point d)
            arm = tasks.unmoved(chain) if task.kind == "pointing" else chain
            looks = dataclasses.replace(aimed, kind="lookat") if arm is not chain else aimed
            try:
                extended, snap = tasks.extend_snapped(arm, looks, tol)
            except NotApplicable as exc:
                reasons.append(f"tool {tasks.AXES[axis]} axis: {exc}")
                continue
            ik, why = choose_pose(extended, classify(extended), named, names, n + 1)
            if snap > 0.0:
                # the exact virtual link where its case is the snapped one's (no refinement:
                # a look-at camera 9e-6 m off its axis); the snapped one where snapping gives
                # a special case (a5 = 0: the exact a5 = 6e-7 left a degenerate quartic)
                exact = tasks.extend(arm, looks)
                exact_ik, _ = choose_pose(exact, classify(exact), named, names, n + 1)
                if (
                    exact_ik is not None
                    and (ik is None or exact_ik.case == ik.case)
                    and not tasks.far_link(arm, exact)
                ):
                    ik, extended, snap = exact_ik, exact, 0.0
            if ik is not None:
                return tasks.lower(ik, arm, extended, aimed, snap), ""
            if why:  # (the methods count the task's virtual joint among the arm's)
                reasons.append(f"tool {tasks.AXES[axis]} axis, with virtual joint {n + 1}: {why}")
        return None, "; ".join(reasons)
    if chain.dof > free.REMAINDER_DOF:
        return choose_free(chain, named, names)
    return choose_method(chain, structure, names)


def choose_cone(
    chain: Chain,
    structure: Structure,
    named: tuple[int, ...] | None,
    names: tuple[str, ...],
    task: tasks.Task,
    tol: float,
    method: str | None = None,
) -> tuple[IkPlan | None, str]:
    """The "axisangle" task's plan (derive/methods/cone.py) for the task's tool axis, else
    the first of z, x, y that works; where the joints chose the task, a method of the arm's
    own first."""
    if task.why != NAMED:
        ik, why = choose(chain, structure, named, names)
        if ik is not None:
            return ik, why
    if method is not None:  # ([ik] method or --method: that method only)
        return None, (
            f"the {task.kind} task's method is the cone (derive/methods/cone.py), and the "
            f"method named is {method}"
        )
    if general.NAME in names:  # (the general round: the closed forms' round tried the cone)
        return None, ""
    reasons = []
    for axis in (task.axis,) if task.fixed else tasks.axis_order(chain, tol):
        try:
            return cone.derive(chain, axis, task.cone, tol), ""
        except NotApplicable as exc:
            reasons.append(f"tool {tasks.AXES[axis]} axis: {exc}")
    return None, "; ".join(reasons)


# how far the nominal solver's equations may miss, relative, and still seed a refinement, in
# units of the nominal arm's deviation (an acos argument of a short link misses by more than
# the deviation: it is a ratio of lengths), and at most
SEED_FACTOR = 100.0
SEED_MAX = 0.1


# the most solutions of a 6R arm's pose (a general one's: Lee and Liang, Raghavan and Roth)
GENERAL_MOST = 16
# a table within this of its exact frames (rounding) needs no refinement
EXACT_ENOUGH = 1e-13
# a nominal table farther than this from the arm (forward kinematics: rotation entries,
# positions over the reach) is not refined from: its seeds need not reach the arm's
# solutions (calibrations move an arm by about 1e-3, a URDF's rounding by 1e-5)
NOMINAL_MAX = 1e-2


def snapped_task(
    correction: Correction | None,
    ik: IkPlan,
    dh: tuple[tuple[float, float, float, float], ...],
    tol: float,
) -> Correction:
    """The correction of a task whose virtual link was snapped (derive/tasks.py): the closed
    form solves the snapped extended arm, whose answers miss the arm's task by about the snap,
    so they are refined onto the arm's exact chain (with its nominal table's, where it has
    one)."""
    change = f"the virtual link of the task, by {ik.task_snap:.3g} (rad, or of the arm's size)"
    if correction is None:
        correction = Correction(dh, (), tol, 0.0, 0.0)
    deviation = max(correction.deviation, ik.task_snap)
    return dataclasses.replace(
        correction,
        changes=(*correction.changes, change),
        deviation=deviation,
        seed_tol=min(SEED_MAX, max(1e-9, SEED_FACTOR * deviation)),
    )


def make_correction(
    near: Nominal, near_chain: Chain, frames: tuple[tuple[float, ...], ...], reach: float
) -> Correction:
    """How the nominal table's answers are refined onto the exact frames (derive/nominal.py);
    positions are compared over the arm's reach (its own table's: a nominal table with two
    axes snapped parallel keeps their far common normal's offsets, which link_size then no
    longer sums first)."""
    info = arm_info(near.spec, near_chain)
    moved = deviation(frames, chain_frames(near_chain), near.spec.joint_types, reach)
    return Correction(
        nominal_dh=info.dh,
        changes=near.changes,
        tol=near.tol,
        deviation=moved,
        seed_tol=min(SEED_MAX, max(1e-9, SEED_FACTOR * moved)),
    )


def choose_method(
    chain: Chain, structure: Structure, names: tuple[str, ...]
) -> tuple[IkPlan | None, str]:
    """The first of the named methods that applies, or None and the reasons none does."""
    if structure.coincident:
        i = structure.coincident[0]
        return None, f"axes {i} and {i + 1} coincide: the arm has a redundant joint"
    reasons = []
    for name in names:
        result = METHODS[name](chain, structure)
        if isinstance(result, IkPlan):
            return result, ""
        reasons.append(result)
    return None, "; ".join(reasons)


def choose_pose(
    chain: Chain,
    structure: Structure,
    named: tuple[int, ...] | None,
    names: tuple[str, ...],
    reserved: int,
) -> tuple[IkPlan | None, str]:
    """The pose problem of a task's chain (joint reserved is the task's virtual joint, or
    the arm's joint that plays it), with free joints where it has more than 6, never the
    reserved one."""
    if chain.dof > free.REMAINDER_DOF:
        return choose_free(chain, named, names, reserved)
    return choose_method(chain, structure, names)


def choose_free(
    chain: Chain,
    named: tuple[int, ...] | None,
    names: tuple[str, ...],
    reserved: int | None = None,
    size: int = free.REMAINDER_DOF,
) -> tuple[IkPlan | None, str]:
    """For an arm of more than 6 joints (more than 3 solved for the tool point's position,
    `size` 3): the first method that solves the remainder of one of the free-joint choices
    (the spec's, else end joints; every closed form on every choice before the general
    method; never the reserved joint: a task's virtual one), lifted to the arm; or None and
    why none does."""
    reasons: list[str] = []
    usable = []
    if not names:  # (the position method is not among those asked for)
        return None, ""
    if named is not None and chain.dof - len(named) != size:
        return None, (
            f"[ik] free names {len(named)} joints; {chain.dof - size} must be free for "
            f"{size} to be solved"
        )
    choices = free.candidates(chain, named, size)
    if reserved is not None:
        if named is not None and reserved in named:
            return None, f"[ik] free names q{reserved}, which the task needs"
        choices = tuple(c for c in choices if reserved not in c)
        if not choices:
            return None, (
                f"the end joints that could be free leave joint {reserved} (the task's) "
                "in the middle"
            )
    for choice in choices:
        label = "free " + ", ".join(f"q{i}" for i in choice)
        why = free.refusal(chain, choice, size)
        if why:
            reasons.append(f"{label}: {why}")
            continue
        rest = free.remainder(chain, choice)
        structure = classify(rest)
        if structure.coincident:
            i = structure.coincident[0]
            reasons.append(
                f"{label}: the remainder loses a degree of freedom (its axes {i} and {i + 1} "
                "coincide)"
            )
            continue
        usable.append((choice, label, rest, structure))
    if size < free.REMAINDER_DOF and named is None:  # (the position: the joints that move
        # the tool point most are solved, the others free: free.position_span)
        usable.sort(key=lambda u: -free.position_span(chain, u[0]))
    for name in names:
        for choice, label, rest, structure in usable:
            result = METHODS[name](rest, structure)
            if isinstance(result, IkPlan):
                return free.lift(result, chain, choice), ""
            reasons.append(f"{label}: {result}")
    return None, "; ".join(reasons)


def relabelled(
    pose: sp.Matrix,
    joint_defs: tuple[tuple[sp.Symbol, sp.Expr], ...],
    chain: Chain,
    shift: sp.Expr,
) -> tuple[sp.Matrix, tuple[tuple[sp.Symbol, sp.Expr], ...]]:
    """The forward kinematics and joint definitions in the steps' variable of joint n, which
    exceeds the arm's by shift (a task's virtual joint moves joint n's frame: derive/tasks.py):
    theta_n = q_n + offset + shift, and the pose's c_n, s_n those of theta_n - shift (d_n
    - shift for a prismatic joint)."""
    n = chain.dof
    target, expr = joint_defs[-1]
    moved = sym.q(n) + sp.Float(float(expr.subs(sym.q(n), 0) + shift), 17)
    return in_steps_variable(pose, chain, shift), (*joint_defs[:-1], (target, moved))


def in_steps_variable(matrix: sp.Matrix, chain: Chain, shift: sp.Expr) -> sp.Matrix:
    """A matrix in the arm's joint n symbols rewritten in the steps' (relabelled's): c_n, s_n
    of theta_n - shift (d_n - shift for a prismatic joint)."""
    n = chain.dof
    if chain.joints[-1].kind == "R":
        cs, ss = sp.cos(shift), sp.sin(shift)
        if not (cs.is_Rational and ss.is_Rational):
            cs, ss = sp.Float(float(cs), 17), sp.Float(float(ss), 17)
        c, s = sym.c(n), sym.s(n)
        return matrix.xreplace({c: c * cs + s * ss, s: s * cs - c * ss})
    return matrix.xreplace({sym.d(n): sym.d(n) - shift})


def joint_definitions(chain: Chain) -> tuple[tuple[sp.Symbol, sp.Expr], ...]:
    """theta_i = q_i + offset (R) or d_i = q_i + offset (P), offsets as floats."""
    defs = []
    for j in chain.joints:
        target = sym.theta(j.index) if j.kind == "R" else sym.d(j.index)
        offset = sp.Float(float(j.offset), 17) if j.offset != 0 else sp.Integer(0)
        defs.append((target, sym.q(j.index) + offset))
    return tuple(defs)


def arm_info(spec: ArmSpec, chain: Chain) -> ArmInfo:
    """Numeric facts about the arm for the generated module."""
    to_rad = math.radians if spec.angle_unit == "deg" else float
    dh = tuple((to_rad(j.alpha), j.a, j.d, to_rad(j.theta)) for j in spec.joints)
    limits = []
    for j in spec.joints:
        if j.limits is None:
            limits.append((-math.inf, math.inf))
        elif j.kind == "R":
            limits.append((to_rad(j.limits[0]), to_rad(j.limits[1])))
        else:
            limits.append(j.limits)
    reach = link_size(spec)  # (|a| + |d|, nearly parallel axes' offsets summed first)
    reach += sum(
        max(abs(lo), abs(hi))
        for (lo, hi), j in zip(limits, spec.joints)
        if j.kind == "P" and math.isfinite(lo) and math.isfinite(hi)
    )
    for frame in (chain.base, chain.tool):
        reach += sum(abs(float(v)) for v in frame[:3, 3])
    example_q = None
    example_pose = None
    if spec.example_pose is not None:
        example_pose = tuple(float(v) for v in frame_matrix(spec.example_pose, spec.angle_unit))
    else:
        values = spec.example_q or tuple(20.0 if j.kind == "R" else 0.0 for j in spec.joints)
        example_q = tuple(to_rad(v) if j.kind == "R" else v for v, j in zip(values, spec.joints))
    return ArmInfo(
        name=spec.name,
        digest=spec.digest(),
        convention=spec.convention,
        angle_unit=spec.angle_unit,
        length_unit=spec.length_unit,
        joint_types=spec.joint_types,
        dh=dh,
        limits=tuple(limits),
        base=tuple(float(v) for v in chain.base),
        tool=tuple(float(v) for v in chain.tool),
        reach=max(reach, 1e-12),
        example_q=example_q,
        example_pose=example_pose,
        origin=spec.origin,
    )
