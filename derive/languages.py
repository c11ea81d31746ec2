"""The output languages: what `derive generate --lang NAME` writes for one arm, behind one small
protocol. Adding a language is one function and one registry line (docs/languages.md).

A language turns an arm's spec and plan into files ({file name: text or bytes}); the CLI
writes them atomically, `derive check` regenerates and compares them. Every language reads the
plan only (derive/plan.py): the plan is the one contract between derivation and emission.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from types import ModuleType

from derive.emit import GenerationError
from derive.load import load_solver, solver_sources
from derive.plan import Plan
from derive.report import Example, render_report
from derive.spec import ArmSpec

Files = dict[str, str | bytes]


@dataclass(frozen=True)
class Language:
    """One output language.

    Attributes:
        name: its --lang name.
        summary: one line for --help.
        files: (spec, plan, figures) -> the files it writes for the arm; GenerationError where
            it cannot serve the arm (the message names the arm and why).
        marker: a file name suffix whose presence beside an arm's module says the arm was
            generated in this language too (`derive check` then checks its files), or "".
    """

    name: str
    summary: str
    files: Callable[[ArmSpec, Plan, bool], Files]
    marker: str = ""


def python_files(spec: ArmSpec, plan: Plan, figures: bool) -> Files:
    """The Python module, the C solver it runs, and the derivation report (with figures: its
    pictures, embedded in it)."""
    sources = solver_sources(plan)
    module = load_solver(spec.name, sources)
    example = worked_example(plan, module)
    files: Files = dict(sources)
    shown: tuple[tuple[str, str], ...] = ()
    if figures and plan.ik is not None:
        made = figure_files(spec, module, example, "svg")
        files.update({name: data for _, name, data in made})
        shown = tuple((caption, name) for caption, name, _ in made)
    files[f"{spec.name}.md"] = render_report(plan, example, "md", shown)
    return files


def c_files(spec: ArmSpec, plan: Plan, figures: bool) -> Files:
    """The C solver alone: <name>_ik.h and <name>_ik.c."""
    from derive.emit_c import render_c

    return dict(render_c(plan))


def ikfast_files(spec: ArmSpec, plan: Plan, figures: bool) -> Files:
    """The C solver and the MoveIt IKFast plugin shim around it."""
    from derive.emit_c import render_c, render_ikfast

    return {**render_c(plan), **render_ikfast(plan)}


LANGUAGES: dict[str, Language] = {
    language.name: language
    for language in (
        Language("python", "the module, its C solver and the report", python_files),
        Language("c", "the C99 solver (header and source)", c_files),
        Language(
            "cpp-ikfast",
            "the C solver and a MoveIt IKFast plugin shim",
            ikfast_files,
            marker="_ikfast_solver.cpp",
        ),
    )
}


def worked_example(plan: Plan, module: ModuleType) -> Example:
    """The report's example: the spec's pose, or fk of its joint values, and the solutions."""
    import numpy as np

    arm = plan.arm
    if arm.example_pose is not None:
        pose = np.array(arm.example_pose).reshape(4, 4)
        how = "the world pose given in the spec's [example]"
    else:
        assert arm.example_q is not None  # a spec gives an example pose or joint values
        pose = module.fk(list(arm.example_q))
        shown = ", ".join(
            f"{math.degrees(v):g}" if t == "R" else f"{v:g}"
            for v, t in zip(arm.example_q, arm.joint_types)
        )
        how = f"the pose of q = ({shown}) (degrees for R joints)"
    if getattr(module, "IK_COMPONENTS", "") == "lookat" and arm.example_pose is None:
        # (the tool point itself is seen from every direction: look at a point one reach ahead)
        pose = pose.copy()
        pose[:3, 3] += arm.reach * pose[:3, module.TOOL_AXIS]
        how += f", its point moved one reach ({arm.reach:.4g}) along the tool axis: the point"
        how += " looked at"
    # one pose: the Python solver (the example shows what the lecture's steps give)
    free = getattr(module, "FREE", ())
    values = {}
    if free:
        given = arm.example_q if arm.example_q is not None else (0.0,) * arm.dof
        values["free"] = [given[j - 1] for j in free]
        given_values = [
            math.degrees(given[j - 1]) if arm.joint_types[j - 1] == "R" else given[j - 1]
            for j in free
        ]
        how += "; free joints " + ", ".join(f"q{j} = {v:g}" for j, v in zip(free, given_values))
    solutions = module.ik(pose, backend="python", **values) if hasattr(module, "ik") else ()
    return Example(
        tuple(float(v) for v in pose.ravel()),
        tuple(tuple(float(v) for v in row) for row in solutions),
        how,
    )


def is_planar(spec: ArmSpec) -> bool:
    """Every axis parallel: the workspace section is the arm's own plane."""
    from derive.classify import classify
    from derive.transforms import chain_from_spec

    chain = chain_from_spec(spec)
    return len(classify(chain).parallel) == chain.dof - 1


# the report's workspace section: grid points per side
REPORT_RESOLUTION = 101


def figure_files(
    spec: ArmSpec, module: ModuleType, example: Example, ext: str
) -> tuple[tuple[str, str, bytes], ...]:
    """The worked example's solutions and a workspace section, as (caption, file name, bytes).

    Raises:
        GenerationError: matplotlib is missing (the message says what to install).
    """
    import numpy as np

    from derive.plot import PlotUnavailable, figure_bytes, solutions_figure, workspace_figure
    from derive.workspace import workspace

    pose = np.array(example.pose).reshape(4, 4)
    planar = is_planar(spec)
    try:
        rows = np.array(example.solutions).reshape(-1, spec.dof)
        title = f"{spec.name}: the worked example"
        drawing, _ = solutions_figure(module, spec.convention, pose, rows, title)
        solutions = figure_bytes(drawing, ext)
        wmap = workspace(module, planar, spec.convention, REPORT_RESOLUTION, progress=None)
        section = figure_bytes(workspace_figure(wmap, f"{spec.name}: workspace section"), ext)
    except PlotUnavailable as exc:
        raise GenerationError(f"--figures: {exc}") from None
    grid = f"{REPORT_RESOLUTION} x {REPORT_RESOLUTION}"
    return (
        (
            f"The worked example's {len(example.solutions)} solutions.",
            f"{spec.name}_solutions.{ext}",
            solutions,
        ),
        (
            f"Workspace section ({grid}): {wmap.summary()}.",
            f"{spec.name}_workspace.{ext}",
            section,
        ),
    )
