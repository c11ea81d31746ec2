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
joints keep the caller's values). The C solver's dk_refine takes the same steps, but turns
the joints' cos and sin by the step's, from their series (no library call), multiplies by
1 / REACH where this divides, and takes the last step (from an error within _REFINE_LAST) with
the step before's Jacobian and factor: the two agree to ~1e-13.
"""

from __future__ import annotations

import math
from operator import mul as _mul

from derive.runtime.arm import (
    _CHAIN,
    _REVOLUTE,
    _SEED_TOL,
    _SOLVED,
    CONE_AXIS,
    IK_COMPONENTS,
    REACH,
    TOOL_AXIS,
)
from derive.runtime.constants import (
    _CURVE_BEND,
    _CURVE_FLAT,
    _CURVE_FLOOR,
    _CURVE_NEAR,
    _STALL_NEAR,
    _TWO_PI,
)
from derive.runtime.scalar import _LOOSE, _Free, _ray_gap

# at most this many steps per candidate (a seed on a singular configuration converges
# linearly); a step longer than _REFINE_STRIDE (radians, or
# REACH of length) is shortened to it, so that a far seed does not jump branches
_REFINE_STEPS = 60
_REFINE_STRIDE = 0.5
# done at this pose error (a few roundings); given up after this many steps in a row that
# do not reduce it; the step from an error within _REFINE_LAST (that reduced it) is the last
_REFINE_DONE = 1e-14
_REFINE_PATIENCE = 10
_REFINE_LAST = 1e-10
# ... if it is at most this many times that error long (else measured: near a singular
# configuration Newton's step can be long, and miss)
_REFINE_TRUST = 100.0
# a refined row is returned if its pose error is within the smaller of this and ik's tol
_REFINE_TOL = 1e-10
# ... or of this in ik's second pass (no row within _REFINE_TOL): at a singular configuration
# of the nominal arm (an IRB 4600's wrist centre on axis 1, sigma_min 2e-10) the exact arm's
# solutions lie in a valley whose floor the damped and QR steps stall on at 1e-10 to 2e-10
_REFINE_STALL = 1e-9
# where the damped steps give up (_REFINE_PATIENCE steps without a better point) within this
# and above _REFINE_DONE, Gauss-Newton steps by QR (_qr_solve) go on from the best point met:
# at a singular solution (a pose on the wrist's or the shoulder's singular set) the normal
# equations' steps alternate between damped and overshooting ones and stall 1e-10 to 1e-9
# short of it, and 4 of 8,400 such poses of zoo URDF arms got no row (a new user's attack)
_REFINE_SETTLE = 1e-6
# a step no longer than this from an error above _REFINE_SETTLE: a stationary point of the
# error, no solution (a look-at seed aimed away from its point, whose error is the point's
# distance behind the camera, took _REFINE_PATIENCE steps of 1e-16 to give up); the seed ends
# there, as it would have after them
_REFINE_STILL = 1e-12
# an exact table's row certified within ik's tol but not within this is polished (_keep): a
# far look-at point's rows came within 1e-10 of the ray by the certification's largest
# entry and 1.5e-10 by its length (a new user's attack); with 1e-10 here, as ik's tol, a
# Stretch head's rows 5.7 reaches from its point were left 0.9e-10 off by the largest entry
# and 1.36e-10 by the length (2.3e-11 rad; a new user's, helper 63): 1e-11 keeps the length
# within 1e-10 (entries within 1e-11, the length within sqrt(3) times that)
_REFINE_POLISH = 1e-11
# ... with this patience (and _REFINE_STEPS / _REFINE_PATIENCE times as many steps at most):
# a row taken at a fold lies on a singular configuration, where the damped steps cross a
# plateau before they converge (an OpenArm's elbow 1e-7 from straight: rows 1e-9 to 1.7e-8
# off with 10, none beyond 1e-10 with 50; 1e-8 from straight, 2 of 172 beyond 1e-9)
_REFINE_POLISH_PATIENCE = 50
# in ik's second pass (no row in the first) an exact table's row within this of the pose,
# though not within ik's tol, is polished too, and kept if that brings it within tol (_keep):
# a myCobot 320's elbow and wrist 1e-10 rad from straight, the elbow's law of cosines solved
# at its boundary, left rows 1.04e-6 from the pose (with tol 1e-6: no row) and 1e-13 once
# polished; a pose out of reach by more than this gives no seed within it
_LOOSE_REACH = 1e-4
# ... and the second pass keeps rows within this (or ik's tol, if smaller) only: near a
# singular configuration of an exact table that nearly has a curve of solutions (ManiSkill's
# SO100 URDF, pi/2 written 1.5708, its wrist straight) the polish stops at the error's local
# least, 4e-8 to 2e-7 from the pose, which is no solution; where the pose is singular to
# rounding (a myCobot 320's elbow and wrist 1e-10 from straight, sigma_min 1e-17) the rows
# stall at up to 2.7e-9 (200 poses), and they are the answer
_LOOSE_TOL = 1e-8
# in ik's second pass (no row in the first) a nominal table's seed whose pose error is beyond
# _SEED_TOL but within _TRIAL_SEED is refined for a trial first (_REFINE_STEPS /
# _REFINE_PATIENCE times _TRIAL_PATIENCE steps at most, given up after _TRIAL_PATIENCE in a row
# that do not reduce the error), and refined in full where the trial brings it within
# _SEED_TOL: a pose near two singular configurations at once (an ARX5 MJCF's wrist within 1e-2
# of straight and its shoulder singular to 5e-9; the table 1.4e-5 from the arm) left every seed
# 1e-2 to 0.15 from it, and ik answered nothing where ik_approximate's refined seeds reached it
# to 1e-15 (a new user's attack, helper 70); a pose out of reach by more than _TRIAL_SEED
# costs nothing more
_TRIAL_SEED = 0.2
_TRIAL_PATIENCE = 2
# a nominal table's arm whose certified rows are odd in number (real solutions pair up where
# the pose is regular) looks for the missed one across a fold (_fold_partners): from each row
# where J's least singular value is within _PARTNER_NEAR (_least_direction), seeds at +- each
# of _PARTNER_STEPS along the direction J nearly loses, refined and certified as _seed's: a
# pybullet xArm6 URDF's pairs 8e-4 to 4.7e-3 rad apart near its shoulder's and wrist's
# singular sets (sigma_min 2e-5 to 3e-5) lost a row in C or Python, with it the sampled vector
# (a new user's attack, helper 70; the rows those pairs were missed beside had least singular
# values 4e-8 to 6e-5); not from a row whose least singular value is below _PARTNER_FLOOR,
# singular to roundings: at a CAD PUMA's straight wrist (q4 = q5 = 0) the exact arm's rows
# there (3e-12 to 4e-11) lie on a valley of points within 1e-10 of the pose, and the seeds
# refined onto other points of it, C keeping one more than Python at 3 of 30 poses; with 1e-6
# both agreed there but the xArm6's misses came back (Python 2 -> 7 of 1,076); and from each
# three revolute joints' flip (q_i + pi, -q_i+1, q_i+2 + pi: a spherical wrist's other
# solution, exact on the nominal table): a Kinova j2s6s200's wrist 1e-8 to 1e-7 rad from
# straight (sigma_min 1.7e-9 to 1.7e-8) had 7 rows, the sampled vector's partner the wrist's
# flip, 2.6 rad away in q4 and q6 (helper 72)
_PARTNER_NEAR = 1e-2
_PARTNER_FLOOR = 1e-9
_PARTNER_STEPS = (1e-3, 4e-3, 1.6e-2, 6.4e-2)
# ... and, where every solved joint turns, seeds a quarter turn either way and a half turn
# along that direction (its largest joint turned by these many radians): near a self-motion
# of the nominal arm (two axes nearly in line) the exact arm's solutions are isolated points
# of the broken circle, and the missed one can lie across it. pib-sdk's humanoid right arm
# (URDF, nominal table 2.4e-4 from it), its axes 3 and 5 2.5e-3 rad from in line (sigma_min
# 1.35e-4): 7 rows, the sampled vector 2.8 rad along q3 - q5 from the row beside it (a new
# user's attack, helper 74); on 300 near-singular poses of each of six such arms (calibrated
# UR5, KR6 and PUMA, the pib arm, the xArm6 URDF and Menagerie's M1013) 8 counts went from odd
# to even, the sampled vector found at 3 poses more, no count went down
_PARTNER_TURNS = (math.pi / 2, -math.pi / 2, math.pi)
# ik_approximate's least squares: at most this many steps, done where the gradient of half
# the squared error is this flat
_LSQ_STEPS = 200
_LSQ_FLAT = 1e-13


def _seed(found, t, q, tol, frees=()):
    """Append q refined onto the exact chain if its pose there reproduces the target t (the
    12 top entries) within tol and _REFINE_TOL (rotation entries; positions within that times
    REACH; _REFINE_STALL in ik's second pass). frees: (values, arm joint index) of the steps
    whose joint can be free: a joint whose step's values are _Free (the pose left it free on
    the nominal table: it took q_ref's value, or a step from it) is first held there, and
    moves only where holding does not reach the tolerance (on the exact arm, nearly singular
    there, Newton's steps along the near-null direction would otherwise carry it anywhere,
    away from q_ref)."""
    held = [i for values, i in frees if values.__class__ is _Free]
    limit = min(tol, _REFINE_STALL if _LOOSE.near else _REFINE_TOL)
    if _LOOSE.near and not _seed_near(q, t):
        return  # (ik's second pass: a seed this far is a pose out of reach, not noise)
    if held:
        moved, size = _refine(q, t, held)
        if size <= limit:
            found.append(_curve_row(found, t, moved, limit))
            return
    q, size = _refine(q, t)
    if _LOOSE.on:  # (ik_approximate keeps every seed)
        found.append(q)
    elif size <= limit:
        found.append(_curve_row(found, t, q, limit))


def _seed_near(q, t):
    """Whether ik's second pass refines the seed q towards t: its pose error within _SEED_TOL,
    or within _TRIAL_SEED and brought within _SEED_TOL by a trial (_TRIAL_PATIENCE; the C
    solver's dk_seed_near)."""
    size = _pose_error(q, t, False)[2]
    if size <= _SEED_TOL:
        return True
    return size <= _TRIAL_SEED and _refine(q, t, (), _TRIAL_PATIENCE)[1] <= _SEED_TOL


def _fold_partners(rows, t, tol):
    """rows (finished: wrapped, no repeats) and, where their number is odd on a nominal table's
    arm solved for the whole pose by six joints, the rows its refinement reaches from either
    side of a fold at each row near one (_PARTNER_NEAR, _PARTNER_FLOOR, _PARTNER_STEPS), across
    the circle of a self-motion the exact arm breaks (_PARTNER_TURNS) and from
    each three of its solved revolute joints' flips: but a row again, one on a row's curve of
    solutions (_curve_row) and one singular to roundings itself (below _PARTNER_FLOOR); the C
    solver's dk_fold_partners."""
    if not (_SEED_TOL and len(rows) % 2 and len(_SOLVED) == 6 and IK_COMPONENTS == "pose"):
        return rows
    limit = min(tol, _REFINE_STALL if _LOOSE.near else _REFINE_TOL)
    turning = all(_REVOLUTE[i] for i in _SOLVED)  # (every solved joint turns: _PARTNER_TURNS)
    out = list(rows)
    for q in rows:
        least, v = _least_direction(_pose_error(q, t, False)[1])
        if not _PARTNER_FLOOR * _PARTNER_FLOOR <= least <= _PARTNER_NEAR * _PARTNER_NEAR:
            continue
        seeds = []
        for h in _PARTNER_STEPS:
            for sign in (1.0, -1.0):
                seed = list(q)
                for k, i in enumerate(_SOLVED):
                    seed[i] += sign * h * v[k]
                seeds.append(seed)
        if turning:  # (across a broken self-motion's circle)
            top = max(abs(x) for x in v)
            for turn in _PARTNER_TURNS:
                seed = list(q)
                for k, i in enumerate(_SOLVED):
                    seed[i] += turn * v[k] / top
                seeds.append(seed)
        for i in range(len(q) - 2):  # (each three solved revolute joints' flip; a free joint
            # keeps the caller's value)
            if all(_REVOLUTE[j] and j in _SOLVED for j in (i, i + 1, i + 2)):
                seed = list(q)
                seed[i], seed[i + 1], seed[i + 2] = q[i] + math.pi, -q[i + 1], q[i + 2] + math.pi
                # (a flip that is no solution of the nominal table is not refined: seeds
                # that do not converge took most of the search's time, +35 to 70% on a
                # near-singular sampler's xArm6 poses)
                if _pose_error(seed, t, False)[2] <= _SEED_TOL:
                    seeds.append(seed)
        for seed in seeds:
            p, size = _refine(seed, t)
            if size > limit or _curve_row(out, t, p, limit, False) is not p:
                continue
            # (a row singular to roundings lies on a valley or curve of solutions whose rows
            # the first pass gave: a flip's seed at a Kinova's straight wrist refined onto a
            # point 3.5e-3 from one)
            if _least_direction(_pose_error(p, t, False)[1])[0] >= _PARTNER_FLOOR**2:
                out.append(p)
    return out


def _least_direction(columns):
    """J^T J's least eigenvalue (J's columns given: square) and its unit eigenvector, by two
    steps of inverse iteration from (1, ..., 1), each (J^T J)^-1 v = J^-1 J^-T v by Householder's
    QR with J^T, then J (_qr_solve: J's own condition; the normal equations' square stopped the
    estimate of J's least singular value near 1e-8 where it was 6e-13, and a singular wrist's
    rows took the search, which added points of its curve of solutions: helper 72); the
    eigenvalue 1 over the last step's growth (the C solver's dk_least_direction)."""
    m = len(columns)
    rows = [[column[r] for column in columns] for r in range(m)]  # (J^T's columns)
    v = [1.0 / math.sqrt(m)] * m
    least = 0.0
    for _ in range(2):
        w = _qr_solve(columns, _qr_solve(rows, v))
        size = math.sqrt(_dot(w, w))
        if not 0.0 < size < math.inf:
            return 0.0, v
        v, least = [x / size for x in w], 1.0 / size
    return least, v


def _curve_row(found, t, q, limit, replace=True):
    """The first row of found that q repeats (that row again, a repeat _finish drops), else q
    (the C dk_same_row): within _CURVE_NEAR (revolute joints around the circle, lengths over
    REACH), both on one curve of solutions, their midpoint reproducing t within limit and
    _CURVE_FLAT times the smaller of their errors (or _CURVE_FLOOR); or within _STALL_NEAR, points
    where the refinement stalled beside one solution (_stalled_beside): where that is q or
    another point (with replace), it takes the row's place in found, and is returned."""
    for p in found:
        d = []
        for a, b, turn in zip(q, p, _REVOLUTE):  # (to the first joint that differs)
            x = math.remainder(a - b, _TWO_PI) if turn else a - b
            if not (abs(x) if turn else abs(x) / REACH) <= _STALL_NEAR:
                break
            d.append(x)
        else:
            far = max(abs(x) if turn else abs(x) / REACH for x, turn in zip(d, _REVOLUTE))
            mid = [b + 0.5 * x for b, x in zip(p, d)]
            ends = (_pose_error(p, t, False)[2], _pose_error(q, t, False)[2])
            if far <= _CURVE_NEAR:
                at = _pose_error(mid, t, False)[2]
                if at <= limit and at <= _CURVE_FLAT * max(min(ends), _CURVE_FLOOR):
                    return p
            kept = _stalled_beside(p, q, mid, t, ends, far, limit)
            if kept is not None and kept is not p and replace:  # (the row stalled: in its
                # place the better point)
                found[:] = [kept if r is p else r for r in found]
                return kept
            if kept is not None:
                return p
    return q


def _stalled_beside(p, q, mid, t, ends, far, limit):
    """Where rows p and q (errors ends, far apart, mid their midpoint) are points where the
    refinement stalled on a valley of points within limit of t that a pose nearly singular
    makes, beside a solution, that solution: mid refined, m, lands within far of mid, the worse
    of them is not within _CURVE_FLAT times m's error (or _CURVE_FLOOR) and J's least singular
    value there times far is within limit (the valley between them within limit); then the
    better row where it is within that of m and m lands within _CURVE_BEND far of it, else m
    (a Lite6 MJCF's pose singular to 6e-9 had rows 5.5e-11 and 1.2e-11 off, 3.6e-3 and 9e-4
    from one within 5.6e-16; at another, singular to 2.9e-9, rows 8.7e-12 to 9.9e-11 off, 1e-3
    to 1.3e-2 apart, round a solution none had reached; C kept 16 such, the room for rows, and
    lost the other elbow's: a new user's attack, helper 73). Else None. Two solutions of a
    fold's pair are both within it, or one stalled where J is not that singular (an xArm6's
    1e-3 to 1e-2 apart at poses singular to 1.4e-6 and 1.3e-5), and the midpoint's refinement
    stops at the fold or lands on either. Only an arm solved for the whole pose by six joints
    (J square)."""
    if not (len(_SOLVED) == 6 and IK_COMPONENTS == "pose"):
        return None
    if not max(ends) > _CURVE_FLAT * _CURVE_FLOOR:  # (both exact: neither stalled)
        return None
    (better, worse) = (p, q) if ends[0] <= ends[1] else (q, p)
    least = _least_direction(_pose_error(worse, t, False)[1])[0]
    if not math.sqrt(least) * far <= limit:
        return None
    moved = _refine(mid, t)[0]
    exact = _CURVE_FLAT * max(_pose_error(moved, t, False)[2], _CURVE_FLOOR)
    if not (max(ends) > exact and _joint_distance(moved, mid) <= far):
        return None
    if min(ends) <= exact:
        return better if _joint_distance(moved, better) <= _CURVE_BEND * far else None
    return moved


def _joint_distance(a, b):
    """The largest difference of joint values a and b (revolute joints around the circle,
    lengths over REACH)."""
    return max(
        abs(math.remainder(x - y, _TWO_PI) if turn else (x - y) / REACH)
        for x, y, turn in zip(a, b, _REVOLUTE)
    )


def _refine(q, t, held=(), patience=_REFINE_PATIENCE):
    """q after Newton's steps towards t on the exact chain (the best point met), and its pose
    error there (the largest rotation entry's difference, or position difference / REACH);
    the joints in held (arm indices) keep their values; given up after `patience` steps in a
    row that do not reduce the error. Plain floats: numpy's calls cost more than this size
    of arithmetic."""
    m = len(_SOLVED)
    cur = [float(x) for x in q]
    best, best_size, worse, settle = list(cur), math.inf, 0, False
    for _ in range(_REFINE_STEPS // _REFINE_PATIENCE * patience):
        error, columns, size = _pose_error(cur, t, False)
        if size < best_size:
            best, best_size, worse = list(cur), size, 0
        else:  # (near a singular configuration the error can grow before it converges)
            worse += 1
        if worse == patience and not settle and best_size <= _REFINE_SETTLE:
            settle, worse, cur = True, 0, list(best)  # (Gauss-Newton by QR from the best)
            continue
        if size <= _REFINE_DONE or worse == patience:
            break
        last = size <= _REFINE_LAST and worse == 0 and not settle
        if held:  # (a held joint's column 0, its row of the normal equations the identity's)
            columns = [[0.0] * len(c) if _SOLVED[k] in held else c for k, c in enumerate(columns)]
        if settle:
            step = _qr_solve(columns, error)
        else:
            mu = _dot(error, error)
            step = [_dot(column, error) for column in columns]
            normal = [[0.0] * m for _ in range(m)]
            for i in range(m):  # (J^T J is symmetric: its lower triangle, mirrored)
                for j in range(i + 1):
                    normal[i][j] = normal[j][i] = _dot(columns[i], columns[j])
                normal[i][i] += mu
            for k in range(m):
                if _SOLVED[k] in held:
                    normal[k][k] = 1.0
            if not _cholesky_solve(normal, step):  # (J^T J singular to roundings: a singular
                # solution near; given up as after `patience` steps, so Gauss-Newton by
                # QR goes on from the best point where that is within _REFINE_SETTLE)
                worse = patience - 1
                continue
        longest = max(map(abs, step))
        if not longest < math.inf or (
            longest <= _REFINE_STILL and size > _REFINE_SETTLE and not settle
        ):
            break
        shrink = _REFINE_STRIDE / longest if longest > _REFINE_STRIDE else 1.0
        for k, i in enumerate(_SOLVED):
            cur[i] += step[k] * shrink
        if last and longest <= _REFINE_TRUST * size:
            best = cur  # (Newton's step from there: the error squared, not measured)
            break
    return tuple(best), best_size


def _qr_solve(columns, e):
    """The least-squares solution x of J x = e, J's columns given (each as long as e), by
    Householder's QR factorisation: the normal equations square J's condition number, which
    a singular solution makes large as q nears it. A column the reflections leave empty (a
    held joint's) gets x = 0. (The C solver's dk_qr_solve.)"""
    A = [list(c) for c in columns]
    b = list(e)
    rows, m = len(b), len(A)
    diag = [0.0] * m
    for k in range(m):
        norm = math.sqrt(sum(A[k][i] * A[k][i] for i in range(k, rows)))
        head = A[k][k] if k < rows else A[k][0]
        diag[k] = -norm if head > 0.0 else norm
        if norm == 0.0:
            continue
        vv = 2.0 * norm * (norm + abs(A[k][k]))  # (v = the column - diag e_k: v^T v)
        A[k][k] -= diag[k]
        for j in range(k + 1, m):  # (I - 2 v v^T / v^T v) on the columns after, and on b
            s = sum(A[k][i] * A[j][i] for i in range(k, rows)) * (2.0 / vv)
            for i in range(k, rows):
                A[j][i] -= s * A[k][i]
        s = sum(A[k][i] * b[i] for i in range(k, rows)) * (2.0 / vv)
        for i in range(k, rows):
            b[i] -= s * A[k][i]
    x = [0.0] * m
    for k in range(m - 1, -1, -1):  # R x = Q^T b
        s = b[k] if k < rows else 0.0
        for j in range(k + 1, m):
            s -= (A[j][k] if k < rows else 0.0) * x[j]
        x[k] = 0.0 if diag[k] == 0.0 else s / diag[k]
    return x


def _least_squares(q, t):
    """q moved to a least-squares point of the pose error towards t on the exact chain
    (Levenberg-Marquardt, its damping adapted to each step's success): ik_approximate's
    nearest configuration of q's branch where t is out of reach."""
    m = len(_SOLVED)
    cur = [float(x) for x in q]
    error, columns, _ = _pose_error(cur, t, True)
    value = 0.5 * sum(e * e for e in error)
    damping = 1e-3
    for _ in range(_LSQ_STEPS):
        gradient = [_dot(column, error) for column in columns]
        if max(map(abs, gradient)) <= _LSQ_FLAT:
            break
        normal = [[sum(a * b for a, b in zip(columns[i], columns[j])) for j in range(m)]
                  for i in range(m)]  # fmt: skip
        for i in range(m):
            normal[i][i] += damping * (normal[i][i] + 1e-12)
        step = list(gradient)
        if not _cholesky_solve(normal, step):
            damping *= 4.0
            continue
        trial = list(cur)
        for k, i in enumerate(_SOLVED):
            trial[i] += step[k]
        trial_error, trial_columns, _ = _pose_error(trial, t, True)
        trial_value = 0.5 * sum(e * e for e in trial_error)
        if trial_value < value:
            cur, error, columns, value = trial, trial_error, trial_columns, trial_value
            damping = max(damping / 3.0, 1e-12)
        else:
            damping *= 4.0
            if damping > 1e12:
                break
    return tuple(cur)


def _pose_error(q, t, exact):
    """The pose error towards t at q on the exact chain: the residual (positions divided by
    REACH; with IK_COMPONENTS "pose", the rotation error 1/2 sum_k r_k x t_k), the columns of
    its Jacobian (minus the residual's derivative) for the joints in _SOLVED, and its size
    (the largest rotation entry's difference, or position difference / REACH). Exact: the
    rotation rows are the error's own derivative, 1/2 sum_k t_k x (z x r_k); else the
    geometric Jacobian's z, which they equal where the error vanishes (Newton's steps).
    The tasks (derive/tasks.py): "direction" has the rotation rows u x t_u (u the tool axis
    TOOL_AXIS, t_u the target's), derivative t_u x (z x u); "pointing" has those and no
    position error (its rows 0); "lookat" has, as its three rows, minus the target point's
    offset from the ray, v - (v.u) u with v = p - o, / REACH; "axisangle" has, as its fourth
    row, the tool axis's component along the base axis CONE_AXIS, t_c - u_c, derivative
    (z x u)_c."""
    task, x = IK_COMPONENTS, TOOL_AXIS
    rows = 6 if task in ("pose", "direction", "pointing") else 4 if task == "axisangle" else 3
    pose, axes, origins = _chain_pose(q)
    error = [(t[4 * r + 3] - pose[4 * r + 3]) / REACH for r in range(3)]
    size = max(map(abs, error))
    u = (pose[x], pose[4 + x], pose[8 + x])
    v = [t[4 * r + 3] - pose[4 * r + 3] for r in range(3)]
    along = v[0] * u[0] + v[1] * u[1] + v[2] * u[2]
    if task == "pose":
        for r in range(3):
            a, b = 4 * ((r + 1) % 3), 4 * ((r + 2) % 3)
            error.append(
                0.5 * sum(pose[a + k] * t[b + k] - pose[b + k] * t[a + k] for k in range(3))
            )
            size = max(size, abs(t[4 * r] - pose[4 * r]), abs(t[4 * r + 1] - pose[4 * r + 1]),
                       abs(t[4 * r + 2] - pose[4 * r + 2]))  # fmt: skip
    elif task in ("direction", "pointing"):
        if task == "pointing":
            error, size = [0.0, 0.0, 0.0], 0.0
        for r in range(3):
            a, b = 4 * ((r + 1) % 3) + x, 4 * ((r + 2) % 3) + x
            error.append(pose[a] * t[b] - pose[b] * t[a])
            size = max(size, abs(t[4 * r + x] - pose[4 * r + x]))
    elif task == "lookat":
        error = [-(v[r] - along * u[r]) / REACH for r in range(3)]
        size = _ray_gap(pose, t, x) / REACH
    elif task == "axisangle":
        k = 4 * CONE_AXIS + x
        error.append(t[k] - pose[k])
        size = max(size, abs(t[k] - pose[k]))
    columns = []
    for i in _SOLVED:
        z, o = axes[i], origins[i]
        if _REVOLUTE[i]:
            dx, dy, dz = pose[3] - o[0], pose[7] - o[1], pose[11] - o[2]
            column = [(z[1] * dz - z[2] * dy) / REACH, (z[2] * dx - z[0] * dz) / REACH,
                      (z[0] * dy - z[1] * dx) / REACH, z[0], z[1], z[2]]  # fmt: skip
            du = (z[1] * u[2] - z[2] * u[1], z[2] * u[0] - z[0] * u[2], z[0] * u[1] - z[1] * u[0])
            if exact and rows == 6 and task == "pose":
                column[3:] = [0.0, 0.0, 0.0]
                for k in range(3):
                    r_k = (pose[k], pose[4 + k], pose[8 + k])
                    t_k = (t[k], t[4 + k], t[8 + k])
                    w = (z[1] * r_k[2] - z[2] * r_k[1], z[2] * r_k[0] - z[0] * r_k[2],
                         z[0] * r_k[1] - z[1] * r_k[0])  # fmt: skip
                    column[3] += 0.5 * (t_k[1] * w[2] - t_k[2] * w[1])
                    column[4] += 0.5 * (t_k[2] * w[0] - t_k[0] * w[2])
                    column[5] += 0.5 * (t_k[0] * w[1] - t_k[1] * w[0])
        else:
            column = [z[0] / REACH, z[1] / REACH, z[2] / REACH, 0.0, 0.0, 0.0]
            du = (0.0, 0.0, 0.0)
        if task in ("direction", "pointing"):
            tu = (t[x], t[4 + x], t[8 + x])
            column[3:] = [tu[1] * du[2] - tu[2] * du[1], tu[2] * du[0] - tu[0] * du[2],
                          tu[0] * du[1] - tu[1] * du[0]]  # fmt: skip
            if task == "pointing":
                column[:3] = [0.0, 0.0, 0.0]
        elif task == "axisangle":
            column[3] = du[CONE_AXIS]
        elif task == "lookat":
            dv = [-column[r] * REACH for r in range(3)]
            dalong = sum(dv[r] * u[r] + v[r] * du[r] for r in range(3))
            column[:3] = [(dv[r] - dalong * u[r] - along * du[r]) / REACH for r in range(3)]
        columns.append(column[:rows])
    return error, columns, size


def _cholesky_solve(A, x):
    """x := A^-1 x (in place) for the symmetric positive definite A (overwritten by its
    Cholesky factor); False where A is not positive definite."""
    m = len(x)
    for j in range(m):
        d = A[j][j] - _dot(A[j][:j], A[j][:j])
        if not d > 0.0:
            return False
        A[j][j] = math.sqrt(d)
        for i in range(j + 1, m):
            A[i][j] = (A[i][j] - _dot(A[i][:j], A[j][:j])) / A[j][j]
    for i in range(m):
        x[i] = (x[i] - _dot(A[i][:i], x[:i])) / A[i][i]
    for i in reversed(range(m)):
        x[i] = (x[i] - _dot([A[k][i] for k in range(i + 1, m)], x[i + 1 :])) / A[i][i]
    return True


def _dot(a, b):
    """a_1 b_1 + a_2 b_2 + ..., summed in order (as sum() of a generator, in a third of its
    time: the refinement's normal equations and their factor were most of a refined arm's
    Python time)."""
    return sum(map(_mul, a, b))


def _chain_jacobian(q):
    """The geometric Jacobian at the tool point in the world (linear velocity over angular
    velocity) of the exact chain at q, 6 * DOF entries row-major: column i is
    (z_i x (p - o_i), z_i) for a revolute joint, (z_i, 0) for a prismatic one. An arm with
    exact frames (a URDF's) computes its Jacobian so (_jacobian_q), rather than from printed
    expressions, whose common subexpressions took half of such an arm's generation."""
    pose, axes, origins = _chain_pose(q)
    n = len(_REVOLUTE)
    J = [0.0] * (6 * n)
    for i, (z, o) in enumerate(zip(axes, origins)):
        if _REVOLUTE[i]:
            dx, dy, dz = pose[3] - o[0], pose[7] - o[1], pose[11] - o[2]
            J[i] = z[1] * dz - z[2] * dy
            J[n + i] = z[2] * dx - z[0] * dz
            J[2 * n + i] = z[0] * dy - z[1] * dx
            J[3 * n + i], J[4 * n + i], J[5 * n + i] = z
        else:
            J[i], J[n + i], J[2 * n + i] = z
    return J


def _chain_pose(q):
    """The exact chain's pose at q (12 floats, the top three rows), with each joint's axis
    and a point on it (world frame)."""
    pose = list(_CHAIN[0])
    axes, origins = [], []
    for i, revolute in enumerate(_REVOLUTE):
        axes.append((pose[2], pose[6], pose[10]))
        origins.append((pose[3], pose[7], pose[11]))
        if revolute:
            c, s = math.cos(q[i]), math.sin(q[i])
            for r in (0, 4, 8):
                x, y = pose[r], pose[r + 1]
                pose[r], pose[r + 1] = c * x + s * y, c * y - s * x
        else:
            for r in (0, 4, 8):
                pose[r + 3] += q[i] * pose[r + 2]
        f = _CHAIN[i + 1]
        for r in (0, 4, 8):
            p0, p1, p2, p3 = pose[r], pose[r + 1], pose[r + 2], pose[r + 3]
            pose[r] = p0 * f[0] + p1 * f[4] + p2 * f[8]
            pose[r + 1] = p0 * f[1] + p1 * f[5] + p2 * f[9]
            pose[r + 2] = p0 * f[2] + p1 * f[6] + p2 * f[10]
            pose[r + 3] = p0 * f[3] + p1 * f[7] + p2 * f[11] + p3
    return pose, axes, origins
