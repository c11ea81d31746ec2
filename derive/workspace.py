"""Workspace maps from a generated solver: the reachable workspace (positions the tool reaches
in some orientation), the dexterous workspace (in every sampled orientation) and the number of
solutions per position, on a plane section, all computed with ``ik_batch``.

The section: for a planar arm (every axis parallel) the arm's own plane; for a spatial arm the
plane through axis 1 (at the zero pose) spanned by that axis and the base's x direction.
Orientations: for a planar arm, headings (rotations about the axes) every 360 / K degrees;
for a spatial arm the 24 rotations of the cube, turned by a fixed generic rotation. A position
is reachable when some orientation has a solution and dexterous when every one has.

An arm that controls only its tool point (IK_COMPONENTS == "position", a 2R) ignores the
target's orientation: there the orientations a position reaches are those of its solutions,
with the free joint of a singular position (q_ref's value) swept over K values, and a
position is dexterous when those cover every sampled heading (the 2R with l1 = l2 at the
origin, where q1 is free).

An arm with free joints (FREE) is mapped with them at q_ref's values (0).
"""

from __future__ import annotations

import itertools
import math
import sys
import time
from dataclasses import dataclass
from types import ModuleType
from typing import TextIO

import numpy as np

RESOLUTION = 201
HEADINGS = 36
# poses per ik_batch call
CHUNK = 40_000
# a sampled orientation is reached when a solution's rotation is within this (entries)
ORIENTATION_TOL = 1e-6


@dataclass(frozen=True)
class WorkspaceMap:
    """A section of an arm's workspace.

    Attributes:
        u, v: the grid's coordinates along the section's two directions (lengths).
        origin, du, dv: the section plane: origin and its two unit directions (world).
        reachable, dexterous: (len(v), len(u)) booleans.
        counts: (len(v), len(u)) the most solutions over the sampled orientations.
        planar: the section is the arm's own plane (else a plane through axis 1).
        limits: the joint limits were honoured.
        orientations: how many orientations were sampled per position; 0 for a look-at
            arm, whose task reads a point only (no orientation to sample: no dexterous
            workspace; reachable is the points its tool axis can pass through).
    """

    u: np.ndarray
    v: np.ndarray
    origin: np.ndarray
    du: np.ndarray
    dv: np.ndarray
    reachable: np.ndarray
    dexterous: np.ndarray
    counts: np.ndarray
    planar: bool
    limits: bool
    orientations: int

    @property
    def cell(self) -> float:
        """The area of one grid cell."""
        return float((self.u[1] - self.u[0]) * (self.v[1] - self.v[0]))

    def area(self, which: np.ndarray) -> float:
        """The area of a set of cells."""
        return float(which.sum()) * self.cell

    def volume(self, which: np.ndarray) -> float:
        """The volume of the solid the section's half u >= 0 sweeps about axis 1 (Pappus):
        the workspace's volume when joint 1 turns freely."""
        r = np.broadcast_to(self.u[None, :], which.shape)
        return float((2.0 * math.pi * r * self.cell)[which & (r > 0)].sum())

    def summary(self) -> str:
        """The figures in words."""
        reach = self.area(self.reachable)
        if self.orientations == 0:  # (a look-at: a new user's attack had every point
            # "dexterous (all 24 orientations)", as ik reads no orientation)
            text = (
                f"points its tool axis can pass through {reach:.6g} (area of the section); the "
                "look-at task reads a point only: no orientations, no dexterous workspace; "
                f"joint limits {'honoured' if self.limits else 'ignored'}"
            )
            if not self.planar:
                text += f"; volume swept about axis 1: {self.volume(self.reachable):.6g}"
            return text
        share = self.dexterous.sum() / max(int(self.reachable.sum()), 1)
        text = (
            f"reachable {reach:.6g} (area of the section), "
            f"dexterous {self.area(self.dexterous):.6g} ({int(self.dexterous.sum())} of "
            f"{int(self.reachable.sum())} reachable positions, "
            f"{100.0 * share:.2f}%); {self.orientations} orientations per position, "
            f"joint limits {'honoured' if self.limits else 'ignored'}"
        )
        if not self.planar:
            text += (
                f"; volume swept about axis 1: reachable {self.volume(self.reachable):.6g}, "
                f"dexterous {self.volume(self.dexterous):.6g}"
            )
        return text


def section(
    module: ModuleType, planar: bool, convention: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The section plane (origin, du, dv): planar arms' own plane, else the plane through axis
    1 spanned by the base's x direction (made normal to the axis) and the axis."""
    from derive.plot import arm_drawing  # (numpy only: no matplotlib needed)

    base = np.array(module.BASE, dtype=float)
    start, axis = arm_drawing(module, convention, np.zeros(module.DOF)).axes[0]
    x = base[:3, 0] - (base[:3, 0] @ axis) * axis
    if np.linalg.norm(x) < 1e-9:
        x = np.cross(axis, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    if planar:
        height = module.fk(np.zeros(module.DOF))[:3, 3]
        origin = start + ((height - start) @ axis) * axis
        return origin, x, np.cross(axis, x)
    return start, x, axis


def orientations(planar: bool, normal: np.ndarray, count: int) -> np.ndarray:
    """The sampled rotations: headings about the normal (planar), or the 24 rotations of the
    cube turned by a fixed generic rotation (spatial)."""
    if planar:
        out = []
        for k in range(count):
            t = 2.0 * math.pi * k / count
            out.append(_rotation(normal, t))
        return np.array(out)
    cube = []
    for perm in ((0, 1, 2), (1, 2, 0), (2, 0, 1), (0, 2, 1), (2, 1, 0), (1, 0, 2)):
        for signs in itertools.product((1, -1), repeat=3):
            R = np.zeros((3, 3))
            for i, (j, s) in enumerate(zip(perm, signs)):
                R[i, j] = s
            if np.linalg.det(R) > 0:
                cube.append(R)
    turn = _rotation(np.array([0.36, 0.48, 0.8]), 0.3)
    return np.array([turn @ R for R in cube])


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


_WINDOW = math.pi + 1e-9


def allowed(module: ModuleType) -> tuple[tuple[int, tuple[tuple[float, float], ...]], ...]:
    """The joints whose limits exclude some value, each with its allowed values as intervals:
    a revolute joint's q + 2 pi k in [lo, hi] (1e-12 slack, as ik's within_limits) for the
    values ik returns, (-pi, pi] (the turns of [lo, hi] that meet it); a prismatic joint's
    [lo, hi]."""
    out: list[tuple[int, tuple[tuple[float, float], ...]]] = []
    for j, ((lo, hi), kind) in enumerate(zip(module.LIMITS, module.JOINT_TYPES)):
        if kind == "R" and not (math.isfinite(lo) and hi - lo < 2.0 * math.pi):
            continue
        if kind == "P" and not (math.isfinite(lo) or math.isfinite(hi)):
            continue
        if kind == "P":
            out.append((j, ((lo - 1e-12, hi + 1e-12),)))
            continue
        turns: list[tuple[float, float]] = []
        for k in range(-3, 4):
            a, b = lo - 1e-12 + 2.0 * math.pi * k, hi + 1e-12 + 2.0 * math.pi * k
            if b >= -_WINDOW and a <= _WINDOW:
                turns.append((a, b))
        out.append((j, tuple(turns)))
    return tuple(out)


def inside_limits(module: ModuleType, Q: np.ndarray) -> np.ndarray:
    """Per row of Q (..., DOF), whether every joint is inside LIMITS (a revolute one at some
    q + 2 pi k), by comparisons with allowed's intervals (a quarter of the time of reducing
    each value modulo 2 pi); values outside (-pi, pi] by the modulo."""
    ok = np.ones(Q.shape[:-1], dtype=bool)
    for j, intervals in allowed(module):
        x = Q[..., j]
        inside = np.zeros(x.shape, dtype=bool)
        for a, b in intervals:
            inside |= (x >= a) & (x <= b)
        if module.JOINT_TYPES[j] == "R":
            far = np.abs(x) > _WINDOW
            if far.any():
                lo, hi = module.LIMITS[j]
                turns = np.ceil((lo - 1e-12 - x[far]) / (2.0 * math.pi))
                inside[far] = x[far] + 2.0 * math.pi * turns <= hi + 1e-12
        ok &= inside
    return ok


def workspace(
    module: ModuleType,
    planar: bool,
    convention: str,
    resolution: int = RESOLUTION,
    limits: bool = False,
    headings: int = HEADINGS,
    progress: TextIO | None = sys.stderr,
) -> WorkspaceMap:
    """The workspace section of a generated module (see the module docstring)."""
    origin, du, dv = section(module, planar, convention)
    extent = 1.05 * float(module.REACH)
    u = np.linspace(-extent, extent, resolution)
    v = np.linspace(-extent, extent, resolution)
    normal = np.cross(du, dv)
    rotations = orientations(planar, normal, headings)
    position_only = module.IK_COMPONENTS == "position"
    point_only = module.IK_COMPONENTS == "lookat"  # (no orientation read: one sampled)
    if point_only:
        rotations = rotations[:1]
    sweeps = [np.zeros(module.DOF)]
    if position_only:  # the free joint of a singular position takes q_ref's value: sweep it
        sweeps = [np.eye(module.DOF)[0] * (2.0 * math.pi * k / headings) for k in range(headings)]
        rotations = rotations[:1]
    # (a position arm's solutions are sorted by the rotations they take: headings about the
    # normal where planar, the 24 of the cube where spatial)
    targets = orientations(planar, normal, headings) if position_only else rotations
    width = len(targets)
    reached = np.zeros((resolution, resolution, width), dtype=bool)
    counts = np.zeros((resolution, resolution), dtype=int)
    start = time.perf_counter()
    # rows solved together: about CHUNK poses per ik_batch call
    step = max(1, CHUNK // (resolution * len(rotations)))
    shown = 0.0
    for first in range(0, resolution, step):
        rows = slice(first, min(resolution, first + step))
        n_rows = rows.stop - rows.start
        points = origin + (u[None, :, None] * du) + (v[rows, None, None] * dv)
        poses = np.zeros((n_rows * resolution * len(rotations), 4, 4))
        poses[:, :3, :3] = np.tile(rotations, (n_rows * resolution, 1, 1))
        poses[:, :3, 3] = np.repeat(points.reshape(-1, 3), len(rotations), axis=0)
        poses[:, 3, 3] = 1.0
        active = np.arange(len(poses))
        first_rows = None
        for k, q_ref in enumerate(sweeps):
            if len(active) == 0:
                break
            Q = np.zeros((len(poses), module.MAX_SOLUTIONS, module.DOF))
            valid = np.zeros((len(poses), module.MAX_SOLUTIONS), dtype=bool)
            Q[active], valid[active] = module.ik_batch(poses[active], q_ref=q_ref)
            if k == 0:
                first_rows = (Q, valid)
            elif k == 1 and first_rows is not None:
                # later values of the free joint matter only where this one changed a row
                changed = (np.abs(Q - first_rows[0]) > 1e-9).any(axis=(1, 2))
                active = np.flatnonzero(changed | (valid != first_rows[1]).any(axis=1))
            if limits:
                valid &= inside_limits(module, Q)
            n = valid.sum(axis=1).reshape(n_rows, resolution, len(rotations))
            counts[rows] = np.maximum(counts[rows], n.max(axis=2))
            if not position_only:
                reached[rows] |= n > 0
            elif len(active):
                # the headings the solutions have (their rotations against each target's), at
                # the positions this sweep solved (one pose per position)
                flat = reached[rows].reshape(-1, width)
                R = module.fk_batch(Q[active].reshape(-1, module.DOF))[:, :3, :3]
                R = R.reshape(len(active), module.MAX_SOLUTIONS, 3, 3)
                gap = np.abs(R[:, :, None] - targets[None, None]).max(axis=(3, 4))
                flat[active] |= ((gap <= ORIENTATION_TOL) & valid[active][:, :, None]).any(axis=1)
                reached[rows] = flat.reshape(n_rows, resolution, width)
        now = time.perf_counter()
        if progress is not None and (now - shown > 0.5 or rows.stop == resolution):
            progress_line(progress, "workspace", rows.stop, resolution, start, "rows")
            shown = now
    if progress is not None:  # end the progress line: what is printed next starts a line
        progress.write("\n")
    reachable = counts > 0
    dexterous = reached.all(axis=2) & reachable & (not point_only)
    return WorkspaceMap(
        u, v, origin, du, dv, reachable, dexterous, counts, planar, limits,
        0 if point_only else len(targets),
    )  # fmt: skip


def progress_line(out: TextIO, label: str, done: int, total: int, start: float, unit: str) -> None:
    """One line of progress (rewritten in place) with an estimate of the time left; the caller
    ends the line once the work is done."""
    elapsed = time.perf_counter() - start
    left = elapsed / max(done, 1) * (total - done)
    bar = "#" * (30 * done // max(total, 1))
    out.write(f"\r{label} [{bar:<30}] {done}/{total} {unit}, {elapsed:.0f} s, ETA {left:.0f} s")
    out.flush()
