"""The C printer: the solver of one pose (dk_solve), forward kinematics and the arm's constants
as C99, from the same plan the Python printers read (templates/arm.c.j2 lays them out).

dk_solve follows the Python solver's steps (derive/printers/scalar.py) with the C runtime's
closed forms (derive/c/runtime.c): one loop per Solve
step over the joint's values; a free joint steps through its values (5 degree steps out from
its first one) until one gives a certified solution, as the Python solver does. Roots failing
the residual test are refined by Aberth iterations and split multiple roots merged (numpy's
role in the Python solver); a polynomial of degree 3 or above 4 (once vanishing leading
coefficients are dropped), makes it return DK_UNSETTLED: the C solver then says so instead of
answering (the general method's dk_general answers every pose itself, as the Python
solver's _general does).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import sympy as sp

from derive import symbols as sym
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
    condition_call,
    cs_arguments,
    cse,
    held_joints,
    live_steps,
    read_pairs,
    same_joints,
    seed_conditions,
    used_joints,
    world_names,
)
from derive.printers.general import eigen_step, fill_entries
from derive.tasks import TASK_CODES


class CPrinter(CodePrinter):
    """C99 source for SymPy expressions: math.h's functions, powers as products."""

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        base, exp = expr.as_base_exp()
        if exp == sp.S.Half:
            return f"sqrt({self._print(base)})"
        if exp.is_Integer:
            k = int(exp)
            inner = self.parenthesize(base, 100)
            if 0 < k <= 4:
                return "(" + "*".join([inner] * k) + ")"
            if -4 <= k < 0:
                return "(1.0/(" + "*".join([inner] * -k) + "))"
        return f"pow({self._print(base)}, {self._print(exp)})"


@dataclass
class Scope:
    """The names declared so far, per open block (C needs each declared once per scope)."""

    levels: list[set[str]]

    def declare(self, name: str) -> bool:
        """Whether name is new in every open block (then it is declared in the innermost)."""
        if any(name in level for level in self.levels):
            return False
        self.levels[-1].add(name)
        return True


def _assign(target: str, text: str, depth: int, scope: Scope) -> Line:
    if scope.declare(target):
        return Line(depth, f"double {target} = {text};")
    return Line(depth, f"{target} = {text};")


def _cse_lines(
    targets: tuple[sp.Symbol, ...],
    exprs: tuple[sp.Expr, ...],
    names: sp.utilities.iterables.numbered_symbols | str,
    printer: CPrinter,
    depth: int,
    scope: Scope,
    live: frozenset[str] | None,
) -> tuple[list[Line], list[str]]:
    """CSE'd declarations for targets = exprs (only those live reads, if given; no targets:
    the temporaries only) and the printed reduced expressions."""
    temps, reduced = cse(exprs, names)
    pairs = [*temps, *zip(targets, reduced)]
    if live is not None:
        needed = set(live) | {str(s) for e in reduced[len(targets) :] for s in e.free_symbols}
        pairs = read_pairs(pairs, needed)
    lines = [_assign(str(t), printer.doprint(e), depth, scope) for t, e in pairs]
    return lines, [printer.doprint(e) for e in reduced[len(targets) :]]


@dataclass(frozen=True)
class Call:
    """A Solve step's call filling its dk_values: the routine and its printed arguments."""

    routine: str
    args: tuple[str, ...]
    # a declaration the call needs first (a polynomial's coefficients: C++ has no compound
    # literals, and the C file is valid C++ too, for the IKFast shim that includes it)
    before: str = ""


def _poly(step: Solve, values: list[str], ref: str) -> Call:
    degree = len(values) - 1
    unit = 1.0 if step.angle else step.unit
    free = 1e-10 * step.scale
    angles = "1" if step.angle else "0"
    coeffs = f"dk_p{step.joint}"
    array = f"const double {coeffs}[] = {{{', '.join(values)}}};"
    length = CPrinter().doprint(unit) if isinstance(unit, sp.Expr) else repr(unit)
    if isinstance(step, PolyPi):
        return Call("dk_poly_pi", (coeffs, repr(free), ref), array)
    return Call("dk_poly", (coeffs, str(degree), angles, repr(free), length, ref), array)


def _cs1(step: Solve, values: list[str], ref: str) -> Call:
    """(up, the least condition of the steps before it, HUGE_VAL: solve_lines prints the
    steps' own where a nominal table has them, seed_conditions)"""
    routine = {Cs1Reach: "dk_cs1r", Cs1Unit: "dk_cs1x"}.get(type(step), "dk_cs1")
    return Call(routine, (*values, repr(step.scale), ref, "HUGE_VAL"))


def _cs2(step: Solve, values: list[str], ref: str) -> Call:
    routine = "dk_cs2r" if isinstance(step, Cs2Reach) else "dk_cs2"
    return Call(routine, (*values, ref))


def _atan2(step: Solve, values: list[str], ref: str) -> Call:
    return Call("dk_atan2", (*values, ref))


CALLS: dict[type[Solve], Callable[[Solve, list[str], str], Call]] = {
    Poly: _poly,
    PolyPi: _poly,
    PolyD: _poly,
    Cs1: _cs1,
    Cs1Unit: _cs1,
    Cs1Reach: _cs1,
    Cs2: _cs2,
    Cs2Reach: _cs2,
    Atan2: _atan2,
}


# the steps whose routines give one value (dk_one) or a free joint's values (dk_set_free)
SINGLE = (Cs2, Cs2Reach, Atan2)


def wrist_flip(plan: Plan) -> tuple[int, int, int] | None:
    """(j5, j4, j6), the joints of a Pieper wrist whose second theta5 value gives the first's
    theta4 + pi and theta6 + pi, else None.

    The wrist's steps (derive.methods.pieper.wrist_equations): theta5 from a c5 + b s5 = e
    with b = 0 (so its values are +-t, exactly so in dk_cs1), v = Rx(alpha4) Rz(theta5)
    Rx(alpha5) e3 with v2 = 0 identically (which is alpha4, alpha5 = +-90 deg: v2 =
    -sin alpha5 c5 cos alpha4 - cos alpha5 sin alpha4), theta4 from (v1, v2) and theta6 by
    atan2. There Rz(pi) Rx(alpha4) Rz(-t5) Rx(alpha5) Rz(pi) = Rx(alpha4) Rz(t5) Rx(alpha5),
    so (theta4 + pi, -theta5, theta6 + pi) gives the wrist rotation of (theta4, theta5,
    theta6): the C solver takes it instead of solving the second branch's theta4 and theta6
    again (where the first branch's are single and not free)."""
    assert plan.ik is not None
    steps = [
        s for s in plan.ik.steps if not isinstance(s, Assign) or s.targets[:1] == (sym.named("v1"),)
    ]
    for k in range(len(steps) - 3):
        five, v, four, six = steps[k : k + 4]
        if (
            isinstance(five, Cs1)  # (Cs1Unit too)
            and isinstance(v, Assign)
            and type(four) is Cs2
            and type(six) is Atan2
            and five.args[1] == 0
            and five.args[0].is_number
            and five.args[0] != 0
            and v.targets == (sym.named("v1"), sym.named("v2"))
            and v.exprs[1] == 0
            and v.exprs[0] != 0
        ):
            return five.joint, four.joint, six.joint
    return None


def seamed_outputs(plan: Plan) -> frozenset[str]:
    """The angle steps' variables that dk_solve brings to ik's range itself (dk_seam, once
    per value), where every revolute output joint is one of them: then dk_finish need not (a
    row has 6 joints, a step's value serves several rows). Empty otherwise, and on a refined
    arm, whose rows are the refinement's (a CAD PUMA's C rows came back with q4 = 6.28326 and
    q6 = -3.72, 53 of 475 of them beyond pi, where the Python solver's were wrapped)."""
    assert plan.ik is not None
    if plan.correction is not None:
        return frozenset()
    angles = {
        step.variable
        for step in plan.ik.steps
        if isinstance(step, Solve) and not isinstance(step, Eigen) and step.angle
    }
    names = set()
    for kind, output in zip(plan.arm.joint_types, plan.ik.outputs):
        if kind != "R":
            continue
        if not (isinstance(output, sp.Symbol) and output.name in angles):
            return frozenset()
        names.add(output.name)
    return frozenset(names)


@dataclass
class HoistedFK:
    """The arm's forward kinematics in dk_solve, spread over its loops (loop-invariant code
    motion done here, where GCC did not: the loops' breaks and calls stop it): the CSE'd
    temporaries (dk_h0, ...) and the 12 pose entries (dk_e0, ...), each printed in the first
    loop body where the joints' cos and sin (or lengths) it reads are known, not once per
    row. A PUMA's entries of theta1..theta3 alone (its position) are computed 4 times a pose
    instead of 8."""

    pairs: list[tuple[str, sp.Expr]]
    emitted: set[str]
    known: set[str]

    @classmethod
    def of(cls, plan: Plan) -> HoistedFK:
        pose = plan.fk_pose
        entries = [pose[i, j] for i in range(3) for j in range(4)]
        temps, reduced = cse(tuple(entries), "dk_h")
        pairs = [(str(t), e) for t, e in temps]
        pairs += [(f"dk_e{k}", e) for k, e in enumerate(reduced)]
        return cls(pairs, set(), set())

    def ready(self, names: set[str], depth: int, printer: CPrinter) -> list[Line]:
        """The lines whose inputs are known once names are (declared at depth)."""
        self.known |= names
        out = []
        for target, expr in self.pairs:
            reads = {str(x) for x in expr.free_symbols}
            if target not in self.emitted and reads <= self.known | self.emitted:
                self.emitted.add(target)
                out.append(Line(depth, f"double {target} = {printer.doprint(expr)};"))
        return out


def solve_lines(plan: Plan) -> tuple[tuple[int, str], ...]:
    """Body of dk_solve(t, tol, ref, found): the certified solutions of the pose t (12 top
    entries) into found, in the Python solver's branch order; their count, or DK_UNSETTLED.
    """
    assert plan.ik is not None
    printer = CPrinter()
    names = sp.numbered_symbols("x")
    scope = Scope([set()])
    steps, inputs = live_steps(plan)
    body: list[Line] = []
    for k, name in enumerate(world_names()):
        if name in inputs or any(name in live.after for live in steps):
            body.append(_assign(name, f"t[{k}]", 0, scope))
    refs = sorted(
        {str(s) for e in _expressions(plan) for s in e.free_symbols if s.name[:2] == "qr"},
        key=lambda s: int(s[2:]),
    )
    body = [_assign(r, f"ref[{int(r[2:]) - 1}]", 0, scope) for r in refs] + body
    fix = plan.correction is not None
    if not fix:
        body.append(Line(0, "const double ptol = tol * DK_REACH;"))
        # (rows within this need no polish: dk_polish; most are, and one dk_match settles it)
        body.append(Line(0, "const double dk_fine = fmin(tol, DK_REFINE_POLISH);"))
        # (a row polishing left beyond DK_LOOSE_TOL: dk_drop_rough)
        body.append(Line(0, "unsigned char dk_rough[DK_MAX];"))
    body.append(Line(0, "int n = 0;"))
    if fix:  # (the seeds wait for others, and are refined with them: dk_defer)
        body.append(Line(0, "dk_pending dk_p;"))
        body.append(
            Line(
                0,
                "dk_pending_start(&dk_p, DK_CHAIN, DK_REVOLUTE, DK_SOLVED, DK_REACH, t, "
                "fmin(tol, loose ? DK_REFINE_STALL : DK_REFINE_TOL), DK_MAX);",
            )
        )
    # whether two rows can repeat: where two values of one step lie within DK_DEDUP_TOL (or
    # always, where a row's joints are not the steps' values themselves, or are refined)
    body.append(Line(0, f"int dk_close = {0 if branches_are_outputs(plan) and not fix else 1};"))
    depth = 0
    closing: list[Line] = []
    # lines ending a loop's body, before its free-joint check (by the loop's closing line)
    endings: dict[int, list[Line]] = {}
    # (not on a refined arm: there the second branch's own theta4 can spread, as the Python
    # solver's does, and the first's flip lost rows at 1 to 3 of 600 near-singular wrist poses
    # of five calibrated arms, a reviewer's attack)
    flip = wrist_flip(plan) if not fix else None
    turned: dict[str, tuple[str, str]] = {}  # an angle's variable: its cos and sin
    seamed = seamed_outputs(plan)
    hoisted = HoistedFK.of(plan) if same_joints(plan) and not fix else None
    # (a nominal acos step's miss: dk_seed_miss of the least condition of the steps before it)
    ups = seed_conditions(plan)
    conditioned = {k for joints in ups.values() for k in joints}
    for live in steps:
        step = live.step
        if isinstance(step, Assign):
            body.append(Line(depth, f"/* {_comment(step.note)} */"))
            lines, _ = _cse_lines(
                step.targets, step.exprs, names, printer, depth, scope, live.after
            )
            body += lines
            continue
        if isinstance(step, Eigen):
            lines, values = _cse_lines((), tuple(step.args), names, printer, depth, scope, None)
            body.append(Line(depth, f"/* {_comment(step.note)} */"))
            body += lines
            body += _eigen_lines(step, values, live.after, depth, scope)
            closing.append(Line(depth + 1, ""))
            depth += 1
            continue
        j = step.joint
        body.append(Line(depth, f"/* {_comment(step.note)} */"))
        lines, values = _cse_lines((), tuple(step.args), names, printer, depth, scope, None)
        body += lines
        call = CALLS[type(step)](step, values, printer.doprint(step.ref))
        if j in ups:  # (its miss on a nominal table: dk_seed_miss)
            up = f"dk_u{ups[j][0]}"
            for k in ups[j][1:]:
                up = f"fmin({up}, dk_u{k})"
            call = Call(call.routine, (*call.args[:-1], up), call.before)
        if call.before:
            body.append(Line(depth, call.before))
        if j in conditioned:
            condition = condition_call(step, values, "dk_")
            body.append(Line(depth, f"const double dk_u{j} = {condition};"))
        body.append(Line(depth, f"dk_values dk_v{j};"))
        body.append(Line(depth, f"dk_v{j}.loose = loose;"))  # (derive/c/runtime.c dk_values)
        if fix and isinstance(step, SPREAD_STEPS):  # (a rough value's spread: dk_wrist_spread)
            body.append(Line(depth, f"dk_v{j}.more = 0.0;"))
        solve = f"{call.routine}(&dk_v{j}, {', '.join(call.args)}) < 0"
        if flip and j in flip[1:]:  # the second theta5 branch: the first's turned by pi
            body.append(Line(depth, "if (dk_flip) {"))
            body.append(
                Line(depth + 1, f"dk_flipped(&dk_v{j}, dk_f{j}[0], dk_f{j}[1], dk_f{j}[2]);")
            )
            body.append(Line(depth, f"}} else if ({solve}) {{"))
            body.append(Line(depth + 1, "return DK_UNSETTLED;"))
            body.append(Line(depth, "}"))
            body.append(
                Line(depth, f"if (dk_k{flip[0]} == 0 && dk_v{j}.n == 1 && !dk_v{j}.free) {{")
            )
            body.append(Line(depth + 1, f"dk_f{j}[0] = dk_v{j}.t[0];"))
            body.append(Line(depth + 1, f"dk_f{j}[1] = dk_v{j}.c[0];"))
            body.append(Line(depth + 1, f"dk_f{j}[2] = dk_v{j}.s[0];"))
            body.append(Line(depth + 1, f"dk_f{j}[3] = 1.0; /* (kept) */"))
            body.append(Line(depth, "}"))
        else:
            body.append(Line(depth, f"if ({solve}) {{"))
            body.append(Line(depth + 1, "return DK_UNSETTLED;"))
            body.append(Line(depth, "}"))
        if flip and j == flip[0]:
            j4, j6 = flip[1:]
            body.append(
                Line(depth, f"/* the wrist flip: theta{j4}, theta{j6} of the second value */")
            )
            body.append(
                Line(
                    depth,
                    f"double dk_f{j4}[4] = {{0.0}}, dk_f{j6}[4] = {{0.0}}; /* t, c, s, kept */",
                )
            )
            body.append(Line(depth, "int dk_flip = 0;"))
        if fix:  # (a free joint's loop, or one that may spread, counts its rows: dk_settle)
            spread = f" || dk_v{j}.more > 0.0" if isinstance(step, SPREAD_STEPS) else ""
            body.append(
                Line(
                    depth,
                    f"const int dk_m{j} = dk_v{j}.free{spread} ? dk_settle(&dk_p, found, &n) : n;",
                )
            )
        else:
            body.append(Line(depth, f"const int dk_m{j} = n;"))
        if type(step) not in SINGLE:  # (one value, or a free joint's loop: never near)
            body.append(Line(depth, f"dk_close |= dk_near(&dk_v{j});"))
        body.append(Line(depth, f"for (int dk_k{j} = 0; dk_k{j} < dk_v{j}.n; dk_k{j}++) {{"))
        scope.levels.append(set())
        var = step.variable
        c_name, s_name = f"c{j}", f"s{j}"
        if not step.angle:
            c_name, s_name = f"dk_c{j}", f"dk_s{j}"
        else:
            turned[str(var)] = (c_name, s_name)
        scope.declare(str(var))
        scope.declare(c_name)
        scope.declare(s_name)
        body.append(Line(depth + 1, f"double {var}, {c_name}, {s_name};"))
        body.append(Line(depth + 1, f"dk_value(&dk_v{j}, dk_k{j}, &{var}, &{c_name}, &{s_name});"))
        if str(var) in seamed:  # (a free joint's ref + step may lie anywhere: dk_seam)
            body.append(
                Line(depth + 1, f"{var} = dk_v{j}.free ? dk_seam({var}) : dk_unit_seam({var});")
            )
        if hoisted is not None:
            body += hoisted.ready({str(var), c_name, s_name}, depth + 1, printer)
        if not step.angle:
            body.append(Line(depth + 1, f"(void){c_name};"))
            body.append(Line(depth + 1, f"(void){s_name};"))
        # a free joint's loop ends at its first value that gave a solution
        count = "dk_settle(&dk_p, found, &n)" if fix else "n"  # (the rows found: all settled)
        closing.append(Line(depth + 1, f"if (dk_v{j}.free && {count} > dk_m{j}) {{"))
        if fix and isinstance(step, SPREAD_STEPS):  # (a rough value that gave no row: the
            # values around it too, dk_wrist_spread)
            endings.setdefault(id(closing[-1]), []).extend(
                [
                    Line(depth + 1, f"if (dk_v{j}.more > 0.0 && {count} == dk_m{j}) {{"),
                    Line(depth + 2, f"dk_spread_more(&dk_v{j});"),
                    Line(depth + 1, "}"),
                ]
            )
        if flip and j == flip[0]:
            j4, j6 = flip[1:]
            endings[id(closing[-1])] = [
                Line(depth + 1, f"dk_flip = dk_k{j} == 0 && dk_v{j}.n == 2 && !dk_v{j}.free &&"),
                Line(depth + 3, f"dk_v{j}.s[0] != 0.0 && dk_v{j}.t[1] == -dk_v{j}.t[0] &&"),
                Line(depth + 3, f"dk_f{j4}[3] == 1.0 && dk_f{j6}[3] == 1.0;"),
            ]
        depth += 1
    outputs = [printer.doprint(e) for e in plan.ik.outputs]
    # (the joints the pose left free, a bit each: a refinement holds them first, a polish
    # throughout)
    held = " | ".join(f"(dk_v{j}.free ? {1 << i}u : 0u)" for j, i in held_joints(plan))
    if fix:  # refined onto the exact chain, certified there
        body.append(Line(depth, "if (n < DK_MAX) {"))
        body.append(Line(depth + 1, f"double dk_q[DK_DOF] = {{{', '.join(outputs)}}};"))
        # (the joints the pose left free, held first: derive/c/runtime.c dk_refine_held)
        body.append(Line(depth + 1, f"const unsigned dk_held = {held or '0u'};"))
        # (the second pass refines only the seeds near the pose: dk_seed_near)
        body.append(
            Line(
                depth + 1,
                "if (!loose || "
                "dk_seed_near(DK_CHAIN, DK_REVOLUTE, DK_SOLVED, DK_REACH, t, dk_q)) {",
            )
        )
        # (a seed held nowhere waits to be refined with others: dk_defer; one
        # with joints held is refined now, after those waiting)
        body.append(Line(depth + 2, "if (!dk_held) {"))
        cs = ", ".join(f"{{{c}, {s}}}" for c, s in _output_cs(plan.ik.outputs, turned))
        body.append(Line(depth + 3, f"const double dk_cs[DK_DOF][2] = {{{cs}}};"))
        body.append(Line(depth + 3, "dk_defer(&dk_p, dk_q, dk_cs, found, &n);"))
        body.append(
            Line(
                depth + 2,
                "} else if (dk_room(&dk_p, found, &n) && dk_refine_held(DK_CHAIN, DK_REVOLUTE, "
                "DK_SOLVED, DK_REACH, t, dk_q, dk_held, dk_p.limit, DK_REFINE_PATIENCE) <= "
                "dk_p.limit) {",
            )
        )
        body.append(Line(depth + 3, "dk_keep(&dk_p, found, &n, dk_q);"))
        body.append(Line(depth + 2, "}"))
        body.append(Line(depth + 1, "}"))
        body.append(Line(depth, "}"))
    elif hoisted is not None:
        body += hoisted.ready(set(cs_arguments(plan).split(", ")), depth, printer)
        entries = ", ".join(f"dk_e{k}" for k in range(12))
        body.append(Line(depth, f"const double e[12] = {{{entries}}};"))
    else:
        body.append(Line(depth, "double e[12];"))
        body += _arm_cs_lines(plan, printer, depth, scope)
    if not fix:
        task = TASK_CODES[plan.ik.certify]
        axis = plan.ik.tool_axis
        if plan.ik.certify == "axisangle":  # (the entry compared: the axis's base-axis one)
            axis += 4 * plan.ik.cone
        match = f"dk_match(e, t, {{}}, {{}}, {task}, {axis})"
        fine = match.format("dk_fine", "dk_fine * DK_REACH")
        body.append(Line(depth, f"const int dk_fine_ok = n < DK_MAX && {fine};"))
        certified = f"dk_fine_ok || (n < DK_MAX && {match.format('tol', 'ptol')})"
        body.append(Line(depth, f"const int dk_ok = {certified};"))
        # (the second pass's row within DK_LOOSE_REACH, polished: _keep says why)
        near = match.format("DK_LOOSE_REACH", "DK_LOOSE_REACH * DK_REACH")
        certified, flag = f"dk_ok || (loose && n < DK_MAX && {near})", "dk_ok"
        if plan.ik.certify == "lookat":  # (a far point's row aimed within tol: dk_aims_at)
            aimed = f"dk_aims_at(e, t, tol, DK_REACH, {task}, {axis})"
            certified += f" || (n < DK_MAX && {aimed})"
        body.append(Line(depth, f"if ({certified}) {{"))
        body += [Line(depth + 1, f"found[n][{k}] = {v};") for k, v in enumerate(outputs)]
        # (a row within tol but not DK_REFINE_POLISH is polished on the exact chain, the
        # joints the pose left free held)
        polish = (
            f"dk_polish(DK_CHAIN, DK_REVOLUTE, DK_SOLVED, DK_REACH, t, found[n], {held or '0u'}, "
            f"tol, {flag})"
        )
        body.append(Line(depth + 1, f"const int dk_kept = dk_fine_ok ? 1 : {polish};"))
        body.append(Line(depth + 1, "if (dk_kept) {"))
        body.append(Line(depth + 2, "dk_rough[n] = dk_kept == 2;"))
        body.append(Line(depth + 2, "n++;"))
        body.append(Line(depth + 1, "}"))
        body.append(Line(depth, "}"))
    for line in reversed(closing):
        body += endings.get(id(line), [])
        if line.text:  # a free joint's loop ends at its first value that gave a solution
            body.append(line)
            body.append(Line(line.depth + 1, "break;"))
            body.append(Line(line.depth, "}"))
        body.append(Line(line.depth - 1, "}"))
        scope.levels.pop()
    if fix:
        body.append(Line(0, "dk_settle(&dk_p, found, &n);"))
    else:  # (the rows polishing left beyond DK_LOOSE_TOL, where the pose has others)
        body.append(Line(0, "n = dk_drop_rough(found, n, dk_rough);"))
    body.append(Line(0, "*repeats = dk_close;"))
    body.append(Line(0, "return n;"))
    return tuple((ln.depth, ln.text) for ln in body)


def _output_cs(
    outputs: tuple[sp.Expr, ...], turned: dict[str, tuple[str, str]]
) -> list[tuple[str, str]]:
    """Each arm joint's cos and sin at a row (C expressions): where its value is +-theta + k,
    theta an angle of the closed form's (its cos c and sin s in turned), theirs turned by k's
    (cos(+-theta + k) = c cos k -+ s sin k, sin = +-s cos k + c sin k), else the library's of
    the row's value dk_q[i] (a length's are not read)."""

    def total(a: str, x: float, b: str, y: float) -> str:  # a x + b y, the signs folded
        return f"{a} * {x!r} {'-' if y < 0 else '+'} {b} * {abs(y)!r}"

    pairs = []
    for i, out in enumerate(outputs):
        pair = (f"cos(dk_q[{i}])", f"sin(dk_q[{i}])")
        for var in out.free_symbols:
            if str(var) not in turned:
                continue
            c, s = turned[str(var)]
            for sign in (1, -1):
                k = sp.expand(out - sign * var)
                if not k.is_number:
                    continue
                ck, sk = math.cos(float(k)), math.sin(float(k))
                if ck == 1.0 and sk == 0.0:
                    pair = (c, s if sign == 1 else f"-{s}")
                else:
                    pair = (total(c, ck, s, -sign * sk), total(s, sign * ck, c, sk))
        pairs.append(pair)
    return pairs


# Solve kind -> the C runtime's sign function of its branches (derive/c/runtime.c)
SIGNS: dict[type[Solve], str] = {
    Cs1: "dk_cs1_branch",
    Cs1Unit: "dk_cs1_branch",
    Cs1Reach: "dk_cs1_branch",
    Poly: "dk_poly_branch",
    PolyPi: "dk_poly_branch",
    PolyD: "dk_polyd_branch",
}


def branch_lines(plan: Plan, name: str) -> tuple[str, ...]:
    """Body of <name>_branch(q, signs): the branch program (printers/branches.py) as C, the
    signs stored in signs[0..] and their count returned (0 where the arm has none); or det J's
    sign over the joints not free (jacobian_branch; <name>_jacobian's columns)."""
    program = branch_program(plan)
    if program is None and jacobian_branch(plan):
        assert plan.ik is not None
        fixed = [j for j in range(plan.arm.dof) if j + 1 not in plan.ik.free]
        copy = [
            f"dk_a[{6 * k + r}] = dk_j[{r}][{j}];" for k, j in enumerate(fixed) for r in range(6)
        ]
        return (
            "double dk_j[6][DK_DOF], dk_a[36];",
            f"{name}_jacobian(q, 0, dk_j);",
            *copy,
            "signs[0] = dk_det_sign(dk_a);",
            "return 1;",
        )
    if program is None:
        return ("(void)q;", "(void)signs;", "return 0;")
    printer = CPrinter()
    scope = Scope([set()])
    lines = ["double e[12];", "dk_fk_q(q, e);"]
    lines += [_assign(w, f"e[{k}]", 0, scope).text for k, w in enumerate(program.world) if w]
    lines += [_assign(j, f"q[{k}]", 0, scope).text for k, j in enumerate(program.joints) if j]
    for target, value in program.lines:
        if isinstance(value, Sign):
            values = [printer.doprint(e) for e in value.args]
            function = SIGNS[type(value.step)]
            name = f"dk{target}"
            if isinstance(value.step, (Cs1, Cs1Reach)):  # (a, b: no coefficient array)
                lines.append(
                    f"const int {name} = {function}({', '.join(values)}, {value.variable});"
                )
                continue
            lines.append(f"const double {name}_p[] = {{{', '.join(values)}}};")
            degree = len(values) - 1
            lines.append(f"const int {name} = {function}({name}_p, {degree}, {value.variable});")
        elif isinstance(value, First):  # (its first value: dk_value's, as the solver reads it)
            step, j = value.step, value.step.joint
            values = [printer.doprint(e) for e in value.args]
            call = CALLS[type(step)](step, values, printer.doprint(step.ref))
            if call.before:
                lines.append(call.before)
            lines.append(f"dk_values dk_v{j};")
            lines.append(f"dk_v{j}.loose = 0;")
            lines.append(f"double dk_c{j}, dk_s{j};")
            lines.append(
                f"if ({call.routine}(&dk_v{j}, {', '.join(call.args)}) < 0 || !dk_v{j}.n) {{"
            )
            lines.append("    return -1; /* (no value: q is not a solution of its own pose) */")
            lines.append("}")
            lines.append(_assign(target, "0.0", 0, scope).text)
            lines.append(f"dk_value(&dk_v{j}, 0, &{target}, &dk_c{j}, &dk_s{j});")
        else:
            lines.append(_assign(target, printer.doprint(value), 0, scope).text)
    for k, sign in enumerate(program.signs):
        lines.append(f"signs[{k}] = dk{sign};")
    return (*lines, f"return {len(program.signs)};")


def branches_are_outputs(plan: Plan) -> bool:
    """Whether every joint value the solve branches on is some output joint up to sign and a
    constant: then rows from branches whose values differ by more than DK_DEDUP_TOL (around
    the circle) differ by as much in that output, and cannot repeat one another. False for
    the general method (its rows are polished candidates, which can meet)."""
    assert plan.ik is not None
    outputs = [sp.expand(o) for o in plan.ik.outputs]
    for step in plan.ik.steps:
        if isinstance(step, Eigen):
            return False
        if not isinstance(step, Solve):
            continue
        x = sym.named(step.variable)
        if not any(
            o.free_symbols == {x} and o.coeff(x) in (1, -1) and (o - o.coeff(x) * x).is_number
            for o in outputs
        ):
            return False
    return True


def _arm_cs_lines(plan: Plan, printer: CPrinter, depth: int, scope: Scope) -> list[Line]:
    """The certification's forward kinematics where the plan's joints are not the arm's (a
    reversed chain, free joints): the arm's cos and sin from the plan's where an output is
    +-theta_j plus a constant (the sum formulas: no transcendental call), else from the
    output's value; then dk_fk_cs."""
    assert plan.ik is not None
    known = _known_cs(plan, scope)
    args = []
    lines = []
    for k, ((target, expr), output) in enumerate(zip(plan.joint_defs, plan.ik.outputs)):
        value = sp.expand(expr.xreplace({sym.q(k + 1): output}))
        if not str(target).startswith("theta"):
            lines.append(Line(depth, f"const double dk_d{k + 1} = {printer.doprint(value)};"))
            args.append(f"dk_d{k + 1}")
            continue
        c, s = f"dk_c{k + 1}", f"dk_s{k + 1}"
        angle = _plus_minus_angle(value, known)
        if angle is None:
            text = printer.doprint(value)
            lines.append(Line(depth, f"const double {c} = cos({text}), {s} = sin({text});"))
        elif angle[3] == 0.0:
            cj, sj, sign, _ = angle
            minus = "" if sign > 0 else "-"
            lines.append(Line(depth, f"const double {c} = {cj}, {s} = {minus}{sj};"))
        else:
            cj, sj, sign, delta = angle
            cd, sd = math.cos(delta), math.sin(delta)
            lines.append(Line(depth, f"const double {c} = {cd!r}*{cj} - {sign * sd!r}*{sj};"))
            lines.append(Line(depth, f"const double {s} = {sd!r}*{cj} + {sign * cd!r}*{sj};"))
        args += [c, s]
    lines.append(Line(depth, f"dk_fk_cs({', '.join(args)}, e);"))
    return lines


def _known_cs(plan: Plan, scope: Scope) -> dict[sp.Symbol, tuple[str, str]]:
    """The angles whose cos and sin are variables in scope at the leaf: theta_j (c_j, s_j)
    and the arguments of cos and sin an assignment names (a free joint's q_ref value)."""
    assert plan.ik is not None
    declared = set().union(*scope.levels)
    known: dict[sp.Symbol, tuple[str, str]] = {}
    for target, _ in plan.joint_defs:
        j = str(target)[5:]
        if str(target).startswith("theta") and {f"c{j}", f"s{j}"} <= declared:
            known[target] = (f"c{j}", f"s{j}")
    halves: dict[sp.Expr, dict[str, str]] = {}
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            for name, expr in zip(step.targets, step.exprs):
                if isinstance(expr, (sp.cos, sp.sin)) and str(name) in declared:
                    kind = "c" if isinstance(expr, sp.cos) else "s"
                    halves.setdefault(expr.args[0], {})[kind] = str(name)
    for arg, names in halves.items():
        if isinstance(arg, sp.Symbol) and len(names) == 2 and arg not in known:
            known[arg] = (names["c"], names["s"])
    return known


def _plus_minus_angle(
    value: sp.Expr, known: dict[sp.Symbol, tuple[str, str]]
) -> tuple[str, str, float, float] | None:
    """(c, s, sign, delta) where value is sign * x + delta for an x whose cos and sin are
    the variables c and s."""
    if len(value.free_symbols) != 1:
        return None
    (x,) = value.free_symbols
    coeff = value.coeff(x)
    rest = value - coeff * x
    if x not in known or coeff not in (1, -1) or not rest.is_number:
        return None
    return known[x][0], known[x][1], float(coeff), float(rest)


def _eigen_lines(
    step: Eigen, values: list[str], after: frozenset[str], depth: int, scope: Scope
) -> list[Line]:
    """The general method's step: dk_general on the splits' flange targets, then a loop over
    its rows opening the joints' values (and their cos and sin where later steps read them)."""
    groups = [values[k : k + 12] for k in range(0, len(values), 12)]
    flanges = ", ".join("{" + ", ".join(g) + "}" for g in groups)
    j = step.joint
    lines = [
        Line(depth, f"const double dk_fl{j}[DK_RR_SPLIT_COUNT][12] = {{{flanges}}};"),
        Line(depth, f"double dk_rows{j}[DK_RR_OUT][6];"),
        Line(depth, f"const int dk_n{j} = dk_general(dk_fl{j}, dk_rows{j});"),
        Line(depth, f"if (dk_n{j} < 0) {{"),
        Line(depth + 1, "return DK_UNSETTLED;"),
        Line(depth, "}"),
        Line(depth, f"for (int dk_k{j} = 0; dk_k{j} < dk_n{j}; dk_k{j}++) {{"),
    ]
    scope.levels.append(set())
    for place, (k, variable) in enumerate(zip(step.indices, step.variables)):
        if not {variable, f"c{k}", f"s{k}"} & after:  # (a task's joint it does not move)
            continue
        scope.declare(variable)
        lines.append(Line(depth + 1, f"const double {variable} = dk_rows{j}[dk_k{j}][{place}];"))
        for kind, function in (("c", "cos"), ("s", "sin")):
            if f"{kind}{k}" in after and variable.startswith("theta"):
                scope.declare(f"{kind}{k}")
                lines.append(Line(depth + 1, f"const double {kind}{k} = {function}({variable});"))
    return lines


def general_fill(plan: Plan) -> tuple[str, ...]:
    """dk_rr_fill's body: per split, the nonzero entries of its matrices from the flange
    target's l and p (CSE'd as for Python: derive/printers/general.py)."""
    step = eigen_step(plan)
    assert step is not None
    printer = CPrinter()
    lines = []
    for k, split in enumerate(step.splits):
        temps, entries = fill_entries(split)
        lines.append(f"if (k == {k}) {{")
        lines += [f"    const double {t} = {printer.doprint(e)};" for t, e in temps]
        lines += [f"    out[{i}] = {printer.doprint(e)};" for i, e in entries]
        lines += ["    return;", "}"]
    return tuple(lines)


def _expressions(plan: Plan) -> list[sp.Expr]:
    """Every expression of the plan's IK (to find the q_ref values it reads)."""
    assert plan.ik is not None
    out: list[sp.Expr] = list(plan.ik.outputs)
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            out += step.exprs
        else:
            out += [*step.args, step.ref]
    return out


def _comment(note: str) -> str:
    """A note as the text of a C comment (no comment end inside)."""
    return note.replace("*/", "* /")


def fk_lines(plan: Plan) -> tuple[tuple[str, ...], tuple[str, ...], str]:
    """dk_fk_cs's body (the pose entries from c_i, s_i and d_i), dk_fk_q's body (c_i, s_i from
    q) and dk_fk_cs's parameter list."""
    printer = CPrinter()
    pose = plan.fk_pose
    entries = tuple(pose[i, j] for i in range(3) for j in range(4))
    targets = tuple(sym.named(f"t{i}{j}") for i in range(3) for j in range(4))
    scope = Scope([set()])
    lines, _ = _cse_lines(targets, entries, "x", printer, 0, scope, None)
    pose_body = tuple(ln.text for ln in lines)
    pose_body += tuple(f"e[{k}] = {t};" for k, t in enumerate(targets))
    joints = []
    for k, (target, expr) in enumerate(plan.joint_defs):
        value = printer.doprint(expr.xreplace({sym.q(k + 1): sp.Symbol(f"q[{k}]")}))
        joints.append(f"const double {target} = {value};")
        if str(target).startswith("theta"):
            joints.append(f"const double c{k + 1} = cos({target});")
            joints.append(f"const double s{k + 1} = sin({target});")
    joints.append(f"dk_fk_cs({cs_arguments(plan)}, e);")
    params = ", ".join(f"double {a}" for a in cs_arguments(plan).split(", "))
    return pose_body, tuple(joints), params


def jacobian_lines(plan: Plan) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The body of NAME_jacobian's world-frame part: theta_i (c_i, s_i) from q, then the
    CSE'd Jacobian entries (derive/jacobian.py) into J[6][DK_DOF]; and its tool frame's: the
    joints the entries did not need (a last joint's c_i, s_i), then the pose's entries e from
    them all (dk_fk_cs), whose rotation turns the columns: not fk again, whose sines and
    cosines made the tool-frame Jacobian 1.8 to 2.6 times fk (a new user's timing)."""
    printer = CPrinter()
    J = plan.jacobian
    if J is None:  # (exact frames: the chain's, at run time, with the tool's pose e)
        call = "dk_chain_jacobian(DK_CHAIN, DK_REVOLUTE, DK_DOF, q, &J[0][0], e);"
        return ("double e[12];", call), ()
    n = J.shape[1]
    entries = tuple(J[i, j] for i in range(6) for j in range(n))
    targets = tuple(sym.named(f"j{i}_{j}") for i in range(6) for j in range(n))
    lines, _ = _cse_lines(targets, entries, "x", printer, 0, Scope([set()]), None)
    body: list[str] = []
    tool: list[str] = []
    used = {k for k, *_ in used_joints(plan, J.free_symbols)}
    for k, (target, expr) in enumerate(plan.joint_defs):
        value = printer.doprint(expr.xreplace({sym.q(k + 1): sp.Symbol(f"q[{k}]")}))
        into = body if k in used else tool
        into.append(f"const double {target} = {value};")
        if str(target).startswith("theta"):
            into.append(f"const double c{k + 1} = cos({target});")
            into.append(f"const double s{k + 1} = sin({target});")
    body += [ln.text for ln in lines]
    body += [f"J[{i}][{j}] = j{i}_{j};" for i in range(6) for j in range(n)]
    tool.append("double e[12];")
    tool.append(f"dk_fk_cs({cs_arguments(plan)}, e);")
    return tuple(body), tuple(tool)


def c_double(value: float) -> str:
    """A double as a C literal (HUGE_VAL for infinities)."""
    if math.isinf(value):
        return "HUGE_VAL" if value > 0 else "-HUGE_VAL"
    return repr(float(value))
