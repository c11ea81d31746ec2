"""A method written the way a new one is added, kept with the tests: two revolute joints
(a pan-tilt head), solved from the orientation alone.

It is what a file under derive/methods/ holds: a ``derive(chain, structure)`` that returns an
IkPlan built from the existing step kinds, or a one-line reason. Registering it is one line in
derive/pipeline.py's METHODS; tests/test_printers.py registers it for one test and generates,
imports and solves with the module.

The derivation: the flange rotation R = Z1 X1 Z2 (Craig's factors) has entries that depend on
theta1 alone (a c1 + b s1, the second joint's axis seen from the base); two of them with
independent coefficients give theta1 from a 2x2 system (Cs2). Entries linear in c2, s2 with
coefficients in c1, s1 give theta2 the same way.
"""

from __future__ import annotations

import math

import sympy as sp

from derive import symbols as sym
from derive.classify import Structure
from derive.halfangle import linear_coeffs
from derive.methods.common import flange_target, joint_outputs, joint_refs
from derive.methods.planar import flange_factors
from derive.plan import Cs2, IkPlan, Step
from derive.transforms import Chain, numbers_of, product

NAME = "pan-tilt"


def derive(chain: Chain, structure: Structure) -> IkPlan | str:
    """The plan of a 2R arm from its orientation, or why not."""
    if chain.dof != 2 or any(j.kind != "R" for j in chain.joints):
        return "pan-tilt: two revolute joints only"
    rotation = product(flange_factors(chain)).xreplace(numbers_of(chain))[:3, :3]
    target = sym.flange_pose()
    c1, s1, c2, s2 = sym.c(1), sym.s(1), sym.c(2), sym.s(2)
    first = _pair(rotation, target, c1, s1, {c1: 1.0, s1: 0.0})
    if first is None:
        return "pan-tilt: no two entries of the rotation give theta1"
    known = {c1: math.cos(0.7), s1: math.sin(0.7)}
    second = _pair(rotation, target, c2, s2, known)
    if second is None:
        return "pan-tilt: no two entries of the rotation give theta2"
    refs = joint_refs(chain)
    steps: list[Step] = [flange_target(chain, sym.world_pose())]
    for joint, args in ((1, first), (2, second)):
        steps.append(Cs2(joint, args, f"theta{joint}: two rotation entries", 1, refs[joint - 1]))
    return IkPlan(NAME, "orientation: two entries per joint", 1, tuple(steps), joint_outputs(chain))


def _pair(
    rotation: sp.Matrix,
    target: sp.Matrix,
    c: sp.Symbol,
    s: sp.Symbol,
    at: dict[sp.Symbol, float],
) -> tuple[sp.Expr, ...] | None:
    """Cs2's arguments from the first two entries linear in (c, s), with coefficients in
    earlier joints only and independent (checked at the values `at`), or None."""
    later = {sym.c(2), sym.s(2)} - {c, s}
    found = []
    for i in range(3):
        for j in range(3):
            expr = sp.expand(rotation[i, j])
            if expr.free_symbols & later or not expr.free_symbols & {c, s}:
                continue
            a, b, rest = linear_coeffs(expr, c, s)
            found.append((a, b, target[i, j] - rest))
    for k, (a1, b1, e1) in enumerate(found):
        for a2, b2, e2 in found[k + 1 :]:
            if abs(float((a1 * b2 - a2 * b1).xreplace(at))) > 1e-6:
                return (a1, b1, e1, a2, b2, e2, sp.Float(1.0), sp.Float(1.0))
    return None
