"""Three parallel axes (UR type), planar arms and arms with fewer than six joints."""

from __future__ import annotations

import math

import numpy as np
import pytest

from derive.pipeline import build_plan
from derive.spec import parse_spec
from derive.verify import roundtrip, sample_joints

from conftest import build_module, needs_cc, reference_fk, spec_text, wrapped_close

UR_COURSE_ARM = [
    (0.0, 0.0, 0.0),
    (-90.0, 0.0, 116.5),
    (0.0, 203.5, 0.0),
    (0.0, 173.0, 0.0),
    (90.0, 0.0, 79.2),
    (-90.0, 0.0, 0.0),
]
UR_COURSE_T = [
    [0.519298147546, 0.0070239512832, 0.854564273805, 347.392802557],
    [-0.822517374485, -0.267282955241, 0.502020906445, 57.0424762899],
    [0.231936634936, -0.963592489565, -0.133022221559, 6.3589802627],
]
UR_COURSE_SOLUTIONS = [
    [-151.350299159, -166.220157444, -57.9793650055, -143.448405678, 91.766911907, -13.7708675391],
    [-151.350299159, -147.440857125, -40.7552306896, 0.548159687357, -91.766911907, 166.229132461],
    [-151.350299159, 140.940483254, 57.9793650055, 153.432223613, 91.766911907, -13.7708675391],
    [-151.350299159, 175.251054161, 40.7552306896, -43.6542129784, -91.766911907, 166.229132461],
    [-10.0, -31.1170869886, 38.0261164468, -176.909029458, 50.0, 160.0],
    [-10.0, -14.6443709826, 60.0, -35.3556290174, -50.0, -20.0],
    [-10.0, 3.71110633032, -38.0261164468, -135.684989884, 50.0, 160.0],
    [-10.0, 40.0, -60.0, 30.0, -50.0, -20.0],
]
UR5 = [
    (90.0, 0.0, 0.089159, 0.0),
    (0.0, -0.425, 0.0, 0.0),
    (0.0, -0.39225, 0.0, 0.0),
    (90.0, 0.0, 0.10915, 0.0),
    (-90.0, 0.0, 0.09465, 0.0),
    (0.0, 0.0, 0.0823, 0.0),
]


def check(m, rng, samples):
    result = roundtrip(m, sample_joints(m, samples, rng))
    print(result.summary())
    assert result.unsound == [], result.summary()
    assert result.misses == [], result.summary()
    assert result.singular_posed == result.singular, result.summary()
    return result


def test_parallel_6r_follows_the_blog_posts_order(generated):
    m = generated("parallel_6r")
    assert "three-parallel method" in m.__doc__ and "a5 = 0" in m.__doc__
    from derive.cli import resolve_spec

    plan = build_plan(resolve_spec("parallel_6r"))
    order = [s.joint for s in plan.ik.steps if hasattr(s, "joint")]
    assert order == [1, 5, 6, 3, 2, 4]


def test_parallel_6r_round_trips(generated):
    result = check(generated("parallel_6r"), np.random.default_rng(21), 300)
    assert max(result.counts) == 8


@pytest.mark.parametrize("mirror", [1.0, -1.0])
def test_course_arm_solution_set_and_its_mirror(mirror, tmp_path):
    rows = [(mirror * a if a else 0.0, l, d, 0.0) for a, l, d in UR_COURSE_ARM]
    m = build_module(spec_text("ur_course", "modified", rows), tmp_path)
    M = np.diag([1.0, mirror, 1.0, 1.0])
    T = M @ np.vstack([np.array(UR_COURSE_T), [0, 0, 0, 1.0]]) @ M
    sols = m.ik(T)
    assert len(sols) == 8
    for row in UR_COURSE_SOLUTIONS:
        assert any(wrapped_close(s, mirror * np.radians(row), 1e-6) for s in sols), row


def test_ur5_published_dh_round_trips(tmp_path):
    m = build_module(spec_text("ur5", "standard", UR5), tmp_path)
    assert "three-parallel" in m.__doc__
    check(m, np.random.default_rng(5), 300)


# the myCobot 320's published standard-DH table (ir-support-extra-robots 0.2.1, PyPI, MIT:
# robots/MyCobot320), (alpha, a, d, theta) in rad and m; its a3 is 5 mm
MYCOBOT_320 = [
    (math.pi / 2, 0.0, 0.17866, 0.0),
    (0.0, 0.136, -0.005, 0.0),
    (0.0, 0.005, -0.1, 0.0),
    (-math.pi / 2, 0.099, 0.08515, 0.0),
    (-math.pi / 2, 0.0, 0.099, 0.0),
    (math.pi, 0.0, -0.0619, 0.0),
]


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_an_elbow_and_a_wrist_both_nearly_straight_are_answered(backend, tmp_path):
    """q3 and q5 both 1e-10 or 1e-8 rad from 0 (the pose singular to rounding): theta6 from
    s5's terms carries rounding over s5, and the elbow's law of cosines then missed 1 by more
    than its band (25 and 31 of 100 such poses of the myCobot 320 got no row, C and Python).
    Where the first pass gives no row, a second solves each equation that misses at its
    boundary, and polishes rows within _LOOSE_REACH (1e-4) of the pose (the first such row
    was 1.04e-6 off). Poses from the textbook FK: every one answered, every row within 1e-8
    of it (the worst of 200 poses per distance 2.7e-9: the pose is singular to rounding,
    sigma_min 1e-17, and the polish stalls), the sampled vector among the rows (1e-6) where
    both are 1e-3 rad from 0."""
    m = build_module(spec_text("mycobot320", "standard", MYCOBOT_320, unit="rad"), tmp_path)
    rng = np.random.default_rng(2)
    for distance in (1e-10, 1e-8, 1e-3):
        for _ in range(40):
            q = rng.uniform(-2.7, 2.7, 6)
            q[2], q[4] = distance * rng.choice([-1.0, 1.0], 2)
            T = reference_fk("standard", MYCOBOT_320, "RRRRRR", q)
            sols = m.ik(T, backend=backend)
            assert len(sols), q
            for s in sols:
                assert np.abs(reference_fk("standard", MYCOBOT_320, "RRRRRR", s) - T).max() < 1e-8
            if distance == 1e-3:
                assert any(wrapped_close(s, q, 1e-6) for s in sols), q


def test_axes_3_4_5_parallel_use_the_reversed_chain(tmp_path):
    reversed_ur5 = [
        (0.0, 0.0, 0.0823, 0.0),
        (-90.0, 0.0, 0.09465, 0.0),
        (90.0, 0.0, 0.10915, 0.0),
        (0.0, -0.39225, 0.0, 0.0),
        (0.0, -0.425, 0.0, 0.0),
        (90.0, 0.0, 0.089159, 0.0),
    ]
    m = build_module(spec_text("rev_ur", "modified", reversed_ur5), tmp_path)
    assert "axes 3-5 parallel: reversed chain" in m.__doc__
    check(m, np.random.default_rng(6), 200)


def test_random_three_parallel_arms_with_a5_nonzero_give_a_quartic(tmp_path):
    rng = np.random.default_rng(8)
    for _ in range(3):
        rows = [
            (0.0, 0.0, 0.0, 0.0),
            (-90.0, 0.1, float(rng.uniform(0.1, 0.3)), 0.0),
            (0.0, float(rng.uniform(0.3, 0.6)), 0.0, 0.0),
            (0.0, float(rng.uniform(0.3, 0.6)), float(rng.uniform(-0.1, 0.1)), 0.0),
            (
                float(rng.uniform(30, 80)),
                float(rng.uniform(-0.2, 0.2)),
                float(rng.uniform(0.05, 0.2)),
                0.0,
            ),
            (float(rng.uniform(-80, -30)), float(rng.uniform(0.05, 0.2)), 0.0, 0.0),
        ]
        m = build_module(spec_text("ur_a5", "modified", rows), tmp_path)
        assert "a5 != 0: quartic" in m.__doc__
        check(m, rng, 80)


def test_lecture_rrr_returns_the_two_published_solutions(generated):
    m = generated("lecture_rrr")
    T = m.fk(np.radians([39.6, 75.5, -70.2]))
    sols = np.degrees(m.ik(T))
    assert len(sols) == 2
    for published in ([39.6, 75.5, -70.2], [78.4, -75.5, 42.1]):
        assert any(np.abs(s - published).max() < 0.3 for s in sols), published


def test_lecture_rrr_too_far_to_reach_and_off_plane(generated):
    m = generated("lecture_rrr")
    far = np.eye(4)
    far[0, 3] = 1.5  # c2 > 1: "too far for the manipulator to reach"
    assert m.ik(far).shape == (0, 3)
    tilted = m.fk(np.radians([10.0, 20.0, 30.0]))
    tilted[2, 3] = 0.01
    assert m.ik(tilted).shape == (0, 3)


def test_planar_2r_agrees_with_the_course_pages_closed_form(generated):
    m = generated("planar_2r")
    a1 = a2 = 1.0
    rng = np.random.default_rng(4)
    for _ in range(200):
        radius = rng.uniform(0.05, 1.95)
        angle = rng.uniform(-math.pi, math.pi)
        x, y = radius * math.cos(angle), radius * math.sin(angle)
        T = np.eye(4)
        T[:2, 3] = (x, y)
        sols = m.ik(T)
        assert len(sols) == 2
        for sign in (1, -1):
            q2 = sign * math.acos((x * x + y * y - a1 * a1 - a2 * a2) / (2 * a1 * a2))
            q1 = math.atan2(y, x) - math.atan2(a2 * math.sin(q2), a1 + a2 * math.cos(q2))
            assert any(wrapped_close(s, [q1, q2], 1e-9) for s in sols)


def test_planar_2r_ignores_the_rotation_but_not_z(generated):
    m = generated("planar_2r")
    T = m.fk(np.radians([30.0, 40.0]))
    T[:3, :3] = np.eye(3)
    assert len(m.ik(T)) == 2
    T[2, 3] = 1e-3
    assert len(m.ik(T)) == 0
    assert len(m.ik(T, tol=1e-2)) == 2
    assert "x and y" in m.__doc__


def test_scara_rrpr_round_trips(tmp_path):
    rows = [
        (0.0, 0.325, 0.4, 0.0),
        (0.0, 0.275, 0.0, 0.0),
        (0.0, 0.0, 0.0, 0.0),
        (0.0, 0.0, 0.05, 0.0),
    ]
    text = spec_text("scara", "standard", rows, kinds="RRPR")
    text = text.replace('type = "P"\n', 'type = "P"\nlimits = [-0.2, 0.0]\n')
    m = build_module(text, tmp_path)
    assert "SCARA" in m.__doc__
    check(m, np.random.default_rng(9), 300)


def test_arm_no_method_covers_gets_a_one_line_reason():
    """A 6-joint arm with a prismatic joint 2 and no special structure: no method covers it
    (the general method takes one prismatic joint, as joint 3 or 4)."""
    rows = [
        (90.0, 0.3, 0.1, 0.0),
        (1.0, 1.0, 0.0, 0.0),
        (90.0, 0.0, 0.2, 0.0),
        (1.0, 1.5, 0.0, 0.0),
        (90.0, 0.0, 0.0, 0.0),
        (1.0, 0.0, 0.0, 0.0),
    ]
    plan = build_plan(parse_spec(spec_text("general6r", "standard", rows, kinds="RPRRRR")))
    assert plan.ik is None
    assert "Pieper: neither axes 4, 5, 6 nor axes 1, 2, 3 meet in a point" in plan.refusal
    assert "general: takes one prismatic joint at most, as joint 3 or 4" in plan.refusal
    assert "\n" not in plan.refusal


@pytest.mark.parametrize("name", ["lecture_rrr", "planar_2r"])
def test_planar_bundled_round_trips(generated, name):
    m = generated(name)
    result = check(m, np.random.default_rng(12), 400)
    assert result.singular_found == result.singular


# Long-run arm 233 (tests/long_run.py): axes 1-3 parallel, and axis 5 parallel to them too
# where theta4 is 0 or 180 deg; there both entries that give theta5 vanish (a curve of
# solutions) and theta5 must be free: with no scale for that test, 8 of its 36 singular
# samples got no solution.
END_PARALLEL_ROWS = [
    (0.0, -0.029004, 0.019387, 180.0),
    (0.0, -0.088153, -0.095523, -90.0),
    (90.0, 0.0, 0.020116, -76.403),
    (-90.0, 0.08323, 0.0, 0.0),
    (90.0, -0.02007, 0.041192, -63.826),
    (-133.0, -0.097086, 0.065132, -90.0),
]


def test_axes_1_2_3_parallel_with_axis_5_joining_them_at_theta4_0(tmp_path):
    m = build_module(spec_text("end_parallel", "standard", END_PARALLEL_ROWS), tmp_path)
    assert "axes 1-3 parallel: theta4 from a polynomial of degree 8" in " ".join(m.__doc__.split())
    Q = sample_joints(m, 120, np.random.default_rng(10_233))
    Q[::2, 3] = np.where(Q[::2, 3] > 0, math.pi, 0.0)  # (half of them on the curves)
    result = roundtrip(m, Q)
    assert result.singular >= 30, result.summary()
    assert result.unsound == [] and result.misses == [], result.summary()
    assert result.singular_posed == result.singular, result.summary()


# Long-run arm 815 (tests/long_run.py, modified DH): axes 1-4 parallel, joint 4 sliding at
# right angles to the plane of the three turning joints. It has all six degrees of freedom,
# but four parallel axes were refused by the three-parallel method, and the general method
# (on a perturbed table: its own is singular) lost 14 of its 189 regular samples.
FOUR_PARALLEL_ROWS = [
    (130.0, 52.678847, 0.0, 116.063),
    (180.0, 80.349542, -85.470747, 95.553),
    (0.0, 74.3039, 0.0, -90.0),
    (0.0, 25.076194, 0.0, -117.608),
    (-156.0, -47.240414, 61.890383, 180.0),
    (-22.0, 0.0, 0.0, 0.0),
]


def test_axes_1_to_4_parallel_with_joint_4_sliding(tmp_path):
    text = spec_text("four_parallel", "modified", FOUR_PARALLEL_ROWS, kinds="RRRPRR")
    text = text.replace('type = "P"\n', 'type = "P"\nlimits = [-100.0, 100.0]\n')
    m = build_module(text, tmp_path)
    assert m.METHOD == "three-parallel"
    assert "theta5 from entry (3,3), d4 from entry (3,4)" in " ".join(m.__doc__.split())
    result = roundtrip(m, sample_joints(m, 200, np.random.default_rng(10_815)))
    assert result.singular >= 5, result.summary()
    assert result.unsound == [] and result.misses == [], result.summary()
    assert result.singular_posed == result.singular, result.summary()
