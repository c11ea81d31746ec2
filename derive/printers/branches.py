"""The branch of a solution, as straight-line code both printers print (the Python module's
_branch_signs, scalar.branch_lines; the C file's <name>_branch, c.branch_lines).

A step that gives several values of its joint gives them as the roots of one equation; the
sign of the equation's derivative at a root names the root's branch, and changes only where
two roots meet (a fold). The branch of a joint vector q of its own pose is found by the
solver's steps in a straight line, each joint's value read from q instead of solved, and the
sign taken at each branching step (branch_steps). This module builds that program once, in
SymPy (its common subexpressions eliminated, the lines nothing reads dropped); the printers
only spell it.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from derive import symbols as sym
from derive.plan import Assign, Cs1, Cs1Reach, Cs1Unit, Eigen, Plan, Poly, PolyD, PolyPi, Solve
from derive.printers.common import live_steps, read_pairs, world_names

# the Solve kinds whose several values have a branch each (their sign functions: the
# runtimes' _cs1_branch, _poly_branch, _polyd_branch and dk_..._branch)
BRANCHING: tuple[type[Solve], ...] = (Cs1, Cs1Unit, Cs1Reach, Poly, PolyPi, PolyD)


@dataclass(frozen=True)
class Sign:
    """The branch of variable among the values of step's equation, whose arguments are args
    (the step's own, reduced by the common subexpressions before them; a cos + b sin = e's
    a and b only: its sign does not read e)."""

    step: Solve
    args: tuple[sp.Expr, ...]
    variable: str


@dataclass(frozen=True)
class First:
    """The first value the step solves (a task's virtual joint that has one value: its
    arguments reduced as Sign's)."""

    step: Solve
    args: tuple[sp.Expr, ...]


@dataclass(frozen=True)
class BranchProgram:
    """target = value lines in order (value an expression, a Sign or a First), the names of
    the signs returned, and the world pose's entries and the joint values (qr1, ...) read."""

    lines: tuple[tuple[str, sp.Expr | Sign | First], ...]
    signs: tuple[str, ...]
    world: tuple[str, ...]
    joints: tuple[str, ...]


def branch_steps(plan: Plan) -> tuple[Solve, ...] | None:
    """The steps that choose a branch (a Solve of more than one value, of a kind in
    BRANCHING), or None where a joint vector alone cannot say which branch it is on: a step
    before one of them gives several values of something that is neither one of the arm's
    joints nor the task's virtual value on q's pose (IkPlan.virtual: the axis-angle task's
    tilt; not a look-at's distance, which is the point's, not q's), or one step solves all
    joints at once (the general method). A step giving one value of a task's virtual joint is
    solved as the solver does (First)."""
    assert plan.ik is not None
    out = []
    unknown = False  # (a value not a joint's solved before: later steps may read it)
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            continue
        if isinstance(step, Eigen):
            return None
        branching = type(step) in BRANCHING and step.fanout > 1
        if from_joints(plan, step) is not None or virtual_value(plan, step) is not None:
            if branching and unknown:
                return None
            if branching:
                out.append(step)
        elif branching:  # (a value not a joint's: which of its values, q cannot say)
            unknown = True
    return tuple(out)


def virtual_value(plan: Plan, step: Solve) -> sp.Expr | None:
    """A branching step's value that is not a joint's but the task's virtual or auxiliary
    one (IkPlan.virtual: its cos and sin, or its length, on a solution's branch, in the world
    pose's entries and the joints' c_i, s_i, d_i); None where the plan has none or numbers
    the steps' joints otherwise than the arm's (a reversed chain)."""
    assert plan.ik is not None
    if not plan.ik.virtual or step.joint <= plan.arm.dof or not _arm_numbering(plan):
        return None
    if plan.ik.certify == "lookat":  # (the distance to the point looked at: not in q's pose)
        return None
    parts = plan.ik.virtual
    return sp.atan2(parts[1], parts[0], evaluate=False) if len(parts) == 2 else parts[0]


def _arm_numbering(plan: Plan) -> bool:
    """Whether the plan's theta_i / d_i are the arm's joint i (same_joints), a free joint's
    output being the caller's value qr_i (its theta_i is still q_i's): not a reversed chain."""
    assert plan.ik is not None
    for i, ((target, _), out) in enumerate(zip(plan.joint_defs, plan.ik.outputs), start=1):
        given = out.free_symbols == {sp.Symbol(f"qr{i}", real=True)} or out.free_symbols == {
            sp.Symbol(f"qr{i}")
        }
        if not given and (out.free_symbols != {target} or out.coeff(target) != 1):
            return False
    return True


def from_joints(plan: Plan, step: Solve) -> sp.Expr | None:
    """The step's value as an expression in the joint values qr_i: the inverse of the one
    output q_i = +-value + constant that reads it, or None where no output is such."""
    assert plan.ik is not None
    value = sp.Symbol(step.variable, real=True)
    for i, out in enumerate(plan.ik.outputs, start=1):
        if out.free_symbols != {value}:
            continue
        k = out.coeff(value)
        rest = sp.expand(out - k * value)
        if k in (1, -1) and not rest.free_symbols:
            return (sp.Symbol(f"qr{i}", real=True) - rest) / k
    return None


def _joint_pairs(plan: Plan) -> list[tuple[str, sp.Expr]]:
    """Every joint's c_i, s_i (or d_i) from q (the plan's joint definitions), for a virtual
    value's expression: the program keeps only those it reads."""
    out: list[tuple[str, sp.Expr]] = []
    qr = {sym.q(i + 1): sp.Symbol(f"qr{i + 1}") for i in range(plan.arm.dof)}
    for k, (target, expr) in enumerate(plan.joint_defs, start=1):
        value = expr.xreplace(qr)
        if str(target).startswith("theta"):
            out.append((f"c{k}", sp.cos(value, evaluate=False)))
            out.append((f"s{k}", sp.sin(value, evaluate=False)))
        else:
            out.append((str(target), value))
    return out


def _reduced(
    exprs: tuple[sp.Expr, ...], names: sp.utilities.iterables.numbered_symbols
) -> tuple[list[tuple[str, sp.Expr]], tuple[sp.Expr, ...]]:
    temps, reduced = sp.cse(list(exprs), symbols=names, order="canonical")
    return [(str(t), e) for t, e in temps], tuple(reduced)


def branch_program(plan: Plan) -> BranchProgram | None:
    """The straight line from q's pose and q to the signs of branch_steps, or None where it
    is None or empty."""
    chosen = branch_steps(plan)
    if not chosen:
        return None
    names = sp.numbered_symbols("x")
    steps, _ = live_steps(plan)
    lines: list[tuple[str, sp.Expr | Sign | First]] = []
    signs: list[str] = []
    for live in steps:
        step = live.step
        if len(signs) == len(chosen):
            break  # (nothing after the last branching step is read)
        if isinstance(step, Assign):
            temps, reduced = sp.cse(list(step.exprs), symbols=names, order="canonical")
            pairs = read_pairs([*temps, *zip(step.targets, reduced)], set(live.after))
            lines += [(str(t), e) for t, e in pairs]
            continue
        assert isinstance(step, Solve)
        value = from_joints(plan, step)
        virtual = virtual_value(plan, step) if value is None else None
        if virtual is not None and any(step is c for c in chosen):  # (its value on q's branch)
            lines += _joint_pairs(plan)
            lines.append((step.variable, virtual))
        elif value is None:  # (a task's virtual joint: its one value, solved)
            temps, args = _reduced(tuple(step.args), names)
            lines += [*temps, (step.variable, First(step, args))]
        else:
            lines.append((step.variable, value))
        if any(step is c for c in chosen):
            temps, args = _reduced(tuple(step.args), names)
            if isinstance(step, (Cs1, Cs1Reach)):  # (a cos t + b sin t = e: the sign reads a, b)
                args = args[:2]
            lines += [*temps, (f"_b{len(signs)}", Sign(step, args, step.variable))]
            signs.append(f"_b{len(signs)}")
        for name, function in ((f"c{step.joint}", sp.cos), (f"s{step.joint}", sp.sin)):
            if step.angle and name in live.after:
                lines.append((name, function(sp.Symbol(step.variable, real=True), evaluate=False)))
    kept = _read(lines, set(signs))
    read = {name for _, value in kept for name in _names(value)}
    qr = [f"qr{i}" for i in range(1, plan.arm.dof + 1)]
    return BranchProgram(
        lines=tuple(kept),
        signs=tuple(signs),
        world=tuple(name if name in read else "" for name in world_names()),
        joints=tuple(name if name in read else "" for name in qr),
    )


def _names(value: sp.Expr | Sign | First) -> set[str]:
    """The names a line's value reads."""
    if isinstance(value, Sign):
        exprs = (*value.args, sp.Symbol(value.variable))
    elif isinstance(value, First):
        exprs = (*value.args, value.step.ref)
    else:
        exprs = (value,)
    return {str(s) for e in exprs for s in sp.sympify(e).free_symbols}


def _read(
    lines: list[tuple[str, sp.Expr | Sign | First]], needed: set[str]
) -> list[tuple[str, sp.Expr | Sign | First]]:
    """The lines whose target is needed, directly or through later lines, in their order."""
    kept = []
    for target, value in reversed(lines):
        if target in needed:
            kept.append((target, value))
            needed |= _names(value)
    return kept[::-1]


# BRANCHES where the closed form names no branch and branch(q) is the sign of the Jacobian's
# determinant (jacobian_branch)
JACOBIAN_BRANCH = "det J"


def jacobian_branch(plan: Plan) -> bool:
    """Whether a solution's branch is the sign of det J over the joints the pose fixes (the
    runtimes' _jacobian_sign, dk_det_sign): where no step of the solve names one (the
    general method solves all joints at once) and the arm is solved for the whole pose with
    six joints not free, so that J over them is square. det J changes sign only where a path
    of solutions crosses a singular configuration, so two solutions of opposite signs are on
    different branches (the converse need not hold: a 6R arm has up to 16 solutions and
    det J two signs)."""
    assert plan.ik is not None
    return (
        not branch_steps(plan)
        and plan.ik.certify == "pose"
        and plan.arm.dof - len(plan.ik.free) == 6
    )


def branch_names(plan: Plan) -> tuple[str, ...]:
    """The arm's joints whose steps choose a branch (BRANCHES in the module: "q3", ...), in
    the order they are solved (a reversed chain's theta_k is another joint of the arm); or
    (JACOBIAN_BRANCH,) where the branch is det J's sign (jacobian_branch)."""
    if jacobian_branch(plan):
        return (JACOBIAN_BRANCH,)
    out = []
    for step in branch_steps(plan) or ():
        value = from_joints(plan, step)
        if value is None:  # (the task's virtual or auxiliary value: IkPlan.virtual)
            out.append("virtual")
            continue
        (joint,) = value.free_symbols
        out.append(f"q{str(joint)[2:]}")
    return tuple(out)
