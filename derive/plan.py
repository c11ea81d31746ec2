"""The solution plan: plain frozen dataclasses that emit and report read.

A plan is symbolic (SymPy expressions) but holds no derivation logic. The IK part is an
ordered list of steps. An :class:`Assign` computes intermediate quantities; a
:class:`Solve` finds the values of one joint and, in the generated code, opens a loop over
them: every later step runs once per value. After the last step the joint values are
complete and the solver certifies them by forward kinematics.

Each kind of Solve step is a subclass of :class:`Solve` (Cs1, Cs1Reach, Cs2, Cs2Reach,
Atan2, Poly, PolyPi, PolyD: :data:`SOLVE_KINDS`) naming its arguments; each backend's printer in
derive/printers/ prints every kind, and the runtime routine it calls solves it.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, ClassVar

import sympy as sp

from derive.spec import Source


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
        origin: the URDF the spec was converted from, or None.
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
    origin: Source | None = None

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
    """Values of one joint variable; each kind of equation is a subclass (below).

    Attributes:
        joint: 1-based joint index.
        args: the kind's arguments (named by the subclass's ARGS), expressions in earlier
            quantities.
        note: the derivation step, printed as a comment ("Pieper r/z ellipse, ...").
        fanout: the most values this step can produce.
        ref: the value the joint takes where the pose leaves it free (``cs2``, ``atan2``, and
            ``poly`` when the polynomial vanishes identically), as an expression in the
            reference joint values qr_i.
        scale: for ``poly``: a typical magnitude of the coefficients; when all of them are
            below 1e-10 of it the polynomial vanishes identically and the joint is free.
            For ``cs1``: the typical size of a^2 + b^2; when a^2 + b^2 and e^2 are below
            1e-14 of it the equation holds for every angle, and the joint is free.
        unit: for ``polyd``: the length the roots are found in (d_i / unit), so that the
            coefficients, powers of a length, are compared at one scale: the arm's length, or
            an expression in the step's inputs where d_i can be far longer (a look-at's
            distance along its ray: the arm's length plus the point's distance).
    """

    joint: int
    args: tuple[sp.Expr, ...]
    note: str
    fanout: int
    ref: sp.Expr = sp.S.Zero
    scale: float = 0.0
    unit: float | sp.Expr = 1.0

    # the kind's short name (in the report and the module docstring's table)
    kind: ClassVar[str] = ""
    # the arguments' names; () for a polynomial's coefficients (any number, at least two)
    ARGS: ClassVar[tuple[str, ...]] = ()
    # whether the joint is revolute (the step gives theta_i; else d_i)
    angle: ClassVar[bool] = True

    def __post_init__(self) -> None:
        if type(self) is Solve:
            raise TypeError("Solve is abstract: use one of its kinds (Cs1, Poly, ...)")
        if self.ARGS and len(self.args) != len(self.ARGS):
            raise ValueError(f"{self.kind} takes {len(self.ARGS)} arguments, got {len(self.args)}")
        if not self.ARGS and len(self.args) < 2:
            raise ValueError(f"{self.kind} takes at least two coefficients")

    def as_kind(self, kind: type[Solve], **changes: Any) -> Solve:
        """This step as another kind, with some fields changed."""
        values = {f.name: getattr(self, f.name) for f in fields(self)}
        return kind(**(values | changes))

    @property
    def variable(self) -> str:
        """The name of the joint variable the step solves: theta_i or d_i."""
        return f"theta{self.joint}" if self.angle else f"d{self.joint}"


@dataclass(frozen=True)
class Cs1(Solve):
    """a cos t + b sin t = e: t = atan2(b, a) +- acos(e / sqrt(a^2 + b^2)); t is free
    (reference value) when the equation vanishes identically (scale)."""

    kind: ClassVar[str] = "cs1"
    ARGS: ClassVar[tuple[str, ...]] = ("a", "b", "e")


@dataclass(frozen=True)
class Cs1Unit(Cs1):
    """Cs1 whose a^2 + b^2 - e^2 is known as a sum of squares, rest, exact to roundings where
    it is small (a spherical wrist's theta5: W33 = -+c5 of the unit column (W13, W23, W33), so
    s5^2 = W13^2 + W23^2): the half-width of the two values is atan2(sqrt(rest), e), the
    lecture's theta5 = atan2(+-sqrt(W13^2 + W23^2), W33), not acos(e / sqrt(a^2 + b^2)),
    which loses half the digits near the fold (the wrist nearly straight)."""

    ARGS: ClassVar[tuple[str, ...]] = ("a", "b", "e", "rest")


@dataclass(frozen=True)
class Cs1Reach(Solve):
    """Cs1 whose free value must leave the next joint t' a value keeping
    W = sum M_ij u_i(t') u_j(t) inside [lo, hi], u = (1, cos, sin): the first value in 5
    degree steps out from the reference value that allows it."""

    kind: ClassVar[str] = "cs1r"
    ARGS: ClassVar[tuple[str, ...]] = (
        "a", "b", "e", "M00", "M01", "M02", "M10", "M11", "M12", "M20", "M21", "M22", "lo", "hi",
    )  # fmt: skip


@dataclass(frozen=True)
class Cs2(Solve):
    """a1 c + b1 s = e1, a2 c + b2 s = e2: one t from the 2x2 system; t is free (reference
    value) when the determinant is below 1e-14 det_scale or e1^2 + e2^2 below 1e-14
    rhs_scale."""

    kind: ClassVar[str] = "cs2"
    ARGS: ClassVar[tuple[str, ...]] = ("a1", "b1", "e1", "a2", "b2", "e2", "det_scale", "rhs_scale")


@dataclass(frozen=True)
class Cs2Reach(Solve):
    """Cs2 whose free value must keep a radius A + B cos t + C sin t inside [lo, hi]: q_ref's
    value if inside, else the nearest one putting the radius mid-range."""

    kind: ClassVar[str] = "cs2r"
    ARGS: ClassVar[tuple[str, ...]] = (*Cs2.ARGS, "A", "B", "C", "lo", "hi")


@dataclass(frozen=True)
class Atan2(Solve):
    """t = atan2(y, x); both vanishing leaves t free (reference value)."""

    kind: ClassVar[str] = "atan2"
    ARGS: ClassVar[tuple[str, ...]] = ("y", "x")


@dataclass(frozen=True)
class Poly(Solve):
    """A polynomial in u = tan(t/2), coefficients highest degree first; u = inf is t = pi."""

    kind: ClassVar[str] = "poly"


@dataclass(frozen=True)
class PolyPi(Poly):
    """A quartic in u = tan(t/2) that t -> t + pi leaves unchanged (its coefficients a, b, c,
    -b, a: the equation has only even harmonics, as a quadratic form in (cos t, sin t) equal
    to a constant). Divided by u^2 it is the quadratic a w^2 + b w + (c + 2a) = 0 in
    w = u - 1/u = -2 cot t; each real w gives u = (w +- sqrt(w^2 + 4)) / 2, the angles t and
    t + pi. The quartic's values, from a quadratic."""

    kind: ClassVar[str] = "polypi"


@dataclass(frozen=True)
class PolyD(Solve):
    """A polynomial in a prismatic joint's d_i, coefficients highest degree first."""

    kind: ClassVar[str] = "polyd"
    angle: ClassVar[bool] = False


@dataclass(frozen=True)
class Split:
    """One way of writing a 6R arm's loop for the general method (docs/algorithms.md, "The
    split and the 14 fundamental equations"): the arm's chain or its reversal, in standard DH
    from the flange frame (d1 = d6 = 0, a6 = alpha6 = 0), lengths in units of the Eigen step's
    unit.

    Attributes:
        reversed: the chain read from the tool (joint k is joint 7 - k, theta'_k = -theta_7-k).
        fill: the 490 entries of P0, Ps, Pc (14 x 9 each) and Q (14 x 8), row-major, in the
            flange target's columns l = (lx, ly, lz) and p = (px, py, pz) (p in units).
        fill_rows: the rows (d, a, cos alpha, sin alpha) the entries were derived from: the
            arm's, or a slightly perturbed table where the arm's gives a singular pencil.
        true_rows: the arm's rows (Newton steps polish on them).
        recovered: at generation, of `poses` random poses, those whose generating joint values
            this split found.
        poses: the number of poses measured.
        cond: the median condition number of the pencil's leading matrix on them.
        singular: the arm's own table gives a singular pencil (fill_rows are perturbed).
        slide: (1.0, theta3) where the split's joint 3 is prismatic (its fixed angle; its d3 is
            then the eigen-variable), else (0.0, 0.0).
        spurious: 12 rows of 2r numbers, the real and imaginary parts of r vectors v (columns
            Re v_1, Im v_1, ...) that the lifted 12 x 12 matrix has in its null space at
            x3 = i whatever the pose (the half-angle substitution's factor 1 + x3^2): the
            companion matrix's eigenvalues there are known before the pose is, and the run
            time deflates them. Empty where joint 3 slides.
        spurious_pivots: the r rows where those vectors are the identity (v_j's entry 1 in
            row spurious_pivots[j], the others' 0).
    """

    reversed: bool
    fill: tuple[sp.Expr, ...]
    fill_rows: tuple[tuple[float, float, float, float], ...]
    true_rows: tuple[tuple[float, float, float, float], ...]
    recovered: int
    poses: int
    cond: float
    singular: bool
    slide: tuple[float, float] = (0.0, 0.0)
    spurious: tuple[tuple[float, ...], ...] = ()
    spurious_pivots: tuple[int, ...] = ()

    @property
    def name(self) -> str:
        """In words, for the report and comments."""
        chain = "the reversed chain" if self.reversed else "the arm's chain"
        return chain + (" (perturbed table)" if self.singular else "")


@dataclass(frozen=True)
class Eigen(Solve):
    """The general 6R method (Raghavan-Roth, Manocha-Canny): all six joints at once, from the
    eigenvalues of a 24 x 24 companion matrix (theta3) and back-substitution. args: the flange
    targets of the splits, 12 entries each (row-major), best split first; unit: the length
    the splits' lengths are measured in."""

    kind: ClassVar[str] = "eigen"
    splits: tuple[Split, ...] = ()
    # the arm's number of the split's first joint (2 where joint 1 of a 7-joint arm is free)
    first: int = 1
    # the six joints' kinds, R or P, in the arm's order
    kinds: str = "RRRRRR"
    # the ends of the six (0: their first three joints, 3: their last three) whose wrist flip
    # leaves the pose unchanged, on the arm's own table (derive/methods/general.py, flip_ends):
    # the run time's wrist-flip partners are tried there only
    flips: tuple[int, ...] = (0, 3)

    @property
    def indices(self) -> range:
        """The arm's numbers of the six joints the step gives."""
        return range(self.first, self.first + 6)

    @property
    def variables(self) -> tuple[str, ...]:
        """The joint values the step gives (the arm's): theta_i, or d_i of a prismatic joint."""
        return tuple(
            f"{'theta' if kind == 'R' else 'd'}{i}" for i, kind in zip(self.indices, self.kinds)
        )


# every kind of Solve step: each backend's printer has a function for each (a test checks it)
SOLVE_KINDS: tuple[type[Solve], ...] = (
    Cs1, Cs1Unit, Cs1Reach, Cs2, Cs2Reach, Atan2, Poly, PolyPi, PolyD, Eigen,
)  # fmt: skip


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
        certify: the task's components every solution reproduces (derive/tasks.py): "pose"
            (the whole pose), "position" (the tool point only: arms that do not control the
            orientation), "direction" (the tool point and the tool axis's direction) or
            "lookat" (the tool axis's ray through the target point) or "axisangle" (the tool
            point and the tool axis's component along the base axis `cone`).
        free: the joints (1-based) the caller gives values for (an arm of more than 6
            joints); their values are the reference values qr_i.
        free_text: which joints are free and why, in words (derive/free.py), "" without
            free joints: what emission and reports say of them.
        tool_axis: the tool axis (0 x, 1 y, 2 z) of the "direction" and "lookat" tasks
            (derive/tasks.py).
        relabel: how much the steps' theta_n (d_n of a prismatic joint n) exceeds the
            arm's own: a task's virtual joint moves joint n's DH frame (derive/tasks.py);
            the plan's forward kinematics are written in the steps' variable.
        virtual: a task's virtual joint's value on a solution's branch, for the report:
            (cos, sin) of its angle, or (its length,), in the world pose's entries and the
            arm's joints' c_i, s_i (d_i); () without one.
        cone: the base axis (0 x, 1 y, 2 z) the "axisangle" task measures the tool axis's
            angle from (derive/methods/cone.py).
        task_snap: how far snapping moved the virtual link (derive/tasks.py, extend_snapped:
            radians, or a length over the arm's size); its rows are then refined onto the
            arm's exact chain.
    """

    method: str
    case: str
    max_solutions: int
    steps: tuple[Step, ...]
    outputs: tuple[sp.Expr, ...]
    details: tuple[tuple[str, sp.Expr], ...] = ()
    solves_for: str = "the full pose (rotation and position)"
    certify: str = "pose"
    free: tuple[int, ...] = ()
    free_text: str = ""
    tool_axis: int = 2
    relabel: sp.Expr = sp.S.Zero
    virtual: tuple[sp.Expr, ...] = ()
    task_snap: float = 0.0
    cone: int = 2


@dataclass(frozen=True)
class Correction:
    """The closed form solves a nominal table near the arm's; its answers are refined onto the
    arm's exact chain (derive/nominal.py).

    Attributes:
        nominal_dh: the nominal rows (alpha, a, d, theta), radians and length units.
        changes: one line per parameter snapping changed.
        tol: the structure tolerance.
        deviation: the largest forward-kinematics difference of the nominal arm from the
            exact one (rotation entries; positions divided by the reach; the exact chain is
            the plan's frames).
        seed_tol: how far the nominal solver's equations may miss (relative) and still seed
            a refinement: an acos argument up to 1 + seed_tol, a root up to sqrt(seed_tol)
            off the real line.
    """

    nominal_dh: tuple[tuple[float, float, float, float], ...]
    changes: tuple[str, ...]
    tol: float
    deviation: float
    seed_tol: float


@dataclass(frozen=True)
class Plan:
    """Everything emit and report need for one arm.

    Attributes:
        arm: the arm's numeric description.
        structure: structure facts found by classification, e.g. "spherical wrist at joints 4-6".
        fk_pose: world pose B 0_nT E as a 4x4 matrix in c_i, s_i (R) and d_i (P).
        jacobian: the geometric Jacobian at the tool point in the world frame, 6 x n (linear
            velocity over angular velocity; derive/jacobian.py), in the same symbols; None
            for an arm with exact frames (a URDF's), which computes it from its chain.
        links: the link transforms (i-1)_iT in the spec's convention, in c_i, s_i and d_i.
        joint_defs: (symbol, expression in q_i) defining theta_i or d_i for each joint.
        ik: the IK plan, or None when no method applies.
        refusal: why no IK method applies (one line), or "" when ik is set.
        correction: where ik solves a nominal table near the arm's, how its answers are
            refined onto the arm's; None where ik solves the arm's own table.
        frames: the arm's exact chain as fixed frames F_0 .. F_n, 12 floats each
            (derive/nominal.py): what ik_approximate's steps, and a correction's, move on.
    """

    arm: ArmInfo
    structure: tuple[str, ...]
    fk_pose: sp.Matrix
    jacobian: sp.Matrix | None
    links: tuple[sp.Matrix, ...]
    joint_defs: tuple[tuple[sp.Symbol, sp.Expr], ...]
    ik: IkPlan | None
    refusal: str = ""
    correction: Correction | None = None
    frames: tuple[tuple[float, ...], ...] = ()

    @property
    def solved(self) -> tuple[int, ...]:
        """The joints (0-based) Newton's steps on the exact chain move: all but the free
        ones."""
        free = self.ik.free if self.ik else ()
        return tuple(i for i in range(self.arm.dof) if i + 1 not in free)
