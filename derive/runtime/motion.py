"""Velocities: the geometric Jacobian at the tool point and the manipulability measures
(derive/jacobian.py derives the Jacobian from the same factors as fk; it is printed per arm
as _jacobian_q)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from derive.runtime.arm import DOF, _fk_q, _jacobian_q
from derive.runtime.common import _real


def jacobian(q: ArrayLike, frame: str = "base") -> np.ndarray:
    """The geometric Jacobian at q, (6, DOF): rows 0-2 the tool point's linear velocity, rows
    3-5 the tool's angular velocity, per unit of each joint's velocity ([v; w] = J dq; length
    units and radians, as fk's).

    Args:
        q: DOF joint values.
        frame: "base": v and w in the world (fk's frame); "tool": both in the tool frame
            (rotated by fk(q)'s R^T; the point is still the tool point).

    Raises:
        ValueError: q is not DOF finite numbers, or frame is neither "base" nor "tool".
    """
    values = _joint_values(q)
    if frame not in ("base", "tool"):
        raise ValueError(f'frame must be "base" or "tool", got {frame!r}')
    J = np.array(_jacobian_q(values)).reshape(6, DOF)
    if frame == "tool":
        e = _fk_q(values)
        R = np.array([e[0:3], e[4:7], e[8:11]])
        J = np.vstack([R.T @ J[:3], R.T @ J[3:]])
    return J


# ik_velocity's damping: none while the Jacobian's smallest singular value is at least
# VELOCITY_BAND; below it, lambda^2 = VELOCITY_DAMPING^2 (1 - (sigma / VELOCITY_BAND)^2), which
# bounds every joint rate by |twist| / (2 VELOCITY_DAMPING) at a singular configuration
VELOCITY_BAND = 0.05
VELOCITY_DAMPING = 0.05


def ik_velocity(
    q: ArrayLike,
    twist: ArrayLike,
    *,
    frame: str = "base",
    damping: float = VELOCITY_DAMPING,
    band: float = VELOCITY_BAND,
    preferred: ArrayLike | None = None,
    gain: float = 1.0,
) -> np.ndarray:
    """Joint velocities dq that move the tool with the twist [v; w] at q: damped least
    squares on jacobian(q, frame), dq = sum_k sigma_k / (sigma_k^2 + lambda^2) v_k u_k^T twist.

    Away from singular configurations (every singular value at least band) lambda is 0 and
    J dq reproduces the twist (to rounding) where the arm can move that way; within band of one
    the damping grows to damping^2 as the smallest singular value goes to 0, which bounds the
    joint rates (by |twist| / (2 damping)) at the price of the twist's component along the lost
    direction. An arm of fewer than 6 joints gets the least-squares dq.

    Args:
        q: DOF joint values; twist: 6 numbers, v (length units per second) then w (rad/s).
        frame: the twist's frame, as jacobian's.
        damping, band: the damping's size and where it starts (singular values, J's units).
        preferred: joint values to drift toward in the Jacobian's null space (an arm with
            more joints than the twist needs, FREE: its self-motion), gain * (preferred - q)
            projected so that the tool does not move; None: no drift.
        gain: the drift's rate (per second).

    Raises:
        ValueError: q or preferred is not DOF finite numbers, twist not 6, frame unknown,
            damping or band negative, gain not finite.
    """
    J = jacobian(q, frame)
    target = _real(twist, "twist")
    if target.shape != (6,) or not np.isfinite(target).all():
        raise ValueError(f"twist must be 6 finite numbers, got {target}")
    if not (damping >= 0.0 and band >= 0.0 and math.isfinite(damping + band + gain)):
        raise ValueError("damping and band must be finite numbers >= 0, gain finite")
    U, sigma, Vt = np.linalg.svd(J, full_matrices=False)
    least = float(sigma[-1]) if len(sigma) == 6 else math.inf
    lam2 = 0.0
    if least < band:
        lam2 = damping * damping * (1.0 - (least / band) ** 2)
    weights = np.divide(sigma, sigma * sigma + lam2, out=np.zeros_like(sigma), where=sigma > 0)
    dq = Vt.T @ (weights * (U.T @ target))
    if preferred is not None:
        drift = gain * (np.array(_joint_values(preferred)) - np.array(_joint_values(q)))
        rank = int(np.sum(sigma > 1e-12 * max(1.0, float(sigma[0]))))
        rows = Vt[:rank]
        dq = dq + drift - rows.T @ (rows @ drift)  # (the null space's share of the drift)
    return dq


def manipulability(q: ArrayLike) -> tuple[float, float]:
    """How far q is from a singular configuration: (the smallest singular value of
    jacobian(q), Yoshikawa's measure w, the product of its singular values: sqrt(det(J J^T))
    for an arm of 6 joints or more, sqrt(det(J^T J)) for fewer). Both are 0 at a singular
    configuration; J mixes length units and radians, so compare values of one arm.

    Raises:
        ValueError: q is not DOF finite numbers.
    """
    sigma = np.linalg.svd(jacobian(q), compute_uv=False)
    return float(sigma[-1]) if len(sigma) == min(6, DOF) else 0.0, float(np.prod(sigma))


def _joint_values(q: ArrayLike) -> list[float]:
    """q as DOF finite floats."""
    values = _real(q, "q")
    if values.shape != (DOF,):
        raise ValueError(f"q must have shape ({DOF},), got {values.shape}")
    joints = values.tolist()
    if not all(map(math.isfinite, joints)):
        raise ValueError(f"q must be {DOF} finite numbers")
    return joints
