"""The 14 fundamental equations of a general 6R arm (Raghavan and Roth; Manocha and Canny's
form), derived once in symbols for every arm: the first step of the general method (issue 17).

Standard DH, A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i) with c_i, s_i, a_i, d_i,
lambda_i = cos(alpha_i), mu_i = sin(alpha_i). The split A3 A4 A5 = A2^-1 A1^-1 T A6^-1 (M-C eq. 3):
columns 3 and 4 of both sides (a direction l and a point p) do not involve theta6, and the
pose enters through six numbers (l_x, l_y, l_z) = column 3 and (p_x, p_y, p_z) = column 4 of
T A6^-1. Per side: l (3), p (3), p.p, p.l, p x l (3), v = (p.p) l - 2 (p.l) p (3); equated,
with s^2 = 1 - c^2 and mu^2 = 1 - lambda^2 applied until no even power of s or mu is left, they
read (M-C eq. 4)

    (P0 + Ps s3 + Pc c3) m45 = Q m12,
    m45 = [s4 s5, s4 c5, c4 s5, c4 c5, s4, c4, s5, c5, 1],
    m12 = [s1 s2, s1 c2, c1 s2, c1 c2, s1, c1, s2, c2],

P0, Ps, Pc 14 x 9 and Q 14 x 8 in the DH parameters and the six pose numbers; the right side's
constant terms go into P0's last column with their sign changed (docs/algorithms.md, "The
split and the 14 fundamental equations").
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

import sympy as sp

# the symbols of the derivation
c = sp.symbols("c1:7")
s = sp.symbols("s1:7")
a = sp.symbols("a1:7")
d = sp.symbols("d1:7")
lam = sp.symbols("lambda1:7")
mu = sp.symbols("mu1:7")
L = sp.symbols("l_x l_y l_z")
P = sp.symbols("p_x p_y p_z")
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


# the generators of the entries' polynomials, in the order of the stored derivation
GENS: tuple[sp.Symbol, ...] = (*a[:5], *d[:5], *lam[:5], *mu[:5], *L, *P)
# the stored derivation (package data; `python -m derive.raghavan_roth` rewrites it)
STORED = "fundamental.json"


@cache
def fundamental() -> Fundamental:
    """The symbolic P0, Ps, Pc and Q, read from the stored derivation (derive_fundamental's
    result, written at build time: 0.1 s to read instead of ~9 s to derive)."""
    text = resources.files("derive.data").joinpath(STORED).read_text(encoding="utf-8")
    return from_terms(json.loads(text))


def to_terms(f: Fundamental) -> dict[str, list[list[list[int]]]]:
    """The matrices as integer terms: per matrix, per entry (row-major), [coefficient,
    exponents of GENS...] sorted (the stored form: plain data, parsed without evaluation)."""
    out = {}
    for name in ("P0", "Ps", "Pc", "Q"):
        entries = []
        for e in getattr(f, name):
            terms = []
            for monomial, coeff in sp.Poly(e, *GENS).as_dict().items():
                if not coeff.is_Integer:
                    raise AssertionError(f"{name}: coefficient {coeff} is not an integer")
                terms.append([int(coeff), *monomial])
            entries.append(sorted(terms))
        out[name] = entries
    return out


def from_terms(data: dict[str, list[list[list[int]]]]) -> Fundamental:
    """The matrices from their stored terms."""
    shapes = {"P0": (14, 9), "Ps": (14, 9), "Pc": (14, 9), "Q": (14, 8)}
    mats = {}
    for name, shape in shapes.items():
        exprs = [
            sp.Add(*(t[0] * sp.Mul(*(g**e for g, e in zip(GENS, t[1:]))) for t in terms))
            for terms in data[name]
        ]
        mats[name] = sp.Matrix(*shape, exprs)
    return Fundamental(**mats)


def derive_fundamental() -> Fundamental:
    """The symbolic P0, Ps, Pc and Q derived from the link transforms (about 9 s)."""
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


def main() -> None:
    """Rewrite the stored derivation: python -m derive.raghavan_roth [PATH]."""
    path = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "data" / STORED
    text = json.dumps(to_terms(derive_fundamental()), separators=(",", ":")) + "\n"
    path.write_text(text, encoding="utf-8")
    print(f"wrote {path} ({len(text)} bytes)")


if __name__ == "__main__":
    main()
