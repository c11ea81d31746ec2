"""The compiled kernel's solver for one pose, printed from the plan (the routines it
calls are in derive/runtime/kernel.py).

It follows the scalar solver's steps (emit.ik_lines) with fixed-size results, so that numba
can compile it: a Solve step gives a count and values and whether the joint is free; a root
the closed forms cannot settle, or a free joint without solution from its first value, makes
it return -1, and the scalar solver settles the pose.
"""

from __future__ import annotations

import math

import sympy as sp

from derive.plan import Assign, Plan, Solve
from derive.printing import (
    CodePrinter,
    Line,
    assign_lines,
    cs_arguments,
    match_expression,
    same_joints,
    step_arguments,
    world_names,
)


def kernel_lines(plan: Plan, printer: CodePrinter) -> tuple[tuple[tuple[int, str], ...], int]:
    """Body of _ksolve, the compiled kernel's solver for one pose: the scalar solver's steps
    with fixed-size results. A free joint takes its first value (from q_ref), as the scalar
    solver does; if no solution follows from it, or a root is one the closed forms cannot
    settle, the function returns -1 (the pose goes to the scalar solver, which tries the
    free joint's further values)."""
    assert plan.ik is not None
    names = sp.numbered_symbols("x")
    dof = plan.arm.dof
    lines = [
        Line(
            0,
            f"{', '.join(f'{v}{i}' for i in range(1, dof + 1))}, = ref[{k * dof}:{(k + 1) * dof}]",
        )
        for k, v in enumerate(("qr", "cr", "sr"))
    ]
    lines += [Line(0, "ptol = tol * REACH"), Line(0, "n = 0"), Line(0, f"t = ({world_names()})")]
    depth = 0
    checks: list[tuple[int, int]] = []
    buffer = 0
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            lines.append(Line(depth, f"# {step.note}"))
            lines += assign_lines(step.targets, step.exprs, names, printer, depth)
            continue
        lines += kernel_solve_lines(step, names, printer, depth, buffer)
        if step.kind in ("poly", "polyd"):
            buffer += poly_slots(len(step.args) - 1)
        checks.append((depth, step.joint))
        if step.kind in ("poly", "polyd", "cs1", "cs1r"):
            depth += 1
    outputs = [printer.doprint(e) for e in plan.ik.outputs]
    if same_joints(plan):
        lines.append(Line(depth, f"e = _fk_from_cs({cs_arguments(plan)})"))
    else:
        lines.append(Line(depth, f"e = _fk_q(({', '.join(outputs)},))"))
    lines.append(Line(depth, f"if {match_expression(plan.ik.certify)}:"))
    lines += [Line(depth + 1, f"found[n, {k}] = {v}") for k, v in enumerate(outputs)]
    lines.append(Line(depth + 1, "n += 1"))
    # a free joint whose first value gave no solution: the scalar solver tries the others
    for level, joint in sorted(checks, key=lambda c: -c[0]):
        lines.append(Line(level, f"if _f{joint} and n == _m{joint}:"))
        lines.append(Line(level + 1, "return -1"))
    lines.append(Line(0, "return n"))
    return tuple((ln.depth, ln.text) for ln in lines), max(buffer, 1)


def reference_tuple(dof: int) -> str:
    """_kreference's result: q, then the cosines and the sines of its values, as one tuple."""
    cosines, sines = (", ".join(f"{f}(q[{k}])" for k in range(dof)) for f in ("cos", "sin"))
    return f"q + ({cosines},) + ({sines},)"


def poly_slots(degree: int) -> int:
    """The scratch _kpoly takes for a polynomial of this degree (see its docstring)."""
    return 6 * degree + 1


def kernel_solve_lines(
    step: Solve,
    names: sp.utilities.iterables.numbered_symbols,
    printer: CodePrinter,
    depth: int,
    at: int,
) -> list[Line]:
    """One Solve step of _ksolve: its values (a loop for polynomials and a c + b s = e, one
    value otherwise), ref where the joint is free (_f{joint}), n marked before (_m{joint});
    a polynomial's values at buf[at:]."""
    lines, values = step_arguments(step, names, printer, depth)
    j = step.joint
    var = f"d{j}" if step.kind == "polyd" else f"theta{j}"
    ref = printer.doprint(step.ref)
    cos_ref, sin_ref = reference_cs(step.ref, printer)
    free = repr(1e-10 * step.scale)
    if step.kind in ("poly", "polyd"):
        angles = step.kind == "poly"
        unit = 1.0 if angles else step.unit
        d = len(values) - 1
        end = at + poly_slots(d)
        call = f"_kpoly(({', '.join(values)},), {angles}, {free}, {unit!r}, buf[{at}:{end}])"
        head = [
            f"_n{j} = {call}",
            f"_f{j} = _n{j} == -2",
            f"if _f{j}:",
            f"    _n{j} = 1",
            f"    buf[{at}] = {ref}",
        ]
        if angles:
            head += [f"    buf[{at + 4 * d + 1}], buf[{at + 5 * d + 1}] = {cos_ref}, {sin_ref}"]
        head += [
            f"elif _n{j} < 0:",
            "    return -1",
            f"_m{j} = n",
            f"for _k{j} in range(_n{j}):",
            f"    {var} = buf[{at} + _k{j}]",
        ]
        if angles:
            head += [
                f"    c{j} = buf[{at + 4 * d + 1} + _k{j}]",
                f"    s{j} = buf[{at + 5 * d + 1} + _k{j}]",
            ]
    elif step.kind in ("cs1", "cs1r"):
        call = (
            f"_kcs1({', '.join(values[:3])}, {step.scale!r})"
            if step.kind == "cs1"
            else f"_kcs1r({', '.join(values)}, {step.scale!r}, {ref})"
        )
        first, second = f"(_a{j}, _ac{j}, _as{j})", f"(_b{j}, _bc{j}, _bs{j})"
        head = [
            f"_n{j}, _a{j}, _ac{j}, _as{j}, _b{j}, _bc{j}, _bs{j}, _st = {call}",
            f"_f{j} = _st == 1",
        ]
        if step.kind == "cs1":  # _kcs1r gives a free angle's value itself
            head += [
                f"if _f{j}:",
                f"    _n{j}, _a{j}, _ac{j}, _as{j} = 1, {ref}, {cos_ref}, {sin_ref}",
            ]
        head += [
            f"_m{j} = n",
            f"for _k{j} in range(_n{j}):",
            f"    {var}, c{j}, s{j} = {first} if _k{j} == 0 else {second}",
        ]
    else:
        call = {
            "atan2": f"_katan2({', '.join(values)})",
            "cs2": f"_kcs2({', '.join(values)})",
            "cs2r": f"_kcs2r({', '.join(values)}, {ref})",
        }[step.kind]
        head = [f"{var}, c{j}, s{j}, _st = {call}", f"_f{j} = _st == 1"]
        if step.kind != "cs2r":  # _kcs2r gives a free angle's value itself
            head += [f"if _f{j}:", f"    {var}, c{j}, s{j} = {ref}, {cos_ref}, {sin_ref}"]
        head.append(f"_m{j} = n")
    return lines + [Line(depth + (1 if h.startswith("    ") else 0), h.strip()) for h in head]


def reference_cs(ref: sp.Expr, printer: CodePrinter) -> tuple[str, str]:
    """cos and sin of a free joint's reference value as _ksolve prints them: cr_i, sr_i for
    q_ref's own value (the caller computes them once, not once per pose), numbers for a
    number, cos(...) and sin(...) otherwise."""
    if isinstance(ref, sp.Symbol) and ref.name.startswith("qr"):
        return f"cr{ref.name[2:]}", f"sr{ref.name[2:]}"
    if ref.is_number:
        return repr(math.cos(float(ref))), repr(math.sin(float(ref)))
    text = printer.doprint(ref)
    return f"cos({text})", f"sin({text})"
