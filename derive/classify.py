"""Which solvable structure an arm has, from its canonical DH chain (docs/algorithms.md,
"Classifying an arm").

Axis i and axis i+1 are related by the twist X_i = Rx(alpha_i) Tx(a_i) and by d_{i+1}, in both
conventions. Exact numbers are tested exactly; float numbers within a relative tolerance.

========================  =============================================================
P(i) axes i, i+1 parallel   sin(alpha_i) = 0
I(i) intersect              a_i = 0 and not P(i) (both joints revolute)
C(i) coincide               a_i = 0 and P(i): degenerate, one DOF is lost
S(i) concurrent triple      I(i), I(i+1) and d_{i+1} = 0 (joint i+1 revolute)
3P(i) parallel triple       P(i) and P(i+1), none coincident
========================  =============================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from derive.transforms import Chain

ANGLE_TOL = 1e-9
LENGTH_TOL = 1e-9


@dataclass(frozen=True)
class Structure:
    """Axis relations of an arm (1-based axis indices).

    Attributes:
        parallel: i such that axes i and i+1 are parallel.
        intersecting: i such that axes i and i+1 intersect.
        coincident: i such that axes i and i+1 coincide (degenerate).
        concurrent: i such that axes i, i+1, i+2 meet in one point.
        parallel_triples: i such that axes i, i+1, i+2 are parallel.
    """

    parallel: tuple[int, ...]
    intersecting: tuple[int, ...]
    coincident: tuple[int, ...]
    concurrent: tuple[int, ...]
    parallel_triples: tuple[int, ...]

    def describe(self, n: int) -> tuple[str, ...]:
        """Human-readable facts, most specific first; e.g. "spherical wrist at joints 4-6"."""
        facts = []
        for i in self.concurrent:
            if i == n - 2:
                facts.append(f"spherical wrist at joints {i}-{i + 2}")
            else:
                facts.append(f"axes {i}, {i + 1}, {i + 2} meet in a point")
        for i in self.parallel_triples:
            facts.append(f"axes {i}, {i + 1}, {i + 2} parallel")
        for i in self.coincident:
            facts.append(f"axes {i} and {i + 1} coincide (degenerate)")
        if n >= 2 and len(self.parallel) == n - 1:
            facts.insert(0, "planar: all axes parallel")
        if not facts and n < 3:
            facts.append("axes 1 and 2 neither parallel nor the same" if n == 2 else "one axis")
        if not facts:
            facts.append("no three consecutive axes meet or are parallel")
        return tuple(facts)


def is_zero(value: sp.Expr, tol: float) -> bool:
    """Exact zero test for exact numbers, |value| < tol for floats."""
    value = sp.sympify(value)
    if value.is_Float or not value.is_number:
        return bool(abs(float(value)) < tol)
    return bool(value == 0)


def classify(chain: Chain) -> Structure:
    """Axis relations of consecutive axes of a canonical chain."""
    n = chain.dof
    scale = max(
        [1.0]
        + [abs(float(t.a)) for t in chain.twists]
        + [abs(float(j.d)) for j in chain.joints if j.kind == "R"]
    )
    parallel, intersecting, coincident = [], [], []
    for i in range(1, n):
        twist = chain.twists[i]
        par = is_zero(twist.sa, ANGLE_TOL)
        zero_a = is_zero(twist.a, LENGTH_TOL * scale)
        both_r = chain.joints[i - 1].kind == "R" and chain.joints[i].kind == "R"
        if par:
            parallel.append(i)
        if par and zero_a and both_r:
            coincident.append(i)
        elif zero_a and both_r:
            intersecting.append(i)
    concurrent = [
        i
        for i in range(1, n - 1)
        if i in intersecting
        and i + 1 in intersecting
        and is_zero(chain.joints[i].d, LENGTH_TOL * scale)
    ]
    triples = [
        i
        for i in range(1, n - 1)
        if i in parallel and i + 1 in parallel and i not in coincident and i + 1 not in coincident
    ]
    return Structure(
        tuple(parallel), tuple(intersecting), tuple(coincident), tuple(concurrent), tuple(triples)
    )
