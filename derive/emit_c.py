"""plan -> the C99 solver: `<name>_ik.h` and `<name>_ik.c` (templates/arm.h.j2, arm.c.j2,
runtime.c.j2), printed by derive/printers/c.py. Deterministic as the Python output: the
same plan gives the same bytes."""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np

from derive.emit import GENERATOR, GenerationError, check_printable, environment
from derive.plan import Eigen, Plan, Poly, PolyD
from derive.printers import c
from derive.printers.general import eigen_step, pad, spurious_counts
from derive.runtime import closed, constants


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
    fk_params: str
    solve: tuple[tuple[int, str], ...]
    # dk_solve brings every revolute output to ik's range (c.seamed_outputs): dk_finish copies
    seamed: bool


@dataclass(frozen=True)
class RuntimeConstants:
    """The runtime's tolerances as C literals (from derive/runtime/constants.py)."""

    FREE_TOL: str
    CLAMP_TOL: str
    FOLD_TOL: str
    LEAD_TOL: str
    ROOT_IMAG_TOL: str
    CLUSTER_TOL: str
    MERGE_TOL: str
    RESIDUAL_TOL: str
    DEDUP_TOL: str
    POSE_TOL: str
    SEAM: str
    SEAM_SNAP: str
    PI: str
    TWO_PI: str
    FREE_COUNT: int
    FREE_STEPS: str
    ANGLE_AT: str
    TAN_AT: str
    UNIT_ANGLE: str
    UNIT_ANGLE_COUNT: int
    UNIT_ANGLE_TERMS: int
    UNIT_ANGLE_SEGMENTS: int
    UNIT_ANGLE_TOP: str


def general_constants(plan: Plan) -> dict[str, object]:
    """The general method's constants and dk_rr_fill for templates/general.c.j2."""
    from derive.runtime import general

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
        "RANK_TOL": repr(constants._RR_RANK_TOL),
        "COND_LIMIT": repr(constants._RR_COND_LIMIT),
        "IMAG_TOL": repr(constants._RR_IMAG_TOL),
        "IMAG_LOOSE": repr(constants._RR_IMAG_LOOSE),
        "CLUSTER_TOL": repr(constants._RR_CLUSTER_TOL),
        "NULL2_TOL": repr(constants._RR_NULL2_TOL),
        "GOOD": repr(constants._RR_GOOD),
        "NEWTON_STEPS": constants._RR_NEWTON_STEPS,
        "NEWTON_REACH": repr(constants._RR_NEWTON_REACH),
        "NEWTON_DONE": repr(constants._RR_NEWTON_DONE[0]),
        "NEWTON_DONE_STEP": repr(constants._RR_NEWTON_DONE[1]),
        "SPLIT_COUNT": len(step.splits),
        "LENGTH": repr(float(step.unit)),
        "MOEBIUS": nested(constants._RR_MOEBIUS),
        "PATH_COUNT": len(constants._RR_PATH),
        "PATH": nested(constants._RR_PATH),
        "H45": nested(general._RR_H45.tolist()),
        "SHIFT4": repr(constants._RR_SHIFT45[0]),
        "SHIFT5": repr(constants._RR_SHIFT45[1]),
        "PAIR_TOL": repr(constants._RR_PAIR_TOL),
        "MIX": nested(general._RR_MIX.tolist()),
        "RULES": nested(general._RR_MONOMIAL_RULES),
        "MOTION_COUNT": len(general._RR_MOTIONS),
        "MOTIONS": nested(general._RR_MOTIONS.tolist()),
        "SEARCH_FROM": repr(constants._RR_SEARCH_FROM),
        "SEARCH_BAIL": repr(constants._RR_SEARCH_BAIL),
        "SEARCH_STEPS": constants._RR_SEARCH_STEPS,
        "SEARCH_SLIDE": repr(constants._RR_SEARCH_SLIDE),
        "SEARCH_COUNT": len(general._RR_SEARCH_STARTS),
        "SEARCH_STARTS": nested(general._RR_SEARCH_STARTS.tolist()),
        "REVERSED": "{" + ", ".join("1" if s.reversed else "0" for s in step.splits) + "}",
        "FILL": nested([(*s.fill_rows, (*s.slide, 0.0, 0.0)) for s in step.splits]),
        "TRUE": nested([(*s.true_rows, (*s.slide, 0.0, 0.0)) for s in step.splits]),
        "fill": c.general_fill(plan),
        **spurious_constants(step),
    }


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


# dk_uangle's table (templates/runtime.c.j2): the Taylor coefficients of asin at
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


def runtime_constants() -> RuntimeConstants:
    steps = [repr(s) for s in constants._FREE_STEPS]
    rows = [", ".join(steps[k : k + 4]) for k in range(0, len(steps), 4)]
    return RuntimeConstants(
        FREE_TOL=repr(constants._FREE_TOL),
        CLAMP_TOL=repr(constants._CLAMP_TOL),
        FOLD_TOL=repr(constants._FOLD_TOL),
        LEAD_TOL=repr(constants._LEAD_TOL),
        ROOT_IMAG_TOL=repr(constants._ROOT_IMAG_TOL),
        CLUSTER_TOL=repr(constants._CLUSTER_TOL),
        MERGE_TOL=repr(constants._MERGE_TOL),
        RESIDUAL_TOL=repr(constants._RESIDUAL_TOL),
        DEDUP_TOL=repr(constants.DEDUP_TOL),
        POSE_TOL=repr(constants.POSE_TOL),
        SEAM=repr(constants._SEAM),
        SEAM_SNAP=repr(constants._SEAM_SNAP),
        PI=repr(math.pi),
        TWO_PI=repr(constants._TWO_PI),
        FREE_COUNT=len(steps),
        FREE_STEPS=",\n".join(f"    {row}" for row in rows),
        ANGLE_AT=_c_array(closed._ANGLE_AT),
        TAN_AT=_c_array(closed._TAN_AT),
        UNIT_ANGLE=",\n".join(f"    {_c_array(row)}" for row in unit_angle_table()),
        UNIT_ANGLE_COUNT=UNIT_ANGLE_SEGMENTS + 1,
        UNIT_ANGLE_TERMS=UNIT_ANGLE_DEGREE + 1,
        UNIT_ANGLE_SEGMENTS=UNIT_ANGLE_SEGMENTS,
        UNIT_ANGLE_TOP=repr(UNIT_ANGLE_TOP),
    )


def _c_array(values: Iterable[float]) -> str:
    """A C array initialiser of doubles."""
    return "{" + ", ".join(repr(float(v)) for v in values) + "}"


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
        fk_params=fk_params,
        solve=solve,
        seamed=bool(c.seamed_outputs(plan)),
    )


# the runtime's routines dk_solve may call, and those each of them calls
ROUTINES = {
    "dk_general": (),
    "dk_poly": (),
    "dk_cs1": (),
    "dk_cs1r": ("dk_cs1",),
    "dk_cs2": ("dk_one",),
    "dk_cs2r": ("dk_one",),
    "dk_atan2": ("dk_one",),
    "dk_flipped": (),
    "dk_seam": (),
    "dk_unit_seam": (),
}


def routines(solve: tuple[tuple[int, str], ...]) -> frozenset[str]:
    """The runtime routines dk_solve calls, with those they call (the C file holds only
    these: an unused static function is an error under -Werror)."""
    called = {name for name in ROUTINES for _, line in solve if f"{name}(" in line}
    return frozenset(called.union(*(ROUTINES[name] for name in called)))


def poly_max(plan: Plan) -> int:
    """The most roots one of the plan's polynomials has (4 at least: the closed forms' size
    of the C runtime's arrays; above it dk_roots has the Aberth iteration for other degrees)."""
    steps = plan.ik.steps if plan.ik else ()
    degrees = [len(s.args) - 1 for s in steps if isinstance(s, (Poly, PolyD))]
    return max([4, *degrees])


def render_c(plan: Plan) -> dict[str, str]:
    """The C solver's files of an arm: {file name: text}."""
    printed = print_c(plan)
    env = environment()
    args = {
        "m": printed,
        "c": runtime_constants(),
        "generator": GENERATOR,
        "uses": routines(printed.solve),
        "poly_max": (size := poly_max(plan)),
        "poly_zeros": ", ".join(["0"] * size),
        "g": general_constants(plan) if "dk_general" in routines(printed.solve) else None,
    }
    return {
        f"{printed.name}_ik.h": env.get_template("arm.h.j2").render(**args),
        f"{printed.name}_ik.c": env.get_template("arm.c.j2").render(**args),
    }


def render_ikfast(plan: Plan) -> dict[str, str]:
    """The MoveIt IKFast plugin shim of an arm: {file name: text}.

    Raises:
        GenerationError: the arm's solver is not a 6-DOF pose solver (IKP_Transform6D).
    """
    printed = print_c(plan)
    assert plan.ik is not None
    if plan.ik.certify != "pose" or printed.dof - len(printed.free) != 6:
        raise GenerationError(
            f"{printed.name}: the IKFast shim serves arms solved for the whole pose with 6 "
            f"joints besides the free ones (IKP_Transform6D); this arm has {printed.dof} joints "
            f"({len(printed.free)} free), solved for {plan.ik.solves_for}"
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
