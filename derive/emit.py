"""plan -> printed IR (CSE, printing) -> jinja2 render.

The printed IR holds only ``str``, ``int`` and tuples of them; templates loop over it and
do nothing else. Printing is deterministic: numbers print as Python float literals (the
shortest repr), terms in SymPy's canonical order, CSE with ``order="canonical"`` and a fresh
``x0, x1, ...`` stream per function.
"""

from __future__ import annotations

import ast
import hashlib
import math
import re
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

import jinja2
import sympy as sp

from derive import symbols as sym
from derive import tasks
from derive.assemble import (
    RUNTIME_FILE,
    all_order,
    assemble,
    import_block,
    import_order,
    runtime_source,
)
from derive.layout import wrap_code
from derive.plan import Assign, Plan
from derive.printers import branches, scalar
from derive.printers.common import (
    SCALAR_FUNCTIONS,
    CodePrinter,
    UnprintableError,
    assign_lines,
    cs_arguments,
    float_literal,
    match_expression,
    used_joints,
)
from derive.printers.general import general_code

GENERATOR = "derive-ik"
REGENERATE = "derive generate"


class GenerationError(ValueError):
    """The plan holds something the generated code cannot evaluate; the message (one line)
    names the arm, the step and what is missing."""


def check_printable(plan: Plan) -> None:
    """Every expression of the plan prints in scalar and vectorised (forward kinematics) code, or a
    GenerationError names the arm, the step and the function (before any code is written)."""
    parts: list[tuple[str, tuple[sp.Basic, ...]]] = [("forward kinematics", tuple(plan.fk_pose))]
    for step in plan.ik.steps if plan.ik else ():
        exprs = step.exprs if isinstance(step, Assign) else (*step.args, step.ref)
        parts.append((step.note, tuple(exprs)))
    for where, exprs in parts:
        for printer in (CodePrinter(), CodePrinter("np.")):
            try:
                for call in _calls(exprs):
                    printer.doprint(call)
            except UnprintableError as exc:
                raise GenerationError(
                    f"{plan.arm.name}: {where}: the generated code has no function {exc}; "
                    f"it calls only {', '.join(sorted(SCALAR_FUNCTIONS))}"
                ) from None


def _calls(exprs: tuple[sp.Basic, ...]) -> list[sp.Basic]:
    """The function applications in exprs, each once: a walk over the expressions' graph,
    not their trees (a URDF's dense frames multiply into entries whose trees are exponential
    in the joints, while their graphs stay small)."""
    seen: set[int] = set()
    calls: dict[sp.Basic, None] = {}
    stack = list(exprs)
    while stack:
        node = stack.pop()
        if id(node) in seen:
            continue
        seen.add(id(node))
        if isinstance(node, sp.Function):
            calls[node.func(*(sp.Dummy() for _ in node.args))] = None
        stack.extend(node.args)
    return list(calls)


def fk_pose_lines(plan: Plan) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Body of _fk_from_cs: the CSE'd pose entries in c_i, s_i (and d_i of prismatic joints).

    The lines hold only arithmetic, so the same text serves scalars and numpy arrays.

    Returns:
        (the lines, the 12 names holding the top three rows of the pose).
    """
    pose = plan.fk_pose
    entries = [pose[i, j] for i in range(3) for j in range(4)]
    targets = tuple(sym.named(f"t{i}{j}") for i in range(3) for j in range(4))
    lines = [ln.text for ln in assign_lines(targets, tuple(entries), "x", CodePrinter(), 0)]
    return tuple(lines), tuple(str(t) for t in targets)


def jacobian_lines(plan: Plan) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Body of _jacobian_q: theta_i (c_i, s_i) from q, then the CSE'd Jacobian entries
    (derive/jacobian.py), and the 6 n names holding them, row-major."""
    J = plan.jacobian
    n = plan.arm.dof
    targets = tuple(sym.named(f"j{i}_{j}") for i in range(6) for j in range(n))
    if J is None:  # (exact frames: the chain's, at run time)
        return (f"({', '.join(map(str, targets))},) = _chain_jacobian(q)",), tuple(
            str(t) for t in targets
        )
    entries = [J[i, j] for i in range(6) for j in range(n)]
    printer = CodePrinter()
    head = []
    for k, target, expr, turns in used_joints(plan, J.free_symbols):
        head.append(
            f"{target} = {printer.doprint(expr.xreplace({sym.q(k + 1): sp.Symbol(f'q[{k}]')}))}"
        )
        if turns:
            head += [f"c{k + 1} = cos({target})", f"s{k + 1} = sin({target})"]
    lines = [ln.text for ln in assign_lines(targets, tuple(entries), "x", printer, 0)]
    return (*head, *lines), tuple(str(t) for t in targets)


def fk_joint_lines(plan: Plan, printer: CodePrinter, columns: bool) -> tuple[str, ...]:
    """theta_i = q_i + offset with c_i, s_i (or d_i = q_i + offset) from q or from Q's columns."""
    lines = []
    for k, (target, expr) in enumerate(plan.joint_defs):
        source = sp.Symbol(f"Q[..., {k}]" if columns else f"q[{k}]")
        lines.append(f"{target} = {printer.doprint(expr.xreplace({sym.q(k + 1): source}))}")
        if str(target).startswith("theta"):
            i = k + 1
            lines.append(f"c{i} = {printer.prefix}cos({target})")
            lines.append(f"s{i} = {printer.prefix}sin({target})")
    return tuple(lines)


@dataclass(frozen=True)
class PrintedModule:
    """Everything the module template needs, as strings and ints."""

    name: str
    digest: str
    convention: str
    length_unit: str
    joint_types: str
    dof: int
    structure: tuple[str, ...]
    dh_table: tuple[str, ...]
    dh_const: str
    limits_const: str
    offsets_const: str
    revolute_const: str
    base_const: str
    tool_const: str
    reach: str
    fk_pose_body: tuple[str, ...]
    jacobian_body: tuple[str, ...]
    jacobian_outputs: tuple[str, ...]
    fk_joints: tuple[str, ...]
    fk_batch_joints: tuple[str, ...]
    fk_outputs: tuple[str, ...]
    cs_args: str
    has_ik: int
    method: str
    case: str
    max_solutions: int
    solves_for: str
    refusal: str
    ik_body: tuple[tuple[int, str], ...]
    # _branch_signs's body and BRANCHES (printers/branches.py, printed by printers/scalar.py)
    branch_body: tuple[tuple[int, str], ...]
    branches_const: str
    qref_names: str
    match: str
    components: str
    general: str
    c_source: str
    free: tuple[int, ...]
    free_const: str
    free_text: str
    seed_tol: str
    correction: str
    correction_doc: str
    tool_axis: int = 2
    cone_axis: int = 2
    task_doc: str = ""
    # a planar arm's plane task (derive/tasks.py, Plane): "xy_heading", "xy" or ""; its
    # constants; whether the caller gives z
    plane: str = ""
    plane_constants: str = ""
    plane_slide: bool = False


def print_plan(plan: Plan) -> PrintedModule:
    """The printed IR of a plan.

    Raises:
        GenerationError: an expression holds a function the generated code cannot call.
    """
    check_printable(plan)
    arm = plan.arm
    python, numpy = CodePrinter(), CodePrinter("np.")
    fk_pose_body, outputs = fk_pose_lines(plan)
    jacobian_body, jacobian_outputs = jacobian_lines(plan)
    ik = plan.ik
    offsets = tuple(float(e.subs(sym.q(k + 1), 0)) for k, (_, e) in enumerate(plan.joint_defs))
    return PrintedModule(
        name=arm.name,
        digest=arm.digest,
        convention=arm.convention,
        length_unit=arm.length_unit,
        joint_types=arm.joint_types,
        dof=arm.dof,
        structure=plan.structure,
        dh_table=dh_table(plan),
        dh_const=_tuple_of_tuples(arm.dh),
        limits_const=_tuple_of_tuples(arm.limits),
        offsets_const=_tuple(offsets),
        revolute_const=_tuple(tuple(k == "R" for k in arm.joint_types)),
        base_const=_tuple_of_tuples(tuple(arm.base[4 * i : 4 * i + 4] for i in range(4))),
        tool_const=_tuple_of_tuples(tuple(arm.tool[4 * i : 4 * i + 4] for i in range(4))),
        reach=float_literal(arm.reach),
        fk_pose_body=fk_pose_body,
        jacobian_body=jacobian_body,
        jacobian_outputs=jacobian_outputs,
        fk_joints=fk_joint_lines(plan, python, columns=False),
        fk_batch_joints=fk_joint_lines(plan, numpy, columns=True),
        fk_outputs=outputs,
        cs_args=cs_arguments(plan),
        has_ik=int(ik is not None),
        method=ik.method if ik else "",
        case=ik.case if ik else "",
        max_solutions=ik.max_solutions if ik else 0,
        solves_for=ik.solves_for if ik else "",
        refusal=plan.refusal,
        ik_body=scalar.ik_lines(plan) if ik else (),
        branch_body=scalar.branch_lines(plan) if ik else (),
        branches_const=repr(branches.branch_names(plan)) if ik else "()",
        qref_names=", ".join(f"qr{i}" for i in range(1, arm.dof + 1)),
        match=match_expression(ik.certify, ik.tool_axis, ik.cone) if ik else "",
        tool_axis=ik.tool_axis if ik else 2,
        cone_axis=ik.cone if ik else 2,
        components=ik.certify if ik else "",
        general=general_code(plan),
        c_source=repr(f"{arm.name}_ik.c" if ik else ""),
        free=ik.free if ik else (),
        free_const=repr(ik.free) if ik else "()",
        free_text=ik.free_text if ik else "",
        seed_tol=repr(plan.correction.seed_tol) if plan.correction else "0.0",
        correction=correction_constants(plan),
        correction_doc=correction_text(plan),
        task_doc=task_text(plan),
        **plane_fields(plan),
    )


def plane_fields(plan: Plan) -> dict[str, Any]:
    """The plane task's fields of PrintedModule (none where the arm has none)."""
    ik = plan.ik
    plane = None
    if ik is not None:
        plane = tasks.plane_of(plan.frames, plan.arm.joint_types, ik.method, ik.certify)
    if plane is None:
        return {}
    return {
        "plane": "xy_heading" if plane.heading else "xy",
        "plane_slide": plane.slide,
        "plane_constants": (
            f"# the plane task ({plane.ikfast}, derive/tasks.py Plane): the tool's rotation at\n"
            "# q = 0 (row-major), the tool axis whose angle about z is the heading (0 x, 1 y)\n"
            "# and that angle at q = 0, the tool point's height at q = 0 (PLANE_Z: every\n"
            "# height without a sliding joint), whether a sliding joint moves it along z\n"
            f"_PLANE_ROTATION = {_tuple(plane.rotation)}\n"
            f"HEADING_AXIS = {plane.axis}\n"
            f"_HEADING_ZERO = {plane.zero!r}\n"
            f"PLANE_Z = {plane.height!r}\n"
            f"_PLANE_SLIDE = {plane.slide!r}\n"
        ),
    }


def task_text(plan: Plan) -> str:
    """The module docstring's paragraph on a task of fewer components than a pose
    (derive/tasks.py), "" for the methods' own problems."""
    ik = plan.ik
    plane = (
        None
        if ik is None
        else tasks.plane_of(plan.frames, plan.arm.joint_types, ik.method, ik.certify)
    )
    if plane is not None:
        call = "ik_xy_heading(x, y, heading" if plane.heading else "ik_xy(x, y"
        return (
            f"The task ({plane.ikfast}): every joint axis is along the world's z, so "
            f"`{call}{', z' if plane.slide else ''})` builds the pose it names (the tool's "
            "rotation at q = 0 turned about z"
            + (
                " to put the tool axis HEADING_AXIS at the heading from the world's x"
                if plane.heading
                else ""
            )
            + (
                ", the tool point at height z: a sliding joint moves it"
                if plane.slide
                else ", the tool point in the plane z = PLANE_Z"
            )
            + ") and solves it with ik."
        )
    if ik is not None and ik.certify == "axisangle":
        return (
            f"The task: the arm has {plan.arm.dof} joints; its solver is derived for "
            f"{ik.solves_for} (IK_COMPONENTS, TOOL_AXIS, CONE_AXIS): joint 1 turns about "
            "that base axis, so the tool axis's component along it depends on joints 2-4 "
            "only, which turn about parallel axes by one angle phi (derive/methods/cone.py)"
            + (", and the wrist roll's value is the caller's (FREE)" if ik.free else "")
            + ". `ik(T)` reads only T's position and the entry of its column TOOL_AXIS along "
            "CONE_AXIS (the angle's cosine); every row reproduces them."
        )
    if ik is None or ik.certify not in ("direction", "lookat", "pointing"):
        return ""
    reads = {
        "direction": "position and its column TOOL_AXIS",
        "lookat": "position (the point looked at)",
        "pointing": "column TOOL_AXIS (the direction)",
    }[ik.certify]
    details = dict(ik.details)
    if "task_spun_joint" in details:
        n = int(details["task_spun_joint"])
        how = (
            f"from the arm's own pose: joint {n} turns about the tool axis through the tool point "
            f"(it moves neither), so it plays the part of a virtual joint and its value is the "
            "caller's (FREE)"
        )
    elif ik.certify == "pointing":
        how = (
            "as a look-at of the arm with every length 0 (its orientations, its tool point the "
            "origin) at the point d, with one more, virtual, joint sliding along the tool axis "
            "(derive/tasks.py), whose value is dropped"
        )
    else:
        how = (
            "as a pose or a position of the arm with one more, virtual, joint (derive/tasks.py), "
            "whose value is dropped"
        )
    fewer = "fewer than a pose needs" if plan.arm.dof < 6 else "more than the task needs"
    return (
        f"The task: the arm has {plan.arm.dof} joints, {fewer}; its solver is derived for "
        f"{ik.solves_for} (IK_COMPONENTS, TOOL_AXIS), {how}. `ik(T)` reads only T's {reads}; "
        "every row reproduces them."
    )


def correction_constants(plan: Plan) -> str:
    """The exact chain and the joints its Newton steps move (ik_approximate's, and the
    refinement of a closed form that solves a nominal table: derive/nominal.py), with the
    nominal table where there is one; the chain only without IK (link_transform's)."""
    chain = (
        "# the exact chain: T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n, J_i = Rz(q_i) (R) or\n"
        "# Tz(q_i) (P); each F_i's top three rows, row-major\n"
        f"_CHAIN = {_frames_literal(plan.frames)}\n"
    )
    if plan.ik is None:
        return chain
    fix = plan.correction
    nominal = ""
    if fix is not None:
        nominal = (
            "# the closed form solves this nominal table (alpha, a, d, theta), radians; its\n"
            "# answers are refined onto the exact chain below (derive/nominal.py)\n"
            f"NOMINAL_DH = {_tuple_of_tuples(fix.nominal_dh)}\n"
            "# the largest FK difference of the nominal arm from this one (rotation entries;\n"
            "# positions / REACH)\n"
            f"NOMINAL_DEVIATION = {fix.deviation:.3g}\n"
        )
    return (
        nominal
        + chain
        + (
            "# the joints (0-based) Newton's steps on it move (free joints keep the caller's\n"
            "# values)\n"
            f"_SOLVED = {plan.solved!r}\n"
        )
    )


def _frames_literal(frames: tuple[tuple[float, ...], ...]) -> str:
    """Frames of 12 numbers as a tuple literal, each frame's rows on lines of their own (the
    module stays within 100 columns)."""
    out = ["("]
    for frame in frames:
        out.append("    (")
        for r in range(3):
            out.append("        " + " ".join(f"{_tuple(frame[4 * r : 4 * r + 4])[1:-1]},".split()))
        out.append("    ),")
    out.append(")")
    return "\n".join(out)


def correction_text(plan: Plan) -> str:
    """The module docstring's paragraph on the refinement, "" where there is none."""
    fix = plan.correction
    if fix is None:
        return ""
    return (
        "Exact answers from a nominal table: the solver above solves NOMINAL_DH "
        + (
            f"(the table snapped within the structure tolerance {fix.tol:g}: "
            f"{len(fix.changes)} parameters)"
            if fix.changes
            else "(the table above, fitted to the URDF's frames)"
        )
        + ", whose forward kinematics differ from this arm's exact chain (_CHAIN) by up to "
        f"NOMINAL_DEVIATION = {fix.deviation:.2g}. Newton's steps refine every solution onto "
        "_CHAIN; fk, and the certification of every row, are the exact chain's. Rows keep the "
        "nominal arm's branch order. An arm this close to a special one can have more real "
        "solutions than it near some poses. Where a nominal equation fixes a joint only "
        "roughly (two links of nearly equal length folded back), seeds all round find them "
        "(up to 16 rows); elsewhere those the nominal arm lacks are not returned (the general "
        'method gives the complete set, slower: [ik] method = "general" in the spec, or '
        "--method general with a URDF or MJCF)."
    )


def _tuple(values: tuple[float | bool, ...]) -> str:
    def one(v: float | bool) -> str:
        if isinstance(v, bool):
            return repr(v)
        if math.isinf(float(v)):
            return "math.inf" if float(v) > 0 else "-math.inf"
        return repr(float(v))

    inner = ", ".join(one(v) for v in values)
    return f"({inner},)" if len(values) == 1 else f"({inner})"


def _tuple_of_tuples(rows: tuple) -> str:
    return "(\n" + "".join(f"    {_tuple(tuple(r))},\n" for r in rows) + ")"


def dh_table(plan: Plan) -> tuple[str, ...]:
    """The DH table as aligned text rows, in the spec's convention and naming."""
    arm = plan.arm
    head = ("alpha_{i-1}", "a_{i-1}") if arm.convention == "modified" else ("alpha_i", "a_i")
    rows = [("i", "type", head[0] + " [deg]", head[1], "d_i", "theta_i [deg]")]
    for i, (alpha, a, d, theta) in enumerate(arm.dh, start=1):
        kind = arm.joint_types[i - 1]
        var_d = f"q{i} + {d:g}" if kind == "P" else f"{d:g}"
        var_t = f"q{i} + {math.degrees(theta):g}" if kind == "R" else f"{math.degrees(theta):g}"
        rows.append((str(i), kind, f"{math.degrees(alpha):g}", f"{a:g}", var_d, var_t))
    widths = [max(len(r[k]) for r in rows) for k in range(6)]
    return tuple("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows)


def _package_template(name: str) -> str:
    """A template's text from the package's own data (``derive.templates``), nowhere else:
    a ``templates/`` folder elsewhere on ``sys.path`` never shadows it."""
    entry = resources.files("derive.templates").joinpath(name)
    if not name.endswith(".j2") or "/" in name or not entry.is_file():
        raise jinja2.TemplateNotFound(name)
    return entry.read_text(encoding="utf-8")


def environment() -> jinja2.Environment:
    """The jinja2 environment: package templates only, strict undefined, no autoescape."""
    return jinja2.Environment(
        loader=jinja2.FunctionLoader(_package_template),
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )


def render_module(plan: Plan) -> str:
    """The generated Python module of an arm: the layout (module.py.j2) around the arm's
    printed code (arm.py.j2), naming what it takes from the runtime (derive.assemble)."""
    printed = print_plan(plan)
    env = environment()
    arm_code = wrap_code(env.get_template("arm.py.j2").render(m=printed))
    parts = assemble(
        arm_code,
        bool(printed.has_ik),
        bool(printed.free),
        printed.plane or printed.components or "pose",
    )
    layout = env.get_template("module.py.j2")

    def render(imports: str, offered: tuple[str, ...]) -> str:
        return layout.render(
            m=printed,
            generator=GENERATOR,
            regenerate=REGENERATE,
            imports=imports,
            used=import_order((*parts.used, *parts.offered)),
            offered=offered,
            runtime_file=RUNTIME_FILE,
            runtime_module=RUNTIME_FILE.removesuffix(".py"),
            runtime_version=runtime_version(),
            arm=arm_code.rstrip("\n"),
        )

    # the imports are those the module's code uses, constants included; it offers the
    # runtime's public names it uses and its own
    draft = render(import_block(render("", ())), ())
    own = {
        n.id
        for node in ast.parse(draft).body
        if isinstance(node, ast.Assign)
        for n in node.targets
        if isinstance(n, ast.Name) and not n.id.startswith("_")
    }
    offered = all_order((*own, *parts.offered))
    return render(import_block(draft), _packed([f'"{n}",' for n in offered], 96))


def _packed(words: list[str], width: int) -> tuple[str, ...]:
    """Words joined by spaces into lines of at most width characters."""
    lines: list[str] = []
    for word in words:
        if lines and len(lines[-1]) + 1 + len(word) <= width:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return tuple(lines)


def render_runtime() -> str:
    """The runtime file (runtime.py.j2): every routine of derive/runtime, once."""
    return _runtime()[0]


def runtime_version() -> str:
    """The version a module checks its runtime file against (the runtime's _RUNTIME_VERSION)."""
    return _runtime()[1]


@cache
def _runtime() -> tuple[str, str]:
    """The runtime file's text and its version (the digest of its text without it)."""
    source, read, public = runtime_source()
    layout = environment().get_template("runtime.py.j2")

    def render(imports: str, version: str) -> str:
        return layout.render(
            generator=GENERATOR,
            regenerate=REGENERATE,
            imports=imports,
            read=read,
            public=public,
            source=source,
            version=version,
        )

    imports = import_block(render("", ""))
    version = hashlib.sha256(render(imports, "").encode("utf-8")).hexdigest()[:16]
    return render(imports, version), version


# the runtime's line stating its version, in whatever form a formatter leaves it (the
# generated module's _RUNTIME_LINE is the same pattern)
RUNTIME_LINE = re.compile(rb"^_RUNTIME_VERSION\s*(?::\s*str\s*)?=\s*[\"']([0-9a-fA-F]+)[\"']", re.M)
