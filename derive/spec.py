"""Arm description: parse and validate a TOML spec into frozen dataclasses.

This module is the one place where spec files are validated. Every error is a
:class:`SpecError` whose one-line message names the file, the field (with the joint
number where there is one) and what is allowed. Values are read as TOML numbers only:
nothing from a spec is evaluated, and the arm name is the only spec text that reaches
generated code or file names.

Spec format (all keys other than those listed are errors)::

    name = "puma560"            # [a-z][a-z0-9_]*, at most 64 characters
    convention = "standard"     # "standard" | "modified" (Craig)
    angle_unit = "deg"          # "deg" | "rad": alpha, theta, revolute limits, rpy
    length_unit = "m"           # a label
    [[joint]]
    type = "R"                  # "R": theta_i = q_i + theta; "P": d_i = q_i + d
    alpha = -90.0               # modified DH: alpha_{i-1}; standard DH: alpha_i
    a = 0.0                     # modified DH: a_{i-1};     standard DH: a_i
    d = 0.0
    theta = 0.0
    limits = [-160.0, 160.0]    # optional
    [base]                      # optional: matrix = 4x4, or translation (+ rpy)
    [tool]                      # optional: same keys
    [example]                   # optional: the report's worked example: q = [...] (joint
                                # values in the spec's units), or a world pose given like base
    [ik]                        # optional
    free = [7]                  # the joints (1-based) an arm of more than 6 joints leaves
                                # free: ik takes their values; default: derive chooses
    structure_tol = 1e-3        # twists within this many radians of a multiple of 90 deg
                                # and lengths within this fraction of the arm's size of 0
                                # are taken as special to choose a closed form, whose
                                # answers are then refined onto the exact table
                                # (derive/nominal.py); 0: only exact special values
    task = "direction"          # what ik solves for: "pose" (6 joints), "position" (3),
                                # "direction" (5: the tool point and the direction of a
                                # tool axis), "lookat" (2: the tool axis's ray through a
                                # point), "pointing" (2: the tool axis's direction only),
                                # "axisangle" (4: the tool point and the angle of a tool
                                # axis to a base axis); default: the joints choose
                                # (derive/tasks.py)
    tool_axis = "z"             # the tool axis of "direction", "lookat", "pointing" and
                                # "axisangle" (x, y or z; default z, or the first that works)
    base_axis = "z"             # the base axis of "axisangle" (x, y or z; default z)
    method = "general"          # this method only (pieper, three-parallel, planar, position,
                                # general); default: the first that applies. "general"
                                # gives an arm near a special one its complete solutions
    [exact]                     # optional (derive import-urdf writes it): the arm's exact
    frames = [[...], ...]       # geometry as n + 1 fixed frames, 12 numbers each (the top
                                # three rows of F_i, row-major; lengths in length_unit):
                                # T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n, J_i = Rz(q_i)
                                # (R) or Tz(q_i) (P). The table above is then the nominal
                                # one the closed form solves; fk is the frames'
"""

from __future__ import annotations

import hashlib
import json
import keyword
import math
import re
import stat
import sys
import tomllib
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

NAME_PATTERN = re.compile(r"[a-z][a-z0-9_]*")
NAME_MAX = 64
# the most joints an arm may have: SymPy's products of a longer chain of generic joints take
# minutes and gigabytes (a new user's generic URDF chains: 10 joints 73 s; 11 a RecursionError
# after 5 minutes and 3.8 GB; 12 killed by the kernel at 24 GB)
MAX_JOINTS = 10
RIGID_TOL = 1e-9
# Spec numbers: 0, or magnitudes a robot description can mean (lengths from nanometres to
# kilometres in any unit, angles); outside this range the derivation's tolerances lose sense.
MIN_MAGNITUDE = 1e-9
MAX_MAGNITUDE = 1e9
# Modules a generated module or its users import besides the standard library's
# (sys.stdlib_module_names): a generated <name>.py must not shadow them in its folder.
SHADOWED_MODULES = frozenset(
    {
        "derive_ik_runtime",  # (the runtime written beside every generated module)
        "numpy",
        "numba",
        "llvmlite",
        "scipy",
        "sympy",
        "mpmath",
        "jinja2",
        "markupsafe",
        "derive",
        "pytest",
        "hypothesis",
        "setuptools",
        "pip",
        "pkg_resources",
        "matplotlib",
        "yaml",
        "six",
        "typing_extensions",
        "conftest",
    }
)
TOP_KEYS = (
    "name", "convention", "angle_unit", "length_unit", "joint", "base", "tool", "example", "source",
    "exact",
    "ik",
)  # fmt: skip
IK_KEYS = ("free", "structure_tol", "task", "tool_axis", "base_axis", "method")
# what [ik] method may be (derive/pipeline.py's METHODS: one method only, not the first that
# applies; "general" gives a calibrated arm its complete solution set)
IK_METHODS = ("pieper", "three-parallel", "planar", "position", "general")
# what [ik] task and tool_axis may be (derive/tasks.py)
IK_TASKS = ("pose", "position", "direction", "lookat", "pointing", "axisangle")
TOOL_AXES = ("x", "y", "z")
# the joints each task needs: an arm with more has free joints ([ik] free)
TASK_JOINTS = {"pose": 6, "position": 3, "direction": 5, "lookat": 2, "pointing": 2, "axisangle": 4}
# what [ik] structure_tol may be: beyond 0.1 rad or 0.1 of the arm's size it changes the arm
STRUCTURE_TOL_RANGE = (0.0, 0.1)
SOURCE_KEYS = ("urdf", "sha256", "base", "tip", "joints", "snaps", "deviation", "format")
# the formats a spec is converted from ([source] format; URDF when absent)
SOURCE_FORMATS = ("URDF", "MJCF")
# the text a [source] table may hold (it reaches the report, never the generated code)
SOURCE_TEXT = re.compile(r"[A-Za-z0-9_ .,:;()+\-<>'=/]{1,200}")
JOINT_KEYS = ("type", "alpha", "a", "d", "theta", "limits")
FRAME_KEYS = ("matrix", "translation", "rpy")


class SpecError(ValueError):
    """A spec file is invalid; the message is one line naming file, field and what is allowed."""


@dataclass(frozen=True)
class Joint:
    """One DH row as written in the spec (angles in the spec's angle unit).

    Attributes:
        kind: "R" (revolute) or "P" (prismatic).
        alpha: link twist (alpha_{i-1} in modified DH, alpha_i in standard DH).
        a: link length (a_{i-1} in modified DH, a_i in standard DH).
        d: link offset d_i (the constant part for a prismatic joint).
        theta: joint angle offset theta_i (the full angle for a prismatic joint).
        limits: (lower, upper) in the spec's unit, or None.
    """

    kind: str
    alpha: float
    a: float
    d: float
    theta: float
    limits: tuple[float, float] | None


@dataclass(frozen=True)
class Frame:
    """A rigid transform given in the spec: a 4x4 matrix, or translation and roll-pitch-yaw.

    Attributes:
        matrix: 16 numbers, row-major, when given as `matrix`; else None.
        translation: (x, y, z) when given as `translation`; else None.
        rpy: (roll, pitch, yaw) in the spec's angle unit; R = Rz(yaw) Ry(pitch) Rx(roll).
    """

    matrix: tuple[float, ...] | None
    translation: tuple[float, float, float] | None
    rpy: tuple[float, float, float]


@dataclass(frozen=True)
class Source:
    """Where a spec came from, when derive wrote it from a URDF (the [source] table).

    Attributes:
        urdf: the URDF's file name.
        sha256: the first 16 hex digits of the URDF's SHA-256.
        base, tip: the links the chain runs between.
        joints: the URDF joint name of each row.
        snaps: the snaps the conversion applied, one line each.
        deviation: the largest FK difference of the spec from the URDF (rotation entries,
            positions divided by the arm's size) on random joint values.
        format: the file's format: "URDF", or "MJCF" (then urdf is the MJCF file's name,
            base and tip are bodies).
    """

    urdf: str
    sha256: str
    base: str
    tip: str
    joints: tuple[str, ...]
    snaps: tuple[str, ...]
    deviation: float
    format: str = "URDF"


@dataclass(frozen=True)
class ArmSpec:
    """A validated arm description.

    Attributes:
        name: identifier of the arm; also the generated module's name.
        convention: "standard" or "modified".
        angle_unit: "deg" or "rad".
        length_unit: a label for the length unit.
        joints: the DH rows in order.
        base: frame 0 in the world, or None.
        tool: tool frame in the last link frame, or None.
        example_q: joint values of the report's worked example (spec units), or None.
        example_pose: world pose of the worked example, or None (then example_q or a default).
        source: the file the spec came from (for messages), or "<memory>".
        origin: the URDF the spec was converted from, or None.
        free: the joints (1-based, ascending) named free in [ik], or None (derive chooses).
        structure_tol: [ik] structure_tol, or None (derive.nominal.STRUCTURE_TOL).
        task: [ik] task, or None (the joints choose: derive/tasks.py).
        tool_axis: [ik] tool_axis, or None (z, or the first that works).
        base_axis: [ik] base_axis, or None (z): the "axisangle" task's.
        method: [ik] method, or None (the first method that applies).
        exact: [exact] frames (n + 1 tuples of 12 floats), or None (the table is exact).
    """

    name: str
    convention: str
    angle_unit: str
    length_unit: str
    joints: tuple[Joint, ...]
    base: Frame | None
    tool: Frame | None
    example_q: tuple[float, ...] | None = None
    example_pose: Frame | None = None
    source: str = "<memory>"
    origin: Source | None = None
    free: tuple[int, ...] | None = None
    structure_tol: float | None = None
    exact: tuple[tuple[float, ...], ...] | None = None
    task: str | None = None
    tool_axis: str | None = None
    method: str | None = None
    base_axis: str | None = None

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joints)

    @property
    def joint_types(self) -> str:
        """Joint kinds as one string, e.g. "RRRRRR"."""
        return "".join(j.kind for j in self.joints)

    def canonical(self) -> dict:
        """The spec as plain data with a fixed key order (source excluded)."""

        def frame(f: Frame | None) -> dict | None:
            if f is None:
                return None
            return {"matrix": f.matrix, "translation": f.translation, "rpy": f.rpy}

        data: dict[str, object] = {
            "name": self.name,
            "convention": self.convention,
            "angle_unit": self.angle_unit,
            "length_unit": self.length_unit,
            "joints": [
                {
                    "type": j.kind,
                    "alpha": j.alpha,
                    "a": j.a,
                    "d": j.d,
                    "theta": j.theta,
                    "limits": j.limits,
                }
                for j in self.joints
            ],
            "base": frame(self.base),
            "tool": frame(self.tool),
            "example": {"q": self.example_q, "pose": frame(self.example_pose)},
        }
        if self.origin is not None:  # (absent from the digests of specs without one)
            data["source"] = asdict(self.origin)
        ik: dict[str, object] = {}
        if self.free is not None:  # (likewise)
            ik["free"] = list(self.free)
        if self.structure_tol is not None:  # (likewise)
            ik["structure_tol"] = self.structure_tol
        if self.task is not None:  # (likewise)
            ik["task"] = self.task
        if self.tool_axis is not None:  # (likewise)
            ik["tool_axis"] = self.tool_axis
        if self.method is not None:  # (likewise)
            ik["method"] = self.method
        if self.base_axis is not None:  # (likewise)
            ik["base_axis"] = self.base_axis
        if ik:
            data["ik"] = ik
        if self.exact is not None:  # (likewise)
            data["exact"] = [list(f) for f in self.exact]
        return data

    def digest(self) -> str:
        """SHA-256 (first 16 hex digits) of the canonical spec; independent of file layout."""
        text = json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_spec(path: str | Path) -> ArmSpec:
    """Read and validate a spec file.

    Args:
        path: the TOML file.

    Returns:
        The validated spec.

    Raises:
        SpecError: the file is missing, unreadable, not TOML, or invalid.
    """
    where = str(path)
    try:
        if not stat.S_ISREG(Path(path).stat().st_mode):  # (a pipe would block the read)
            raise SpecError(f"{where}: not a regular file")
        raw = Path(path).read_bytes()
    except OSError as exc:
        raise SpecError(f"{where}: cannot read the spec file ({exc.strerror or exc})") from None
    return parse_spec(raw, where)


def parse_spec(raw: bytes | str, where: str = "<memory>") -> ArmSpec:
    """Validate spec text.

    Args:
        raw: TOML text (bytes must be UTF-8).
        where: the name used in error messages.

    Returns:
        The validated spec.

    Raises:
        SpecError: the text is not UTF-8 TOML or does not describe a valid arm.
    """
    if isinstance(raw, bytes):
        try:
            raw = raw.decode("utf-8-sig")  # a byte-order mark (as some editors save) is fine
        except UnicodeDecodeError:
            raise SpecError(f"{where}: not UTF-8 text; a spec is a TOML file") from None
    try:
        data = tomllib.loads(raw)
    except tomllib.TOMLDecodeError as exc:
        raise SpecError(f"{where}: not valid TOML ({exc})") from None
    except RecursionError:
        raise SpecError(f"{where}: not valid TOML (nesting too deep)") from None
    return _validate(data, where)


def shadows_a_module(name: str) -> bool:
    """Whether a generated <name>.py would shadow a module its folder imports (SHADOWED_MODULES,
    or the standard library's)."""
    return name in SHADOWED_MODULES or name in sys.stdlib_module_names


def _validate(data: dict, where: str) -> ArmSpec:
    _no_unknown_keys(data, TOP_KEYS, where, "")
    name = _choice_or_text(data, "name", where)
    if not NAME_PATTERN.fullmatch(name) or len(name) > NAME_MAX or keyword.iskeyword(name):
        raise SpecError(
            f"{where}: name: {name[:40]!r} is not allowed; use [a-z][a-z0-9_]* "
            f"(at most {NAME_MAX} characters, not a Python keyword)"
        )
    if shadows_a_module(name):
        raise SpecError(
            f"{where}: name: {name!r} is the name of a module the generated code or Python "
            f"uses; {name}.py would shadow it for every import in its folder; choose another "
            f"name (e.g. {name}_arm)"
        )
    convention = _choice_or_text(data, "convention", where, ("standard", "modified"))
    angle_unit = _choice_or_text(data, "angle_unit", where, ("deg", "rad"))
    length_unit = _choice_or_text(data, "length_unit", where)
    if not re.fullmatch(r"[A-Za-z]{1,16}", length_unit):
        raise SpecError(
            f"{where}: length_unit: {length_unit[:40]!r} is not allowed; "
            'use a unit label of 1 to 16 letters, e.g. "m" or "mm"'
        )
    rows = data.get("joint")
    if rows is None:
        raise SpecError(f"{where}: joint: missing; give one [[joint]] table per joint")
    if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
        raise SpecError(f"{where}: joint: must be an array of tables ([[joint]])")
    if not 1 <= len(rows) <= MAX_JOINTS:
        raise SpecError(
            f"{where}: joint: {len(rows)} joints; allowed 1 to {MAX_JOINTS} (a longer chain's "
            "derivation takes minutes and gigabytes: give the arm's own joints, --base and "
            "--tip nearer together for a URDF or MJCF)"
        )
    joints = tuple(_joint(row, where, i + 1) for i, row in enumerate(rows))
    if angle_unit == "rad":  # (a table in degrees with the unit left at "rad")
        for i, joint in enumerate(joints, start=1):
            for key in ("alpha", "theta"):
                value = getattr(joint, key)
                if abs(value) > 2.0 * math.pi + 1e-9:
                    raise SpecError(
                        f"{where}: joint {i}: {key}: {value:g} is beyond 2 pi with angle_unit "
                        '= "rad"; allowed: radians from -2 pi to 2 pi (is the table in degrees? '
                        'then set angle_unit = "deg")'
                    )
    base = _frame(data.get("base"), where, "base", angle_unit)
    tool = _frame(data.get("tool"), where, "tool", angle_unit)
    example_q, example_pose = _example(data.get("example"), where, len(joints))
    return ArmSpec(
        name,
        convention,
        angle_unit,
        length_unit,
        joints,
        base,
        tool,
        example_q,
        example_pose,
        where,
        _source(data.get("source"), where, len(joints)),
        _free(data.get("ik"), where, joints),
        _structure_tol(data.get("ik"), where),
        _exact(data.get("exact"), where, len(joints)),
        _choice(data.get("ik"), where, "task", IK_TASKS),
        _choice(data.get("ik"), where, "tool_axis", TOOL_AXES),
        _choice(data.get("ik"), where, "method", IK_METHODS),
        _choice(data.get("ik"), where, "base_axis", TOOL_AXES),
    )


def _choice(table: object, where: str, key: str, allowed: tuple[str, ...]) -> str | None:
    """An optional [ik] key whose value is one of allowed (the table is checked by _free)."""
    if not isinstance(table, dict) or key not in table:
        return None
    value = table[key]
    if value not in allowed:
        shown = repr(value)[:40] if isinstance(value, str) else type(value).__name__
        raise SpecError(
            f"{where}: ik.{key}: {shown} is not allowed; one of "
            + ", ".join(f'"{a}"' for a in allowed)
        )
    return str(value)


def _exact(table: object, where: str, dof: int) -> tuple[tuple[float, ...], ...] | None:
    """The optional [exact] table: `frames`, dof + 1 rigid frames of 12 numbers each."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise SpecError(f"{where}: exact: must be a table with `frames`")
    _no_unknown_keys(table, ("frames",), where, "exact.")
    frames = table.get("frames")
    if not isinstance(frames, list) or len(frames) != dof + 1:
        raise SpecError(
            f"{where}: exact.frames: must be {dof + 1} frames (one more than the joints) of "
            "12 numbers each"
        )
    out = []
    for i, frame in enumerate(frames):
        field = f"exact.frames[{i}]"
        if not isinstance(frame, list) or len(frame) != 12:
            raise SpecError(f"{where}: {field}: must be a list of 12 numbers")
        # (any magnitude up to MAX_MAGNITUDE: the frames are only computed with, never
        # derived from, and a URDF's rotations hold rounding noise such as 6e-17)
        flat = tuple(_frame_entry(v, where, f"{field}[{k}]") for k, v in enumerate(frame))
        _check_rigid((*flat, 0.0, 0.0, 0.0, 1.0), where, field, "")
        out.append(flat)
    return tuple(out)


def _structure_tol(table: object, where: str) -> float | None:
    """The optional [ik] structure_tol (the table itself is checked by _free)."""
    if not isinstance(table, dict) or "structure_tol" not in table:
        return None
    value = table["structure_tol"]
    lo, hi = STRUCTURE_TOL_RANGE
    if type(value) not in (int, float):
        raise SpecError(f"{where}: ik.structure_tol: must be a number (got {type(value).__name__})")
    if not lo <= value <= hi:
        raise SpecError(
            f"{where}: ik.structure_tol: {str(value)[:40]} is not allowed; a number from "
            f"{lo:g} to {hi:g} (radians for twists, a fraction of the arm's size for lengths)"
        )
    return float(value)


def _free(table: object, where: str, joints: tuple[Joint, ...]) -> tuple[int, ...] | None:
    """The optional [ik] table: `free`, the joints an arm of more joints than its task needs
    leaves free (a pose needs 6)."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise SpecError(f"{where}: ik: must be a table ({', '.join(IK_KEYS)})")
    _no_unknown_keys(table, IK_KEYS, where, "ik.")
    if "free" not in table:
        return None
    value = table["free"]
    n = len(joints)
    task = table.get("task", "pose")
    needs = TASK_JOINTS.get(task, 6) if isinstance(task, str) else 6
    allowed = f"allowed: a list of {n - needs} distinct joint numbers 1 to {n}"
    if n <= needs:
        raise SpecError(
            f"{where}: ik.free: the arm has {n} joints; only an arm of more than {needs} "
            f"has free joints (the {task} task needs {needs})"
        )
    if (
        not isinstance(value, list)
        or len(value) != n - needs
        or not all(type(v) is int and 1 <= v <= n for v in value)
        or len(set(value)) != len(value)
    ):
        shown = repr(value) if isinstance(value, str) else str(value)  # ("7", not 7)
        raise SpecError(f"{where}: ik.free: {shown[:40]} is not allowed; {allowed}")
    return tuple(sorted(value))


def _source(table: object, where: str, dof: int) -> Source | None:
    """The optional [source] table (written by derive import-urdf)."""
    if table is None:
        return None
    if not isinstance(table, dict):
        raise SpecError(f"{where}: source: must be a table ({', '.join(SOURCE_KEYS)})")
    _no_unknown_keys(table, SOURCE_KEYS, where, "source.")

    def text(key: str, value: object) -> str:
        if not isinstance(value, str) or not SOURCE_TEXT.fullmatch(value):
            raise SpecError(
                f"{where}: source.{key}: {str(value)[:40]!r} is not allowed; allowed: 1 to 200 "
                "letters, digits, spaces and _ . , : ; ( ) + - < > ' = /"
            )
        return value

    def texts(key: str, count: int | None) -> tuple[str, ...]:
        values = table.get(key, [])
        if not isinstance(values, list) or (count is not None and len(values) != count):
            size = f"{count} " if count is not None else ""
            raise SpecError(f"{where}: source.{key}: must be an array of {size}strings")
        if len(values) > 100:
            raise SpecError(f"{where}: source.{key}: at most 100 entries")
        return tuple(text(key, v) for v in values)

    for key in ("urdf", "sha256", "base", "tip", "joints", "deviation"):
        if key not in table:
            raise SpecError(f"{where}: source.{key}: missing")
    sha = text("sha256", table["sha256"])
    if not re.fullmatch(r"[0-9a-f]{16}", sha):
        raise SpecError(f"{where}: source.sha256: {sha[:40]!r}; allowed: 16 hex digits")
    deviation = table["deviation"]
    if type(deviation) not in (int, float) or not 0 <= deviation < math.inf:
        raise SpecError(
            f"{where}: source.deviation: {str(deviation)[:40]}; allowed: a number, 0 or more"
        )
    kind = table.get("format", "URDF")
    if kind not in SOURCE_FORMATS:
        allowed = " | ".join(f'"{c}"' for c in SOURCE_FORMATS)
        raise SpecError(f"{where}: source.format: {str(kind)[:40]!r}; allowed: {allowed}")
    return Source(
        urdf=text("urdf", table["urdf"]),
        sha256=sha,
        base=text("base", table["base"]),
        tip=text("tip", table["tip"]),
        joints=texts("joints", dof),
        snaps=texts("snaps", None),
        deviation=deviation,
        format=kind,
    )


def _example(table: object, where: str, dof: int) -> tuple[tuple[float, ...] | None, Frame | None]:
    if table is None:
        return None, None
    if not isinstance(table, dict):
        raise SpecError(
            f"{where}: example: must be a table with `q`, or a pose (`matrix`, or "
            "`translation` and optional `rpy`)"
        )
    if "q" in table:
        if len(table) != 1:
            raise SpecError(f"{where}: example: give either `q` or a pose, not both")
        return _numbers(table["q"], where, "example.q", dof), None
    return None, _frame(table, where, "example", "")


def _no_unknown_keys(table: dict, allowed: tuple[str, ...], where: str, prefix: str) -> None:
    for key in table:
        if key not in allowed:
            raise SpecError(
                f"{where}: {prefix}{str(key)[:40]}: unknown key; allowed keys: {', '.join(allowed)}"
            )


def _choice_or_text(data: dict, key: str, where: str, choices: tuple[str, ...] = ()) -> str:
    allowed = " | ".join(f'"{c}"' for c in choices) if choices else "a string"
    if key not in data:
        raise SpecError(f"{where}: {key}: missing; allowed: {allowed}")
    value = data[key]
    if not isinstance(value, str):
        raise SpecError(f"{where}: {key}: must be a string; allowed: {allowed}")
    if choices and value not in choices:
        raise SpecError(f"{where}: {key}: {value[:40]!r} is not allowed; allowed: {allowed}")
    return value


def _frame_entry(value: object, where: str, field: str) -> float:
    """A number of an [exact] frame: finite, magnitude at most MAX_MAGNITUDE (any small one:
    the frames are computed with, never derived from, and a URDF's hold noise like 6e-17)."""
    if (
        isinstance(value, (int, float))
        and not isinstance(value, bool)
        and math.isfinite(value)
        and abs(value) < MIN_MAGNITUDE
    ):
        return float(value)
    return _number(value, where, field)


def _number(value: object, where: str, field: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise SpecError(f"{where}: {field}: must be a number (got {type(value).__name__})")
    try:
        number = float(value)
    except OverflowError:
        raise SpecError(
            f"{where}: {field}: number too large; allowed: 0 or finite numbers "
            f"of magnitude {MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g}"
        ) from None
    if (
        not math.isfinite(number)
        or abs(number) > MAX_MAGNITUDE
        or (number != 0.0 and abs(number) < MIN_MAGNITUDE)
    ):
        raise SpecError(
            f"{where}: {field}: {str(value)[:40]} is not allowed; allowed: 0 or "
            f"finite numbers of magnitude {MIN_MAGNITUDE:g} to {MAX_MAGNITUDE:g}"
        )
    return number


def _numbers(
    value: object,
    where: str,
    field: str,
    count: int,
    number: Callable[[object, str, str], float] = _number,
) -> tuple[float, ...]:
    """A list of count numbers, each as number takes it (_frame_entry: a frame's entries)."""
    if not isinstance(value, list) or len(value) != count:
        raise SpecError(f"{where}: {field}: must be a list of {count} numbers")
    return tuple(number(v, where, f"{field}[{k}]") for k, v in enumerate(value))


def _joint(row: dict, where: str, index: int) -> Joint:
    prefix = f"joint {index}: "
    _no_unknown_keys(row, JOINT_KEYS, where, prefix)
    kind = row.get("type")
    if kind not in ("R", "P"):
        shown = "missing" if kind is None else f"{str(kind)[:20]!r} is not allowed"
        raise SpecError(f'{where}: {prefix}type: {shown}; allowed: "R" | "P"')
    values = {}
    for key in ("alpha", "a", "d", "theta"):
        if key not in row:
            raise SpecError(f"{where}: {prefix}{key}: missing; give a number")
        values[key] = _number(row[key], where, prefix + key)
    limits = None
    if "limits" in row:
        lo, hi = _numbers(row["limits"], where, prefix + "limits", 2)
        if not lo < hi:
            raise SpecError(
                f"{where}: {prefix}limits: [{lo}, {hi}] is reversed or empty; "
                "give [lower, upper] with lower < upper"
            )
        limits = (lo, hi)
    return Joint(kind, values["alpha"], values["a"], values["d"], values["theta"], limits)


def _frame(table: object, where: str, field: str, angle_unit: str) -> Frame | None:
    if table is None:
        return None
    if not isinstance(table, dict):
        raise SpecError(
            f"{where}: {field}: must be a table with `matrix`, or `translation` and optional `rpy`"
        )
    _no_unknown_keys(table, FRAME_KEYS, where, field + ".")
    if "matrix" in table:
        if len(table) != 1:
            raise SpecError(
                f"{where}: {field}: give either `matrix` or `translation`/`rpy`, not both"
            )
        rows = table["matrix"]
        if not isinstance(rows, list) or len(rows) != 4:
            raise SpecError(f"{where}: {field}.matrix: must be 4 rows of 4 numbers")
        # (any small entry: a base turned by CAD decimals about two axes has entries 1e-11, as
        # the [exact] frames' rotations hold; the matrix is computed with)
        fields = (f"{field}.matrix[{i}]" for i in range(4))
        flat = sum((_numbers(r, where, f, 4, _frame_entry) for r, f in zip(rows, fields)), ())
        _check_rigid(flat, where, field)
        return Frame(flat, None, (0.0, 0.0, 0.0))
    if "translation" not in table:
        raise SpecError(f"{where}: {field}: give `matrix` (4x4) or `translation` [x, y, z]")
    x, y, z = _numbers(table["translation"], where, field + ".translation", 3)
    roll, pitch, yaw = _numbers(table.get("rpy", [0.0, 0.0, 0.0]), where, field + ".rpy", 3)
    return Frame(None, (x, y, z), (roll, pitch, yaw))


def _check_rigid(flat: tuple[float, ...], where: str, field: str, key: str = ".matrix") -> None:
    """Reject a matrix that is not [R t; 0 0 0 1] with R orthonormal and det R = +1."""
    if flat[12:] != (0.0, 0.0, 0.0, 1.0):
        raise SpecError(f"{where}: {field}{key}: last row must be [0, 0, 0, 1]")
    rot = [flat[0:3], flat[4:7], flat[8:11]]
    for i in range(3):
        for j in range(3):
            dot = sum(rot[k][i] * rot[k][j] for k in range(3))
            if abs(dot - (1.0 if i == j else 0.0)) > RIGID_TOL:
                raise SpecError(
                    f"{where}: {field}{key}: rotation part is not orthonormal "
                    f"(tolerance {RIGID_TOL}); a rigid transform is required"
                )
    det = (
        rot[0][0] * (rot[1][1] * rot[2][2] - rot[1][2] * rot[2][1])
        - rot[0][1] * (rot[1][0] * rot[2][2] - rot[1][2] * rot[2][0])
        + rot[0][2] * (rot[1][0] * rot[2][1] - rot[1][1] * rot[2][0])
    )
    if det < 0:
        raise SpecError(
            f"{where}: {field}{key}: rotation part is a reflection (det -1); "
            "a rigid transform is required"
        )
