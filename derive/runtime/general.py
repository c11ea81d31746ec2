"""The general 6R method at run time, in the Python solver (numpy's LAPACK).

The arm's printed code gives, per split (the arm's chain, or its reversal), the flange target
in the split's standard-DH frame (12 numbers) and fills the Raghavan-Roth matrices P0, Ps, Pc
and Q (``_rr_fill``). From there the steps are the same for every arm (docs/algorithms.md,
"The general 6R method"):

1. the left null space N of Q (SVD) removes theta1 and theta2: N P(theta3) m45 = 0;
2. the half-angle substitution and the dialytic lift give a 12 x 12 quadratic matrix
   polynomial in y, x3 = tan(theta3 / 2) = (a y + b) / (c y + d) (a Moebius map, so that
   theta3 = pi is a finite y); its real eigenvalues (24 x 24 companion matrix) give theta3;
3. the null space of the matrix at each eigenvalue (SVD) gives theta4 and theta5 (its
   variables are x = tan((theta - shift) / 2), shifts _RR_SHIFT45, so that theta4, theta5 =
   pi are finite too); a two-dimensional one (two solutions sharing theta3) is split by the
   monomial structure; a nearly real pair of eigenvalues (theta3's imaginary part within
   _RR_PAIR_ANGLE) is also tried at theta3's real part -+ that, as optional candidates;
4. theta1, theta2 by least squares from Q m12 = P m45, theta6 from the pose;
5. Newton steps on the arm's forward kinematics polish every candidate, then, where they do
   not converge (a pose with a curve of solutions), Levenberg-Marquardt steps.

A pose whose answer is in doubt (a candidate that does not polish, eigenvalues in a cluster,
an odd number of solutions, none at all) is solved again with the runner-up split and then
from slightly moved poses (a rescue), every candidate polished back onto the true pose; the
union of what certifies is returned. Where still nothing polishes but the pose looks like one
on a curve of solutions (a pencil on the arm's own table singular, or candidates that stopped
short), damped steps from those candidates and from fixed starting points look for the curve
(_rr_search). The tolerances are stated beside their values in derive/runtime/constants.py.
"""

from __future__ import annotations

import math

import numpy as np

from derive.runtime.arm import (
    _RR_FLIPS,
    _RR_LENGTH,
    _RR_PIVOTS,
    _RR_SPLITS,
    _RR_SPURIOUS,
    _RR_SPURIOUS_COUNT,
    _SEED_TOL,
    MAX_SOLUTIONS,
    _rr_fill,
)
from derive.runtime.constants import (
    _RR_CLUSTER_TOL,
    _RR_COND_LIMIT,
    _RR_DAMPED_FROM,
    _RR_FOLD_NEAR,
    _RR_FOLD_STEP,
    _RR_GOOD,
    _RR_IMAG_LOOSE,
    _RR_IMAG_TOL,
    _RR_MOEBIUS,
    _RR_NEAR,
    _RR_NEAR_SINGULAR,
    _RR_NEWTON_DONE,
    _RR_NEWTON_REACH,
    _RR_NEWTON_STEPS,
    _RR_NULL2_TOL,
    _RR_PAIR_ANGLE,
    _RR_PAIR_DOUBT,
    _RR_PAIR_TOL,
    _RR_PATH,
    _RR_PATH_STEPS,
    _RR_RANK_TOL,
    _RR_RESCUE,
    _RR_SAME,
    _RR_SEARCH_BAIL,
    _RR_SEARCH_FROM,
    _RR_SEARCH_SLIDE,
    _RR_SEARCH_STEPS,
    _RR_SETTLED,
    _RR_SHIFT45,
    _RR_SINGULAR,
    _TWO_PI,
)


def _rr_half_angle(shift):
    """The coefficients over (1, x, x^2) of (1 + x^2) sin t, (1 + x^2) cos t and 1 + x^2 for
    x = tan((t - shift) / 2): sin t = sin shift c' + cos shift s' and cos t = cos shift c' -
    sin shift s' with s' (1 + x^2) = 2x and c' (1 + x^2) = 1 - x^2."""
    cs, ss = math.cos(shift), math.sin(shift)
    return (ss, 2.0 * cs, -ss), (cs, -2.0 * ss, -cs), (1.0, 0.0, 1.0)


# m45 (1 + x4^2)(1 + x5^2) = _RR_H45 [x4^i x5^j], column 3 i + j (docs/algorithms.md,
# "Half-angles, the dialytic lift and the eigenproblem", with the half-angles of
# _RR_SHIFT45): rows are outer products of _rr_half_angle's coefficients
_RR_S4, _RR_C4, _RR_O4 = _rr_half_angle(_RR_SHIFT45[0])
_RR_S5, _RR_C5, _RR_O5 = _rr_half_angle(_RR_SHIFT45[1])
_RR_H45 = np.array(
    [
        [u[i] * w[j] for i in range(3) for j in range(3)]
        for u, w in zip(
            (_RR_S4, _RR_S4, _RR_C4, _RR_C4, _RR_S4, _RR_C4, _RR_O4, _RR_O4, _RR_O4),
            (_RR_S5, _RR_C5, _RR_S5, _RR_C5, _RR_O5, _RR_O5, _RR_S5, _RR_C5, _RR_O5),
        )
    ]
)
# _rr_search's starting points (split values; a sliding joint 3's scaled to _RR_SEARCH_SLIDE):
# deterministic numbers spread over the joints' turns, any such do
_RR_SEARCH_STARTS = math.pi * np.sin(np.outer(np.arange(1, 65), np.arange(1, 7)) * 2.113 + 0.5)
# fixed combinations of the rows of a null space of Q with more than six rows (a Q of rank
# below 8): deterministic numbers, any generic ones do
_RR_MIX = np.sin(np.outer(np.arange(1, 7), np.arange(1, 15)) * 0.731 + 0.25)
# (slides, theta3) of a split whose joint 3 turns; one whose joint 3 slides has (1.0, theta3)
_RR_TURNS = (0.0, 0.0)
# the seeds of one near miss (_rr_fold_seeds): a nominal table's near misses give the
# refinement onto the exact arm at most this many times MAX_SOLUTIONS seeds, three for as many
# near misses as a pose has rows (_rr_seed_misses; C's DK_RR_SEEDS)
_RR_SEEDS_EACH = 3
# the pairs (k, k') of null-vector entries whose ratio is x5 (k' = k + 1) and x4 (k' = k + 3)
_RR_X5_PAIRS = (np.array([0, 1, 3, 4, 6, 7, 9, 10]), np.array([1, 2, 4, 5, 7, 8, 10, 11]))
_RR_X4_PAIRS = (np.arange(9), np.arange(3, 12))
# for a two-dimensional null space: the products v[i] v[j] - v[k] v[l] that vanish on a
# vector of monomials x4^a x5^b (index 3 a + b)
_RR_MONOMIAL_RULES = ((0, 4, 1, 3), (1, 5, 2, 4), (3, 7, 4, 6), (4, 8, 5, 7), (6, 10, 7, 9))


def _general(flanges, tol):
    """Every solution of the general method for one pose: a list of joint-angle tuples
    (theta_1..theta_6 of the arm), each polished; the caller certifies them.

    flanges: per split, the 12 top entries of the target in the split's frame (row-major).
    """
    found: list[np.ndarray] = []
    near: list[np.ndarray] = []
    leads = _RRLeads()
    targets = [_rr_target(f) for f in flanges]
    doubt = _RESCUE
    walked = False  # whether a perturbed table's solutions were walked back to the arm's
    grew = False  # whether the fallback split found what the first missed
    tried = 0  # (the splits the first round tried)
    # (an out-of-reach answer from the first split alone: where its table is the arm's own,
    # exact; a perturbed or nominal one's, the fallback split's too: below)
    alone = _RR_SPLITS[0][1] == _RR_SPLITS[0][2] and not _SEED_TOL
    for k, F in enumerate(targets):
        candidates, close, doubt = _rr_split(k, F, F, leads, found)
        tried += 1
        walked |= _RR_SPLITS[k][1] != _RR_SPLITS[k][2]
        before = len(found)
        _rr_merge(found, [_rr_to_arm(k, q) for q in candidates])
        grew |= k > 0 and len(found) > before
        _rr_merge(near, [_rr_to_arm(k, q) for q in close])
        if not doubt and len(found) % 2 == 0 and (found or not leads.clear or alone):
            break  # (nothing found and nothing nearly real: the fallback split too, below)
    if (
        not found
        and (tried == len(targets) or alone)
        and not doubt
        and leads.clear
        and not (near or leads.rows or leads.seeds)
        and not any(
            _RR_SPLITS[k][1] == _RR_SPLITS[k][2] and _rr_singular(k, targets[k])
            for k in range(tried)
        )
    ):
        # a pose out of reach: the first split's pencil regular, with no real eigenvalue and
        # none nearly real (no pair of the arm's solutions made complex by a perturbed
        # table's difference, as _rr_settled), and the fallback split's candidates polished
        # to nothing, not even a near miss: the rescue's moved poses, the last resort and the
        # search find nothing there, and took 9 to 17 times an answered pose's time (a new
        # user's seven-joint arms swept over q7, most of whose values leave the pose out of
        # reach: 1.3 to 2.7 ms a pose in C, helper 56). On the arm's own exact table the
        # first split's pencil says so alone (a solution would be a real eigenvalue of it);
        # on a perturbed or nominal table the fallback's candidates must find nothing too
        # (its near misses seeded the only rows of a snapped SO-101 task's pose whose first,
        # nominal, split saw nothing).
        return []
    if walked and doubt != _RESCUE and found and _rr_near_singular(found):
        doubt = _RESCUE  # (a perturbed table's continuation near where solutions meet)
    if doubt == _RESCUE or grew or not found or len(found) % 2:
        # the rescue: solve slightly moved poses, polish back onto the true one
        for motion in _RR_MOTIONS:
            for k, F in enumerate(targets):
                candidates, close, _ = _rr_split(k, F, F @ motion, leads, found)
                walked |= _RR_SPLITS[k][1] != _RR_SPLITS[k][2]
                _rr_merge(found, [_rr_to_arm(k, q) for q in candidates])
                _rr_merge(near, [_rr_to_arm(k, q) for q in close])
    if 0 < len(found) < MAX_SOLUTIONS and walked:
        # a perturbed table walks two solutions that share the eigen-joint value (the PUMA's
        # wrist flip) onto one now and then, whether the count stays even or not: their
        # partners, tried for every row found (_rr_partners), where such a table answered
        # (manocha_canny's own table answers most poses alone: 7% of its C time saved)
        _rr_merge(found, _rr_partners(targets, found))
    if len(found) % 2:
        # an odd number (real solutions pair up where the pose is regular): one was missed,
        # most likely the partner of a found one with the same eigen-joint value (the PUMA's
        # wrist flip, on a perturbed table, continued onto the found one): the search
        _rr_merge(found, _rr_search(targets, found))
    for motion in (np.eye(4), *_RR_MOTIONS):
        if found:
            break
        # the last resort: a pose whose pencil is singular (a curve of solutions) scatters
        # the eigenvalues off the real line; those within _RR_IMAG_LOOSE of it, polished
        for k, F in enumerate(targets):
            candidates, close, _ = _rr_split(k, F, F @ motion, leads, found, _RR_IMAG_LOOSE)
            _rr_merge(found, [_rr_to_arm(k, q) for q in candidates])
            _rr_merge(near, [_rr_to_arm(k, q) for q in close])
    if not found and not near and not leads.singular and not leads.rows:
        # a pencil singular to roundings at the pose, which its eigenvalues do not show
        leads.singular = any(
            _RR_SPLITS[k][1] == _RR_SPLITS[k][2] and _rr_singular(k, F)
            for k, F in enumerate(targets)
        )
    if not found and not near and (leads.singular or leads.rows):
        # a curve of solutions that none of the above reached: a search (_rr_search)
        _rr_merge(found, _rr_search(targets, leads.rows))
    if not found and not leads.seeds:
        # a singular pose, where Newton converges slowly: what came within _RR_NEAR (the
        # caller's certification decides)
        found = near
    # a self-motion (a singular pose) has a curve of solutions: at most MAX_SOLUTIONS of them
    found = found[:MAX_SOLUTIONS]
    # a nominal table's near misses, after the rows (a budget of their own, as in C): seeds
    # the caller refines onto the exact arm and certifies there (a pair of the exact arm near
    # a fold, complex on the nominal table)
    _rr_merge(found, leads.seeds)
    return [tuple(float(t) for t in q) for q in found]


def _rr_near_singular(rows):
    """Whether a row (the arm's values) is within _RR_NEAR_SINGULAR of a singular
    configuration: |det J| over the product of J's column norms (Hadamard's ratio: 1 where
    the columns are orthogonal, 0 where J is singular), J the geometric Jacobian of split 0's
    chain (lengths in units of _RR_LENGTH)."""
    _, _, true_rows, slide = _RR_SPLITS[0]
    frames = _rr_frames(np.array([_rr_from_arm(0, q) for q in rows]), true_rows, slide)
    columns = _rr_columns(frames, slide)
    norms = np.linalg.norm(columns, axis=2).prod(axis=1)
    ratios = np.abs(np.linalg.det(columns)) / np.where(norms > 0.0, norms, 1.0)
    return bool(((ratios <= _RR_NEAR_SINGULAR) | (norms <= 0.0)).any())


def _rr_fold_seeds(k, q, rows, slide):
    """Seeds for the refinement onto the exact arm from split k's values q, which damped steps
    left near the pose on a nominal table (rows): q, and q +- _RR_FOLD_STEP along the
    direction the table's Jacobian nearly loses there (two steps of inverse iteration on
    J^T J from (1, ..., 1)), where the exact arm's two solutions lie when q is near a fold;
    as the arm's values. The caller refines and certifies them."""
    v, _ = _rr_lost_direction(q, rows, slide)
    return [_rr_to_arm(k, q + h * v) for h in (0.0, _RR_FOLD_STEP, -_RR_FOLD_STEP)]


def _rr_lost_direction(q, rows, slide):
    """The unit direction the Jacobian of the split's table (rows) nearly loses at q (two
    steps of inverse iteration on J^T J from (1, ..., 1)), and the least eigenvalue of J^T J
    that estimates (1 over the last step's growth; 0 where J^T J is singular)."""
    J = _rr_columns(_rr_frames(q[None], rows, slide), slide)[0].T
    v = np.full(6, 1.0 / math.sqrt(6.0))
    least = 0.0
    for _ in range(2):
        try:
            w = np.linalg.solve(J.T @ J, v)
        except np.linalg.LinAlgError:
            least = 0.0
            break  # (singular: v is as good a direction as any)
        size = float(np.linalg.norm(w))
        if not 0.0 < size < math.inf:
            least = 0.0
            break
        v, least = w / size, 1.0 / size
    return v, least


def _rr_fold_partners(k, F, q, start, rows, slide):
    """Split k's rows near q that Newton's steps reach from q +- h along the direction the
    Jacobian nearly loses (_rr_lost_direction), h the gap between q and the
    candidate it came from (at least _RR_FOLD_STEP): the partner of a row that two candidates
    of a nearly real pair both polished onto, which lies across the fold between them; none
    where J's least singular value at q exceeds _RR_FOLD_NEAR. (The caller keeps those not
    within _RR_SAME of a row.)"""
    h = max(_RR_FOLD_STEP, float(_rr_gaps(_rr_to_arm(k, start), [_rr_to_arm(k, q)])[0]))
    v, least = _rr_lost_direction(q, rows, slide)
    if least > _RR_FOLD_NEAR**2:  # (not near a fold: a complex pair's real row, alone)
        return []
    starts = np.array([q + h * v, q - h * v])
    Q, errors = _rr_steps_many(rows, F, starts, slide, False)
    return [p for p, error in zip(Q, errors) if error <= _RR_GOOD]


class _RRLeads:
    """What the splits saw of a pose that may lie on a curve of solutions: whether a pencil
    on the arm's own table was singular at it or at a pose moved by the rescue, and the
    candidates (the arm's joint values) whose polishing stopped within _RR_SEARCH_FROM of the
    pose without settling."""

    def __init__(self):
        self.singular = False
        self.rows: list[np.ndarray] = []
        self.seeds: list[np.ndarray] = []  # (a nominal table's near misses: _rr_fold_seeds)
        # whether the first split at the pose gave no real eigenvalue and none within
        # _RR_PAIR_DOUBT (a nominal table's seeds' window, if wider) of real (_general's early
        # answer)
        self.clear = False


def _rr_partners(targets, rows):
    """The wrist-flip partners of the rows: each row with the three joints at an end that is
    a spherical wrist (_RR_FLIPS: never the end with a sliding joint) turned as its flip,
    (t1 + pi, -t2, t3 + pi), polished by Newton's steps on split 0's frame and the arm's own
    table; the arm's values of those that reach _RR_GOOD (the caller merges repeats)."""
    _, _, true_rows, slide = _RR_SPLITS[0]
    starts = []
    for q in rows:
        for first in _RR_FLIPS:
            p = np.array(q, dtype=float)
            p[first : first + 3] = (p[first] + math.pi, -p[first + 1], p[first + 2] + math.pi)
            starts.append(_rr_from_arm(0, p))
    if not starts:
        return []
    Q, errors = _rr_steps_many(true_rows, targets[0], np.array(starts), slide, False)
    return [_rr_to_arm(0, q) for q in Q[errors <= _RR_GOOD]]


def _rr_search(targets, rows):
    """The last resort of a pose whose solutions form a curve (its pencils singular, or
    polishing slow everywhere) that the eigenvalues did not reach: damped steps
    (_RR_SEARCH_STEPS of them, without _RR_NEWTON_REACH) from the leads' rows and from the
    fixed starting points _RR_SEARCH_STARTS, on split 0's frame and the arm's own table, then
    Newton's; the arm's values of those that reach _RR_GOOD."""
    _, _, true_rows, slide = _RR_SPLITS[0]
    starts = _RR_SEARCH_STARTS.copy()
    if slide[0]:  # (a sliding joint 3: the starts' values over the arm's size)
        starts[:, 2] *= _RR_SEARCH_SLIDE / math.pi
    starts = np.vstack([_rr_from_arm(0, q) for q in rows] + [starts])
    F = targets[0]
    # (a first quarter of the steps: where no row came within _RR_SEARCH_BAIL, a pose out of
    # reach, most likely, the search ends there)
    first = _RR_SEARCH_STEPS // 4
    Q, errors = _rr_steps_many(true_rows, F, starts, slide, True, math.inf, first)
    if not errors.min(initial=math.inf) <= _RR_SEARCH_BAIL:
        return []
    Q, errors = _rr_steps_many(true_rows, F, Q, slide, True, math.inf, _RR_SEARCH_STEPS - first)
    Q = Q[errors <= _RR_SEARCH_FROM]
    if not len(Q):
        return []
    Q, errors = _rr_steps_many(true_rows, F, Q, slide, False)
    return [_rr_to_arm(0, q) for q in Q[errors <= _RR_GOOD]]


def _rr_target(flange):
    """The 4 x 4 target of a split from its 12 numbers, positions divided by _RR_LENGTH."""
    F = np.eye(4)
    F[:3, :] = np.reshape(flange, (3, 4))
    F[:3, 3] /= _RR_LENGTH
    return F


def _rr_motion(angle, shift):
    """A small rigid motion: a rotation by angle about a fixed skew axis and a shift."""
    axis = np.array([0.48, -0.6, 0.64])
    c, s = math.cos(angle), math.sin(angle)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    M = np.eye(4)
    M[:3, :3] = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    M[:3, 3] = shift * np.array([0.36, 0.48, -0.8])
    return M


# the rescue's moves, one per (angle, shift) of _RR_RESCUE
_RR_MOTIONS = np.array([_rr_motion(angle, shift) for angle, shift in _RR_RESCUE])


def _rr_to_arm(k, q):
    """A split's joint values as the arm's: a sliding joint 3 in the arm's lengths, and the
    reversed chain's joint j is -q_{7-j}."""
    if _RR_SPLITS[k][3][0]:
        q = q.copy()
        q[2] *= _RR_LENGTH
    return -q[::-1] if _RR_SPLITS[k][0] else q


def _rr_from_arm(k, q):
    """The arm's joint values as split k's (_rr_to_arm's inverse)."""
    q = -np.asarray(q, dtype=float)[::-1] if _RR_SPLITS[k][0] else np.array(q, dtype=float)
    if _RR_SPLITS[k][3][0]:
        q[2] /= _RR_LENGTH
    return q


def _rr_merge(found, candidates):
    """Add the candidates not already in found, nor equal to an earlier candidate added
    (angles compared modulo 2 pi, within 1e-7): one table of the differences of all of them."""
    if not candidates:
        return
    start = len(found)
    rows = np.array(found + candidates)
    gaps = np.abs((rows[:, None, :] - rows[None, :, :] + math.pi) % _TWO_PI - math.pi)
    near = (gaps.max(axis=2) <= 1e-7).tolist()
    kept = list(range(start))
    for i in range(start, len(rows)):
        if not any(near[i][j] for j in kept):
            kept.append(i)
            found.append(candidates[i - start])


# an answer in doubt (_rr_split): the fallback split is tried (_FALLBACK: clusters on a
# perturbed table), and the rescue too (_RESCUE: clusters on the arm's own table, a candidate
# Newton does not settle there, or no usable pencil)
_FALLBACK = 2
_RESCUE = 1


def _rr_split(k, F, moved, leads, known=(), imag_tol=_RR_IMAG_TOL):
    """The polished candidates of split k for the target F, found from the pose `moved` (F
    itself, or F slightly moved in a rescue; eigenvalues real within imag_tol), but those
    within _RR_SAME of a row in known (the arm's values); those that came within _RR_NEAR
    only; and whether the answer is in doubt (0, _FALLBACK or _RESCUE). Noted in leads
    (_RRLeads): a singular pencil on the arm's own table, and the candidates that stopped
    within _RR_SEARCH_FROM of F."""
    _, fill_rows, true_rows, slide = _RR_SPLITS[k]
    perturbed = fill_rows != true_rows
    values = np.zeros(490)
    _rr_fill(k, *moved[:3, 2], *moved[:3, 3], values)
    P0 = values[:126].reshape(14, 9)
    Ps = values[126:252].reshape(14, 9)
    Pc = values[252:378].reshape(14, 9)
    Q = values[378:].reshape(14, 8)
    count = _RR_SPURIOUS_COUNT[k]
    spurious = (_RR_SPURIOUS[k, :, :count], _RR_PIVOTS[k, : count // 2]) if count else None
    candidates, doubt, extras, (reals, pair) = _rr_candidates(
        P0, Ps, Pc, Q, moved, fill_rows, slide, imag_tol, spurious
    )
    if k == 0 and moved is F:  # (the first split at the pose itself: _general's early
        # answer; on a nominal table a pair within its seeds' window is nearly real too)
        window = max(_RR_PAIR_DOUBT, math.sqrt(_SEED_TOL))
        leads.clear = candidates is not None and reals == 0 and pair > window
    # a perturbed table's solutions are walked back to the arm's in steps (a continuation),
    # so that Newton does not jump to another branch
    path = [_rr_between(fill_rows, true_rows, t) for t in _RR_PATH] if perturbed else []
    out: list[np.ndarray] = []
    close: list[np.ndarray] = []
    paired: list[bool] = []  # (per row of out: an extra candidate's, first)
    if candidates is None:  # (a singular pencil)
        leads.singular = leads.singular or not perturbed
        return out, close, _RESCUE
    # a perturbed table's clusters are the arm's pairs sharing the eigen-joint's value, which
    # its special geometry makes common: both come from the plane, and the partners and the
    # search find one lost; they ask for the fallback split only (on 2,000 poses of each of
    # two cobots, the rescue they started added rows at 14 poses, 13 of them with an odd
    # count, which starts it anyway), and only where a row may be missing (_rr_settled).
    # A pair within _RR_PAIR_DOUBT of real does so too, clusters or not: it may be two of the
    # arm's solutions that the table's difference made complex, whose nearly double roots
    # only a plane (a second singular value below _RR_NULL2_TOL) brings out, and that test
    # sits at the edge there (a calibrated CRX-10iA/L's and a nearly nominal INDY7's pose,
    # the second singular value 4e-6 to 1e-5 of the largest, C's pivots 1.5e-5 to 4e-5: C
    # saw no plane, lifted no doubt and returned 4 and 2 of the 6 and 8 rows; a reviewer's
    # find, helper 75). (The last split's pair has no split to ask for: _general's early
    # answer for a pose out of reach stands.)
    if perturbed:
        nearly = pair <= _RR_PAIR_DOUBT and k + 1 < len(_RR_SPLITS)
        doubt = _FALLBACK if doubt or nearly else 0
    else:
        doubt = _RESCUE if doubt else 0
    if known and candidates:  # (one within _RR_SAME of a known row is that row again)
        near = _rr_gap_table([_rr_to_arm(k, q) for q in candidates], list(known)) <= _RR_SAME
        kept = np.flatnonzero(~near.any(axis=1))
        candidates = [candidates[c] for c in kept]
        extras = [extras[c] for c in kept]
    if not candidates:
        return out, close, _rr_settled(doubt, known, [], reals, pair)
    # every candidate at once (numpy's stacked products and solves: the Python solver's time
    # went to calling numpy on 4 x 4 matrices one candidate at a time)
    Q = np.array(candidates)
    for rows in path:  # (Newton's steps only: damped ones may change branch on the way)
        Q, _ = _rr_steps_many(rows, F, Q, slide, False, steps=_RR_PATH_STEPS, track=True)
    Q, residuals, damped = _rr_newton_many(true_rows, F, Q, slide, np.array(extras))
    # the arm's values of the starts and rows, and their gaps from each other and from the
    # known rows, one table each (the Python solver's time went to comparing candidates one
    # by one: 11% of it on two cobots); a row moved after these (_rr_unsettled_copy), or a
    # partner, is compared on its own
    starts = [_rr_to_arm(k, q) for q in candidates]
    arms = [_rr_to_arm(k, q) for q in Q]
    start_gaps = _rr_gap_table(starts, arms)
    row_gaps = _rr_gap_table(arms, arms)
    known_gaps = _rr_gap_table(arms, list(known)).min(axis=1, initial=math.inf)
    out_arms: list[np.ndarray] = []  # (the arm's values of out's rows)
    out_from: list[int] = []  # (per row of out: the candidate whose row it is; -1: moved)
    misses: list[tuple[np.ndarray, np.ndarray]] = []  # (a nominal table's near misses)
    for c, (q, residual, was_damped, extra) in enumerate(zip(Q, residuals, damped, extras)):
        if (
            perturbed
            and (_rr_out_gaps(start_gaps[c], starts[c], out_arms, out_from) <= _RR_SAME).any()
        ):
            # a perturbed table's candidate within _RR_SAME of a row this split found already
            # is that row again (as a later split's is): the C solver does not walk it (on 500
            # Jaco2 poses 5,802 of the 13,152 candidates walked went onto a row found; the
            # compiled ik of it and of the CRX-like arm took 18% and 17% less time, 3,000
            # uniform poses, the same rows at every one), so it is not kept here either
            continue
        if was_damped and not perturbed and not extra:  # Newton did not settle it
            doubt = _RESCUE
        if residual <= _RR_GOOD:
            arm, row = arms[c], c
            if residual > _RR_SETTLED and _rr_unsettled_copy(arm, list(known) + out_arms):
                Q1, errors = _rr_steps_many(true_rows, F, q[None], slide, False, steps=2)
                q, residual = Q1[0], min(residual, float(errors[0]))
                arm, row = _rr_to_arm(k, q), -1
            if row >= 0:
                seen = known_gaps[c] <= 1e-7
                gaps = _rr_out_gaps(row_gaps[c], arm, out_arms, out_from)
            else:
                seen = _rr_gaps(arm, list(known)).min(initial=math.inf) <= 1e-7
                gaps = _rr_gaps(arm, out_arms)
            same = np.flatnonzero(gaps <= 1e-7)
            out.append(q)
            out_arms.append(arm)
            out_from.append(row)
            paired.append(extra and not seen and not same.size)
            if extra and not seen and same.size and paired[same[0]]:
                # two candidates of a nearly real pair polished onto one row (a Sawyer's pair
                # 0.023 rad apart near a fold, its candidates' real parts a rounding apart in
                # C and numpy: C lost the pair's partners, and the sampled vector, at 33 of 71
                # regular poses there; a new user's find, helper 54): the row across the fold
                # (one within _RR_SAME of a row is a copy of it, not its partner: at a singular
                # pose such copies 1e-5 rad off passed the dedup and took genuine rows' places,
                # a reviewer's find)
                for p in _rr_fold_partners(k, F, q, candidates[c], true_rows, slide):
                    p_arm = _rr_to_arm(k, p)
                    if _rr_gaps(p_arm, list(known) + out_arms).min() > _RR_SAME:
                        out.append(p)
                        out_arms.append(p_arm)
                        out_from.append(-1)
                        paired.append(False)
            continue
        if residual <= _RR_SEARCH_FROM:
            leads.rows.append(_rr_to_arm(k, q))
        if residual <= _SEED_TOL:  # (a nominal table's near miss: _SEED_TOL is 0 elsewhere)
            misses.append((q, arms[c]))
        if extra:
            continue
        if residual <= _RR_NEAR:
            close.append(q)
        if not perturbed:  # (a perturbed table has solutions the arm has not)
            doubt = _RESCUE
    _rr_seed_misses(k, misses, true_rows, slide, leads)
    return out, close, _rr_settled(doubt, known, [_rr_to_arm(k, q) for q in out], reals, pair)


def _rr_seed_misses(k, misses, rows, slide, leads):
    """The seeds of split k's near misses on a nominal table (rows; its values q and the
    arm's, (q, arm) each) added to leads.seeds (_rr_fold_seeds: new ones, at most
    _RR_SEEDS_EACH * MAX_SOLUTIONS, the C solver's buffer): first those of each miss not
    within _RR_FOLD_STEP of a seed, then the others'. With room for sixteen, filled candidate
    by candidate, twelve candidates of one near miss, a few 1e-4 apart, took it all, and the
    pose's own near miss, later, got none: a pose near a singular set that the exact arm
    reaches got no row (a new user's attack on synriard's Alicia-D URDF;
    tests/data/urdf/desktop_6r.urdf). Where the seeds fit they are the same as they were, in
    another order. Leaving the others out instead (the same miss again) lost near-singular
    samples' vectors: of 200 on that URDF 1e-7 to 1e-2 from a singular set, 15 and 16 missed
    in C and Python (a radius of _RR_SAME), 8 and 7 (_RR_FOLD_STEP), against 10 and 7
    before. The order alone, with room for sixteen, lost a row the old order had found at 3
    poses of a reviewer's attack (300 near-singular and 300 boundary poses on each of eight
    such arms); hence room for three seeds of as many near misses as a pose has rows.
    Against the old order and room (that attack's poses, seed 7): on desktop_6r 300
    near-singular poses missed their vector 21 and 12 times (C, Python) against 26 and 17,
    300 poses just inside the workspace's boundary 4 and 8 times against 14 and 24, and got
    no row 0 and 0 times against 5 and 9; on Alicia-D 7 and 2 against 10 and 5, 7 and 5
    against 17 and 16, none empty against 6 and 11; no pose lost a row it had."""
    late = []
    for q, arm in misses:
        if leads.seeds and _rr_gaps(arm, leads.seeds).min() <= _RR_FOLD_STEP:
            late.append(q)
            continue
        _rr_add_seeds(k, q, rows, slide, leads)
    for q in late:
        _rr_add_seeds(k, q, rows, slide, leads)


def _rr_add_seeds(k, q, rows, slide, leads):
    """_rr_fold_seeds(k, q, rows, slide) added to leads.seeds where new, while there is room
    (_RR_SEEDS_EACH * MAX_SOLUTIONS)."""
    room = _RR_SEEDS_EACH * MAX_SOLUTIONS
    if len(leads.seeds) >= room:
        return
    for seed in _rr_fold_seeds(k, q, rows, slide):
        if len(leads.seeds) < room:
            _rr_merge(leads.seeds, [seed])


def _rr_settled(doubt, known, rows, reals, pair):
    """A perturbed table's doubt (_FALLBACK, from its clusters) lifted where the split's rows
    new to known number its real eigenvalues (reals) and no complex one is within
    _RR_PAIR_DOUBT of real (pair): every real root gave its row, and the table's difference
    made no pair of the arm's solutions complex (_RR_PAIR_DOUBT). The doubt otherwise."""
    if doubt != _FALLBACK or pair <= _RR_PAIR_DOUBT:
        return doubt
    merged = list(known)
    _rr_merge(merged, rows)
    return 0 if len(merged) - len(known) >= reals else doubt


def _rr_unsettled_copy(arm, rows):
    """Whether a row's values (the arm's; not settled to rounding) lie within _RR_SAME of one
    of the rows found (the arm's values) but not within the dedup's 1e-7: perhaps a copy of
    that row near a fold (_RR_SETTLED says why)."""
    gaps = _rr_gaps(arm, rows)
    return bool(((gaps <= _RR_SAME) & (gaps > 1e-7)).any())


def _rr_gaps(q, rows):
    """The largest joint gap of q from each of rows (the arm's values; angles modulo 2 pi)."""
    return _rr_gap_table([q], rows)[0]


def _rr_gap_table(qs, rows):
    """The largest joint gap of each of qs from each of rows at once (the arm's values;
    angles modulo 2 pi): shape (len(qs), len(rows))."""
    if not len(qs) or not len(rows):
        return np.zeros((len(qs), len(rows)))
    # (each value reduced modulo 2 pi first, then each difference: the gap is the shorter
    # way round)
    A, B = (np.array(qs) + math.pi) % _TWO_PI, (np.array(rows) + math.pi) % _TWO_PI
    D = np.abs(B[None, :, :] - A[:, None, :])
    return np.minimum(D, _TWO_PI - D).max(axis=2)


def _rr_out_gaps(table, q, out, out_from):
    """q's gaps from the rows of out (the arm's values): from its row of a gap table (table,
    over the candidates) where a row is a candidate's (out_from), on its own where it moved
    (-1)."""
    if not out:
        return np.zeros(0)
    gaps = table[out_from]
    moved = [j for j, c in enumerate(out_from) if c < 0]
    if moved:
        gaps[moved] = _rr_gaps(q, [out[j] for j in moved])
    return gaps


def _rr_between(fill_rows, true_rows, t):
    """The rows a share t of the way from true_rows to fill_rows (twists renormalised)."""
    out = []
    for f, r in zip(fill_rows, true_rows):
        d, a = r[0] + t * (f[0] - r[0]), r[1] + t * (f[1] - r[1])
        ca, sa = r[2] + t * (f[2] - r[2]), r[3] + t * (f[3] - r[3])
        h = math.hypot(ca, sa)
        out.append((d, a, ca / h, sa / h))
    return out


def _rr_candidates(P0, Ps, Pc, Q, F, rows, slide=_RR_TURNS, imag_tol=_RR_IMAG_TOL, spurious=None):
    """The unpolished joint values of one split from its matrices (docs/algorithms.md, "The
    general 6R method"), whether the eigenvalues came in clusters (an answer in doubt), and
    which candidates are extras (from nearly real pairs: one that does not polish puts nothing
    in doubt), and (the number of real eigenvalues within reach, the least |Im y| / (1 + |y|)
    of the others, inf where none). Where joint 3 slides (slide[0] set) the eigen-variable x3
    is d3 itself, not tan(theta3 / 2)."""
    found = _rr_eigenvalues(P0, Ps, Pc, Q, spurious)
    if found is None:  # (a singular pencil: None, where no eigenvalue is real gives [])
        return None, True, [], (0, math.inf)
    values, (A, B, C), moebius = found
    size = 1.0 + np.abs(values)
    real = np.sort(values[np.abs(values.imag) <= imag_tol * size].real)
    upper = values.imag > imag_tol * size
    pair = float((values.imag[upper] / size[upper]).min()) if upper.any() else math.inf
    extra = _rr_pair_extras(values[values.imag > imag_tol * size], moebius, slide[0])
    ma, mb, mc, md = moebius
    if slide[0]:
        # a sliding joint 3 moves the flange by d3 along its axis, the other links by at most
        # the sum of their lengths: |d3| <= |p| + that sum. The pencil's roots beyond (the
        # degree it loses without a half-angle, near x3 = infinity) are left out before
        # clustering.
        reach = float(np.abs(F[:3, 3]).sum()) + sum(abs(r[0]) + abs(r[1]) for r in rows)
        real = real[np.abs(ma * real + mb) <= reach * np.abs(mc * real + md)]
        extra = extra[np.abs(ma * extra + mb) <= reach * np.abs(mc * extra + md)]
    spread = (len(real), pair)
    doubt = False
    ys: list[list[float]] = []
    for y in real:
        if ys and abs(y - ys[-1][-1]) <= _RR_CLUSTER_TOL * (1.0 + abs(y)):
            ys[-1].append(y)
            doubt = True
        else:
            ys.append([y])
    primary = len(ys)
    ys += [[y] for y in extra]  # (on their own: they put nothing in doubt)
    if not ys:
        return [], doubt, [], spread
    # every cluster's null space at once (one stacked SVD), then every candidate's theta1,
    # theta2 and theta6 at once
    centres = np.array([sum(cluster) / len(cluster) for cluster in ys])
    Y = centres[:, None, None]
    first, second, planes = _rr_null_vectors(A * Y * Y + B * Y + C)
    thetas3, vectors, optional = [], [], []
    for k, (cluster, y, v1, v2, plane) in enumerate(zip(ys, centres, first, second, planes)):
        if slide[0]:
            theta3 = (ma * y + mb) / (mc * y + md)
        else:
            theta3 = 2.0 * math.atan2(ma * y + mb, mc * y + md)
        found = [v1]
        if len(cluster) > 1 or plane:
            # two solutions may share theta3: both from the null space's plane
            found += _rr_unmix(v1, v2)
            doubt = doubt or k < primary
        thetas3 += [float(theta3)] * len(found)
        vectors += found
        optional += [k >= primary] * len(found)
    V = np.array(vectors)
    T345 = np.column_stack(
        (
            thetas3,
            _rr_ratio_angles(V, _RR_X4_PAIRS) + _RR_SHIFT45[0],
            _rr_ratio_angles(V, _RR_X5_PAIRS) + _RR_SHIFT45[1],
        )
    )
    owner, theta1, theta2 = _rr_joints12_many(rows, F, T345, slide)
    if not owner.size:
        return [], doubt, [], spread
    X = np.column_stack((theta1, theta2, T345[owner]))
    extras = np.array(optional)[owner].tolist()
    candidates = list(np.column_stack((X, _rr_theta6_many(rows, F, X, slide))))
    return candidates, doubt, extras, spread


def _rr_pair_extras(upper, moebius, slides):
    """The values of y tried for the nearly real pairs among the eigenvalues upper (those
    with Im > 0): two near-equal real roots that the pencil's rounding split apart (the twins
    of a nearly folded elbow or wrist), or that a perturbed table's difference made complex.
    Nearly real is judged by the imaginary part theta3 takes, 2 |det M| Im y / ((ma y + mb)^2
    + (mc y + md)^2) to first order (M the Moebius map): the map changes from pose to pose,
    and a pair the imaginary part of y calls far (up to 0.8 (1 + |y|), measured on xArm6)
    can be 0.01 rad from real. A pair within _RR_PAIR_ANGLE is tried at theta3's real part
    -+ that imaginary part (Newton and the certification decide); a sliding joint 3 (x3 is
    d3) at Re y -+ Im y, within _RR_PAIR_TOL (1 + |y|)."""
    if slides:
        pair = upper[upper.imag <= _RR_PAIR_TOL * (1.0 + np.abs(upper))]
        return np.sort(np.concatenate((pair.real - pair.imag, pair.real + pair.imag)))
    ma, mb, mc, md = moebius
    num, den = ma * upper.real + mb, mc * upper.real + md
    spread = 2.0 * abs(ma * md - mb * mc) * upper.imag / (num * num + den * den)
    near = spread <= _RR_PAIR_ANGLE
    centre = 2.0 * np.arctan2(num[near], den[near])
    half = np.tan(np.concatenate((centre - spread[near], centre + spread[near])) / 2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        y = (md * half - mb) / (ma - mc * half)
    return np.sort(y[np.isfinite(y)])


def _rr_joints12_many(rows, F, T345, slide):
    """The (theta1, theta2) pairs once theta3..theta5 are known (the rows of T345), as the row
    of T345 each pair belongs to (in order), theta1 and theta2. The third
    and fourth columns of A3 A4 A5 (a direction l and a point p in frame 2), moved by X2 and
    Tz(d2) to g, meet those of the target f: Rz(theta1) X1 Rz(theta2) g = f. Four equations
    linear in (cos, sin) of theta2 (the z components, |p|^2 and l.p, which theta1 leaves alone)
    give theta2 by least squares (two values where the equations fix only one direction); the
    rotation about z0 taking X1 Rz(theta2) g onto f gives theta1. (Least squares on
    Q m12 = P m45 would need Q of full rank, which arms with a1 = 0 lack.)"""
    links = _rr_chain(T345, rows, slide, first=2)
    d2, a2, ca2, sa2 = rows[1]
    _, a1, ca1, sa1 = rows[0]
    # g[:, :, 0] = l, g[:, :, 1] = p
    M = links[:, 0] @ (links[:, 1] @ links[:, 2, :, 2:])
    g = np.array([[1.0, 0.0, 0.0], [0.0, ca2, -sa2], [0.0, sa2, ca2]]) @ M[:, :3]
    g[:, 0, 1] += a2
    g[:, 2, 1] += d2
    fl, fp = F[:3, 2], F[:3, 3]
    # rows: l_z, p_z, |p|^2, l.p; coefficients of (cos theta2, sin theta2) (linear in
    # (l_x, p_x, l_y, p_y)), right sides
    n = len(g)
    weights = np.zeros((4, 8))
    weights[[2, 0, 3, 1], [0, 1, 2, 3]] = sa1
    weights[1, 4], weights[3, 5], weights[0, 6], weights[2, 7] = 2.0 * a1, -2.0 * a1, a1, -a1
    coefficients = (g[:, :2].reshape(n, 4) @ weights).reshape(n, 4, 2)
    E = np.empty((n, 4))
    E[:, :2] = F[2, 2:4] - ca1 * g[:, 2]
    E[:, 2:] = (fp @ fp - a1 * a1, fl @ fp) - (g.transpose(0, 2, 1) @ g[:, :, 1:])[:, ::-1, 0]
    Us, Ss, Vts = np.linalg.svd(coefficients, full_matrices=False)
    # (cos, sin) of theta2 per row: rows whose equations span the plane all at once, the
    # others (one direction: two points) on their own
    regular = np.flatnonzero(Ss[:, 1] > 1e-8 * Ss[:, 0])
    owner, C2, S2 = [regular], [], []
    x = np.einsum("nij,ni->nj", Us[regular], E[regular]) / Ss[regular]
    cs = np.einsum("nji,nj->ni", Vts[regular], x)
    h = np.hypot(cs[:, 0], cs[:, 1])
    unit = h > 0.0  # (else (1, 0), as _rr_unit_solutions)
    h = np.where(unit, h, 1.0)
    C2.append(np.where(unit, cs[:, 0] / h, 1.0))
    S2.append(np.where(unit, cs[:, 1] / h, 0.0))
    if len(regular) == n:
        rows_of, c2, s2 = regular, C2[0], S2[0]
    else:
        for i in np.flatnonzero(Ss[:, 1] <= 1e-8 * Ss[:, 0]):
            units = np.array(_rr_unit_solutions(Us[i], Ss[i], Vts[i], E[i]))
            owner.append(np.full(len(units), i))
            C2.append(units[:, 0])
            S2.append(units[:, 1])
        order = np.argsort(np.concatenate(owner), kind="stable")
        rows_of = np.concatenate(owner)[order]
        c2, s2 = np.concatenate(C2)[order], np.concatenate(S2)[order]
        g = g[rows_of]
    gl, gp = g[:, :, 0], g[:, :, 1]
    # w = X1 Rz(theta2) g, then Rz(theta1) w = f
    wl0, wl1 = c2 * gl[:, 0] - s2 * gl[:, 1], s2 * gl[:, 0] + c2 * gl[:, 1]
    wp0, wp1 = c2 * gp[:, 0] - s2 * gp[:, 1] + a1, s2 * gp[:, 0] + c2 * gp[:, 1]
    # (X1's rotation by alpha1; only the x and y components are needed)
    wl1, wp1 = ca1 * wl1 - sa1 * gl[:, 2], ca1 * wp1 - sa1 * gp[:, 2]
    across = wl0 * fl[1] - wl1 * fl[0] + wp0 * fp[1] - wp1 * fp[0]
    along = wl0 * fl[0] + wl1 * fl[1] + wp0 * fp[0] + wp1 * fp[1]
    return rows_of, np.arctan2(across, along), np.arctan2(s2, c2)


def _rr_null_vectors(M):
    """Per matrix of the stack M (n x 12 x 12, each singular or nearly): its last two right
    singular vectors, and whether the second singular value is at most _RR_NULL2_TOL of the
    largest (a two-dimensional null space). (Inverse iteration with a Rayleigh-Ritz step
    took 2/3 of the stacked SVD's time, but where a third singular value lay near the second
    its plane leaned 1e-4 off the null space's, and arms solved on a perturbed table lost
    solutions: 2 of 200 samples on one long-run arm.)"""
    _, svs, vts = np.linalg.svd(M)
    return vts[:, -1], vts[:, -2], svs[:, -2] <= _RR_NULL2_TOL * svs[:, 0]


def _rr_unit_solutions(U, S, Vt, e):
    """Unit vectors (c, s) solving the rows a c + b s = e by least squares, from the SVD
    U S Vt of the rows' (a, b): one where the rows span the plane, the two points of the unit
    circle on the line they give where they span one direction only."""
    if S[1] > 1e-8 * S[0]:
        cs = Vt.T @ ((U.T @ e) / S)
        h = math.hypot(cs[0], cs[1])
        return [(cs[0] / h, cs[1] / h)] if h > 0.0 else [(1.0, 0.0)]
    if S[0] == 0.0:
        return [(1.0, 0.0)]
    n = Vt[0]
    along = float(U[:, 0] @ e) / S[0]
    along = max(-1.0, min(1.0, along))
    side = math.sqrt(1.0 - along * along)
    return [
        (along * n[0] - side * n[1], along * n[1] + side * n[0]),
        (along * n[0] + side * n[1], along * n[1] - side * n[0]),
    ]


def _rr_pencil6(P0, Ps, Pc, Q):
    """The pencil in x3 (6 x 9 each: x3^2, x3, 1; flattened, a row each): Q's left null
    space N (a generic mix of it where it has more than 6 rows) times P's."""
    U, S, _ = np.linalg.svd(Q)
    floor = _RR_RANK_TOL * max(S[0], 1.0)
    rank = int((floor < S).sum())
    N = U[:, rank:].T
    if N.shape[0] > 6:
        N = _RR_MIX[:, : N.shape[0]] @ N
    return np.array(
        (N @ (P0 - Pc) @ _RR_H45, N @ (2.0 * Ps) @ _RR_H45, N @ (P0 + Pc) @ _RR_H45)
    ).reshape(3, 54)


def _rr_singular(k, F):
    """Whether split k's pencil at the target F is singular to roundings: its leading matrix
    under every Moebius map (the pencil at three values of x3) singular within _RR_SINGULAR
    of its largest singular value (C: dk_rr_singular, by completely pivoted LU)."""
    values = np.zeros(490)
    _rr_fill(k, *F[:3, 2], *F[:3, 3], values)
    pencil6 = _rr_pencil6(
        values[:126].reshape(14, 9),
        values[126:252].reshape(14, 9),
        values[252:378].reshape(14, 9),
        values[378:].reshape(14, 8),
    )
    for moebius in _RR_MOEBIUS:
        s = np.linalg.svd(_rr_pencil(pencil6, moebius)[0], compute_uv=False)
        if not s[-1] <= _RR_SINGULAR * s[0]:
            return False
    return True


def _rr_eigenvalues(P0, Ps, Pc, Q, spurious=None):
    """The eigenvalues y of the pencil (24, complex; without the 2r known ones where
    spurious is (vectors, pivots) of Split.spurious: _rr_deflated), the pencil (A, B, C) and
    the Moebius map used; None where no map gives a usable leading matrix (a singular
    pencil)."""
    # the pencil in x3, lifted and mapped per Moebius map
    pencil6 = _rr_pencil6(P0, Ps, Pc, Q)
    # a map whose leading matrix has a 1-norm condition number below _RR_COND_LIMIT / 12 has
    # a (2-norm) one below _RR_COND_LIMIT: the first map is taken at the cost of the inverse
    # the companion matrix needs anyway; otherwise as before, by the condition numbers
    moebius = _RR_MOEBIUS[0]
    pencil = _rr_pencil(pencil6, moebius)
    try:
        Ainv = np.linalg.inv(pencil[0])
        fast = np.abs(pencil[0]).sum(axis=0).max() * np.abs(Ainv).sum(axis=0).max()
    except np.linalg.LinAlgError:
        fast = math.inf
    if not 12.0 * fast < _RR_COND_LIMIT:
        best = math.inf
        for m in _RR_MOEBIUS:
            abc = pencil if m == _RR_MOEBIUS[0] else _rr_pencil(pencil6, m)
            cond = np.linalg.cond(abc[0])
            if cond < best:
                pencil, moebius, best = abc, m, cond
            if cond < _RR_COND_LIMIT:
                break
        if not best < 1e16:
            return None
        try:  # (an estimate of cond below 1e16 does not rule out an exactly singular A)
            Ainv = np.linalg.inv(pencil[0])
        except np.linalg.LinAlgError:
            return None
    companion = np.zeros((24, 24))
    companion[:12, 12:] = _RR_EYE12
    companion[12:, :12] = -Ainv @ pencil[2]
    companion[12:, 12:] = -Ainv @ pencil[1]
    if spurious is not None:
        vectors, pivots = spurious
        companion = _rr_deflated(companion, vectors, pivots, moebius)
    try:
        return np.linalg.eigvals(companion), pencil, moebius
    except np.linalg.LinAlgError:
        return None


# _rr_deflated's rows and matrices by (vectors, pivots, Moebius map): a few per arm
_RR_DEFLATIONS: dict = {}


def _rr_deflated(K, vectors, pivots, moebius):
    """The companion matrix K without its 2r known eigenvalues, as a (24 - 2r) square matrix
    with the others. y+ = (d i - b) / (a - c i), the image of x3 = i under the map (a, b, c,
    d), and its conjugate are eigenvalues with the eigenvectors [v; y+ v] for the split's
    pose-independent null vectors v (Split.spurious: the identity at rows p = pivots). The
    real and imaginary parts of those, W = [Re, Im] (24 x 2r), span an invariant subspace;
    with S = [W, E] (E the unit vectors of the rows o outside p and 12 + p), S^-1 K S is
    block upper triangular and its last block K[o, o] - G K[p', o] (p' = p, 12 + p;
    G = W[o] W[p']^-1) has the other eigenvalues. W[p'] = [[I, 0], [yr I, yi I]], so
    G = [Re[o] - (yr / yi) Im[o], Im[o] / yi] (yi is near 1 for every map)."""
    key = (vectors.tobytes(), tuple(pivots), moebius)
    found = _RR_DEFLATIONS.get(key)
    if found is None:
        a, b, c, d = moebius
        scale = 1.0 / (a * a + c * c)
        yr, yi = (-b * a - d * c) * scale, (d * a - b * c) * scale
        v = vectors[:, 0::2] + 1j * vectors[:, 1::2]
        W = np.concatenate((v, complex(yr, yi) * v))
        p = np.concatenate((pivots, np.asarray(pivots) + 12))
        o = np.setdiff1d(np.arange(24), p)
        G = np.hstack((W[o].real - (yr / yi) * W[o].imag, W[o].imag / yi))
        found = (np.ix_(o, o), np.ix_(p, o), G)
        _RR_DEFLATIONS[key] = found
    oo, po, G = found
    return K[oo] - G @ K[po]


def _rr_pencil(pencil6, moebius):
    """The 12 x 12 lifted pencil (A, B, C) in y for the map x3 = (a y + b) / (c y + d), from
    the 6 x 9 one in x3 (pencil6: its three matrices flattened, a row each). (Elementwise,
    not as one matrix product: on arms solved on a perturbed table the product's different
    rounding lost 7 of 200 samples' solutions more on one long-run arm.)"""
    a, b, c, d = moebius
    A6, B6, C6 = pencil6.reshape(3, 6, 9)
    out = np.zeros((3, 12, 12))
    out[:, :6, :9] = (
        a * a * A6 + a * c * B6 + c * c * C6,
        2.0 * a * b * A6 + (a * d + b * c) * B6 + 2.0 * c * d * C6,
        b * b * A6 + b * d * B6 + d * d * C6,
    )
    out[:, 6:, 3:] = out[:, :6, :9]  # times x4: x4^i x5^j -> x4^(i+1) x5^j
    return out


def _rr_unmix(v1, v2):
    """The (up to two) vectors of monomials x4^a x5^b in the plane of v1 and v2: the mixture
    u v1 + w v2 with (u, w) a root of the largest of the quadratic rules v_i v_j = v_k v_l."""
    best = (0.0, 0.0, 0.0)
    size = -1.0
    a, b = v1.tolist(), v2.tolist()  # (Python's floats: numpy's scalars cost 10 times more)
    for i, j, k, l in _RR_MONOMIAL_RULES:
        # (u v1 + w v2)_i (u v1 + w v2)_j - (...)_k (...)_l = p u^2 + q u w + r w^2
        p = a[i] * a[j] - a[k] * a[l]
        q = a[i] * b[j] + b[i] * a[j] - a[k] * b[l] - b[k] * a[l]
        r = b[i] * b[j] - b[k] * b[l]
        if abs(p) + abs(q) + abs(r) > size:
            best, size = (p, q, r), abs(p) + abs(q) + abs(r)
    p, q, r = best
    out = []
    disc = q * q - 4.0 * p * r
    if disc < 0.0:
        disc = 0.0
    root = math.sqrt(disc)
    # roots (u : w) of p u^2 + q u w + r w^2, as directions (2 p, -q -+ root) or (-q -+ root, 2 r)
    for sign in (1.0, -1.0):
        h = -q - sign * root if q >= 0.0 else -q + sign * root
        if abs(p) >= abs(r):
            u, w = h, 2.0 * p
        else:
            u, w = 2.0 * r, h
        if abs(u) + abs(w) > 0.0:
            out.append(u * v1 + w * v2)
    return out or [v1]


def _rr_ratio_angles(V, pairs):
    """Per row v of V, the angle t with x = tan(t / 2) the common ratio v[hi] / v[lo] of the
    pairs, by least squares in the direction (lo, hi): x = inf (t = pi) is fine. (theta4 and
    theta5 are t plus their _RR_SHIFT45.)"""
    lo, hi = V[:, pairs[0]], V[:, pairs[1]]
    across, low, high = (hi * lo).sum(axis=1), (lo * lo).sum(axis=1), (hi * hi).sum(axis=1)
    return 2.0 * np.where(low >= high, np.arctan2(across, low), np.arctan2(high, across))


def _rr_theta6_many(rows, F, X, slide):
    """theta6 of each row of X (theta1..theta5) from the pose: (A1 ... A5)^-1 F = Rz(theta6)
    in the split's frame."""
    links = _rr_chain(X[:, :5], rows, slide)
    M = links[:, 0]
    for i in range(1, 5):
        M = M @ links[:, i]
    R = M[:, :3, :3].transpose(0, 2, 1) @ F[:3, :3]
    return np.arctan2(R[:, 1, 0], R[:, 0, 0])


def _rr_newton_many(rows, F, Q, slide, extras):
    """Newton steps on the split's forward kinematics (geometric Jacobian) from each row of Q
    towards F, then, for those they do not bring within _RR_GOOD (but leave within
    _RR_DAMPED_FROM, or on a nominal table or an arm whose wrist flips), Levenberg-Marquardt
    steps from the best point met: the polished rows, their final errors (largest entry of the
    top three rows of the pose difference, lengths in units of _RR_LENGTH) and which Newton did
    not settle, damped steps or not (such a candidate puts the answer in doubt, as before the
    damped steps existed). Newton's steps again after the damped ones: a regular solution the
    damped steps reach slowly is settled exactly, not left a rounding's width from the same
    solution found otherwise. Rows marked in extras get Newton's steps only (but on a nominal
    table)."""
    Q, errors = _rr_steps_many(rows, F, Q, slide, False)
    slow = np.flatnonzero((errors > _RR_NEWTON_DONE[0]) & (errors <= _RR_GOOD))
    if slow.size:  # (Newton converges slowly near a double root: as many steps again)
        A, again_errors = _rr_steps_many(rows, F, Q[slow], slide, False)
        Q[slow], errors[slow] = A, np.minimum(errors[slow], again_errors)
    # (an extra Newton does not settle is dropped, but on a nominal table, where the damped
    # steps may bring it near enough to seed the refinement: _rr_fold_seeds; one that Newton
    # leaves beyond _RR_DAMPED_FROM takes none, but there and where a wrist flips)
    damped = (errors > _RR_GOOD) & (~extras | (_SEED_TOL > 0.0))
    near = damped & ((errors <= _RR_DAMPED_FROM) | (_SEED_TOL > 0.0 or bool(_RR_FLIPS)))
    if near.any():
        tried = np.flatnonzero(near)
        D, damped_errors = _rr_steps_many(rows, F, Q[tried], slide, True)
        better = damped_errors < errors[tried]
        kept = tried[better]
        Q[kept], errors[kept] = D[better], damped_errors[better]
        if kept.size:
            A, again_errors = _rr_steps_many(rows, F, Q[kept], slide, False)
            better = again_errors < errors[kept]
            Q[kept[better]], errors[kept[better]] = A[better], again_errors[better]
    return Q, errors, damped


def _rr_chain(X, rows, slide, first=0):
    """The split's link transforms A_i of joints first + 1, first + 2, ... at the values in the
    columns of X (one row per candidate): shape (n, columns, 4, 4). Each entry of
    Rz(theta) Tz(d) Tx(a) Rx(alpha) is cos theta, sin theta or 1 times a constant; a sliding
    joint 3 has theta = slide[1] and d its value."""
    return _rr_links(X, _rr_chain_weights(rows, slide[0], first, X.shape[1]), slide, first)


def _rr_links(X, weights, slide, first=0):
    """_rr_chain with its constants (_rr_chain_weights) looked up already: a loop of steps on
    one table looks them up once (a lookup's key is the table's rows, a few microseconds)."""
    count = X.shape[1]
    sliding = 2 - first if slide[0] and first <= 2 < first + count else -1
    angles = X
    if sliding >= 0:
        angles = X.copy()
        angles[:, sliding] = slide[1]
    # [cos theta_1 .. cos theta_n, sin theta_1 .. sin theta_n, 1] per row, then each entry's
    # one factor taken and scaled (two calls, where sums of the three scaled took five)
    factors = np.empty((len(X), 2 * count + 1))
    np.cos(angles, out=factors[:, :count])
    np.sin(angles, out=factors[:, count : 2 * count])
    factors[:, 2 * count] = 1.0
    index, scale = weights
    L = np.multiply(factors.take(index, axis=1), scale).reshape(len(X), count, 4, 4)
    if sliding >= 0:
        L[:, sliding, 2, 3] = X[:, sliding]
    return L


# _rr_chain_weights by (rows, slides, first, count): a few per split (its rows and the
# continuation path's)
_RR_CHAIN_WEIGHTS: dict = {}


def _rr_chain_weights(rows, slides, first, count):
    """_rr_chain's constants: per joint and entry, which factor the entry takes (cos theta of
    the joint: its index k; sin theta: count + k; 1: 2 count) and the constant it is scaled
    by (an entry that is 0 takes 1 scaled by 0). Computed once per table (the rows of a split
    are the same pose after pose)."""
    key = (tuple(map(tuple, rows)), slides, first, count)
    found = _RR_CHAIN_WEIGHTS.get(key)
    if found is not None:
        return found
    index = np.full((count, 16), 2 * count)
    scale = np.zeros((count, 16))
    for k in range(count):
        d, a, ca, sa = rows[first + k]
        if slides and first + k == 2:
            d = 0.0
        index[k, [0, 3, 5, 6]] = k
        scale[k, [0, 3, 5, 6]] = 1.0, a, ca, -sa
        index[k, [1, 2, 4, 7]] = count + k
        scale[k, [1, 2, 4, 7]] = -ca, sa, 1.0, a
        scale[k, [9, 10, 11, 15]] = sa, ca, d, 1.0
    index, scale = index.reshape(-1), scale.reshape(-1)
    index.flags.writeable = False
    scale.flags.writeable = False
    _RR_CHAIN_WEIGHTS[key] = (index, scale)
    return index, scale


# numpy's stacked solver of A x = b (x, b vectors) without np.linalg.solve's checks and
# conversions, which took a third of a step's solve on the cobots' six or so rows (the same
# LAPACK call, the same bits); where a numpy lacks it, np.linalg.solve
_SOLVE_STACK = getattr(getattr(np.linalg, "_umath_linalg", None), "solve1", None)
_RR_EYE4 = np.eye(4)
_RR_EYE6 = np.eye(6)
_RR_EYE12 = np.eye(12)
# the components after and before each of x, y, z (cross products: a x b = a[NEXT] b[LAST] -
# a[LAST] b[NEXT])
_RR_NEXT = np.array([1, 2, 0])
_RR_LAST = np.array([2, 0, 1])
# z @ _RR_CROSS, as 3 x 3, is z's cross-product matrix: (z x r)_i = sum_k [z]_ik r_k, [z]_ik
# = sum_j eps_ijk z_j (the Levi-Civita symbol)
_RR_CROSS = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ]
)


# P.reshape(9) @ _RR_VEE = 0.5 (P[NEXT, LAST] - P[LAST, NEXT]) per component (a 3 x 3 P
# flattened by rows; each sum has two terms, halved exactly: the same bits as the indexing)
_RR_VEE = np.zeros((9, 3))
_RR_VEE[3 * _RR_NEXT + _RR_LAST, [0, 1, 2]] = 0.5
_RR_VEE[3 * _RR_LAST + _RR_NEXT, [0, 1, 2]] = -0.5


def _rr_steps_many(
    rows, F, Q, slide, damped, reach=_RR_NEWTON_REACH, steps=_RR_NEWTON_STEPS, track=False
):
    """`steps` + 1 steps from each row of Q, all at once (the last measured only where it is
    Newton's last, _RR_NEWTON_DONE); each stops on its own, where it is exact, its pose error
    beyond `reach` or its system is singular: Newton's (J step = error), or damped ones
    (J^T J + mu) step = J^T error with mu = |error|^2 (Levenberg-Marquardt as Yamashita and
    Fukushima: still quadratic onto a curve of solutions, where J is singular and Newton's
    steps jump; slow in a direction J nearly loses, which is why Newton goes first). The best
    point met by each, and its error; where track is set, `steps` Newton steps and the points
    where they end, not measured (a continuation's corrector), and no errors (None)."""
    q = np.array(Q, dtype=float)
    best_q, best = q.copy(), np.full(len(q), math.inf)
    live = np.arange(len(q))
    Ft = F[:3, :3].T
    weights = _rr_chain_weights(rows, slide[0], 0, 6)
    # (each numpy call costs about a microsecond whatever its size, and a step is a few dozen
    # of them, on a few rows: the filters below are skipped where they would keep every row,
    # and the walk's steps keep no best point)
    for _ in range(steps if track else steps + 1):
        x = q[live]
        frames = _rr_frames(x, rows, slide, weights)
        E = frames[:, 6]
        D = F[:3] - E[:, :3]
        size = np.abs(D).reshape(len(x), 12).max(axis=1)
        if not track:
            better = size < best[live]
            moved = live[better]
            best_q[moved], best[moved] = x[better], size[better]
        going = (size > 1e-15) & (size <= reach)
        if not going.all():
            live, x, frames, E, D = live[going], x[going], frames[going], E[going], D[going]
            size = size[going]
            if not live.size:
                break
        # position error, and half the sum of E's columns crossed with F's (the rotation):
        # the antisymmetric part of E's rotation times F's transposed (_RR_VEE)
        P = E[:, :3, :3] @ Ft
        error = np.concatenate((D[:, :, 3], P.reshape(len(x), 9) @ _RR_VEE), axis=1)
        J = _rr_columns(frames, slide).transpose(0, 2, 1)
        moves, solved = _rr_solve_many(J, error, damped)
        if solved is not None:  # (a singular J: it stops)
            live, x, moves, size = live[solved], x[solved], moves[solved], size[solved]
        longest = np.abs(moves).max(axis=1, initial=0.0)
        q[live] = x + moves * (0.5 / np.maximum(longest, 0.5))[:, None]  # (at most 0.5 a joint)
        if not damped:
            # Newton's step of at most _RR_NEWTON_DONE[1] from within _RR_NEWTON_DONE[0] lands
            # a rounding's width from the solution (the error after it is at most the step
            # squared times the arm's curvature): taken, and not measured again (its error is
            # counted as the one before it; the caller certifies anyway)
            done = (size <= _RR_NEWTON_DONE[0]) & (longest <= _RR_NEWTON_DONE[1])
            if done.any():
                settled = live[done]
                best_q[settled], best[settled] = q[settled], size[done]
                live = live[~done]
                if not live.size:
                    break
    return (q, None) if track else (best_q, best)


def _rr_frames(X, rows, slide, weights=None):
    """The frames F_0 = I, F_1, ..., F_6 of the split's chain at the joint values in the rows
    of X: shape (n, 7, 4, 4) (weights: _rr_chain_weights of rows, where looked up already)."""
    if weights is None:
        weights = _rr_chain_weights(rows, slide[0], 0, 6)
    links = _rr_links(X, weights, slide)
    frames = np.empty((len(X), 7, 4, 4))
    frames[:, 0] = _RR_EYE4
    frames[:, 1] = links[:, 0]
    for i in range(1, 6):
        np.matmul(frames[:, i], links[:, i], out=frames[:, i + 1])
    return frames


def _rr_columns(frames, slide):
    """The geometric Jacobian's columns at those frames, shape (n, 6, 6) (column i last but
    one): z_i x (p - o_i) over z_i (a sliding joint 3: z_3 over 0)."""
    z = frames[:, :6, :3, 2]
    r = frames[:, 6, None, :3, 3] - frames[:, :6, :3, 3]
    columns = np.empty((len(frames), 6, 6))
    # z x r as (z's cross-product matrix) r: the matrix's entries from z by one product
    # (_RR_CROSS), then one product with r (a call each, where the components' products
    # took eight)
    columns[..., :3] = ((z @ _RR_CROSS).reshape(len(frames), 6, 3, 3) @ r[..., None])[..., 0]
    columns[..., 3:] = z
    if slide[0]:  # a sliding joint 3 moves the flange along its axis
        columns[:, 2, :3] = z[:, 2]
        columns[:, 2, 3:] = 0.0
    return columns


def _rr_solve_many(J, error, damped):
    """The steps J step = error (or the damped ones, as _rr_steps_many) of a stack, and None
    where every one could be taken, else which could (a singular system's cannot)."""
    if damped:
        Jt = J.transpose(0, 2, 1)
        mu = np.einsum("ij,ij->i", error, error)
        A = Jt @ J + mu[:, None, None] * _RR_EYE6
        b = (Jt @ error[:, :, None])[:, :, 0]
    else:
        A, b = J, error
    try:
        if _SOLVE_STACK is None:
            return np.linalg.solve(A, b[:, :, None])[:, :, 0], None
        with np.errstate(invalid="raise"):  # (a singular system: LAPACK's info, as NaN)
            return _SOLVE_STACK(A, b), None
    except (np.linalg.LinAlgError, FloatingPointError):  # one is singular: each on its own
        steps, solved = np.zeros_like(b), np.ones(len(A), dtype=bool)
        for k in range(len(A)):
            try:
                steps[k] = np.linalg.solve(A[k], b[k])
            except np.linalg.LinAlgError:
                solved[k] = False
        return steps, solved
