"""Linear-in-(cos, sin) equations and tangent-half-angle reductions to polynomials.

The lecture's tool for ``a cos(theta) + b sin(theta) = c``: with u = tan(theta/2),
cos(theta) = (1 - u^2)/(1 + u^2) and sin(theta) = 2u/(1 + u^2), so an equation that is a
polynomial of degree m in (cos, sin) becomes, times (1 + u^2)^m, a polynomial of degree 2m
in u. A root at u = infinity is theta = pi; it shows as a vanishing leading coefficient.
"""

from __future__ import annotations

import sympy as sp


def reduce_pairs(expr: sp.Expr, pairs: list[tuple[sp.Symbol, sp.Symbol]]) -> sp.Expr:
    """Apply sin^2 = 1 - cos^2 for each (sin, cos) pair until sin appears at most linearly.

    Args:
        expr: a polynomial in the symbols.
        pairs: (sin symbol, cos symbol) pairs, e.g. (s3, c3) or (sin alpha1, cos alpha1).
    """
    expr = sp.expand(expr)
    for si, ci in pairs:
        if not expr.has(si):
            continue
        out = sp.Integer(0)
        for (power,), coeff in sp.Poly(expr, si).terms():
            out += coeff * (1 - ci**2) ** (power // 2) * si ** (power % 2)
        expr = sp.expand(out)
    return expr


def linear_coeffs(expr: sp.Expr, cs: sp.Symbol, sn: sp.Symbol) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """(A, B, C) with expr = A cs + B sn + C; raises ValueError if expr is not linear in them."""
    poly = sp.Poly(sp.expand(expr), cs, sn)
    if poly.total_degree() > 1:
        raise ValueError(f"not linear in {cs}, {sn}")
    get = poly.as_dict()
    return (
        get.get((1, 0), sp.Integer(0)),
        get.get((0, 1), sp.Integer(0)),
        get.get((0, 0), sp.Integer(0)),
    )


def half_angle_poly(
    expr: sp.Expr, cs: sp.Symbol, sn: sp.Symbol, u: sp.Symbol
) -> tuple[sp.Expr, ...]:
    """Coefficients (highest degree first) of (1 + u^2)^m expr(cos, sin) as a polynomial in u.

    Args:
        expr: a polynomial in cs, sn (other symbols are parameters), already reduced so that
            sn appears at most linearly.
        cs: the cos symbol.
        sn: the sin symbol.
        u: the half-angle tangent symbol.

    Returns:
        2m + 1 coefficients, m the total degree of expr in (cs, sn); leading ones may be zero
        (roots at u = infinity).
    """
    degree = sp.Poly(expr, cs, sn).total_degree()
    one_plus = 1 + u**2
    out = sp.Integer(0)
    for (pc, ps), coeff in sp.Poly(expr, cs, sn).terms():
        out += coeff * (1 - u**2) ** pc * (2 * u) ** ps * one_plus ** (degree - pc - ps)
    poly = sp.Poly(sp.expand(out), u)
    coeffs = [sp.Integer(0)] * (2 * degree + 1 - len(poly.all_coeffs())) + poly.all_coeffs()
    return tuple(sp.expand(cf) for cf in coeffs)
