"""Three-joint spatial arms: the tool point's position (IKFast's Translation3D), Pieper's
position part with the tool point as the wrist centre (derive/methods/position.py)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from derive.pipeline import build_plan
from derive.report import method_blocks
from derive.spec import parse_spec

from conftest import build_module, needs_cc, spec_text

# (rows alpha, a, d, theta in deg and m; joint kinds; tool point in frame 3; the case)
ARMS = {
    # yaw, then two pitch axes (the elbow manipulator): a1 = 0, r = k3
    "anthro3": ([(0, 0, 0.4, 0), (90, 0, 0, 0), (0, 0.45, 0, 0)], "RRR", (0.4, 0, 0), "a1 = 0"),
    # offsets everywhere: the general case's quartic
    "offset3": (
        [(0, 0, 0.4, 0), (90, 0.1, 0.05, 0), (0, 0.45, 0, 0)],
        "RRR",
        (0.4, 0.02, 0),
        "general",
    ),
    # axes 1 and 2 parallel, axis 3 across them: sin(alpha1) = 0, z = k4
    "scara3": ([(0, 0, 0.4, 0), (0, 0.3, 0, 0), (90, 0.25, 0, 0)], "RRR", (0.1, 0, 0.05), "sin"),
    # the Stanford arm's position part: a prismatic joint 3, a polynomial in d3
    "stanford3": ([(0, 0, 0.4, 0), (-90, 0, 0.1, 0), (90, 0, 0, 0)], "RRP", (0, 0, 0.1), "d3"),
    # no twist a multiple of 90 deg
    "skew3": (
        [(0, 0, 0.3, 0), (-70, 0.05, 0.0, 0), (20, 0.4, 0.02, 0)],
        "RRR",
        (0.35, 0.01, 0.03),
        "general",
    ),
}


def arm_text(name: str) -> str:
    rows, kinds, (x, y, z), _ = ARMS[name]
    tool = f"\n[tool]\nmatrix = [[1, 0, 0, {x}], [0, 1, 0, {y}], [0, 0, 1, {z}], [0, 0, 0, 1]]\n"
    return spec_text(name, "modified", rows, kinds=kinds, extra=tool)


def position_sigma(module, q: np.ndarray, step: float = 1e-6) -> float:
    """The smallest singular value of the tool point's Jacobian, over the reach."""
    J = np.zeros((3, module.DOF))
    for i in range(module.DOF):
        dq = np.zeros(module.DOF)
        dq[i] = step
        J[:, i] = (module.fk(q + dq)[:3, 3] - module.fk(q - dq)[:3, 3]) / (2 * step)
    return float(np.linalg.svd(J / module.REACH, compute_uv=False)[-1])


def round_trips(module, backend: str, n: int, seed: int) -> tuple[int, int, int, float]:
    """(regular samples, those whose joint vector was missed, samples answered with
    nothing, the worst row's position error over the reach)."""
    rng = np.random.default_rng(seed)
    regular = missed = empty = 0
    worst = 0.0
    for q in rng.uniform(-math.pi, math.pi, (n, module.DOF)):
        if module.DOF == 3 and ARMS[module.NAME][1][2] == "P":
            q[2] = rng.uniform(0.05, 0.8)
        T = module.fk(q)
        rows = module.ik(T, backend=backend)
        empty += len(rows) == 0
        for row in rows:
            worst = max(worst, float(np.max(np.abs(module.fk(row)[:3, 3] - T[:3, 3]))))
        if position_sigma(module, q) >= 0.05:
            regular += 1
            gaps = np.abs(np.remainder(rows - q + math.pi, 2 * math.pi) - math.pi)
            missed += not len(rows) or bool(np.min(np.max(gaps, axis=1)) > 1e-8)
    return regular, missed, empty, worst / module.REACH


@pytest.mark.parametrize("name", sorted(ARMS))
def test_three_joint_arms_get_the_position_method_with_its_case(name):
    plan = build_plan(parse_spec(arm_text(name), "<test>"))
    assert plan.ik is not None and plan.ik.method == "position"
    assert plan.ik.certify == "position" and plan.ik.max_solutions == 4
    assert ARMS[name][3] in plan.ik.case


@pytest.mark.parametrize("name", sorted(ARMS))
def test_every_row_reaches_the_point_and_the_sampled_vector_is_among_them(name, tmp_path):
    module = build_module(arm_text(name), tmp_path)
    assert name == module.NAME
    regular, missed, empty, worst = round_trips(module, "python", 300, 1)
    assert regular >= 100 and missed == 0 and empty == 0 and worst <= 1e-10


@needs_cc
@pytest.mark.parametrize("name", sorted(ARMS))
def test_the_c_solver_agrees_on_many_samples(name, tmp_path):
    module = build_module(arm_text(name), tmp_path, c=True)
    regular, missed, empty, worst = round_trips(module, "c", 3000, 2)
    assert regular >= 1000 and missed == 0 and empty == 0 and worst <= 1e-10
    rng = np.random.default_rng(4)
    for q in rng.uniform(-math.pi, math.pi, (100, 3)):
        T = module.fk(q)
        a, b = module.ik(T, backend="c"), module.ik(T, backend="python")
        assert a.shape == b.shape and np.allclose(a, b, atol=1e-9)


@pytest.mark.parametrize(
    ("q", "rows"),
    [
        ((0.3, math.pi / 2, 0.0), 1),  # the tool point on axis 1: theta1 free (takes q_ref)
        ((0.2, 0.5, 0.0), 2),  # elbow stretched: a double root
        ((0.2, 0.5, math.pi), 2),  # elbow folded back
    ],
)
def test_degenerate_positions_are_answered(q, rows, tmp_path):
    module = build_module(arm_text("anthro3"), tmp_path)
    T = module.fk(np.array(q))
    found = module.ik(T)
    assert len(found) == rows
    for row in found:
        assert np.max(np.abs(module.fk(row)[:3, 3] - T[:3, 3])) <= 1e-12
    if rows == 1:
        assert found[0][0] == 0.0 and abs(abs(found[0][1]) - math.pi / 2) <= 1e-9


def test_the_module_says_what_it_solves_for(tmp_path):
    module = build_module(arm_text("offset3"), tmp_path)
    assert module.METHOD == "position"
    assert "the tool point's position" in module.__doc__


def test_the_report_shows_the_tool_point_as_the_wrist_centre():
    plan = build_plan(parse_spec(arm_text("offset3"), "<test>"))
    blocks = method_blocks(plan)
    heads = [b.text for b in blocks if b.kind == "h3"]
    assert "The tool point as the wrist centre" in heads
    maths = {b.text: b.math for b in blocks if b.kind == "math"}
    # the tool point (0.4, 0.02, 0) in frame 3: a3 = 0.4, d4 = 0.02, alpha3 = -90 deg
    assert maths["a_{3}"] == "0.4" and maths["d_{4}"] == "0.02"
    assert maths["\\sin\\alpha_{3}"] == "-1" and maths["\\cos\\alpha_{3}"] == "0"


def test_ik_position_takes_the_point_and_ignores_any_rotation(tmp_path, generated):
    """ik_position(p) (Translation3D's own arguments) gives ik's rows for a pose at p, whatever
    its rotation; a point that is not 3 finite numbers is refused."""
    module = build_module(arm_text("offset3"), tmp_path)
    rng = np.random.default_rng(5)
    for q in rng.uniform(-math.pi, math.pi, (50, 3)):
        T = module.fk(q)
        rows = module.ik_position(T[:3, 3], backend="python")
        assert len(rows) and np.allclose(rows, module.ik(T, backend="python"), atol=1e-12)
        gaps = np.abs(np.remainder(rows - q + math.pi, 2 * math.pi) - math.pi)
        assert np.min(np.max(gaps, axis=1)) <= 1e-8
    for bad in ([0.1, 0.2], [0.1, np.nan, 0.2], "xyz"):
        with pytest.raises(ValueError):
            module.ik_position(bad)
    assert "ik_position(p" in module.__doc__
    # a planar arm's task is ik_xy's, not ik_position's
    planar = generated("planar_2r")
    assert "ik_xy" in planar.__all__ and not hasattr(planar, "ik_position")


@needs_cc
def test_the_c_ik_position_gives_the_module_s_rows(tmp_path):
    """NAME_ik_position of the generated C (arm.h) through ctypes: the Python module's rows,
    and a point that is not finite refused (INVALID_ARGUMENT)."""
    import ctypes

    module = build_module(arm_text("offset3"), tmp_path, c=True)
    lib, why = module._c_library()
    assert lib is not None, why
    double_p = ctypes.POINTER(ctypes.c_double)
    call = lib["offset3_ik_position"]
    rows = np.zeros((module.MAX_SOLUTIONS, module.DOF))
    rng = np.random.default_rng(6)
    tol = ctypes.c_double(module.CERTIFY_TOL)
    for q in rng.uniform(-math.pi, math.pi, (100, 3)):
        p = np.ascontiguousarray(module.fk(q)[:3, 3])
        n = call(p.ctypes.data_as(double_p), None, None, tol, rows.ctypes.data_as(double_p))
        expected = module.ik_position(p, backend="python")
        assert n == len(expected) > 0 and np.allclose(rows[:n], expected, atol=1e-9)
    bad = np.array([0.1, np.inf, 0.2])
    assert call(bad.ctypes.data_as(double_p), None, None, tol, rows.ctypes.data_as(double_p)) == -3


def free_round_trips(module, backend: str, n: int, seed: int) -> tuple[int, int, float]:
    """ik_position with the free joints at the sample's values: (samples whose joint vector
    was missed, samples answered with nothing, the worst row's position error over the
    reach); every row keeps the free values."""
    rng = np.random.default_rng(seed)
    missed = empty = 0
    worst = 0.0
    for q in rng.uniform(-math.pi, math.pi, (n, module.DOF)):
        p = module.fk(q)[:3, 3]
        rows = module.ik_position(p, free=[q[j - 1] for j in module.FREE], backend=backend)
        empty += len(rows) == 0
        for row in rows:
            worst = max(worst, float(np.max(np.abs(module.fk(row)[:3, 3] - p))))
            assert all(row[j - 1] == q[j - 1] for j in module.FREE)
        gaps = np.abs(np.remainder(rows - q + math.pi, 2 * math.pi) - math.pi)
        missed += not len(rows) or bool(np.min(np.max(gaps, axis=1)) > 1e-8)
    return missed, empty, worst / module.REACH


# a 6R arm with its tool 206 mm out along z6 (the wrist's joints move the tool point), and a
# humanoid's shoulder (three axes meeting), the elbow 0.3 m down the upper arm's roll axis, the
# hand 0.28 m beyond it
LECTURE_POSITION = Path("derive/arms/lecture_6r.toml").read_text() + '\n[ik]\ntask = "position"\n'
SHOULDER_ELBOW = spec_text(
    "shoulder_elbow",
    "modified",
    [(0, 0, 0, 0), (-90, 0, 0, -90), (90, 0, 0.3, 0), (-90, 0, 0, 0)],
    extra="\n[tool]\nmatrix = [[1, 0, 0, 0.28], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]\n",
)


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_an_arm_with_more_joints_than_the_position_needs_has_free_joints(backend, tmp_path):
    """task = "position" on a 6R arm (it was refused: "position" needed exactly 3 joints):
    joints 4-6 free, 1-3 solved with the tool point in frame 3 computed from the free values
    first; the sampled joint vector among the rows at every sample, every row within 1e-10."""
    module = build_module(LECTURE_POSITION, tmp_path, c=backend == "c")
    assert module.FREE == (4, 5, 6) and module.IK_COMPONENTS == "position"
    assert "ik_position(p, *, free=None" in module.__doc__
    missed, empty, worst = free_round_trips(module, backend, 300, 3)
    assert missed == 0 and empty == 0 and worst <= 1e-10


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_four_joints_beyond_the_angle_task_solve_the_position_one_free(backend, tmp_path):
    """A shoulder of three meeting axes and an elbow: the four-joint default, the angle of a
    tool axis to a base axis, does not apply (joint 1 is not along the base z axis once the
    tool is turned; it was "FK only", a new user's humanoid arms), so the tool point's
    position is solved with one end joint free, and the summary says so."""
    plan = build_plan(parse_spec(SHOULDER_ELBOW, "<test>"))
    assert plan.ik is not None and plan.ik.certify == "position" and len(plan.ik.free) == 1
    assert any("the tool point's position, one joint free" in fact for fact in plan.structure)
    module = build_module(SHOULDER_ELBOW, tmp_path, c=backend == "c")
    missed, empty, worst = free_round_trips(module, backend, 300, 5)
    assert missed == 0 and empty == 0 and worst <= 1e-10


@needs_cc
def test_the_c_ik_position_takes_the_free_values(tmp_path):
    """NAME_ik_position(p, free, q_ref, tol, q) of an arm with free joints: the module's
    rows for the same free values."""
    import ctypes

    module = build_module(LECTURE_POSITION, tmp_path, c=True)
    lib, why = module._c_library()
    assert lib is not None, why
    double_p = ctypes.POINTER(ctypes.c_double)
    call = lib[f"{module.NAME}_ik_position"]
    rows = np.zeros((module.MAX_SOLUTIONS, module.DOF))
    tol = ctypes.c_double(module.CERTIFY_TOL)
    for q in np.random.default_rng(8).uniform(-math.pi, math.pi, (50, 6)):
        p = np.ascontiguousarray(module.fk(q)[:3, 3])
        free = np.ascontiguousarray(q[3:])
        n = call(p.ctypes.data_as(double_p), free.ctypes.data_as(double_p), None, tol,
                 rows.ctypes.data_as(double_p))  # fmt: skip
        expected = module.ik_position(p, free=free, backend="python")
        assert n == len(expected) > 0 and np.allclose(rows[:n], expected, atol=1e-9)


# a humanoid arm of seven joints: a shoulder of three meeting axes, the elbow 0.3 m down the
# upper arm, a wrist whose axes are 2-3 cm apart, the hand beyond it
HUMANOID7 = spec_text(
    "humanoid7",
    "modified",
    [(0, 0, 0, 0), (-90, 0, 0, -90), (90, 0, 0.3, 0), (-90, 0, 0, 0), (90, 0, 0.25, 0),
     (-90, 0.02, 0, 0), (90, 0.03, 0, 0)],
    extra="\n[tool]\nmatrix = [[1, 0, 0, 0.05], [0, 1, 0, 0], [0, 0, 1, 0.08], [0, 0, 0, 1]]\n"
    '\n[ik]\ntask = "position"\n',
)  # fmt: skip


def test_the_position_s_free_joints_leave_the_joints_that_move_the_point_most():
    """Of the usable choices of free end joints, the one whose solved joints move the tool
    point most (free.position_span): the shoulder and elbow solved, not the wrist, which
    moves the hand a few centimetres (an iCub arm solved its wrist, so almost no point was
    reached at the given free values, a new user's attack); then every sample is found."""
    plan = build_plan(parse_spec(HUMANOID7, "<test>"))
    assert plan.ik is not None and plan.ik.free == (1, 5, 6, 7)


@needs_cc
def test_a_humanoid_arm_s_position_round_trips(tmp_path):
    module = build_module(HUMANOID7, tmp_path, c=True)
    for backend in ("c", "python"):
        missed, empty, worst = free_round_trips(module, backend, 200, 9)
        assert missed == 0 and empty == 0 and worst <= 1e-10


# an Allegro hand's finger (example-robot-data 6.0.0, allegro_right_hand.urdf, palm_link to
# link_3.0_tip, as derive import-urdf writes it): a sideways joint, then three parallel ones,
# the tip 26.7 mm beyond the last along its link
ALLEGRO_FINGER = spec_text(
    "allegro_finger",
    "modified",
    [(0, 0, 0, 0), (90, 0, 0, 90), (0, 0.054, 0, 0), (0, 0.0384, 0, 0)],
    extra="\n[tool]\nmatrix = [[0, 0, 1, 0.0267], [1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0, 1]]\n"
    '\n[ik]\ntask = "position"\n',
)


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_a_free_joint_that_puts_the_point_on_frame_3_s_x_axis_is_solved(backend, tmp_path):
    """The finger's position with q4 free: at q4 = 0 (the finger straight, and the default
    free value) the tool point lies on the x axis of frame 3, d4 = 0 and alpha3 any; the
    solver divided by d4 (ZeroDivisionError in Python, no row in C: a new user's attack). Now
    the sampled vector is among the rows at q4 = 0, 1e-9 and 0.5, and with no free value
    given at q4 = 0."""
    module = build_module(ALLEGRO_FINGER, tmp_path, c=backend == "c")
    assert module.FREE == (4,)
    for q4 in (0.0, 1e-9, 0.5):
        q = np.array([0.2, 0.5, 0.3, q4])
        p = module.fk(q)[:3, 3]
        calls = [{"free": [q4]}] + ([{}] if q4 == 0.0 else [])
        for kw in calls:
            rows = module.ik_position(p, backend=backend, **kw)
            assert len(rows) == 4
            assert np.min(np.max(np.abs(rows - q), axis=1)) <= 1e-9, (q4, kw, rows)
            for row in rows:
                assert np.max(np.abs(module.fk(row)[:3, 3] - p)) <= 1e-10 * module.REACH
    missed, empty, worst = free_round_trips(module, backend, 200, 11)
    assert missed == 0 and empty == 0 and worst <= 1e-10
