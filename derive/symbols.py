"""The one place where SymPy symbols and exact numbers are created.

Glossary (lecture notation, Craig ch. 4):

=============  =====================================================================
``q1..qn``     joint variables: radians for R joints, length for P joints
``qr1..qrn``   reference joint values (free joints at singular poses take them)
``theta1..``   joint angles theta_i = q_i + offset (R joints)
``c1, s1..``   cos(theta_i), sin(theta_i); ``c23`` style sums appear only in reports
``d1..dn``     link offsets d_i; the joint variable's d_i = q_i + d for P joints
``a1..``       link lengths a_i in general (not yet numeric) formulas
``calpha1..``  cos(alpha_i), ``salpha1..`` sin(alpha_i) in general formulas
``u``          half-angle tangent u = tan(theta/2) of the joint being solved
``w11..w33``   world target rotation;  ``wx, wy, wz`` world target position
``r11..r33``   target rotation of the flange (base and tool removed); ``px, py, pz``
               its position (the lecture's 0_6T)
``r``, ``z``   Pieper's r = x^2 + y^2 + z^2 and z of the wrist centre
=============  =====================================================================

Numbers from a spec become exact SymPy numbers: lengths as the rational number their
decimal text denotes (0.4318 -> 2159/5000), angles that are multiples of 15 degrees as
exact multiples of pi (so cos(-90 deg) is exactly 0), other angles as floats.
"""

from __future__ import annotations

import math
from functools import cache

import sympy as sp

ANGLE_SNAP = 1e-12


@cache
def q(i: int) -> sp.Symbol:
    """Joint variable q_i."""
    return sp.Symbol(f"q{i}", real=True)


@cache
def q_ref(i: int) -> sp.Symbol:
    """Reference value of q_i, taken by a joint that a singular pose leaves free."""
    return sp.Symbol(f"qr{i}", real=True)


@cache
def theta(i: int) -> sp.Symbol:
    """Joint angle theta_i."""
    return sp.Symbol(f"theta{i}", real=True)


@cache
def c(i: int) -> sp.Symbol:
    """cos(theta_i)."""
    return sp.Symbol(f"c{i}", real=True)


@cache
def s(i: int) -> sp.Symbol:
    """sin(theta_i)."""
    return sp.Symbol(f"s{i}", real=True)


@cache
def d(i: int) -> sp.Symbol:
    """Prismatic joint offset d_i."""
    return sp.Symbol(f"d{i}", real=True)


@cache
def named(name: str) -> sp.Symbol:
    """A real symbol for an intermediate quantity (u, r, z, ...)."""
    return sp.Symbol(name, real=True)


def world_pose() -> sp.Matrix:
    """The world target pose as a 4x4 matrix of symbols w11..w33, wx, wy, wz."""
    return _pose_matrix("w", ("wx", "wy", "wz"))


def flange_pose() -> sp.Matrix:
    """The flange target pose as a 4x4 matrix of symbols r11..r33, px, py, pz."""
    return _pose_matrix("r", ("px", "py", "pz"))


def _pose_matrix(prefix: str, position: tuple[str, str, str]) -> sp.Matrix:
    rows = [
        [named(f"{prefix}{i}{j}") for j in (1, 2, 3)] + [named(position[i - 1])] for i in (1, 2, 3)
    ]
    return sp.Matrix([*rows, [0, 0, 0, 1]])


def length(value: float) -> sp.Expr:
    """An exact rational for a length written in a spec (its shortest decimal text)."""
    return sp.Rational(repr(float(value)))


def angle(value: float, unit: str) -> sp.Expr:
    """An angle in radians: an exact multiple of pi/12 when it is one, else a float.

    Args:
        value: the angle as written in the spec.
        unit: "deg" or "rad".
    """
    if unit == "deg":
        exact = sp.Rational(repr(float(value)))
        if (exact / 15).is_integer:
            return sp.pi * exact / 180
        return sp.Float(math.radians(value), 17)
    twelfths = value * 12 / math.pi
    if abs(twelfths - round(twelfths)) < ANGLE_SNAP * max(1.0, abs(twelfths)):
        return sp.pi * sp.Rational(round(twelfths), 12)
    return sp.Float(value, 17)


def cos_sin(rad: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(cos, sin) of an angle from :func:`angle`: exact for multiples of pi/12."""
    if rad.is_Float:
        return sp.Float(math.cos(float(rad)), 17), sp.Float(math.sin(float(rad)), 17)
    return sp.cos(rad), sp.sin(rad)


@cache
def link_a(i: int) -> sp.Symbol:
    """Link length a_i (general form, before the arm's numbers are substituted)."""
    return sp.Symbol(f"a{i}", real=True)


@cache
def cos_alpha(i: int) -> sp.Symbol:
    """cos(alpha_i) (general form)."""
    return sp.Symbol(f"calpha{i}", real=True)


@cache
def sin_alpha(i: int) -> sp.Symbol:
    """sin(alpha_i) (general form)."""
    return sp.Symbol(f"salpha{i}", real=True)
