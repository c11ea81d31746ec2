"""MJCF in: a MuJoCo model's chain between two bodies as a spec, through the URDF path.

MuJoCo's own compiler reads the file (the optional ``mjcf`` extra), so default classes,
``<include>``, ``<frame>``, ``euler``/``axisangle`` orientations and the compiler's angle unit
mean what MuJoCo makes of them; meshes the file names but the folder lacks are left out
(kinematics does not need them). The compiled model gives each body's pose in its parent at
qpos0 and each joint's anchor and axis in its body. A body with joints j_1 .. j_k moves as
MuJoCo moves it,

    parent -> body = (pos, quat) Tr(p_1) M_1(q_1 - ref_1) Tr(-p_1) ... Tr(p_k) M_k Tr(-p_k)

(M a rotation about the joint's axis or a translation along it), which is a URDF chain: each
joint's origin carries the translations, and a fixed joint ends at the body's frame. That
chain is checked first against MuJoCo's own forward kinematics (mj_kinematics) on random joint
vectors (a difference above 1e-9 is a converter error, refused), then converted as a URDF is
(derive/urdf.py: snapping, [exact] frames, the measured deviation).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import random
import stat
from pathlib import Path
from typing import Any

from derive import extras, urdf
from derive.spec import ArmSpec, parse_spec
from derive.urdf import Matrix, Robot, UrdfError, UrdfJoint, Vector

# MuJoCo's joint types (mjtJoint) other than slide (2)
FREE, BALL, HINGE = 0, 1, 3
# the compiled chain against MuJoCo's own FK: this many joint vectors, this close
CHECK_SAMPLES = 20
CHECK_TOL = 1e-9
# MuJoCo's compiler message, cut to this many characters
COMPILE_SHOWN = 300
# the name MuJoCo gives a model whose <mujoco> has no model attribute
MUJOCO_UNNAMED = "MuJoCo Model"


def _mujoco(where: str) -> Any:
    try:
        import mujoco  # type: ignore[import-untyped,import-not-found,unused-ignore]  # (extra)
    except ImportError:
        raise UrdfError(
            f"{where}: reading MJCF needs MuJoCo's compiler: {extras.install_hint('mjcf')}"
        ) from None
    return mujoco


def compile_model(path: Path) -> Any:
    """The MuJoCo model of an MJCF file (meshes it names but cannot find left out)."""
    where = str(path)
    mujoco = _mujoco(where)
    try:
        status = path.stat()
    except OSError as exc:
        raise UrdfError(f"{where}: cannot read: {exc.strerror}") from None
    if not stat.S_ISREG(status.st_mode):
        raise UrdfError(f"{where}: not a regular file")
    if status.st_size > urdf.MAX_BYTES:
        raise UrdfError(
            f"{where}: {status.st_size} bytes; an MJCF may have at most {urdf.MAX_BYTES}"
        )
    # MuJoCo's warnings (a nan in the XML) go to stderr and to MUJOCO_LOG.TXT in the working
    # folder unless a handler takes them: the checks below refuse what they warn of, in one line
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        return _compile(mujoco, path)
    finally:
        mujoco.set_mju_user_warning(previous)


def _compile(mujoco: Any, path: Path) -> Any:
    """compile_model's compilation (meshes it names but cannot find left out)."""
    where = str(path)
    try:
        return mujoco.MjModel.from_xml_path(str(path))
    except ValueError as first:
        try:  # (meshes, heightfields and textures are not kinematics)
            spec = mujoco.MjSpec.from_file(str(path))
            for geom in spec.geoms:
                if geom.type in (mujoco.mjtGeom.mjGEOM_MESH, mujoco.mjtGeom.mjGEOM_HFIELD):
                    geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
                    geom.size = [0.01, 0.0, 0.0]
                    geom.meshname = ""
                    geom.hfieldname = ""
            for kind in ("meshes", "hfields", "skins", "textures"):
                for element in list(getattr(spec, kind)):
                    spec.delete(element)
            for material in spec.materials:
                material.textures = [""] * len(material.textures)
            spec.compiler.boundmass = 1e-6  # (bodies without geoms: MuJoCo wants mass)
            spec.compiler.boundinertia = 1e-9
            return spec.compile()
        except Exception as second:  # (without the meshes MuJoCo's message names what is
            # wrong with the kinematics; where the file does not parse, both say that; a new
            # user's WidowX MJCF with an axis "0 0 0" and its meshes absent was refused for
            # the missing meshes only)
            message = " ".join(str(second or first).split())[:COMPILE_SHOWN]
            raise UrdfError(f"{where}: MuJoCo cannot compile it: {message}") from None


def _frame(
    position: Any, rotation: Any = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
) -> Matrix:
    """The 4x4 transform of a position and a rotation's rows (the identity by default)."""
    return [[*(float(v) for v in rotation[r]), float(position[r])] for r in range(3)] + [
        [0.0, 0.0, 0.0, 1.0]
    ]


def _quaternion(quat: Any) -> list[list[float]]:
    """The rotation's rows of a quaternion (w, x, y, z), normalised."""
    w, x, y, z = (float(v) for v in quat)
    n = math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w / n, x / n, y / n, z / n
    return [
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ]


def _names(model: Any, count: int, kind: Any, label: str) -> list[str]:
    """The elements' names; an unnamed one is label + its index."""
    mujoco = _mujoco("")
    out = []
    for i in range(count):
        name = mujoco.mj_id2name(model, kind, i)
        out.append(name if name else f"{label}{i}")
    return out


def model_robot(
    model: Any, where: str, digest: str
) -> tuple[Robot, dict[str, int], dict[str, tuple[str, int]]]:
    """The model's bodies as links and its joints as URDF joints (module docstring), its
    named sites as links fixed to their bodies (a gripper's tool point is often a site), and
    the MuJoCo indices of the hinge and slide joints by name and of the bodies and sites
    ("body" or "site", index) by name (a site of a body's name is left out)."""
    mujoco = _mujoco(where)
    bodies = _names(model, model.nbody, mujoco.mjtObj.mjOBJ_BODY, "body")
    names = _names(model, model.njnt, mujoco.mjtObj.mjOBJ_JOINT, "joint")
    links = set(bodies)
    joints: list[UrdfJoint] = []
    index: dict[str, int] = {}
    for b in range(1, model.nbody):
        body, above = bodies[b], bodies[int(model.body_parentid[b])]
        place = _frame(model.body_pos[b], _quaternion(model.body_quat[b]))
        first = int(model.body_jntadr[b])
        for j in range(first, first + int(model.body_jntnum[b])):
            kind, name = int(model.jnt_type[j]), names[j]
            anchor = _vector(model.jnt_pos[j])
            if kind in (FREE, BALL):  # (chain_between refuses it between base and tip)
                joint = UrdfJoint(name, "free" if kind == FREE else "ball", above,
                                  f"{body}#{name}", place,
                                  (0.0, 0.0, 1.0), None, False)  # fmt: skip
                place = _frame((0.0, 0.0, 0.0))
            else:
                limits = (
                    tuple(float(v) for v in model.jnt_range[j]) if model.jnt_limited[j] else None
                )
                joint = UrdfJoint(
                    name,
                    "revolute" if kind == HINGE else "prismatic",
                    above,
                    f"{body}#{name}",
                    urdf.matmul(place, _frame(anchor)),
                    _vector(model.jnt_axis[j]),
                    limits,  # type: ignore[arg-type]
                    False,
                )
                ref = float(model.qpos0[model.jnt_qposadr[j]])
                if ref != 0.0:  # (MuJoCo moves the joint by q - qpos0)
                    origin = urdf.matmul(joint.origin, urdf.motion(joint, -ref))
                    joint = dataclasses.replace(joint, origin=origin)
                index[name] = j
                place = _frame([-v for v in anchor])
            joints.append(joint)
            links.add(joint.child)
            above = joint.child
        joints.append(UrdfJoint(f"{body}#frame", "fixed", above, body, place, (0.0, 0.0, 1.0),
                                None, False))  # fmt: skip
    places = {name: ("body", b) for b, name in enumerate(bodies)}
    for i in range(model.nsite):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, i)
        if not name or name in links:
            continue
        body = bodies[int(model.site_bodyid[i])]
        place = _frame(model.site_pos[i], _quaternion(model.site_quat[i]))
        joints.append(UrdfJoint(f"{name}#site", "fixed", body, name, place, (0.0, 0.0, 1.0),
                                None, False))  # fmt: skip
        links.add(name)
        places[name] = ("site", i)
    # (the model's name is the first of model.names, which mj_id2name does not give)
    model_name = bytes(model.names).split(b"\0", 1)[0].decode("utf-8", "replace")
    return Robot(model_name, frozenset(links), tuple(joints), digest), index, places


def _vector(values: Any) -> Vector:
    x, y, z = (float(v) for v in values)
    return (x, y, z)


def check_against_mujoco(
    model: Any,
    chain: list[UrdfJoint],
    index: dict[str, int],
    ids: list[tuple[str, int]],
    where: str,
) -> None:
    """Refuse the chain unless its FK is MuJoCo's (the tip body or site in the base's frame)
    within CHECK_TOL on CHECK_SAMPLES random joint vectors: else the reading above is
    wrong."""
    mujoco = _mujoco(where)
    data = mujoco.MjData(model)
    rng = random.Random(0)
    moving = [j for j in chain if j.kind in urdf.MOVING]
    worst = 0.0
    for _ in range(CHECK_SAMPLES):
        q = [rng.uniform(-math.pi, math.pi) for _ in moving]
        data.qpos[:] = model.qpos0
        for joint, value in zip(moving, q):
            data.qpos[model.jnt_qposadr[index[joint.name]]] = value
        mujoco.mj_kinematics(model, data)
        frames = [
            _frame(data.xpos[i], data.xmat[i].reshape(3, 3))
            if kind == "body"
            else _frame(data.site_xpos[i], data.site_xmat[i].reshape(3, 3))
            for kind, i in ids
        ]
        expected = urdf.matmul(urdf.inverse(frames[0]), frames[1])
        got = urdf.urdf_fk(chain, q)
        worst = max(worst, *(abs(got[r][c] - expected[r][c]) for r in range(3) for c in range(4)))
    if not worst <= CHECK_TOL:
        raise UrdfError(
            f"{where}: the chain read from MuJoCo's model differs from MuJoCo's own forward "
            f"kinematics by {worst:.3g} (a converter error; please report it with the file)"
        )


def check_numbers(model: Any, chain: list[UrdfJoint], index: dict[str, int], where: str) -> None:
    """Refuse the chain where a frame, axis or range MuJoCo compiled is not finite or exceeds
    MAX_NUMBER in magnitude (the URDF reader's rule; MuJoCo takes nan and 1e300, and leaves
    a joint whose range holds a nan without limits)."""
    for joint in chain:
        moving = joint.kind in urdf.MOVING
        name = joint.name if moving else joint.name.split("#")[0]
        what = "joint" if moving else "body"
        parts = {
            "frame (its body's pos and quat, its own pos)" if moving else "frame (pos and quat)": [
                v for row in joint.origin[:3] for v in row
            ],
            "axis": list(joint.axis),
            "range": [float(v) for v in model.jnt_range[index[name]]] if moving else [],
        }
        for part, values in parts.items():
            if not all(abs(v) <= urdf.MAX_NUMBER for v in values):
                shown = " ".join(f"{v:g}" for v in values)
                raise UrdfError(
                    f"{where}: {what} {urdf._shown(name)}: {part} {shown}; allowed: finite "
                    f"numbers of magnitude at most {urdf.MAX_NUMBER:g}"
                )


def check_couplings(
    model: Any, chain: list[UrdfJoint], index: dict[str, int], base: str, where: str
) -> None:
    """Refuse the chain where an active <equality> couples one of its joints to another or
    fixes it (a joint or tendon equality: a URDF mimic joint's kind), or ties one of its
    bodies past the base to the chain or to something fixed in the world (a connect or weld:
    a closed loop); its joints would not move freely. A weld to a mocap body (a controller's
    handle) or to a body that moves freely (a grasped object), or one that starts inactive,
    is not a loop."""
    mujoco = _mujoco(where)
    joints = {index[j.name] for j in chain if j.kind in urdf.MOVING}
    body = mujoco.mjtObj.mjOBJ_BODY
    bodies = {mujoco.mj_name2id(model, body, j.child) for j in chain if j.kind == "fixed"} - {
        -1,
        mujoco.mj_name2id(model, body, base),
    }
    fixed = {
        b
        for b in range(model.nbody)
        if int(model.body_weldid[b]) == 0 and int(model.body_mocapid[b]) < 0
    }
    held = bodies | fixed | {mujoco.mj_name2id(model, body, base)}
    eq = mujoco.mjtEq
    for e in range(model.neq):
        if not model.eq_active0[e]:
            continue
        kind = int(model.eq_type[e])
        ends: tuple[int, ...] = (int(model.eq_obj1id[e]), int(model.eq_obj2id[e]))
        if kind == eq.mjEQ_JOINT:
            coupled = any(j in joints for j in ends)
        elif kind == eq.mjEQ_TENDON:
            wraps = [
                int(model.wrap_objid[w])
                for t in ends
                if t >= 0
                for w in range(model.tendon_adr[t], model.tendon_adr[t] + model.tendon_num[t])
                if int(model.wrap_type[w]) == mujoco.mjtWrap.mjWRAP_JOINT
            ]
            coupled = any(j in joints for j in wraps)
        elif kind in (eq.mjEQ_CONNECT, eq.mjEQ_WELD):
            if int(model.eq_objtype[e]) == mujoco.mjtObj.mjOBJ_SITE:
                ends = tuple(int(model.site_bodyid[i]) if i >= 0 else -1 for i in ends)
            ends = tuple(0 if b < 0 else b for b in ends)  # (no second body: the world)
            coupled = any(b in bodies for b in ends) and all(b in held for b in ends)
        else:
            coupled = False
        if coupled:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_EQUALITY, e)
            label = urdf._shown(name) if name else f"number {e + 1} (unnamed)"
            raise UrdfError(
                f"{where}: equality {label}, a {eq(kind).name[5:].lower()} constraint, ties the "
                "chain's joints or bodies between base and tip; not supported (the joints "
                "must move freely, as a URDF mimic joint's does not)"
            )


def import_mjcf(path: Path, options: urdf.Options) -> tuple[str, urdf.Conversion]:
    """The spec text of the chain options.base .. options.tip (bodies) of an MJCF file, and
    the conversion's record (derive/urdf.py's import_chain)."""
    where = str(path)
    model = compile_model(path)
    digest = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
    robot, index, places = model_robot(model, where, digest)
    if not options.base or not options.tip:
        world = _names(model, 1, _mujoco(where).mjtObj.mjOBJ_BODY, "body")[0]
        hint = urdf.ends_hint(robot, "bodies and sites", world) if model.nbody > 1 else ""
        raise UrdfError(f"{where}: an MJCF needs --base BODY and --tip BODY{hint}")
    if model.nbody == 1:  # (only MuJoCo's world: no <worldbody> of the file's own)
        raise UrdfError(
            f"{where}: no bodies but MuJoCo's world (an included fragment without a "
            "<worldbody>? give the model that includes it)"
        )
    for name, what in ((options.base, "--base"), (options.tip, "--tip")):
        if name not in places:
            bodies = sorted(n for n, (kind, _) in places.items() if kind == "body")
            sites = sorted(n for n, (kind, _) in places.items() if kind == "site")
            hint = urdf.did_you_mean(name, places)
            raise UrdfError(
                f"{where}: {what} {urdf._shown(name)}: no such body or site; {hint}bodies: "
                f"{urdf._listing(bodies)}" + (f"; sites: {urdf._listing(sites)}" if sites else "")
            )
    if places[options.base][0] == "site":
        raise UrdfError(
            f"{where}: --base {urdf._shown(options.base)}: a site; the chain starts from a body "
            "(a site, a frame fixed to a body, can be the --tip)"
        )
    chain = urdf.chain_between(
        robot, options.base, options.tip, where, "hinge, slide (a body without joints is fixed)"
    )
    check_numbers(model, chain, index, where)
    check_couplings(model, chain, index, options.base, where)
    ids = [places[options.base], places[options.tip]]
    check_against_mujoco(model, chain, index, ids, where)
    part = "body/site" if places[options.tip][0] == "site" else "body"
    # (named after the model, <mujoco model="...">, as a URDF after its robot; after the file
    # where the model has no name, which MuJoCo reports as MUJOCO_UNNAMED)
    model_name = "" if robot.name == MUJOCO_UNNAMED else robot.name
    named = dataclasses.replace(options, name=options.name or urdf.arm_name(model_name, path))
    return urdf.import_chain(robot, chain, path, named, source="MJCF", part=part)


def load_mjcf(path: Path, options: urdf.Options) -> ArmSpec:
    """The spec of an MJCF chain, as load_spec gives it for a spec file."""
    text, _ = import_mjcf(path, options)
    return parse_spec(text, where=f"{path} ({options.base} .. {options.tip})")
