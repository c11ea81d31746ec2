"""The Python solver's printer: _ik_scalar's body, one loop per Solve step.

Each Solve kind has one function here (SOLVES) that prints the call giving the joint's values;
the loop over them, the cos and sin later steps read, and the break after a free joint's first
value that gave a solution are the same for every kind.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import sympy as sp

from derive import symbols as sym
from derive.plan import (
    Assign,
    Atan2,
    Cs1,
    Cs1Reach,
    Cs2,
    Cs2Reach,
    Eigen,
    Plan,
    Poly,
    PolyD,
    Solve,
)
from derive.printers.common import (
    CodePrinter,
    Line,
    assign_lines,
    cs_arguments,
    live_steps,
    same_joints,
    step_arguments,
)

# Solve kind -> the call giving the joint's values, from the step and its printed arguments,
# reference value and free-polynomial threshold
SolvePrinter = Callable[[Solve, str, str, str], str]
SOLVES: dict[type[Solve], SolvePrinter] = {
    Poly: lambda step, args, ref, free: f"_poly_angles(({args},), {ref}, {free})",
    PolyD: lambda step, args, ref, free: f"_poly_real(({args},), {ref}, {free}, {step.unit!r})",
    Cs1: lambda step, args, ref, free: f"_cs1({args}, {step.scale!r}, {ref})",
    Cs1Reach: lambda step, args, ref, free: f"_cs1_reach({args}, {step.scale!r}, {ref})",
    Cs2: lambda step, args, ref, free: f"_cs2({args}, {ref})",
    Cs2Reach: lambda step, args, ref, free: f"_cs2_reach({args}, {ref})",
    Atan2: lambda step, args, ref, free: f"_atan2({args}, {ref})",
    Eigen: lambda step, args, ref, free: f"_general(({args},), tol)",
}


def ik_lines(plan: Plan) -> tuple[tuple[int, str], ...]:
    """Body of the scalar IK: one block per step, each Solve opening a loop over its values."""
    assert plan.ik is not None
    printer = CodePrinter()
    names = sp.numbered_symbols("x")
    lines: list[Line] = []
    depth = 0
    loops = []
    steps, inputs = live_steps(plan)
    world = ", ".join(name if name in inputs else "_" for name in WORLD)
    lines.append(Line(0, f"({world}) = target"))
    lines.append(Line(0, "found = []"))
    for live in steps:
        step = live.step
        if isinstance(step, Assign):
            lines.append(Line(depth, f"# {step.note}"))
            lines += assign_lines(step.targets, step.exprs, names, printer, depth, live.after)
            continue
        lines += solve_lines(step, live.after, names, printer, depth)
        if not isinstance(step, Eigen):  # it gives every joint: no free joint to step
            loops.append((depth, step.joint))
        depth += 1
    outputs = ", ".join(printer.doprint(e) for e in plan.ik.outputs)
    if plan.correction is not None:  # refined onto the exact chain, certified there
        lines.append(Line(depth, f"_seed(found, target, ({outputs},), tol)"))
    elif same_joints(plan):
        fk = f"_fk_from_cs({cs_arguments(plan)})"
        lines.append(Line(depth, f"_keep(found, target, ({outputs},), {fk}, tol)"))
    else:
        lines.append(Line(depth, f"q = ({outputs},)"))
        lines.append(Line(depth, "_keep(found, target, q, _fk_q(q), tol)"))
    for level, joint in reversed(loops):
        # a free joint's loop (over _Free values) ends at its first value that gave a solution
        lines.append(
            Line(level + 1, f"if _v{joint}.__class__ is _Free and len(found) > _n{joint}:")
        )
        lines.append(Line(level + 2, "break"))
    lines.append(Line(0, "return found"))
    return tuple((ln.depth, ln.text) for ln in lines)


WORLD = ("w11", "w12", "w13", "wx", "w21", "w22", "w23", "wy", "w31", "w32", "w33", "wz")


def solve_lines(
    step: Solve,
    after: frozenset[str],
    names: sp.utilities.iterables.numbered_symbols,
    printer: CodePrinter,
    depth: int,
) -> list[Line]:
    """The loop header of one Solve step, with its arguments CSE'd before it, and the cos
    and sin of an angle where later steps read them."""
    lines, values = step_arguments(step, names, printer, depth)
    if isinstance(step, Eigen):
        # the splits' flange targets, 12 entries each
        groups = [values[k : k + 12] for k in range(0, len(values), 12)]
        call = SOLVES[Eigen](step, ", ".join(f"({', '.join(g)})" for g in groups), "", "")
        lines.append(Line(depth, f"for {', '.join(step.variables)} in {call}:"))
        for k, variable in zip(step.indices, step.variables):
            for name, function in ((f"c{k}", "cos"), (f"s{k}", "sin")):
                if name in after and variable.startswith("theta"):
                    lines.append(Line(depth + 1, f"{name} = {function}({variable})"))
        return lines
    call = SOLVES[type(step)](
        step, ", ".join(values), printer.doprint(step.ref), repr(1e-10 * step.scale)
    )
    j = step.joint
    lines.append(Line(depth, f"_n{j} = len(found)"))
    lines.append(Line(depth, f"for {step.variable} in (_v{j} := {call}):"))
    for name, function in ((f"c{j}", "cos"), (f"s{j}", "sin")):
        if step.angle and name in after:
            lines.append(Line(depth + 1, f"{name} = {function}({step.variable})"))
    return lines


# Solve kind -> the call giving the branch of the step's value (derive/runtime/scalar.py): the
# sign of its equation's derivative in the joint's value; kinds that give one value have none
BRANCHES: dict[type[Solve], Callable[[Solve, list[str]], str]] = {
    Cs1: lambda step, values: f"_cs1_branch({values[0]}, {values[1]}, {step.variable})",
    Cs1Reach: lambda step, values: f"_cs1_branch({values[0]}, {values[1]}, {step.variable})",
    Poly: lambda step, values: f"_poly_branch(({', '.join(values)},), {step.variable})",
    PolyD: lambda step, values: f"_polyd_branch(({', '.join(values)},), {step.variable})",
}


def branch_steps(plan: Plan) -> tuple[Solve, ...] | None:
    """The steps that choose a branch (a Solve of more than one value, of a kind in BRANCHES),
    or None where a joint vector alone cannot say which branch it is on: a step before one of
    them gives several values of something that is neither one of the arm's joints nor the
    task's virtual value on q's pose (IkPlan.virtual: the axis-angle task's tilt; not a
    look-at's distance, which is the point's, not q's), or one step solves all joints at
    once (the general method). A step giving one value of a task's virtual joint is solved
    as the solver does (branch_lines)."""
    assert plan.ik is not None
    out = []
    unknown = False  # (a value not a joint's solved before: later steps may read it)
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            continue
        if isinstance(step, Eigen):
            return None
        branching = type(step) in BRANCHES and step.fanout > 1
        if _from_joints(plan, step) is not None or _virtual(plan, step) is not None:
            if branching and unknown:
                return None
            if branching:
                out.append(step)
        elif branching:  # (a value not a joint's: which of its values, q cannot say)
            unknown = True
    return tuple(out)


def _virtual(plan: Plan, step: Solve) -> str | None:
    """A branching step's value that is not a joint's but the task's virtual or auxiliary
    one (IkPlan.virtual: its cos and sin, or its length, on a solution's branch, in the world
    pose's entries and the joints' c_i, s_i, d_i), printed; None where the plan has none or
    numbers the steps' joints otherwise than the arm's (a reversed chain)."""
    assert plan.ik is not None
    if not plan.ik.virtual or step.joint <= plan.arm.dof or not same_joints(plan):
        return None
    if plan.ik.certify == "lookat":  # (the distance to the point looked at: not in q's pose)
        return None
    printer = CodePrinter()
    parts = [printer.doprint(e) for e in plan.ik.virtual]
    return f"atan2({parts[1]}, {parts[0]})" if len(parts) == 2 else parts[0]


def _joint_lines(plan: Plan) -> list[Line]:
    """Every joint's theta_i (c_i, s_i) or d_i from q (the plan's joint definitions), for a
    virtual value's expression: the straight line's later lines keep only those it reads."""
    printer = CodePrinter()
    out = []
    for k, (target, expr) in enumerate(plan.joint_defs, start=1):
        value = printer.doprint(
            expr.xreplace({sym.q(i + 1): sp.Symbol(f"qr{i + 1}") for i in range(plan.arm.dof)})
        )
        if str(target).startswith("theta"):
            out += [Line(0, f"c{k} = cos({value})"), Line(0, f"s{k} = sin({value})")]
        else:
            out.append(Line(0, f"{target} = {value}"))
    return out


def _from_joints(plan: Plan, step: Solve) -> sp.Expr | None:
    """The step's value as an expression in the joint values q_i: the inverse of the one
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


def branch_lines(plan: Plan) -> tuple[tuple[int, str], ...]:
    """Body of _branch_signs(target, q): the solver's steps in a straight line, each joint's
    value read from q instead of solved, and the branch of each step of branch_steps; a body
    returning () where branch_steps is None."""
    chosen = branch_steps(plan)
    if not chosen:
        return ((0, "return ()"),)
    printer = CodePrinter()
    names = sp.numbered_symbols("x")
    steps, _ = live_steps(plan)
    lines: list[Line] = []
    out: list[str] = []
    for live in steps:
        step = live.step
        if len(out) == len(chosen):
            break  # (nothing after the last branching step is read)
        if isinstance(step, Assign):
            lines += assign_lines(step.targets, step.exprs, names, printer, 0, live.after)
            continue
        assert isinstance(step, Solve)
        value = _from_joints(plan, step)
        virtual = _virtual(plan, step) if value is None else None
        if virtual is not None and any(step is c for c in chosen):  # (its value on q's branch)
            lines += _joint_lines(plan)
            lines.append(Line(0, f"{step.variable} = {virtual}"))
        elif value is None:  # (a task's virtual joint: its one value, solved)
            more, values = step_arguments(step, names, printer, 0)
            call = SOLVES[type(step)](
                step, ", ".join(values), printer.doprint(step.ref), repr(1e-10 * step.scale)
            )
            lines += more[1:]
            lines.append(Line(0, f"{step.variable} = {call}[0]"))
        else:
            lines.append(Line(0, f"{step.variable} = {printer.doprint(value)}"))
        if any(step is c for c in chosen):
            more, values = step_arguments(step, names, printer, 0)
            lines += more[1:]  # (the step's note is the solver's)
            lines.append(Line(0, f"_b{len(out)} = {BRANCHES[type(step)](step, values)}"))
            out.append(f"_b{len(out)}")
        for name, function in ((f"c{step.joint}", "cos"), (f"s{step.joint}", "sin")):
            if step.angle and name in live.after:
                lines.append(Line(0, f"{name} = {function}({step.variable})"))
    lines = _read_lines(lines, set(out))
    read = {name for ln in lines for name in _NAME.findall(ln.text.split(" = ", 1)[1])}
    world = ", ".join(name if name in read else "_" for name in WORLD)
    joints = ", ".join(
        name if name in read else "_" for name in _qr_names(plan).split(", ")
    )  # fmt: skip
    head = [Line(0, f"({world}) = target"), Line(0, f"({joints},) = q")]
    return tuple(
        (ln.depth, ln.text) for ln in [*head, *lines, Line(0, f"return ({', '.join(out)},)")]
    )


_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def _read_lines(lines: list[Line], needed: set[str]) -> list[Line]:
    """The assignment lines (name = expression) whose name is needed, directly or through
    later lines, in their order."""
    kept = []
    for line in reversed(lines):
        target, expr = line.text.split(" = ", 1)
        if target in needed:
            kept.append(line)
            needed |= set(_NAME.findall(expr))
    return kept[::-1]


def branch_names(plan: Plan) -> tuple[str, ...]:
    """The arm's joints whose steps choose a branch (BRANCHES in the module: "q3", ...), in
    the order they are solved (a reversed chain's theta_k is another joint of the arm)."""
    out = []
    for step in branch_steps(plan) or ():
        value = _from_joints(plan, step)
        if value is None:  # (the task's virtual or auxiliary value: IkPlan.virtual)
            out.append("virtual")
            continue
        (joint,) = value.free_symbols
        out.append(f"q{str(joint)[2:]}")
    return tuple(out)


def _qr_names(plan: Plan) -> str:
    return ", ".join(f"qr{i}" for i in range(1, plan.arm.dof + 1))
