"""The general method for any 6R arm: Raghavan and Roth's 14 equations, Manocha and Canny's
eigen-solve (docs/algorithms.md, "The general 6R method").

Per arm, at generation:

1. The chain is written in standard DH from the flange frame (base, X_0, Tz(d1) and Tz(d6),
   X_6, tool moved into the target, as for Pieper): A_i = Z_i X_i for i = 1..5, A_6 = Rz(theta6).
   Lengths are divided by the arm's size (the largest |a|, |d|), which keeps the matrices'
   entries of one scale whatever the unit.
2. The 14 fundamental equations, derived once in symbols for every arm
   (:func:`derive.raghavan_roth.fundamental`), get the arm's numbers; their 490 entries are
   polynomials in the flange target's third and fourth columns, printed after CSE.
3. Two splits are candidates: the arm's chain and its reversal (which eliminates other
   joints). Each is measured on random poses (the share of generating joint values found,
   and the conditioning of the pencil's leading matrix); the better one is used first, the
   other is the fallback when a pose's answer is in doubt. Where both give a singular pencil
   (special geometry: det Sigma(x3) = 0 for every x3), the matrices come from a table
   perturbed by 1e-4 and Newton steps polish onto the true arm (docs/algorithms.md,
   "Choosing the split, singular pencils and the rescue").

The run-time steps (null space of Q, pencil, eigenvalues, back-substitution, Newton, rescue)
are in :mod:`derive.runtime.general` (Python) and derive/c/general.c (C).
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np
import sympy as sp

from derive import raghavan_roth as rr
from derive import symbols as sym
from derive.classify import Structure
from derive.methods.common import flange_target, joint_outputs
from derive.plan import Assign, Eigen, IkPlan, Split
from derive.runtime import general as runtime
from derive.transforms import Chain, inverse, reverse_chain

NAME = "general"
# the random poses each split is measured on at generation, and the relative perturbation of
# a table whose pencil is singular
POSES = 40
PERTURBATION = 1e-4
# below this ratio of the Jacobian's smallest to largest singular value, a configuration is
# singular (for refusing an arm singular everywhere)
SINGULAR_EVERYWHERE = 1e-10
# a singular value of the lifted matrix at x3 = i below this share of the largest is zero
# (the spurious null space's are rounding: 1e-17 in double precision)
SPURIOUS_RANK_TOL = 1e-12
Row = tuple[float, float, float, float]


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """The general method's plan, or why it does not apply (not 6 joints; a prismatic joint
    other than one joint 3 or 4, which a split's eigen-joint (its joint 3) must be)."""
    if chain.dof != 6:
        return f"general: needs 6 joints, the arm has {chain.dof}"
    sliding = [j.index for j in chain.joints if j.kind == "P"]
    if len(sliding) > 1 or (sliding and sliding[0] not in (3, 4)):
        where = ", ".join(map(str, sliding))
        return (
            "general: takes one prismatic joint at most, as joint 3 or 4 (the eigen-joint of the "
            f"arm's chain or of its reversal); the arm's prismatic joints: {where}"
        )
    length = max(
        [abs(float(t.a)) for t in chain.twists[1:6]]
        + [abs(float(j.d if j.kind == "R" else j.offset)) for j in chain.joints[1:5]]
    )
    if length == 0.0:
        return "general: every link length and offset is zero (the arm is a point)"
    chains = (chain, reverse_chain(chain))
    # the chains whose joint 3 is the sliding joint, if there is one
    usable = [k for k in (0, 1) if not sliding or chains[k].joints[2].kind == "P"]
    # (on a chain whose sliding joint is its joint 3: the rows hold no other kind of joint)
    if everywhere_singular(flange_rows(chains[usable[0]], length), slide_of(chains[usable[0]])):
        return (
            "general: the arm's Jacobian has rank below 6 at every configuration"
            f"{parallel_run(structure)}: it reaches a set of poses of dimension below 6, each "
            "along a curve of solutions; no solver is generated"
        )
    splits = [measure(chains[k], k, length, False) for k in usable]
    if max(s.recovered for s in splits) < POSES or len(splits) < 2:
        splits += [measure(chains[k], k, length, True) for k in usable]
    splits.sort(key=lambda s: (-s.recovered, s.singular, round(math.log10(s.cond), 1)))
    chosen = tuple(splits[:2])
    steps: list[Assign | Eigen] = []
    args: list[sp.Expr] = []
    for k, split in enumerate(chosen):
        world = inverse(sym.world_pose()) if split.reversed else sym.world_pose()
        assign = split_target(chains[split.reversed], world, k)
        steps.append(assign)
        args += assign.targets
    first = chosen[0]
    steps.append(
        Eigen(
            joint=3,
            args=tuple(args),
            note=f"general 6-joint: Raghavan-Roth equations of {first.name}, its joint 3 from a "
            "24 x 24 eigenproblem, the rest by back-substitution",
            fanout=16,
            unit=length,
            splits=chosen,
            kinds="".join(j.kind for j in chain.joints),
            flips=flip_ends(first),
        )
    )
    return IkPlan(
        method=NAME,
        case=f"no closed form applies; split: {first.name} (fallback: {chosen[1].name})",
        max_solutions=16,
        steps=tuple(steps),
        outputs=joint_outputs(chain),
    )


def slide_of(chain: Chain) -> tuple[float, float]:
    """(1.0, theta3) where the chain's joint 3 slides (theta3 its fixed angle), else
    runtime._RR_TURNS."""
    joint = chain.joints[2]
    return (1.0, float(joint.theta)) if joint.kind == "P" else runtime._RR_TURNS


def everywhere_singular(rows: tuple[Row, ...], slide: tuple[float, float]) -> bool:
    """Whether the Jacobian of the chain (flange rows) is singular at 8 random configurations:
    smallest singular value below SINGULAR_EVERYWHERE of the largest at each (a regular arm's
    is ~1e-2 at random configurations; a degenerate one's is rounding)."""
    rng = np.random.default_rng(5)
    for _ in range(8):
        frames = [np.eye(4)]
        for i, t in enumerate(rng.uniform(-math.pi, math.pi, 6)):
            frames.append(frames[-1] @ _split_joint(i, t, rows, slide))
        end = frames[6][:3, 3]
        z = [f[:3, 2] for f in frames[:6]]
        J = np.array(
            [
                np.concatenate((z[i], np.zeros(3)))
                if i == 2 and slide[0]
                else np.concatenate((np.cross(z[i], end - frames[i][:3, 3]), z[i]))
                for i in range(6)
            ]
        )
        S = np.linalg.svd(J, compute_uv=False)
        if S[-1] > SINGULAR_EVERYWHERE * S[0]:
            return False
    return True


def parallel_run(structure: Structure) -> str:
    """ " (axes i-j are parallel)" for the first run of four or more parallel axes, else ""."""
    for i in structure.parallel_triples:
        if i + 1 in structure.parallel_triples:
            j = i + 3
            while j in structure.parallel:
                j += 1
            return f" (axes {i}-{j} are parallel)"
    return ""


def split_target(chain: Chain, target: sp.Matrix, k: int) -> Assign:
    """The flange target of a split's chain (target: the world target, or its inverse for the
    reversed chain), in symbols F{k}_ij (k: the split's place)."""
    flange = flange_target(chain, target)
    names = tuple(sym.named(f"F{k}_{i}{j}") for i in range(1, 4) for j in range(1, 5))
    return Assign(names, flange.exprs, f"split {k}: {flange.note}")


def flange_rows(chain: Chain, length: float) -> tuple[Row, ...]:
    """The standard-DH rows (d, a, cos alpha, sin alpha) of the chain from its flange frame,
    lengths divided by `length`: A_i = Z_i X_i (i = 1..5), A_6 = Rz(theta6); d1 = d6 = 0."""
    rows: list[Row] = []
    for i in range(1, 7):
        twist = chain.twists[i]
        joint = chain.joints[i - 1]
        # (a sliding joint's d is its variable: the row's is not read)
        d = 0.0 if i in (1, 6) or joint.kind == "P" else float(joint.d) / length
        if i == 6:
            rows.append((0.0, 0.0, 1.0, 0.0))
        else:
            rows.append((d, float(twist.a) / length, float(twist.ca), float(twist.sa)))
    return tuple(rows)


def perturbed(rows: tuple[Row, ...]) -> tuple[Row, ...]:
    """The rows with every d, a and alpha moved by about PERTURBATION (fixed numbers)."""
    out: list[Row] = []
    for i, (d, a, ca, sa) in enumerate(rows[:5]):
        wobble = [math.sin(1.7 * i + 0.4 * k + 0.3) for k in range(3)]
        alpha = math.atan2(sa, ca) + PERTURBATION * wobble[2]
        out.append(
            (
                d + PERTURBATION * wobble[0] if i else d,
                a + PERTURBATION * wobble[1],
                math.cos(alpha),
                math.sin(alpha),
            )
        )
    return (*out, rows[5])


def fill_expressions(
    rows: tuple[Row, ...], exact: dict[sp.Symbol, sp.Expr], slide: tuple[float, float]
) -> tuple[sp.Expr, ...]:
    """The 490 entries of P0, Ps, Pc, Q for these rows (exact numbers where given). Where joint
    3 slides, P(d3) = P0 + Ps s3 + Pc c3 at its fixed theta3 is B0 + B1 d3 + B2 d3^2 (degree 2:
    d3 enters p linearly), and the entries are those of P0' = (B0 + B2) / 2, Ps' = B1 / 2,
    Pc' = (B0 - B2) / 2: the run time's pencil in x3, (P0' - Pc') x3^2 + 2 Ps' x3 + P0' + Pc',
    is then B(x3) with x3 = d3."""
    f = rr.fundamental()
    subs: dict[sp.Symbol, sp.Expr] = {}
    for i, (d, a, ca, sa) in enumerate(rows[:5]):
        subs[rr.a[i]] = sp.Float(a, 17)
        subs[rr.d[i]] = sp.Float(d, 17)
        subs[rr.lam[i]] = sp.Float(ca, 17)
        subs[rr.mu[i]] = sp.Float(sa, 17)
    subs.update(exact)
    if not slide[0]:
        out = []
        for m in (f.P0, f.Ps, f.Pc, f.Q):
            out += [sp.expand(e.xreplace(subs)) for e in m]
        return tuple(out)
    d3 = rr.d[2]
    del subs[d3]
    c3, s3 = exact_cos_sin(slide[1])
    B = [sp.expand((p0 + ps * s3 + pc * c3).xreplace(subs)) for p0, ps, pc in zip(f.P0, f.Ps, f.Pc)]
    terms = [[b.coeff(d3, k) for b in B] for k in range(3)]
    half = sp.Rational(1, 2)
    P0 = [sp.expand(half * (b0 + b2)) for b0, b2 in zip(terms[0], terms[2])]
    Ps = [sp.expand(half * b1) for b1 in terms[1]]
    Pc = [sp.expand(half * (b0 - b2)) for b0, b2 in zip(terms[0], terms[2])]
    Q = [sp.expand(e.xreplace(subs)) for e in f.Q]
    return (*P0, *Ps, *Pc, *Q)


def exact_cos_sin(angle: float) -> tuple[sp.Expr, sp.Expr]:
    """cos and sin of a fixed angle: exact integers at multiples of 90 deg, else floats."""
    quarter = angle / (math.pi / 2)
    if abs(quarter - round(quarter)) < 1e-12:
        k = round(quarter) % 4
        return sp.Integer((1, 0, -1, 0)[k]), sp.Integer((0, 1, 0, -1)[k])
    return sp.Float(math.cos(angle), 17), sp.Float(math.sin(angle), 17)


def exact_numbers(chain: Chain) -> dict[sp.Symbol, sp.Expr]:
    """The exact twists of the chain (cos, sin of 0, 90, 180 deg stay exact integers)."""
    subs: dict[sp.Symbol, sp.Expr] = {}
    for i in range(1, 6):
        t = chain.twists[i]
        if t.ca.is_Integer and t.sa.is_Integer:
            subs[rr.lam[i - 1]] = t.ca
            subs[rr.mu[i - 1]] = t.sa
        if t.a == 0:
            subs[rr.a[i - 1]] = sp.Integer(0)
        if i > 1 and chain.joints[i - 1].kind == "R" and chain.joints[i - 1].d == 0:
            subs[rr.d[i - 1]] = sp.Integer(0)
    return subs


def measure(chain: Chain, reversed_: int, length: float, perturb: bool) -> Split:
    """A split of the chain, measured on POSES random poses (fixed seed)."""
    true_rows = flange_rows(chain, length)
    fill_rows = perturbed(true_rows) if perturb else true_rows
    slide = slide_of(chain)
    fill = fill_expressions(fill_rows, {} if perturb else exact_numbers(chain), slide)
    recovered, conds = score(fill_rows, true_rows, slide)
    spurious, pivots = spurious_vectors(fill) if not slide[0] else ((), ())
    return Split(
        reversed=bool(reversed_),
        fill=fill,
        fill_rows=fill_rows,
        true_rows=true_rows,
        recovered=recovered,
        poses=POSES,
        cond=float(np.median(conds)),
        singular=perturb,
        slide=slide,
        spurious=spurious,
        spurious_pivots=pivots,
    )


def spurious_vectors(
    fill: tuple[sp.Expr, ...],
) -> tuple[tuple[tuple[float, ...], ...], tuple[int, ...]]:
    """Split.spurious and Split.spurious_pivots: the null space, at x3 = i, of the lifted
    12 x 12 matrix a split's fill gives, as 12 rows (Re v_1, Im v_1, Re v_2, ...), and the
    rows where the basis is the identity; ((), ()) where it has none.

    (1 + x3^2) P(x3) = (P0 - Pc) x3^2 + 2 Ps x3 + P0 + Pc is 2 (Pc + i Ps) at x3 = i, and Ps,
    Pc do not depend on the pose (only P0 and Q do): so neither does G = (Pc + i Ps) H45 nor
    the null space of its lift [[G, 0], [0, G]] (the second copy shifted by 3 columns, times
    x4), which the pose's pencil N G has too. Computed in 40-digit arithmetic from the fill's
    numbers (deterministic); a singular value below SPURIOUS_RANK_TOL of the largest counts
    as zero. The result is canonical: the basis whose rows at the r pivot rows (chosen by
    size) are the identity."""
    import mpmath

    Ps, Pc = fill[126:252], fill[252:378]
    if any(sp.sympify(e).free_symbols for e in (*Ps, *Pc)):
        return (), ()  # (never for the 14 equations: the condition the argument needs)
    H = runtime._RR_H45
    with mpmath.workdps(40):
        G = mpmath.matrix(14, 9)
        for r in range(14):
            for c in range(9):
                G[r, c] = mpmath.mpc(mpmath.mpf(Pc[9 * r + c]), mpmath.mpf(Ps[9 * r + c]))
        G = G * mpmath.matrix(H.tolist())
        lifted = mpmath.matrix(28, 12)
        for r in range(14):
            for c in range(9):
                lifted[r, c] = G[r, c]
                lifted[14 + r, 3 + c] = G[r, c]
        _, S, V = mpmath.svd_c(lifted)
        rank = sum(1 for k in range(12) if S[k] > SPURIOUS_RANK_TOL * S[0])
        if rank == 12:
            return (), ()
        # the null vectors (columns), then the canonical basis: pivot rows by size
        null = mpmath.matrix(12, 12 - rank)
        for j in range(12 - rank):
            for i in range(12):
                null[i, j] = mpmath.conj(V[rank + j, i])
        pivots: list[int] = []
        work = null.copy()
        for j in range(12 - rank):
            row = max((i for i in range(12) if i not in pivots), key=lambda i: abs(work[i, j]))
            pivots.append(row)
            work[:, j] = work[:, j] / work[row, j]
            for other in range(12 - rank):
                if other != j:
                    work[:, other] = work[:, other] - work[row, other] * work[:, j]
        # (parts below 1e-30 are the 40-digit arithmetic's rounding: zeros)
        vectors = tuple(
            tuple(
                float(part) if abs(part) > 1e-30 else 0.0
                for j in range(12 - rank)
                for part in (work[i, j].real, work[i, j].imag)
            )
            for i in range(12)
        )
        for j, row in enumerate(pivots):  # (exactly the identity there)
            assert vectors[row] == tuple(float(k == 2 * j) for k in range(2 * (12 - rank)))
        return vectors, tuple(pivots)


def score(
    fill_rows: tuple[Row, ...], true_rows: tuple[Row, ...], slide: tuple[float, float]
) -> tuple[int, list[float]]:
    """Of POSES random poses (a fifth of the joints at 0, +-90 or 180 deg; a sliding joint 3
    within +-1 arm size), how many have their generating joint values among the split's
    polished candidates; and the condition numbers of the pencil's leading matrix."""
    rng = np.random.default_rng(20261201)
    recovered = 0
    conds = []
    for _ in range(POSES):
        q = rng.uniform(-math.pi, math.pi, 6)
        special = rng.random(6) < 0.2
        q[special] = rng.choice([0.0, math.pi / 2, -math.pi / 2, math.pi], special.sum())
        if slide[0]:
            q[2] /= math.pi
        F = np.eye(4)
        for i, t in enumerate(q):
            F = F @ _split_joint(i, t, true_rows, slide)
        P0, Ps, Pc, Q = matrices_at(fill_rows, F, slide)
        candidates, _, _, _ = runtime._rr_candidates(P0, Ps, Pc, Q, F, fill_rows, slide)
        conds.append(leading_condition(P0, Ps, Pc, Q))
        if candidates:
            # (Newton's steps only, as the splits were always measured)
            P, errors = runtime._rr_steps_many(true_rows, F, np.array(candidates), slide, False)
            gaps = np.abs((P - q + math.pi) % (2 * math.pi) - math.pi).max(axis=1)
            recovered += bool(((errors <= runtime._RR_GOOD) & (gaps <= 1e-6)).any())
    return recovered, conds


def leading_condition(P0, Ps, Pc, Q) -> float:
    """cond of the pencil's leading matrix under the first Moebius map (a finite stand-in
    for a singular one: 1e20)."""
    U, S, _ = np.linalg.svd(Q)
    rank = int((runtime._RR_RANK_TOL * max(S[0], 1.0) < S).sum())
    N = U[:, rank:].T
    if N.shape[0] > 6:
        N = runtime._RR_MIX[:, : N.shape[0]] @ N
    H = runtime._RR_H45
    pencil6 = np.array((N @ (P0 - Pc) @ H, N @ (2.0 * Ps) @ H, N @ (P0 + Pc) @ H)).reshape(3, 54)
    A = runtime._rr_pencil(pencil6, runtime._RR_MOEBIUS[0])[0]
    return float(min(np.linalg.cond(A), 1e20))


def matrices_at(
    rows: tuple[Row, ...], F: np.ndarray, slide: tuple[float, float] = runtime._RR_TURNS
) -> tuple[np.ndarray, ...]:
    """P0, Ps, Pc, Q as numbers for the rows (d, a, cos alpha, sin alpha) and the flange
    target F (position in the rows' units); where joint 3 slides, those of fill_expressions
    (P at d3 = 0, 1, -1 gives B's three coefficients)."""

    def at(d3: float | None) -> tuple[np.ndarray, ...]:
        ds = [r[0] if i != 2 or d3 is None else d3 for i, r in enumerate(rows[:5])]
        numbers = [r[1] for r in rows[:5]] + ds
        numbers += [r[2] for r in rows[:5]] + [r[3] for r in rows[:5]]
        args = [*numbers, *F[:3, 2], *F[:3, 3]]
        return tuple(np.array(fn(*args), dtype=float) for fn in numeric_matrices())

    if not slide[0]:
        return at(None)
    c3, s3 = math.cos(slide[1]), math.sin(slide[1])
    B = []
    for d3 in (0.0, 1.0, -1.0):
        P0, Ps, Pc, Q = at(d3)
        B.append(P0 + Ps * s3 + Pc * c3)
    B1 = 0.5 * (B[1] - B[2])
    B2 = 0.5 * (B[1] + B[2]) - B[0]
    return 0.5 * (B[0] + B2), 0.5 * B1, 0.5 * (B[0] - B2), Q


@cache
def numeric_matrices():
    """P0, Ps, Pc, Q as numpy functions of (a1..a5, d1..d5, cos alpha1..5, sin alpha1..5,
    lx, ly, lz, px, py, pz): the generic matrices, for measuring splits."""
    f = rr.fundamental()
    return [sp.lambdify(rr.GENS, m, "numpy") for m in (f.P0, f.Ps, f.Pc, f.Q)]


def _split_joint(i: int, value: float, rows, slide) -> np.ndarray:
    """A_i of a split's joint i (0-based) at its value: split_link, or, for joint 3
    where it slides, Rz(theta3) Tz(value) Tx(a) Rx(alpha) with theta3 = slide[1] fixed."""
    if i == 2 and slide[0]:
        return split_link(slide[1], (value, *rows[2][1:]))
    return split_link(value, rows[i])


# a wrist flip of three joints, (t1 + pi, -t2, t3 + pi), leaves their motion unchanged where
# their axes meet at right angles (a spherical wrist's): the run time tries each row's flip at
# such an end (_rr_partners), for a partner a perturbed table walked onto its twin. An end
# counts as such a wrist where the flip moves the motion by at most this (the largest entry's
# change, lengths in the split's unit), at FLIP_SAMPLES: a calibrated wrist's axes miss each
# other by a fraction of a millimetre; an offset wrist's (the cobots' 0.1-0.2 m) moves it by
# 0.4-2, and Newton's steps from its flips found no row on 800 poses of two such arms
FLIP_TOL = 1e-2
FLIP_SAMPLES = ((0.3, 0.7, -1.1), (2.0, -0.4, 0.9), (-2.5, 1.9, 2.7))


def flip_ends(split: Split) -> tuple[int, ...]:
    """The arm's ends (0: joints 1-3, 3: joints 4-6) where the wrist flip leaves the motion
    of the three joints unchanged within FLIP_TOL on the split's own rows (the reversed
    chain's first three joints are the arm's last three); an end with the sliding joint is
    none."""
    ends = []
    for first in (0, 3):
        if split.slide[0] and first == 0:  # (the split's joint 3 slides)
            continue
        worst = 0.0
        for t1, t2, t3 in FLIP_SAMPLES:
            turned = (t1 + math.pi, -t2, t3 + math.pi)
            motions = [
                split_link(a, split.true_rows[first])
                @ split_link(b, split.true_rows[first + 1])
                @ split_link(c, (0.0, 0.0, 1.0, 0.0))
                for a, b, c in ((t1, t2, t3), turned)
            ]
            worst = max(worst, float(np.abs(motions[0] - motions[1]).max()))
        if worst <= FLIP_TOL:
            ends.append(3 - first if split.reversed else first)
    return tuple(sorted(ends))


def split_link(theta: float, row) -> np.ndarray:
    """A_i = Rz(theta) Tz(d) Tx(a) Rx(alpha) of standard DH; row = (d, a, cos alpha, sin alpha)."""
    d, a, ca, sa = row
    ct, st = math.cos(theta), math.sin(theta)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )
