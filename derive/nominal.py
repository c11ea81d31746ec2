"""The nominal arm of an exact one: the table a closed form solves, and how far it is.

Real arms are never exactly special: a calibration moves every DH parameter a little, a URDF
writes pi/2 as 1.5708. Their tables have no closed form, but a table a little away does. The
nominal table snaps each parameter that shapes the structure to the special value within the
structure tolerance (spec `[ik] structure_tol`): twists alpha (and a prismatic joint's fixed
theta) to a multiple of 90 deg within `tol` radians, lengths a (and a revolute joint's d) to 0
within `tol` times the arm's size. Joint offsets (a revolute joint's theta, a prismatic one's
d), the base and the tool do not shape the structure and are kept.

The generated module solves the nominal table in closed form and refines every solution by
Newton's steps on the exact chain (derive/runtime/refine.py, dk_refine in derive/c/runtime.c),
which it holds as fixed frames: T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n with J_i a rotation
about (R) or a translation along (P) the z axis (docs/algorithms.md, "Nominal closed form,
exact answers").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import sympy as sp

from derive import symbols as sym
from derive.spec import ArmSpec, Joint
from derive.transforms import Chain, rot_z, trans, x_factor

# the default structure tolerance: a calibration moves twists by ~0.02 deg (3.5e-4 rad) and
# lengths by ~0.2 mm of a 1 m arm; a URDF's 1.5708 is 3.7e-6 from pi/2
STRUCTURE_TOL = 1e-3
# joint vectors the nominal table's forward kinematics is compared with the exact one's on
SAMPLES = 256


@dataclass(frozen=True)
class Nominal:
    """The nominal table of an arm and what snapping changed.

    Attributes:
        spec: the arm with the snapped table (the closed form's).
        changes: one line per snapped parameter ("row 2 alpha: 0.02 deg to 0 deg").
        tol: the structure tolerance used.
    """

    spec: ArmSpec
    changes: tuple[str, ...]
    tol: float


# two axes within this (radians) of parallel, but not exactly parallel, have their common
# normal far out along them: link_size sums their offsets d first
NEARLY_PARALLEL = 0.05


def link_size(spec: ArmSpec) -> float:
    """The sum of the table's lengths |a| + |d|, the offsets d of two joints whose axes are
    nearly parallel (within NEARLY_PARALLEL, not exactly) summed first: their common normal,
    which the table's frames lie on, is far out along them, and their d's are large and
    cancel (a calibrated KR6 URDF's axes 2 and 3, 2e-5 rad from parallel: d2 = 15.5958 m, d3 =
    -15.5958 m, which made the arm's size 32 m, not 1.4 m: its real 25 mm shoulder offset
    was then snapped to 0 and its rows certified 20 times too loosely). A run of such joints
    is one group; an axis that points back along the one before (a twist near 180 deg) runs
    its offset the other way (a calibrated KR6 written as a URDF with arbitrary link frames:
    d2 = -1.2822 m, d3 = -1.2825 m at 179.98 deg, which made its size 4.66 m, not 1.42 m; a
    reviewer's find, helper 47)."""
    to_rad = math.radians if spec.angle_unit == "deg" else float
    joints = spec.joints
    # the twist between axes k and k + 1 (0-based): modified row k + 1's, standard row k's
    twists = [to_rad(j.alpha) for j in (joints[1:] if spec.convention == "modified" else joints)]
    size = sum(abs(j.a) for j in joints)
    group, sign = 0.0, 1.0
    for k, joint in enumerate(joints):
        group += sign * joint.d if joint.kind == "R" else 0.0
        twist = twists[k] if k < len(twists) else 0.0
        off = abs(math.remainder(twist, math.pi))
        if k + 1 < len(joints) and 0.0 < off <= NEARLY_PARALLEL:
            sign = -sign if math.cos(twist) < 0.0 else sign  # (axis k + 1 points back)
            continue  # (joint k + 1's offset joins this group)
        size += abs(group)
        group, sign = 0.0, 1.0
    size += sum(abs(j.d) for j in joints if j.kind == "P")
    return size


def nominal(spec: ArmSpec, tol: float = STRUCTURE_TOL) -> Nominal:
    """The spec with every structure parameter within tol of its special value snapped."""
    size = link_size(spec) or 1.0
    quarter = 90.0 if spec.angle_unit == "deg" else math.pi / 2
    to_rad = math.radians if spec.angle_unit == "deg" else float
    unit = "deg" if spec.angle_unit == "deg" else "rad"
    changes: list[str] = []
    joints: list[Joint] = []

    def angle(value: float, what: str) -> float:
        target = quarter * round(value / quarter)
        if value != target and abs(to_rad(value - target)) <= tol:
            changes.append(f"{what}: {value!r} {unit} to {target:g} {unit}")
            return float(target)
        return value

    def length(value: float, what: str) -> float:
        if value != 0.0 and abs(value) <= tol * size:
            changes.append(f"{what}: {value!r} to 0")
            return 0.0
        return value

    for i, j in enumerate(spec.joints, start=1):
        row = f"row {i}"
        alpha = angle(j.alpha, f"{row} alpha")
        a = length(j.a, f"{row} a")
        if j.kind == "R":
            joints.append(replace(j, alpha=alpha, a=a, d=length(j.d, f"{row} d")))
        else:
            joints.append(replace(j, alpha=alpha, a=a, theta=angle(j.theta, f"{row} theta")))
    return Nominal(replace(spec, joints=tuple(joints)), tuple(changes), tol)


def chain_frames(chain: Chain) -> tuple[tuple[float, ...], ...]:
    """The fixed frames F_0 .. F_n of the chain, 12 floats each (the top three rows,
    row-major): T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n, J_i = Rz(q_i) (R) or Tz(q_i) (P).

    The canonical chain is B X_0 Z_1 X_1 ... Z_n X_n E with Z_i = Rz(theta_i) Tz(d_i); Z_i at
    q_i = 0 times J_i(q_i) is Z_i (Rz and Tz commute), so F_0 = B X_0 Z_1(0),
    F_i = X_i Z_{i+1}(0) and F_n = X_n E."""
    at_zero = []
    for j in chain.joints:
        if j.kind == "R":
            at_zero.append(rot_z(*sym.cos_sin(j.offset)) * trans(0, 0, j.d))
        else:
            at_zero.append(rot_z(*sym.cos_sin(j.theta)) * trans(0, 0, j.offset))
    n = chain.dof
    frames = []
    for i in range(n + 1):
        m = x_factor(chain.twists[i])
        if i == 0:
            m = chain.base * m
        if i < n:
            m = m * at_zero[i]
        else:
            m = m * chain.tool
        frames.append(tuple(float(sp.N(m[r, c], 30)) for r in range(3) for c in range(4)))
    return tuple(frames)


def frames_pose(frames: tuple[tuple[float, ...], ...], chain: Chain) -> sp.Matrix:
    """The world pose of a chain of fixed frames in the joint symbols of chain (c_i, s_i of
    theta_i = q_i + offset, or d_i = q_i + offset): F_0 Z_1 G_1 ... Z_n G_n with Z_i the joint's
    Rz(theta_i) or Tz(d_i) and G_i = Rz(-offset_i) F_i or Tz(-offset_i) F_i (unexpanded: CSE
    prints it in fewer operations)."""
    out = sp.eye(4)
    for factor in frames_factors(frames, chain):
        out = out * factor
    return out


def frames_factors(frames: tuple[tuple[float, ...], ...], chain: Chain) -> list[sp.Matrix]:
    """frames_pose's factors F_0, Z_1, G_1, ..., Z_n, G_n."""
    out = [_exact_matrix(_square(frames[0]))]
    for j, frame in zip(chain.joints, frames[1:]):
        offset = float(j.offset)
        if j.kind == "R":
            c, s = math.cos(-offset), math.sin(-offset)
            undo = np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])
            move = rot_z(sym.c(j.index), sym.s(j.index))
        else:
            undo = np.eye(4)
            undo[2, 3] = -offset
            move = trans(0, 0, sym.d(j.index))
        out += [move, _exact_matrix(undo @ _square(frame))]
    return out


def _exact_matrix(m: np.ndarray) -> sp.Matrix:
    """A numeric 4x4 as SymPy numbers: 0 and 1 exact, the rest 17-digit floats."""

    def number(v: float) -> sp.Expr:
        if v in (0.0, 1.0, -1.0):
            return sp.Integer(int(v))
        return sp.Float(float(v), 17)

    return sp.Matrix(4, 4, [number(v) for v in m.reshape(-1)])


def frames_fk(frames: tuple[tuple[float, ...], ...], kinds: str, Q: np.ndarray) -> np.ndarray:
    """World poses (N, 4, 4) of joint vectors Q (N, n) on a chain of fixed frames."""
    out = np.broadcast_to(_square(frames[0]), (len(Q), 4, 4)).copy()
    for i, kind in enumerate(kinds):
        q = Q[:, i]
        joint = np.zeros((len(Q), 4, 4))
        joint[:, 2, 2] = joint[:, 3, 3] = 1.0
        if kind == "R":
            c, s = np.cos(q), np.sin(q)
            joint[:, 0, 0] = joint[:, 1, 1] = c
            joint[:, 0, 1] = -s
            joint[:, 1, 0] = s
        else:
            joint[:, 0, 0] = joint[:, 1, 1] = 1.0
            joint[:, 2, 3] = q
        out = out @ joint @ _square(frames[i + 1])
    return out


def _square(frame: tuple[float, ...]) -> np.ndarray:
    return np.array([*np.reshape(frame, (3, 4)), (0.0, 0.0, 0.0, 1.0)])


def deviation(
    exact: tuple[tuple[float, ...], ...],
    snapped: tuple[tuple[float, ...], ...],
    kinds: str,
    reach: float,
) -> float:
    """The largest forward-kinematics difference of two chains over SAMPLES joint vectors
    (a fixed seed): rotation entries as they are, positions divided by reach."""
    rng = np.random.default_rng(0)
    Q = rng.uniform(-math.pi, math.pi, (SAMPLES, len(kinds)))
    Q[:, [k for k, kind in enumerate(kinds) if kind == "P"]] *= reach / math.pi
    a, b = frames_fk(exact, kinds, Q), frames_fk(snapped, kinds, Q)
    rotation = np.max(np.abs(a[:, :3, :3] - b[:, :3, :3]))
    position = np.max(np.abs(a[:, :3, 3] - b[:, :3, 3])) / reach
    return float(max(rotation, position))
