"""URDF in: the kinematic chain between two links as a spec (modified DH, base and tool frames).

Reading: a hardened XML parser (defusedxml: no DTDs, no entities, nothing fetched), a size
limit, and only the elements kinematics needs (``joint``: type, parent, child, origin, axis,
limit, mimic; ``link`` names). Meshes, transmissions, gazebo and other tags are never looked at.

Converting (plain Python floats throughout, so that the output is the same on every machine):
at q = 0 every moving joint's axis is a line in the base link's frame, z along the URDF axis
direction so that joint values keep their meaning. Frame i of Craig's convention sits on axis i
where the common normal to axis i + 1 meets it, x along that normal; for parallel axes the
normal goes through the point where the previous normal meets axis i (d = 0 there). Frame 0 is
frame 1 at q = 0; the base link to frame 0 is the spec's [base], frame n to the tip link its
[tool]. Fixed joints only move these lines and frames. Number noise: axes within an angle
tolerance of parallel are taken as parallel, lines within a length tolerance of meeting as
meeting, and DH angles within the angle tolerance of a multiple of 90 deg and lengths within
the length tolerance of 0 are snapped. What that changed is measured: the spec's forward
kinematics against the URDF's on random joint vectors. A deviation above a bound is refused.
"""

from __future__ import annotations

import difflib
import hashlib
import keyword
import math
import random
import re
import stat
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree.ElementTree import TreeBuilder
from xml.sax import SAXParseException
from xml.sax.handler import ContentHandler
from xml.sax.xmlreader import AttributesImpl

import defusedxml.sax as SafeSax
from defusedxml import DefusedXmlException

from derive.spec import (
    IK_METHODS,
    IK_TASKS,
    TOOL_AXES,
    ArmSpec,
    SpecError,
    parse_spec,
    shadows_a_module,
)

MAX_BYTES = 10_000_000
MOVING = ("revolute", "continuous", "prismatic")
KNOWN_TYPES = (*MOVING, "fixed", "floating", "planar")
# the defaults: about 1e-5 rad, 1e-6 of the arm's size, and the FK deviation allowed after
# snapping (relative to the reach for positions; rotation entries as they are)
ANGLE_TOL = 1e-5
LENGTH_TOL = 1e-6
MAX_DEVIATION = 1e-4
SAMPLES = 200
# a link offset beyond this many reaches comes from nearly parallel axes (never a real arm)
OFFSET_LIMIT = 100.0
# two axes within FAR_PARALLEL radians of parallel whose common normal lies more than FAR_NORMAL
# reaches out along them are taken as parallel (_far_normal): a calibration turns parallel
# axes by 1e-5 to 3e-4 rad, and its table's common normals lie tens to hundreds of metres out;
# where that moves the table beyond --max-deviation, only those beyond OFFSET_LIMIT are (the
# others keep their far normals, as before; import_chain)
FAR_PARALLEL = 1e-2
FAR_NORMAL = 10.0
# the largest magnitude of a number in a URDF (metres, radians, axis components): no arm is
# 1000 km long, and above it squares and degrees stay far from overflow
MAX_NUMBER = 1e6
# a number as a URDF writes one: decimal, ASCII, an optional exponent
DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
# what the options may be: snapping beyond 0.1 rad or 0.1 of the arm's size changes the arm;
# a deviation is a rotation entry or a fraction of the reach, so above 1 it bounds nothing
TOLERANCE_RANGE = (0.0, 0.1)
DEVIATION_RANGE = (0.0, 1.0)
# a base or tool rotation further than this from orthonormal is refused, not repaired
ORTHONORMAL_TOL = 1e-6
# joints between base and tip, fixed ones included (an arm has tens; FK is checked in Python)
MAX_CHAIN = 1000
# error lines: names cut to this many characters, listings to this many names
SHOWN = 40
LISTED = 8

Matrix = list[list[float]]
Vector = tuple[float, float, float]


class UrdfError(SpecError):
    """The URDF cannot be converted; the message (one line) names the file, the element and
    the problem."""


@dataclass(frozen=True)
class UrdfJoint:
    """A joint as the URDF states it (origin as a 4x4 matrix, axis normalised)."""

    name: str
    kind: str
    parent: str
    child: str
    origin: Matrix
    axis: Vector
    limits: tuple[float, float] | None
    mimic: bool
    # a revolute or prismatic joint whose <limit> gives neither lower nor upper (read as
    # unlimited, and said in a note: URDF's defaults, 0 and 0, would hold it at 0)
    unbounded: bool = False
    # what refuses a chain through it (one elsewhere in the file is not refused: a NICO's left
    # arm, read for its head): its <limit>'s lower above its upper, or two of its <origin>,
    # <axis> or <limit> elements (which one counts would be the reader's choice)
    refused: str = ""


@dataclass(frozen=True)
class Robot:
    """The kinematic part of a URDF."""

    name: str
    links: frozenset[str]
    joints: tuple[UrdfJoint, ...]
    digest: str
    # attributes (drake:...) and <elements> with a prefix nobody declared
    ignored: tuple[str, ...] = ()


@dataclass
class Conversion:
    """A chain as DH rows, with what the conversion did.

    Attributes:
        rows: (type, alpha, a, d, theta, limits) per moving joint; radians and URDF lengths.
        joint_names: the URDF joint name of each row.
        base, tool: 4x4 matrices.
        snaps: one line per snap applied.
        notes: what was ignored (one line each; not in the spec, said on stderr).
        deviation: the largest FK difference of the spec from the URDF over the samples.
        frames: the URDF's own chain as fixed frames (derive/nominal.py): F_0 .. F_n, the
            top three rows of each, row-major; the spec keeps them as [exact] where
            snapping moved its table.
        far: the snaps of axes taken as parallel for their far common normal (_far_normal).
        reach: the arm's size.
    """

    rows: list[tuple[str, float, float, float, float, tuple[float, float] | None]]
    joint_names: list[str]
    base: Matrix
    tool: Matrix
    snaps: list[str] = field(default_factory=list)
    deviation: float = 0.0
    reach: float = 1.0
    rounded: bool = True
    notes: list[str] = field(default_factory=list)
    frames: list[list[float]] = field(default_factory=list)
    far: list[str] = field(default_factory=list)


# --- reading ---------------------------------------------------------------------------------


def read_urdf(path: Path) -> Robot:
    """The links and joints of a URDF file."""
    where = str(path)
    try:
        status = path.stat()
        if not stat.S_ISREG(status.st_mode):  # (a pipe would block the read)
            raise UrdfError(f"{where}: not a regular file")
        size = status.st_size
        if size > MAX_BYTES:
            raise UrdfError(f"{where}: {size} bytes; a URDF may have at most {MAX_BYTES}")
        data = path.read_bytes()
    except OSError as exc:
        raise UrdfError(f"{where}: cannot read: {exc.strerror}") from None
    reader = _TreeReader()
    try:
        SafeSax.parseString(data, reader, forbid_dtd=True)
    except DefusedXmlException as exc:
        raise UrdfError(f"{where}: refused: {type(exc).__name__} (DTDs and entities)") from None
    except SAXParseException as exc:
        raise UrdfError(
            f"{where}: not well-formed XML: {exc.getMessage()}: line {exc.getLineNumber()}, "
            f"column {exc.getColumnNumber()}"
        ) from None
    if reader.xacro:
        raise UrdfError(
            f"{where}: a xacro file ({reader.xacro}); expand it first: "
            f"`xacro {path.name} > robot.urdf` (ROS's xacro, or `pip install xacro`)"
        )
    root = reader.builder.close()
    if root.tag != "robot":
        raise UrdfError(f"{where}: the root element is <{_cut(root.tag)}>, not <robot>")
    links: set[str] = set()
    for element in root.findall("link"):
        name = _name(element, where, "link")
        if name in links:
            raise UrdfError(f"{where}: link {_shown(name)}: defined twice")
        links.add(name)
    joints: list[UrdfJoint] = []
    names: set[str] = set()
    above: dict[str, UrdfJoint] = {}
    for element in root.findall("joint"):
        joint = _joint(element, where)
        if joint.name in names:
            raise UrdfError(f"{where}: joint {_shown(joint.name)}: defined twice")
        names.add(joint.name)
        for end in (joint.parent, joint.child):
            if end not in links:
                raise UrdfError(f"{where}: joint {_shown(joint.name)}: unknown link {_shown(end)}")
        if joint.child in above:
            raise UrdfError(
                f"{where}: joint {_shown(joint.name)}: link {_shown(joint.child)} is already "
                f"the child of joint {_shown(above[joint.child].name)}; a URDF is a tree"
            )
        above[joint.child] = joint
        joints.append(joint)
    rooted: set[str] = set()  # links whose way up ends at a root: each walked once
    for start in sorted(above):
        link, seen = start, set()
        while link in above and link not in rooted:
            if link in seen:
                raise UrdfError(
                    f"{where}: joint {_shown(above[link].name)}: the links form a cycle; "
                    "a URDF is a tree"
                )
            seen.add(link)
            link = above[link].parent
        rooted |= seen
    return Robot(
        name=root.get("name", ""),
        links=frozenset(links),
        joints=tuple(joints),
        digest=hashlib.sha256(data).hexdigest()[:16],
        ignored=tuple(sorted(reader.undeclared)),
    )


# the namespace xacro's elements live in (ROS wiki address, with or without www.)
XACRO_NAMESPACE = re.compile(r"^https?://(www\.)?ros\.org/wiki/xacro/?$")


class _TreeReader(ContentHandler):
    """An element tree from SAX events, read without namespace processing: a prefix stays
    part of the name, so a prefix nobody declared (``drake:acceleration``, as some URDFs
    write) is no parse error. Such attributes are dropped and their names kept in
    ``undeclared``; kinematics reads only unprefixed ones. ``xacro`` says what xacro would
    still change (a xacro element, ``${...}`` or ``$(...)`` in a value), or is empty: an
    expanded URDF that keeps ``xmlns:xacro`` on its robot element is a URDF."""

    def __init__(self) -> None:
        super().__init__()
        self.builder = TreeBuilder()
        self.scopes: list[dict[str, str]] = [{"xml": "http://www.w3.org/XML/1998/namespace"}]
        self.undeclared: set[str] = set()
        self.xacro = ""

    def startElement(self, name: str, attrs: AttributesImpl) -> None:
        declared = self.scopes[-1]
        added = {k[6:]: attrs.getValue(k) for k in attrs.getNames() if k.startswith("xmlns:")}
        if added:
            declared = {**declared, **added}
        self.scopes.append(declared)
        prefix = name.partition(":")[0] if ":" in name else ""
        if (
            prefix
            and not self.xacro
            and (prefix == "xacro" or XACRO_NAMESPACE.match(declared.get(prefix, "")))
        ):
            self.xacro = f"element <{_cut(name)}>"
        elif prefix and prefix not in declared:
            self.undeclared.add(f"<{name}>")  # (not a URDF element: never read)
        kept = {}
        for key in attrs.getNames():
            value = attrs.getValue(key)
            if not self.xacro and ("${" in value or "$(" in value):
                self.xacro = f'{_cut(key)}="{_cut(value)}"'
            prefix = key.partition(":")[0] if ":" in key else ""
            if prefix and prefix != "xmlns" and prefix not in declared:
                self.undeclared.add(key)
            else:
                kept[key] = value
        self.builder.start(name, kept)

    def endElement(self, name: str) -> None:
        self.scopes.pop()
        self.builder.end(name)


def _cut(text: str) -> str:
    """text cut to SHOWN characters for an error line (names can be megabytes long)."""
    return text if len(text) <= SHOWN else text[:SHOWN] + "..."


def _shown(text: str) -> str:
    """text quoted and cut for an error line."""
    return repr(_cut(text))


def ends_hint(robot: Robot, parts: str = "links", world: str = "") -> str:
    """Where the caller named no base or tip: the file's root parts (no joint's child; with
    world, MJCF's world body, the bodies on it) and leaf parts (no joint's parent: URDF links,
    MJCF bodies and sites), the usual base and tip, as a hint."""
    children = {j.child for j in robot.joints}
    parents = {j.parent for j in robot.joints}
    if world:
        roots = sorted({j.child for j in robot.joints if j.parent == world})
    else:
        roots = [n for n in robot.links if n not in children]
    leaves = [n for n in robot.links if n not in parents and n in children]
    first = f"the {parts} on its world" if world else f"its root {parts}"
    return f" ({first}: {_listing(roots)}; its leaf {parts}: {_listing(leaves)})"


def did_you_mean(name: str, names: Iterable[str]) -> str:
    """The hint "did you mean 'a', 'b'? " with the names nearest name (difflib's), or "":
    the nearest names first (a misspelled --tip "urdf_hed" got the first links alphabetically,
    which did not include "urdf_head", a new user's attack); not for names or files of hostile
    sizes (each comparison is quadratic)."""
    known = sorted(names)
    if len(name) > 200 or len(known) > 10_000:
        return ""
    near = difflib.get_close_matches(name, known, n=3, cutoff=0.6)
    return f"did you mean {', '.join(map(_shown, near))}? " if near else ""


def _listing(names: list[str]) -> str:
    """The first LISTED of names, sorted and cut, and how many more there are."""
    ordered = sorted(names)
    shown = ", ".join(_shown(n) for n in ordered[:LISTED])
    more = len(ordered) - LISTED
    return shown + (f", ... and {more} more" if more > 0 else "")


def _name(element, where: str, what: str) -> str:
    name = element.get("name")
    if not name:
        raise UrdfError(f"{where}: a <{what}> without a name")
    return str(name)


def _numbers(text: str | None, count: int, where: str, default: tuple[float, ...]) -> list[float]:
    """count numbers written in text (default if it is None), each finite and of magnitude
    at most MAX_NUMBER; refused as written otherwise."""
    if text is None:
        return list(default)
    parts = text.split()
    # (decimal numbers in ASCII, as URDF's parsers read them: float() would also take
    # "0.089_159" and other scripts' digits)
    if all(DECIMAL.fullmatch(p) for p in parts):
        values = [float(p) for p in parts]
    else:
        values = []
    if len(values) != count or not all(abs(v) <= MAX_NUMBER for v in values):
        numbers = "a finite number" if count == 1 else f"{count} finite numbers"
        raise UrdfError(
            f"{where}: {_shown(text)}; allowed: {numbers} of magnitude at most {MAX_NUMBER:g}"
        )
    return values


def _joint(element, where: str) -> UrdfJoint:
    name = _name(element, where, "joint")
    at = f"{where}: joint {_shown(name)}"
    kind = element.get("type", "")
    if kind not in KNOWN_TYPES:
        raise UrdfError(f"{at}: type {_shown(kind)}; allowed: {', '.join(KNOWN_TYPES)}")
    refused = ""
    for tag in ("parent", "child", "origin", "axis", "limit"):  # (the kinematics' elements:
        # two would leave it to the reader which one counts; two ends, which way the tree goes)
        count = len(element.findall(tag))
        if count > 1 and tag in ("parent", "child"):
            raise UrdfError(f"{at}: {count} <{tag}> elements; allowed: one")
        if count > 1 and not refused:
            refused = f"{at}: {count} <{tag}> elements; allowed: one"
    ends = []
    for tag in ("parent", "child"):
        node = element.find(tag)
        if node is None or not node.get("link"):
            raise UrdfError(f"{at}: <{tag} link=...> missing")
        ends.append(str(node.get("link")))
    origin = element.find("origin")
    xyz = _numbers(None if origin is None else origin.get("xyz"), 3, f"{at}: origin xyz", (0,) * 3)
    rpy = _numbers(None if origin is None else origin.get("rpy"), 3, f"{at}: origin rpy", (0,) * 3)
    axis_node = element.find("axis")
    axis = _numbers(
        None if axis_node is None else axis_node.get("xyz"), 3, f"{at}: axis xyz", (1.0, 0.0, 0.0)
    )
    norm = math.sqrt(sum(x * x for x in axis))
    if kind in MOVING and norm < 1e-9:
        raise UrdfError(f"{at}: axis xyz is zero")
    limits = None
    limit = element.find("limit")
    if kind in ("revolute", "prismatic") and limit is not None:
        lo = _numbers(limit.get("lower"), 1, f"{at}: limit lower", (0.0,))[0]
        hi = _numbers(limit.get("upper"), 1, f"{at}: limit upper", (0.0,))[0]
        if lo > hi and not refused:  # (refused where the chain uses the joint: import_chain)
            refused = f"{at}: limit lower {lo} is above upper {hi}"
        limits = (lo, hi) if lo < hi else None  # lower = upper = 0: URDF's "no limits given"
    return UrdfJoint(
        name=name,
        kind=kind,
        parent=ends[0],
        child=ends[1],
        origin=pose(xyz, rpy),
        axis=(axis[0] / norm, axis[1] / norm, axis[2] / norm) if norm else (1.0, 0.0, 0.0),
        limits=limits,
        mimic=element.find("mimic") is not None,
        unbounded=limit is not None
        and kind in ("revolute", "prismatic")
        and limit.get("lower") is None
        and limit.get("upper") is None,
        refused=refused,
    )


def chain_between(
    robot: Robot,
    base: str,
    tip: str,
    where: str,
    allowed: str = "revolute, continuous, prismatic, fixed",
) -> list[UrdfJoint]:
    """The joints from base down to tip, in order; allowed: the joint kinds a refusal names
    (an MJCF file's own words, derive/mjcf.py)."""
    for link, what in ((base, "--base"), (tip, "--tip")):
        if link not in robot.links:
            known = _listing(list(robot.links))
            hint = did_you_mean(link, robot.links)
            raise UrdfError(f"{where}: {what} {_shown(link)}: no such link; {hint}links: {known}")
    above = {j.child: j for j in robot.joints}
    path: list[UrdfJoint] = []
    link = tip
    seen = {tip}
    while link != base:
        joint = above.get(link)
        if joint is None:
            raise UrdfError(f"{where}: --tip {_shown(tip)} is not below --base {_shown(base)}")
        if joint.parent in seen:
            raise UrdfError(f"{where}: joint {_shown(joint.name)}: the links form a cycle")
        seen.add(joint.parent)
        path.append(joint)
        link = joint.parent
    path.reverse()
    if len(path) > MAX_CHAIN:
        raise UrdfError(
            f"{where}: {len(path)} joints between {_shown(base)} and {_shown(tip)}; "
            f"allowed at most {MAX_CHAIN}"
        )
    for joint in path:
        if joint.kind in ("floating", "planar", "ball", "free"):
            raise UrdfError(
                f"{where}: joint {_shown(joint.name)}: a {joint.kind} joint between base and tip; "
                f"allowed: {allowed}"
            )
        if joint.mimic and joint.kind in MOVING:
            raise UrdfError(
                f"{where}: joint {_shown(joint.name)}: a mimic joint between base and tip is not "
                "supported (its value follows another joint's)"
            )
    if not any(j.kind in MOVING for j in path):
        raise UrdfError(f"{where}: no moving joint between {_shown(base)} and {_shown(tip)}")
    return path


# --- plain-Python geometry -------------------------------------------------------------------


def pose(xyz: list[float], rpy: list[float]) -> Matrix:
    """The URDF origin: translation xyz, rotation Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cr, sr, cp, sp = math.cos(r), math.sin(r), math.cos(p), math.sin(p)
    cy, sy = math.cos(y), math.sin(y)
    return [
        [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr, xyz[0]],
        [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr, xyz[1]],
        [-sp, cp * sr, cp * cr, xyz[2]],
        [0.0, 0.0, 0.0, 1.0],
    ]


def matmul(a: Matrix, b: Matrix) -> Matrix:
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inverse(m: Matrix) -> Matrix:
    """The inverse of a rigid transform."""
    rt = [[m[j][i] for j in range(3)] for i in range(3)]
    p = [-sum(rt[i][k] * m[k][3] for k in range(3)) for i in range(3)]
    return [[*rt[i], p[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def motion(joint: UrdfJoint, q: float) -> Matrix:
    """The joint's motion by q: a rotation about its axis, or a translation along it."""
    x, y, z = joint.axis
    if joint.kind == "prismatic":
        return [[1.0, 0, 0, x * q], [0, 1.0, 0, y * q], [0, 0, 1.0, z * q], [0, 0, 0, 1.0]]
    if joint.kind == "fixed":
        return [[1.0, 0, 0, 0], [0, 1.0, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1.0]]
    c, s = math.cos(q), math.sin(q)
    t = 1.0 - c
    return [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y, 0.0],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x, 0.0],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]


def urdf_fk(path: list[UrdfJoint], q: list[float]) -> Matrix:
    """The tip link's pose in the base link for the moving joints' values q."""
    out = [[float(i == j) for j in range(4)] for i in range(4)]
    values = iter(q)
    for joint in path:
        out = matmul(out, joint.origin)
        if joint.kind in MOVING:
            out = matmul(out, motion(joint, next(values)))
    return out


def dh_modified(alpha: float, a: float, theta: float, d: float) -> Matrix:
    """Craig's A_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)."""
    ca, sa, ct, st = math.cos(alpha), math.sin(alpha), math.cos(theta), math.sin(theta)
    return [
        [ct, -st, 0.0, a],
        [st * ca, ct * ca, -sa, -sa * d],
        [st * sa, ct * sa, ca, ca * d],
        [0.0, 0.0, 0.0, 1.0],
    ]


def _sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _add(a: Vector, b: Vector, k: float = 1.0) -> Vector:
    return (a[0] + k * b[0], a[1] + k * b[1], a[2] + k * b[2])


def _dot(a: Vector, b: Vector) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _unit(a: Vector) -> Vector:
    n = math.sqrt(_dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


def _angle(u: Vector, v: Vector, about: Vector) -> float:
    """The angle from u to v about the unit vector `about` (u, v perpendicular to it)."""
    return math.atan2(_dot(_cross(u, v), about), _dot(u, v))


# --- converting ------------------------------------------------------------------------------


# rounding noise: what --exact still takes as parallel, meeting, 0 or 90 deg (and never reports)
NOISE = 1e-12
# a spec whose FK differs from its file's by more than this (its numbers rounded to 15 digits,
# entries below 1e-9 written as 0: a tool written with pi as 3.14159265359) keeps the file's
# frames as [exact], as a snapped one does
ROUNDED = 1e-13


def convert(
    path: list[UrdfJoint],
    where: str,
    angle_tol: float = ANGLE_TOL,
    length_tol: float = LENGTH_TOL,
    exact: bool = False,
    task: str | None = None,
    far: float = FAR_NORMAL,
) -> Conversion:
    """The chain as modified-DH rows, base and tool, snapping within the tolerances (exact:
    rounding noise only); the deviation is measured by :func:`measure`. The base's and the
    tool's rotations are snapped only where the task's structure reads them (_frames_snapped):
    a base written with euler 1.57079 would otherwise make the arm nominal for nothing. Axes
    within FAR_PARALLEL of parallel whose common normal lies more than `far` reaches out are
    taken as parallel (_far_normal; not where exact)."""
    if exact:
        angle_tol = length_tol = NOISE
    moving = [j for j in path if j.kind in MOVING]
    reach = sum(math.sqrt(sum(j.origin[i][3] ** 2 for i in range(3))) for j in path) or 1.0
    ltol = length_tol * reach
    # the axis lines at q = 0 in the base link: a point and the direction
    frame = [[float(i == j) for j in range(4)] for i in range(4)]
    lines: list[tuple[Vector, Vector]] = []
    for joint in path:
        frame = matmul(frame, joint.origin)
        if joint.kind in MOVING:
            point = (frame[0][3], frame[1][3], frame[2][3])
            turned = [sum(frame[i][k] * joint.axis[k] for k in range(3)) for i in range(3)]
            lines.append((point, _unit((turned[0], turned[1], turned[2]))))
    tip_pose = frame
    snaps: list[str] = []
    n = len(moving)
    # origins O_i and x axes of frames 1..n at q = 0
    origins: list[Vector] = []
    xs: list[Vector] = []
    parallel: set[int] = set()  # (the rows whose axis _far_normal takes as the previous one's)
    far_snaps: list[str] = []
    for i in range(n):
        p, z = lines[i]
        if i == n - 1:  # the last frame: on its axis where the previous normal meets it
            if n == 1:
                origins.append(p)
                xs.append(_perpendicular(z))
            else:
                origins.append(_foot(origins[-1], xs[-1], lines[i]))
                xs.append(xs[-1])
            break
        q_point, z_next = lines[i + 1]
        cross = _cross(z, z_next)
        sine = math.sqrt(_dot(cross, cross))
        start = p if i == 0 else _foot(origins[-1], xs[-1], lines[i])
        taken = sine <= math.sin(angle_tol)
        feet = None if taken else _normal_feet(lines[i], lines[i + 1], sine)
        out = "" if exact or feet is None else _far_normal(start, z, feet[0], sine, far * reach)
        if out:
            parallel.add(i + 1)  # (row i + 2's twist: 0 or pi below)
        if taken or out:
            if sine > NOISE:
                snaps.append(
                    f"axes {i + 1} and {i + 2}: {math.asin(min(sine, 1.0)):.3g} rad from "
                    f"parallel: taken as parallel{out}"
                )
                far_snaps += [snaps[-1]] if out else []
            # parallel: the normal through `start` (d = 0 for this joint)
            offset = _sub(q_point, start)
            normal = _add(offset, z, -_dot(offset, z))
            length = math.sqrt(_dot(normal, normal))
            origins.append(start)
            xs.append(_across(normal, z) if length > ltol else _perpendicular(z))
            continue
        # skew or intersecting: the feet of the common normal
        assert feet is not None
        foot_i, foot_next = feet
        gap = _sub(foot_next, foot_i)
        distance = math.sqrt(_dot(gap, gap))
        origins.append(foot_i)
        if distance <= ltol:
            if distance > NOISE * reach:
                snaps.append(f"axes {i + 1} and {i + 2}: {distance:.3g} apart: taken as meeting")
            xs.append(_unit(cross))
        else:  # along z_i x z_i+1 (the gap's own direction is noise when it is short)
            xs.append(_unit(cross if _dot(gap, cross) > 0 else _cross(z_next, z)))
    # DH rows from consecutive frames (frame 0 = frame 1 at q = 0)
    rows = []
    for i, joint in enumerate(moving):
        z = lines[i][1]
        if i == 0:
            alpha = a = d = theta = 0.0
        else:
            z_prev, x_prev, o_prev = lines[i - 1][1], xs[i - 1], origins[i - 1]
            alpha = _angle(z_prev, z, x_prev)
            foot = _add(o_prev, x_prev, _dot(_sub(origins[i], o_prev), x_prev))
            a = _dot(_sub(foot, o_prev), x_prev)
            d = _dot(_sub(origins[i], foot), z)
            theta = _angle(x_prev, xs[i], z)
        kind = "P" if joint.kind == "prismatic" else "R"
        row = f"row {i + 1} ({joint.name})"
        if i in parallel:  # (reported with the axes above)
            alpha = math.pi * round(alpha / math.pi)
        alpha = _snap_angle(alpha, angle_tol, snaps, f"{row} alpha")
        theta = _snap_angle(theta, angle_tol, snaps, f"{row} theta")
        a = _snap_length(a, ltol, snaps, f"{row} a", NOISE * reach)
        d = _snap_length(d, ltol, snaps, f"{row} d", NOISE * reach)
        for value, what in ((a, "a"), (d, "d")):
            if abs(value) > OFFSET_LIMIT * reach:
                raise UrdfError(
                    f"{where}: joint {_shown(joint.name)}: DH {what} = {value:.4g} "
                    f"({abs(value) / reach:.3g} times the arm's size): its axis is nearly "
                    "parallel to the previous one; take them as parallel with --angle-tol "
                    "above the angle between them, and check the deviation it reports"
                )
        limits = joint.limits if joint.kind != "continuous" else None
        rows.append((kind, alpha, a, d, theta, limits))
    first = orthonormalise(_frame(origins[0], xs[0], lines[0][1]), where, "base", snaps)
    # frame n at q = 0 as the (snapped) rows build it: the tool closes the chain from there
    built = first
    for _kind, alpha, a, d, theta, _limits in rows:
        built = matmul(built, dh_modified(alpha, a, theta, d))
    tool = orthonormalise(matmul(inverse(built), tip_pose), where, "tool", snaps)
    snap_base, snap_tool = _frames_snapped(task, [j.kind for j in moving], bool(snaps))
    if snap_base:
        first = _snap_frame(first, angle_tol, ltol, snaps, "base")
    if snap_tool:
        tool = _snap_frame(tool, angle_tol, ltol, snaps, "tool")
    for matrix, what in ((first, "base"), (tool, "tool")):
        away = math.sqrt(sum(matrix[i][3] ** 2 for i in range(3)))
        if away > OFFSET_LIMIT * reach:
            raise UrdfError(
                f"{where}: the {what} frame lies {away:.4g} away ({away / reach:.3g} times "
                "the arm's size): two consecutive axes nearly parallel meet far away; take them "
                "as parallel with --angle-tol above the angle between them, and check the "
                "deviation it reports"
            )
    return Conversion(
        rows=rows,
        joint_names=[j.name for j in moving],
        base=first,
        tool=tool,
        snaps=snaps,
        reach=reach,
        rounded=not exact,
        frames=exact_frames(path),
        far=far_snaps,
    )


def _normal_feet(
    line: tuple[Vector, Vector], after: tuple[Vector, Vector], sine: float
) -> tuple[Vector, Vector]:
    """The feet of two axes' common normal on each (sine: of the angle between them, not 0)."""
    (p, z), (q, z_next) = line, after
    w = _sub(p, q)
    b = _dot(z, z_next)
    denom = sine * sine  # 1 - b^2, without its cancellation
    s = (b * _dot(z_next, w) - _dot(z, w)) / denom
    t = (_dot(z_next, w) - b * _dot(z, w)) / denom
    return _add(p, z, s), _add(q, z_next, t)


def _far_normal(start: Vector, z: Vector, foot: Vector, sine: float, beyond: float) -> str:
    """Where two axes within FAR_PARALLEL of parallel meet their common normal (at foot on the
    first, along z) more than `beyond` from start, why they are taken as parallel, else "". A
    calibrated UR5 written with 7 decimals (tests/test_nominal.py, noisy_urdf) had axes 2 and
    3 2.0e-5 rad apart and their normal 312 m out, 242 times its size: refused (OFFSET_LIMIT)
    at 2 of 100 seeds, at 53 of 100 with 5 decimals (a new user's find, helper 67); with only
    those taken as parallel, its axes 3 and 4, 1.1e-5 apart, kept theirs 98 m out, the nominal
    table (which snaps them about that far point) was 6.5e-4 from the arm, and a pose near its
    shoulder singularity got no row. Taken as parallel, the table is the nominal arm the closed form
    solves (its deviation from the file measured and bounded as any snap's: 3.7e-5 there)
    and the file's frames, kept exact, are fk's and every answer's."""
    out = abs(_dot(_sub(foot, start), z))
    if not sine <= FAR_PARALLEL or out <= beyond:
        return ""
    return f" (their common normal {out:.3g} away)"


def _frames_snapped(task: str | None, kinds: list[str], rows_snapped: bool) -> tuple[bool, bool]:
    """Whether conversion snaps the base's and the tool's frames: where the rows are snapped
    (the arm is nominal anyway, and a snapped tool can undo some of the rows' difference: an
    xArm6's deviation 1.4e-5 with it, 2.2e-5 without), or where the frame shapes the structure
    of the task (given, or the arm's joints' choice: six or more joints the pose, five a tool
    axis's direction; derive/tasks.py default_task). A pose's closed forms solve B^-1 T E^-1
    for any rigid B and E; a tool axis's task reads the tool's frame (the virtual joint's
    line) and not the base's; the others (a planar arm's, an axis angle to a base axis, a
    position) read both, or are left as they were."""
    chosen = task or ("pose" if len(kinds) >= 6 else "direction" if len(kinds) == 5 else None)
    return (
        rows_snapped or chosen not in ("pose", "direction"),
        rows_snapped or chosen != "pose",
    )


def exact_frames(path: list[UrdfJoint]) -> list[list[float]]:
    """The chain as fixed frames, T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n with J_i a
    rotation about z or a translation along it (derive/nominal.py): each moving joint's
    frame turned so that its axis is z (R_i e_z = axis), F_i = R_i^T (origins up to the next
    moving joint) R_(i+1); the top three rows of each, row-major."""
    frames: list[list[float]] = []
    acc = [[float(i == j) for j in range(4)] for i in range(4)]
    for joint in path:
        acc = matmul(acc, joint.origin)
        if joint.kind in MOVING:
            turn = _onto_z(joint.axis)
            acc = matmul(acc, turn)
            frames.append([acc[r][c] for r in range(3) for c in range(4)])
            acc = inverse(turn)
    frames.append([acc[r][c] for r in range(3) for c in range(4)])
    return frames


def _onto_z(axis: Vector) -> Matrix:
    """A rotation R (4x4) with R e_z = axis (a unit vector)."""
    x, y, z = axis
    if z < 0.0 and x * x + y * y < 1e-30:  # (the half turn about x: within 1e-15 of -e_z)
        return [[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -1.0, 0.0], [0, 0, 0, 1.0]]
    # Rodrigues' rotation about e_z x axis by the angle between them, written without it;
    # 1 / (1 + z) = (1 - z) / (x^2 + y^2) for a unit axis, the second where z < 0: near -e_z
    # 1 + z loses its digits (an axis "0 -0.0015509 -1", a DClaw finger's, made frames 9e-11
    # from orthonormal and fk 8e-11 from the URDF's, a new user's attack)
    k = 1.0 / (1.0 + z) if z >= 0.0 else (1.0 - z) / (x * x + y * y)
    return [
        [1.0 - k * x * x, -k * x * y, x, 0.0],
        [-k * x * y, 1.0 - k * y * y, y, 0.0],
        [-x, -y, z, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]


def _snap_frame(m: Matrix, angle_tol: float, ltol: float, snaps: list[str], what: str) -> Matrix:
    """m with a rotation within angle_tol of a right-angle one (entries 0, +-1) made exact,
    and translations within ltol of 0 made 0."""
    out = [row[:] for row in m]
    rotation = [[round(m[i][j]) for j in range(3)] for i in range(3)]
    near = all(abs(m[i][j] - rotation[i][j]) <= angle_tol for i in range(3) for j in range(3))
    if near and sorted(abs(v) for row in rotation for v in row) == [0] * 6 + [1] * 3:
        for i in range(3):
            out[i][:3] = [float(v) for v in rotation[i]]
        if any(abs(out[i][j] - m[i][j]) > NOISE for i in range(3) for j in range(3)):
            snaps.append(f"{what}: rotation taken as a right-angle rotation")
    for i in range(3):
        if out[i][3] != 0.0 and abs(out[i][3]) <= ltol:
            if abs(out[i][3]) > NOISE:
                snaps.append(f"{what}: translation {'xyz'[i]} {out[i][3]!r} to 0")
            out[i][3] = 0.0
    return out


def orthonormalise(m: Matrix, where: str, what: str, snaps: list[str]) -> Matrix:
    """m with its rotation made orthonormal by Gram-Schmidt: z kept (a joint's axis for the
    base), x made perpendicular to it, y = z x x. A change above rounding noise is recorded
    in snaps with how far the entries moved; one above ORTHONORMAL_TOL is refused."""
    z = _unit((m[0][2], m[1][2], m[2][2]))
    x = _across((m[0][0], m[1][0], m[2][0]), z)
    out = _frame((m[0][3], m[1][3], m[2][3]), x, z)
    moved = max(abs(out[i][j] - m[i][j]) for i in range(3) for j in range(3))
    if not moved <= ORTHONORMAL_TOL:
        raise UrdfError(
            f"{where}: the {what} frame's rotation is {moved:.3g} from orthonormal; allowed "
            f"{ORTHONORMAL_TOL:g} (a converter error)"
        )
    if moved <= NOISE:
        return m
    snaps.append(f"{what}: rotation re-orthonormalised (entries moved up to {moved:.2g})")
    return out


def _across(v: Vector, z: Vector) -> Vector:
    """The unit vector along the part of v perpendicular to the unit vector z (projected
    twice: one projection leaves rounding of v's size along z)."""
    once = _add(v, z, -_dot(v, z))
    return _unit(_add(once, z, -_dot(once, z)))


def _perpendicular(z: Vector) -> Vector:
    """A unit vector perpendicular to z (the x axis where nothing else chooses one)."""
    helper = (1.0, 0.0, 0.0) if abs(z[0]) < 0.9 else (0.0, 1.0, 0.0)
    return _unit(_cross(_cross(z, helper), z))


def _foot(origin: Vector, x: Vector, line: tuple[Vector, Vector]) -> Vector:
    """Where the line through origin along x comes nearest the axis line (its point there)."""
    p, z = line
    return _add(p, z, _dot(_sub(origin, p), z))


def _frame(origin: Vector, x: Vector, z: Vector) -> Matrix:
    y = _cross(z, x)
    return [[x[i], y[i], z[i], origin[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def _snap_angle(value: float, tol: float, snaps: list[str], what: str) -> float:
    """value made the nearest multiple of 90 deg if within tol of it (-180 deg is 180 deg)."""
    quarter = round(value / (math.pi / 2))
    near = quarter * (math.pi / 2)
    off = abs(value - near)
    if value == near or off > tol:
        return value
    target = math.pi if abs(quarter) == 2 else near
    if off > NOISE:
        snaps.append(f"{what}: {math.degrees(value)!r} deg to {math.degrees(target):g} deg")
    return target


def _snap_length(value: float, tol: float, snaps: list[str], what: str, noise: float) -> float:
    if value != 0.0 and abs(value) <= tol:
        if abs(value) > noise:
            snaps.append(f"{what}: {value!r} to 0")
        return 0.0
    return value


def spec_fk(spec: ArmSpec, q: list[float]) -> Matrix:
    """The pose of a spec this module wrote (degrees, base and tool matrices)."""
    out = _matrix(spec.base.matrix if spec.base and spec.base.matrix else None)
    for joint, value in zip(spec.joints, q):
        alpha, theta, d = math.radians(joint.alpha), math.radians(joint.theta), joint.d
        if joint.kind == "R":
            theta += value
        else:
            d += value
        if spec.convention == "modified":
            out = matmul(out, dh_modified(alpha, joint.a, theta, d))
        else:  # Rz(theta) Tz(d) Tx(a) Rx(alpha) = Tz(d) Rz(theta) then the twist
            out = matmul(out, dh_modified(0.0, 0.0, theta, d))
            out = matmul(out, dh_modified(alpha, joint.a, 0.0, 0.0))
    return matmul(out, _matrix(spec.tool.matrix if spec.tool and spec.tool.matrix else None))


def _matrix(flat: tuple[float, ...] | None) -> Matrix:
    if flat is None:
        return [[float(i == j) for j in range(4)] for i in range(4)]
    return [list(flat[4 * i : 4 * i + 4]) for i in range(4)]


def measure(spec: ArmSpec, path: list[UrdfJoint], reach: float, samples: int = SAMPLES) -> float:
    """The largest difference between the spec's FK and the URDF's over random joint values
    (within limits; +-pi, or +-reach for prismatic joints without them): rotation entries, and
    positions relative to the reach."""
    rng = random.Random(0)
    worst = 0.0
    moving = [j for j in path if j.kind in MOVING]
    for _ in range(samples):
        q = []
        for joint in moving:
            if joint.limits is not None and joint.kind != "continuous":
                lo, hi = joint.limits
            else:
                lo, hi = (-reach, reach) if joint.kind == "prismatic" else (-math.pi, math.pi)
            q.append(rng.uniform(lo, hi))
        expected = urdf_fk(path, q)
        got = spec_fk(spec, q)
        for i in range(3):
            for j in range(4):
                scale = reach if j == 3 else 1.0
                worst = max(worst, abs(got[i][j] - expected[i][j]) / scale)
    return worst


def spec_name(text: str) -> str:
    """A spec name ([a-z][a-z0-9_]*) from a robot's name; "_arm" after a Python keyword or a
    module's name, which a spec refuses (<robot name="class">, "site", "numpy": the user did
    not choose it, so it is not theirs to change)."""
    name = re.sub(r"[^a-z0-9_]+", "_", text.lower()).strip("_")
    if not name or not name[0].isalpha():
        name = "arm_" + name
    name = name[:60]
    if keyword.iskeyword(name) or shadows_a_module(name):
        name += "_arm"
    return name


def arm_name(given: str, path: Path) -> str:
    """The spec name of the robot a file names given: given's, or the file's where given has
    no letter or digit (<robot name="  "> was named "arm_")."""
    return spec_name(given if re.search(r"[A-Za-z0-9]", given) else path.stem)


def spec_text(
    conversion: Conversion,
    robot: Robot,
    source: str,
    base: str,
    tip: str,
    name: str,
    convention: str = "modified",
    kind: str = "URDF",
    part: str = "link",
    ik: tuple[tuple[str, str], ...] = (),
) -> str:
    """The spec as canonical TOML, with the conversion's record as comments and [source].

    The standard convention's rows are the same numbers regrouped: with alpha_0 = a_0 = 0
    (frame 0 is frame 1 at q = 0), Craig's X0 Z1 X1 Z2 ... Zn is Z1 X1 Z2 X2 ... Zn, and
    Rx Tx commute, so standard row i holds (alpha_i, a_i) of modified row i + 1 with its own
    (d_i, theta_i), and the last row a_n = alpha_n = 0; base and tool stay."""

    def number(x: float) -> str:
        # the spec takes 0 or magnitudes from 1e-9 (rounding noise below that is 0), and
        # 15 significant digits when snapping (0.39225000000000004 is 0.39225)
        x = float(x) + 0.0
        if abs(x) < 1e-9:
            return "0.0"
        return repr(float(f"{x:.15g}")) if conversion.snaps or conversion.rounded else repr(x)

    lines = [
        f"# Converted by derive-ik from the {kind} {source!r} (sha256 {robot.digest}...),",
        f"# robot {robot.name!r}, from {part.split('/')[0]} {base!r} to {part.split('/')[-1]} "
        f"{tip!r}. Joint values mean what",
        f"# they mean in the {kind} (same axis direction, same zero).",
    ]
    for snap in conversion.snaps:
        lines.append(f"# snapped: {snap}")
    lines.append(
        f"# FK of this spec against the {kind}'s on {SAMPLES} random joint vectors: largest "
        f"difference {conversion.deviation:.2g}"
    )
    lines.append("# (rotation entries, and positions divided by the arm's size)")
    lines += [
        f'name = "{name}"',
        f'convention = "{convention}"',
        'angle_unit = "deg"',
        'length_unit = "m"',
    ]
    if ik:
        lines += ["", "# from the command line (--task, --tool-axis, --method, --base-axis)"]
        lines += ["[ik]"]
        lines += [f'{key} = "{value}"' for key, value in ik]
    rows = conversion.rows
    if convention == "standard":
        twists = [(r[1], r[2]) for r in rows[1:]] + [(0.0, 0.0)]
        rows = [(r[0], t[0], t[1], r[3], r[4], r[5]) for r, t in zip(rows, twists)]
    for k, (joint_type, alpha, a, d, theta, limits) in enumerate(rows):
        lines += [
            "",
            f"# row {k + 1}: {kind} joint {conversion.joint_names[k]!r}",
            "[[joint]]",
            f'type = "{joint_type}"',
            f"alpha = {number(math.degrees(alpha))}",
            f"a = {number(a)}",
            f"d = {number(d)}",
            f"theta = {number(math.degrees(theta))}",
        ]
        if limits is not None:
            lo, hi = (math.degrees(v) for v in limits) if joint_type == "R" else limits
            lines.append(f"limits = [{number(lo)}, {number(hi)}]")

    def entry(x: float) -> str:
        # a base's or a tool's entry: kept down to rounding noise (a frame turned by CAD
        # decimals about two axes has entries 1e-11: written as 0, its FK moved 2.7e-11)
        x = float(x) + 0.0
        return "0.0" if abs(x) < 1e-15 else repr(float(f"{x:.15g}"))

    for title, matrix in (("base", conversion.base), ("tool", conversion.tool)):
        entries = ", ".join("[" + ", ".join(entry(v) for v in row) + "]" for row in matrix)
        lines += ["", f"[{title}]", f"matrix = [{entries}]"]

    def strings(values: list[str]) -> str:
        return "[" + ", ".join(f'"{_label(v)}"' for v in values) + "]"

    if conversion.snaps or conversion.deviation > ROUNDED:
        lines += [
            "",
            f"# the {kind}'s own geometry: the table above is snapped (its structure picks the",
            "# closed form) or rounded; fk, and every answer, are these frames'",
            "# (derive/nominal.py)",
            "[exact]",
            "frames = [",
            *(f"    [{', '.join(_exact_number(v) for v in f)}]," for f in conversion.frames),
            "]",
        ]
    lines += [
        "",
        "# where this spec came from (the report shows it)",
        "[source]",
        f'urdf = "{_label(source)}"',
        f'sha256 = "{robot.digest}"',
        f'base = "{_label(base)}"',
        f'tip = "{_label(tip)}"',
        f"joints = {strings(conversion.joint_names)}",
        f"snaps = {strings(conversion.snaps)}",
        f"deviation = {float(f'{conversion.deviation:.2g}')!r}",
    ]
    if kind != "URDF":
        lines.append(f'format = "{kind}"')
    return "\n".join(lines) + "\n"


def _exact_number(x: float) -> str:
    """A frame entry as TOML: every digit (rounding noise below 1e-15 as 0)."""
    x = float(x) + 0.0
    return "0.0" if abs(x) < 1e-15 else repr(x)


def _label(text: str) -> str:
    """text with every character a spec's [source] strings may not hold replaced by _."""
    return re.sub(r"[^A-Za-z0-9_ .,:;()+\-<>'=/]", "_", text)[:200] or "_"


@dataclass(frozen=True)
class Options:
    """How a URDF becomes a spec (the command line's --base, --tip, ...)."""

    base: str | None = None
    tip: str | None = None
    name: str | None = None
    angle_tol: float = ANGLE_TOL
    length_tol: float = LENGTH_TOL
    exact: bool = False
    max_deviation: float = MAX_DEVIATION
    convention: str = "modified"
    task: str | None = None
    tool_axis: str | None = None
    method: str | None = None
    base_axis: str | None = None

    def __post_init__(self) -> None:
        """Refuse tolerances that mean nothing: negative, NaN, or so large that snapping
        would change the arm (or a deviation bound nothing), and unknown tasks and axes."""
        for option, choice, allowed in (
            ("--task", self.task, IK_TASKS),
            ("--tool-axis", self.tool_axis, TOOL_AXES),
            ("--method", self.method, IK_METHODS),
            ("--base-axis", self.base_axis, TOOL_AXES),
        ):
            if choice is not None and choice not in allowed:
                raise UrdfError(f"{option} {choice!r}: allowed: {', '.join(allowed)}")
        for option, value, (lo, hi), unit in (
            ("--angle-tol", self.angle_tol, TOLERANCE_RANGE, " rad"),
            ("--length-tol", self.length_tol, TOLERANCE_RANGE, " of the arm's size"),
            ("--max-deviation", self.max_deviation, DEVIATION_RANGE, " of the reach"),
        ):
            if not lo <= value <= hi:
                raise UrdfError(f"{option} {value!r}: allowed: {lo:g} to {hi:g}{unit}")


def import_urdf(path: Path, options: Options) -> tuple[str, Conversion]:
    """The spec text of the chain options.base .. options.tip of a URDF, and the conversion's
    record. The spec's FK is checked against the URDF's: within 1e-9 without snapping (else
    the converter is wrong), within max_deviation with it (else the user must decide). What
    was ignored is said on stderr, one ``note:`` line each (also in the record's notes)."""
    where = str(path)
    robot = read_urdf(path)
    if not options.base or not options.tip:
        raise UrdfError(f"{where}: a URDF needs --base LINK and --tip LINK{ends_hint(robot)}")
    try:
        chain = chain_between(robot, options.base, options.tip, where)
    except UrdfError as exc:
        elements = [n for n in robot.ignored if n.startswith("<")]
        if not elements:
            raise
        raise UrdfError(
            f"{exc} (elements with a prefix no xmlns declares were not read as URDF: "
            f"{_listing(elements)})"
        ) from None
    return import_chain(robot, chain, path, options)


def import_chain(
    robot: Robot,
    chain: list[UrdfJoint],
    path: Path,
    options: Options,
    source: str = "URDF",
    part: str = "link",
) -> tuple[str, Conversion]:
    """import_urdf's conversion of a chain read from a file of the format source (whose
    frames are parts: URDF links, MJCF bodies; derive/mjcf.py; "body/site": the base's kind,
    then the tip's)."""
    where = str(path)
    assert options.base is not None and options.tip is not None
    for joint in chain:
        if joint.refused:
            raise UrdfError(joint.refused)
    tolerances = (options.angle_tol, options.length_tol, options.exact, options.task)
    conversion = convert(chain, where, *tolerances)
    name = options.name or arm_name(robot.name, path)
    given = (
        ("task", options.task),
        ("tool_axis", options.tool_axis),
        ("method", options.method),
        ("base_axis", options.base_axis),
    )
    ik = tuple((key, value) for key, value in given if value)
    args = (conversion, robot, path.name, options.base, options.tip, name, options.convention,
            source, part, ik)  # fmt: skip
    conversion.deviation = measure(parse_spec(spec_text(*args), f"{where} (converted)"), chain,
                                   conversion.reach)  # fmt: skip
    if conversion.far and not conversion.deviation <= options.max_deviation:
        # (axes taken as parallel for their far normal moved the table too far: only those
        # beyond OFFSET_LIMIT, which would be refused, are taken so)
        conversion = convert(chain, where, *tolerances, far=OFFSET_LIMIT)
        args = (conversion, *args[1:])
        conversion.deviation = measure(parse_spec(spec_text(*args), f"{where} (converted)"),
                                       chain, conversion.reach)  # fmt: skip
    bound = options.max_deviation if conversion.snaps else 1e-9
    if not conversion.deviation <= bound:
        cause = "after snapping" if conversion.snaps else "without snapping (a converter error)"
        far = f" ({'; '.join(conversion.far)})" if conversion.far else ""
        raise UrdfError(
            f"{where}: the spec's FK differs from the {source}'s by {conversion.deviation:.3g} "
            f"{cause}{far}; allowed {bound:g} ({_deviation_advice(conversion, bound)})"
        )
    if unbounded := [joint.name for joint in chain if joint.unbounded]:
        conversion.notes.append(
            f"{where}: joint(s) {_listing(unbounded)}: <limit> gives neither lower nor upper; "
            "read as unlimited (URDF's defaults, 0 and 0, would hold the joint at 0)"
        )
    if robot.ignored:
        conversion.notes.append(
            f"{where}: ignored {len(robot.ignored)} attribute(s) or element(s) with a prefix "
            f"no xmlns declares ({_listing(list(robot.ignored))}); kinematics does not read them"
        )
    for note in conversion.notes:
        print(f"note: {note}", file=sys.stderr)
    return spec_text(*args), conversion


def _deviation_advice(conversion: Conversion, bound: float) -> str:
    """What a refusal for the deviation can do: the --max-deviation that accepts the snapped
    table (its exact frames keep the module's fk and rows the file's own; up to DEVIATION_RANGE),
    or --exact."""
    needed = float(f"{conversion.deviation * 1.05:.2g}")
    if conversion.snaps and bound < needed <= DEVIATION_RANGE[1]:
        return (
            f"--max-deviation {needed:g} accepts it: the module's fk and every row stay the "
            "file's own, refined from the snapped table's closed form; --exact switches "
            "snapping off"
        )
    return "--max-deviation; --exact to switch snapping off"


def load_urdf(path: Path, options: Options) -> ArmSpec:
    """The spec of a URDF chain, as load_spec gives it for a spec file."""
    text, _ = import_urdf(path, options)
    return parse_spec(text, where=f"{path} ({options.base} .. {options.tip})")
