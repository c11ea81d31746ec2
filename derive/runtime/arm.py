"""Stand-ins for the names a generated module prints for its arm; never copied.

The runtime's routines refer to these names as globals. A generated module defines them from
the arm's plan (constants, forward kinematics, the body of the solver); here they
describe a sample arm of one revolute and one prismatic joint, and the arm's functions raise,
so that the runtime imports, type-checks and its routines can be tested on their own.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

NAME = "sample"
DOF = 2
JOINT_TYPES = "RP"
# (lower, upper) per joint: radians for R joints, length for P joints
LIMITS = ((-math.pi, math.pi), (-1.0, 1.0))
REACH = 1.0
# the most solutions a pose can have by the arm's derivation
MAX_SOLUTIONS = 2
# the joints (1-based) whose values the caller gives (an arm of more than 6 joints)
FREE: tuple[int, ...] = ()
# "pose", "position", "direction", "lookat", "pointing" or "axisangle": what certification
# compares (derive/tasks.py)
IK_COMPONENTS = "pose"
# the tool axis of the "direction", "lookat", "pointing" and "axisangle" tasks: 0 x, 1 y, 2 z
TOOL_AXIS = 2
# the base axis of the "axisangle" task: 0 x, 1 y, 2 z
CONE_AXIS = 2
_REVOLUTE = (True, False)
# a planar arm's plane task (derive/tasks.py, Plane): the tool's rotation at q = 0, the tool
# axis whose angle about z is the heading (0 x, 1 y) and that angle at q = 0, the plane's
# height, whether a sliding joint moves the tool along z
_PLANE_ROTATION: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
HEADING_AXIS = 0
_HEADING_ZERO = 0.0
PLANE_Z = 0.0
_PLANE_SLIDE = False
# how far the solver's equations may miss and still seed a refinement onto the exact chain
# (0.0: the closed form solves the arm's own table)
_SEED_TOL = 0.0
# the exact chain's fixed frames (top three rows, row-major) and the joints (0-based) the
# refinement moves: derive/runtime/refine.py
_CHAIN: tuple[tuple[float, ...], ...] = (
    (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0),
    (1.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0),
    (1.0, 0.0, 0.0, 0.5, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0),
)
_SOLVED: tuple[int, ...] = (0, 1)
# the arm's C solver, beside the module ("" where the arm has none): derive/runtime/native.py
_C_SOURCE = ""


def _missing(*args: Any) -> Any:
    raise NotImplementedError("printed per arm by derive's emitter")


_fk_from_cs = _fk_q = _jacobian_q = _cs_columns = _keep = _ik_scalar = _rr_fill = _missing
_branch_signs = _missing
# the joint values whose steps choose a branch (branch(q)), in the order they are solved
BRANCHES: tuple[str, ...] = ()
BASE = TOOL = np.eye(4)
# the general method's splits: (reversed, rows the matrices were filled from, the arm's rows,
# (1.0, theta3) where joint 3 slides else (0.0, 0.0)), rows (d, a, cos alpha, sin alpha) of
# standard DH in units of _RR_LENGTH
_RR_SPLITS: tuple[
    tuple[bool, tuple[tuple[float, ...], ...], tuple[tuple[float, ...], ...], tuple[float, float]],
    ...,
]
_RR_SPLITS = ()
_RR_LENGTH = 1.0
# the ends of the six joints (0: joints 1-3, 3: joints 4-6) whose wrist flip leaves the pose
# unchanged (Eigen.flips)
_RR_FLIPS: tuple[int, ...] = ()
# per split, the vectors of Split.spurious (12 x _RR_SPURIOUS_COUNT[k] of the columns; the
# rest zeros)
_RR_SPURIOUS = np.zeros((0, 12, 0))
_RR_SPURIOUS_COUNT: tuple[int, ...] = ()
_RR_PIVOTS = np.zeros((0, 1), dtype=np.int64)
