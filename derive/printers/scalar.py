"""The Python solver's printer: _ik_scalar's body, one loop per Solve step.

Each Solve kind has one function here (SOLVES) that prints the call giving the joint's values;
the loop over them, the cos and sin later steps read, and the break after a free joint's first
value that gave a solution are the same for every kind.
"""

from __future__ import annotations

from collections.abc import Callable

import sympy as sp

from derive.plan import (
    Assign,
    Atan2,
    Cs1,
    Cs1Reach,
    Cs1Unit,
    Cs2,
    Cs2Reach,
    Eigen,
    Plan,
    Poly,
    PolyD,
    PolyPi,
    Solve,
)
from derive.printers.branches import First, Sign, branch_program, jacobian_branch
from derive.printers.common import (
    SPREAD_STEPS,
    CodePrinter,
    Line,
    assign_lines,
    condition_call,
    cs_arguments,
    held_joints,
    live_steps,
    same_joints,
    seed_conditions,
    step_arguments,
)


def _unit(step: Solve) -> str:
    """A polyd step's unit as Python: a number, or an expression in the step's inputs."""
    if isinstance(step.unit, sp.Expr):
        return CodePrinter().doprint(step.unit)
    return repr(step.unit)


# Solve kind -> the call giving the joint's values, from the step and its printed arguments,
# reference value and free-polynomial threshold
SolvePrinter = Callable[[Solve, str, str, str], str]
SOLVES: dict[type[Solve], SolvePrinter] = {
    Poly: lambda step, args, ref, free: f"_poly_angles(({args},), {ref}, {free})",
    PolyPi: lambda step, args, ref, free: f"_poly_angles_pi(({args},), {ref}, {free})",
    PolyD: lambda step, args, ref, free: f"_poly_real(({args},), {ref}, {free}, {_unit(step)})",
    Cs1: lambda step, args, ref, free: f"_cs1({args}, {step.scale!r}, {ref})",
    Cs1Unit: lambda step, args, ref, free: f"_cs1x({args}, {step.scale!r}, {ref})",
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
    # (a nominal acos step's miss: _seed_miss of the least condition of the steps before it)
    ups = seed_conditions(plan)
    conditioned = {j for joints in ups.values() for j in joints}
    world = ", ".join(name if name in inputs else "_" for name in WORLD)
    lines.append(Line(0, f"({world}) = target"))
    lines.append(Line(0, "found = []"))
    for live in steps:
        step = live.step
        if isinstance(step, Assign):
            lines.append(Line(depth, f"# {step.note}"))
            lines += assign_lines(step.targets, step.exprs, names, printer, depth, live.after)
            continue
        up = None
        if not isinstance(step, Eigen) and step.joint in ups:
            up = ", ".join(f"_u{j}" for j in ups[step.joint])
            up = f"min({up})" if len(ups[step.joint]) > 1 else up
        condition = not isinstance(step, Eigen) and step.joint in conditioned
        lines += solve_lines(step, live.after, names, printer, depth, up, condition)
        if not isinstance(step, Eigen):  # it gives every joint: no free joint to step
            loops.append((depth, step.joint))
        depth += 1
    outputs = ", ".join(printer.doprint(e) for e in plan.ik.outputs)
    # (the joints the pose left free: a refinement holds them first, a polish throughout)
    frees = "".join(f"(_v{j}, {i}), " for j, i in held_joints(plan))
    if plan.correction is not None:  # refined onto the exact chain, certified there
        lines.append(Line(depth, f"_seed(found, target, ({outputs},), tol, ({frees}))"))
    elif same_joints(plan):
        fk = f"_fk_from_cs({cs_arguments(plan)})"
        lines.append(Line(depth, f"_keep(found, target, ({outputs},), {fk}, tol, ({frees}))"))
    else:
        lines.append(Line(depth, f"q = ({outputs},)"))
        lines.append(Line(depth, f"_keep(found, target, q, _fk_q(q), tol, ({frees}))"))
    spread = {s.joint for s in plan.ik.steps if isinstance(s, SPREAD_STEPS)}
    for level, joint in reversed(loops):
        # a free joint's loop (over _Free values) ends at its first value that gave a solution
        lines.append(
            Line(level + 1, f"if _v{joint}.__class__ is _Free and len(found) > _n{joint}:")
        )
        lines.append(Line(level + 2, "break"))
        if plan.correction is not None and joint in spread:  # (a rough value gave no row:
            # the values around it too, _wrist_spread)
            check = f"_v{joint}.__class__ is _Spread and len(found) == _n{joint}"
            lines.append(Line(level + 1, f"if {check}:"))
            lines.append(Line(level + 2, f"_v{joint}.widen()"))
    lines.append(Line(0, "return found"))
    return tuple((ln.depth, ln.text) for ln in lines)


WORLD = ("w11", "w12", "w13", "wx", "w21", "w22", "w23", "wy", "w31", "w32", "w33", "wz")


def solve_lines(
    step: Solve,
    after: frozenset[str],
    names: sp.utilities.iterables.numbered_symbols,
    printer: CodePrinter,
    depth: int,
    up: str | None = None,
    condition: bool = False,
) -> list[Line]:
    """The loop header of one Solve step, with its arguments CSE'd before it, and the cos
    and sin of an angle where later steps read them; up: the least condition of the steps
    before an acos step (printed), and condition: whether a later one reads this step's
    (_u<joint>)."""
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
    if up is not None:  # (its miss on a nominal table: _seed_miss)
        call = f"{call[:-1]}, up={up})"
    j = step.joint
    if condition:
        lines.append(Line(depth, f"_u{j} = {condition_call(step, values, '_')}"))
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
    Cs1Unit: lambda step, values: f"_cs1_branch({values[0]}, {values[1]}, {step.variable})",
    Cs1Reach: lambda step, values: f"_cs1_branch({values[0]}, {values[1]}, {step.variable})",
    Poly: lambda step, values: f"_poly_branch(({', '.join(values)},), {step.variable})",
    PolyPi: lambda step, values: f"_poly_branch(({', '.join(values)},), {step.variable})",
    PolyD: lambda step, values: f"_polyd_branch(({', '.join(values)},), {step.variable})",
}


def branch_lines(plan: Plan) -> tuple[tuple[int, str], ...]:
    """Body of _branch_signs(target, q): the branch program (printers/branches.py) as Python,
    a body returning () where the arm has none."""
    program = branch_program(plan)
    if program is None:
        return ((0, "return (_jacobian_sign(q),)" if jacobian_branch(plan) else "return ()"),)
    printer = CodePrinter()
    world = ", ".join(name or "_" for name in program.world)
    joints = ", ".join(name or "_" for name in program.joints)
    lines = [(0, f"({world}) = target"), (0, f"({joints},) = q")]
    for target, value in program.lines:
        if isinstance(value, Sign):
            values = [printer.doprint(e) for e in value.args]
            lines.append((0, f"{target} = {BRANCHES[type(value.step)](value.step, values)}"))
        elif isinstance(value, First):
            step = value.step
            args = ", ".join(printer.doprint(e) for e in value.args)
            ref, tol = printer.doprint(step.ref), repr(1e-10 * step.scale)
            call = SOLVES[type(step)](step, args, ref, tol)
            lines.append((0, f"{target} = {call}[0]"))
        else:
            lines.append((0, f"{target} = {printer.doprint(value)}"))
    return (*lines, (0, f"return ({', '.join(program.signs)},)"))
