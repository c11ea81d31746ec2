"""Velocities: the geometric Jacobian at the tool point and the manipulability measures
(derive/jacobian.py derives the Jacobian from the same factors as fk; it is printed per arm
as _jacobian_q)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from derive.runtime.api import _pose, ik
from derive.runtime.arm import (
    _CHAIN,
    _REVOLUTE,
    BASE,
    BRANCHES,
    DOF,
    FREE,
    IK_COMPONENTS,
    LIMITS,
    REACH,
    _branch_signs,
    _fk_q,
    _jacobian_q,
)
from derive.runtime.common import _joint_values, _real
from derive.runtime.constants import _BRANCH_FOLD
from derive.runtime.refine import _pose_error, _refine


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


def link_transform(q: ArrayLike, k: int) -> np.ndarray:
    """The pose (4, 4) of frame k at q on the arm's exact chain, T(q) = F_0 J_1(q_1) F_1 ...
    J_n(q_n) F_n (_CHAIN; J_i = Rz(q_i), or Tz(q_i) for a sliding joint): k = 0 the base frame
    (BASE), k = 1..DOF the frame of joint k, F_0 J_1 F_1 ... F_{k-1} J_k (its z axis the joint's
    axis, its origin on it: Craig's frame k for a table in modified DH), k = DOF + 1 the tool's
    (fk(q)). A kinematics plugin's link transform (the C header's table).

    Raises:
        ValueError: q is not DOF finite numbers, or k is not an integer in 0..DOF + 1.
    """
    values = _joint_values(q)
    if not isinstance(k, (int, np.integer)) or isinstance(k, bool) or not 0 <= k <= DOF + 1:
        raise ValueError(f"k must be an integer from 0 to {DOF + 1}, got {k!r}")
    if k == 0:
        return np.array(BASE, dtype=float)
    pose = np.vstack([np.array(_CHAIN[0]).reshape(3, 4), (0.0, 0.0, 0.0, 1.0)])
    for i in range(min(k, DOF)):
        joint = np.eye(4)
        if _REVOLUTE[i]:
            c, s = math.cos(values[i]), math.sin(values[i])
            joint[:2, :2] = ((c, -s), (s, c))
        else:
            joint[2, 3] = values[i]
        pose = pose @ joint
        if i + 1 < k:
            pose = pose @ np.vstack([np.array(_CHAIN[i + 1]).reshape(3, 4), (0, 0, 0, 1.0)])
    return pose


# ik_velocity's damping: none while the Jacobian's smallest singular value is at least
# VELOCITY_BAND; below it, lambda^2 = VELOCITY_DAMPING^2 (1 - (sigma / VELOCITY_BAND)^2), which
# bounds every joint rate by |twist| / (2 VELOCITY_DAMPING) at a singular configuration and,
# VELOCITY_DAMPING being VELOCITY_BAND, by |twist| / VELOCITY_BAND anywhere
VELOCITY_BAND = 0.05
VELOCITY_DAMPING = 0.05
# the drift of ik_velocity stays off the directions whose singular values exceed _RANK_TOL
# times the largest (at least 1): the C ik_velocity's singular values once came from J^T J's
# eigenvalues, which carry about 1e-16 of the largest's square (now from J's own, by one-sided
# Jacobi rotations; the threshold stays, so that the two agree where it decides)
_RANK_TOL = 1e-7


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
    joint rates (by |twist| / (2 damping) at a singular configuration, by |twist| / band
    anywhere where damping >= band, as the defaults) at the price of the twist's component
    along the lost direction. An arm of fewer than 6 joints gets the least-squares dq of the
    whole twist (a direction arm cannot follow a roll about its tool axis, a position arm any
    rotation: give a twist its task can follow, and read J dq for what it does).

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
    least = float(sigma[-1])
    lam2 = 0.0
    if least < band:
        lam2 = damping * damping * (1.0 - (least / band) ** 2)
    weights = np.divide(sigma, sigma * sigma + lam2, out=np.zeros_like(sigma), where=sigma > 0)
    dq = Vt.T @ (weights * (U.T @ target))
    if preferred is not None:
        try:
            wanted = _joint_values(preferred)
        except ValueError as exc:  # (named as the argument it is)
            raise ValueError(str(exc).replace("q must", "preferred must", 1)) from None
        drift = gain * (np.array(wanted) - np.array(_joint_values(q)))
        rank = int(np.sum(sigma > _RANK_TOL * max(1.0, float(sigma[0]))))
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
    J = jacobian(q)
    return _least_sigma(J), float(np.prod(np.linalg.svd(J, compute_uv=False)))


def _least_sigma(J: np.ndarray) -> float:
    """The smallest of the min(6, columns) singular values of the 6-row J."""
    sigma = np.linalg.svd(J, compute_uv=False)
    return float(sigma[-1]) if len(sigma) == min(6, J.shape[1]) else 0.0


def branch(q: ArrayLike) -> tuple[int, ...]:
    """The branch of the solution q of its own pose: one sign per step of the closed form that
    gives several values (BRANCHES names their joints, in the order they are solved), +1 or
    -1, 0 where that step's values meet (a fold: a singular configuration, as the elbow
    stretched or the wrist straight). Each is the sign of the derivative of the step's
    equation in its joint's value (a cos t + b sin t = e: +1 for the + acos value); it changes
    only where a path of solutions crosses a fold, so it names the configuration (shoulder,
    elbow, wrist) whatever the distances between solutions; "virtual" in BRANCHES is the
    task's own value (the axis-angle task's tilt). Where the derivation has no such steps
    (the general method), an arm solved for the pose with six joints not free has one label,
    the sign of det J over them (BRANCHES == ("det J",)): it too changes only where a path
    crosses a singular configuration, but two solutions can share it. () where neither
    applies (a look-at: its distance along the ray is the point's, not q's).

    Raises:
        ValueError: q is not DOF finite numbers.
    """
    q = _joint_values(q)
    if not BRANCHES:
        return ()
    e = _fk_q(q)
    return tuple(_branch_signs(tuple(e), q))


def _jacobian_sign(q):
    """The sign of det J over the joints the pose fixes (jacobian(q)'s columns but FREE's),
    where the closed form names no branch (BRANCHES == ("det J",): the general method): +1 or
    -1, 0 where |det J| is within _BRANCH_FOLD of the product of its columns' lengths (its
    largest value, Hadamard's bound): a singular configuration, where two branches meet."""
    J = np.array(_jacobian_q(q)).reshape(6, DOF)
    J = J[:, [j for j in range(DOF) if j + 1 not in FREE]]
    det = float(np.linalg.det(J))
    if abs(det) <= _BRANCH_FOLD * float(np.prod(np.linalg.norm(J, axis=0))):
        return 0
    return 1 if det > 0.0 else -1


# ik_path: the continuation of a path from q to the next pose is Newton's iteration from q
# (at most PATH_NEWTON steps of q += J^+ dX, until the pose error is within PATH_CONVERGED);
# the solution nearest it continues the path if they agree within PATH_SLACK (radians, or
# PATH_SLACK * REACH for a sliding joint) and its step is within PATH_GAIN times |dX| /
# sigma_min (the pose step over the Jacobian's smallest singular value at q)
PATH_NEWTON = 12
PATH_CONVERGED = 1e-10
PATH_GAIN = 3.0
# where a pose has no row with the free joints' values of a path, it is tried at this many
# values of each over its limits before it is called out of reach (_unreached)
PATH_FREE_SAMPLES = 16
PATH_SLACK = 1e-6
# ... or within PATH_GAIN PATH_CONVERGED / sigma_min, at most PATH_SLACK_MOST: how far apart
# two points within PATH_CONVERGED of the pose can be there (an iiwa14's shoulder at sigma_min
# 3e-7: Newton's point and the row 5.7e-5 apart, and the path broke, a new user's attack)
PATH_SLACK_MOST = 1e-2
# ... and, within PATH_SLACK_MOST, if the points between them reach the pose within this too
# (one valley of solutions near a singular configuration: _joined)
PATH_JOINED = 1e-9
# ... and q0 must reach Ts[0] within this (its pose error, as ik's certification measures it);
# a step whose finest part (_follow's halves) moves more than PATH_JUMP (radians, or REACH)
# where sigma_min is below PATH_SINGULAR is a break: the first-order bound allows any step
# there, and which way the path goes depends on how finely it is sampled
PATH_START_TOL = 1e-6
PATH_SINGULAR = 1e-3
PATH_JUMP = 0.5
# the row on the last row's branch continues the path where its step is within PATH_NEAR
# (radians, or REACH) or PATH_GAIN times the nearest row's (near a fold, the other branch's
# row can be the nearer one by more than PATH_GAIN: measured on open_manipulator_x)
PATH_NEAR = 0.25
# ... and a step whose row moves a joint more than PATH_NEAR, or changes branch, is taken in
# halves, at most this many times (2^10 = 1,024 parts; _follow)
PATH_SPLITS = 10
# ... and so is a step within which a fold may lie (_fold_within): sigma_min^2, which falls
# linearly in the distance to a fold near one, reaches 0 within PATH_FOLD_AHEAD steps from
# either end at its rate there along the first-order joint step (h = PATH_FOLD_PROBE steps)
PATH_FOLD_AHEAD = 1.0
PATH_FOLD_PROBE = 1e-4
# ... where sigma_min is above this part of the largest singular value, and in at most
# PATH_FOLD_SPLITS halvings (64 parts)
PATH_FOLD_FLOOR = 1e-4
PATH_FOLD_SPLITS = 6


def ik_path(
    Ts: ArrayLike,
    q0: ArrayLike,
    *,
    within_limits: bool = False,
    on_break: str = "stop",
    backend: str | None = None,
) -> tuple[np.ndarray, list[tuple[int, str]]]:
    """One joint vector per pose of a path, each continuing the previous one: the closed-form
    solution of pose k on q_{k-1}'s branch (branch) nearest q_{k-1}, where its step is within
    PATH_NEAR or PATH_GAIN times the nearest solution's; else the one that Newton's iteration
    from q_{k-1} reaches (q += J^+ dX, dX the pose error as a twist: a path crossing a fold,
    the wrist turning through straight). Either is accepted only within PATH_GAIN |dX| /
    sigma_min + PATH_SLACK of q_{k-1} (the joint step a continuous branch can take;
    sigma_min the Jacobian's smallest singular value). The free joints of an arm with free
    joints (FREE) follow Newton's iteration. An arm solved for a task (IK_COMPONENTS) takes
    Newton's steps on the task's components only (the poses' other components need not be
    reachable), its free joints kept.

    Where no solution continues the path (a singular crossing where the branch ends, a joint
    limit with within_limits, a pose out of reach, or the straight line to it leaving the
    branch's workspace between the poses), the break is reported: (k, why) in the
    returned list, and the path stops there (rows k.. NaN) or, with on_break="flag", goes on
    from the nearest solution.

    Args:
        Ts: the poses, (N, 4, 4); Ts[0] is q0's pose (q0 is its row, as given).
        q0: the starting joint vector.
        within_limits: only solutions inside LIMITS continue the path.
        on_break: "stop" or "flag".
        backend: as ik's.

    Returns:
        (Q (N, DOF), breaks): the path's joint vectors and its breaks, in order.

    Raises:
        ValueError: Ts is not (N, 4, 4) with N >= 1, q0 not DOF finite numbers or not
            reaching Ts[0] within PATH_START_TOL, on_break unknown; ik's errors for a pose.
    """
    poses = np.asarray(Ts, dtype=float)
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or len(poses) == 0:
        raise ValueError(f"Ts must have shape (N, 4, 4), N >= 1, got {poses.shape}")
    if on_break not in ("stop", "flag"):
        raise ValueError(f'on_break must be "stop" or "flag", got {on_break!r}')
    if backend not in (None, "auto", "c", "python"):  # (a one-pose path calls no ik)
        raise ValueError(f"backend must be 'auto', 'c' or 'python', got {backend!r}")
    q = np.array(_joint_values(q0))
    if IK_COMPONENTS == "pose":
        size = _pose_error_to(q, poses[0])[1]
    else:
        size = _pose_error(q.tolist(), poses[0][:3].ravel().tolist(), False)[2]
    if not size <= PATH_START_TOL:
        raise ValueError(
            f"q0 does not reach Ts[0] (pose error {size:.3g}, rotation entries and position "
            f"/ REACH; at most {PATH_START_TOL:g})"
        )
    out = np.full((len(poses), DOF), np.nan)
    out[0] = q
    breaks: list[tuple[int, str]] = []
    for k in range(1, len(poses)):
        row, why, least, _ = _follow(poses[k - 1], poses[k], q, within_limits, backend, 0)
        if why:
            breaks.append((k, f"pose {k}: {why}; sigma_min {least:.3g}"))
            if on_break == "stop":
                return out, breaks
            if row is None:  # (no solution: the path goes on from the last row)
                continue
        out[k] = row
        q = row
    return out, breaks


def _step_bound(q, A, B):
    """The joint step a continuous branch can take from q (a solution of the pose A) to the
    pose B: PATH_GAIN |dX| / sigma_min, dX the pose step (an arm solved for a task: its
    components' error at B), sigma_min the smallest singular value of the Jacobian at q
    (of the task's; of the joints ik solves, not the free ones); and sigma_min. An arm of
    fewer than six joints solved for the pose (a planar arm) has as many singular values as
    joints, and its least is the bound's too (it was taken as 1: a lecture_rrr line at
    sigma_min 0.18 broke where its branch went on, 12 of 100 random lines, a new user's
    attack)."""
    if IK_COMPONENTS == "pose":
        change = float(np.linalg.norm(_pose_step(A, B)))
    else:  # (the task's components: what the task's rows follow)
        change = float(np.linalg.norm(_pose_error(q.tolist(), B[:3].ravel().tolist(), False)[0]))
    least = _path_sigma(q, B)
    return PATH_GAIN * change / max(least, 1e-300), least


def _path_sigma(q, B):
    """sigma_min at q of the Jacobian a path follows towards the pose B: of the joints ik
    solves (the free ones take the values Newton's iteration gives them, so near a singular
    configuration of the others, as an iiwa14's shoulder with axes 1 and 3 nearly aligned,
    those turn fast though the whole arm's sigma_min is not small: the bound of the whole
    arm's broke such lines, or took the shoulder's partner row (q1 + pi, -q2, q3 + pi) with
    no break, a new user's attack: 8 of 40 iiwa14 lines); of the task's components' for an
    arm solved for a task."""
    if IK_COMPONENTS == "pose":
        return _least_sigma(jacobian(q)[:, [i for i in range(DOF) if i + 1 not in FREE]])
    columns = _pose_error(q.tolist(), B[:3].ravel().tolist(), False)[1]
    return float(np.linalg.svd(np.array(columns).T, compute_uv=False)[-1])


def _fold_within(q, B, least):
    """Whether a fold (sigma_min 0, where q's branch can end) may lie within the step from q
    towards the pose B: sigma_min^2 (of _step_bound's Jacobian) reaches 0 within
    PATH_FOLD_AHEAD steps at its rate at q along the first-order joint step (Newton's, the
    pose error over J^+; least, sigma_min at q where known). Near a fold sigma_min^2 falls
    linearly in the pose's distance to it, so the step's halves (_follow) meet it. Not where
    sigma_min is within PATH_FOLD_FLOOR of the largest: there q lies on a singular set, and
    the rate says nothing (an iiwa14 line along its solved joints' singular set, sigma_min
    5e-6, was taken in 1,024 parts a step, 40 times as slow, a new user's attack)."""
    if IK_COMPONENTS == "pose":  # (J^+ from J's singular value decomposition, which gives
        # sigma_min too where no joint is free)
        J = jacobian(q)
        u, values, vt = np.linalg.svd(J, full_matrices=False)
        kept = values > 1e-9 * values[0]
        step = vt[kept].T @ ((u[:, kept].T @ _pose_error_to(q, B)[0]) / values[kept])
        if least is None:
            least = float(values[-1]) if not FREE else _path_sigma(q, B)
        J[:3] /= REACH  # (the floor's singular values: lengths in units of the arm's size)
        solved = [i for i in range(DOF) if i + 1 not in FREE]
        values = np.linalg.svd(J[:, solved], compute_uv=False)
    else:
        error, columns, _ = _pose_error(q.tolist(), B[:3].ravel().tolist(), False)
        values = np.linalg.svd(np.array(columns).T, compute_uv=False)
        step = np.zeros(DOF)
        solved = [i for i in range(DOF) if i + 1 not in FREE]
        step[solved] = np.linalg.lstsq(np.array(columns).T, np.array(error), rcond=1e-9)[0]
        if least is None:
            least = float(values[-1])
    if float(values[-1]) <= PATH_FOLD_FLOOR * float(values[0]):
        return False
    probe = _path_sigma(q + PATH_FOLD_PROBE * step, B)
    rate = (probe * probe - least * least) / PATH_FOLD_PROBE
    return rate < 0.0 and least * least < -rate * PATH_FOLD_AHEAD


def _follow(A, B, q, within_limits, backend, depth):
    """ik_path's step from q (a solution of the pose A) to the pose B: _continuation, but
    where its row moves a joint by more than PATH_NEAR (radians, or REACH), finds no
    continuation or changes branch, the step in halves (straight_line's middle pose), up to
    PATH_SPLITS times:
    near a singular configuration a branch turns fast (the wrist centre passing near axis 1
    turned a KR 10's q1 by 1.6 rad in one of 20 steps, sigma_min 4e-3), and the other
    shoulder's row, nearer by joint distance, was taken with no break reported (a new user's
    attack); a straight line passing 0.003 rad from a KR 10's wrist singularity took the
    partner (q4 + pi, -q5, q6 + pi), 0.15 rad away, where q's branch turns q4 and q6 by pi
    within the step (a second attack). A jumping step whose first half finds no continuation
    is a break: the branch
    ends within it (a GP7's elbow line jumped 3.1 rad so, onto another branch, with no break).
    A step one of whose finest parts (the step itself where it was not split) still moves a
    joint more than PATH_JUMP, where sigma_min at the part's start is below PATH_SINGULAR, is
    a break: the first-order bound allows any step there, and which way the path goes depends
    on how finely it is sampled; a step whose parts all move less is a branch followed
    closely enough, however fast it turns. Returns (row, why) as _continuation, the least
    sigma_min at the starts of the step and its parts, and (jump, sigma_min, joint) of the
    part that moves a joint most."""
    bound, least = _step_bound(q, A, B)
    row, why = _continuation(B, q, branch(q), bound, least, within_limits, backend)
    if row is None and FREE and depth < PATH_SPLITS:  # (the free joints took values at
        # which the pose has no solution: Newton's iteration over a long step can wander so,
        # where shorter steps keep them on the path; a panda line broke so at 7 poses and not
        # at 20, a new user's attack)
        whole = _halves(A, B, q, least, within_limits, backend, depth)[1]
        if whole is not None:
            return whole[0], _jumped(whole[1], whole[3], depth), whole[2], whole[3]
    if row is None or "limits" in why:
        return row, why, least, (0.0, least, 0)
    revolute = np.array(_REVOLUTE)
    units = np.where(revolute, 1.0, REACH)
    jump = np.abs(_turned(row - q, revolute)) / units
    worst = (float(jump.max()), least, int(np.argmax(jump)))
    label = branch(q)
    switched = bool(label) and not _same_branch(branch(row), label)
    suspect = worst[0] > PATH_NEAR or switched
    if depth < PATH_FOLD_SPLITS and not why and not suspect:  # (a branch can leave the workspace
        # and come back within one step, its rows at both ends near each other: a youbot line
        # of 7 poses went on where the branch has no row for 4% of a step, a parallel_6r line
        # where it has none for most of one, a new user's attack)
        suspect = _fold_within(q, B, least) or _fold_within(row, A, None)
    if depth < PATH_SPLITS and (why or suspect):
        (half, first, least_first, _), whole = _halves(
            A, B, q, least, within_limits, backend, depth
        )
        if (half is None or first) and not why and suspect:  # (the branch ends within the
            # step, at a fold where q's branch meets another, and the row is another
            # branch's: a jump, or a row 0.087 rad away of the other sign of det J, the
            # fold's partner, where a 100,000 times finer walk ends 0.29 into the step with
            # the nearest solution 0.6 rad away, a new user's Alicia D line; or the same
            # branch's, where the branch comes back)
            why = first or "out of reach"
            if why.startswith("out of reach") and "part way" not in why:  # (the line leaves the
                # workspace inside the step: its end may be reached, by other branches too; a
                # new user's youbot lines said "pose k: out of reach" at poses with 4 rows)
                why = "out of reach part way through the step" + why[len("out of reach") :]
            least = min(least, least_first)
        elif whole is not None:
            row, why, least, worst = whole  # (the parts' own starts' least sigma_min)
    return row, _jumped(why, worst, depth), least, worst


def _halves(A, B, q, least, within_limits, backend, depth):
    """The step from q (a solution of A) to B in two halves (straight_line's middle pose):
    _follow's result for the first, and the whole step's (row, why, least sigma_min of least
    and the parts', the worst part) through both where the first continues the path and the
    second finds a row, else None."""
    middle = straight_line(A, B, 3)[1]
    first = _follow(A, middle, q, within_limits, backend, depth + 1)
    half, why_first, least_first, worst_first = first
    if half is None or why_first:
        return first, None
    split, why_split, least_split, worst_split = _follow(
        middle, B, half, within_limits, backend, depth + 1
    )
    if split is None:
        return first, None
    least = min(least, least_first, least_split)
    return first, (split, why_split, least, max(worst_first, worst_split))


def _jumped(why, worst, depth):
    """why, or, for a whole step (depth 0) that continues, why not where its finest part
    that moves a joint most, by more than PATH_JUMP, starts below PATH_SINGULAR."""
    if not why and depth == 0 and worst[1] < PATH_SINGULAR and worst[0] > PATH_JUMP:
        return (
            f"q{worst[2] + 1} jumps by {worst[0]:.3g} at a singular configuration (the path "
            "passes one; where it goes from there the poses do not say)"
        )
    return why


def _continuation(T, q, label, bound, least, within_limits, backend):
    """ik_path's step from q (on the branch label) to the pose T: the solution of T nearest
    Newton's iteration from q (its revolute joints' turn nearest it), and "" if it continues
    the path, else why not (the row None where T has no solution). Before it, the solution
    on q's own branch nearest q continues the path if its step is within the bound and
    within PATH_NEAR or PATH_GAIN times the nearest solution's: near a fold (the elbow nearly
    stretched) both branches lie within one step, and Newton's iteration may cross to the
    other. (Not where the branch is det J's sign: _follow halves a step that changes it.)
    least, sigma_min at q, sets how far Newton's point and the row may differ (PATH_SLACK,
    PATH_SLACK_MOST)."""
    revolute = np.array(_REVOLUTE)
    units = np.where(revolute, 1.0, REACH)
    guess = np.array(q, dtype=float)
    if IK_COMPONENTS == "pose":
        guess, size = _newton_to(guess, T)
    else:  # (a task arm: Newton's steps on the task's components, the free joints kept)
        moved, size = _refine(guess.tolist(), T[:3].ravel().tolist())
        guess = np.array(moved)
    converged = size <= PATH_CONVERGED
    slack = min(max(PATH_SLACK, PATH_GAIN * PATH_CONVERGED / max(least, 1e-300)), PATH_SLACK_MOST)
    free = [guess[j - 1] for j in FREE] if FREE else None
    rows = ik(T, free=free, q_ref=guess, backend=backend)
    if len(rows) == 0 and converged:  # (Newton's iteration reached a solution that the
        # closed form, at a singular configuration of the joints it solves, did not give)
        rows = guess[None]
    if len(rows) == 0:
        return None, _unreached(T, guess, backend)
    gaps = _turned(rows - guess, revolute)
    misses = np.abs(gaps / units).max(axis=1)
    best = int(np.argmin(misses))
    if label and BRANCHES != ("det J",):  # (det J's sign is no branch of its own: two
        # solutions share it, and a path crosses det J = 0 smoothly where it touches a fold;
        # a manocha_canny line took another solution of q's sign 0.55 rad away, where a 1,520
        # times finer walk steps 1e-5 rad, and broke: _follow halves a step whose sign changes)
        # (the row of q's branch nearest q continues it if its step is within the
        # bound and within PATH_NEAR or PATH_GAIN times the nearest row's: else the path
        # crosses a fold, as the wrist turning through straight, where the row of q's branch
        # turns joints 4 and 6 by half a turn)
        moves = _turned(rows - q, revolute)
        sizes = np.abs(moves / units).max(axis=1)
        same = [i for i, r in enumerate(rows) if _same_branch(branch(r), label)]
        if same:
            kept = min(same, key=lambda i: sizes[i])
            reach = max(PATH_GAIN * sizes.min(), PATH_NEAR)  # (how far q's branch may be)
            if sizes[kept] <= min(bound, reach) + slack:
                return _within(q + moves[kept], within_limits)
    row = guess + gaps[best]
    move = _turned(row - q, revolute)  # (Newton's iteration may have wandered whole turns)
    row = q + move
    step = np.abs(move) / units
    j = int(np.argmax(step))
    joined = misses[best] <= slack or (
        misses[best] <= PATH_SLACK_MOST and _joined(guess, guess + gaps[best], T)
    )
    if not converged or not joined or step.max() > bound + slack:
        return row, (
            "no solution continues the path ("
            + ("Newton's iteration from the last row does not converge"
               if not converged else f"the nearest moves q{j + 1} by {step[j]:.3g}")
            + ": a singular crossing where the branch ends, or another branch)"
        )  # fmt: skip
    return _within(row, within_limits)


def _joined(a, b, T):
    """Whether the joint vectors a and b, both solutions of the pose T, lie on one valley of
    solutions: the points between them reach T within PATH_JOINED too. Near a singular
    configuration Newton's steps wander along the direction J barely moves (a panda with its
    elbow 4e-3 from straight, axes 3 and 5 nearly one: Newton's point and the row 1.5e-3 rad
    apart in q3 and q5, both within 3e-11 of the pose, every point between within 2e-11;
    the path broke there, a new user's attack); two solutions of a fold, as far apart, are
    not joined (the pose error between them grows as the square of their distance)."""
    return all(_pose_error_to(a + s * (b - a), T)[1] <= PATH_JOINED for s in (0.25, 0.5, 0.75))


def _unreached(T, guess, backend):
    """Why the pose T has no row continuing a path: out of reach, or, on an arm with free
    joints, no solution with the values Newton's iteration gave them while other values of
    them reach T (PATH_FREE_SAMPLES each over its limits; a panda line 7e-4 from a singular
    configuration broke as "out of reach" at a pose ik solves with other values of q7, a new
    user's attack)."""
    if not FREE:
        return "out of reach"
    held = ", ".join(f"q{j} = {guess[j - 1]:.6g}" for j in FREE)
    grids = []
    for j in FREE:
        lo, hi = (float(v) for v in LIMITS[j - 1])
        if _REVOLUTE[j - 1]:
            lo, hi = max(lo, -math.pi), min(hi, math.pi)
        grids.append(np.linspace(lo, hi, PATH_FREE_SAMPLES))
    for values in np.stack(np.meshgrid(*grids), axis=-1).reshape(-1, len(FREE)):
        if len(ik(T, free=list(values), backend=backend)):
            return (
                f"no solution with {held}, the free joints' values Newton's iteration from "
                "the last row reached (the pose has solutions with other values: a singular "
                "crossing where the branch ends)"
            )
    return f"out of reach (with {held} and at {PATH_FREE_SAMPLES} values of each free joint)"


def _turned(d: np.ndarray, revolute: np.ndarray) -> np.ndarray:
    """Joint differences d (..., DOF), the revolute ones by the turn nearest 0 (in [-pi, pi))."""
    d = d.copy()
    d[..., revolute] = np.remainder(d[..., revolute] + math.pi, 2 * math.pi) - math.pi
    return d


def _within(row, within_limits):
    """The continuing row, and why it does not continue a path kept within the limits."""
    if within_limits:
        lo, hi = np.array(LIMITS).T
        outside = [f"q{i + 1}" for i in range(DOF) if not lo[i] <= row[i] <= hi[i]]
        if outside:
            return row, f"the continuing solution leaves the limits ({', '.join(outside)})"
    return row, ""


def _same_branch(a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    """Whether two branches agree on every step where neither is at a fold (0)."""
    return all(x == y or not x or not y for x, y in zip(a, b))


def _newton_to(guess: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, float]:
    """At most PATH_NEWTON steps of q += J^+ dX from guess towards the pose T (each halved
    until the error shrinks: a full step can overshoot), and the pose error reached."""
    error, size = _pose_error_to(guess, T)
    for _ in range(PATH_NEWTON):
        if size <= PATH_CONVERGED:
            break
        step = np.linalg.pinv(jacobian(guess), rcond=1e-9) @ error
        for _ in range(8):
            trial = guess + step
            trial_error, trial_size = _pose_error_to(trial, T)
            if trial_size < size:
                break
            step = step / 2.0
        else:
            break
        guess, error, size = trial, trial_error, trial_size
    return guess, size


def _pose_error_to(q: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, float]:
    """The twist from fk(q) to T (_pose_step) and its size: the largest position entry over
    REACH or rotation entry."""
    e = _fk_q(q.tolist())
    error = _pose_step(np.array([e[0:4], e[4:8], e[8:12], (0.0, 0.0, 0.0, 1.0)]), T)
    return error, max(float(np.abs(error[:3]).max()) / REACH, float(np.abs(error[3:]).max()))


def _pose_step(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The twist that moves pose A to pose B in one unit of time, to first order: the
    position difference over the rotation vector of B_R A_R^T (in the world)."""
    R = B[:3, :3] @ A[:3, :3].T
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / 2.0
    s = float(np.linalg.norm(w))
    c = (float(np.trace(R)) - 1.0) / 2.0
    angle = math.atan2(s, c)
    axis = w / s if s > 0.0 else w
    if s < 1e-6 and c < 0.0:  # (near a half turn w vanishes: the axis from R's symmetric
        # part, (R + R^T) / 2 = cos I + (1 - cos) a a^T, its sign w's)
        outer = ((R + R.T) / 2.0 - c * np.eye(3)) / (1.0 - c)
        column = outer[:, int(np.argmax(np.diag(outer)))]
        axis = column / float(np.linalg.norm(column))
        if float(axis @ w) < 0.0:
            axis = -axis
    return np.concatenate([B[:3, 3] - A[:3, 3], axis * angle])


def straight_line(A: ArrayLike, B: ArrayLike, n: int) -> np.ndarray:
    """n poses from A to B (both included): the position along the straight line, the
    rotation turning about one fixed axis at a constant rate (slerp), (n, 4, 4).

    Raises:
        ValueError: A or B is not a 4x4 rigid transform, or n < 2.
    """
    if type(n) is bool or not isinstance(n, (int, np.integer)) or n < 2:
        raise ValueError(f"n must be an integer >= 2, got {n!r}")
    ends = []
    for T in (A, B):
        try:
            _pose(T)
        except ValueError as error:
            raise ValueError(f"A and B must be rigid 4x4 transforms: {error}") from None
        ends.append(np.asarray(T, dtype=float))
    twist = _pose_step(ends[0], ends[1])
    angle = float(np.linalg.norm(twist[3:]))
    axis = twist[3:] / angle if angle > 0.0 else np.zeros(3)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    out = np.zeros((n, 4, 4))
    for k, t in enumerate(np.linspace(0.0, 1.0, n)):
        turn = np.eye(3) + math.sin(t * angle) * K + (1.0 - math.cos(t * angle)) * (K @ K)
        out[k, :3, :3] = turn @ ends[0][:3, :3]
        out[k, :3, 3] = ends[0][:3, 3] + t * twist[:3]
        out[k, 3, 3] = 1.0
    return out
