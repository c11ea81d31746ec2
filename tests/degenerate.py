"""Degenerate poses of any generated solver, constructed on purpose (shared by the suites).

Each check solves with warnings turned into errors and asserts: no NaN, every solution
reproduces the pose within the singular tolerance, and where the pose came from a joint
vector q, q is among the solutions (revolute modulo 2 pi).
"""

from __future__ import annotations

import math
import warnings
from types import ModuleType

import numpy as np

from derive.verify import SINGULAR_TOL, jacobian_nullity, pose_error

PI = math.pi


WORST = {"error": 0.0}


def solve_checked(m: ModuleType, T: np.ndarray, backend: str | None = None) -> np.ndarray:
    """ik(T) and ik_batch (with `backend`) with warnings as errors; asserts no NaN, soundness
    and that the two agree; returns ik's solutions.

    The largest pose error seen is kept in WORST["error"] (rotation rad, position / REACH).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sols = m.ik(T, backend=backend)
        batch, valid = m.ik_batch(T[None], backend=backend)
    rows = batch[0][valid[0]]
    assert not np.isnan(sols).any() and not np.isnan(batch).any()
    for s in list(sols) + list(rows):
        error = max(pose_error(m, s, T))
        WORST["error"] = max(WORST["error"], error)
        assert error <= SINGULAR_TOL, (s, error)
    # at a degenerate pose the scalar and vectorised arithmetic may split a double root
    # differently (by ~sqrt(eps), amplified by the later joints' conditioning: 1.2e-5 rad seen
    # at a singular wrist of a 1 mm arm); each solution of one must be within 1e-4 of the other
    assert all(contains(m, rows, s, 1e-4) for s in sols)
    assert all(contains(m, sols, s, 1e-4) for s in rows)
    return sols


def contains(m: ModuleType, sols: np.ndarray, q: np.ndarray, tol: float = 1e-6) -> bool:
    """q is among sols (revolute joints modulo 2 pi)."""
    revolute = np.array([k == "R" for k in m.JOINT_TYPES])
    for s in sols:
        d = np.abs(s - q)
        d[revolute] = np.abs(np.remainder(d[revolute] + PI, 2 * PI) - PI)
        if d.max() <= tol:
            return True
    return False


def theta_to_q(m: ModuleType, joint: int, theta: float) -> float:
    """The q of a revolute joint (1-based) whose angle theta_i = q_i + offset is theta."""
    return theta - m.DH[joint - 1][3]


def elbow_singularities(m: ModuleType, q: np.ndarray, joint: int) -> list[np.ndarray]:
    """Joint vectors along q with `joint` varied where the Jacobian's sigma_min vanishes.

    Scans the joint over one period and refines each local minimum of sigma_min below 1e-2 by
    golden-section search; returns those that reach sigma_min < 1e-7.
    """
    grid = np.linspace(-PI / 2, 3 * PI / 2, 721) + 0.0037  # 0 and pi are interior points
    sig = []
    for v in grid:
        qq = q.copy()
        qq[joint - 1] = v
        sig.append(jacobian_nullity(m, qq)[0])
    found = []
    for k in range(1, len(grid) - 1):
        if sig[k] <= sig[k - 1] and sig[k] <= sig[k + 1] and sig[k] < 1e-2:
            lo, hi = grid[k - 1], grid[k + 1]
            for _ in range(60):
                m1, m2 = lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo)
                q1, q2 = q.copy(), q.copy()
                q1[joint - 1], q2[joint - 1] = m1, m2
                if jacobian_nullity(m, q1)[0] < jacobian_nullity(m, q2)[0]:
                    hi = m2
                else:
                    lo = m1
            best = q.copy()
            best[joint - 1] = 0.5 * (lo + hi)
            if jacobian_nullity(m, best)[0] < 1e-7:
                found.append(best)
    return found


def run_suite(
    m: ModuleType,
    elbow: int,
    pi_joints: list[int],
    wrist: int | None,
    rng: np.random.Generator,
    backend: str | None = None,
) -> dict:
    """Every degenerate construction for one solver (solved with `backend`); returns counts of
    what was checked."""
    counts = {"wrist": 0, "elbow": 0, "pi": 0, "boundary": 0}
    base = rng.uniform(-2.5, 2.5, m.DOF)
    base[[k for k, t in enumerate(m.JOINT_TYPES) if t == "P"]] = 0.0
    if wrist is not None:
        for theta in (0.0, PI):
            q = base.copy()
            q[wrist - 1] = theta_to_q(m, wrist, theta)
            T = m.fk(q)
            sols = solve_checked(m, T, backend)
            assert len(sols) > 0
            counts["wrist"] += 1
    for joint in pi_joints:
        q = base.copy()
        q[joint - 1] = theta_to_q(m, joint, PI)
        sols = solve_checked(m, m.fk(q), backend)
        assert len(sols) > 0
        if jacobian_nullity(m, q)[0] >= 1e-6:  # at a singular q only the pose must be kept
            assert contains(m, sols, q), (joint, q)
        counts["pi"] += 1
    for q in elbow_singularities(m, base, elbow):
        T = m.fk(q)
        sols = solve_checked(m, T, backend)
        assert len(sols) > 0
        counts["elbow"] += 1
        for axis in range(3):
            for sign in (1.0, -1.0):
                moved = T.copy()
                moved[axis, 3] += sign * 1e-12 * m.REACH
                solve_checked(m, moved, backend)
                counts["boundary"] += 1
    return counts
