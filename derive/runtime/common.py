"""Argument checks and joint-value helpers shared by the generated module's solvers."""

from __future__ import annotations

import math

import numpy as np

from derive.runtime.arm import _REVOLUTE, DOF, LIMITS, REACH
from derive.runtime.constants import _LIMIT_SLACK, _SEAM_SNAP, _TWO_PI, FAR_REACH

_PERIODS = tuple(2.0 * math.pi if r else math.inf for r in _REVOLUTE)


def _joint_values(q: object) -> list[float]:
    """q as DOF finite floats (fk's and jacobian's argument).

    Raises:
        ValueError: q is not DOF finite numbers.
    """
    values = _real(q, "q")
    if values.shape != (DOF,):
        raise ValueError(f"q must have shape ({DOF},), got {values.shape}")
    joints = values.tolist()
    if not all(map(math.isfinite, joints)):
        raise ValueError(f"q must be {DOF} finite numbers")
    return joints


def _real(x: object, name: str) -> np.ndarray:
    """x as a float64 array; ValueError for anything but real numbers (ints and floats:
    not complex numbers, booleans, strings or None)."""
    if type(x) is np.ndarray and x.dtype == np.float64:
        return x
    try:
        a = np.asarray(x)
        if a.dtype.kind not in "fiu" and not (
            a.dtype.kind == "O"
            and not any(v is None or isinstance(v, (bool, np.bool_, str, bytes)) for v in a.flat)
        ):
            raise TypeError
        if type(x) is not np.ndarray and _holds_bool(x):  # ([True, 0.5, 0.2] is floats to numpy)
            raise TypeError
        return a.astype(float)
    except (TypeError, ValueError, OverflowError):  # (OverflowError: an int beyond a float)
        raise ValueError(f"{name} must be an array of real numbers (ints or floats)") from None


def _holds_bool(x: object) -> bool:
    """Whether x is a boolean or a list or tuple holding one, at any depth."""
    if isinstance(x, (list, tuple)):
        return any(map(_holds_bool, x))
    return isinstance(x, (bool, np.bool_))


_ONES = np.ones(DOF)


# a pose farther than this along an axis is out of reach (constants.FAR_REACH)
_FAR = FAR_REACH * REACH


def _reference(q_ref: object, required: bool = False) -> tuple[float, ...]:
    """q_ref as a tuple of DOF floats (zeros for None unless required)."""
    if q_ref is None and not required:
        return _ZEROS
    if type(q_ref) is tuple and len(q_ref) == DOF and all(type(x) is float for x in q_ref):
        values = q_ref
    else:
        try:
            a = _real(q_ref, "q_ref")
        except ValueError:
            a = None
        if a is None or a.shape != (DOF,):
            shape = "" if a is None else f", got shape {a.shape}"
            raise ValueError(f"q_ref must be {DOF} finite real numbers, shape ({DOF},){shape}")
        values = tuple(a.tolist())
    if not all(map(math.isfinite, values)):
        raise ValueError(f"q_ref must be {DOF} finite real numbers, got {values}")
    return values


_ZEROS = (0.0,) * DOF


def _tolerance(tol: float) -> float:
    """tol as a float, if it is a positive finite number."""
    if type(tol) is float and 0.0 < tol < math.inf:
        return tol
    try:
        value = float(tol)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(tol, (bool, str, bytes)) or not (0.0 < value < math.inf):
        raise ValueError(f"tol must be a positive finite number, got {tol!r}")
    return value


def _wrap(x: float) -> float:
    w = math.remainder(x, _TWO_PI)
    return math.pi if w <= -math.pi else w


def _seam(x: float) -> float:
    """A wrapped revolute value near +-pi: above pi if it is within _SEAM_BAND above -pi, pi
    itself within _SEAM_SNAP of pi."""
    if x < 0.0:
        x += _TWO_PI
    return math.pi if abs(x - math.pi) <= _SEAM_SNAP else x


_REV = np.array([1.0 if r else 0.0 for r in _REVOLUTE])


_LOWER = np.array([lo - _LIMIT_SLACK for lo, _ in LIMITS])


_UPPER = np.array([hi + _LIMIT_SLACK for _, hi in LIMITS])
