"""The geometric Jacobian, derived from the same factors as the forward kinematics.

The pose is a product of fixed factors and joint factors, M_0 Z_1 M_1 ... Z_n M_n, each Z_i a
turn Rz(theta_i) or a slide Tz(d_i) about (along) its own frame's z axis: the table's
B X_0 Z_1 X_1 ... Z_n X_n E, or an arm's exact frames F_0 Z_1 G_1 ... Z_n G_n
(derive/nominal.py). With P_i = M_0 Z_1 ... M_{i-1} the frame joint i moves in, z_i its z
column and o_i its origin, and p the tool point, column i of the Jacobian is

    revolute:  [z_i x (p - o_i); z_i]        prismatic:  [z_i; 0]

(the tool point's velocity over the angular velocity, in the world: d p / d q_i and the axis
of the rotation d R / d q_i R^T). The entries are unexpanded products of the factors in c_i,
s_i and d_i, printed with CSE beside the forward kinematics (Python and C). An arm with exact
frames (a URDF's, every frame a dense matrix) has no printed Jacobian: the common
subexpressions of its entries took half of its generation (a zoo URDF's UR3e 23.5 s, 6.2 s
without), and its module computes the same columns from its chain at run time
(_chain_jacobian in derive/runtime/refine.py, dk_chain_jacobian in derive/c/runtime.c).
"""

from __future__ import annotations

import sympy as sp


def geometric(factors: list[sp.Matrix], joints: list[int], kinds: str) -> sp.Matrix:
    """The 6 x n geometric Jacobian at the tool point, in the world frame (module docstring).

    Args:
        factors: the pose's factors, left to right.
        joints: the positions in factors of the joint factors Z_1 .. Z_n.
        kinds: the joints' kinds, "R" or "P", in order.
    """
    frame = sp.eye(4)
    axes, origins = [], []
    at = 0
    for position in joints:
        for factor in factors[at:position]:
            frame = frame * factor
        axes.append(frame[:3, 2])
        origins.append(frame[:3, 3])
        at = position
    for factor in factors[at:]:
        frame = frame * factor
    p = frame[:3, 3]
    columns = []
    for z, o, kind in zip(axes, origins, kinds):
        if kind == "R":
            columns.append(sp.Matrix.vstack(z.cross(p - o), z))
        else:
            columns.append(sp.Matrix.vstack(z, sp.zeros(3, 1)))
    return sp.Matrix.hstack(*columns)
