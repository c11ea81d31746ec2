"""The compiled kernel's printer: _ksolve's body, the solver for one pose in the subset of
Python numba compiles (the routines it calls are in derive/runtime/kernel.py).

It follows the scalar solver's steps with fixed-size results: a Solve step gives a count and
values and whether the joint is free; a root the closed forms cannot settle, or a free joint
without solution from its first value, makes it return -1, and the scalar solver settles the
pose. Each Solve kind has one function here (SOLVES) printing its block.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp

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
    match_expression,
    same_joints,
    step_arguments,
    world_names,
)


@dataclass(frozen=True)
class Context:
    """What a Solve kind's block is printed from.

    Attributes:
        step: the step.
        values: its printed arguments.
        ref: its printed reference value (where the joint is free).
        cos_ref, sin_ref: the reference value's cos and sin, printed (see reference_cs).
        at: where its values go in _ksolve's scratch buf (polynomial steps).
        after: the names later steps read (an unread cos or sin is not kept).
    """

    step: Solve
    values: tuple[str, ...]
    ref: str
    cos_ref: str
    sin_ref: str
    at: int
    after: frozenset[str]

    def name(self, kind: str) -> str:
        """c{j} or s{j} if a later step reads it, else _."""
        name = f"{kind}{self.step.joint}"
        return name if name in self.after else "_"


@dataclass(frozen=True)
class Block:
    """A Solve step's printed block: lines at depths relative to the step's, whether it opens a
    loop over the joint's values (the next steps go one level deeper), whether it reads the
    reference value's cos and sin, and the scratch it takes in buf."""

    lines: tuple[Line, ...]
    loop: bool
    reads_cs: bool
    slots: int = 0


def poly_slots(degree: int) -> int:
    """The scratch _kpoly takes for a polynomial of this degree (see its docstring)."""
    return 6 * degree + 1


def _poly(c: Context) -> Block:
    step, j, at = c.step, c.step.joint, c.at
    d = len(c.values) - 1
    angles = step.angle
    unit = 1.0 if angles else step.unit
    end = at + poly_slots(d)
    call = f"_kpoly(({', '.join(c.values)},), {angles}, {1e-10 * step.scale!r}, {unit!r}, "
    lines = [
        Line(0, f"_n{j} = {call}buf[{at}:{end}])"),
        Line(0, f"_f{j} = _n{j} == -2"),
        Line(0, f"if _f{j}:"),
        Line(1, f"_n{j} = 1"),
        Line(1, f"buf[{at}] = {c.ref}"),
    ]
    if angles:
        lines.append(
            Line(1, f"buf[{at + 4 * d + 1}], buf[{at + 5 * d + 1}] = {c.cos_ref}, {c.sin_ref}")
        )
    lines += [
        Line(0, f"elif _n{j} < 0:"),
        Line(1, "return -1"),
        Line(0, f"_m{j} = n"),
        Line(0, f"for _k{j} in range(_n{j}):"),
        Line(1, f"{step.variable} = buf[{at} + _k{j}]"),
    ]
    if angles:
        for kind, offset in (("c", 4 * d + 1), ("s", 5 * d + 1)):
            if c.name(kind) != "_":
                lines.append(Line(1, f"{c.name(kind)} = buf[{at + offset} + _k{j}]"))
    return Block(tuple(lines), loop=True, reads_cs=angles, slots=poly_slots(d))


def _cs1(c: Context) -> Block:
    step, j = c.step, c.step.joint
    if isinstance(step, Cs1Reach):
        call = f"_kcs1r({', '.join(c.values)}, {step.scale!r}, {c.ref})"
    else:
        call = f"_kcs1({', '.join(c.values)}, {step.scale!r})"
    first, second = f"(_a{j}, _ac{j}, _as{j})", f"(_b{j}, _bc{j}, _bs{j})"
    lines = [
        Line(0, f"_n{j}, _a{j}, _ac{j}, _as{j}, _b{j}, _bc{j}, _bs{j}, _st = {call}"),
        Line(0, f"_f{j} = _st == 1"),
    ]
    if not isinstance(step, Cs1Reach):  # _kcs1r gives a free angle's value itself
        lines += [
            Line(0, f"if _f{j}:"),
            Line(1, f"_n{j}, _a{j}, _ac{j}, _as{j} = 1, {c.ref}, {c.cos_ref}, {c.sin_ref}"),
        ]
    cs = f"{c.name('c')}, {c.name('s')}"
    lines += [
        Line(0, f"_m{j} = n"),
        Line(0, f"for _k{j} in range(_n{j}):"),
        Line(1, f"{step.variable}, {cs} = {first} if _k{j} == 0 else {second}"),
    ]
    return Block(tuple(lines), loop=True, reads_cs=not isinstance(step, Cs1Reach))


# the one-value kinds' routines
_SINGLE = {Atan2: "_katan2", Cs2: "_kcs2", Cs2Reach: "_kcs2r"}


def _single(c: Context) -> Block:
    step, j = c.step, c.step.joint
    args = ", ".join(c.values) + (f", {c.ref}" if isinstance(step, Cs2Reach) else "")
    cs = f"{c.name('c')}, {c.name('s')}"
    lines = [
        Line(0, f"{step.variable}, {cs}, _st = {_SINGLE[type(step)]}({args})"),
        Line(0, f"_f{j} = _st == 1"),
    ]
    if not isinstance(step, Cs2Reach):  # _kcs2r gives a free angle's value itself
        lines += [
            Line(0, f"if _f{j}:"),
            Line(1, f"{step.variable}, {cs} = {c.ref}, {c.cos_ref}, {c.sin_ref}"),
        ]
    lines.append(Line(0, f"_m{j} = n"))
    return Block(tuple(lines), loop=False, reads_cs=not isinstance(step, Cs2Reach))


# the scratch of the general method's step: up to KGENERAL_ROWS joint vectors of six angles
KGENERAL_ROWS = 16


def _eigen(c: Context) -> Block:
    step = c.step
    assert isinstance(step, Eigen)
    j = step.joint
    groups = [c.values[k : k + 12] for k in range(0, len(c.values), 12)]
    flanges = ", ".join(f"({', '.join(g)})" for g in groups)
    at, end = c.at, c.at + 6 * KGENERAL_ROWS
    lines = [
        Line(0, f"_n{j} = _kgeneral(({flanges},), buf[{at}:{end}])"),
        Line(0, f"if _n{j} < 0:"),
        Line(1, "return -1"),
        Line(0, f"_f{j} = False"),
        Line(0, f"_m{j} = n"),
        Line(0, f"for _k{j} in range(_n{j}):"),
    ]
    for place, (k, variable) in enumerate(zip(step.indices, step.variables)):
        lines.append(Line(1, f"{variable} = buf[{at} + 6 * _k{j} + {place}]"))
        for kind, function in (("c", "cos"), ("s", "sin")):
            if f"{kind}{k}" in c.after and variable.startswith("theta"):
                lines.append(Line(1, f"{kind}{k} = {function}({variable})"))
    return Block(tuple(lines), loop=True, reads_cs=False, slots=6 * KGENERAL_ROWS)


SOLVES: dict[type[Solve], Callable[[Context], Block]] = {
    Poly: _poly,
    PolyD: _poly,
    Cs1: _cs1,
    Cs1Reach: _cs1,
    Cs2: _single,
    Cs2Reach: _single,
    Atan2: _single,
    Eigen: _eigen,
}


def kernel_lines(plan: Plan) -> tuple[tuple[tuple[int, str], ...], int]:
    """Body of _ksolve: the scalar solver's steps with fixed-size results. A free joint takes
    its first value (from q_ref), as the scalar solver does; if no solution follows from it,
    or a root is one the closed forms cannot settle, the function returns -1 (the pose goes
    to the scalar solver, which tries the free joint's further values).

    Returns:
        (the body's lines, the length of the scratch its polynomial steps share: _KBUF).
    """
    assert plan.ik is not None
    printer = CodePrinter()
    names = sp.numbered_symbols("x")
    body: list[Line] = []
    depth = 0
    checks: list[tuple[int, int]] = []
    buffer = 0
    refs: set[str] = set()
    steps, _ = live_steps(plan)
    for live in steps:
        step = live.step
        if isinstance(step, Assign):
            body.append(Line(depth, f"# {step.note}"))
            body += assign_lines(step.targets, step.exprs, names, printer, depth, live.after)
            # (free joints' values: an arm with free joints reads them here)
            refs |= {str(s) for e in step.exprs for s in e.free_symbols if s.name[:2] == "qr"}
            continue
        head, values = step_arguments(step, names, printer, depth)
        cos_ref, sin_ref = reference_cs(step.ref, printer)
        context = Context(
            step, tuple(values), printer.doprint(step.ref), cos_ref, sin_ref, buffer, live.after
        )
        block = SOLVES[type(step)](context)
        body += head + [Line(depth + ln.depth, ln.text) for ln in block.lines]
        refs |= {str(s) for s in step.ref.free_symbols}
        if block.reads_cs:
            refs |= {r for r in (cos_ref, sin_ref) if r[:2] in ("cr", "sr") and r[2:].isdigit()}
        buffer += block.slots
        checks.append((depth, step.joint))
        depth += block.loop
    outputs = [printer.doprint(e) for e in plan.ik.outputs]
    refs |= {str(s) for e in plan.ik.outputs for s in e.free_symbols if s.name[:2] == "qr"}
    if same_joints(plan):
        body.append(Line(depth, f"e = _fk_from_cs({cs_arguments(plan)})"))
    else:
        body.append(Line(depth, f"e = _fk_q(({', '.join(outputs)},))"))
    body.append(Line(depth, f"if {match_expression(plan.ik.certify)}:"))
    body += [Line(depth + 1, f"found[n, {k}] = {v}") for k, v in enumerate(outputs)]
    body.append(Line(depth + 1, "n += 1"))
    # a free joint whose first value gave no solution: the scalar solver tries the others
    for level, joint in sorted(checks, key=lambda c: -c[0]):
        body.append(Line(level, f"if _f{joint} and n == _m{joint}:"))
        body.append(Line(level + 1, "return -1"))
    body.append(Line(0, "return n"))
    dof = plan.arm.dof
    # q_ref's values and their cos and sin, as far as the steps read them (see _kreference)
    head = [
        Line(0, f"{kind}{i} = ref[{k * dof + i - 1}]")
        for k, kind in enumerate(("qr", "cr", "sr"))
        for i in range(1, dof + 1)
        if f"{kind}{i}" in refs
    ]
    head += [Line(0, "ptol = tol * REACH"), Line(0, "n = 0")]
    head.append(Line(0, f"t = ({', '.join(world_names())})"))
    lines = head + body
    return tuple((ln.depth, ln.text) for ln in lines), max(buffer, 1)


def reference_tuple(dof: int) -> str:
    """_kreference's result: q's values, then their cosines, then their sines, as one tuple."""
    items = [f"{f}(q[{k}])" if f else f"q[{k}]" for f in ("", "cos", "sin") for k in range(dof)]
    return f"({', '.join(items)})"


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
