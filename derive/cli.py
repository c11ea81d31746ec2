"""The command line: argparse and the commands (files are read through derive/inputs.py and
written through derive/outputs.py).

Exit codes: 0 ok, 1 check found differences, 2 bad input (one line on stderr, no
traceback), 3 `generate --require-ik` found an arm without an IK method.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import resource
import sys
import tempfile
import time
from collections.abc import Callable
from functools import partial
from pathlib import Path
from types import ModuleType
from typing import TYPE_CHECKING, Any, NoReturn

if TYPE_CHECKING:
    from collections.abc import Iterable

from derive import extras, mjcf, urdf
from derive.emit import GenerationError, render_module
from derive.inputs import bundled_specs, converts, resolve_spec
from derive.languages import LANGUAGES, figure_files, is_planar, worked_example
from derive.load import LoadError, load_solver, solver_sources
from derive.outputs import (
    OutputError,
    describe_difference,
    existing_folder,
    output_file,
    output_folder,
    writable_file,
    write_atomic,
)
from derive.pipeline import build_plan, task_of
from derive.plan import Plan
from derive.report import Example, render_report
from derive.spec import IK_METHODS, IK_TASKS, TOOL_AXES, ArmSpec, SpecError, load_spec, parse_spec
from derive.transforms import chain_from_spec

DEFAULT_OUT = "generated"


class UsageError(Exception):
    """Bad command-line input; the message is printed on one line and the exit code is 2."""


def outputs_for(
    spec: ArmSpec, figures: bool = False, lang: str = "python"
) -> tuple[Plan, dict[str, str | bytes]]:
    """The plan and file name -> content of everything language lang writes for one arm."""
    plan = build_plan(spec)
    return plan, LANGUAGES[lang].files(spec, plan, figures)


def urdf_options(args: argparse.Namespace) -> urdf.Options:
    """The URDF conversion options of a command line."""
    return urdf.Options(
        base=args.base,
        tip=args.tip,
        name=args.name,
        angle_tol=args.angle_tol,
        length_tol=args.length_tol,
        exact=args.exact,
        max_deviation=args.max_deviation,
        convention=getattr(args, "convention", "modified"),
        task=args.task,
        tool_axis=args.tool_axis,
        method=args.method,
        base_axis=args.base_axis,
    )


def load_specs(texts: list[str], options: urdf.Options | None = None) -> list[ArmSpec]:
    """Specs named on the command line (all bundled arms if none), with unique names."""
    if texts:
        specs = [resolve_spec(t, o) for t, o in zip(texts, options_for(texts, options))]
    else:
        specs = [load_spec(p) for p in bundled_specs()]
    unique_names(specs)
    return specs


def options_for(texts: list[str], options: urdf.Options | None) -> list[urdf.Options | None]:
    """Per arm named, the conversion's options: where the command line names a URDF or MJCF
    file, they are its, and a spec or bundled arm beside it keeps its own (`derive bench
    robot.urdf puma560 --base b --tip t` times both in one run); where it names none, every
    arm gets them, and a spec refuses them in one line (they would be ignored)."""
    converting = any(converts(t) for t in texts)
    return [options if converts(t) or not converting else None for t in texts]


def unique_names(specs: Iterable[ArmSpec]) -> None:
    """Refuse two arms of one name (their files would replace each other), naming both."""
    seen: dict[str, str] = {}
    for spec in specs:
        if spec.name in seen:
            raise UsageError(
                f"{spec.source}: name: {spec.name!r} is also the name of "
                f"{seen[spec.name]}; arm names must be unique"
            )
        seen[spec.name] = spec.source


def other_runtime_users(out: Path, names: set[str], lang: str = "python") -> list[str]:
    """The files in out of arms not among names whose runtime is not this derive-ik's (a
    module's _RUNTIME_VERSION, a C file's DK_RUNTIME check), where generating lang into out
    would replace that runtime (and in the folder a runtime file in out links to)."""
    from derive.assemble import C_RUNTIME_FILE, RUNTIME_FILE
    from derive.emit import RUNTIME_LINE, runtime_version
    from derive.emit_c import c_runtime_digest

    if not out.is_dir():
        return []
    wanted = {  # (the files of an arm that run each runtime file, and how they say its version)
        ".py": (RUNTIME_LINE, runtime_version(), ""),
        ".c": (re.compile(rb"^#if DK_RUNTIME != 0x(\w+)", re.M), c_runtime_digest(), "_ik"),
    }
    if lang != "python":  # (C alone: the Python runtime is not written)
        del wanted[".py"]
    # the folders whose arms run the runtime files written into out (a symbolic link there
    # is followed: its target is replaced)
    here = out.resolve()
    folders = {here} | {(out / name).resolve().parent for name in (RUNTIME_FILE, C_RUNTIME_FILE)}
    found = []
    for folder in sorted(folders):
        for path in sorted(folder.iterdir()) if folder.is_dir() else ():
            if path.suffix not in wanted or not path.is_file():
                continue
            pattern, version, tail = wanted[path.suffix]
            arm = path.stem.removesuffix(tail) if path.stem.endswith(tail) else ""
            if not arm or path.name in (RUNTIME_FILE, C_RUNTIME_FILE):
                continue
            if arm in names and folder == here:
                continue
            with open(path, "rb") as handle:
                said = pattern.search(handle.read(1 << 20))
            if said is not None and said.group(1).decode().lower() != version:
                found.append(path.name if folder == here else str(path))
    return found


def cmd_generate(args: argparse.Namespace) -> int:
    """Generate the module of each arm; report each arm on one line. Every spec is read
    first (two arms of one name are refused before anything is written); a spec that
    cannot be read is said and the others are generated."""
    out = output_folder(Path(args.out), "--out")
    options = urdf_options(args)  # (a bad option is one line, not one per arm)
    failed, no_ik = [], []
    specs: dict[str, ArmSpec] = {}
    texts = args.specs or [str(p) for p in bundled_specs()]
    for text, text_options in zip(texts, options_for(texts, options)):
        try:
            specs[text] = resolve_spec(text, text_options)
        except (SpecError, UsageError, OutputError, OSError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            failed.append(text)
    unique_names(specs.values())
    others = other_runtime_users(out, {spec.name for spec in specs.values()}, args.lang)
    if others:
        print(
            f"error: {out} holds arms generated by another derive-ik ({', '.join(others)}): "
            "the runtime files beside them (derive_ik_runtime.py, derive_ik_runtime.h) would "
            "be replaced by this one's and they would stop working; regenerate them in the "
            f"same run (derive generate SPEC ... --out {out}), or write into another folder",
            file=sys.stderr,
        )
        return 2
    for text, spec in specs.items():
        start = time.perf_counter()
        try:
            plan, files = outputs_for(spec, args.figures, args.lang)
            targets = {output_file(out / name): content for name, content in files.items()}
            for target, content in targets.items():  # (each checked before any is written)
                write_atomic(target, content)
        except GenerationError as exc:
            if args.lang != "python" and not args.specs:  # a bundled arm C does not serve
                print(f"{Path(text).stem}: skipped: {exc}")
                continue
            print(f"error: {exc}", file=sys.stderr)
            failed.append(text)
            continue
        except (SpecError, UsageError, OutputError, OSError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            failed.append(text)
            continue
        seconds = time.perf_counter() - start
        structure = "; ".join(plan.structure)
        if plan.ik:
            method = f"IK {plan.ik.method} ({plan.ik.case}), up to {plan.ik.max_solutions}"
            if plan.correction is not None:  # (how far the snapped arm is, said where it is)
                method += (
                    f", refined onto the exact arm (the nominal table's FK "
                    f"{plan.correction.deviation:.2g} from it)"
                )
        else:
            method = f"FK only, no IK: {plan.refusal}"
            no_ik.append(spec.name)
        print(f"{spec.name}: {structure}; {method}; {seconds:.2f} s")
    if failed:
        if len(failed) < len(args.specs or bundled_specs()):
            print(
                f"error: {len(failed)} arm(s) failed ({', '.join(failed)}); "
                "the other arms were written",
                file=sys.stderr,
            )
        return 2
    if args.require_ik and no_ik:
        print(f"error: no IK method for: {', '.join(no_ik)}", file=sys.stderr)
        return 3
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    """Compare DIR with a fresh generation; never writes into DIR."""
    out = output_folder(Path(args.out), "--out")
    specs = load_specs(args.specs, urdf_options(args))
    expected: dict[str, bytes] = {}
    c_only = 0  # (arms generated with --lang c alone: C files, no module or report beside)
    with tempfile.TemporaryDirectory() as tmp:
        for spec in specs:
            module = any((out / f"{spec.name}{end}").exists() for end in (".py", ".md"))
            c_alone = not module and (out / f"{spec.name}_ik.c").exists()
            c_only += c_alone
            plan, files = outputs_for(spec, args.figures, "c" if c_alone else "python")
            # the files of other languages the arm was generated in (a marker file is there)
            for language in LANGUAGES.values():
                if language.marker and (out / f"{spec.name}{language.marker}").exists():
                    files.update(language.files(spec, plan, args.figures))
            for name, content in files.items():
                write_atomic(Path(tmp) / name, content)
        for path in sorted(Path(tmp).iterdir()):
            expected[path.name] = path.read_bytes()
    names = set(expected)
    if not args.specs and out.is_dir():
        suffixes = (".py", ".md", ".svg", ".c", ".h", ".cpp")
        names |= {p.name for p in out.iterdir() if p.suffix in suffixes}
    problems = []
    for name in sorted(names):
        path = out / name
        if name not in expected:
            problems.append(f"{path}: not generated by any arm (stale extra file)")
        elif not path.is_file():
            problems.append(f"{path}: missing")
        elif (actual := path.read_bytes()) != expected[name]:
            problems.append(describe_difference(path, actual, expected[name]))
    if not problems:
        print(f"{out}: up to date ({len(expected)} files)")
        return 0
    for problem in problems:
        print(problem)
    specs_text = " ".join(args.specs)
    if any(p.split(":")[0].endswith(".cpp") for p in problems):
        print(f"to update the IKFast shims: derive generate ARM --lang cpp-ikfast --out {out}")
    lang = " --lang c" if c_only == len(specs) else ""
    print(
        f"to update: derive generate {specs_text + ' ' if specs_text else ''}--out {out}{lang}"
        + (" and delete the stale files" if any("stale" in p for p in problems) else "")
    )
    return 1


def load_module(spec: ArmSpec) -> ModuleType:
    """Generate an arm's module (and its C) and import it (derive/load.py)."""
    return load_solver(spec.name, solver_sources(build_plan(spec)))


def parse_numbers(values: list[str], what: str) -> list[float]:
    """Floats from command-line words (commas allowed as separators)."""
    words = [w for v in values for w in v.replace(",", " ").split()]
    try:
        numbers = [float(w) for w in words]
    except ValueError:
        raise UsageError(f"{what}: expected numbers, got {' '.join(words)[:60]!r}") from None
    if not all(math.isfinite(x) for x in numbers):
        raise UsageError(f"{what}: numbers must be finite")
    return numbers


def joint_vector(spec: ArmSpec, values: list[float], radians: bool) -> list[float]:
    """Joint values from the user's units (degrees for R joints unless --rad); a revolute
    value beyond MAX_TURN radians is refused (a new user's `--from 1e308` printed 300-digit
    angles and a path that did not converge)."""
    if len(values) != spec.dof:
        raise UsageError(f"expected {spec.dof} joint values for {spec.name}, got {len(values)}")
    out = [
        math.radians(v) if k == "R" and not radians else v for v, k in zip(values, spec.joint_types)
    ]
    for i, (v, k) in enumerate(zip(out, spec.joint_types)):
        if k == "R" and abs(v) > MAX_TURN:
            raise UsageError(
                f"q{i + 1}: {values[i]:g} {'rad' if radians else 'deg'} is beyond {MAX_TURN:g} "
                "rad, where an angle's own rounding exceeds the solvers' 1e-10 (give it within "
                "a turn)"
            )
    return out


# a revolute joint's value on the command line is at most this many radians: beyond 2^20 its
# double's spacing is above 1e-10 rad, the certification's tolerance
MAX_TURN = 2.0**20


def format_pose(pose: Iterable[Iterable[float]]) -> str:
    """Four rows of a 4x4 matrix; a value that rounds to zero prints as 0 (not -0)."""
    return "\n".join("  ".join(f"{round(x, 10) + 0.0: .10f}" for x in row) for row in pose)


def cmd_fk(args: argparse.Namespace) -> int:
    """Print the pose of a joint vector."""
    spec = resolve_spec(args.arm, urdf_options(args))
    module = load_module(spec)
    q = joint_vector(spec, parse_numbers(args.q, "q"), args.rad)
    print(format_pose(module.fk(q)))
    return 0


def cmd_solve(args: argparse.Namespace) -> int:
    """Print every IK solution of a pose, its FK residual and the joints outside limits."""

    spec, module = ik_module(args)
    pose, free, sols = solve_arguments(spec, module, args)
    task = getattr(module, "IK_COMPONENTS", "pose")
    if task == "pose":
        print("pose:")
    else:
        axis = "xyz"[getattr(module, "TOOL_AXIS", 2)]
        reads = TASK_READS[task].format(axis=axis)
        print(f"target (the {task} task reads {reads}):")
    print(format_pose(pose))
    if free:
        given = [
            f"q{j} = {math.degrees(v) if spec.joint_types[j - 1] == 'R' else v:g}"
            for j, v in zip(module.FREE, free)
        ]
        print(f"free joints: {', '.join(given)} (degrees for R joints)")
    print(f"{len(sols)} solution(s) (degrees for R joints):")
    branches = getattr(module, "BRANCHES", ())
    if branches == ("det J",) and len(sols):  # (the general method: printers/branches.py)
        print("(branch: the sign of det J; 0 at a singular configuration)")
    elif branches and len(sols):
        print(f"(branch: the signs of the steps of {', '.join(branches)}; 0 at a fold)")
    for k, q in enumerate(sols, start=1):
        shown = [math.degrees(v) if t == "R" else v for v, t in zip(q, spec.joint_types)]
        # (the components the solver reproduces: its task's)
        residual = task_residual(module, q, pose)
        outside = [
            f"q{i + 1}"
            for i, (v, (lo, hi)) in enumerate(zip(q, module.LIMITS))
            if not lo <= v <= hi
        ]
        flag = f"  out of limits: {', '.join(outside)}" if outside else ""
        signs = branch_signs(module, q) if branches else ""
        print(
            f"{k:2d}: "
            + " ".join(f"{round(v, 4) + 0.0:10.4f}" for v in shown)  # (+ 0.0: no -0.0000)
            + f"  residual {residual:.1e}"
            + (f"  branch {signs}" if signs else "")
            + flag
        )
    return 0


def branch_signs(module: ModuleType, q: Any) -> str:
    """A solution's branch(q) as signs: "+-0" for (1, -1, 0)."""
    return "".join("0+-"[sign] for sign in module.branch(q))


def cmd_path(args: argparse.Namespace) -> int:
    """Follow a straight line (position on a line, rotation by slerp) from the pose of --from
    to that of --to in --steps poses, keeping the branch of --from (the module's ik_path; an
    arm solved for a task follows the task's components of those poses); print the joint
    values per pose with the breaks, and draw the joint curves with -o."""
    import numpy as np

    spec, module = ik_module(args)
    if getattr(module, "IK_COMPONENTS", "pose") == "lookat":
        raise UsageError(
            f"{spec.name}: a look-at arm's path is of points looked at, not of poses; use the "
            "module's ik_path with poses whose position is the point (ik_lookat's)"
        )
    if not 2 <= args.steps <= 100_000:
        raise UsageError(f"--steps: an integer from 2 to 100000, got {args.steps}")
    start = np.array(joint_vector(spec, parse_numbers(args.start, "--from"), args.rad))
    end = np.array(joint_vector(spec, parse_numbers(args.end, "--to"), args.rad))
    output = figure_output(args, f"{spec.name}_path.svg") if args.output is not None else None
    if output is not None:  # (matplotlib first: not after the whole path is printed)
        from derive.plot import PlotUnavailable, pyplot

        try:
            pyplot()
        except PlotUnavailable as exc:
            raise UsageError(str(exc)) from None
    poses = module.straight_line(module.fk(start), module.fk(end), args.steps)
    Q, breaks = module.ik_path(poses, start, within_limits=args.within_limits,
                               on_break="flag" if args.flag else "stop")  # fmt: skip
    notes = dict(breaks)
    units = ["deg" if t == "R" else spec.length_unit for t in spec.joint_types]
    branches = getattr(module, "BRANCHES", ())
    print(
        "step  "
        + "  ".join(f"{f'q{i + 1} / {u}':>11}" for i, u in enumerate(units))
        + "  sigma_min"
        + (f"  branch ({' '.join(branches)})" if branches else "")
    )
    for k, q in enumerate(Q):
        if np.isnan(q).any():
            break
        shown = [math.degrees(v) if t == "R" else v for v, t in zip(q, spec.joint_types)]
        least = module.manipulability(q)[0]
        signs = "  " + branch_signs(module, q) if branches else ""
        flag = f"  BREAK: {notes[k]}" if k in notes else ""
        print(f"{k:4d}  " + "  ".join(f"{v:11.4f}" for v in shown) + f"  {least:9.3g}{signs}{flag}")
    stopped = [k for k, _ in breaks]
    if stopped and not args.flag:
        k = stopped[0]  # (ik_path's note starts with "pose k: " too)
        print(f"stopped at pose {k} of {args.steps}: {notes[k].removeprefix(f'pose {k}: ')}")
    elif branches and module.branch(Q[-1]) != module.branch(end):
        print(
            "the path ends on another branch than --to's: the same pose in another "
            "configuration (the path keeps --from's branch unless it crosses a fold)"
        )
    print(f"{spec.name}: {args.steps} poses, {len(breaks)} break(s)")
    if output is not None:
        from derive.plot import PlotUnavailable, figure_bytes, path_figure

        try:
            data = figure_bytes(path_figure(Q, breaks, spec.joint_types, spec.name), output[1])
        except PlotUnavailable as exc:
            raise UsageError(str(exc)) from None
        write_atomic(output[0], data)
        print(f"{output[0]}: written")
    return 0 if not breaks else 1


def ik_module(args: argparse.Namespace) -> tuple[ArmSpec, ModuleType]:
    """The arm of args.arm and its generated module, which must have an IK solver."""
    spec = resolve_spec(args.arm, urdf_options(args))
    module = load_module(spec)
    if not hasattr(module, "ik"):
        raise UsageError(f"{spec.name}: no IK method applies to this arm")
    return spec, module


def figure_output(args: argparse.Namespace, default: str) -> tuple[Path, str]:
    """The picture's file (-o, else default) and its format, svg or png."""
    if args.output == "":  # (not the default: `-o ""` drew nothing and said nothing)
        raise UsageError("-o: an empty file name; give FILE.svg or FILE.png")
    output = Path(args.output or default)
    fmt = output.suffix.lstrip(".").lower()
    if fmt not in ("svg", "png"):
        raise UsageError(f"-o: {output}: the file must end in .svg or .png")
    writable_file(output)  # (a file, or none yet, where one can be made: before the work)
    return output, fmt


def solve_arguments(
    spec: ArmSpec, module: ModuleType, args: argparse.Namespace
) -> tuple[Any, list[float], Any]:
    """The pose of --pose or --q, the free joints' values, and every solution (Python ik)."""
    import numpy as np

    q = None
    task = getattr(module, "IK_COMPONENTS", "pose")
    if args.pose is None and args.q is None and args.point is None and args.direction is None:
        raise UsageError(
            "give --pose, --q or --point (or --direction alone for an arm solved for a "
            "direction only; --angle goes with --point)"
        )
    if args.direction is not None and task not in ("direction", "pointing"):
        raise UsageError(
            f"--direction: {spec.name} is solved for "
            + {
                "lookat": "a look-at: give the point only (--point)",
                "axisangle": "a point and the tool axis's angle to a base axis: give --point "
                "and --angle",
            }.get(task, f"the {task}; --direction is for an arm solved for a point and a direction")
        )
    if args.direction is not None and args.point is None and task == "direction":
        raise UsageError("--direction: give the tool point too (--point x y z)")
    if args.direction is not None and (args.pose is not None or args.q is not None):
        raise UsageError("--direction: give it with --point (or alone), not with --pose or --q")
    heading = hasattr(module, "PLANE_Z") and task == "pose"  # (a planar arm's heading)
    if getattr(args, "angle", None) is not None and (
        (task != "axisangle" and not heading) or args.point is None
    ):
        raise UsageError(
            "--angle: with --point, for an arm solved for a point and the tool axis's angle to "
            "a base axis (axisangle) or a planar arm solved for the pose (the heading); "
            f"{spec.name} is solved for the {task}"
        )
    if args.point is not None or args.direction is not None:
        pose = task_pose(spec, module, args)
    elif args.q is not None:
        q = joint_vector(spec, parse_numbers(args.q, "--q"), args.rad)
        pose = module.fk(q)
        if task == "lookat":  # (every configuration sees its own tool point: look ahead)
            pose[:3, 3] += module.REACH * pose[:3, module.TOOL_AXIS]
    else:
        numbers = parse_numbers([args.pose], "--pose")
        if len(numbers) not in (12, 16):
            raise UsageError("--pose: give 12 numbers (3 rows of 4) or 16 (4 rows of 4)")
        pose = np.array([*numbers[:12], 0.0, 0.0, 0.0, 1.0]).reshape(4, 4)
    free = free_values(spec, module, args, q)
    try:
        # (the module's BACKEND: C where it compiles, once per machine; DERIVE_BACKEND sets it)
        sols = module.ik(pose, **({"free": free} if free else {}))
    except ValueError as exc:
        raise UsageError(f"--pose: {exc}") from None
    return pose, free, sols


# what each task reads of a target pose (derive/tasks.py)
TASK_READS = {
    "position": "its position",
    "direction": "its position and its {axis} column",
    "lookat": "its position, the point looked at",
    "pointing": "its {axis} column only",
    "axisangle": "its position and its {axis} column's entry along the base axis",
}


def task_pose(spec: ArmSpec, module: ModuleType, args: argparse.Namespace) -> Any:
    """The pose ik reads an arm's task from: --point's position and, for a direction task,
    --direction as the tool axis's column (the module's own _task_pose completes the frame)."""
    import numpy as np

    task = getattr(module, "IK_COMPONENTS", "pose")
    # (a point beyond any reach: refused here, not solved in overflowing arithmetic)
    far = getattr(module, "FAR_REACH", 1e6) * module.REACH
    if hasattr(module, "PLANE_Z") and args.point is not None:  # (ik_xy(_heading)'s)
        return plane_pose(spec, module, args, far)
    if task == "pose":
        raise UsageError(f"--point: {spec.name} is solved for the full pose; give --pose or --q")
    if task == "pointing":
        if args.point is not None:
            raise UsageError(
                f"--point: {spec.name} is solved for a direction only: give --direction alone"
            )
        return module._task_pose((0.0, 0.0, 0.0), direction_numbers(args.direction))
    if args.point is None:
        raise UsageError(f"--direction: {spec.name} is solved for a point: give --point x y z")
    point = parse_numbers(args.point, "--point")
    if len(point) != 3:
        raise UsageError(f"--point: give 3 numbers, x y z (got {len(point)})")
    if max(map(abs, point)) > far:
        raise UsageError(f"--point: beyond {far:g} (a million times the reach): out of reach")
    direction = None
    if task == "axisangle":
        if args.direction is not None or args.angle is None:
            raise UsageError(
                f"--point: {spec.name} is solved for a point and the tool axis's angle to the "
                "base axis: give --angle (not --direction)"
            )
        top = math.pi if args.rad else 180.0
        if not 0.0 <= args.angle <= top:  # (NaN fails too)
            raise UsageError(
                f"--angle: from 0 to {top:g} ({'radians' if args.rad else 'degrees'}), the "
                f"angle between the tool axis and the base axis; got {args.angle:g}"
            )
        angle = args.angle if args.rad else math.radians(args.angle)
        direction = [0.0, 0.0, 0.0]  # (at that angle: ik reads the base-axis entry only)
        direction[module.CONE_AXIS] = math.cos(angle)
        direction[(module.CONE_AXIS + 1) % 3] = math.sin(angle)
        return module._task_pose(point, direction)
    if task == "direction":
        if args.direction is None:
            raise UsageError(
                f"--point: {spec.name} is solved for a point and a direction: give --direction"
            )
        direction = direction_numbers(args.direction)
    if direction is None:  # (a task that reads the point only: position, look-at)
        pose = np.eye(4)
        pose[:3, 3] = point
        return pose
    return module._task_pose(point, direction)


def plane_pose(spec: ArmSpec, module: ModuleType, args: argparse.Namespace, far: float) -> Any:
    """A planar arm's pose for --point 'x y' (or 'x y z' where a sliding joint lifts the tool)
    and, for an arm solved for the pose, --angle's heading (the module's _plane_pose)."""
    slides = module._PLANE_SLIDE
    point = parse_numbers(args.point, "--point")
    if len(point) != (3 if slides else 2):
        raise UsageError(
            f"--point: {spec.name} is planar: give "
            + ("x y z (a sliding joint lifts the tool)" if slides else "x y, in its plane")
            + f" (got {len(point)} numbers)"
        )
    if max(map(abs, point)) > far:
        raise UsageError(f"--point: beyond {far:g} (a million times the reach): out of reach")
    heading = 0.0
    if module.IK_COMPONENTS == "pose":
        if args.angle is None:
            raise UsageError(
                f"--point: {spec.name} is solved for a point and a heading: give --angle (the "
                f"tool's {'xy'[module.HEADING_AXIS]} axis's angle about z)"
            )
        heading = args.angle if args.rad else math.radians(args.angle)
    try:
        return module._plane_pose(*point[:2], point[2] if slides else None, heading)
    except ValueError as exc:
        raise UsageError(f"--point: {exc}") from None


def direction_numbers(text: list[str]) -> list[float]:
    """--direction's 3 numbers, not all 0."""
    direction = parse_numbers(text, "--direction")
    if len(direction) != 3 or not any(direction):
        raise UsageError("--direction: give 3 numbers, dx dy dz, not all 0")
    return direction


def task_residual(module: ModuleType, q: Any, pose: Any) -> float:
    """How far fk(q) misses the components of pose the arm's task reads (verify.pose_error's
    two errors, the position's in length units)."""
    from derive.verify import pose_error

    rotation, position = pose_error(module, q, pose)
    return max(rotation, position * module.REACH)


def cmd_plot(args: argparse.Namespace) -> int:
    """Draw every IK solution of a pose (one panel each) into an SVG or PNG file."""
    from derive.plot import PlotUnavailable, figure_bytes, solutions_figure

    spec, module = ik_module(args)
    output, fmt = figure_output(args, f"{spec.name}_solutions.svg")
    pose, _, sols = solve_arguments(spec, module, args)
    try:
        fig, _ = solutions_figure(
            module, spec.convention, pose, sols, f"{spec.name}: {len(sols)} solution(s)"
        )
        data = figure_bytes(fig, fmt)
    except PlotUnavailable as exc:
        raise UsageError(str(exc)) from None
    write_atomic(output, data)
    print(f"{output}: {len(sols)} solution(s) drawn")
    return 0


def cmd_workspace(args: argparse.Namespace) -> int:
    """Map a section of the reachable and dexterous workspace and the solutions per position."""
    from derive.plot import PlotUnavailable, figure_bytes, workspace_figure
    from derive.workspace import workspace

    spec, module = ik_module(args)
    if getattr(module, "IK_COMPONENTS", "pose") == "pointing":
        raise UsageError(
            f"{spec.name}: its solver points a tool axis, wherever the tool point is: it has "
            "no workspace of positions (derive solve --direction answers one direction)"
        )
    if not 3 <= args.resolution <= 2001 or args.resolution % 2 == 0:
        raise UsageError("--resolution: an odd number from 3 to 2001 (the grid holds the centre)")
    output, fmt = figure_output(args, f"{spec.name}_workspace.svg")
    planar = is_planar(spec)
    try:
        from derive.plot import pyplot

        pyplot()  # before the computation: say at once if matplotlib is missing
        wmap = workspace(module, planar, spec.convention, args.resolution, args.limits)
        data = figure_bytes(workspace_figure(wmap, f"{spec.name}: workspace section"), fmt)
    except PlotUnavailable as exc:
        raise UsageError(str(exc)) from None
    write_atomic(output, data)
    print(f"{spec.name}: {wmap.summary()}")
    print(f"{output}: written")
    return 0


def cmd_reach(args: argparse.Namespace) -> int:
    """Map where the arm reaches: IK solution counts of every pose of a voxel grid x
    orientations, stored in a zarr folder (resumable), locally or on a Dask cluster."""
    from derive import reach

    spec = resolve_spec(args.arm, urdf_options(args))
    plan = build_plan(spec)
    source = solver_sources(plan)
    if plan.ik is None:
        raise UsageError(f"{spec.name}: no IK method applies to this arm")
    if plan.ik.certify == "lookat":
        raise UsageError(
            f"{spec.name}: its solver looks at a point; reach maps sample orientations "
            "(use derive workspace)"
        )
    if plan.ik.certify == "pointing":
        raise UsageError(
            f"{spec.name}: its solver points a tool axis, wherever the tool point is; reach "
            "maps sample positions (derive solve --direction answers one direction)"
        )
    if plan.ik.certify == "position":
        raise UsageError(
            f"{spec.name}: its solver places the tool point only; reach maps sample "
            "orientations (use derive workspace)"
        )
    if plan.ik.certify == "axisangle":
        raise UsageError(
            f"{spec.name}: its solver places the tool point and tilts the tool axis; reach "
            "maps sample whole orientations (use derive workspace, or derive solve --point "
            "--angle)"
        )
    if not (math.isfinite(args.resolution) and args.resolution > 0):
        raise UsageError(f"--resolution: a positive length, got {args.resolution:g}")
    if not 1 <= args.directions <= 100_000:
        raise UsageError(f"--directions: from 1 to 100000, got {args.directions}")
    if not 1 <= args.rolls <= 3600:
        raise UsageError(f"--rolls: from 1 to 3600, got {args.rolls}")
    if args.directions * args.rolls > 65_536:
        raise UsageError("--directions x --rolls: at most 65536 orientations per voxel")
    if not 0 <= args.processes <= 1024:
        raise UsageError(f"--processes: from 0 (one per core) to 1024, got {args.processes}")
    if not 0 <= args.worker_threads <= 1024:
        raise UsageError(f"--worker-threads: from 0 (automatic) to 1024, got {args.worker_threads}")
    if not 1 <= args.chunk <= 10_000_000:
        raise UsageError(f"--chunk: from 1 to 10000000 poses, got {args.chunk}")
    params = reach.Parameters(
        resolution=args.resolution,
        directions=args.directions,
        rolls=args.rolls,
        within_limits=args.within_limits,
        first=args.first,
        symmetry=not args.no_symmetry,
        chunk=args.chunk,
    )
    output = output_folder(Path(args.output), "-o")
    try:
        figure = None
        if args.output_plot:
            figure = Path(args.output_plot), Path(args.output_plot).suffix.lstrip(".").lower()
            if figure[1] not in ("svg", "png"):
                raise UsageError(f"--plot: {figure[0]}: the file must end in .svg or .png")
            writable_file(figure[0])
            from derive.plot import pyplot

            pyplot()  # say at once if matplotlib is missing
        if args.hdf5:
            writable_file(Path(args.hdf5))
            reach.h5py_module()  # (likewise h5py)
        if args.dask:
            reach.dask_workers(args.dask)  # (a bad address, or no dask.distributed)
        done = reach.run(
            output,
            spec.name,
            spec.digest(),
            source,
            spec.convention,
            params,
            dask=args.dask,
            worker_threads=args.worker_threads,
            processes=args.processes,
        )
        rmap = reach.load(output)
        print(rmap.summary())
        rate = f", {done.poses / done.seconds:,.0f} poses/s" if done.seconds > 0 else ""
        print(
            f"{output}: {done.computed} chunk(s) computed in {done.seconds:.1f} s{rate}"
            + (f", {done.skipped} done before" if done.skipped else "")
            + (f"; {done.repaired} damaged chunk(s) computed again" if done.repaired else "")
        )
        if args.bench and done.computed == 0:
            print("bench: nothing was computed (the map was complete): give a new -o")
        elif args.bench:
            alone = reach.batch_alone(spec.name, source, spec.convention, params)
            rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
            workers = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
            run_rate, alone_rate = done.poses / done.seconds, alone.poses / alone.seconds
            print(
                f"bench: the run {run_rate:,.0f} poses/s; ik_batch alone on the same poses "
                f"{alone_rate:,.0f} poses/s; the run at {100 * run_rate / alone_rate:.1f}% of "
                f"it; peak RSS {rss:.0f} MB (this process), {workers:.0f} MB (its largest "
                "worker process)"
            )
        if args.hdf5:
            poses = reach.export_hdf5(rmap, output_file(Path(args.hdf5)))
            print(f"{args.hdf5}: written (Reuleaux layout, {poses:,} poses)")
        if figure is not None:
            from derive.plot import figure_bytes

            data = figure_bytes(reach.reach_figure(rmap, f"{spec.name}: reachability"), figure[1])
            write_atomic(figure[0], data)
            print(f"{figure[0]}: written")
    except reach.ReachError as exc:
        raise UsageError(str(exc)) from None
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: the chunks written are kept; the same command continues {output}",
            file=sys.stderr,
        )
        return 130
    return 0


def free_values(
    spec: ArmSpec, module: ModuleType, args: argparse.Namespace, q: list[float] | None
) -> list[float]:
    """The free joints' values for solve: --free's (degrees for R joints unless --rad), else
    those of --q, else zeros; [] for an arm without free joints."""
    free = getattr(module, "FREE", ())
    if args.free is None:
        return [q[j - 1] if q is not None else 0.0 for j in free]
    if not free:
        raise UsageError(f"--free: {spec.name} has no free joints")
    numbers = parse_numbers(args.free, "--free")
    if len(numbers) != len(free):
        names = ", ".join(f"q{j}" for j in free)
        raise UsageError(f"--free: give {len(free)} value(s), for {names}")
    values = [
        math.radians(v) if spec.joint_types[j - 1] == "R" and not args.rad else v
        for v, j in zip(numbers, free)
    ]
    limit = module.FREE_LIMIT
    for v, given, j in zip(values, numbers, free):
        if spec.joint_types[j - 1] == "R" and not abs(v) <= limit:
            shown = f"{math.degrees(limit):g} deg" if not args.rad else f"{limit:g} rad"
            raise UsageError(f"--free: q{j} = {given:g}: allowed: within +-{shown}")
    return values


def cmd_bench(args: argparse.Namespace) -> int:
    """Print generation time, solver timings and round-trip figures per arm."""
    import json

    from derive.bench import bench_text, machine, measure

    specs = load_specs(args.specs, urdf_options(args))  # (a bad spec: its error line only)
    if not args.json:
        print(f"machine: {machine()}", flush=True)
    if args.lang == "c":
        return bench_c(args, specs)
    results: list[dict[str, object]] = []
    for spec in specs:
        start = time.perf_counter()
        plan = build_plan(spec)
        render_module(plan)
        generation = time.perf_counter() - start
        if plan.ik is None:  # (an FK-only arm: nothing to time, said in one line)
            results.append({"name": spec.name, "generate_s": generation, "no_ik": plan.refusal})
            if not args.json:
                print(f"{spec.name}: no IK figures: FK only, no IK: {plan.refusal}", flush=True)
            continue
        module = load_module(spec)
        figures = {
            "generate_s": generation,
            "machine": machine(),
            **measure(module, args.samples, args.seed, args.batch, args.memory, sys.stderr),
        }
        results.append(figures)
        if not args.json:
            print(bench_text(spec.name, figures), flush=True)
    if args.json:
        print(json.dumps(results, indent=2, sort_keys=True))
    return 0


# the C benchmark's compiler flags: what a controller's release build would use on this CPU
BENCH_CFLAGS = ("-O3", "-march=native")


def bench_c(args: argparse.Namespace, specs: list[ArmSpec]) -> int:
    """`derive bench --lang c`: the C solver of each spec compiled (BENCH_CFLAGS) and timed by
    its harness on --samples random poses (no joint at a special value), beside the compiled
    Python ik."""
    import numpy as np

    from derive.bench import eaik_figures, median_us, solve_with
    from derive.cbuild import BuildError, Harness
    from derive.verify import sample_joints, targets

    for spec in specs:
        plan = build_plan(spec)
        if plan.ik is None:
            print(f"{spec.name}: no C figures: FK only, no IK: {plan.refusal}")
            continue
        with tempfile.TemporaryDirectory() as tmp:
            try:
                harness = Harness(plan, Path(tmp), opt=BENCH_CFLAGS)
            except (BuildError, GenerationError) as exc:
                print(f"{spec.name}: no C figures: {exc}")
                continue
            module = load_module(spec)
            rng = np.random.default_rng(args.seed)
            Q = sample_joints(module, args.samples, rng, degenerate_share=0.0)
            T = targets(module, Q)  # (a look-at's point one REACH ahead)
            refs = np.zeros_like(Q)
            for j in module.FREE:
                refs[:, j - 1] = Q[:, j - 1]
            least, median, single = harness.bench(T, refs)
        kw = [{"free": [r[j - 1] for j in module.FREE]} if module.FREE else {} for r in refs]
        module.ik(T[0], **kw[0])  # compile the C (or load it from the cache) before timing
        python = median_us(partial(solve_with, module), list(zip(T, kw)))
        batch = math.inf
        free = {"free": refs[:, [j - 1 for j in module.FREE]]} if module.FREE else {}
        for _ in range(3):
            start = time.perf_counter()
            module.ik_batch(T, **free)
            batch = min(batch, (time.perf_counter() - start) / len(T) * 1e6)
        line = (
            f"{spec.name}: C ({' '.join(BENCH_CFLAGS)}) ik {least / 1000:.3f} us/pose (least "
            f"of 21 rounds over {len(T)} poses; median round {median / 1000:.3f}), "
            f"{single / 1000:.3f} us median single call (each pose's least of 21); Python "
            f"module ({module.BACKEND} backend): ik {python:.1f} us (median), ik_batch "
            f"{batch:.2f} us/pose (best of 3)"
        )
        eaik = eaik_figures(module, T)
        if "eaik_ik_us" in eaik:
            line += (
                f"; EAIK ik {eaik['eaik_ik_us']:.1f} us (median), batch "
                f"{eaik['eaik_batch_us']:.2f} us/pose"
            )
        print(line, flush=True)
    return 0


def cmd_build(args: argparse.Namespace) -> int:
    """`derive build ARM --lang c`: lib<name>_ik.so and its ctypes binding <name>_c.py."""
    from derive.cbuild import BuildError, build

    spec = resolve_spec(args.arm, urdf_options(args))
    out = output_folder(Path(args.out), "-o")
    for name in (f"lib{spec.name}_ik.so", f"{spec.name}_c.py"):
        if output_file(out / name) != out / name:
            raise UsageError(
                f"{out / name}: is a symbolic link; derive build replaces its files in the -o "
                "folder (give -o the folder the link points into)"
            )
    try:
        binding = build(build_plan(spec), out)
    except BuildError as exc:
        raise UsageError(str(exc).replace("\n", " ")) from None
    print(f"{binding} (and {binding.with_name(f'lib{spec.name}_ik.so').name}): import it")
    return 0


def cmd_report(args: argparse.Namespace) -> int:
    """Write (or print) the derivation report of one arm."""
    output = text_output(args.output)
    spec = resolve_spec(args.arm, urdf_options(args))
    plan = build_plan(spec)
    module = load_solver(spec.name, solver_sources(plan))
    example = worked_example(plan, module)
    figures = report_figures(spec, plan, module, example, args) if args.figures else ()
    text = render_report(plan, example, args.format, figures)
    if output is not None:
        write_atomic(output, text)
    else:
        sys.stdout.write(text)
    return 0


# how -o of a text output is read (its help)
TEXT_OUTPUT = (
    "default or -: standard output; a symbolic link's file is replaced; a pipe, device or "
    "socket is refused"
)


def text_output(option: str | None) -> Path | None:
    """The file of a text output's -o, checked before any work (see output_file); None for
    standard output (no -o, or ``-o -``)."""
    if option is None or option == "-":
        return None
    try:
        path = output_file(Path(option))
        existing_folder(path.parent, option)
        return path
    except OutputError as exc:
        raise OutputError(f"{exc} (-o - prints to standard output)") from None


def report_figures(
    spec: ArmSpec, plan: Plan, module: ModuleType, example: Example, args: argparse.Namespace
) -> tuple[tuple[str, str], ...]:
    """The report's pictures, written beside its output (or into the working folder), SVG
    for Markdown, PNG for LaTeX (which pdflatex includes). Returns (caption, file name)
    pairs."""
    folder = Path(args.output).parent if args.output not in (None, "-") else Path(".")
    made = figure_files(spec, module, example, "png" if args.format == "tex" else "svg")
    for _, name, _ in made:
        output_file(folder / name)  # (each checked before any is written)
    for _, name, data in made:
        write_atomic(folder / name, data)
    return tuple((caption, name) for caption, name, _ in made)


class Parser(argparse.ArgumentParser):
    """argparse's parser, its errors one line on stderr (exit 2) as every other error here:
    the usage is one `--help` away."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"error: {self.prog}: {message} (see {self.prog} --help)\n")


def count(least: int) -> Any:
    """An argparse type: an integer of at least `least` (a count of samples or poses)."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = least - 1
        if value < least:
            raise argparse.ArgumentTypeError(f"{text!r}: allowed: an integer >= {least}")
        return value

    return parse


def parser() -> argparse.ArgumentParser:
    """The argument parser of `derive`."""
    top = Parser(prog="derive", description="Closed-form IK solvers from DH tables.")
    top.add_argument("--version", action="version", version=f"derive-ik {extras.version()}")
    sub = top.add_subparsers(dest="command", required=True)
    gen = sub.add_parser("generate", help="write generated/<name>.py and <name>.md for each arm")
    gen.add_argument(
        "specs", nargs="*", help="spec files or bundled arm names (default: all bundled)"
    )
    gen.add_argument("-o", "--out", default=DEFAULT_OUT, help="output folder (default ./generated)")
    gen.add_argument("--require-ik", action="store_true", help="exit 3 if an arm has no IK method")
    gen.add_argument(
        "--lang",
        choices=tuple(LANGUAGES),
        default="python",
        help="; ".join(f"{lang.name}: {lang.summary}" for lang in LANGUAGES.values())
        + " (default: python)",
    )
    gen.add_argument(
        "--figures",
        action="store_true",
        help="also draw each report's worked example and workspace section (SVG, embedded)",
    )
    gen.set_defaults(run=cmd_generate)
    chk = sub.add_parser("check", help="fail if DIR is not what generate would write")
    chk.add_argument("specs", nargs="*", help="spec files (default: all bundled arms)")
    chk.add_argument("--out", default=DEFAULT_OUT, help="folder to check (default ./generated)")
    chk.add_argument("--figures", action="store_true", help="as generate --figures wrote DIR")
    chk.set_defaults(run=cmd_check)
    fk = sub.add_parser("fk", help="print the pose for joint values")
    fk.add_argument("arm", help="spec file or bundled arm name")
    fk.add_argument("q", nargs="+", help="joint values (degrees for R joints unless --rad)")
    fk.add_argument("--rad", action="store_true", help="R joint values are in radians")
    fk.set_defaults(run=cmd_fk)
    solve = sub.add_parser("solve", help="print every IK solution of a pose")
    add_pose_arguments(solve)
    solve.set_defaults(run=cmd_solve)
    path = sub.add_parser(
        "path", help="follow a straight line of poses keeping the branch (ik_path), with breaks"
    )
    path.add_argument("arm", help="spec file or bundled arm name")
    path.add_argument(
        "--from", dest="start", nargs="+", required=True, help="the start's joint values"
    )
    path.add_argument(
        "--to", dest="end", nargs="+", required=True, help="joint values whose pose ends the line"
    )
    path.add_argument("--steps", type=int, default=50, help="poses on the line (default 50)")
    path.add_argument("--rad", action="store_true", help="joint values are in radians")
    path.add_argument("--within-limits", action="store_true", help="stay inside the limits")
    path.add_argument("--flag", action="store_true", help="go on after a break (flagged)")
    path.add_argument("-o", "--output", help="draw the joint curves: FILE.svg or FILE.png")
    path.set_defaults(run=cmd_path)
    plot = sub.add_parser("plot", help="draw every IK solution of a pose (needs matplotlib)")
    add_pose_arguments(plot)
    plot.add_argument("-o", "--output", help="FILE.svg or FILE.png (default: NAME_solutions.svg)")
    plot.set_defaults(run=cmd_plot)
    space = sub.add_parser(
        "workspace", help="reachable and dexterous workspace section (needs matplotlib)"
    )
    space.add_argument("arm", help="spec file or bundled arm name")
    space.add_argument("-o", "--output", help="FILE.svg or FILE.png (default: NAME_workspace.svg)")
    space.add_argument(
        "--resolution", type=int, default=201, help="grid points per side, odd (default 201)"
    )
    space.add_argument("--limits", action="store_true", help="honour the joint limits")
    space.set_defaults(run=cmd_workspace)
    reach = sub.add_parser(
        "reach", help="reachability map: IK on a voxel grid x orientations (zarr, needs [scale])"
    )
    reach.add_argument("arm", help="spec file or bundled arm name")
    reach.add_argument("-o", "--output", required=True, help="the map's folder, MAP.zarr")
    reach.add_argument(
        "--resolution", type=float, default=0.05, help="voxel side, in the arm's lengths (0.05)"
    )
    reach.add_argument(
        "--directions", type=int, default=200, help="approach directions per voxel (200)"
    )
    reach.add_argument("--rolls", type=int, default=8, help="rolls about each direction (8)")
    reach.add_argument(
        "--within-limits", action="store_true", help="count the solutions inside the limits"
    )
    reach.add_argument("--first", action="store_true", help="also store each pose's first solution")
    reach.add_argument(
        "--no-symmetry", action="store_true", help="solve every voxel and roll (no reduction)"
    )
    reach.add_argument(
        "--chunk",
        type=int,
        default=262_144,
        help="poses per chunk, the unit of work, storage and resuming (262144)",
    )
    reach.add_argument(
        "--dask",
        metavar="ADDRESS",
        help="run on Dask: local:N (N worker processes here) or tcp://HOST:PORT (a scheduler)",
    )
    reach.add_argument(
        "--bench",
        action="store_true",
        help="then time ik_batch alone on the same poses and compare (needs a fresh -o)",
    )
    reach.add_argument(
        "--processes",
        type=int,
        default=0,
        help="without --dask: worker processes here (default 0: one per core; 1: this one)",
    )
    reach.add_argument(
        "--worker-threads",
        type=int,
        default=0,
        help="ik_batch threads per Dask worker (default: cores / N for local:N, else a "
        "worker's cores / its task threads)",
    )
    reach.add_argument("--hdf5", metavar="FILE.h5", help="also export in Reuleaux's HDF5 layout")
    reach.add_argument(
        "--plot", metavar="FILE", dest="output_plot", help="draw two sections (.svg or .png)"
    )
    reach.set_defaults(run=cmd_reach)
    report = sub.add_parser("report", help="the derivation, lecture style (Markdown or LaTeX)")
    report.add_argument("arm", help="spec file or bundled arm name")
    report.add_argument("--format", choices=("md", "tex"), default="md", help="md (default) or tex")
    report.add_argument("-o", "--output", help=f"write to this file ({TEXT_OUTPUT})")
    report.add_argument(
        "--figures",
        action="store_true",
        help="draw the worked example's solutions and a workspace section beside the report",
    )
    report.set_defaults(run=cmd_report)
    bench = sub.add_parser("bench", help="time generation and solvers; round-trip figures")
    bench.add_argument("specs", nargs="*", help="spec files or bundled arm names (default: all)")
    bench.add_argument(
        "--samples", "--n", type=count(1), default=10000, help="round-trip samples (10000)"
    )
    bench.add_argument("--seed", type=int, default=0, help="random seed (0)")
    bench.add_argument(
        "--batch",
        type=count(1),
        default=100_000,
        help=(
            "the most poses for ik_batch timing (100000; fewer where one call would take over"
            " 2 s: the figures say how many)"
        ),
    )
    bench.add_argument(
        "--memory",
        type=count(0),
        default=0,
        help="also measure ik_batch peak memory on this many poses",
    )
    bench.add_argument("--json", action="store_true", help="print figures as JSON")
    bench.add_argument(
        "--lang",
        choices=("python", "c"),
        default="python",
        help=(
            "c: time the generated C solver (compiled -O3 -march=native here) instead: timings"
            " only, no round trip (the default, python, runs that)"
        ),
    )
    bench.set_defaults(run=cmd_bench)
    build = sub.add_parser(
        "build", help="compile an arm's C solver into a shared library with a Python binding"
    )
    build.add_argument("arm", help="spec file or bundled arm name")
    build.add_argument("--lang", choices=("c",), default="c", help="c (the only one)")
    build.add_argument("-o", "--out", default="build", help="output folder (default ./build)")
    build.set_defaults(run=cmd_build)
    imp = sub.add_parser("import-urdf", help="write the spec of a URDF's chain from base to tip")
    imp.add_argument("urdf", help="the URDF file (xacro expanded)")
    imp.add_argument(
        "--convention",
        choices=("modified", "standard"),
        default="modified",
        help="DH convention of the spec (modified)",
    )
    imp.add_argument("-o", "--output", help=f"write the spec to this file ({TEXT_OUTPUT})")
    imp.set_defaults(run=cmd_import_urdf)
    imj = sub.add_parser(
        "import-mjcf",
        help="write the spec of an MJCF (MuJoCo XML) chain from base to tip body (extra: mjcf)",
    )
    imj.add_argument("mjcf", help="the MJCF file (MuJoCo's compiler reads it)")
    imj.add_argument(
        "--convention",
        choices=("modified", "standard"),
        default="modified",
        help="DH convention of the spec (modified)",
    )
    imj.add_argument("-o", "--output", help=f"write the spec to this file ({TEXT_OUTPUT})")
    imj.set_defaults(run=cmd_import_mjcf)
    for command in (gen, chk, fk, solve, plot, path, space, reach, report, bench, build, imp, imj):
        add_urdf_arguments(command, required=command in (imp, imj))
    return top


def add_pose_arguments(command: argparse.ArgumentParser) -> None:
    """The arm and the pose of solve and plot: --pose or --q, --rad, --free."""
    command.add_argument("arm", help="spec file or bundled arm name")
    # (one of them, or --direction alone for an arm solved for a direction only: checked in
    # solve_arguments)
    group = command.add_mutually_exclusive_group()
    group.add_argument("--pose", help="'r11 r12 r13 px r21 ... pz' (12 or 16 numbers)")
    group.add_argument("--q", nargs="+", help="solve the pose of these joint values")
    group.add_argument(
        "--point",
        nargs="+",
        help="an arm solved for a task: the tool point (position, direction) or the point "
        "looked at (lookat), 'x y z'; a planar arm: 'x y' in its plane ('x y z' where a "
        "sliding joint lifts it), with --angle the heading",
    )
    command.add_argument(
        "--direction",
        nargs="+",
        help="with --point: the tool axis's direction, 'dx dy dz' (alone for an arm solved for "
        "a direction only: pointing)",
    )
    command.add_argument(
        "--angle",
        type=float,
        help="with --point (axisangle): the tool axis's angle to the base axis; a planar arm "
        "solved for the pose: the heading about z; degrees (--rad: radians)",
    )
    command.add_argument(
        "--rad", action="store_true", help="--q, --free and --angle values are in radians"
    )
    command.add_argument(
        "--free", nargs="+", help="an arm with free joints: their values (default: --q's, or 0)"
    )


def add_urdf_arguments(command: argparse.ArgumentParser, required: bool) -> None:
    """The options of a URDF's conversion (used where an arm is a .urdf file)."""
    group = command.add_argument_group(
        "URDF or MJCF input (ARM.urdf, ARM.xml)",
        "applied to the URDF and MJCF files named; spec files and bundled arms named beside "
        "them keep their own",
    )
    group.add_argument(
        "--base", required=required, help="the URDF link (MJCF body) the chain starts from"
    )
    group.add_argument(
        "--tip", required=required, help="the URDF link (MJCF body or site) the chain ends at"
    )
    group.add_argument("--name", help="the arm's name (default: the URDF robot's)")
    group.add_argument(
        "--angle-tol",
        type=float,
        default=urdf.ANGLE_TOL,
        help=f"snap angles this close (rad) to parallel / 0 / 90 / 180 deg ({urdf.ANGLE_TOL:g})",
    )
    group.add_argument(
        "--length-tol",
        type=float,
        default=urdf.LENGTH_TOL,
        help=f"snap lengths this close to 0, relative to the arm's size ({urdf.LENGTH_TOL:g})",
    )
    group.add_argument("--exact", action="store_true", help="no snapping")
    group.add_argument(
        "--task",
        choices=IK_TASKS,
        help="what ik solves for (the spec's [ik] task; default: the joints choose)",
    )
    group.add_argument(
        "--tool-axis",
        choices=TOOL_AXES,
        help='the tool axis of the "direction", "lookat", "pointing" and "axisangle" tasks '
        "(default: z, else the first of x, y that works)",
    )
    group.add_argument(
        "--base-axis",
        choices=TOOL_AXES,
        help='the base axis of the "axisangle" task (the tool axis\'s angle to it; default z)',
    )
    group.add_argument(
        "--method",
        choices=IK_METHODS,
        help="this IK method only (the spec's [ik] method; default: the first that applies; "
        "general: an arm near a special one gets its complete solution set, slower)",
    )
    group.add_argument(
        "--max-deviation",
        type=float,
        default=urdf.MAX_DEVIATION,
        help=f"refuse if snapping moves FK more than this, of the reach ({urdf.MAX_DEVIATION:g})",
    )


def cmd_import_urdf(args: argparse.Namespace) -> int:
    """Write (or print) the spec of a URDF chain; say what the conversion did on stderr."""
    return write_import(args, args.urdf, "URDF", urdf.import_urdf)


def cmd_import_mjcf(args: argparse.Namespace) -> int:
    """Write (or print) the spec of an MJCF chain; say what the conversion did on stderr."""
    return write_import(args, args.mjcf, "MJCF", mjcf.import_mjcf)


def write_import(
    args: argparse.Namespace,
    source: str,
    kind: str,
    convert: Callable[[Path, urdf.Options], tuple[str, urdf.Conversion]],
) -> int:
    """import-urdf's and import-mjcf's work: the spec to the output, the record to stderr."""
    output = text_output(args.output)
    text, conversion = convert(Path(source), urdf_options(args))
    # a task the chain cannot do is refused here, as generate refuses it, rather than written
    # into a spec every later command refuses
    spec = parse_spec(text, f"{source} ({args.base} .. {args.tip})")
    task_of(spec, chain_from_spec(spec))
    if output is not None:
        write_atomic(output, text)
    else:
        sys.stdout.write(text)
    snaps = f"{len(conversion.snaps)} snap(s)" if conversion.snaps else "no snapping"
    print(
        f"{source}: {len(conversion.rows)} joint{'s' if len(conversion.rows) != 1 else ''}; "
        f"{snaps}; FK deviation from the {kind} "
        f"{conversion.deviation:.2g} (of the reach, {urdf.SAMPLES} random joint vectors)",
        file=sys.stderr,
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the `derive` command."""
    top = parser()
    args, extra = top.parse_known_args(argv)
    if extra:  # (spec names after options: `derive bench robot.urdf --base B --tip T puma560`)
        names = [x for x in extra if not x.startswith("-")]
        if names != extra or not isinstance(getattr(args, "specs", None), list):
            top.error(f"unrecognized arguments: {' '.join(extra)}")
        args.specs += names
    try:
        code: int = args.run(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at exit
        return code
    except (SpecError, UsageError, OutputError, GenerationError, LoadError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (RecursionError, MemoryError) as exc:  # (an arm whose expressions grow too large)
        what = "recursion depth" if isinstance(exc, RecursionError) else "memory"
        print(
            f"error: the derivation ran out of {what}: the arm's expressions are too large "
            "(a chain of many joints with no special structure); give fewer joints",
            file=sys.stderr,
        )
        return 2
    except BrokenPipeError:
        # the reader went away (`derive check | head`): stop quietly, as cat would
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
