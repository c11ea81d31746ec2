"""Printing SymPy expressions and plan pieces as Python source, shared by the Python solver's
printer (scalar) and emit (forward kinematics).

Printing is deterministic: numbers print as Python float literals (the shortest repr), terms
in SymPy's canonical order, CSE with ``order="canonical"`` and a fresh ``x0, x1, ...``
stream per function.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import sympy as sp
from sympy.printing.str import StrPrinter

from derive import symbols as sym
from derive.plan import Assign, Cs1, Cs1Reach, Cs2, Cs2Reach, Plan, Solve, Step


class UnprintableError(Exception):
    """An expression holds a function the generated code has no name for (the function's
    name is the message); emit turns it into a GenerationError naming the arm and step."""


# the steps whose value a nominal table fixes only roughly where the wrist is nearly straight:
# their loops try the values around it where it gives no row (runtime _wrist_spread)
SPREAD_STEPS = (Cs2, Cs2Reach)

# the steps solving a cos t + b sin t = e (Cs1Unit is a Cs1): on a nominal table their
# acos argument seeds the refinement up to _seed_miss(up) beyond 1, up the least condition of
# the one- and two-equation steps before them (runtime _cs1_sig, _cs2_sig)
CS1_STEPS = (Cs1, Cs1Reach)
CONDITIONED_STEPS = (Cs1, Cs1Reach, Cs2, Cs2Reach)


def seed_conditions(plan: Plan) -> dict[int, tuple[int, ...]]:
    """On a nominal table (plan.correction): each acos step's joint with the joints of the
    one- and two-equation steps before it (CONDITIONED_STEPS; the loops nest, so all of them
    enclose it), where there are any; empty on an exact table."""
    assert plan.ik is not None
    if plan.correction is None:
        return {}
    before: list[int] = []
    out = {}
    for step in plan.ik.steps:
        if isinstance(step, CS1_STEPS) and before:
            out[step.joint] = tuple(before)
        if isinstance(step, CONDITIONED_STEPS):
            before.append(step.joint)
    return out


def condition_call(step: Solve, values: list[str], prefix: str) -> str:
    """The call giving a one- or two-equation step's condition from its printed arguments
    (prefix "_": the Python runtime's, "dk_": the C one's)."""
    if isinstance(step, CS1_STEPS):  # (a, b, e, ...; the step's scale)
        return f"{prefix}cs1_sig({values[0]}, {values[1]}, {values[2]}, {step.scale!r})"
    # (a1, b1, e1, a2, b2, e2, det_scale, ...)
    return f"{prefix}cs2_sig({values[0]}, {values[1]}, {values[3]}, {values[4]}, {values[6]})"


# SymPy function -> the name the generated code calls it by: from `math` in scalar code,
# `np.` in vectorised code (the module imports exactly these)
SCALAR_FUNCTIONS = {"sin": "sin", "cos": "cos", "sqrt": "sqrt", "atan2": "atan2", "acos": "acos"}
VECTOR_FUNCTIONS = {
    "sin": "sin",
    "cos": "cos",
    "sqrt": "sqrt",
    "atan2": "arctan2",
    "acos": "arccos",
}


class CodePrinter(StrPrinter):
    """Python source for SymPy expressions: float literals, ``prefix``-qualified functions."""

    def __init__(self, prefix: str = "") -> None:
        super().__init__({"order": None})
        self.prefix = prefix

    def _print_Rational(self, expr: sp.Rational) -> str:
        return float_literal(float(expr))

    def _print_Integer(self, expr: sp.Integer) -> str:
        return float_literal(float(expr))

    def _print_Float(self, expr: sp.Float) -> str:
        return float_literal(float(expr))

    def _print_Pi(self, expr: sp.Expr) -> str:
        return float_literal(math.pi)

    def _print_Mul(self, expr: sp.Mul) -> str:
        coeff, rest = expr.as_coeff_Mul()
        if coeff.is_Rational and not coeff.is_Integer and rest is not sp.S.One:
            if coeff < 0:
                return f"-{float(-coeff)!r}*{self.parenthesize(rest, 49)}"
            return f"{float(coeff)!r}*{self.parenthesize(rest, 49)}"
        return super()._print_Mul(expr)

    def _print_Function(self, expr: sp.Function) -> str:
        names = VECTOR_FUNCTIONS if self.prefix else SCALAR_FUNCTIONS
        name = expr.func.__name__
        if name not in names:
            raise UnprintableError(name)
        args = ", ".join(self._print(a) for a in expr.args)
        return f"{self.prefix}{names[name]}({args})"

    def _print_Pow(self, expr: sp.Pow, rational: bool = False) -> str:
        base, exp = expr.as_base_exp()
        if exp == sp.S.Half:
            return f"{self.prefix}sqrt({self._print(base)})"
        if exp.is_Integer and exp == 2 and base.is_Symbol:
            return f"{self._print(base)}*{self._print(base)}"
        return super()._print_Pow(expr, rational)


def float_literal(value: float) -> str:
    return repr(value)


@dataclass(frozen=True)
class Line:
    """One line of generated code at an indentation depth (in 4-space units)."""

    depth: int
    text: str


def assign_lines(
    targets: tuple[sp.Symbol, ...],
    exprs: tuple[sp.Expr, ...],
    names: sp.utilities.iterables.numbered_symbols | str,
    printer: CodePrinter,
    depth: int,
    live: frozenset[str] | None = None,
) -> list[Line]:
    """CSE'd straight-line code for targets = exprs (temporaries from names, or from a fresh
    stream where names is its prefix: cse); with live, only the lines whose value something
    in live reads, directly or through later lines.

    The CSE runs on all the expressions either way, so that the arithmetic of the lines kept
    does not depend on which others are read.
    """
    temps, reduced = cse(exprs, names)
    pairs = [*temps, *zip(targets, reduced)]
    if live is not None:
        pairs = read_pairs(pairs, set(live))
    return [Line(depth, f"{t} = {printer.doprint(e)}") for t, e in pairs]


def cse(
    exprs: tuple[sp.Expr, ...], names: sp.utilities.iterables.numbered_symbols | str
) -> tuple[tuple[tuple[sp.Symbol, sp.Expr], ...], tuple[sp.Expr, ...]]:
    """sp.cse of exprs in canonical order, its temporaries from names; names a prefix: a fresh
    stream of it (x0, x1, ... for "x"), and the result is kept for the process (the pose's
    and the Jacobian's entries, which the Python and the C printer both print, and C's
    hoisted pose: their CSE was a third of the time a calibrated arm's module took)."""
    if isinstance(names, str):
        return _fresh_cse(tuple(exprs), names)
    temps, reduced = sp.cse(list(exprs), symbols=names, order="canonical")
    return tuple(temps), tuple(reduced)


@functools.lru_cache(maxsize=16)
def _fresh_cse(
    exprs: tuple[sp.Expr, ...], prefix: str
) -> tuple[tuple[tuple[sp.Symbol, sp.Expr], ...], tuple[sp.Expr, ...]]:
    temps, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols(prefix), order="canonical")
    return tuple(temps), tuple(reduced)


def read_pairs(
    pairs: list[tuple[sp.Symbol, sp.Expr]], needed: set[str]
) -> list[tuple[sp.Symbol, sp.Expr]]:
    """The (target, expression) pairs whose target is needed, directly or through later
    pairs, in their order."""
    kept = []
    for target, expr in reversed(pairs):
        if str(target) in needed:
            kept.append((target, expr))
            needed |= {str(s) for s in expr.free_symbols}
    return kept[::-1]


def used_joints(plan: Plan, used: set[sp.Basic]) -> list[tuple[int, sp.Symbol, sp.Expr, bool]]:
    """The joint definitions (k, target, expression in q_{k+1}, revolute) whose symbols (c_k,
    s_k, or d_k) appear in used: a Jacobian needs no sine and cosine of a last joint that
    moves neither the tool point nor the axes."""
    out = []
    for k, (target, expr) in enumerate(plan.joint_defs):
        turns = str(target).startswith("theta")
        if ({sym.c(k + 1), sym.s(k + 1)} if turns else {target}) & used:
            out.append((k, target, expr, turns))
    return out


def cs_arguments(plan: Plan) -> str:
    """The arguments of _fk_from_cs: c1, s1, ... for R joints, d_i for P joints, in order."""
    out = []
    for target, _ in plan.joint_defs:
        name = str(target)
        out += [f"c{name[5:]}", f"s{name[5:]}"] if name.startswith("theta") else [name]
    return ", ".join(out)


def same_joints(plan: Plan) -> bool:
    """The plan's theta_i / d_i are the arm's (not a reversed chain's): q_i = theta_i - offset."""
    assert plan.ik is not None
    for (target, _), out in zip(plan.joint_defs, plan.ik.outputs):
        if out.free_symbols != {target} or out.coeff(target) != 1:
            return False
    return True


def held_joints(plan: Plan) -> tuple[tuple[int, int], ...]:
    """(step joint j, arm joint index i) for each arm joint whose value is one step's variable
    (q_i = +-theta_j + const): where that step's joint is free (it takes q_ref's value at a
    singular configuration), the refinement onto the exact chain first holds joint i there
    (derive/runtime/refine.py _refine)."""
    assert plan.ik is not None
    steps = {
        s.variable: s.joint
        for s in plan.ik.steps
        if isinstance(s, Solve) and s.kind != "eigen"  # (the general method: no free joint)
    }
    pairs = []
    for i, out in enumerate(plan.ik.outputs):
        names = [str(x) for x in out.free_symbols]
        if len(names) == 1 and names[0] in steps:
            pairs.append((steps[names[0]], i))
    return tuple(pairs)


def match_expression(certify: str, axis: int = 2, cone: int = 2) -> str:
    """The certification test of entries e against target t in the task's components
    (derive/tasks.py), unrolled: rotation entries within tol, positions within ptol."""
    if certify == "lookat":
        return "_ray_gap(e, t, TOOL_AXIS) <= ptol"
    rotation: tuple[int, ...] = {
        "pose": (0, 1, 2, 4, 5, 6, 8, 9, 10),
        "direction": (axis, 4 + axis, 8 + axis),
        "pointing": (axis, 4 + axis, 8 + axis),
        "axisangle": (4 * cone + axis,),  # (the tool axis's component along the base axis)
    }.get(certify, ())
    tests = [f"abs(e[{k}] - t[{k}]) <= tol" for k in rotation]
    if certify != "pointing":  # (a pointing reads no position)
        tests += [f"abs(e[{k}] - t[{k}]) <= ptol" for k in (3, 7, 11)]
    return " and ".join(tests)


def step_arguments(
    step: Solve, names: sp.utilities.iterables.numbered_symbols, printer: CodePrinter, depth: int
) -> tuple[list[Line], list[str]]:
    """A Solve step's note and the CSE'd temporaries of its arguments, and the arguments'
    printed expressions (in terms of those temporaries)."""
    temps, reduced = sp.cse(list(step.args), symbols=names, order="canonical")
    lines = [Line(depth, f"# {step.note}")]
    lines += [Line(depth, f"{t} = {printer.doprint(e)}") for t, e in temps]
    return lines, [printer.doprint(e) for e in reduced]


def world_names() -> tuple[str, ...]:
    """The names of the world pose's 12 top entries, row by row (w11, w12, w13, wx, ...)."""
    world = sym.world_pose()
    return tuple(str(world[i, j]) for i in range(3) for j in range(4))


@dataclass(frozen=True)
class Live:
    """An IK step and the names read after it (by later steps and by the certification): the
    printers leave out the assignments nothing reads (assign_lines with live=after) and the
    cos and sin of an angle that nothing reads."""

    step: Step
    after: frozenset[str]


def live_steps(plan: Plan) -> tuple[tuple[Live, ...], frozenset[str]]:
    """The plan's IK steps without the assignments nothing reads, each with the names read
    after it; and the names the first step reads (the target's entries and q_ref's values
    the solver uses)."""
    assert plan.ik is not None
    live = {str(s) for e in plan.ik.outputs for s in e.free_symbols}
    if same_joints(plan) and plan.correction is None:  # (certified by fk from the cs; a
        # corrected arm's rows are refined and certified on its exact chain instead)
        live |= set(cs_arguments(plan).split(", "))
    out = []
    for step in reversed(plan.ik.steps):
        after = frozenset(live)
        if isinstance(step, Assign):
            read = False
            for target, expr in reversed(tuple(zip(step.targets, step.exprs))):
                if str(target) in live:
                    read = True
                    live |= {str(s) for s in expr.free_symbols}
            if read:
                out.append(Live(step, after))
            continue
        out.append(Live(step, after))
        unit = (step.unit,) if isinstance(step.unit, sp.Expr) else ()
        live |= {str(s) for e in (*step.args, step.ref, *unit) for s in e.free_symbols}
    return tuple(reversed(out)), frozenset(live)
