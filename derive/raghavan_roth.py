"""The 14 fundamental equations of a general 6R arm (Raghavan and Roth; Manocha and Canny's
form), derived once in symbols for every arm: the first step of the general method (issue 17).

Standard DH, A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) with c_i, s_i, a_i, d_i,
lam_i = cos(alpha_i), mu_i = sin(alpha_i). The split A3 A4 A5 = A2^-1 A1^-1 T A6^-1 (M-C eq. 3):
columns 3 and 4 of both sides (a direction l and a point p) do not involve theta6, and the
pose enters through six numbers (lx, ly, lz) = column 3 and (px, py, pz) = column 4 of
T A6^-1. Per side: l (3), p (3), p.p, p.l, p x l (3), v = (p.p) l - 2 (p.l) p (3); equated,
with s^2 = 1 - c^2 and mu^2 = 1 - lam^2 applied until no even power of s or mu is left, they
read (M-C eq. 4)

    (P0 + Ps s3 + Pc c3) m45 = Q m12,
    m45 = [s4 s5, s4 c5, c4 s5, c4 c5, s4, c4, s5, c5, 1],
    m12 = [s1 s2, s1 c2, c1 s2, c1 c2, s1, c1, s2, c2],

P0, Ps, Pc 14 x 9 and Q 14 x 8 in the DH parameters and the six pose numbers; the right side's
constant terms go into P0's last column with their sign changed (ALGORITHMS.md 4.1-4.3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np
import sympy as sp

# the symbols of the derivation
c = sp.symbols("c1:7")
s = sp.symbols("s1:7")
a = sp.symbols("a1:7")
d = sp.symbols("d1:7")
lam = sp.symbols("lam1:7")
mu = sp.symbols("mu1:7")
L = sp.symbols("lx ly lz")
P = sp.symbols("px py pz")
M45 = (s[3] * s[4], s[3] * c[4], c[3] * s[4], c[3] * c[4], s[3], c[3], s[4], c[4], sp.S.One)
M12 = (s[0] * s[1], s[0] * c[1], c[0] * s[1], c[0] * c[1], s[0], c[0], s[1], c[1])
# the equations' order (names for the report)
ROWS: tuple[str, ...] = ("l_x", "l_y", "l_z", "p_x", "p_y", "p_z", "p.p", "p.l")
ROWS += ("(pxl)_x", "(pxl)_y", "(pxl)_z", "v_x", "v_y", "v_z")


@dataclass(frozen=True)
class Fundamental:
    """The matrices of (P0 + Ps s3 + Pc c3) m45 = Q m12 in symbols."""

    P0: sp.Matrix
    Ps: sp.Matrix
    Pc: sp.Matrix
    Q: sp.Matrix


def link(i: int) -> sp.Matrix:
    """A_i of standard DH in symbols (i is 0-based)."""
    ci, si, li, mi = c[i], s[i], lam[i], mu[i]
    return sp.Matrix(
        [
            [ci, -si * li, si * mi, a[i] * ci],
            [si, ci * li, -ci * mi, a[i] * si],
            [0, mi, li, d[i]],
            [0, 0, 0, 1],
        ]
    )


def inverse(m: sp.Matrix) -> sp.Matrix:
    """[R t; 0 1]^-1 = [R^T, -R^T t; 0 1]."""
    rt = m[:3, :3].T
    return sp.Matrix.vstack(sp.Matrix.hstack(rt, -rt * m[:3, 3]), sp.Matrix([[0, 0, 0, 1]]))


def fourteen(l: sp.Matrix, p: sp.Matrix) -> list[sp.Expr]:
    """The 14 scalars of one side from its direction l and point p."""
    pp = p.dot(p)
    pl = p.dot(l)
    cross = p.cross(l)
    v = pp * l - 2 * pl * p
    return [*l, *p, pp, pl, *cross, *v]


# the identities s^2 = 1 - c^2 and mu^2 = 1 - lam^2, as (even variable, its partner)
PAIRS = tuple(zip(s, c)) + tuple(zip(mu, lam))


def normal_form(expr: sp.Expr) -> sp.Expr:
    """expr with s_i^2 = 1 - c_i^2 and mu_i^2 = 1 - lam_i^2 applied until every s_i and mu_i
    appears at most to the first power."""
    expr = sp.expand(expr)
    gens = [g for pair in PAIRS for g in pair]
    poly = sp.Poly(expr, *gens)
    terms = dict(poly.as_dict())
    index = {g: k for k, g in enumerate(gens)}
    changed = True
    while changed:
        changed = False
        out: dict[tuple[int, ...], sp.Expr] = {}
        for monomial, coeff in terms.items():
            for odd, partner in PAIRS:
                k, j = index[odd], index[partner]
                if monomial[k] >= 2:
                    # odd^e = odd^(e-2) (1 - partner^2)
                    base = list(monomial)
                    base[k] -= 2
                    lifted = list(base)
                    lifted[j] += 2
                    for mono, value in ((tuple(base), coeff), (tuple(lifted), -coeff)):
                        out[mono] = out.get(mono, sp.S.Zero) + value
                    changed = True
                    break
            else:
                out[monomial] = out.get(monomial, sp.S.Zero) + coeff
        terms = {m: v for m, v in out.items() if v != 0}
    return sp.Add(*(v * sp.Mul(*(g**e for g, e in zip(gens, m))) for m, v in terms.items()))


@cache
def fundamental() -> Fundamental:
    """The symbolic P0, Ps, Pc and Q (derived once per process)."""
    left = link(2) * link(3) * link(4)
    right = inverse(link(1)) * inverse(link(0))
    target_l = right[:3, :3] * sp.Matrix(L)
    target_p = right[:3, :3] * sp.Matrix(P) + right[:3, 3]
    lhs = [normal_form(e) for e in fourteen(left[:3, 2], left[:3, 3])]
    rhs = [normal_form(e) for e in fourteen(target_l, target_p)]
    P0, Ps, Pc = (sp.zeros(14, 9) for _ in range(3))
    Q = sp.zeros(14, 8)
    angles345 = (s[2], c[2], s[3], c[3], s[4], c[4])
    angles12 = (s[0], c[0], s[1], c[1])
    for row, (one, other) in enumerate(zip(lhs, rhs)):
        poly = sp.Poly(one, *angles345)
        for monomial, coeff in poly.as_dict().items():
            s3e, c3e, rest = monomial[0], monomial[1], monomial[2:]
            column = _column(rest, M45, (s[3], c[3], s[4], c[4]))
            target = Ps if s3e else Pc if c3e else P0
            assert s3e + c3e <= 1, "not linear in (s3, c3)"
            target[row, column] += coeff
        poly = sp.Poly(other, *angles12)
        for monomial, coeff in poly.as_dict().items():
            if sum(monomial) == 0:
                P0[row, 8] -= coeff
                continue
            Q[row, _column(monomial, M12, angles12)] += coeff
    return Fundamental(P0, Ps, Pc, Q)


def _column(exponents: tuple[int, ...], basis: tuple[sp.Expr, ...], gens: tuple) -> int:
    """The index in basis of the monomial with these exponents of gens."""
    term = sp.Mul(*(g**e for g, e in zip(gens, exponents)))
    if term not in basis:
        raise AssertionError(f"{term} is not in the basis (degree above 1 in a pair)")
    return basis.index(term)


# --- the numeric steps for one pose (a numpy reference; the printed solvers follow it) -------

# coefficients over (x^0, x^1, x^2) of s (1 + x^2), c (1 + x^2) and (1 + x^2), x = tan(t/2)
_S, _C, _O = (0.0, 2.0, 0.0), (1.0, 0.0, -1.0), (1.0, 0.0, 1.0)
# m45 (1 + x4^2)(1 + x5^2) = H45 [x4^i x5^j], column 3 i + j
_H45_ROWS = (
    (_S, _S), (_S, _C), (_C, _S), (_C, _C), (_S, _O), (_C, _O), (_O, _S), (_O, _C), (_O, _O),
)  # fmt: skip


def h45() -> list[list[float]]:
    """The 9 x 9 map from m45 to the monomials x4^i x5^j (i, j in 0..2)."""
    return [[u[i] * w[j] for i in range(3) for j in range(3)] for u, w in _H45_ROWS]


def eliminate(P0, Ps, Pc, Q, moebius=(1.0, 0.3, -0.4, 1.0)):
    """The 12 x 12 matrix polynomial A y^2 + B y + C in y, x3 = (a y + b) / (c y + d), whose
    real roots give theta3 (numpy arrays in, out). Q's left null space N (generically 6 x 14)
    removes theta1, theta2; the half-angle substitution and the dialytic lift (stack and times
    x4) give 12 x 12 (M-C eqs 13-14); the Moebius map keeps theta3 = pi (x3 = inf) finite."""
    import numpy as np

    U, S, _ = np.linalg.svd(Q)
    rank = int((1e-10 * max(S[0], 1.0) < S).sum())
    N = U[:, rank:].T
    if N.shape[0] > 6:  # a rank-deficient Q: six fixed combinations of the rows
        mix = np.random.default_rng(0).normal(size=(6, N.shape[0]))
        N = mix @ N
    H = np.array(h45())
    A6, B6, C6 = (N @ M @ H for M in (P0 - Pc, 2.0 * Ps, P0 + Pc))
    a_, b_, c_, d_ = moebius
    # x3 = (a y + b) / (c y + d); times (c y + d)^2
    A6, B6, C6 = (
        a_ * a_ * A6 + a_ * c_ * B6 + c_ * c_ * C6,
        2 * a_ * b_ * A6 + (a_ * d_ + b_ * c_) * B6 + 2 * c_ * d_ * C6,
        b_ * b_ * A6 + b_ * d_ * B6 + d_ * d_ * C6,
    )

    def lift(M6):
        M = np.zeros((12, 12))
        for i in range(3):
            for j in range(3):
                M[:6, 3 * i + j] = M6[:, 3 * i + j]
                M[6:, 3 * (i + 1) + j] = M6[:, 3 * i + j]
        return M

    return lift(A6), lift(B6), lift(C6)


def theta3_candidates(A, B, C, moebius=(1.0, 0.3, -0.4, 1.0), imag_tol=1e-6):
    """Real roots y of det(A y^2 + B y + C) as theta3 values, with their null vectors v
    (12, proportional to x4^i x5^j), from the companion matrix [[0, I], [-A^-1 C, -A^-1 B]]."""
    Ainv = np.linalg.inv(A)
    top = np.hstack((np.zeros((12, 12)), np.eye(12)))
    bottom = np.hstack((-Ainv @ C, -Ainv @ B))
    values, vectors = np.linalg.eig(np.vstack((top, bottom)))
    a_, b_, c_, d_ = moebius
    out = []
    for y, z in zip(values, vectors.T):
        if abs(y.imag) > imag_tol * (1 + abs(y)):
            continue
        y = y.real
        x3 = (a_ * y + b_) / (c_ * y + d_)
        v = z[:12].real if abs(z[:12]).max() >= abs(z[12:]).max() else (z[12:] / y).real
        out.append((2.0 * np.arctan(x3), v))
    return out


def half_angle_ratio(v, step):
    """The angle t whose x = tan(t/2) relates the entries of v (12, proportional to
    x4^i x5^j at 3 i + j) that are `step` apart (1: x5, 3: x4), by least squares; x = inf
    (t = pi) is fine."""
    if step == 1:
        lo = np.array([v[3 * i + j] for i in range(4) for j in range(2)])
        hi = np.array([v[3 * i + j + 1] for i in range(4) for j in range(2)])
    else:
        lo, hi = v[:9], v[3:]
    across, low, high = float(hi @ lo), float(lo @ lo), float(hi @ hi)
    if low >= high:
        return 2.0 * np.arctan2(across, low)
    return 2.0 * np.arctan2(high, across)


def back_substitute(theta3, v, P0, Ps, Pc, Q, rows, T):
    """The joint angles of one theta3 candidate: theta4, theta5 from v, theta1, theta2 from
    Q m12 = P(theta3) m45 (least squares), theta6 from the pose. rows: standard-DH (offset,
    d, a, alpha) per joint, the angles here being the full theta_i."""
    t4, t5 = half_angle_ratio(v, 3), half_angle_ratio(v, 1)
    s3, c3, s4, c4, s5, c5 = (f(t) for t in (theta3, t4, t5) for f in (np.sin, np.cos))
    m45 = np.array([s4 * s5, s4 * c5, c4 * s5, c4 * c5, s4, c4, s5, c5, 1.0])
    m12 = np.linalg.lstsq(Q, (P0 + Ps * s3 + Pc * c3) @ m45, rcond=None)[0]
    t1, t2 = np.arctan2(m12[4], m12[5]), np.arctan2(m12[6], m12[7])
    thetas = [t1, t2, theta3, t4, t5]
    front = np.eye(4)
    for t, (_, di, ai, alpha) in zip(thetas, rows):
        front = front @ _standard(t, di, ai, alpha)
    last = np.linalg.inv(front) @ T @ np.linalg.inv(_standard(0.0, 0.0, rows[5][2], rows[5][3]))
    # last = Rz(theta6) Tz(d6): its first column is (c6, s6, 0)
    return [*thetas, float(np.arctan2(last[1, 0], last[0, 0]))]


def _standard(theta, d, a, alpha):
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0, sa, ca, d],
            [0, 0, 0, 1],
        ]
    )


def pose_numbers(rows, T):
    """The six pose numbers: columns 3 and 4 of T A6^-1 (free of theta6)."""
    M = T @ np.linalg.inv(_standard(0.0, *rows[5][1:]))
    return (*M[:3, 2], *M[:3, 3])


@cache
def _numeric_matrices():
    f = fundamental()
    args = (*a[:5], *d[:5], *lam[:5], *mu[:5], *L, *P)
    return [sp.lambdify(args, m, "numpy") for m in (f.P0, f.Ps, f.Pc, f.Q)]


def solve_reference(rows, T, tol=1e-6):
    """Every certified solution of a standard-DH 6R arm for the pose T (numpy 4x4): the
    general method's steps in numpy, as the printed solvers will run them (no polish, no
    rescue yet). rows: (theta offset, d, a, alpha) per joint; angles returned are theta_i."""
    numbers = (
        *(r[2] for r in rows[:5]), *(r[1] for r in rows[:5]),
        *(math.cos(r[3]) for r in rows[:5]), *(math.sin(r[3]) for r in rows[:5]),
        *pose_numbers(rows, T),
    )  # fmt: skip
    P0, Ps, Pc, Q = (np.array(fn(*numbers), dtype=float) for fn in _numeric_matrices())
    A, B, C = eliminate(P0, Ps, Pc, Q)
    out = []
    for theta3, v in theta3_candidates(A, B, C):
        q = back_substitute(theta3, v, P0, Ps, Pc, Q, rows, T)
        pose = np.linalg.multi_dot([_standard(t, *r[1:]) for t, r in zip(q, rows)])
        if np.abs(pose - T).max() <= tol:
            out.append(q)
    return out
