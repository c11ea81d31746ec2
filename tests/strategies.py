"""Hypothesis strategies for random arms of every family the generator solves.

Lengths are O(1) numbers times a per-arm scale from 1e-3 to 1e3; twists and offsets mix
0 and multiples of 90 degrees with generic values.
"""

from __future__ import annotations

from hypothesis import assume
from hypothesis import strategies as st

from conftest import spec_text

TWISTS = st.one_of(
    st.sampled_from([90.0, -90.0]),
    st.floats(15.0, 165.0).map(round),
    st.floats(-165.0, -15.0).map(round),
)
OFFSETS = st.one_of(
    st.sampled_from([0.0, 90.0, -90.0, 180.0]), st.floats(-180.0, 180.0).map(lambda v: round(v, 3))
)
LENGTH = st.floats(0.1, 1.0) | st.floats(-1.0, -0.1)
MAYBE_ZERO = st.one_of(st.just(0.0), LENGTH)
SCALE = st.integers(-3, 3).map(lambda k: 10.0**k)


def rows_for(convention: str, alpha: list, a: list, d: list, theta: list) -> list[tuple]:
    """DH rows from canonical alpha_i, a_i (i = 0..n) and d_i, theta_i (i = 1..n)."""
    n = len(d) - 1
    if convention == "modified":
        return [(alpha[k - 1], a[k - 1], d[k], theta[k]) for k in range(1, n + 1)]
    return [(alpha[k], a[k], d[k], theta[k]) for k in range(1, n + 1)]


def scaled(values: list, scale: float) -> list:
    return [None if v is None else round(v * scale, 6) for v in values]


@st.composite
def pieper_arms(draw) -> str:
    """6-joint arms with axes 4-6 (or, reversed, 1-3) meeting; joint 3 revolute or prismatic."""
    convention = draw(st.sampled_from(["standard", "modified"]))
    case = draw(st.sampled_from(["general", "a1=0", "salpha1=0"]))
    prismatic = draw(st.booleans())
    alpha = [draw(TWISTS) for _ in range(7)]
    a = [draw(MAYBE_ZERO) for _ in range(7)]
    d = [None] + [draw(MAYBE_ZERO) for _ in range(6)]
    theta = [None] + [draw(OFFSETS) for _ in range(6)]
    a[2] = draw(LENGTH)
    d[4] = draw(LENGTH)
    a[4] = a[5] = d[5] = 0.0
    if case == "a1=0":
        a[1] = 0.0
    elif case == "salpha1=0":
        alpha[1] = draw(st.sampled_from([0.0, 180.0]))
        a[1] = draw(LENGTH)
        alpha[2] = draw(st.floats(20.0, 70.0))
    else:
        a[1] = draw(LENGTH)
    kinds = "RRPRRR" if prismatic else "RRRRRR"
    if prismatic:
        theta[3] = draw(OFFSETS)
    scale = draw(SCALE)
    rows = rows_for(convention, alpha, scaled(a, scale), scaled(d, scale), theta)
    text = spec_text("pieper_arm", convention, rows, kinds=kinds)
    if prismatic:
        text = text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')
    if draw(st.booleans()):
        # the same structure read from the tool: axes 1-3 meet (solved on the reversed chain)
        text = text.replace("pieper_arm", "pieper_arm_reversed")
        text = reverse_rows_text(convention, rows, kinds, scale, prismatic)
    return text


def reverse_rows_text(
    convention: str, rows: list, kinds: str, scale: float, prismatic: bool
) -> str:
    """An arm whose axes 1-3 meet: the reversed chain of `rows` (docs/algorithms.md, "The
    reversed chain")."""
    n = len(rows)
    if convention == "modified":
        alpha = [r[0] for r in rows] + [0.0]
        a = [r[1] for r in rows] + [0.0]
    else:
        alpha = [0.0] + [r[0] for r in rows]
        a = [0.0] + [r[1] for r in rows]
    d = [None] + [r[2] for r in rows]
    theta = [None] + [r[3] for r in rows]
    ralpha = [-alpha[n - k] if alpha[n - k] else 0.0 for k in range(n + 1)]
    ra = [-a[n - k] if a[n - k] else 0.0 for k in range(n + 1)]
    rd = [None] + [-d[n + 1 - k] if d[n + 1 - k] else 0.0 for k in range(1, n + 1)]
    rtheta = [None] + [-theta[n + 1 - k] if theta[n + 1 - k] else 0.0 for k in range(1, n + 1)]
    out_rows = rows_for(convention, ralpha, ra, rd, rtheta)
    text = spec_text("pieper_arm_reversed", convention, out_rows, kinds=kinds[::-1])
    if prismatic:
        text = text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')
    return text


@st.composite
def parallel_arms(draw) -> str:
    """6R arms with axes 2, 3, 4 parallel (UR type), a5 zero or not, sometimes reversed."""
    convention = draw(st.sampled_from(["standard", "modified"]))
    alpha = [draw(TWISTS) for _ in range(7)]
    a = [draw(MAYBE_ZERO) for _ in range(7)]
    d = [None] + [draw(MAYBE_ZERO) for _ in range(6)]
    theta = [None] + [draw(OFFSETS) for _ in range(6)]
    alpha[2] = alpha[3] = 0.0
    a[2], a[3] = draw(LENGTH), draw(LENGTH)
    alpha[4] = draw(st.floats(30.0, 150.0))
    alpha[5] = draw(st.floats(-150.0, -30.0))
    if draw(st.booleans()):
        a[5] = 0.0
    scale = draw(SCALE)
    rows = rows_for(convention, alpha, scaled(a, scale), scaled(d, scale), theta)
    if draw(st.booleans()):
        return reverse_rows_text(convention, rows, "RRRRRR", scale, False).replace(
            "pieper_arm_reversed", "parallel_arm_reversed"
        )
    return spec_text("parallel_arm", convention, rows)


@st.composite
def planar_arms(draw) -> str:
    """All axes parallel: RR, RRR, RRP, RRPR (SCARA) with random lengths and offsets.

    The two links after the first two revolute joints have length; in modified DH a link's
    length sits in the next row, so a modified RR arm gets its second link as a tool offset.
    """
    convention = draw(st.sampled_from(["standard", "modified"]))
    kinds = draw(st.sampled_from(["RR", "RRR", "RRP", "RRPR"]))
    scale = draw(SCALE)
    needed = (0, 1) if convention == "standard" else (1, 2)
    rows = []
    for k, kind in enumerate(kinds):
        length = (
            draw(LENGTH)
            if k in needed
            else (0.0 if convention == "modified" and k == 0 else draw(MAYBE_ZERO))
        )
        rows.append(
            (
                0.0,
                round(length * scale, 6),
                round(draw(MAYBE_ZERO) * scale, 6),
                draw(OFFSETS) if kind == "R" else 0.0,
            )
        )
    if kinds == "RRPR":
        # the prismatic joint does not turn the plane, so the links before and after it add
        # up: where they cancel, joint 2 does not move the tool point (it only turns the
        # tool, like joint 4) and the arm is redundant; the planar method refuses it
        assume(rows[needed[1]][1] + rows[needed[1] + 1][1] != 0.0)
    extra = ""
    if convention == "modified" and kinds == "RR":
        extra = f"[tool]\ntranslation = [{round(draw(LENGTH) * scale, 6)}, 0.0, 0.0]\n"
    text = spec_text("planar_arm", convention, rows, kinds=kinds, extra=extra)
    return text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')


@st.composite
def general_arms(draw) -> str:
    """6-joint arms of any geometry (most have no closed form): twists mix 0, +-90, 180 and
    generic values, lengths and offsets are zero or not, a fifth have joint 3 or 4 prismatic
    (the places the general method takes one); the arm is solved by whichever method applies
    (the general one where none of the others does)."""
    slider = draw(st.sampled_from([0, 0, 0, 0, 0, 0, 0, 0, 3, 4]))
    convention = draw(st.sampled_from(["standard", "modified"]))
    twist = st.one_of(TWISTS, st.sampled_from([0.0, 180.0]))
    alpha = [draw(twist) for _ in range(7)]
    a = [draw(MAYBE_ZERO) for _ in range(7)]
    d = [None] + [draw(MAYBE_ZERO) for _ in range(6)]
    theta = [None] + [draw(OFFSETS) for _ in range(6)]
    a[draw(st.integers(1, 5))] = draw(LENGTH)  # at least one link with length
    scale = draw(SCALE)
    rows = rows_for(convention, alpha, scaled(a, scale), scaled(d, scale), theta)
    if not slider:
        return spec_text("general_arm", convention, rows)
    kinds = "RRRRRR"[: slider - 1] + "P" + "RRRRRR"[slider:]
    text = spec_text("general_arm", convention, rows, kinds=kinds)
    return text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')


@st.composite
def end_parallel_arms(draw) -> str:
    """6-joint arms with axes 1, 2, 3 (or 4, 5, 6) parallel and the other three joints
    generic, half of them with the joint next to the parallel three prismatic (its axis
    sometimes parallel to the three: four parallel axes)."""
    convention = draw(st.sampled_from(["standard", "modified"]))
    alpha = [draw(TWISTS) for _ in range(7)]
    a = [draw(MAYBE_ZERO) for _ in range(7)]
    d = [None] + [draw(MAYBE_ZERO) for _ in range(6)]
    theta = [None] + [draw(OFFSETS) for _ in range(6)]
    # axes 1, 2, 3 parallel: the twists between them 0 or 180 deg, both links with length
    # (canonical alpha_i, a_i lie between axes i and i + 1 in both conventions; TWISTS has
    # no 0 or 180, so a turning axis 4 is not parallel too)
    for i in (1, 2):
        alpha[i] = draw(st.sampled_from([0.0, 180.0]))
        a[i] = draw(LENGTH)
    a[4] = draw(LENGTH)  # (joints 4-6 meeting in a point would leave the position planar)
    kinds = draw(st.sampled_from(["RRRRRR", "RRRPRR"]))
    if "P" in kinds:
        # a sliding joint 4 at right angles to the parallel axes would move in their plane
        # (the method then does not apply): twist 3 generic, or 0 or 180 deg (axes 1-4
        # parallel, joint 4 sliding at right angles to the plane of the three)
        alpha[3] = draw(
            st.sampled_from([0.0, 180.0])
            | st.floats(15.0, 75.0).map(round)
            | st.floats(105.0, 165.0).map(round)
        )
    scale = draw(SCALE)
    rows = rows_for(convention, alpha, scaled(a, scale), scaled(d, scale), theta)
    text = spec_text("end_parallel_arm", convention, rows, kinds=kinds)
    if "P" in kinds:
        text = text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')
    if draw(st.booleans()):
        # axes 4, 5, 6 parallel: the reversed chain
        text = reverse_rows_text(convention, rows, kinds, scale, "P" in kinds)
        text = text.replace("pieper_arm_reversed", "end_parallel_arm_reversed")
    return text
