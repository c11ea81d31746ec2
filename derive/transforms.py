"""Link transforms for standard and modified DH, their products, and forward kinematics.

Both conventions are the same product of elementary factors grouped differently
(docs/algorithms.md, "One product for both conventions"). With X_i = Rx(alpha_i) Tx(a_i)
and Z_i = Rz(theta_i) Tz(d_i):

* modified (Craig): (i-1)_iT = X_{i-1} Z_i, so 0_nT = X_0 Z_1 X_1 ... X_{n-1} Z_n;
* standard:         A_i = Z_i X_i,          so 0_nT = Z_1 X_1 ... Z_n X_n.

:class:`Chain` holds the canonical form X_0 Z_1 X_1 ... Z_n X_n with exact numbers, so that
every derivation works on one representation whichever convention the spec used.
Joint quantities appear as the symbols c_i, s_i (revolute) or d_i (prismatic) of
:mod:`derive.symbols`.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from derive import symbols as sym
from derive.spec import ArmSpec, Frame


@dataclass(frozen=True)
class Twist:
    """X_i = Rx(alpha_i) Tx(a_i) with exact cos/sin of the twist."""

    ca: sp.Expr
    sa: sp.Expr
    a: sp.Expr


@dataclass(frozen=True)
class JointZ:
    """Z_i = Rz(theta_i) Tz(d_i) of joint i (1-based).

    For an R joint theta_i = q_i + offset and d is the constant d_i; for a P joint
    d_i = q_i + offset and theta is the constant theta_i.
    """

    index: int
    kind: str
    offset: sp.Expr
    theta: sp.Expr
    d: sp.Expr


@dataclass(frozen=True)
class Chain:
    """An arm in canonical form: base B, X_0, (Z_i, X_i) for i = 1..n, tool E.

    Attributes:
        twists: X_0 .. X_n (n + 1 entries).
        joints: Z_1 .. Z_n.
        base: B, 4x4 exact (identity when the spec has none).
        tool: E, 4x4 exact (identity when the spec has none).
        convention: the spec's convention, for convention-specific link transforms.
    """

    twists: tuple[Twist, ...]
    joints: tuple[JointZ, ...]
    base: sp.Matrix
    tool: sp.Matrix
    convention: str

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joints)


def chain_from_spec(spec: ArmSpec) -> Chain:
    """Exact canonical chain of a spec (docs/algorithms.md, "One product for both conventions")."""
    n = spec.dof
    rows = [_twist(j.alpha, j.a, spec.angle_unit) for j in spec.joints]
    identity = Twist(sp.Integer(1), sp.Integer(0), sp.Integer(0))
    twists = [*rows, identity] if spec.convention == "modified" else [identity, *rows]
    joints = []
    for i, j in enumerate(spec.joints, start=1):
        if j.kind == "R":
            joints.append(
                JointZ(i, "R", sym.angle(j.theta, spec.angle_unit), sym.theta(i), sym.length(j.d))
            )
        else:
            joints.append(
                JointZ(i, "P", sym.length(j.d), sym.angle(j.theta, spec.angle_unit), sym.d(i))
            )
    assert len(twists) == n + 1
    return Chain(
        tuple(twists),
        tuple(joints),
        frame_matrix(spec.base, spec.angle_unit),
        frame_matrix(spec.tool, spec.angle_unit),
        spec.convention,
    )


def _twist(alpha: float, a: float, unit: str) -> Twist:
    ca, sa = sym.cos_sin(sym.angle(alpha, unit))
    return Twist(ca, sa, sym.length(a))


def frame_matrix(frame: Frame | None, unit: str) -> sp.Matrix:
    """The exact 4x4 matrix of a spec frame; R = Rz(yaw) Ry(pitch) Rx(roll)."""
    if frame is None:
        return sp.eye(4)
    if frame.matrix is not None:
        return sp.Matrix(4, 4, [sym.length(v) for v in frame.matrix])
    assert frame.translation is not None  # a frame is a matrix or a translation
    roll, pitch, yaw = (sym.cos_sin(sym.angle(v, unit)) for v in frame.rpy)
    rot = rot_z(*yaw) * rot_y(*pitch) * rot_x(*roll)
    rot[:3, 3] = sp.Matrix([sym.length(v) for v in frame.translation])
    return rot


def rot_x(ca: sp.Expr, sa: sp.Expr) -> sp.Matrix:
    """Rx as a 4x4 homogeneous transform, from cos and sin of the angle."""
    return sp.Matrix([[1, 0, 0, 0], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])


def rot_y(ca: sp.Expr, sa: sp.Expr) -> sp.Matrix:
    """Ry as a 4x4 homogeneous transform."""
    return sp.Matrix([[ca, 0, sa, 0], [0, 1, 0, 0], [-sa, 0, ca, 0], [0, 0, 0, 1]])


def rot_z(ca: sp.Expr, sa: sp.Expr) -> sp.Matrix:
    """Rz as a 4x4 homogeneous transform."""
    return sp.Matrix([[ca, -sa, 0, 0], [sa, ca, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])


def trans(x: sp.Expr, y: sp.Expr, z: sp.Expr) -> sp.Matrix:
    """A pure translation."""
    return sp.Matrix([[1, 0, 0, x], [0, 1, 0, y], [0, 0, 1, z], [0, 0, 0, 1]])


def x_factor(t: Twist) -> sp.Matrix:
    """X_i = Rx(alpha_i) Tx(a_i)."""
    return sp.Matrix([[1, 0, 0, t.a], [0, t.ca, -t.sa, 0], [0, t.sa, t.ca, 0], [0, 0, 0, 1]])


def z_factor(j: JointZ) -> sp.Matrix:
    """Z_i = Rz(theta_i) Tz(d_i) in the symbols c_i, s_i (R) or d_i (P)."""
    if j.kind == "R":
        ct, st = sym.c(j.index), sym.s(j.index)
    else:
        ct, st = sym.cos_sin(j.theta)
    return sp.Matrix([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, j.d], [0, 0, 0, 1]])


def link_transform(chain: Chain, i: int) -> sp.Matrix:
    """(i-1)_iT in the spec's own convention (Craig's for modified DH, A_i for standard)."""
    if chain.convention == "modified":
        return x_factor(chain.twists[i - 1]) * z_factor(chain.joints[i - 1])
    return z_factor(chain.joints[i - 1]) * x_factor(chain.twists[i])


def product(mats: list[sp.Matrix], expand: bool = True) -> sp.Matrix:
    """Left-to-right product; with expand, each entry is expanded so that terms cancel exactly.

    Unexpanded products keep the factored structure, which CSE turns into fewer operations.
    """
    out = sp.eye(4)
    for m in mats:
        out = out * m
        if expand:
            out = out.applyfunc(sp.expand)
    return out


def arm_factors(chain: Chain) -> list[sp.Matrix]:
    """X_0, Z_1, X_1, ..., Z_n, X_n."""
    mats = [x_factor(chain.twists[0])]
    for j, t in zip(chain.joints, chain.twists[1:]):
        mats += [z_factor(j), x_factor(t)]
    return mats


def world_transform(chain: Chain, expand: bool = True) -> sp.Matrix:
    """B 0_nT E: the pose of the tool frame in the world."""
    return product([chain.base, *arm_factors(chain), chain.tool], expand)


def inverse(m: sp.Matrix) -> sp.Matrix:
    """Inverse of a rigid transform: [R^T, -R^T t]."""
    rt = m[:3, :3].T
    out = sp.eye(4)
    out[:3, :3] = rt
    out[:3, 3] = -rt * m[:3, 3]
    return out.applyfunc(sp.expand)


def to_angles(expr: sp.Expr, chain: Chain) -> sp.Expr:
    """Replace c_i, s_i by cos(theta_i), sin(theta_i) (for comparing with printed formulas)."""
    subs = {}
    for j in chain.joints:
        if j.kind == "R":
            subs[sym.c(j.index)] = sp.cos(sym.theta(j.index))
            subs[sym.s(j.index)] = sp.sin(sym.theta(j.index))
    return expr.xreplace(subs)


def general_twist(i: int) -> Twist:
    """X_i with symbolic cos(alpha_i), sin(alpha_i), a_i (the lecture's general formulas)."""
    return Twist(sym.cos_alpha(i), sym.sin_alpha(i), sym.link_a(i))


def general_joint(i: int) -> JointZ:
    """Z_i of a revolute joint with symbolic d_i."""
    return JointZ(i, "R", sp.Integer(0), sym.theta(i), sym.d(i))


def general_pairs(indices: range) -> list[tuple[sp.Symbol, sp.Symbol]]:
    """(sin, cos) symbol pairs of the twists and joint angles with these indices."""
    pairs = [(sym.sin_alpha(i), sym.cos_alpha(i)) for i in indices]
    return pairs + [(sym.s(i), sym.c(i)) for i in indices]


def numbers_of(chain: Chain) -> dict[sp.Symbol, sp.Expr]:
    """Substitution of the general symbols by this arm's numbers.

    Twists 0..n give cos(alpha_i), sin(alpha_i), a_i; revolute joints give d_i; prismatic
    joints give c_i, s_i of their constant theta_i (their d_i stays a variable).
    """
    subs: dict[sp.Symbol, sp.Expr] = {}
    for i, t in enumerate(chain.twists):
        subs[sym.cos_alpha(i)] = t.ca
        subs[sym.sin_alpha(i)] = t.sa
        subs[sym.link_a(i)] = t.a
    for j in chain.joints:
        if j.kind == "R":
            subs[sym.d(j.index)] = j.d
        else:
            subs[sym.c(j.index)], subs[sym.s(j.index)] = sym.cos_sin(j.theta)
    return subs


def reverse_chain(chain: Chain) -> Chain:
    """The chain read from the tool back to the base (docs/algorithms.md, "The reversed chain").

    T^-1 = E^-1 X_n^-1 Z_n^-1 ... X_1^-1 Z_1^-1 X_0^-1 B^-1 with X_i^-1 = X(-alpha_i, -a_i) and
    Z_i^-1 = Z(-theta_i, -d_i). Joint k of the reversed chain is joint n + 1 - k of the arm
    with q'_k = -q_{n+1-k}: its offset and constant part change sign.
    """
    n = chain.dof
    twists = tuple(Twist(t.ca, -t.sa, -t.a) for t in reversed(chain.twists))
    joints = []
    for k, j in enumerate(reversed(chain.joints), start=1):
        if j.kind == "R":
            joints.append(JointZ(k, "R", -j.offset, sym.theta(k), -j.d))
        else:
            joints.append(JointZ(k, "P", -j.offset, -j.theta, sym.d(k)))
    assert len(joints) == n
    return Chain(twists, tuple(joints), inverse(chain.tool), inverse(chain.base), chain.convention)
