"""Round-trip verification of a generated solver against its forward kinematics.

Used by the tests and by benchmark scripts. A round trip draws joint vectors q (a share of
joints at the degenerate values 0, +-pi/2, pi), computes T = fk(q), solves ik(T) and measures

* soundness: every returned solution reproduces T (rotation error in radians, position error
  relative to the arm's REACH);
* completeness: q is among the solutions (revolute joints modulo 2 pi, DEDUP tolerance).

A sample is *singular* when the smallest singular value of the normalised Jacobian at q is below
SINGULAR_SIGMA. There the pose leaves some joints free and soundness is held to the looser
SINGULAR_TOL. Two completeness figures are kept: *strict*, a solution that reproduces the pose
and equals q on the joints outside the Jacobian's null space (at a Pieper wrist singularity:
theta1..theta3 and theta5, so theta4 +- theta6 is what differs); and *pose kept*, at least one
solution that reproduces the pose. The strict figure assumes a straight self-motion; where the
self-motion is curved (a UR wrist singularity moves the elbow too) only the second applies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import ModuleType

import numpy as np

SOUND_TOL = 1e-9
SINGULAR_TOL = 1e-6
SINGULAR_SIGMA = 1e-6
MATCH_TOL = 1e-6
DEGENERATE_VALUES = (0.0, math.pi / 2, -math.pi / 2, math.pi)


@dataclass
class RoundTrip:
    """Figures of one round-trip run.

    Attributes:
        samples: number of joint vectors drawn.
        singular: how many of them were singular.
        solutions: total number of solutions returned.
        worst_rot: largest rotation error of a solution at a non-singular sample (rad).
        worst_pos: largest position error / REACH at a non-singular sample.
        worst_singular: largest error (either kind) at a singular sample.
        unsound: samples with a solution above tolerance.
        found: non-singular samples whose q was among the solutions.
        singular_found: singular samples covered strictly (module docstring).
        singular_posed: singular samples with at least one solution reproducing the pose.
        misses: indices of non-singular samples whose q was not found.
        counts: number of solutions -> number of samples.
    """

    samples: int = 0
    singular: int = 0
    solutions: int = 0
    worst_rot: float = 0.0
    worst_pos: float = 0.0
    worst_singular: float = 0.0
    unsound: list[int] = field(default_factory=list)
    found: int = 0
    singular_found: int = 0
    singular_posed: int = 0
    misses: list[int] = field(default_factory=list)
    counts: dict[int, int] = field(default_factory=dict)

    @property
    def completeness(self) -> float:
        """Share of non-singular samples whose q was found."""
        regular = self.samples - self.singular
        return self.found / regular if regular else 1.0

    def summary(self) -> str:
        """One line with every figure."""
        counts = ", ".join(f"{k}: {v}" for k, v in sorted(self.counts.items()))
        return (
            f"{self.samples} samples ({self.singular} singular): completeness "
            f"{self.found}/{self.samples - self.singular} = {100 * self.completeness:.3f}%, "
            f"singular: strict {self.singular_found}/{self.singular}, pose kept "
            f"{self.singular_posed}/{self.singular}; unsound {len(self.unsound)}; "
            f"worst rot {self.worst_rot:.1e} rad, pos {self.worst_pos:.1e} x reach, "
            f"singular {self.worst_singular:.1e}; solution counts {{{counts}}}"
        )


def sample_joints(
    module: ModuleType, n: int, rng: np.random.Generator, degenerate_share: float = 0.2
) -> np.ndarray:
    """n joint vectors: revolute uniform in (-pi, pi], prismatic within limits (or +-REACH)."""
    revolute = np.array([k == "R" for k in module.JOINT_TYPES])
    Q = np.empty((n, module.DOF))
    for j, (lo, hi) in enumerate(module.LIMITS):
        if revolute[j]:
            Q[:, j] = rng.uniform(-math.pi, math.pi, n)
        else:
            lo = lo if math.isfinite(lo) else -module.REACH
            hi = hi if math.isfinite(hi) else module.REACH
            Q[:, j] = rng.uniform(lo, hi, n)
    special = rng.random((n, module.DOF)) < degenerate_share
    picks = rng.choice(DEGENERATE_VALUES, size=(n, module.DOF))
    Q[special & revolute] = picks[special & revolute]
    return Q


def pose_error(module: ModuleType, q: np.ndarray, T: np.ndarray) -> tuple[float, float]:
    """(rotation error in rad, position error / REACH) of fk(q) against T, on the components
    the solver's task reads (derive/tasks.py): all of them; the position only (rotation error
    0); the position and the tool axis TOOL_AXIS ("direction"); the distance of T's point from
    the ray of the tool axis, infinite behind the tool ("lookat", rotation error 0); the tool
    axis only ("pointing", position error 0); the position and the tool axis's component along
    the base axis CONE_AXIS ("axisangle").
    """
    P = module.fk(q)
    task = module.IK_COMPONENTS
    axis = getattr(module, "TOOL_AXIS", 2)
    if task == "axisangle":
        cone = module.CONE_AXIS
        rot = abs(float(P[cone, axis] - T[cone, axis]))
        return rot, float(np.abs(P[:3, 3] - T[:3, 3]).max()) / module.REACH
    if task == "lookat":
        v = T[:3, 3] - P[:3, 3]
        along = float(v @ P[:3, axis])
        gap = float(np.abs(v - along * P[:3, axis]).max()) if along >= 0.0 else math.inf
        return 0.0, gap / module.REACH
    rot = float(np.abs(P[:3, :3] - T[:3, :3]).max())
    if task == "position":
        rot = 0.0
    elif task in ("direction", "pointing"):
        rot = float(np.abs(P[:3, axis] - T[:3, axis]).max())
    if task == "pointing":
        return rot, 0.0
    pos = float(np.abs(P[:3, 3] - T[:3, 3]).max()) / module.REACH
    return rot, pos


def targets(module: ModuleType, Q: np.ndarray) -> np.ndarray:
    """The poses whose task the joint vectors Q (n, DOF) solve: fk_batch, with a look-at's
    point one REACH ahead on the tool axis (the tool point itself lies on every ray)."""
    T = module.fk_batch(Q)
    if module.IK_COMPONENTS == "lookat":
        T[:, :3, 3] += module.REACH * T[:, :3, getattr(module, "TOOL_AXIS", 2)]
    return T


def task_components(module: ModuleType, q: np.ndarray) -> np.ndarray:
    """What the solver's task reads of fk(q), as one vector (positions / REACH): the pose's
    top rows, the position, the position and the tool axis (or its component along the base
    axis), the tool axis, or for a look-at the point one REACH ahead on the tool axis (the
    ray, through a point at a typical distance)."""
    P = module.fk(q)
    task = module.IK_COMPONENTS
    axis = getattr(module, "TOOL_AXIS", 2)
    position = P[:3, 3] / module.REACH
    if task == "position":
        return position
    if task == "direction":
        return np.concatenate([position, P[:3, axis]])
    if task == "axisangle":
        return np.concatenate([position, [P[module.CONE_AXIS, axis]]])
    if task == "pointing":
        return P[:3, axis].copy()
    if task == "lookat":
        return position + P[:3, axis]
    top = P[:3, :].copy()
    top[:, 3] /= module.REACH
    return top.ravel()


def jacobian_nullity(module: ModuleType, q: np.ndarray) -> tuple[float, np.ndarray]:
    """Smallest singular value of the normalised Jacobian at q and its right singular vector.

    Columns are central differences of the task's components (task_components: the pose's
    rotation entries and position / REACH, or what a task reads of them). An arm's free
    joints (FREE) are given, not solved: their columns are left out (their entries of the
    vector are 0). A look-at's rows are the point one REACH ahead with its motion along the
    ray (which does not change what the arm looks at) projected out.
    """
    h = 1e-6
    cols = []
    free = getattr(module, "FREE", ())
    solved = [j for j in range(module.DOF) if j + 1 not in free]
    for j in solved:
        step = np.zeros(module.DOF)
        step[j] = h if module.JOINT_TYPES[j] == "R" else h * module.REACH
        d = (task_components(module, q + step) - task_components(module, q - step)) / (2 * h)
        if module.IK_COMPONENTS == "lookat":
            u = module.fk(q)[:3, getattr(module, "TOOL_AXIS", 2)]
            d = d - (d @ u) * u
        cols.append(d)
    J = np.array(cols).T
    _, sigma, vt = np.linalg.svd(J)
    null = np.zeros(module.DOF)
    null[solved] = vt[-1]
    if len(sigma) < len(solved):
        return 0.0, null
    return float(sigma[-1]), null


def same_joints(a: np.ndarray, b: np.ndarray, revolute: np.ndarray, mask: np.ndarray) -> bool:
    """a equals b on the masked joints (revolute modulo 2 pi) within MATCH_TOL."""
    d = np.abs(a - b)
    d[revolute] = np.abs(np.remainder(d[revolute] + math.pi, 2 * math.pi) - math.pi)
    return bool(np.all(d[mask] <= MATCH_TOL))


def roundtrip(module: ModuleType, Q: np.ndarray, backend: str | None = None) -> RoundTrip:
    """Solve fk(q) for each row q of Q (with ik's `backend`) and collect the figures of
    :class:`RoundTrip`."""
    out = RoundTrip()
    revolute = np.array([k == "R" for k in module.JOINT_TYPES])
    everything = np.ones(module.DOF, dtype=bool)
    free = [j - 1 for j in getattr(module, "FREE", ())]
    poses = targets(module, Q)  # (a look-at's point one REACH ahead: its own tool point lies
    # on every ray, and every row of the head would look at it)
    for index, (q, T) in enumerate(zip(Q, poses)):
        # an arm with free joints: solved for q's values of them
        sols = module.ik(T, backend=backend, **({"free": q[free]} if free else {}))
        out.samples += 1
        out.solutions += len(sols)
        out.counts[len(sols)] = out.counts.get(len(sols), 0) + 1
        sigma, null = jacobian_nullity(module, q)
        singular = sigma < SINGULAR_SIGMA
        errors = [pose_error(module, s, T) for s in sols]
        worst = max((max(e) for e in errors), default=0.0)
        if singular:
            out.singular += 1
            out.worst_singular = max(out.worst_singular, worst)
            if worst > SINGULAR_TOL:
                out.unsound.append(index)
            mask = np.abs(null) < 0.1
            if any(max(e) <= SINGULAR_TOL for e in errors):
                out.singular_posed += 1
            if any(
                same_joints(s, q, revolute, mask) and max(e) <= SINGULAR_TOL
                for s, e in zip(sols, errors)
            ):
                out.singular_found += 1
            continue
        out.worst_rot = max([out.worst_rot] + [e[0] for e in errors])
        out.worst_pos = max([out.worst_pos] + [e[1] for e in errors])
        if worst > SOUND_TOL:
            out.unsound.append(index)
        if any(same_joints(s, q, revolute, everything) for s in sols):
            out.found += 1
        else:
            out.misses.append(index)
    return out
