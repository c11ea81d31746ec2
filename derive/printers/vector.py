"""The numpy batch solver's printer: _ik_candidates's body, one array axis per Solve step.

Broadcasting does the branching and flattening the axes gives the scalar solver's loop order.
Each Solve kind has one function here (SOLVES) that prints the call giving the joint's values
along its axis, their validity and where the joint was free.
"""

from __future__ import annotations

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
    assign_lines,
    cs_arguments,
    live_steps,
    match_expression,
    same_joints,
    step_arguments,
    world_names,
)

# Solve kind -> the call, from the step, its printed arguments, reference value,
# free-polynomial threshold and array axis
SolvePrinter = Callable[[Solve, str, str, str, int], str]
SOLVES: dict[type[Solve], SolvePrinter] = {
    Poly: lambda step, args, ref, free, axis: (
        f"_vpoly(({args},), {axis}, valid, True, {ref}, {free})"
    ),
    PolyD: lambda step, args, ref, free, axis: (
        f"_vpoly(({args},), {axis}, valid, False, {ref}, {free}, {step.unit!r})"
    ),
    Cs1: lambda step, args, ref, free, axis: f"_vcs1({args}, {step.scale!r}, {ref}, {axis}, valid)",
    Cs1Reach: lambda step, args, ref, free, axis: (
        f"_vcs1_reach({args}, {step.scale!r}, {ref}, {axis}, valid)"
    ),
    Cs2: lambda step, args, ref, free, axis: f"_vcs2({args}, {ref}, {axis}, valid)",
    Cs2Reach: lambda step, args, ref, free, axis: f"_vcs2_reach({args}, {ref}, {axis}, valid)",
    Atan2: lambda step, args, ref, free, axis: f"_vatan2({args}, {ref}, {axis}, valid)",
    # one eigenproblem per pose: every pose goes to the scalar solver
    Eigen: lambda step, args, ref, free, axis: "_vdefer(T.shape[0], DOF)",
}


def ik_batch_lines(plan: Plan) -> tuple[str, ...]:
    """Body of the vectorised IK: one array axis per Solve step, validity combined, every
    branch certified by forward kinematics."""
    assert plan.ik is not None
    for step in plan.ik.steps:
        if isinstance(step, Eigen):
            return (
                f"# {step.note}: one eigenproblem per pose, in the scalar solver",
                f"return {SOLVES[Eigen](step, '', '', '', 0)}",
            )
    printer = CodePrinter("np.")
    names = sp.numbered_symbols("x")
    steps, _ = live_steps(plan)
    solves = [live for live in steps if isinstance(live.step, Solve)]
    lines = [f"shape = (T.shape[0],) + (1,) * {len(solves)}"]
    world = sym.world_pose()
    lines += [f"{world[i, j]} = T[:, {i}, {j}].reshape(shape)" for i in range(3) for j in range(4)]
    lines.append("valid = np.ones(shape, dtype=bool)")
    # a free joint's value may differ per pose (ik_batch's free)
    lines += [f"qr{j} = _vshape(qr{j}, shape)" for j in plan.ik.free]
    level = 0
    for live in steps:
        step = live.step
        if isinstance(step, Assign):
            lines.append(f"# {step.note}")
            lines += [
                ln.text
                for ln in assign_lines(step.targets, step.exprs, names, printer, 0, live.after)
            ]
            continue
        level += 1
        lines += solve_lines(step, live.after, names, printer, level)
    outputs = ", ".join(
        f"np.broadcast_to({printer.doprint(e)}, valid.shape)" for e in plan.ik.outputs
    )
    lines.append(f"Q = np.stack(({outputs}), axis=-1)")
    if same_joints(plan):
        lines.append(f"e = _fk_from_cs({cs_arguments(plan)})")
    else:
        lines.append("e = _fk_from_cs(*_cs_columns(Q))")
    lines.append("Q = Q.reshape(T.shape[0], -1, DOF)")
    lines.append(f"t = ({', '.join(world_names())})")
    lines.append("ptol = tol * REACH")
    lines.append(f"valid = valid & {match_expression(plan.ik.certify, vector=True)}")
    # a free joint's first value without a certified solution below it: the scalar solver,
    # which tries further values, settles that pose
    lines.append("retry = np.zeros(T.shape[0], dtype=bool)")
    for k in range(1, level + 1):
        rest = tuple(range(k + 1, level + 1))
        below = f"valid.any(axis={rest}, keepdims=True)" if rest else "valid"
        lines.append(f"retry |= (free{k} & ~{below}).reshape(T.shape[0], -1).any(axis=1)")
    lines.append("return Q, valid.reshape(T.shape[0], -1), retry")
    return tuple(lines)


def solve_lines(
    step: Solve,
    after: frozenset[str],
    names: sp.utilities.iterables.numbered_symbols,
    printer: CodePrinter,
    level: int,
) -> list[str]:
    """One Solve step of the vectorised IK: its values along axis `level`, validity combined,
    and the cos and sin of an angle where later steps read them."""
    head, values = step_arguments(step, names, printer, 0)
    lines = [ln.text for ln in head]
    call = SOLVES[type(step)](
        step, ", ".join(values), printer.doprint(step.ref), repr(1e-10 * step.scale), level
    )
    lines += [
        f"{step.variable}, ok, free{level} = {call}",
        "valid = valid & ok",
        f"free{level} = free{level} & valid",
    ]
    j = step.joint
    for name, function in ((f"c{j}", "np.cos"), (f"s{j}", "np.sin")):
        if step.angle and name in after:
            lines.append(f"{name} = {function}({step.variable})")
    return lines
