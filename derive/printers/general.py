"""The general method's printed pieces: the splits' constants and _rr_fill, the straight-line
code giving the Raghavan-Roth matrices of a pose. The same text serves the Python solver and
the C one prints its own from the same entries (derive/printers/c.py)."""

from __future__ import annotations

import textwrap

import sympy as sp

from derive import raghavan_roth as rr
from derive.plan import Eigen, Plan, Split
from derive.printers.common import CodePrinter, float_literal


def eigen_step(plan: Plan) -> Eigen | None:
    """The plan's Eigen step, if it uses the general method."""
    if plan.ik is None:
        return None
    for step in plan.ik.steps:
        if isinstance(step, Eigen):
            return step
    return None


def fill_entries(
    split: Split,
) -> tuple[list[tuple[sp.Symbol, sp.Expr]], list[tuple[int, sp.Expr]]]:
    """A split's fill as CSE'd straight-line code: the temporaries, and (index, expression)
    of each nonzero entry of out (every backend's _rr_fill prints these)."""
    entries = [(i, e) for i, e in enumerate(split.fill) if e != 0]
    names = sp.numbered_symbols("x")
    temps, reduced = sp.cse([e for _, e in entries], symbols=names, order="canonical")
    return temps, [(i, e) for (i, _), e in zip(entries, reduced)]


def pad(values: tuple[int, ...], width: int) -> tuple[int, ...]:
    """values followed by zeros up to width (one array shape for every split)."""
    return (*values, *[0] * (width - len(values)))


def spurious_counts(step: Eigen) -> tuple[list[int], int]:
    """Per split, the columns of Split.spurious (2 per vector), and the width every split's
    table is padded to: a vector's columns at least (no empty arrays in C, and GCC's
    bounds checks see the columns the C routine names)."""
    counts = [len(split.spurious[0]) if split.spurious else 0 for split in step.splits]
    return counts, max(2, *counts)


def general_code(plan: Plan) -> str:
    """_RR_SPLITS, _RR_LENGTH and _rr_fill for a plan of the general method ("" otherwise)."""
    step = eigen_step(plan)
    if step is None:
        return ""
    printer = CodePrinter()

    def rows(table: tuple[tuple[float, ...], ...]) -> list[str]:
        inner = [f"            ({', '.join(float_literal(v) for v in r)})," for r in table]
        return ["        (", *inner, "        ),"]

    lines = [
        "# the general method's splits, best first: (reversed, the rows the matrices are filled",
        "# from, the arm's rows, (1.0, theta3) where joint 3 slides else (0.0, 0.0)); rows (d, a,",
        "# cos alpha, sin alpha) of standard DH from the flange frame, lengths in units of",
        "# _RR_LENGTH",
        "_RR_SPLITS = (",
    ]
    for split in step.splits:
        lines += ["    (", f"        {split.reversed},", *rows(split.fill_rows)]
        slide = ", ".join(float_literal(v) for v in split.slide)
        lines += [*rows(split.true_rows), f"        ({slide}),", "    ),"]
    lines += [")", f"_RR_LENGTH = {float_literal(step.unit)}"]
    lines += [
        "# the ends of the arm's six joints (0: joints 1-3, 3: joints 4-6) whose wrist flip leaves",
        "# the pose unchanged: _rr_partners tries the flips there",
        f"_RR_FLIPS = {tuple(step.flips)}",
    ]
    counts, width = spurious_counts(step)
    lines += [
        "# per split, the null vectors its lifted 12 x 12 matrix has at x3 = i whatever the pose",
        "# (real and imaginary parts in turn, _RR_SPURIOUS_COUNT columns, then zeros): the",
        "# companion matrix's eigenvalues there are deflated (_rr_deflated)",
        f"_RR_SPURIOUS_COUNT = {tuple(counts)}",
        "# the rows where those vectors are the identity (v_j's entry 1 in row _RR_PIVOTS[k][j])",
        "_RR_PIVOTS = np.array(",
        f"    {[list(pad(split.spurious_pivots, width // 2)) for split in step.splits]},",
        "    dtype=np.int64,",
        ")",
        "_RR_SPURIOUS = np.array(",
        "    [",
    ]
    numbers = [
        float_literal(v)
        for split, n in zip(step.splits, counts)
        for i in range(12)
        for v in ((*split.spurious[i], *[0.0] * (width - n)) if n else (0.0,) * width)
    ]
    lines += textwrap.wrap(
        ", ".join(numbers) + ",", width=96, initial_indent="        ", subsequent_indent="        "
    )
    lines += ["    ]", f").reshape({len(step.splits)}, 12, {width})", "", ""]
    args = ", ".join(str(s) for s in (*rr.L, *rr.P))
    lines += [
        f"def _rr_fill(k, {args}, out):",
        '    """The entries of P0, Ps, Pc (14 x 9 each) and Q (14 x 8), row-major, of split k at',
        "    the flange target whose third and fourth columns are l and p (p in units of",
        '    _RR_LENGTH), into out (490 zeros on entry)."""',
    ]
    for k, split in enumerate(step.splits):
        temps, entries = fill_entries(split)
        last = k == len(step.splits) - 1
        indent = "    " if last else "        "
        if not last:
            lines.append(f"    if k == {k}:")
        lines += [f"{indent}{t} = {printer.doprint(e)}" for t, e in temps]
        lines += [f"{indent}out[{i}] = {printer.doprint(e)}" for i, e in entries]
        if not last:
            lines.append(f"{indent}return")
    return "\n".join(lines) + "\n"
