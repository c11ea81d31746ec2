"""The public functions of arms with free joints (FREE: more joints than the task fixes):
ik_sweep, and nearest searching the free joints (an arm without them: api's _nearest_fixed).
ik_sweep is in the __all__ of those modules only (derive/assemble.py)."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from derive.runtime.api import (
    _distances,
    _in_limits,
    _nearest_arguments,
    _nearest_fixed,
    _pose,
    ik,
    ik_batch,
)
from derive.runtime.arm import _REVOLUTE, FREE, LIMITS, REACH
from derive.runtime.common import _real, _reference
from derive.runtime.constants import (
    _TWO_PI,
    CERTIFY_TOL,
    FREE_STEP,
    MAX_FREE_VALUES,
    NEAREST_BATCH,
)


def nearest(
    T: ArrayLike,
    q_ref: ArrayLike,
    *,
    within_limits: bool = True,
    weights: ArrayLike | None = None,
    metric: str = "l2",
    free_step: float = FREE_STEP,
    backend: str | None = None,
) -> np.ndarray | None:
    """The solution closest to q_ref, over the free joints' values where FREE has any, or None.

    An arm without free joints: its solution closest to q_ref (_nearest_fixed; free_step
    is not used). With free joints, they start at q_ref's values and step outward by
    free_step (as MoveIt's IKFast plugin does) to their limits (within_limits) or half a
    turn; values are solved NEAREST_BATCH at a time, in order of their own distance from
    q_ref's, and the search stops once that distance alone exceeds the best solution's: the
    result is the closest solution over the stepped values. With within_limits=True each
    revolute joint takes its value q + 2 pi k inside LIMITS nearest q_ref's; with
    within_limits=False revolute differences are wrapped to (-pi, pi] and the solution is
    returned wrapped.

    Args:
        weights: DOF finite non-negative numbers (default ones).
        metric: "l2" (weighted squared distance, sum of w_i dq_i^2) or "max" (max of
            w_i |dq_i|).
        free_step: the free joints' step (radians, or length for a prismatic joint).
        backend: as for ik.
    """
    if not FREE:
        return _nearest_fixed(
            T, q_ref, within_limits=within_limits, weights=weights, metric=metric, backend=backend
        )
    refs, w = _nearest_arguments(q_ref, weights, metric)
    step = float(free_step)
    if not 0.0 < step < math.inf:
        raise ValueError(f"free_step must be a positive finite number, got {free_step!r}")
    A = _real(T, "T")
    if A.shape != (4, 4):
        raise ValueError(f"T must have shape (4, 4), got {A.shape}")
    _pose(A)
    axes = []
    for j in FREE:
        lo, hi = LIMITS[j - 1] if within_limits else (-math.inf, math.inf)
        half = math.pi if _REVOLUTE[j - 1] else REACH
        centre = refs[j - 1]
        if _REVOLUTE[j - 1] and not within_limits:
            centre = math.remainder(centre, _TWO_PI)  # (the result is wrapped)
        # q_ref's value, or the limit nearest it: half a turn (or REACH) either side
        start = min(max(centre, lo), hi)
        lo, hi = max(lo, start - half), min(hi, start + half)
        if (hi - lo) / step >= MAX_FREE_VALUES:
            raise ValueError(f"free_step {step!r} gives more than {MAX_FREE_VALUES} values")
        k = np.arange(-math.floor((start - lo) / step), math.floor((hi - start) / step) + 1)
        axes.append(start + step * k)
    grid = _product_grid(axes, "nearest: {} free values", f" at free_step {step:g}",
                         "a larger free_step")  # fmt: skip
    columns = [j - 1 for j in FREE]
    own = np.tile(np.array(refs), (len(grid), 1))
    own[:, columns] = grid
    bound = _distances(own, refs, w, metric, not within_limits)
    order = np.argsort(bound, kind="stable")
    best, least = None, math.inf
    # q_ref's own free values first (one ik: along a smooth path that usually settles it),
    # then NEAREST_BATCH values per ik_batch
    starts = [0, *range(1, len(order), NEAREST_BATCH)]
    for first, end in zip(starts, [*starts[1:], len(order)]):
        chunk = order[first:end]
        if best is not None and bound[chunk[0]] >= least:
            break
        if len(chunk) == 1:
            rows = ik(A, free=grid[chunk[0]], q_ref=refs, backend=backend)
        else:
            poses = np.repeat(A[None], len(chunk), axis=0)
            Q, valid = ik_batch(poses, free=grid[chunk], q_ref=refs, backend=backend)
            rows = Q[valid]
        if within_limits:
            rows = _in_limits(rows, refs, False)
        if len(rows) == 0:
            continue
        costs = _distances(rows, refs, w, metric, not within_limits)
        i = int(np.argmin(costs))
        if best is None or costs[i] < least:
            best, least = rows[i], float(costs[i])
    return best


def ik_sweep(
    T: ArrayLike,
    *,
    n: int | None = None,
    step: float | None = None,
    within_limits: bool = True,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Every solution of T for the free joints sampled over their limits (an arm with FREE).

    Args:
        n: values per free joint, evenly spaced over its limits (both ends included; a
            revolute joint without limits: n values over a turn); default 64.
        step: instead of n, values this far apart from the lower limit.
        within_limits: keep only solutions inside LIMITS (each joint at its variant nearest
            q_ref's, as in ik).
        q_ref, tol, backend: as for ik; several free joints are sampled on their product grid.

    Returns:
        (values, Q): Q (M, DOF), every solution for every sample, as full joint vectors in
        the order of the samples; values (M, len(FREE)): the free joints' values of each row.
    """
    if n is not None and step is not None:
        raise ValueError("ik_sweep: give n or step, not both")
    axes = [_sweep_values(j, 64 if n is None and step is None else n, step) for j in FREE]
    grid = _product_grid(axes, "ik_sweep: {} samples", "", "a smaller n or a larger step")
    A = _real(T, "T")
    if A.shape != (4, 4):
        raise ValueError(f"T must have shape (4, 4), got {A.shape}")
    _pose(A)
    refs = _reference(q_ref)
    Q, valid = ik_batch(
        np.repeat(A[None], len(grid), axis=0), free=grid, q_ref=refs, tol=tol, backend=backend
    )
    rows = Q[valid]
    if within_limits:
        rows = _in_limits(rows, refs, False)
    return rows[:, [j - 1 for j in FREE]], rows


def _product_grid(axes, what: str, how: str, advice: str) -> np.ndarray:
    """Every combination of the free joints' values in axes, (count, len(axes)); its count is
    checked first (a base's 2,001 x 2,001 x 629 values of three free joints were 19 GiB an
    array before the check, a new user's attack): ValueError beyond MAX_FREE_VALUES, saying
    what (its {} the count) and how the sizes came, and the advice."""
    count = math.prod(len(a) for a in axes)
    if count > MAX_FREE_VALUES:
        sizes = " x ".join(str(len(a)) for a in axes)
        raise ValueError(
            f"{what.format(count)} ({sizes}{how}); at most {MAX_FREE_VALUES}: give {advice}"
        )
    return np.stack([g.ravel() for g in np.meshgrid(*axes, indexing="ij")], axis=-1)


def _sweep_values(j: int, n: int | None, step: float | None) -> np.ndarray:
    """The samples of free joint j: n over its limits, or `step` apart."""
    lo, hi = LIMITS[j - 1]
    closed = math.isfinite(lo) and math.isfinite(hi)
    if not closed:
        half = math.pi if _REVOLUTE[j - 1] else REACH
        lo, hi = -half, half
    if step is not None:
        step = float(step)
        if not 0.0 < step < math.inf or (hi - lo) / step >= MAX_FREE_VALUES:
            raise ValueError(
                f"step must be a positive number giving at most {MAX_FREE_VALUES} values, "
                f"got {step!r}"
            )
        return lo + step * np.arange(math.floor((hi - lo) / step + 1e-9) + 1)
    if type(n) is bool or not isinstance(n, (int, np.integer)) or not 1 <= n <= MAX_FREE_VALUES:
        raise ValueError(f"n must be an integer 1 to {MAX_FREE_VALUES}, got {n!r}")
    return np.linspace(lo, hi, int(n), endpoint=closed or not _REVOLUTE[j - 1])
