"""The generated module's public functions and their plumbing: argument checks, wrapping and
dropping repeats, joint limits, and the choice between the compiled C solver (native.py) and
the Python one."""

from __future__ import annotations

import math
from operator import sub as _sub

import numpy as np
from numpy.typing import ArrayLike

from derive.runtime.arm import (
    _C_SOURCE,
    _REVOLUTE,
    DOF,
    FREE,
    LIMITS,
    MAX_SOLUTIONS,
    REACH,
    _cs_columns,
    _fk_from_cs,
    _fk_q,
    _ik_scalar,
)
from derive.runtime.common import (
    _FAR,
    _LOWER,
    _ONES,
    _PERIODS,
    _REV,
    _UPPER,
    _ZEROS,
    _joint_values,
    _real,
    _reference,
    _seam,
    _tolerance,
)
from derive.runtime.constants import (
    _LIMIT_SLACK,
    _RIGID_SNAP,
    _SEAM,
    _TWO_PI,
    BACKEND,
    CERTIFY_TOL,
    DEDUP_TOL,
    FREE_LIMIT,
    MAX_TURN_ROWS,
    POSE_TOL,
)
from derive.runtime.native import (
    _UNSETTLED,
    _batch_threads,
    _loaded,
    _native_solver,
    _scratch,
)
from derive.runtime.refine import _LOOSE_TOL, _fold_partners, _least_squares, _pose_error
from derive.runtime.scalar import _LOOSE


def fk(q: ArrayLike) -> np.ndarray:
    """World pose of the tool frame (base and tool included) for joint vector q."""
    e = _fk_q(_joint_values(q))
    return np.array([e[0:4], e[4:8], e[8:12], (0.0, 0.0, 0.0, 1.0)])


def fk_batch(Q: ArrayLike) -> np.ndarray:
    """World poses (N, 4, 4) for joint vectors Q of shape (N, DOF), without a Python loop."""
    values = _real(Q, "Q")
    if values.ndim != 2 or values.shape[1] != DOF:
        raise ValueError(f"Q must have shape (N, {DOF}), got {values.shape}")
    if not np.isfinite(values).all():
        raise ValueError("Q must be finite numbers")
    native = _native_solver(None) if _C_SOURCE else None
    if native is not None:
        Q = np.ascontiguousarray(values)
        out = np.empty((Q.shape[0], 4, 4))
        native.fk_batch(Q.ctypes.data, Q.shape[0], out.ctypes.data)
        return out
    out = np.zeros((values.shape[0], 4, 4))
    entries = _fk_from_cs(*_cs_columns(values))
    for k, value in enumerate(entries):
        out[:, k // 4, k % 4] = value
    out[:, 3, 3] = 1.0
    return out


def ik(
    T: ArrayLike,
    *,
    free: ArrayLike | None = None,
    within_limits: bool = False,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
    all_turns: bool = False,
) -> np.ndarray:
    """All solutions for the world pose T, as an (n, DOF) array; empty (0, DOF) if unreachable.

    Args:
        T: 4x4 homogeneous transform of the tool frame in the world.
        free: an arm with free joints (FREE, more than 6 joints): their values, one per joint
            in FREE's order (a number where FREE has one); default: q_ref's values. Every
            solution has these values.
        within_limits: keep only solutions inside LIMITS. Each solution comes once, each
            revolute joint at the value q + 2 pi k inside its limits nearest q_ref's (joints
            without limits too: by default the wrapped value). A solution with a joint that
            no such k brings inside its limits is dropped.
        q_ref: joint vector whose values free joints take at singular poses, and that
            within_limits picks variants near (default zeros).
        tol: certification tolerance: a solution is returned only if its forward kinematics
            matches T within tol in rotation entries and tol * REACH in position. For an arm
            that does not control every pose component this is also the test that T's other
            components are reachable: if they are not, the result is empty.
        backend: "c" runs the arm's C solver (compiled on the first call of a process, or
            at warmup(), into a per-user cache: see _c_library); "python" runs the Python
            solver; "auto" is "c" where the C solver compiles; None (default): BACKEND,
            which is "auto" unless you set it. The two agree to rounding (far below tol)
            at regular poses; at a pose within about 1e-6 of singular (a curve of solutions,
            or two that nearly meet) each may return other points of it, every one certified.
            Poses the C solver does not settle (a split multiple root) are solved in Python
            either way.
        all_turns: with within_limits, every variant of every solution inside the limits
            (all k per joint, as a product; at most MAX_TURN_ROWS rows, else ValueError).

    Raises:
        ValueError: T is not 4x4, has non-finite or complex entries, or its rotation is not
            orthonormal within POSE_TOL; q_ref is not DOF finite numbers; tol is not a
            positive finite number; all_turns would give more than MAX_TURN_ROWS rows; free
            is given for an arm without free joints, or is not len(FREE) finite numbers.
    """
    native = _loaded()
    if (
        native is not None
        and free is None
        and q_ref is None
        and not within_limits
        and tol is CERTIFY_TOL
        and backend is None
        and BACKEND != "python"
        and type(T) is np.ndarray
        and T.shape == (4, 4)
        and T.dtype == np.float64
    ):  # the common call, in C with nothing to check or choose (the rest: below)
        pose, at, rows, rows_at, _, _ = _scratch()
        pose[...] = T
        n = native.ik(at, None, None, tol, rows_at)
        if n >= 0:
            return rows[:n].copy()
    refs = _with_free(_reference(q_ref), free)
    solve = _free_turns(refs)
    tol = _tolerance(tol)
    if within_limits:

        def result(rows):
            return _in_limits(rows, refs, all_turns)
    else:
        result = _as_rows
    native = _native_solver(backend)
    if native is not None:
        A = _array44(T)
        if A is not None:  # else _pose says what is wrong with T
            pose, at, rows, rows_at, ref, ref_at = _scratch()
            pose[...] = A
            given = None
            if solve is not _ZEROS:
                ref[:] = solve
                given = ref_at
            n = native.ik(at, None, given, tol, rows_at)
            if n >= 0:
                # (C picks variants near the values it solves with: near q_ref's own ones
                # where a free value was reduced to a turn, result does)
                if within_limits and not all_turns and solve == refs:
                    return rows[: native.within_limits(rows_at, n, given)].copy()
                return result(rows[:n].copy())
    # the Python solver; for the compiled one a pose it did not settle, or an invalid one
    target = _pose(T)
    if max(abs(target[3]), abs(target[7]), abs(target[11])) > _FAR:
        return result(_finish([]))
    return result(_finish(_solve(target, solve, tol)))


def _solve(target, solve, tol):
    """The Python solver's certified rows of target. Where the first pass gives none, a
    second takes each a cos + b sin = e that misses at its boundary (_LOOSE.near): near a
    singular configuration a pose the arm reaches can leave an equation missed by more than
    its band. On an exact table an earlier step's rounding, divided by a nearly vanishing
    factor, does it (a three-parallel arm's elbow and wrist both 1e-8 rad from straight:
    theta6 from s5's terms, then the elbow's law of cosines beyond 1 by 2e-7 of its ratio; a
    MyCobot 320 got no row at 31 of 100 such poses); its rows are certified and polished as
    in the first pass (_keep). On a nominal table (_SEED_TOL > 0: the rows refined onto the
    exact chain) the table's difference does it, near a singular configuration; there the
    seeds whose pose error is within _SEED_TOL are refined (a pose out of reach gives seeds far
    from it: measured 0.026 or more on a hextilt arm, where the seeds that reach the pose
    were within 2e-4), and kept where certified (_seed). The C solver takes the same second
    pass (dk_solve, loose), and keeps rows within _LOOSE_TOL (or tol, if smaller) only."""
    rows = _exact_first(target, solve, tol)
    if rows:
        return _fold_partners(_finish(rows), target, tol)
    _LOOSE.near = True
    try:
        tol = min(tol, _LOOSE_TOL)
        return _fold_partners(_finish(_exact_first(target, solve, tol)), target, tol)
    finally:
        _LOOSE.near = False


def _exact_first(target, solve, tol):
    """_ik_scalar's rows of target, but those that polishing left beyond _LOOSE_TOL (_keep notes
    them in _LOOSE.rough) where the pose has others: they are a branch's that misses the
    pose by up to tol, not its solutions (C: dk_drop_rough)."""
    _LOOSE.rough = []
    try:
        rows = _ik_scalar(target, *solve, tol)
        rough = _LOOSE.rough
    finally:
        _LOOSE.rough = None
    if rough and len(rough) < len(rows):
        rows = [r for r in rows if not any(r is x for x in rough)]
    return rows


def ik_approximate(
    T: ArrayLike,
    *,
    free: ArrayLike | None = None,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    backend: str | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ik's solutions where T is reached; where it is not (slightly out of reach, or a
    rotation the arm cannot take), the nearest configuration of each branch instead, each
    with its residual and a flag. Opt-in: ik never returns an approximate row.

    The nearest configurations: the solver's equations solved at their boundary where they
    miss (an acos argument beyond 1 taken as +-1, a complex root's real part), each such
    seed then moved by damped Newton steps on the exact chain to the least-squares point of
    the pose error (positions divided by REACH, and the rotation error), so that the result
    depends on how far out of reach T is, not on the derivation. Where the solver gives no
    seed (the general method's arms: their candidates are eigenvalues) q_ref's
    configuration is the one seed. In Python (the C solver answers the reachable case).

    Returns:
        (Q, residual, exact): Q (n, DOF) in branch order as ik's; residual (n,) the largest
        difference of fk(Q[i]) from T (rotation entries, positions divided by REACH; the
        position only for an arm solved for its position); exact (n,) residual <= tol, True
        for every row where T is reached.
    """
    rows = ik(T, free=free, q_ref=q_ref, tol=tol, backend=backend)
    target = _pose(T)
    if not len(rows):
        refs = _with_free(_reference(q_ref), free)
        _LOOSE.on = True
        try:
            seeds = _ik_scalar(target, *_free_turns(refs), math.inf)
        finally:
            _LOOSE.on = False
        # (none: the general method's candidates are eigenvalues, with no boundary to
        # solve at; then q_ref's configuration is the one seed)
        seeds = seeds or [_free_turns(refs)]
        rows = _as_rows(_finish([_least_squares(q, target) for q in seeds]))
    residual = np.array([_pose_error(q, target, False)[2] for q in rows.tolist()])
    return rows, residual, residual <= _tolerance(tol)


def _array44(T):
    """T as a float64 array if it is 4x4, else None."""
    try:
        T = _real(T, "T")
    except ValueError:
        return None
    return T if T.shape == (4, 4) else None


def ik_batch(
    T: ArrayLike,
    *,
    free: ArrayLike | None = None,
    q_ref: ArrayLike | None = None,
    tol: float = CERTIFY_TOL,
    chunk: int = 4096,
    backend: str | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """All solutions for many world poses at once: in C, split over the cores (the Python
    fallback loops over the poses).

    Args:
        T: (N, 4, 4) poses.
        free: an arm with free joints: their values per pose, (N, len(FREE)) (or (N,) where
            FREE has one); default: q_ref's values for every pose.
        q_ref: as for ik (one joint vector for all poses).
        tol: as for ik.
        chunk: accepted for compatibility (the poses are solved one by one, in C over
            every core, or in Python).
        backend: "c" solves the poses in C, split over every core (_THREADS threads, each
            call releasing the GIL); "python" solves them one by one with the Python
            solver; "auto" and None as for ik. Both give ik's solutions.

    Returns:
        (Q, valid): Q (N, M, DOF) with M = MAX_SOLUTIONS, the most solutions a pose can
        have; valid (N, M) marks the slots that hold a solution: for each pose the first
        slots, holding the rows ik returns, in the same order; the other slots are zero.
        within_limits is not offered here. A pose that is not a valid transform (not
        finite, rotation not orthonormal within POSE_TOL) gets no valid slot instead of an
        exception.
    """
    tol = _tolerance(tol)
    if type(chunk) is bool or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise ValueError(f"chunk must be a positive integer, got {chunk!r}")
    refs = _reference(q_ref)
    if free is None:  # (else _free_rows reduces the values given)
        refs = _free_turns(refs)
    native = _native_solver(backend)
    T = np.ascontiguousarray(_real(T, "T"))
    if T.ndim != 3 or T.shape[1:] != (4, 4):
        raise ValueError(f"T must have shape (N, 4, 4), got {T.shape}")
    n = T.shape[0]
    per_pose = _free_rows(free, refs, n)
    Q = np.empty((n, MAX_SOLUTIONS, DOF))
    counts = np.full(n, _UNSETTLED, dtype=np.intc)
    if native is not None:
        qref = np.array(refs) if per_pose is None else per_pose
        stride = 0 if per_pose is None else DOF
        size, cells = T.itemsize, MAX_SOLUTIONS * DOF

        def part(first, count):
            native.ik_batch(
                T.ctypes.data + 16 * size * first,
                count,
                qref.ctypes.data + stride * size * first,
                stride,
                tol,
                Q.ctypes.data + cells * size * first,
                counts.ctypes.data + counts.itemsize * first,
            )

        _batch_threads(part, n)
    else:
        Q.fill(0.0)
    valid = np.arange(MAX_SOLUTIONS) < counts[:, None]
    # the poses C did not settle (a split multiple root), or all of them in Python
    for i in np.flatnonzero(counts == _UNSETTLED):
        ref_i = refs if per_pose is None else tuple(per_pose[i].tolist())
        try:
            _settle(Q, valid, i, ik(T[i], q_ref=ref_i, tol=tol, backend="python"))
        except ValueError:  # not a valid transform: no valid slot
            Q[i] = 0.0
    return Q, valid


def _with_free(refs, free):
    """q_ref's values with the free joints' values from free (None: q_ref's own)."""
    if free is None:
        return refs
    if not FREE:
        raise ValueError("free: this arm has no free joints (FREE is empty)")
    values = _real(free, "free")
    if values.ndim == 0:
        values = values.reshape(1)
    if values.shape != (len(FREE),) or not np.isfinite(values).all():
        raise ValueError(
            f"free must be {len(FREE)} finite number(s), one per joint in FREE = {FREE}"
        )
    out = list(refs)
    for j, x in zip(FREE, values.tolist()):
        out[j - 1] = x
    return tuple(out)


def _free_turns(refs):
    """refs with each revolute free joint's value reduced to (-pi, pi]: the value the solver
    works with and returns, so that a returned row reproduces the pose with its own values.

    Raises:
        ValueError: a free value beyond FREE_LIMIT radians (FREE_LIMIT * REACH for a sliding
            joint), where neither the reduction nor cos and sin are accurate.
    """
    if not FREE:
        return refs
    out = list(refs)
    for j in FREE:
        x = out[j - 1]
        limit, unit = (FREE_LIMIT, "rad") if _REVOLUTE[j - 1] else (FREE_LIMIT * REACH, "")
        if not abs(x) <= limit:
            raise ValueError(
                f"free joint q{j} = {x!r}: a free value must lie within +-{limit:g} {unit}".rstrip()
            )
        if _REVOLUTE[j - 1]:
            out[j - 1] = math.remainder(x, _TWO_PI)
    return tuple(out)


def _free_rows(free, refs, n):
    """Per pose, q_ref's values with the free joints' values from free ((n, len(FREE)), or
    (n,) where FREE has one), as an (n, DOF) array; None for free=None."""
    if free is None:
        return None
    if not FREE:
        raise ValueError("free: this arm has no free joints (FREE is empty)")
    values = _real(free, "free")
    if values.ndim == 1 and len(FREE) == 1:
        values = values[:, None]
    if values.shape != (n, len(FREE)) or not np.isfinite(values).all():
        raise ValueError(
            f"free must be finite numbers of shape ({n}, {len(FREE)}): one value per pose "
            f"for each joint in FREE = {FREE}"
        )
    limits = np.array([FREE_LIMIT if _REVOLUTE[j - 1] else FREE_LIMIT * REACH for j in FREE])
    if not (np.abs(values) <= limits).all():
        raise ValueError(
            f"free values must lie within +-{FREE_LIMIT:g} rad (+-{FREE_LIMIT * REACH:g} for "
            f"a sliding joint), one per pose for each joint in FREE = {FREE}"
        )
    turns = np.array([_REVOLUTE[j - 1] for j in FREE])
    # fmod is exact; one addition of 2 pi brings its (-2 pi, 2 pi) to (-pi, pi]
    reduced = np.fmod(values, _TWO_PI)
    reduced = np.where(reduced > math.pi, reduced - _TWO_PI, reduced)
    reduced = np.where(reduced <= -math.pi, reduced + _TWO_PI, reduced)
    rows = np.tile(np.array(refs), (n, 1))
    rows[:, [j - 1 for j in FREE]] = np.where(turns, reduced, values)
    return rows


def _settle(Q, valid, i, sols):
    """Pose i's slots set to the rows sols."""
    sols = sols[:MAX_SOLUTIONS]
    Q[i], valid[i] = 0.0, False
    Q[i, : len(sols)], valid[i, : len(sols)] = sols, True


def _nearest_fixed(
    T: ArrayLike,
    q_ref: ArrayLike,
    *,
    within_limits: bool = True,
    weights: ArrayLike | None = None,
    metric: str = "l2",
    backend: str | None = None,
) -> np.ndarray | None:
    """The solution closest to q_ref, or None.

    With within_limits=True each revolute joint takes its value q + 2 pi k inside LIMITS
    nearest q_ref's (the distance is a sum or maximum over joints, so this is the nearest
    variant of the whole vector); with within_limits=False revolute differences are wrapped
    to (-pi, pi] and the solution is returned wrapped.

    Args:
        weights: DOF finite non-negative numbers (default ones).
        metric: "l2" (weighted squared distance, sum of w_i dq_i^2) or "max" (max of
            w_i |dq_i|).
        backend: as for ik.
    """
    refs, w = _nearest_arguments(q_ref, weights, metric)
    native = _native_solver(backend)
    A = _array44(T) if native is not None and metric == "l2" and within_limits else None
    if native is not None and A is not None:
        pose, at, rows, rows_at, ref, ref_at = _scratch()
        pose[...], ref[:] = A, refs
        w_at = None if weights is None else np.ascontiguousarray(w).ctypes.data
        found = native.nearest(at, None, ref_at, w_at, CERTIFY_TOL, rows_at)
        if found >= 0:
            return rows[0].copy() if found else None
    sols = ik(T, within_limits=within_limits, q_ref=refs, backend=backend)
    if len(sols) == 0:
        return None
    return sols[int(np.argmin(_distances(sols, refs, w, metric, not within_limits)))]


def _nearest_arguments(q_ref, weights, metric):
    """nearest's q_ref and weights, checked."""
    refs = _reference(q_ref, required=True)
    if weights is None:
        w = _ONES
    else:
        w = _real(weights, "weights")
        if w.shape != (DOF,) or not np.isfinite(w).all() or (w < 0.0).any():
            raise ValueError(f"weights must be {DOF} finite non-negative numbers")
    if metric not in ("l2", "max"):
        raise ValueError(f"metric must be 'l2' or 'max', got {metric!r}")
    return refs, w


def _distances(rows, refs, w, metric, wrap):
    """Per row, its distance from refs: sum of w dq^2 ("l2") or max of w |dq| ("max")."""
    d = rows - np.array(refs)
    if wrap:
        d -= _TWO_PI * np.rint(d / _TWO_PI) * _REV
    if metric == "max":
        return (w * np.abs(d)).max(axis=1, initial=0.0)
    with np.errstate(over="ignore"):  # a q_ref far out: inf, every row as far
        return (w * d * d).sum(axis=1)


def _pose(T):
    """The 12 top entries of a validated pose, as floats (plain Python: this is the hot path)."""
    if type(T) is np.ndarray and T.shape == (4, 4) and T.dtype == np.float64:
        v = T.ravel().tolist()
    else:
        try:
            A = _real(T, "T")
        except ValueError:
            raise ValueError("T must be a 4x4 array of real numbers") from None
        if A.shape != (4, 4):
            raise ValueError(f"T must have shape (4, 4), got {A.shape}")
        v = A.ravel().tolist()
    if not all(map(math.isfinite, v)):
        raise ValueError("T has non-finite entries")
    if max(abs(v[12]), abs(v[13]), abs(v[14]), abs(v[15] - 1.0)) > POSE_TOL:
        raise ValueError("T's last row must be [0, 0, 0, 1]")
    a, b, c = v[0:3], v[4:7], v[8:11]
    worst = max(
        abs(a[0] * a[0] + a[1] * a[1] + a[2] * a[2] - 1.0),
        abs(b[0] * b[0] + b[1] * b[1] + b[2] * b[2] - 1.0),
        abs(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] - 1.0),
        abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2]),
        abs(a[0] * c[0] + a[1] * c[1] + a[2] * c[2]),
        abs(b[0] * c[0] + b[1] * c[1] + b[2] * c[2]),
    )
    det = (
        a[0] * (b[1] * c[2] - b[2] * c[1])
        - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
    )
    if worst > POSE_TOL or det < 0.0:
        raise ValueError(f"T's rotation is not orthonormal within {POSE_TOL}")
    if worst > _RIGID_SNAP:
        v = _rigid(v)
    return tuple(v[:12])


def _rigid(v):
    """The pose's entries v (row-major) with its rotation R replaced by the nearest rotation,
    its polar factor, by Newton-Schulz steps R := (3 I - R R^T) R / 2 (each squares the
    distance from orthonormal: 1e-6, 1e-12, 1e-24); the C solver's dk_rigid."""
    R = [v[0:3], v[4:7], v[8:11]]
    for _ in range(3):
        G = [[sum(R[i][k] * R[j][k] for k in range(3)) for j in range(3)] for i in range(3)]
        R = [
            [1.5 * R[i][c] - 0.5 * sum(G[i][k] * R[k][c] for k in range(3)) for c in range(3)]
            for i in range(3)
        ]
    return [*R[0], v[3], *R[1], v[7], *R[2], v[11]]


def _finish(found):
    """Revolute values wrapped to (-pi, pi] (at the seam: _seam) and repeats
    (DEDUP_TOL, revolute differences modulo 2 pi) dropped.

    Repeats are found by comparing the last joint first, then all joints; the first of
    equal candidates is kept. At most MAX_SOLUTIONS rows, the first ones, as the C solver's
    buffer keeps: a pose on a curve of solutions (a singular configuration of a nominal table
    whose exact arm keeps it, SO-ARM100's wrist roll at 90 deg) certifies every seed.
    """
    rows: list[tuple[float, ...]] = []
    for q in found:
        q = tuple(map(math.remainder, q, _PERIODS))
        if max(map(abs, q)) > _SEAM:
            q = tuple(
                _seam(x) if abs(x) > _SEAM and p != math.inf else x for x, p in zip(q, _PERIODS)
            )
        for p in rows:
            if (
                abs(math.remainder(q[-1] - p[-1], _PERIODS[-1])) <= DEDUP_TOL
                and max(map(abs, map(math.remainder, map(_sub, q, p), _PERIODS))) <= DEDUP_TOL
            ):
                break
        else:
            rows.append(q)
    return rows[:MAX_SOLUTIONS]


def _as_rows(rows):
    """ik's (n, DOF) array of rows."""
    if type(rows) is np.ndarray:
        return rows
    return np.array(rows, dtype=float).reshape(len(rows), DOF)


def _in_limits(rows, refs, all_turns):
    """The rows inside LIMITS: each once, every revolute joint at its variant q + 2 pi k
    nearest refs (vectorised over the rows); with all_turns, every variant (a bounded
    product)."""
    if all_turns:
        return _every_turn(rows.tolist() if type(rows) is np.ndarray else rows)
    Q = _as_rows(rows)
    k = np.rint((np.array(refs) - Q) / _TWO_PI) * _REV
    # for a prismatic joint first <= 0 <= last says it is inside its limits
    first = np.ceil((_LOWER - Q) / _TWO_PI)
    last = np.floor((_UPPER - Q) / _TWO_PI)
    k = np.minimum(np.maximum(k, first), last) * _REV
    ok = ((first <= k) & (k <= last)).all(axis=1)
    return (Q + k * _TWO_PI)[ok]


def _every_turn(rows):
    """Every variant of the rows inside LIMITS, at most MAX_TURN_ROWS of them."""
    options = [_turns(q) for q in rows]
    total = sum(math.prod(len(o) for o in opts) for opts in options)
    if total > MAX_TURN_ROWS:
        raise ValueError(
            f"all_turns: the limits allow {total} variants of the solutions; "
            f"at most MAX_TURN_ROWS = {MAX_TURN_ROWS} are returned"
        )
    out = []
    for opts in options:
        combos: list[tuple[float, ...]] = [()]
        for values in opts:
            combos = [(*c, v) for c in combos for v in values]
        out += combos if opts else []
    return _as_rows(out)


def _turn_range(x, lo, hi):
    """The k with lo <= x + 2 pi k <= hi (_LIMIT_SLACK of slack): (first, last), empty if first >
    last."""
    first = -math.inf if lo == -math.inf else math.ceil((lo - _LIMIT_SLACK - x) / _TWO_PI)
    last = math.inf if hi == math.inf else math.floor((hi + _LIMIT_SLACK - x) / _TWO_PI)
    return first, last


def _turns(q):
    """Per joint, every value of q's joint inside LIMITS (revolute: x + 2 pi k, nearest to
    zero first; an unlimited revolute joint only its wrapped value); [] if some has none."""
    options = []
    for x, r, (lo, hi) in zip(q, _REVOLUTE, LIMITS):
        first, last = _turn_range(x, lo, hi) if r else (0, 0)
        if (not r and not lo - _LIMIT_SLACK <= x <= hi + _LIMIT_SLACK) or first > last:
            return []
        if math.isinf(first) or math.isinf(last):
            options.append([x])
            continue
        if last - first >= MAX_TURN_ROWS:
            raise ValueError(
                f"all_turns: joint limits allow more than MAX_TURN_ROWS = {MAX_TURN_ROWS} turns"
            )
        options.append(sorted((x + k * _TWO_PI for k in range(first, last + 1)), key=abs))
    return options


def warmup() -> bool:
    """Compile (or load from the cache) the C solver now, not at the first ik: call it at a
    program's start. Returns whether the C solver is available."""
    return _native_solver(None) is not None
