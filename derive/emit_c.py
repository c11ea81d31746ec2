"""plan -> the C99 solver: `<name>_ik.h` and `<name>_ik.c` (templates/arm.h.j2, arm.c.j2,
general_arm.c.j2), printed by derive/printers/c.py, and the C runtime it includes,
`derive_ik_runtime.h` (derive/c/, templates/runtime.h.j2). Deterministic as the Python
output: the same plan gives the same bytes."""

from __future__ import annotations

import functools
import hashlib
import textwrap
from dataclasses import dataclass
from typing import Any

import numpy as np

from derive import tasks
from derive.assemble import C_RUNTIME_FILE, c_runtime_source
from derive.emit import GENERATOR, REGENERATE, GenerationError, check_printable, environment
from derive.layout import wrap_c
from derive.plan import Eigen, Plan, Poly, PolyD
from derive.printers import branches, c
from derive.printers.general import eigen_step, pad, spurious_counts
from derive.runtime import constants, motion
from derive.tasks import TASK_CODES


@dataclass(frozen=True)
class PrintedC:
    """Everything the C templates need, as strings, ints and tuples of them."""

    name: str
    upper: str
    guard: str
    digest: str
    dof: int
    method: str
    max_solutions: int
    free: tuple[int, ...]
    free_list: str
    free_zero: str
    free_tuple: str
    free_text: str
    certify_tol: str
    reach: str
    far: str
    free_limit: str
    revolute: str
    limits: tuple[tuple[str, str], ...]
    fk_pose: tuple[str, ...]
    fk_joints: tuple[str, ...]
    jacobian: tuple[str, ...]
    jacobian_tool: tuple[str, ...]
    # <name>_branch's body and the joints its signs name (the Python module's BRANCHES)
    branch: tuple[str, ...]
    branch_names: tuple[str, ...]
    branch_doc: str
    fk_params: str
    solve: tuple[tuple[int, str], ...]
    # dk_solve brings every revolute output to ik's range (c.seamed_outputs): dk_finish copies
    seamed: bool
    # how far the solver's equations may miss and still seed a refinement (0.0: exact arms)
    seed_tol: str = "0.0"
    # the exact chain's frames (each three lines of 4 numbers, link_transform's and the
    # refinement's) and the base's (3 lines); whether the closed form solves a nominal table
    # (refined: every row is refined onto the chain; else a row within tol but not 1e-10 is
    # polished there, dk_polish); the joints (0-based) the steps move
    chain: tuple[tuple[str, ...], ...] = ()
    base: tuple[str, ...] = ()
    refined: bool = False
    # a planar arm's plane task (derive/tasks.py, Plane): "xy_heading", "xy" or ""; the tool's
    # rotation at q = 0 (9 numbers), the heading there, the plane's height, a sliding joint
    plane: str = ""
    plane_rotation: str = ""
    plane_zero: str = "0.0"
    plane_z: str = "0.0"
    plane_slide: bool = False
    heading_axis: int = 0
    # ik_velocity's defaults (derive/runtime/motion.py)
    velocity_damping: str = repr(motion.VELOCITY_DAMPING)
    velocity_band: str = repr(motion.VELOCITY_BAND)
    solved: tuple[int, ...] = ()
    refine_rows: int = 6
    # the task's code (derive/tasks.py TASK_CODES) and its tool axis
    task_code: int = 0
    tool_axis: int = 2
    cone_axis: int = 2


def general_constants(plan: Plan) -> dict[str, object]:
    """A general arm's tables and dk_rr_fill for templates/general_arm.c.j2 (the method's
    constants are derive/c/general.c's own)."""
    step = eigen_step(plan)
    assert step is not None

    def nested(values: Any) -> str:
        """Nested sequences of numbers as a C initialiser (floats as doubles)."""
        if isinstance(values, (float, np.floating)):
            return repr(float(values))
        if isinstance(values, (int, np.integer)):
            return str(int(values))
        return "{" + ", ".join(nested(v) for v in values) + "}"

    return {
        "SPLIT_COUNT": len(step.splits),
        "LENGTH": repr(float(step.unit)),
        "REVERSED": "{" + ", ".join("1" if s.reversed else "0" for s in step.splits) + "}",
        "FILL": nested([(*s.fill_rows, (*s.slide, 0.0, 0.0)) for s in step.splits]),
        "TRUE": nested([(*s.true_rows, (*s.slide, 0.0, 0.0)) for s in step.splits]),
        "FLIPS": nested([int(first in step.flips) for first in (0, 3)]),
        "fill": c.general_fill(plan),
        **spurious_constants(step),
    }


def branch_doc(plan: Plan) -> str:
    """The header's comment on <NAME>_BRANCHES: what the signs of <name>_branch are."""
    names = branches.branch_names(plan)
    if names == (branches.JACOBIAN_BRANCH,):
        text = (
            'the branch of a solution (1 sign; the Python module\'s BRANCHES, ("det J",), and '
            "branch): no step of this arm's method names one (it solves all joints at once), so "
            "the sign is det J's over the joints the pose fixes, +1 or -1, 0 at a singular "
            "configuration (|det J| within 1e-9 of the product of its columns' lengths); it "
            "changes only where a path crosses a singular configuration, but two solutions "
            "can share it"
        )
    else:
        solving = f": the steps solving {', '.join(names)}" if names else ""
        text = (
            f"the branches of the closed form ({len(names)}{solving}; the Python module's "
            "BRANCHES and branch): one sign per step that gives several values, +1 or -1 (the "
            "sign of the derivative of the step's equation at the value), 0 at a fold, where "
            "the step's values meet (a singular configuration: the elbow stretched, the wrist "
            "straight); the signs change only where a path crosses a fold, so they name a "
            "solution's configuration (shoulder, elbow, wrist)"
        )
        if not names:
            text += (
                "; this arm has none (its method solves all joints at once, or q alone cannot "
                "tell its branch)"
            )
    lines = textwrap.wrap(f"/* {text} */", 96, subsequent_indent="   ")
    return "\n".join(lines)


def spurious_constants(step: Eigen) -> dict[str, object]:
    """DK_RR_SPURIOUS (splits x 12 x width, zeros beyond each split's count: spurious_counts),
    its counts and width, and DK_RR_PIVOTS."""
    counts, width = spurious_counts(step)
    tables = []
    for split, n in zip(step.splits, counts):
        rows = split.spurious if n else ((),) * 12
        tables.append(
            "{"
            + ", ".join(
                "{" + ", ".join(repr(float(v)) for v in (*row, *[0.0] * (width - n))) + "}"
                for row in rows
            )
            + "}"
        )
    pivots = [pad(s.spurious_pivots, width // 2) for s in step.splits]
    return {
        "PIVOTS": "{" + ", ".join("{" + ", ".join(map(str, p)) + "}" for p in pivots) + "}",
        "SPURIOUS_WIDTH": width,
        "SPURIOUS_COUNT": "{" + ", ".join(map(str, counts)) + "}",
        "SPURIOUS": "{" + ", ".join(tables) + "}",
    }


# dk_uangle's table (derive/c/runtime.c): the Taylor coefficients of asin at
# UNIT_ANGLE_SEGMENTS + 1 points evenly spaced over [0, UNIT_ANGLE_TOP], to degree
# UNIT_ANGLE_DEGREE. An offset of at most half a spacing (0.0028) from a point at most 0.72,
# 0.28 from asin's singularity at 1, leaves terms beyond the degree below about 0.01^9 = 1e-18
# (129 x 9 doubles: 2 fewer multiply-adds a call than 65 points to degree 10, 1.3% of a PUMA
# pose's instructions)
UNIT_ANGLE_SEGMENTS = 128
UNIT_ANGLE_TOP = 0.72
UNIT_ANGLE_DEGREE = 8  # dk_uangle's Estrin scheme is written out for degree 8


@functools.cache
def unit_angle_table() -> list[list[float]]:
    """asin's Taylor coefficients at the points k * top / segments, from its derivative
    g = (1 - x^2)^(-1/2) and the recurrence (1 - x^2) g^(n+1) = (2n + 1) x g^(n) + n^2 g^(n-1)
    (differentiating (1 - x^2) g' = x g n times), in 50-digit arithmetic, then rounded once."""
    import mpmath

    with mpmath.workdps(50):
        rows = []
        for k in range(UNIT_ANGLE_SEGMENTS + 1):
            x = mpmath.mpf(k * (UNIT_ANGLE_TOP / UNIT_ANGLE_SEGMENTS))  # the C code's point
            g = [1 / mpmath.sqrt(1 - x * x)]
            for n in range(UNIT_ANGLE_DEGREE - 1):
                before = g[n - 1] if n else mpmath.mpf(0)
                g.append(((2 * n + 1) * x * g[n] + n * n * before) / (1 - x * x))
            degrees = range(1, UNIT_ANGLE_DEGREE + 1)
            terms = [mpmath.asin(x)] + [g[i - 1] / mpmath.factorial(i) for i in degrees]
            rows.append([float(t) for t in terms])
    return rows


def print_c(plan: Plan) -> PrintedC:
    """The printed IR of the C solver.

    Raises:
        GenerationError: the arm has no IK.
    """
    check_printable(plan)
    arm, ik = plan.arm, plan.ik
    if ik is None:
        raise GenerationError(f"{arm.name}: no IK method, so no C solver: {plan.refusal}")
    solve = c.solve_lines(plan)
    fk_pose, fk_joints, fk_params = c.fk_lines(plan)
    jacobian, jacobian_tool = c.jacobian_lines(plan)
    upper = arm.name.upper()
    text = ik.free_text
    return PrintedC(
        name=arm.name,
        upper=upper,
        guard=f"{upper}_IK_H",
        digest=arm.digest,
        dof=arm.dof,
        method=ik.method,
        max_solutions=ik.max_solutions,
        free=ik.free,
        free_list=", ".join(str(j) for j in ik.free) or "0",
        free_zero=", ".join(str(j - 1) for j in ik.free),
        free_tuple=repr(tuple(ik.free)),
        free_text=f"Free joints: {text}." if text else "",
        certify_tol=repr(constants.CERTIFY_TOL),
        reach=repr(arm.reach),
        far=repr(constants.FAR_REACH * arm.reach),
        free_limit=repr(constants.FREE_LIMIT),
        revolute=", ".join("1" if k == "R" else "0" for k in arm.joint_types),
        limits=tuple((c.c_double(lo), c.c_double(hi)) for lo, hi in arm.limits),
        fk_pose=fk_pose,
        fk_joints=fk_joints,
        jacobian=jacobian,
        jacobian_tool=jacobian_tool,
        branch=c.branch_lines(plan, arm.name),
        branch_names=branches.branch_names(plan),
        branch_doc=branch_doc(plan),
        fk_params=fk_params,
        solve=solve,
        seamed=bool(c.seamed_outputs(plan)),
        seed_tol=repr(plan.correction.seed_tol) if plan.correction else "0.0",
        chain=tuple(_frame_rows(f) for f in plan.frames),
        base=_frame_rows(arm.base[:12]),
        refined=plan.correction is not None,
        solved=plan.solved,
        refine_rows={"position": 3, "lookat": 3, "axisangle": 4}.get(ik.certify, 6),  # (pointing:
        # 3 zero)
        task_code=TASK_CODES[ik.certify],
        tool_axis=ik.tool_axis,
        cone_axis=ik.cone,
        **plane_fields(plan),
    )


def plane_fields(plan: Plan) -> dict[str, Any]:
    """The plane task's fields of PrintedC (none where the arm has none)."""
    assert plan.ik is not None
    plane = tasks.plane_of(plan.frames, plan.arm.joint_types, plan.ik.method, plan.ik.certify)
    if plane is None:
        return {}
    return {
        "plane": "xy_heading" if plane.heading else "xy",
        "plane_rotation": ", ".join(map(repr, plane.rotation)),
        "plane_zero": repr(plane.zero),
        "plane_z": repr(plane.height),
        "plane_slide": plane.slide,
        "heading_axis": plane.axis,
    }


def _frame_rows(frame: tuple[float, ...]) -> tuple[str, ...]:
    """A frame's 12 numbers (top three rows) as three lines of C initialiser, one row each."""
    return tuple(", ".join(map(repr, map(float, frame[4 * r : 4 * r + 4]))) for r in range(3))


def poly_max(plan: Plan) -> int:
    """The most roots one of the plan's polynomials has (4 at least: the closed forms' size
    of the C runtime's arrays; above it dk_roots has the Aberth iteration for other degrees)."""
    steps = plan.ik.steps if plan.ik else ()
    degrees = [len(s.args) - 1 for s in steps if isinstance(s, (Poly, PolyD))]
    return max([4, *degrees])


def render_c(plan: Plan) -> dict[str, str]:
    """The C solver's files of an arm: {file name: text}. The arm's code is printed from its
    plan (templates/arm.c.j2; a general arm's tables: general_arm.c.j2); it includes the C
    runtime (derive/c/), written beside it as derive_ik_runtime.h (render_c_runtime)."""
    printed = print_c(plan)
    env = environment()
    general = ""
    if eigen_step(plan) is not None:
        tables = env.get_template("general_arm.c.j2").render(g=general_constants(plan))
        general = "\n" + tables
    args = {
        "m": printed,
        "generator": GENERATOR,
        "poly_max": poly_max(plan),
        "values_max": max(
            poly_max(plan),
            max(constants._SPREAD_COUNT, constants._FOLD_SPREAD) if plan.correction else 0,
        ),
        "arm_general": general,
    }
    arm = env.get_template("arm.c.j2")
    runtime = {"runtime_file": C_RUNTIME_FILE, "runtime_digest": c_runtime_digest()}
    return {
        f"{printed.name}_ik.h": wrap_c(env.get_template("arm.h.j2").render(**args)),
        f"{printed.name}_ik.c": wrap_c(arm.render(**args, **runtime)),
        C_RUNTIME_FILE: render_c_runtime(),
    }


@functools.cache
def c_runtime_digest() -> str:
    """DK_RUNTIME of the C runtime header: 12 hex digits of the SHA-256 of its routines."""
    runtime, general = c_runtime_source()
    return hashlib.sha256(f"{runtime}\0{general}".encode()).hexdigest()[:12]


@functools.cache
def render_c_runtime() -> str:
    """The C runtime header every arm's C file includes (templates/runtime.h.j2)."""
    runtime, general = c_runtime_source()
    return (
        environment()
        .get_template("runtime.h.j2")
        .render(
            generator=GENERATOR,
            regenerate=REGENERATE,
            digest=c_runtime_digest(),
            runtime=runtime,
            general=general,
        )
    )


def render_ikfast(plan: Plan) -> dict[str, str]:
    """The MoveIt IKFast plugin shim of an arm: {file name: text}.

    Raises:
        GenerationError: the arm's solver is neither a 6-DOF pose solver (IKP_Transform6D)
            nor a task's (IKP_Translation3D, IKP_TranslationDirection5D, IKP_Lookat3D,
            IKP_Direction3D, IKP_Translation{X,Y,Z}AxisAngle4D): a planar arm's plane tasks
            are not served.
    """
    printed = print_c(plan)
    assert plan.ik is not None
    if printed.plane or (plan.ik.certify == "pose" and printed.dof - len(printed.free) != 6):
        raise GenerationError(
            f"{printed.name}: the IKFast shim serves arms solved for the whole pose with 6 "
            "joints besides the free ones (IKP_Transform6D), or for a task: the tool point "
            "(IKP_Translation3D), the point and a direction (IKP_TranslationDirection5D), a "
            "look-at (IKP_Lookat3D), a direction (IKP_Direction3D) or the point and an axis's "
            "angle (IKP_Translation{X,Y,Z}AxisAngle4D); this arm has "
            f"{printed.dof} joints ({len(printed.free)} free), solved for {plan.ik.solves_for}"
            + (" in a plane" if printed.plane else "")
        )
    text = environment().get_template("ikfast.cpp.j2").render(m=printed, generator=GENERATOR)
    return {f"{printed.name}_ikfast_solver.cpp": text}


def render_binding(plan: Plan) -> str:
    """The ctypes binding `derive build` writes beside the compiled library."""
    printed = print_c(plan)
    return environment().get_template("binding.py.j2").render(m=printed, generator=GENERATOR)


def render_harness(plan: Plan) -> str:
    """The command-line harness around the C solver (tests, `derive bench --lang c`)."""
    return environment().get_template("harness.c.j2").render(m=print_c(plan))
