"""Redundant arms (more than 6 joints): which joints are left free, and the 6-joint
remainder the solution methods solve.

A free joint takes its value from the caller (``ik(T, free=...)``; in the generated code it
is the joint's reference value qr_i). Only end joints are freed: with joints 1..k and
n-m+1..n free (k + m = n - 6), the remainder is the chain of joints k+1..n-m, and the free
joints only move its base and tool:

    B' = B X_0 Z_1 X_1 ... Z_k,        E' = Z_{n-m+1} X_{n-m+1} ... Z_n X_n E,

so one derivation serves every free value: the flange target of the remainder holds the free
joints' cos and sin (docs/algorithms.md, "Free joints of 7-joint arms"). A middle joint would
put a free angle between two joints of the remainder, where no DH row can hold it; it is
refused.

The remainder is derived with its joints numbered 1..6 (the methods' own numbering); the plan
is then renumbered to the arm's joints (:func:`lift`).
"""

from __future__ import annotations

from dataclasses import fields, replace

import numpy as np
import sympy as sp

from derive import symbols as sym
from derive.plan import Assign, Eigen, IkPlan, Solve, Step
from derive.transforms import Chain, JointZ, product, x_factor

REMAINDER_DOF = 6


def candidates(
    chain: Chain, named: tuple[int, ...] | None, size: int = REMAINDER_DOF
) -> tuple[tuple[int, ...], ...]:
    """The free-joint choices to try, best first: the spec's, else the end joints (the last
    joints first, then the first, then mixes) that leave `size` joints (6 for the pose, 3 for
    the tool point's position)."""
    n = chain.dof
    extra = n - size
    if named is not None:
        return (named,)
    out = []
    for k in [0, extra, *range(1, extra)]:
        out.append(tuple(range(1, k + 1)) + tuple(range(n - (extra - k) + 1, n + 1)))
    return tuple(dict.fromkeys(out))


def refusal(chain: Chain, free: tuple[int, ...], size: int = REMAINDER_DOF) -> str:
    """Why this choice of free joints cannot be used, or "" if it can (`size`: 6 joints left
    for the pose, 3 for the tool point's position)."""
    n = chain.dof
    rank = remainder_rank(chain, free, position=size < REMAINDER_DOF)
    if rank < size:
        what = "tool point" if size < REMAINDER_DOF else "tool"
        return (
            f"with these joints fixed the other joints move the {what} in {rank} "
            f"direction{'s' if rank != 1 else ''} "
            f"only (their Jacobian has rank {rank} at random configurations): the remainder "
            "loses a degree of freedom"
        )
    k, m = split(free, n)
    if free[k:] == tuple(range(n - m + 1, n + 1)):
        return ""
    middle = next(i for i in free[k:] if not set(range(i, n + 1)) <= set(free))
    return (
        f"free joint {middle} is a middle joint: only end joints (the first or the last ones) "
        f"can be free here, so that the other {size} joints form one chain whose base "
        "and tool the free joints move"
    )


def remainder_rank(chain: Chain, free: tuple[int, ...], position: bool = False) -> int:
    """The rank of the other joints' Jacobian (rotation and position, lengths in units of the
    arm's size; the tool point's position only, with `position`) at three random
    configurations, the largest: below 6 where fixing the free joints takes a degree of
    freedom from the tool (q4 of an S-R-S arm fixes the distance from shoulder to wrist)."""
    best = 0
    for J in remainder_jacobians(chain, free, position, 3, 18):
        sigma = np.linalg.svd(J, compute_uv=False)
        best = max(best, int((sigma > 1e-6 * sigma[0]).sum()))
    return best


def position_span(chain: Chain, free: tuple[int, ...]) -> float:
    """How much room the other joints give the tool point: the median over eight random
    configurations of |det| of their 3 x 3 position Jacobian, lengths in units of the arm's
    size. A humanoid arm's wrist moves the hand a few centimetres, its shoulder and elbow the
    whole reach: with the wrist solved and the shoulder free, almost no point is reached at
    the given free values (an iCub arm, a new user's attack)."""
    dets = [abs(float(np.linalg.det(J))) for J in remainder_jacobians(chain, free, True, 8, 19)]
    return float(np.median(dets))


def remainder_jacobians(
    chain: Chain, free: tuple[int, ...], position: bool, count: int, seed: int
) -> list[np.ndarray]:
    """The other joints' Jacobian by central differences at `count` random configurations:
    rows the pose's 12 top entries (the tool point's 3 with `position`), lengths in units of
    the arm's size, a column per joint not in free."""
    rng = np.random.default_rng(seed)
    size = max(
        [1.0]
        + [abs(float(t.a)) for t in chain.twists]
        + [abs(float(j.d if j.kind == "R" else j.offset)) for j in chain.joints]
    )
    moving = [i for i in range(chain.dof) if i + 1 not in free]
    tool = np.array(chain.tool.evalf(), dtype=float)
    tool[:3, 3] /= size
    out = []
    for _ in range(count):
        q = rng.uniform(-np.pi, np.pi, chain.dof)
        columns = []
        for i in moving:
            step = np.zeros(chain.dof)
            step[i] = 1e-6
            d = (pose_numbers(chain, q + step, size) - pose_numbers(chain, q - step, size)) / 2e-6
            # (the tool point's: the tool frame moves it, where it does not turn the frame)
            columns.append(d[:3, :3] @ tool[:3, 3] + d[:3, 3] if position else d[:3].ravel())
        out.append(np.array(columns).T)
    return out


def pose_numbers(chain: Chain, q: np.ndarray, size: float) -> np.ndarray:
    """X_0 Z_1 X_1 ... Z_n X_n at joint values q (a prismatic joint's q in units of size),
    lengths divided by size."""
    out = np.eye(4)
    for k, twist in enumerate(chain.twists):
        if k:
            j = chain.joints[k - 1]
            angle = q[k - 1] if j.kind == "R" else float(j.theta)
            shift = float(j.d) / size if j.kind == "R" else q[k - 1]
            c, s = np.cos(angle), np.sin(angle)
            out = out @ np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, shift], [0, 0, 0, 1]])
        ca, sa, a = float(twist.ca), float(twist.sa), float(twist.a) / size
        out = out @ np.array([[1, 0, 0, a], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])
    return out


def split(free: tuple[int, ...], n: int) -> tuple[int, int]:
    """(k, m): the free joints are 1..k and n-m+1..n."""
    k = 0
    while k + 1 in free:
        k += 1
    return k, len(free) - k


def placeholder(i: int) -> tuple[sp.Symbol, ...]:
    """The symbols a free joint i's cos and sin (or d) take in the remainder's derivation
    (distinct from the remainder's c_1..c_6)."""
    return (sym.named(f"cfree{i}"), sym.named(f"sfree{i}"), sym.named(f"dfree{i}"))


def free_z(j: JointZ) -> sp.Matrix:
    """Z_i of a free joint, in its placeholder symbols."""
    c, s, d = placeholder(j.index)
    if j.kind == "R":
        return sp.Matrix([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, j.d], [0, 0, 0, 1]])
    ct, st = sym.cos_sin(j.theta)
    return sp.Matrix([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, d], [0, 0, 0, 1]])


def remainder(chain: Chain, free: tuple[int, ...]) -> Chain:
    """The chain left when the free joints are fixed (6 joints for the pose, 3 for the tool
    point's position): joints renumbered from 1, the free joints (in placeholder symbols)
    moved into its base and tool."""
    n = chain.dof
    k, m = split(free, n)
    head = [chain.base, x_factor(chain.twists[0])]
    for i in range(k):
        head.append(free_z(chain.joints[i]))
        if i + 1 < k:
            head.append(x_factor(chain.twists[i + 1]))
    tail = []
    for i in range(n - m, n):
        tail += [free_z(chain.joints[i]), x_factor(chain.twists[i + 1])]
    joints = []
    for r, j in enumerate(chain.joints[k : n - m], start=1):
        if j.kind == "R":
            joints.append(JointZ(r, "R", j.offset, sym.theta(r), j.d))
        else:
            joints.append(JointZ(r, "P", j.offset, j.theta, sym.d(r)))
    return Chain(
        twists=chain.twists[k : n - m + 1],
        joints=tuple(joints),
        base=product(head),
        tool=product([*tail, chain.tool]),
        convention=chain.convention,
    )


def lift(ik: IkPlan, chain: Chain, free: tuple[int, ...]) -> IkPlan:
    """The remainder's plan as the arm's: joints renumbered, the free joints' cos and sin (or
    d) computed from their values (qr_i) first, the free values among the outputs."""
    n = chain.dof
    k, m = split(free, n)
    rename: dict[sp.Symbol, sp.Symbol] = {}
    for r in range(1, n - len(free) + 1):
        for f in (sym.theta, sym.c, sym.s, sym.d, sym.q, sym.q_ref):
            rename[f(r)] = f(r + k)
    head: list[sp.Symbol] = []
    exprs: list[sp.Expr] = []
    for i in free:
        j = chain.joints[i - 1]
        c, s, d = placeholder(i)
        offset = sp.Float(float(j.offset), 17) if j.offset != 0 else sp.Integer(0)
        if j.kind == "R":
            rename |= {c: sym.c(i), s: sym.s(i)}
            head += [sym.c(i), sym.s(i)]
            exprs += [sp.cos(sym.q_ref(i) + offset), sp.sin(sym.q_ref(i) + offset)]
        else:
            rename[d] = sym.d(i)
            head.append(sym.d(i))
            exprs.append(sym.q_ref(i) + offset)
    names = ", ".join(f"q{i}" for i in free)
    steps: list[Step] = [Assign(tuple(head), tuple(exprs), f"free joints: {names} as given")]
    steps += [renumber(step, rename, k) for step in ik.steps]
    remainder_outputs = iter(e.xreplace(rename) for e in ik.outputs)
    outputs = tuple(sym.q_ref(i) if i in free else next(remainder_outputs) for i in range(1, n + 1))
    lifted = replace(
        ik,
        steps=tuple(steps),
        outputs=outputs,
        details=tuple((name, e.xreplace(rename)) for name, e in ik.details),
        free=free,
        case=f"{ik.case}; joints {names} free (given), the remainder joints {k + 1}-{n - m} solved",
    )
    return replace(lifted, free_text=describe(lifted, n))


def renumber(step: Step, rename: dict[sp.Symbol, sp.Symbol], shift: int) -> Step:
    """One step with the remainder's symbols renamed to the arm's, its joint number shifted."""
    if isinstance(step, Assign):
        return Assign(
            tuple(rename.get(t, t) for t in step.targets),
            tuple(e.xreplace(rename) for e in step.exprs),
            step.note,
        )
    assert isinstance(step, Solve)
    values = {f.name: getattr(step, f.name) for f in fields(step)}
    values |= {
        "joint": step.joint + shift,
        "args": tuple(e.xreplace(rename) for e in step.args),
        "ref": step.ref.xreplace(rename),
    }
    if isinstance(step, Eigen):
        values["first"] = step.first + shift
    return type(step)(**values)


def describe(ik: IkPlan, dof: int) -> str:
    """Which joints are free and why, in words ("" for an arm without free joints)."""
    if not ik.free:
        return ""
    joints = ", ".join(f"q{i}" for i in ik.free)
    k, m = split(ik.free, dof)
    moved = " and ".join(w for w, n in (("base", k), ("tool", m)) if n)
    return (
        f"{joints} (end joint{'s' if len(ik.free) > 1 else ''}: the given value only moves the "
        f"{moved} of joints {k + 1}-{dof - m}, which the {ik.method} method solves, so one "
        "derivation serves every value)"
    )
