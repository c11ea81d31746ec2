"""Refinement onto the exact arm: the Python solver's Newton steps on the exact chain, for an
arm whose closed form solves a nominal table near its own (derive/nominal.py; the C solver's
are dk_refine in derive/c/runtime.c).

The exact chain is held as fixed frames, T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n (_CHAIN),
J_i a rotation about z (R) or a translation along it (P). A nominal solution q is within the
nominal arm's deviation of an exact one; Newton's steps on the pose error, damped by its
square (Levenberg-Marquardt: quadratic where the Jacobian is regular, still converging where
it is singular), bring it there. The error is the position difference divided by REACH and
the rotation error 1/2 sum_k r_k x t_k (r_k, t_k the columns of the rotations), whose
Jacobian at the solution is the geometric one: J_i = (z_i x (p - o_i) / REACH, z_i) for a
revolute joint, (z_i / REACH, 0) for a prismatic one; only the joints in _SOLVED move (free
joints keep the caller's values).
"""

from __future__ import annotations

import math

import numpy as np

from derive.runtime.arm import _CHAIN, _REVOLUTE, _SOLVED, IK_COMPONENTS, REACH

# the exact chain's frames as 4x4 arrays
_FRAMES = np.array([np.vstack((np.reshape(f, (3, 4)), (0.0, 0.0, 0.0, 1.0))) for f in _CHAIN])
# at most this many steps per candidate (a seed on a singular configuration converges
# linearly); a step longer than _REFINE_STRIDE (radians, or
# REACH of length) is shortened to it, so that a far seed does not jump branches
_REFINE_STEPS = 30
_REFINE_STRIDE = 0.5
# done at this pose error (a few roundings); given up after this many steps in a row that
# do not reduce it; the step from an error within _REFINE_LAST (that reduced it) is the last
_REFINE_DONE = 1e-14
_REFINE_PATIENCE = 3
_REFINE_LAST = 1e-10
# a refined row is returned if its pose error is within the smaller of this and ik's tol
_REFINE_TOL = 1e-10


def _seed(found, t, q, tol):
    """Append q refined onto the exact chain if its pose there reproduces the target t (the
    12 top entries) within tol and _REFINE_TOL (rotation entries; positions within that times
    REACH)."""
    q, size = _refine(q, t)
    if size <= min(tol, _REFINE_TOL):
        found.append(q)


def _refine(q, t):
    """q after Newton's steps towards t on the exact chain, and its pose error there (the
    largest rotation entry's difference, or position difference / REACH)."""
    target = np.array((*t, 0.0, 0.0, 0.0, 1.0)).reshape(4, 4)
    rows = 6 if IK_COMPONENTS == "pose" else 3
    cur = np.array(q, dtype=float)
    best, best_size, worse = cur.copy(), math.inf, 0
    for _ in range(_REFINE_STEPS):
        pose, axes, origins = _chain_pose(cur)
        gap = (target[:3, 3] - pose[:3, 3]) / REACH
        size = float(np.max(np.abs(gap)))
        if rows == 6:
            size = max(size, float(np.max(np.abs(target[:3, :3] - pose[:3, :3]))))
        if size < best_size:
            best, best_size, worse = cur.copy(), size, 0
        else:  # (near a singular configuration the error can grow before it converges)
            worse += 1
        if size <= _REFINE_DONE or worse == _REFINE_PATIENCE:
            break
        last = size <= _REFINE_LAST and worse == 0
        error = np.concatenate((gap, 0.5 * np.cross(pose[:3, :3].T, target[:3, :3].T).sum(0)))
        J = np.zeros((6, len(_SOLVED)))
        for k, i in enumerate(_SOLVED):
            if _REVOLUTE[i]:
                J[:3, k] = np.cross(axes[i], pose[:3, 3] - origins[i]) / REACH
                J[3:, k] = axes[i]
            else:
                J[:3, k] = axes[i] / REACH
        J, error = J[:rows], error[:rows]
        normal = J.T @ J + float(error @ error) * np.eye(len(_SOLVED))
        try:
            step = np.linalg.solve(normal, J.T @ error)
        except np.linalg.LinAlgError:
            break
        longest = float(np.max(np.abs(step)))
        if not longest < math.inf:
            break
        if longest > _REFINE_STRIDE:
            step *= _REFINE_STRIDE / longest
        cur[list(_SOLVED)] += step
        if last:  # (Newton's step from there: the error squared, not measured)
            best = cur
            break
    return tuple(best.tolist()), best_size


def _chain_pose(q):
    """The exact chain's pose at q, with each joint's axis and a point on it (world frame)."""
    pose = _FRAMES[0].copy()
    axes, origins = [], []
    for i, revolute in enumerate(_REVOLUTE):
        axes.append(pose[:3, 2].copy())
        origins.append(pose[:3, 3].copy())
        if revolute:
            c, s = math.cos(q[i]), math.sin(q[i])
            x, y = pose[:, 0].copy(), pose[:, 1]
            pose[:, 0] = c * x + s * y
            pose[:, 1] = c * y - s * x
        else:
            pose[:, 3] += q[i] * pose[:, 2]
        pose = pose @ _FRAMES[i + 1]
    return pose, axes, origins
