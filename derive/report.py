"""plan -> derivation report: Markdown with LaTeX math, or a standalone LaTeX document.

The report is built from the same plan as the solver module, in the lecture's order: the DH
table and link transforms, the structure and the method, the method's derivation (for
Pieper: f, g, k1..k4, r and z, the case, the polynomial), every step of the plan as an
equation, and a worked example whose numbers come from walking the plan along one branch of
the generated solver's own solutions. Every formula is printed by SymPy's LaTeX printer.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
import sympy as sp

from derive import raghavan_roth as rr
from derive import symbols as sym
from derive.emit import GENERATOR, environment
from derive.methods import general
from derive.plan import Assign, Eigen, Plan, Solve
from derive.runtime import general as runtime_general

DIGITS = 4
CRAIG = "Craig's"


@dataclass(frozen=True)
class Block:
    """One piece of the report.

    Attributes:
        kind: "h2", "h3", "p" (text), "math" (lhs = rhs, display), "table" or "image".
        text: the text, the math block's left-hand side (LaTeX, may be empty), or the
            image's caption.
        math: the math block's right-hand side, printed by SymPy, or the image's file.
        rows: the table's rows, the first one its header.
    """

    kind: str
    text: str = ""
    math: str = ""
    rows: tuple[tuple[str, ...], ...] = ()


@dataclass(frozen=True)
class Example:
    """The worked example: a world pose and the generated solver's solutions for it.

    Attributes:
        pose: 16 floats, row-major.
        solutions: the rows `ik` returned.
        how: where the pose comes from, in words.
    """

    pose: tuple[float, ...]
    solutions: tuple[tuple[float, ...], ...]
    how: str


def tex(expr: sp.Basic) -> str:
    """LaTeX of an expression, rationals shown as decimals, general twists as cos/sin(alpha_i)."""
    subs = {}
    for i in range(0, 13):
        alpha = sp.Symbol(f"alpha_{i}", real=True)
        subs[sym.cos_alpha(i)] = sp.cos(alpha)
        subs[sym.sin_alpha(i)] = sp.sin(alpha)
    expr = sp.sympify(expr).xreplace(subs)
    expr = expr.xreplace(
        {r: sp.Float(float(r), 15) for r in expr.atoms(sp.Rational) if not r.is_Integer}
    )
    return sp.latex(expr)


def number(value: float) -> str:
    """A number rounded for the worked example."""
    text = f"{value:.{DIGITS}f}"
    return "0.0000" if text == "-0.0000" else text


def matrix_of(values: np.ndarray) -> str:
    """A numeric matrix as LaTeX via SymPy, rounded to DIGITS decimals."""
    rows = [[sp.Float(round(float(v), DIGITS), DIGITS + 3) for v in row] for row in values]
    return tex(sp.Matrix(rows))


def arm_blocks(plan: Plan) -> list[Block]:
    """The DH table, the convention's link transform, base and tool."""
    arm = plan.arm
    modified = arm.convention == "modified"
    general = (
        "R_X(\\alpha_{i-1}) D_X(a_{i-1}) R_Z(\\theta_i) D_Z(d_i)"
        if modified
        else "R_Z(\\theta_i) D_Z(d_i) D_X(a_i) R_X(\\alpha_i)"
    )
    head = ("alpha_{i-1} [deg]", "a_{i-1}") if modified else ("alpha_i [deg]", "a_i")
    rows = [("i", "type", head[0], head[1], "d_i", "theta_i [deg]")]
    for k, (alpha, a, d, theta) in enumerate(arm.dh, start=1):
        kind = arm.joint_types[k - 1]
        rows.append(
            (
                str(k),
                kind,
                f"{math.degrees(alpha):g}",
                f"{a:g}",
                f"q{k} + {d:g}" if kind == "P" else f"{d:g}",
                f"q{k} + {math.degrees(theta):g}" if kind == "R" else f"{math.degrees(theta):g}",
            )
        )
    out = [
        Block("h2", "1. The arm"),
        Block(
            "p",
            f"{arm.convention.capitalize()} DH parameters (lengths in {arm.length_unit}); "
            f"the link transform is {CRAIG if modified else 'the standard one'}, "
            f"${{}}^{{i-1}}_{{i}}T = {general}$:",
        ),
        Block("table", rows=tuple(rows)),
    ]
    base = np.array(arm.base).reshape(4, 4)
    tool = np.array(arm.tool).reshape(4, 4)
    if not np.array_equal(base, np.eye(4)):
        out.append(Block("math", "{}^{W}_{0}T", matrix_of(base)))
    if not np.array_equal(tool, np.eye(4)):
        out.append(Block("math", "{}^{n}_{E}T", matrix_of(tool)))
    return out + urdf_blocks(plan)


def urdf_blocks(plan: Plan) -> list[Block]:
    """Where the arm came from, when it was converted from a URDF: the URDF joint of each
    row, the links, the snaps and the measured FK deviation."""
    origin = plan.arm.origin
    if origin is None:
        return []
    kind = origin.format
    part = "body" if kind == "MJCF" else "link"
    rows = [("row", f"{kind} joint")] + [(str(k), name) for k, name in enumerate(origin.joints, 1)]
    snaps = "; ".join(origin.snaps) if origin.snaps else "none"
    return [
        Block("h3", f"From the {kind}"),
        Block(
            "p",
            f"Converted from {origin.urdf} (sha256 {origin.sha256}...), the chain from {part} "
            f"{origin.base} to {part} {origin.tip}: base and tool frames above close it. Joint "
            f"values mean what they mean in the {kind}.",
        ),
        Block("table", rows=tuple(rows)),
        Block(
            "p",
            f"Snaps applied: {snaps}. FK of this table against the {kind}'s on 200 random joint "
            f"vectors: largest difference {origin.deviation:.2g} (rotation entries, and "
            "positions divided by the arm's size).",
        ),
    ]


def link_blocks(plan: Plan) -> list[Block]:
    """Every link transform with this arm's numbers, and 0_nT."""
    out = [
        Block("h2", "2. Link transforms"),
        Block("p", "With $c_i = \\cos\\theta_i$, $s_i = \\sin\\theta_i$:"),
    ]
    for k, link in enumerate(plan.links, start=1):
        out.append(Block("math", f"{{}}^{{{k - 1}}}_{{{k}}}T", tex(link)))
    total = sp.eye(4)
    for link in plan.links:
        total = (total * link).applyfunc(sp.expand)
    n = plan.arm.dof
    names = sp.Matrix(4, 4, lambda i, j: sp.Symbol(ENTRY_NAMES[i][j]) if i < 3 else total[i, j])
    out.append(
        Block(
            "p",
            "Their product, entry by entry (one equation per entry, so that a "
            "long one stays on its own line):",
        )
    )
    out.append(Block("math", f"{{}}^{{0}}_{{{n}}}T", tex(names)))
    out += [
        Block("math", tex(sp.Symbol(ENTRY_NAMES[i][j])), tex(total[i, j]))
        for j in range(4)
        for i in range(3)
    ]
    return out


# the names of 0_nT's top three rows: rotation entries r_ij and the position p_x, p_y, p_z
ENTRY_NAMES = (
    ("r_{11}", "r_{12}", "r_{13}", "p_{x}"),
    ("r_{21}", "r_{22}", "r_{23}", "p_{y}"),
    ("r_{31}", "r_{32}", "r_{33}", "p_{z}"),
)


def method_blocks(plan: Plan) -> list[Block]:
    """Structure, method, and the method's derivation facts."""
    out = [
        Block("h2", "3. Structure and method"),
        Block("p", "Structure found from the DH table: " + "; ".join(plan.structure) + "."),
    ]
    if plan.ik is None:
        out.append(Block("p", f"No closed-form method applies: {plan.refusal}."))
        return out
    ik = plan.ik
    out.append(
        Block(
            "p",
            f"Method: {ik.method}; case: {ik.case}. At most {ik.max_solutions} "
            f"solutions; the solver is defined on {ik.solves_for}.",
        )
    )
    if ik.free:
        out.append(
            Block(
                "p",
                f"Free joints: {ik.free_text}. The solver takes their values "
                "(`ik(T, free=...)`) and solves the other joints; in the steps below free joint "
                "$i$'s value is $qr_{i}$ (`qr` for q_ref: the solver's reference values carry "
                "it).",
            )
        )
    details = dict(ik.details)
    if "task_virtual_joint" in details:  # (derive/tasks.py)
        out += task_blocks(plan, details)
    if "tool_point_a3" in details:  # (derive/methods/position.py)
        out.append(Block("h3", "The tool point as the wrist centre"))
        out.append(
            Block(
                "p",
                "The arm controls a position: its tool point p in frame 3 (the translation of "
                "$X_3 E$) is taken as Pieper's wrist centre $^3P_{4org} = (a_3, -\\sin\\alpha_3 "
                "d_4, \\cos\\alpha_3 d_4)$, with $a_3 = p_x$, $d_4 = \\sqrt{p_y^2 + p_z^2}$ and "
                "$\\alpha_3 = \\operatorname{atan2}(-p_y, p_z)$:",
            )
        )
        for name, symbol in (("a3", "a_{3}"), ("d4", "d_{4}"), ("cos_alpha3", "\\cos\\alpha_{3}"),
                             ("sin_alpha3", "\\sin\\alpha_{3}")):  # fmt: skip
            out.append(Block("math", symbol, tex(details[f"tool_point_{name}"])))
    if "general_f1" in details:
        out.append(Block("h3", "Pieper's functions, general form (lecture, Pieper -2 to -4)"))
        for name in ("f1", "f2", "f3", "g1", "g2", "g3", "k1", "k2", "k3", "k4"):
            out.append(Block("math", f"{name[0]}_{{{name[1]}}}", tex(details[f"general_{name}"])))
        out.append(Block("h3", "With this arm's numbers"))
        out.append(Block("math", "f", tex(sp.Matrix([details[k] for k in ("f1", "f2", "f3")]))))
        out.append(Block("math", "g", tex(sp.Matrix([details[k] for k in ("g1", "g2", "g3")]))))
        for name in ("k1", "k2", "k3", "k4"):
            out.append(Block("math", f"k_{{{name[1]}}}", tex(details[name])))
        out.append(
            Block(
                "p",
                "$r = x^2 + y^2 + z^2 = 2 a_1 (k_1 c_2 + k_2 s_2) + k_3$ and "
                "$z = \\sin\\alpha_1 (k_1 s_2 - k_2 c_2) + k_4$; the case's equation, "
                "reduced with $s_3^2 = 1 - c_3^2$:",
            )
        )
        out.append(Block("math", "0", tex(details["joint3_equation"])))
    for step in ik.steps:
        if isinstance(step, Eigen):
            out += general_blocks(step)
    return out


def task_blocks(plan: Plan, details: dict[str, sp.Expr]) -> list[Block]:
    """The task's virtual joint (derive/tasks.py), lecture style."""
    assert plan.ik is not None
    n = plan.arm.dof
    v = n + 1
    axis = "xyz"[plan.ik.tool_axis]
    if plan.ik.certify == "direction":
        what = (
            f"The arm has {n} joints; the task fixes the tool point $p$ and the direction $d$ of "
            f"the tool {axis} axis, five numbers. A virtual revolute joint {v} about the tool "
            f"{axis} axis, through the tool point, turns the tool frame about that axis without "
            f"moving $p$ or the axis: the arm reaches $(p, d)$ exactly where the arm with joint "
            f"{v} reaches a pose of origin $p$ whose {axis} axis is $d$ (any such pose: the "
            f"value of joint {v} absorbs the rest). The steps below solve that arm's pose and "
            f"drop the value of joint {v}."
        )
    elif plan.ik.certify == "pointing":
        what = (
            f"The arm has {n} joints; the task fixes only the direction $d$ of the tool {axis} "
            "axis, two numbers. Lengths do not turn frames: the arm with every length 0 (every "
            "$a_i$, $d_i$ and the base's and tool's translations) turns as the arm does, and its "
            f"tool point is the origin for every $q$. Its tool {axis} axis points along $d$ "
            f"exactly where its ray from the origin passes through the point $d$: a look-at of "
            f"that arm. A virtual prismatic joint {v} slides a point along the axis from the "
            f"origin; the steps below solve that arm's position at the point $d$ (they read "
            f"the target's {axis} column where a look-at reads its position) and drop "
            f"$d_{{{v}}}$ (it is 1); a row pointing the opposite way fails the certification."
        )
    else:
        what = (
            f"The arm has {n} joints; the task asks that the tool {axis} axis, from the tool "
            f"point forward, pass through the point $p$. A virtual prismatic joint {v} slides a "
            f"point along that axis from the tool point: the arm looks at $p$ exactly where the "
            f"arm with joint {v} puts that point at $p$ with $d_{{{v}}} \\geq 0$ (the distance). "
            f"The steps below solve that arm's position and drop $d_{{{v}}}$; a row whose "
            "point lies behind the tool fails the certification."
        )
    out = [Block("h3", "The task as one more joint"), Block("p", what)]
    shift = details["task_relabel"]
    out.append(
        Block(
            "p",
            f"Joint {v} is one more DH link after joint {n}: the common normal of axis {n} and "
            f"the tool {axis} axis gives the twist and length below; the tool sits $s$ along "
            f"the axis from the normal's foot"
            + (
                f", and the normal's direction moves joint {n}'s x axis, so that $\\theta_{{{n}}}$"
                f" in the steps is the arm's plus {math.degrees(float(shift)):g} deg"
                if shift != 0
                else ""
            )
            + ":",
        )
    )
    out.append(Block("math", f"\\cos\\alpha_{{{n}}}", tex(details["task_cos_alpha"])))
    out.append(Block("math", f"\\sin\\alpha_{{{n}}}", tex(details["task_sin_alpha"])))
    out.append(Block("math", f"a_{{{n}}}", tex(details["task_a"])))
    out.append(Block("math", "s", tex(details["task_s"])))
    return out


def general_blocks(step: Eigen) -> list[Block]:
    """The general method's derivation (docs/algorithms.md, "The general 6R method", its first
    four sections): the split, the 14 equations in general form, the elimination, the matrix
    polynomial."""
    f = rr.fundamental()
    out = [
        Block("h3", "The split (Raghavan and Roth)"),
        Block(
            "p",
            "The chain is written in standard DH from the flange frame ($d_1 = d_6 = 0$, "
            "$A_6 = R_z(\\theta_6)$; lengths divided by "
            f"{number(step.unit)}), and the loop $A_1 \\cdots A_6 = F$ is split as "
            "$A_3 A_4 A_5 = A_2^{-1} A_1^{-1} F A_6^{-1}$. The third and fourth columns of "
            "both sides (a direction $l$ and a point $p$) do not involve $\\theta_6$. Two "
            "splits were measured on random poses (generating joint values found; median "
            "condition number of the pencil's leading matrix); the first is used, the second "
            "is the fallback:",
        ),
    ]
    rows = [("split", "rows (d, a, alpha [deg]) i = 1..5", "found", "cond")]
    for split in step.splits:
        table = "; ".join(
            f"({number(r[0])}, {number(r[1])}, {number(math.degrees(math.atan2(r[3], r[2])))})"
            for r in split.fill_rows[:5]
        )
        found = f"{split.recovered}/{split.poses}"
        rows.append((split.name, table, found, f"{split.cond:.2g}"))
    out.append(Block("table", rows=tuple(rows)))
    out += [
        Block("h3", "The 14 fundamental equations, general form"),
        Block(
            "p",
            "Per side: $l$ (3), $p$ (3), $p \\cdot p$, $p \\cdot l$, $p \\times l$ (3) and "
            "$v = (p \\cdot p) l - 2 (p \\cdot l) p$ (3), equated, with $s_i^2 = 1 - c_i^2$ "
            "and $\\mu_i^2 = 1 - \\lambda_i^2$ ($\\lambda_i = \\cos\\alpha_i$, "
            "$\\mu_i = \\sin\\alpha_i$) applied until no even power is left:",
        ),
        Block("math", "(P_0 + P_s s_3 + P_c c_3)\\, m_{45}", "Q\\, m_{12}"),
        Block("math", "m_{45}", tex(sp.Matrix(rr.M45).T)),
        Block("math", "m_{12}", tex(sp.Matrix(rr.M12).T)),
        Block(
            "p",
            "$P_0, P_s, P_c$ are 14 x 9 and $Q$ 14 x 8, polynomials in the DH parameters of "
            "joints 1-5 and the six numbers $l_x, l_y, l_z, p_x, p_y, p_z$ "
            f"({sum(e.count_ops() for m in (f.P0, f.Ps, f.Pc, f.Q) for e in m):,} operations "
            "in all, derived once for every arm). Their third row ($l_z$) for example:",
        ),
        Block("math", "P_0[3, :]", tex(f.P0.row(2))),
        Block("math", "Q[3, :]", tex(f.Q.row(2))),
    ]
    ops = [sum(sp.count_ops(e) for e in split.fill) for split in step.splits]
    shift4, shift5 = runtime_general._RR_SHIFT45
    out += [
        Block(
            "p",
            "With this arm's numbers the 490 entries come to "
            + " and ".join(f"{n:,}" for n in ops)
            + " operations (the splits), printed after CSE in `_rr_fill`.",
        ),
        Block("h3", "Elimination and the matrix polynomial (Manocha and Canny)"),
        Block(
            "p",
            "$N$, six rows spanning the left null space of $Q$ (from its SVD), removes "
            "$\\theta_1, \\theta_2$: $N (P_0 + P_s s_3 + P_c c_3) m_{45} = 0$. With "
            "$x_3 = \\tan(\\theta_3 / 2)$ and $x_i = \\tan((\\theta_i - \\phi_i) / 2)$ for "
            f"$i = 4, 5$ (generic shifts $\\phi_4 = {shift4}$, $\\phi_5 = {shift5}$ rad, "
            "so that $\\theta_4, \\theta_5 = \\pi$ are "
            "not at $x = \\infty$), times $(1 + x_3^2)(1 + x_4^2)(1 + x_5^2)$, "
            "$m_{45}$ becomes the monomials $x_4^i x_5^j$ ($i, j \\le 2$) and the six "
            "equations $\\Sigma_6(x_3) = A_6 x_3^2 + B_6 x_3 + C_6$ (6 x 9); stacked with "
            "$x_4 \\Sigma_6$ they give the 12 x 12 quadratic matrix polynomial "
            "$\\Sigma(x_3) v = 0$, $v = [x_4^i x_5^j]$, $i \\le 3$, $j \\le 2$. "
            "$\\det \\Sigma$ has degree 24: 16 genuine roots and 8 at $x_3 = \\pm i$. "
            "A Moebius map $x_3 = (a y + b)/(c y + d)$ keeps $\\theta_3 = \\pi$ finite; "
            "the real eigenvalues $y$ of the 24 x 24 companion matrix give $\\theta_3$ "
            "(a nearly real pair $y \\pm i \\eta$ is tried at $y \\mp \\eta$: two near-equal "
            "roots its rounding split), "
            "the null space of $\\Sigma$ at each gives $\\theta_4, \\theta_5$, and "
            "$\\theta_1, \\theta_2, \\theta_6$ follow by back-substitution; Newton "
            "steps polish every candidate and forward kinematics certifies it.",
        ),
    ]
    if step.splits[0].slide[0]:
        out.append(
            Block(
                "p",
                "Joint 3 of the split is prismatic here ($\\theta_3$ fixed at "
                f"{number(math.degrees(step.splits[0].slide[1]))} deg, $d_3$ its variable): "
                "$P_0 + P_s s_3 + P_c c_3$ at that angle is a polynomial "
                "$B_0 + B_1 d_3 + B_2 d_3^2$ ($d_3$ enters $p$ linearly), so no half-angle is "
                "taken for it: the matrices are filled as $P_0' = (B_0 + B_2)/2$, "
                "$P_s' = B_1/2$, $P_c' = (B_0 - B_2)/2$ and the eigen-variable $x_3$ is $d_3$ "
                "itself.",
            )
        )
    return out


def eigen_blocks(step: Eigen, env: dict[sp.Symbol, float]) -> list[Block]:
    """The worked example's eigenvalues: the first split's companion matrix at the pose."""
    split = step.splits[0]
    F = np.eye(4)
    for k, target in enumerate(step.args[:12]):
        F[k // 4, k % 4] = env[target]
    F[:3, 3] /= step.unit
    P0, Ps, Pc, Q = general.matrices_at(split.fill_rows, F, split.slide)
    found = runtime_general._rr_eigenvalues(P0, Ps, Pc, Q)
    if found is None:
        return [Block("p", f"The pencil of {split.name} is singular at this pose.")]
    values, _, (a, b, c, d) = found
    real = sorted(v.real for v in values if abs(v.imag) <= 1e-6 * (1 + abs(v)))
    if split.slide[0]:
        lengths = [(a * y + b) / (c * y + d) * step.unit for y in real if c * y + d != 0.0]
        return [
            Block(
                "p",
                f"The companion matrix of {split.name} at this pose has {len(values)} "
                f"eigenvalues, {len(real)} of them real (y, with d3 = ({a:g} y + {b:g}) / "
                f"({c:g} y + {d:g}) times {number(step.unit)}); d3 from each:",
            ),
            Block("math", "y", ", ".join(number(y) for y in real)),
            Block("math", "d_3", ", ".join(number(t) for t in lengths)),
        ]
    thetas = [math.degrees(2 * math.atan2(a * y + b, c * y + d)) for y in real]
    known = len(split.spurious[0]) if split.spurious else 0
    deflated = (
        [
            Block(
                "p",
                f"{known} of the {len(values)} are known before the pose is: at "
                "$x_3 = \\pm i$, where the half-angle substitution's factor $1 + x_3^2$ "
                "vanishes, $P_0 (1 + x_3^2) + 2 P_s x_3 + P_c (1 - x_3^2)$ is "
                "$2 (P_c \\pm i P_s)$, which does not depend on the pose, and the lifted "
                f"12 x 12 matrix has {known // 2} null vectors $v$ there for every pose. The "
                "solver takes the invariant subspace spanned by $[v; y_+ v]$ out of the "
                "companion matrix (Householder reflections on both sides) "
                f"and computes the other {len(values) - known} eigenvalues only.",
            )
        ]
        if known
        else []
    )
    return [
        Block(
            "p",
            f"The companion matrix of {split.name} at this pose has {len(values)} eigenvalues, "
            f"{len(real)} of them real (y, with x3 = ({a:g} y + {b:g}) / ({c:g} y + {d:g})); "
            "theta3 from each, in degrees:",
        ),
        Block("math", "y", ", ".join(number(y) for y in real)),
        Block("math", "\\theta_3 / ^\\circ", ", ".join(number(t) for t in thetas)),
        *deflated,
    ]


def step_blocks(plan: Plan) -> list[Block]:
    """Every step of the plan as the equation it solves, in order."""
    assert plan.ik is not None
    out = [
        Block("h2", "4. The solution, step by step"),
        Block(
            "p",
            "Each step below is one block of the generated `ik`; a step that solves a "
            "joint is a loop over its values.",
        ),
    ]
    for step in plan.ik.steps:
        out.append(Block("h3", step.note))
        if isinstance(step, Assign):
            for target, expr in zip(step.targets, step.exprs):
                out.append(Block("math", tex(target), tex(expr)))
            continue
        if isinstance(step, Eigen):
            out.append(Block("math", "(P_0 + P_s s_3 + P_c c_3)\\, m_{45}", "Q\\, m_{12}"))
            continue
        for lhs, rhs in solve_equations(step):
            out.append(Block("math", lhs, rhs))
    return out


def joint_symbol(step: Solve) -> sp.Symbol:
    """theta_j, or d_j for a prismatic joint's step."""
    return sym.d(step.joint) if step.kind == "polyd" else sym.theta(step.joint)


def solve_equations(step: Solve) -> list[tuple[str, str]]:
    """The equation(s) a Solve step solves, as (lhs, rhs) LaTeX pairs."""
    t = joint_symbol(step)
    c, s = sp.cos(t), sp.sin(t)
    a = step.args
    if step.kind in ("cs1", "cs1r"):
        return [(tex(a[0] * c + a[1] * s), tex(a[2]))]
    if step.kind in ("cs2", "cs2r"):
        return [(tex(a[0] * c + a[1] * s), tex(a[2])), (tex(a[3] * c + a[4] * s), tex(a[5]))]
    if step.kind == "atan2":
        return [(tex(sp.tan(t)), tex(a[0] / a[1]))]
    var = sym.named("u") if step.kind in ("poly", "polypi") else t
    degree = len(a) - 1
    out = [(tex(sum(cf * var ** (degree - k) for k, cf in enumerate(a))), "0")]
    if step.kind == "polypi":  # (divided by u^2: a quadratic in w = u - 1/u)
        w = sym.named("w")
        out.append((tex(a[0] * w**2 + a[1] * w + a[2] + 2 * a[0]), "0"))
    return out


def walk(plan: Plan, pose: np.ndarray, q: tuple[float, ...]) -> list[tuple[str, str]]:
    """Every intermediate number of the plan along the branch of solution q.

    Assignments are evaluated in order; each Solve step takes its joint's value from q (the
    solver's own result), so the numbers shown are the ones the solver computed.
    """
    assert plan.ik is not None
    env: dict[sp.Symbol, float] = {}
    world = sym.world_pose()
    for i in range(3):
        for j in range(4):
            env[world[i, j]] = float(pose[i, j])
    values = plan_values(plan, q)
    env |= free_values(values)
    lines = []
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            for target, expr in zip(step.targets, step.exprs):
                env[target] = float(expr.xreplace(env))
                lines.append((tex(target), number(env[target])))
            continue
        if isinstance(step, Eigen):
            for k, kind in zip(step.indices, step.kinds):  # the solution's, from the eigen-solve
                # (a task's virtual joint, or the arm's joint playing it, is not among q's
                # values: read from the target, derive/tasks.py)
                t = sym.d(k) if kind == "P" else sym.theta(k)
                env[t] = values[t] if t in values else virtual_value(plan, q, env)
                if kind == "P":
                    lines.append((tex(t), number(env[t])))
                else:
                    lines.append((f"{tex(t)} / ^\\circ", number(math.degrees(env[t]))))
            continue
        args = [float(a.xreplace(env)) for a in step.args]
        shown = ", ".join(number(x) for x in args)
        t = joint_symbol(step)
        value = values[t] if t in values else virtual_value(plan, q, env)
        env[t] = value
        if step.kind != "polyd":
            env[sym.c(step.joint)], env[sym.s(step.joint)] = math.cos(value), math.sin(value)
            lines.append(
                (
                    f"{tex(t)} / ^\\circ\\ (\\text{{{step.kind}}}: {shown})",
                    number(math.degrees(value)),
                )
            )
        else:
            lines.append((f"{tex(t)}\\ (\\text{{{step.kind}}}: {shown})", number(value)))
    return lines


def virtual_value(plan: Plan, q: tuple[float, ...], env: dict[sp.Symbol, float]) -> float:
    """A task's virtual joint's value on the branch of solution q (derive/tasks.py), from the
    world pose and the arm's joints (their c_i, s_i or d_i by the plan's joint definitions:
    the steps may number a reversed chain's joints otherwise)."""
    assert plan.ik is not None and plan.ik.virtual
    known = {k: v for k, v in env.items() if k in set(sym.world_pose())}
    for target, expr in plan.joint_defs:
        value = float(expr.xreplace({sym.q(k + 1): q[k] for k in range(len(q))}))
        known[target] = value
        if str(target).startswith("theta"):
            k = int(str(target)[5:])
            known[sym.c(k)], known[sym.s(k)] = math.cos(value), math.sin(value)
    numbers = [float(e.xreplace(known)) for e in plan.ik.virtual]
    return math.atan2(numbers[1], numbers[0]) if len(numbers) == 2 else numbers[0]


def assigned(plan: Plan, pose: np.ndarray, q: tuple[float, ...]) -> dict[sp.Symbol, float]:
    """The values of the plan's assignments at the pose (world entries included), the free
    joints (if any) at solution q's values."""
    assert plan.ik is not None
    world = sym.world_pose()
    env = {world[i, j]: float(pose[i, j]) for i in range(3) for j in range(4)}
    env |= free_values(plan_values(plan, q))
    for step in plan.ik.steps:
        if isinstance(step, Assign):
            for target, expr in zip(step.targets, step.exprs):
                env[target] = float(expr.xreplace(env))
    return env


def free_values(values: dict[sp.Symbol, float]) -> dict[sp.Symbol, float]:
    """Of plan_values, the free joints' values (qr_i: the solver's input)."""
    return {k: v for k, v in values.items() if k.name.startswith("qr")}


def plan_values(plan: Plan, q: tuple[float, ...]) -> dict[sp.Symbol, float]:
    """The plan's joint symbols (theta_j / d_j of possibly reversed chains) for a solution q."""
    assert plan.ik is not None
    values = {}
    for qi, out in zip(q, plan.ik.outputs):
        (var,) = sorted(out.free_symbols, key=sp.default_sort_key)
        coeff = out.coeff(var)
        values[var] = float((qi - out.xreplace({var: 0})) / coeff)
    return values


def example_blocks(plan: Plan, example: Example) -> list[Block]:
    """The worked example: pose, flange target, one branch's numbers, all solutions."""
    arm = plan.arm
    pose = np.array(example.pose).reshape(4, 4)
    base, tool = np.array(arm.base).reshape(4, 4), np.array(arm.tool).reshape(4, 4)
    flange = np.linalg.inv(base) @ pose @ np.linalg.inv(tool)
    out = [
        Block("h2", "5. Worked example"),
        Block("p", f"The target is {example.how}:"),
        Block("math", "T", matrix_of(pose)),
        Block(
            "math",
            f"{{}}^{{0}}_{{{arm.dof}}}T = ({{}}^{{W}}_{{0}}T)^{{-1}} T "
            f"({{}}^{{{arm.dof}}}_{{E}}T)^{{-1}}",
            matrix_of(flange),
        ),
    ]
    if plan.ik is None:
        return out
    if not example.solutions:
        out.append(Block("p", "The pose is out of reach: no solution."))
        return out
    first = example.solutions[0]
    out.append(
        Block(
            "p",
            "Every intermediate quantity along the first solution's branch "
            "(solve steps show their numeric arguments):",
        )
    )
    out += [Block("math", lhs, rhs) for lhs, rhs in walk(plan, pose, first)]
    for step in plan.ik.steps:
        if isinstance(step, Eigen):
            out += eigen_blocks(step, assigned(plan, pose, first))
    if arm.dof == 6:
        out += wrist_matrices(plan, first, flange)
    rows = [
        (
            "#",
            *tuple(
                f"q{k + 1}" + (" [deg]" if t == "R" else "") for k, t in enumerate(arm.joint_types)
            ),
        )
    ]
    for n, sol in enumerate(example.solutions, start=1):
        rows.append(
            (
                str(n),
                *tuple(
                    number(math.degrees(v)) if t == "R" else number(v)
                    for v, t in zip(sol, arm.joint_types)
                ),
            )
        )
    out.append(
        Block("p", f"All {len(example.solutions)} solutions, each certified by forward kinematics:")
    )
    out.append(Block("table", rows=tuple(rows)))
    return out


def wrist_matrices(plan: Plan, q: tuple[float, ...], flange: np.ndarray) -> list[Block]:
    """0_3R and 3_6R = 0_3R^T 0_6R at solution q (lecture, Pieper -5)."""
    subs = {}
    for k, ((_, expr), kind) in enumerate(zip(plan.joint_defs, plan.arm.joint_types)):
        value = float(expr.xreplace({sym.q(k + 1): q[k]}))
        if kind == "R":
            subs[sym.c(k + 1)], subs[sym.s(k + 1)] = math.cos(value), math.sin(value)
        else:
            subs[sym.d(k + 1)] = value
    t03 = sp.eye(4)
    for link in plan.links[:3]:
        t03 = t03 * link
    r03 = np.array(t03[:3, :3].xreplace(subs).evalf(), dtype=float)
    return [
        Block("math", "{}^{0}_{3}R", matrix_of(r03)),
        Block(
            "math", "{}^{3}_{6}R = ({}^{0}_{3}R)^T {}^{0}_{6}R", matrix_of(r03.T @ flange[:3, :3])
        ),
    ]


def correction_blocks(plan: Plan) -> list[Block]:
    """Where the closed form solves a nominal table near the arm's: the two tables, how far
    apart, and the correction step (derive/nominal.py)."""
    fix = plan.correction
    if fix is None:
        return []
    header = ("i", "alpha exact [deg]", "alpha nominal", "a exact", "a nominal", "d exact",
              "d nominal")  # fmt: skip
    rows = [header]
    for i, (exact, near) in enumerate(zip(plan.arm.dh, fix.nominal_dh), start=1):
        rows.append(
            (
                str(i),
                f"{math.degrees(exact[0]):.6g}",
                f"{math.degrees(near[0]):g}",
                f"{exact[1]:.6g}",
                f"{near[1]:g}",
                f"{exact[2]:.6g}",
                f"{near[2]:g}",
            )
        )
    return [
        Block("h3", "The nominal table, and the correction onto the exact one"),
        Block(
            "p",
            (
                "This arm's table is not exactly special, and no closed form solves it. Within "
                f"the structure tolerance {fix.tol:g} (twists in radians, lengths as a fraction "
                f"of the arm's size) it is near one that is: snapping {len(fix.changes)} "
                "parameters gives the nominal table below, and the method above is the nominal "
                "table's."
                if fix.changes
                else "This arm's exact geometry is its URDF's, kept in the spec as [exact] "
                "frames; the table, fitted to it with the URDF's rounding snapped (section 1), "
                "is the nominal one the method above solves."
            )
            + " The forward kinematics of the two differ by up to "
            f"{fix.deviation:.2g} (rotation entries; positions divided by the reach).",
        ),
        *([Block("table", rows=tuple(rows))] if fix.changes else []),
        Block(
            "p",
            "Every nominal solution is a seed: Newton's steps on the exact chain, damped by "
            "the error's square, bring it onto this arm, and only what reproduces the pose on "
            "the exact chain is returned. With e the pose error (position difference over the "
            "reach; rotation error half the sum of the cross products of the current and "
            "target rotation's columns) and J the geometric Jacobian of the exact chain:",
        ),
        Block("math", "q_{k+1}", "q_k + (J^T J + |e|^2 I)^{-1} J^T e"),
        Block(
            "p",
            "Where an equation of the nominal arm just misses (an acos argument above 1 by at "
            f"most {fix.seed_tol:.2g}, a double root split off the real line by at most "
            f"{math.sqrt(fix.seed_tol):.2g}) its boundary value still seeds a refinement: the "
            "exact arm may reach what the nominal one does not.",
        ),
    ]


def report_blocks(plan: Plan, example: Example) -> tuple[Block, ...]:
    """All blocks of the report, in order."""
    blocks = arm_blocks(plan) + link_blocks(plan) + method_blocks(plan)
    blocks += correction_blocks(plan)
    if plan.ik is not None:
        blocks += step_blocks(plan)
    return tuple(blocks + example_blocks(plan, example))


TEX_SPECIALS = {
    "\\": "\\textbackslash{}",
    "_": "\\_",
    "^": "\\^{}",
    "#": "\\#",
    "%": "\\%",
    "&": "\\&",
    "{": "\\{",
    "}": "\\}",
    "~": "\\~{}",
}


def latex_text(text: str) -> str:
    """Text for LaTeX: specials escaped outside $...$ (inline math is kept as it is)."""
    parts = text.split("$")
    for k in range(0, len(parts), 2):
        parts[k] = "".join(TEX_SPECIALS.get(ch, ch) for ch in parts[k])
    return "$".join(parts)


# a table with a row longer than this (characters) is scaled to the text width
TEX_TABLE = 120
# a displayed equation's right-hand side longer than this (LaTeX source characters; about a
# line of a page with 2 cm margins) is broken at its top-level + and - signs
TEX_LINE = 110


def break_sum(math: str, width: int = TEX_LINE) -> tuple[str, ...]:
    """LaTeX math split at its top-level + and - signs and commas (outside braces and
    \\left ... \\right) into pieces of about width characters; a sign starts the next piece,
    a comma ends its own."""
    cuts = []
    depth = 0
    k = 0
    while k < len(math):
        if math.startswith("\\left", k):
            depth += 1
            k += 5
            continue
        if math.startswith("\\right", k):
            depth -= 1
            k += 6
            continue
        ch = math[k]
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        elif depth == 0 and ch in "+-" and k > 0 and math[k - 1] == " ":
            cuts.append(k)
        elif depth == 0 and ch == "," and math.startswith(", ", k):
            cuts.append(k + 2)
        k += 1
    pieces: list[str] = []
    start = 0
    for at in cuts:
        if at - start >= width:
            pieces.append(math[start:at].rstrip())
            start = at
    pieces.append(math[start:])
    return tuple(p for p in pieces if p)


NoteReplacement = str | Callable[[re.Match[str]], str]
# the plan's notes write maths in plain text ("0_3R", "Rx(alpha4)", "theta3", "x^2 + y^2");
# in LaTeX headings these pieces become inline math: (pattern, replacement) in order
NOTE_MATH = (
    (r"\b0P_4org\b", r"{}^{0}P_{4\,org}"),
    (r"\b(\d|n)_(\d|n)([RT])\b", r"{}^{\1}_{\2}\3"),
    (r"\bR([xyz])\(", lambda m: f"R_{m.group(1).upper()}("),
    (r"\bT([xyz])\(", lambda m: f"T_{m.group(1)}("),
    (r"\b(theta|alpha)(\d)\b", r"\\\1_{\2}"),
    (r"\bt(\d)\b", r"\\theta_{\1}"),
    (r"\b([csgkvdxq])(\d|n)\b", r"\1_{\2}"),
    (r"\bW(\d)(\d)\b", r"W_{\1\2}"),
    (r"\be3\b", r"e_3"),
    (r"\b([XZ])(\d|n)\b", r"\1_{\2}"),
    (r"\^-1\b", r"^{-1}"),
)


def note_tex(note: str) -> str:
    """A plan note for a LaTeX heading: its maths pieces as inline math, the rest escaped."""
    pieces: list[str] = []

    def keep(match: re.Match[str], replacement: NoteReplacement) -> str:
        """The match kept aside as inline math; a placeholder in its place."""
        text = replacement(match) if callable(replacement) else match.expand(replacement)
        pieces.append(f"${text}$")
        return f"\x00{len(pieces) - 1}\x00"

    out = note
    for pattern, replacement in NOTE_MATH:
        out = re.sub(pattern, partial(keep, replacement=replacement), out)
    # x^2, ^T and the like
    out = re.sub(r"\^(\w+)", lambda m: keep(m, r"^{\1}"), out)
    text = latex_text(out)
    text = re.sub("\x00(\\d+)\x00", lambda m: pieces[int(m.group(1))], text)
    return text.replace("$$", "")  # adjacent pieces: one inline formula


def for_tex(block: Block) -> Block:
    """A block whose plain text is escaped for LaTeX; a long equation broken into lines
    (kind "lines": rows of one piece each)."""
    if block.kind == "math" and len(block.math) > TEX_LINE:
        pieces = break_sum(block.math)
        if len(pieces) > 1:
            return Block("lines", block.text, rows=tuple((p,) for p in pieces))
    if block.kind == "math" and len(block.text) > TEX_LINE:  # a long left-hand side
        pieces = break_sum(block.text)
        if len(pieces) > 1:
            lines = (*pieces[:-1], f"{pieces[-1]} = {block.math}")
            return Block("lines", "", rows=tuple((p,) for p in lines))
    if block.kind == "table" and max(len(" & ".join(r)) for r in block.rows) > TEX_TABLE:
        rows = tuple(tuple(latex_text(c) for c in r) for r in block.rows)
        return Block("widetable", rows=rows)
    if block.kind == "h3":
        return Block("h3", note_tex(block.text))
    if block.kind in ("h2", "p"):
        return Block(block.kind, latex_text(block.text))
    if block.kind == "image":
        return Block("image", latex_text(block.text), block.math)
    if block.kind == "table":
        return Block("table", rows=tuple(tuple(latex_text(c) for c in r) for r in block.rows))
    return block


def render_report(
    plan: Plan, example: Example, fmt: str = "md", figures: tuple[tuple[str, str], ...] = ()
) -> str:
    """The report as Markdown ("md") or a standalone LaTeX document ("tex"); figures:
    (caption, file name) pairs shown in a last section."""
    blocks = report_blocks(plan, example)
    if figures:
        blocks += (Block("h2", "6. Figures"),)
        blocks += tuple(Block("image", caption, name) for caption, name in figures)
    if fmt == "tex":
        blocks = tuple(for_tex(b) for b in blocks)
    template = environment().get_template(f"report.{fmt}.j2")
    return template.render(
        name=plan.arm.name,
        name_tex=latex_text(plan.arm.name),
        digest=plan.arm.digest,
        generator=GENERATOR,
        blocks=blocks,
    )
