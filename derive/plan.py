"""The solution plan: plain frozen dataclasses that emit and report read.

A plan is symbolic (SymPy expressions) but holds no derivation logic. The IK part is an
ordered list of steps. An :class:`Assign` computes intermediate quantities; a
:class:`Solve` finds the values of one joint and, in the generated code, opens a loop over
them: every later step runs once per value. After the last step the joint values are
complete and the solver certifies them by forward kinematics.

Solve kinds (the generated module implements each once, as a helper):

=========  =========================================================================
``cs1``    a cos t + b sin t = e: t = atan2(b, a) +- acos(e / sqrt(a^2 + b^2)); args (a, b, e);
           t is free (reference value) when the equation vanishes identically (Solve.scale)
``cs1r``   cs1 whose free value must leave the next joint t' a value keeping
           W = sum M_ij u_i(t') u_j(t) inside [lo, hi], u = (1, cos, sin); args (a, b, e,
           M00, M01, M02, M10, M11, M12, M20, M21, M22, lo, hi): the first value in 5 degree
           steps out from the reference value that allows it
``cs2``    a1 c + b1 s = e1, a2 c + b2 s = e2: one t from the 2x2 system; args (a1, b1, e1,
           a2, b2, e2, det_scale, rhs_scale): t is free (reference value) when the determinant
           is below 1e-14 det_scale or e1^2 + e2^2 below 1e-14 rhs_scale
``cs2r``   cs2 whose free value must keep a radius A + B cos t + C sin t inside [lo, hi]; args
           (the cs2 args, A, B, C, lo, hi): q_ref's value if inside, else the nearest one
           putting the radius mid-range
``atan2``  t = atan2(y, x); args (y, x); both vanishing leaves t free (reference value)
``poly``   polynomial in u = tan(t/2), coefficients highest degree first; u = inf is t = pi
``polyd``  polynomial in a prismatic joint's d_i, coefficients highest degree first
=========  =========================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp


@dataclass(frozen=True)
class ArmInfo:
    """What the generated module states about the arm (numbers as Python floats).

    Attributes:
        name: module name.
        digest: digest of the canonical spec.
        convention: "standard" or "modified".
        angle_unit: the spec's angle unit (the DH constants are exported in radians).
        length_unit: the spec's length label.
        joint_types: e.g. "RRRRRR".
        dh: rows (alpha, a, d, theta) in radians and length units, as in the spec.
        limits: (lower, upper) per joint in radians / length; +-inf where none.
        base: 16 floats, row-major.
        tool: 16 floats, row-major.
        reach: characteristic length of the arm (sum of |a| and |d| and the frame offsets),
            used to scale position tolerances.
        example_q: joint values of the worked example (radians / length), or None.
        example_pose: world pose of the worked example (16 floats, row-major), or None.
    """

    name: str
    digest: str
    convention: str
    angle_unit: str
    length_unit: str
    joint_types: str
    dh: tuple[tuple[float, float, float, float], ...]
    limits: tuple[tuple[float, float], ...]
    base: tuple[float, ...]
    tool: tuple[float, ...]
    reach: float
    example_q: tuple[float, ...] | None = None
    example_pose: tuple[float, ...] | None = None

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.joint_types)


@dataclass(frozen=True)
class Assign:
    """Intermediate quantities computed in order: targets[k] = exprs[k]."""

    targets: tuple[sp.Symbol, ...]
    exprs: tuple[sp.Expr, ...]
    note: str = ""


@dataclass(frozen=True)
class Solve:
    """Values of one joint variable.

    Attributes:
        joint: 1-based joint index.
        kind: one of the kinds in the module docstring.
        args: the kind's arguments, expressions in earlier quantities.
        note: the derivation step, printed as a comment ("Pieper r/z ellipse, ...").
        fanout: the most values this step can produce.
        ref: the value the joint takes where the pose leaves it free (``cs2``, ``atan2``, and
            ``poly`` when the polynomial vanishes identically), as an expression in the
            reference joint values qr_i.
        scale: for ``poly``: a typical magnitude of the coefficients; when all of them are
            below 1e-10 of it the polynomial vanishes identically and the joint is free.
            For ``cs1``: the typical size of a^2 + b^2; when a^2 + b^2 and e^2 are below
            1e-14 of it the equation holds for every angle, and the joint is free.
        unit: for ``polyd``: the arm's length; the roots are found for d_i / unit, so that the
            coefficients, powers of a length, are compared at one scale.
    """

    joint: int
    kind: str
    args: tuple[sp.Expr, ...]
    note: str
    fanout: int
    ref: sp.Expr = sp.S.Zero
    scale: float = 0.0
    unit: float = 1.0


Step = Assign | Solve


@dataclass(frozen=True)
class IkPlan:
    """A closed-form IK solution.

    Attributes:
        method: short method name ("pieper", ...).
        case: the case of the method that applies, in words.
        max_solutions: the most solutions a pose can have by this derivation.
        steps: the ordered steps; see the module docstring.
        outputs: q_1..q_n as expressions of the solved joint quantities.
        details: derivation facts for the report: name -> expression (sorted by name).
        solves_for: the pose components the solver is defined on, in words.
        certify: "pose" (every solution reproduces the whole pose) or "position" (the tool
            point only: arms that do not control the orientation).
    """

    method: str
    case: str
    max_solutions: int
    steps: tuple[Step, ...]
    outputs: tuple[sp.Expr, ...]
    details: tuple[tuple[str, sp.Expr], ...] = ()
    solves_for: str = "the full pose (rotation and position)"
    certify: str = "pose"


@dataclass(frozen=True)
class Plan:
    """Everything emit and report need for one arm.

    Attributes:
        arm: the arm's numeric description.
        structure: structure facts found by classification, e.g. "spherical wrist at joints 4-6".
        fk_pose: world pose B 0_nT E as a 4x4 matrix in c_i, s_i (R) and d_i (P).
        links: the link transforms (i-1)_iT in the spec's convention, in c_i, s_i and d_i.
        joint_defs: (symbol, expression in q_i) defining theta_i or d_i for each joint.
        ik: the IK plan, or None when no method applies.
        refusal: why no IK method applies (one line), or "" when ik is set.
    """

    arm: ArmInfo
    structure: tuple[str, ...]
    fk_pose: sp.Matrix
    links: tuple[sp.Matrix, ...]
    joint_defs: tuple[tuple[sp.Symbol, sp.Expr], ...]
    ik: IkPlan | None
    refusal: str = ""
