"""The task functions of an arm solved for fewer components than a pose (derive/tasks.py):
ik_position(p), ik_direction(p, d), ik_lookat(p), ik_pointing(d) and ik_axis_angle(p, angle)
(and a planar arm's ik_xy_heading and ik_xy, derive/tasks.py Plane) build a pose whose
components the task reads and call ik, which certifies every row on those components
(IK_COMPONENTS, TOOL_AXIS, CONE_AXIS)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from derive.runtime.api import ik
from derive.runtime.arm import (
    _HEADING_ZERO,
    _PLANE_ROTATION,
    _PLANE_SLIDE,
    CONE_AXIS,
    PLANE_Z,
    TOOL_AXIS,
)
from derive.runtime.common import _real
from derive.runtime.constants import CERTIFY_TOL


def ik_position(
    p: ArrayLike,
    *,
    free: ArrayLike | None = None,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions that put the tool point at p, whatever the tool's orientation (IKFast's
    Translation3D: three joints solved, any others free), as an (n, DOF) array; empty if
    unreachable.

    Args:
        p: the tool point in the world, 3 numbers.
        free, within_limits, q_ref, tol, backend: as ik's (free: an arm of more than three
            joints, the values of its free joints FREE). Every row reproduces p within
            tol * REACH.

    Raises:
        ValueError: p is not 3 finite numbers; free as ik says.
    """
    T = _point_pose(p)
    return ik(T, free=free, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_direction(
    p: ArrayLike,
    d: ArrayLike,
    *,
    free: ArrayLike | None = None,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions that put the tool point at p with the tool axis TOOL_AXIS along d
    (IKFast's TranslationDirection5D), as an (n, DOF) array; empty if unreachable.

    Args:
        p: the tool point in the world, 3 numbers.
        d: the tool axis's direction in the world, 3 numbers (not all 0; normalised here).
        free, within_limits, q_ref, tol, backend: as ik's (free: an arm with more joints
            than the task needs, FREE). Every row reproduces p within tol * REACH and the
            unit d within tol per entry.

    Raises:
        ValueError: p or d is not 3 finite numbers, or d is 0; free as ik says.
    """
    T = _task_pose(p, d)
    return ik(T, free=free, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_lookat(
    p: ArrayLike,
    *,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions whose tool axis TOOL_AXIS, from the tool point forward, passes through
    the point p (IKFast's Lookat3D), as an (n, DOF) array; empty if no configuration looks
    at p.

    Args:
        p: the point in the world, 3 numbers.
        within_limits, q_ref, tol, backend: as ik's. Every row's ray passes within
            tol * REACH of p.

    Raises:
        ValueError: p is not 3 finite numbers.
    """
    return ik(_point_pose(p), within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_pointing(
    d: ArrayLike,
    *,
    free: ArrayLike | None = None,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions that point the tool axis TOOL_AXIS along d, wherever the tool point is
    (IKFast's Direction3D), as an (n, DOF) array; empty if no configuration points that way.

    Args:
        d: the direction in the world, 3 numbers (not all 0; normalised here).
        free, within_limits, q_ref, tol, backend: as ik's. Every row reproduces the unit d
            within tol per entry.

    Raises:
        ValueError: d is not 3 finite numbers, or is 0; free as ik says.
    """
    T = _task_pose((0.0, 0.0, 0.0), d)
    return ik(T, free=free, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_axis_angle(
    p: ArrayLike,
    angle: float,
    *,
    free: ArrayLike | None = None,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions that put the tool point at p with the tool axis TOOL_AXIS at the angle
    `angle` to the base axis CONE_AXIS (IKFast's Translation{X,Y,Z}AxisAngle4D), as an
    (n, DOF) array; empty if unreachable. The task does not fix the direction about the base
    axis: the arm's joints choose it.

    Args:
        p: the tool point in the world, 3 numbers.
        angle: radians, 0 (the tool axis along the base axis) to pi (against it); the task
            reads its cosine.
        free, within_limits, q_ref, tol, backend: as ik's (free: a five-joint arm's wrist
            roll, FREE). Every row reproduces p within tol * REACH and the tool axis's
            component along the base axis, cos(angle), within tol.

    Raises:
        ValueError: p is not 3 finite numbers, or angle is not a number from 0 to pi; free
            as ik says.
    """
    if isinstance(angle, np.ndarray) and angle.shape == ():  # (a 0-d array: its number)
        angle = angle.item()
    if not 0.0 <= _number(angle, "angle") <= math.pi:  # (NaN fails too)
        raise ValueError(f"angle must be from 0 to pi (radians), got {angle!r}")
    d = np.zeros(3)  # (a direction at that angle: the task reads only its CONE_AXIS entry)
    d[CONE_AXIS] = math.cos(float(angle))
    d[(CONE_AXIS + 1) % 3] = math.sin(float(angle))
    T = _task_pose(p, d)
    return ik(T, free=free, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_xy_heading(
    x: float,
    y: float,
    heading: float,
    z: float | None = None,
    *,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions of a planar arm (every axis along the world's z) with the tool point at
    (x, y) and the tool axis HEADING_AXIS at the angle heading about z from the world's x axis
    (IKFast's TranslationXYOrientation3D), as an (n, DOF) array; empty if unreachable.

    Args:
        x, y: the tool point in the world's plane; heading: radians.
        z: the tool point's height, for an arm with a sliding joint; else None (the arm's
            plane, PLANE_Z).
        within_limits, q_ref, tol, backend: as ik's (the pose it solves: the tool's rotation
            turned about z, its point at (x, y, z)).

    Raises:
        ValueError: a number is not finite, or z is missing (a sliding joint) or given (none).
    """
    T = _plane_pose(x, y, z, heading)
    return ik(T, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def ik_xy(
    x: float,
    y: float,
    z: float | None = None,
    *,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> np.ndarray:
    """All solutions of a planar arm of two revolute joints (every axis along the world's z)
    with the tool point at (x, y) (IKFast's TranslationXY2D), as an (n, DOF) array.

    Args:
        x, y: the tool point in the world's plane; z: as ik_xy_heading's.
        within_limits, q_ref, tol, backend: as ik's.

    Raises:
        ValueError: as ik_xy_heading's.
    """
    T = _plane_pose(x, y, z, 0.0)
    return ik(T, within_limits=within_limits, q_ref=q_ref, tol=tol, backend=backend)


def _plane_pose(x: float, y: float, z: float | None, heading: float) -> np.ndarray:
    """The pose at (x, y, z or PLANE_Z) whose tool axis HEADING_AXIS is at heading about z:
    Rz(heading - _HEADING_ZERO) times the tool's rotation at q = 0, _PLANE_ROTATION."""
    numbers = {"x": x, "y": y, "heading": heading, "z": 0.0 if z is None else z}
    for name, value in numbers.items():
        if not math.isfinite(_number(value, name)):
            raise ValueError(f"{name} must be finite, got {value!r}")
    if _PLANE_SLIDE and z is None:
        raise ValueError("z is needed: a sliding joint moves the tool along z")
    if not _PLANE_SLIDE and z is not None:
        raise ValueError(f"z is the arm's plane's ({PLANE_Z!r}): give none")
    R0 = np.array(_PLANE_ROTATION).reshape(3, 3)
    c, s = math.cos(float(heading) - _HEADING_ZERO), math.sin(float(heading) - _HEADING_ZERO)
    T = np.eye(4)
    T[:3, :3] = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ R0
    T[:3, 3] = (float(x), float(y), PLANE_Z if z is None else float(z))
    return T


def _number(value: object, name: str) -> float:
    """value as a float: an int or a float (numpy's too), not a bool.

    Raises:
        ValueError: it is not one.
    """
    if type(value) is bool or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    return float(value)


def _point(p: ArrayLike) -> list[float]:
    """p as 3 finite floats (ValueError otherwise)."""
    point = _real(p, "p")
    if point.shape != (3,) or not all(map(math.isfinite, coordinates := point.tolist())):
        raise ValueError(f"p must be 3 finite numbers, got {point}")
    return coordinates


def _point_pose(p: ArrayLike) -> np.ndarray:
    """A pose with origin p and the world's axes (a task that reads the position only)."""
    x, y, z = _point(p)
    return np.array(
        [[1.0, 0.0, 0.0, x], [0.0, 1.0, 0.0, y], [0.0, 0.0, 1.0, z], [0.0, 0.0, 0.0, 1.0]]
    )


def _task_pose(p: ArrayLike, d: ArrayLike) -> np.ndarray:
    """A pose with origin p and column TOOL_AXIS along d (the other two columns complete it to
    a right-handed frame: the task does not read them); d None is no direction (ValueError:
    it had been taken as the world's z, a reviewer's attack). Plain floats, and the matrix
    made once at the end: numpy's small-array calls (isfinite, eye, slice assignments) cost
    24 us a call here, four times the compiled ik's own time."""
    x, y, z = _point(p)
    axis = _real(d, "d")
    if axis.shape != (3,) or not all(map(math.isfinite, direction := axis.tolist())):
        raise ValueError(f"d must be 3 finite numbers, got {axis}")
    d0, d1, d2 = direction
    largest = max(abs(d0), abs(d1), abs(d2))
    if not largest > 0.0:
        raise ValueError("d must be a direction: not all 0")
    u = [d0 / largest, d1 / largest, d2 / largest]  # (first: 1e-300 and 1e300 neither
    # underflow nor overflow)
    size = math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2])
    u = [v / size for v in u]
    m0, m1, m2 = abs(u[0]), abs(u[1]), abs(u[2])  # (the first least entry)
    least = 0 if m0 <= m1 and m0 <= m2 else 1 if m1 <= m2 else 2
    a = [(1.0 if k == least else 0.0) - u[least] * u[k] for k in range(3)]
    size = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    a = [v / size for v in a]
    b = [u[1] * a[2] - u[2] * a[1], u[2] * a[0] - u[0] * a[2], u[0] * a[1] - u[1] * a[0]]
    columns = [u, u, u]
    for k, column in enumerate((u, a, b)):  # (a cyclic order keeps the frame right-handed)
        columns[(TOOL_AXIS + k) % 3] = column
    r0, r1, r2 = columns
    return np.array(
        [
            [r0[0], r1[0], r2[0], x],
            [r0[1], r1[1], r2[1], y],
            [r0[2], r1[2], r2[2], z],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
