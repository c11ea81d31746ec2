"""Pieper's method: the course material's answers, published solution sets, and round trips."""

from __future__ import annotations

import math

import numpy as np
import pytest

from derive.pipeline import build_plan
from derive.spec import parse_spec
from derive.verify import roundtrip, sample_joints

from cases import PIEPER_CASES, PUMA_REPORT_FLAGS, PUMA_REPORT_SOLUTIONS
from conftest import build_module, needs_cc, reference_fk, spec_text, wrapped_close


def cup_pose() -> np.ndarray:
    c, s = math.cos(math.radians(35)), math.sin(math.radians(35))
    world_desk = np.array([[1, 0, 0, 830], [0, 1, 0, 20], [0, 0, 1, 330], [0, 0, 0, 1.0]])
    desk_cup = np.array([[c, -s, 0, -280], [s, c, 0, 250], [0, 0, 1, 62.5], [0, 0, 0, 1]])
    return world_desk @ desk_cup


def test_lecture_cup_example_contains_the_published_answer(generated):
    m = generated("lecture_6r")
    sols = np.degrees(m.ik(cup_pose()))
    answer = np.array([21.8, -52.2, 2.5, -20.0, -42.0, 15.0])
    errors = np.abs(sols - answer).max(axis=1)
    # The slides round every intermediate to 4 digits: the exact cup pose gives theta6 =
    # 15.162 deg (hard_cases.yaml: "0.2 deg on angles; the largest difference, theta6, 0.17").
    assert errors.min() < 0.2
    best = sols[errors.argmin()]
    assert np.abs(best[:5] - answer[:5]).max() < 0.1
    assert len(sols) == 8


def test_lecture_arm_uses_the_general_case_quartic(generated):
    from derive.cli import resolve_spec

    plan = build_plan(resolve_spec("lecture_6r"))
    assert plan.ik.case.startswith("general")
    poly = next(s for s in plan.ik.steps if getattr(s, "kind", "") == "poly")
    assert poly.joint == 3 and len(poly.args) == 5
    assert "degree 4 in u = tan(theta3/2)" in generated("lecture_6r").__doc__


def test_puma_report_pose_has_the_reports_eight_solutions(generated):
    m = generated("puma560")
    sols = np.degrees(m.ik(m.fk(np.radians([20.0] * 6))))
    assert len(sols) == 8
    for row in PUMA_REPORT_SOLUTIONS:
        assert any(
            wrapped_close(np.radians(s), np.radians(row), math.radians(2e-3)) for s in sols
        ), row


def test_puma_limits_with_wrapping_versus_the_reports_flags(generated):
    """The report flags a joint when its printed value is outside the range; printed values
    beyond +-180 (e.g. theta4 = 351.68) lie inside once taken modulo 360, so our flags differ
    exactly there."""
    m = generated("puma560")
    lines = []
    for row, report_flags in zip(PUMA_REPORT_SOLUTIONS, PUMA_REPORT_FLAGS):
        q = np.radians(row)
        ours = set()
        for j, (lo, hi) in enumerate(m.LIMITS):
            if not any(lo <= v <= hi for v in (q[j], q[j] - 2 * math.pi, q[j] + 2 * math.pi)):
                ours.add(j + 1)
        lines.append(f"{row}: report flags {sorted(report_flags)}, with wrapping {sorted(ours)}")
        assert ours <= report_flags
        for j in report_flags - ours:
            assert abs(row[j - 1]) > 180
    print("\n".join(lines))
    inside = m.ik(m.fk(np.radians([20.0] * 6)), within_limits=True)
    assert any(wrapped_close(q, np.radians([20.0] * 6), 1e-9) for q in inside)
    for q in inside:
        assert all(lo <= v <= hi for v, (lo, hi) in zip(q, m.LIMITS))


def test_within_limits_returns_each_solution_once_nearest_q_ref(generated):
    m = generated("puma560")
    q = np.radians([10.0, 20.0, 30.0, -100.0, 50.0, 60.0])
    T = m.fk(q)
    plain = m.ik(T)
    inside = m.ik(T, within_limits=True)
    assert len(inside) <= len(plain)
    for row in inside:
        assert all(lo <= v <= hi for v, (lo, hi) in zip(row, m.LIMITS))
        assert any(wrapped_close(row, p, 1e-12) for p in plain)
    # theta6's range is +-266 deg: the flipped wrist's theta6 = -120 deg is also inside as
    # 240; with q_ref near 240 that variant is the one returned
    flipped = [r for r in inside if abs(np.degrees(r[5]) + 120.0) < 1e-6]
    assert flipped
    ref = flipped[0].copy()
    ref[5] += 2 * math.pi
    near = m.ik(T, within_limits=True, q_ref=ref)
    assert any(abs(np.degrees(r[5]) - 240.0) < 1e-6 for r in near)
    assert not any(abs(np.degrees(r[5]) + 120.0) < 1e-6 for r in near)
    # all_turns: every variant inside the limits, as the product over joints
    every = m.ik(T, within_limits=True, all_turns=True)
    values = np.degrees(every[:, 5]).round(6)
    assert 240.0 in values and -120.0 in values and 60.0 in values
    assert len(every) > len(inside)


def test_nearest_picks_the_closest_solution(generated):
    m = generated("puma560")
    q = np.radians([10.0, 20.0, 30.0, 40.0, 50.0, 60.0])
    best = m.nearest(m.fk(q), q + 0.01)
    assert wrapped_close(best, q, 1e-9)
    far = np.eye(4)
    far[0, 3] = 5.0
    assert m.nearest(far, q) is None


def hard_case_module(rows, tmp_path):
    text = spec_text("hard_case", "modified", [(a, b, d, 0.0) for a, b, d in rows])
    return build_module(text, tmp_path)


@pytest.mark.parametrize("case", sorted(PIEPER_CASES))
def test_published_solution_sets(case, tmp_path):
    data = PIEPER_CASES[case]
    m = hard_case_module(data["rows"], tmp_path)
    T = np.vstack([np.array(data["T"]), [0, 0, 0, 1.0]])
    u, _, vt = np.linalg.svd(T[:3, :3])
    T[:3, :3] = u @ vt
    sols = m.ik(T)
    expected = np.radians(data["solutions"])
    assert len(sols) == len(expected)
    for row in expected:
        assert any(wrapped_close(s, row, 1e-6) for s in sols), np.degrees(row)


def test_theta3_pi_root_is_found_through_vanishing_leading_coefficient(tmp_path):
    m = hard_case_module(PIEPER_CASES["craig_lecture_theta3_pi"]["rows"], tmp_path)
    q = np.radians([21.8, -52.2, 180.0, -20.0, -42.0, 15.0])
    sols = m.ik(m.fk(q))
    assert any(wrapped_close(s, q, 1e-9) for s in sols)


def test_out_of_reach_pose_returns_empty(generated):
    for name in ("puma560", "lecture_6r"):
        m = generated(name)
        T = m.fk(np.zeros(6))
        T[:3, 3] *= 50
        sols = m.ik(T)
        assert sols.shape == (0, 6)


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_bad_poses_raise_value_error(generated, backend):
    """The compiled ik checks the pose in compiled code; what it rejects gets the Python
    solver's message."""
    m = generated("puma560")
    with pytest.raises(ValueError, match="shape"):
        m.ik(np.eye(3), backend=backend)
    with pytest.raises(ValueError, match="non-finite"):
        m.ik(np.full((4, 4), np.nan), backend=backend)
    with pytest.raises(ValueError, match="orthonormal"):
        m.ik(np.diag([1.0, 2.0, 1.0, 1.0]), backend=backend)
    with pytest.raises(ValueError, match="last row"):
        m.ik(np.vstack([np.eye(4)[:3], [0.0, 0.0, 0.1, 1.0]]), backend=backend)
    with pytest.raises(ValueError, match="4x4 array of real numbers"):
        m.ik("pose", backend=backend)
    assert m.ik(np.eye(4).tolist(), backend=backend).shape[1] == 6  # nested lists are fine


@pytest.mark.parametrize("name", ["puma560", "lecture_6r"])
def test_bundled_round_trips(generated, name):
    m = generated(name)
    result = roundtrip(m, sample_joints(m, 300, np.random.default_rng(11)))
    print(name, result.summary())
    assert result.unsound == []
    assert result.misses == []
    assert result.singular_found == result.singular


def canonical_rows(rng, case):
    """Random canonical Pieper arm: alpha_i, a_i for i = 0..6, d_i for i = 1..6 (degrees)."""

    def twist():
        return float(rng.choice([90.0, -90.0, rng.uniform(15, 165) * rng.choice([-1, 1])]))

    def length(zero_share=0.3):
        return 0.0 if rng.random() < zero_share else float(rng.uniform(-1, 1))

    alpha = [twist() for _ in range(7)]
    a = [length() for _ in range(7)]
    d = [None] + [length() for _ in range(6)]
    a[2] = float(rng.uniform(0.3, 1.0))
    d[4] = float(rng.uniform(0.3, 1.0)) * rng.choice([-1, 1])
    a[4] = a[5] = d[5] = 0.0
    if case == "a1=0":
        a[1] = 0.0
    elif case == "salpha1=0":
        alpha[1] = float(rng.choice([0.0, 180.0]))
        a[1] = float(rng.uniform(0.2, 1.0))
    else:
        a[1] = float(rng.uniform(0.1, 1.0)) * rng.choice([-1, 1])
    theta = [float(rng.choice([0.0, 90.0, rng.uniform(-180, 180)])) for _ in range(7)]
    return alpha, a, d, theta


def rows_for(convention, alpha, a, d, theta):
    if convention == "modified":
        return [(alpha[k - 1], a[k - 1], d[k], theta[k]) for k in range(1, 7)]
    return [(alpha[k], a[k], d[k], theta[k]) for k in range(1, 7)]


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("case", ["general", "a1=0", "salpha1=0"])
def test_random_pieper_arms_round_trip(convention, case, tmp_path):
    rng = np.random.default_rng(
        ["standard", "modified"].index(convention) * 10
        + ["general", "a1=0", "salpha1=0"].index(case)
    )
    extra = (
        "[base]\ntranslation = [0.1, 0.2, 0.3]\nrpy = [5.0, 10.0, 15.0]\n"
        "[tool]\ntranslation = [0.0, 0.05, 0.1]\n"
    )
    for _ in range(4):
        rows = rows_for(convention, *canonical_rows(rng, case))
        m = build_module(spec_text("random_arm", convention, rows, extra=extra), tmp_path)
        assert m.__doc__.count("pieper method") == 1
        result = roundtrip(m, sample_joints(m, 60, rng))
        assert result.unsound == [], (rows, result.summary())
        assert result.misses == [], (rows, result.summary())
        assert result.singular_found == result.singular, (rows, result.summary())


def check_round_trips(m, rng, samples=60):
    result = roundtrip(m, sample_joints(m, samples, rng))
    assert result.unsound == [], result.summary()
    assert result.misses == [], result.summary()
    assert result.singular_found == result.singular, result.summary()
    return result


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_spherical_joint_at_the_base_is_solved_on_the_reversed_chain(convention, tmp_path):
    rng = np.random.default_rng(5 + len(convention))
    for _ in range(4):
        alpha, a, d, theta = canonical_rows(rng, "general")
        # mirror the wrist conditions to the base: axes 1, 2, 3 meet, 4-6 generic
        a[1] = a[2] = d[2] = 0.0
        a[4], a[5], d[5] = (float(rng.uniform(0.2, 0.8)) for _ in range(3))
        a[3] = float(rng.uniform(0.3, 1.0))
        m = build_module(
            spec_text("base_wrist", convention, rows_for(convention, alpha, a, d, theta)), tmp_path
        )
        assert "axes 1-3 meet: reversed chain" in m.__doc__
        check_round_trips(m, rng)


def test_stanford_arm_prismatic_joint_3(tmp_path):
    rows = [
        (-90.0, 0.0, 0.412, 0.0),
        (90.0, 0.0, 0.154, 0.0),
        (0.0, 0.0, 0.0, 0.0),
        (-90.0, 0.0, 0.0, 0.0),
        (90.0, 0.0, 0.0, 0.0),
        (0.0, 0.0, 0.263, 0.0),
    ]
    text = spec_text("stanford", "standard", rows, kinds="RRPRRR")
    text = text.replace(
        'type = "P"\nalpha = 0.0\na = 0.0\nd = 0.0\ntheta = 0.0\n',
        'type = "P"\nalpha = 0.0\na = 0.0\nd = 0.0\ntheta = 0.0\nlimits = [0.1, 0.8]\n',
    )
    m = build_module(text, tmp_path)
    assert "degree 2 in d3" in m.__doc__
    result = check_round_trips(m, np.random.default_rng(2), 150)
    assert max(result.counts) == 8
    inside = m.ik(m.fk([0.3, 0.2, 0.5, 0.1, 0.4, 0.2]), within_limits=True)
    assert all(0.1 <= q[2] <= 0.8 for q in inside) and len(inside) == 4


@pytest.mark.parametrize("case", ["general", "a1=0", "salpha1=0"])
def test_random_prismatic_joint_3_arms(case, tmp_path):
    rng = np.random.default_rng(40 + ["general", "a1=0", "salpha1=0"].index(case))
    for convention in ("standard", "modified"):
        alpha, a, d, theta = canonical_rows(rng, case)
        alpha[2] = float(rng.uniform(20, 70))  # cos(alpha2) = 0 with sin(alpha1) = 0 is planar
        rows = rows_for(convention, alpha, a, d, theta)
        text = spec_text("prismatic3", convention, rows, kinds="RRPRRR")
        text = text.replace('type = "P"\n', 'type = "P"\nlimits = [-1.0, 1.0]\n')
        m = build_module(text, tmp_path)
        assert "in d3" in m.__doc__
        check_round_trips(m, rng, 80)


def test_degenerate_prismatic_arm_is_refused_with_a_reason(tmp_path):
    rows = [
        (0.0, 0.5, 0.0, 0.0),
        (90.0, 0.4, 0.1, 0.0),
        (-90.0, 0.0, 0.0, 0.0),
        (90.0, 0.0, 0.3, 0.0),
        (-90.0, 0.0, 0.0, 0.0),
        (0.0, 0.0, 0.0, 0.0),
    ]
    plan = build_plan(parse_spec(spec_text("flat", "standard", rows, kinds="RRPRRR")))
    assert plan.ik is None
    assert "does not involve joint 3" in plan.refusal


def test_wrist_centre_on_axis_1_takes_theta1_from_q_ref(tmp_path):
    m = hard_case_module(PIEPER_CASES["craig_lecture_pieper"]["rows"], tmp_path)
    theta3 = 0.3
    f1 = 340 - 338 * math.sin(theta3) - 40 * math.cos(theta3)
    f2 = 338 * math.cos(theta3) - 40 * math.sin(theta3)
    # g1 = c2 f1 - s2 f2 - 30 = 0 puts the wrist centre on axis 1 (g2 = 0 for this arm)
    theta2 = math.atan2(-f2, f1) + math.acos(30 / math.hypot(f1, f2))
    q = np.array([0.7, theta2, theta3, 0.4, 0.5, 0.6])
    T = m.fk(q)
    assert math.hypot(*T[:2, 3]) < 1e-9
    with_ref = m.ik(T, q_ref=q)
    assert any(wrapped_close(s, q, 1e-9) for s in with_ref)
    default = m.ik(T)
    assert len(default) > 0 and np.allclose(default[:, 0], 0.0)
    # a shoulder singularity: the theta3 roots are double here, so the singular tolerance holds
    for s in default:
        assert np.abs(m.fk(s) - T).max() < 1e-6 * m.REACH


def test_singular_wrist_keeps_theta4_plus_theta6(generated):
    m = generated("puma560")
    q = np.radians([30.0, -40.0, 20.0, 50.0, 0.0, 70.0])
    T = m.fk(q)
    sols = m.ik(T)
    assert len(sols) == 7  # the branch with a singular wrist has one representative, not two
    for s in sols:
        assert np.abs(m.fk(s) - T).max() < 1e-9
    match = [s for s in sols if wrapped_close(s[:3], q[:3], 1e-9)]
    assert len(match) == 1
    assert match[0][3] == 0.0
    assert wrapped_close(match[0][3] + match[0][5], q[3] + q[5], 1e-9)
    flipped = m.ik(T, q_ref=q)
    assert any(wrapped_close(s, q, 1e-9) for s in flipped)


def test_fewer_real_solutions_return_only_the_real_ones(tmp_path):
    data = PIEPER_CASES["pieper_parallel_axes_1_2"]
    m = hard_case_module(data["rows"], tmp_path)
    T = np.vstack([np.array(data["T"]), [0, 0, 0, 1.0]])
    assert len(m.ik(T)) == 4


# two published standard-DH tables (ir-support-extra-robots 0.2.1, PyPI, MIT: robots/EpsonVT6,
# robots/FanucLRMate200iC), (alpha, a, d, theta) in rad and m, whose quartic in
# u = tan(theta3/2) has both ends nearly vanishing near q3 = 0 (the Epson's elbow roots are
# theta3 and pi - theta3) or near q2 = -90 deg, q3 = 0 (the LR Mate)
_HALF = math.pi / 2
EPSON_VT6 = [
    (_HALF, -0.09816, 0.411523, 0.0),
    (0.0, 0.4234, 0.0, 0.0),
    (_HALF, 0.0, 0.0, 0.0),
    (_HALF, 0.0, -0.395804, 0.0),
    (_HALF, 0.0, 0.0, 0.0),
    (0.0, 0.0, -0.087348, 0.0),
]
LR_MATE_200IC = [
    (-_HALF, 0.075, 0.33, 0.0),
    (0.0, 0.3, 0.0, -_HALF),
    (-_HALF, 0.075, 0.0, 0.0),
    (_HALF, 0.0, 0.32, 0.0),
    (-_HALF, 0.0, 0.0, 0.0),
    (0.0, 0.0, 0.08, 0.0),
]


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
@pytest.mark.parametrize("name", ["epson_vt6", "lr_mate_200ic"])
def test_a_quartic_whose_both_ends_nearly_vanish_keeps_all_its_roots(name, backend, tmp_path):
    """Where the quartic's first and last coefficients are 1e-9 of its largest, Ferrari's
    formulas gave one real root right and three complex ones wrong: the rows of the other
    three roots were lost (the Epson VT6 missed the sampled vector at 23 of 100 such poses in
    C, 33 in Python; the LR Mate at 12 of 100 in Python). A closed form's complex root that
    fails the residual test now sends the quartic to the companion matrix (C: Aberth's
    iteration). Poses from the textbook FK (a rounding away from the module's own), the
    chosen joints 1e-8 to 1e-5 rad from their values: every sampled vector found, every row
    within 1e-10."""
    rows = EPSON_VT6 if name == "epson_vt6" else LR_MATE_200IC
    m = build_module(spec_text(name, "standard", rows, unit="rad"), tmp_path)
    rng = np.random.default_rng(5)
    for k in range(60):
        q = rng.uniform(-math.pi, math.pi, 6)
        nudge = 10.0 ** rng.uniform(-8, -5) * rng.choice([-1.0, 1.0], 2)
        if name == "epson_vt6":
            q[2] = nudge[0]
        else:
            q[1], q[2] = -_HALF + nudge[0], nudge[1]
        T = reference_fk("standard", rows, "RRRRRR", q)
        sols = m.ik(T, backend=backend)
        assert any(wrapped_close(s, q, 1e-6) for s in sols), (k, q)
        for s in sols:
            assert np.abs(reference_fk("standard", rows, "RRRRRR", s) - T).max() <= 1e-10
