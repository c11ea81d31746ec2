"""Link transforms and FK against the course material and an independent numpy FK."""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from derive import symbols as sym
from derive.methods.pieper import general_f_g
from derive.spec import load_spec
from derive.transforms import (
    chain_from_spec,
    link_transform,
    numbers_of,
    to_angles,
    x_factor,
    z_factor,
)

from conftest import BUNDLED, ROOT, reference_fk


def chain(name):
    return chain_from_spec(load_spec(ROOT / "derive" / "arms" / f"{name}.toml"))


def test_puma_fk_matches_report_pose(generated):
    m = generated("puma560")
    report = np.array(
        [
            [0.105754155679965, -0.642514138372515, 0.758941131147761, 0.577649533099654],
            [0.701905312986400, 0.588858820882606, 0.4007171329881, 0.368809723984954],
        ]
    )
    T = m.fk(np.radians([20.0] * 6))
    assert np.abs(T[:2] - report).max() < 2e-9


def test_puma_zyz_angles_match_report(generated):
    R = generated("puma560").fk(np.radians([20.0] * 6))[:3, :3]
    b = math.atan2(math.hypot(R[0, 2], R[1, 2]), R[2, 2])
    a = math.atan2(R[1, 2], R[0, 2])
    c = math.atan2(R[2, 1], -R[2, 0])
    assert np.degrees([a, b, c]) == pytest.approx([27.8338, 59.1189, 34.8424], abs=5e-5)


def test_lecture_f_and_g_equal_the_lectures():
    ch = chain("lecture_6r")
    c3, s3 = sym.c(3), sym.s(3)
    p4 = sp.Matrix(
        [ch.twists[3].a, -ch.twists[3].sa * ch.joints[3].d, ch.twists[3].ca * ch.joints[3].d, 1]
    )
    f = link_transform(ch, 3) * p4
    lecture_f = sp.Matrix([340 - 338 * s3 - 40 * c3, 338 * c3 - 40 * s3, 0, 1])
    assert sp.simplify(f - lecture_f) == sp.zeros(4, 1)
    g = link_transform(ch, 2) * f
    t2, t3 = sym.theta(2), sym.theta(3)
    lecture_g = sp.Matrix(
        [
            340 * sp.cos(t2) - 40 * sp.cos(t2 + t3) - 338 * sp.sin(t2 + t3) - 30,
            0,
            40 * sp.sin(t2 + t3) - 338 * sp.cos(t2 + t3) - 340 * sp.sin(t2),
            1,
        ]
    )
    assert sp.simplify(to_angles(g, ch) - lecture_g) == sp.zeros(4, 1)


def test_general_f_and_g_equal_the_lectures_formulas():
    f, g = general_f_g()
    a, d, ca, sa = sym.link_a, sym.d, sym.cos_alpha, sym.sin_alpha
    c3, s3, c2, s2 = sym.c(3), sym.s(3), sym.c(2), sym.s(2)
    lecture_f = [
        a(3) * c3 + d(4) * sa(3) * s3 + a(2),
        a(3) * ca(2) * s3 - d(4) * sa(3) * ca(2) * c3 - d(4) * sa(2) * ca(3) - d(3) * sa(2),
        a(3) * sa(2) * s3 - d(4) * sa(3) * sa(2) * c3 + d(4) * ca(2) * ca(3) + d(3) * ca(2),
    ]
    F = sp.symbols("F1:4")
    lecture_g = [
        c2 * F[0] - s2 * F[1] + a(1),
        s2 * ca(1) * F[0] + c2 * ca(1) * F[1] - sa(1) * F[2] - d(2) * sa(1),
        s2 * sa(1) * F[0] + c2 * sa(1) * F[1] + ca(1) * F[2] + d(2) * ca(1),
    ]
    for k in range(3):
        assert sp.expand(f[k] - lecture_f[k]) == 0
        fill = dict(zip(F, lecture_f))
        assert sp.expand(g[k] - lecture_g[k].xreplace(fill)) == 0


def test_parallel_6r_link_transforms_equal_the_blog_posts():
    ch = chain("parallel_6r")
    t = [sym.theta(i) for i in range(1, 7)]
    d2, a2, a3, d5 = 116.5, 203.5, 173, 79.2
    C, S = sp.cos, sp.sin
    blog = [
        [[C(t[0]), -S(t[0]), 0, 0], [S(t[0]), C(t[0]), 0, 0], [0, 0, 1, 0]],
        [[C(t[1]), -S(t[1]), 0, 0], [0, 0, 1, d2], [-S(t[1]), -C(t[1]), 0, 0]],
        [[C(t[2]), -S(t[2]), 0, a2], [S(t[2]), C(t[2]), 0, 0], [0, 0, 1, 0]],
        [[C(t[3]), -S(t[3]), 0, a3], [S(t[3]), C(t[3]), 0, 0], [0, 0, 1, 0]],
        [[C(t[4]), -S(t[4]), 0, 0], [0, 0, -1, -d5], [S(t[4]), C(t[4]), 0, 0]],
        [[C(t[5]), -S(t[5]), 0, 0], [0, 0, 1, 0], [-S(t[5]), -C(t[5]), 0, 0]],
    ]
    for i in range(1, 7):
        derived = to_angles(link_transform(ch, i), ch)[:3, :]
        diff = (derived - sp.Matrix(blog[i - 1])).applyfunc(lambda e: sp.nsimplify(sp.expand(e)))
        assert diff == sp.zeros(3, 4), i


def test_lecture_answer_reaches_the_cup_pose(generated):
    m = generated("lecture_6r")
    c, s = math.cos(math.radians(35)), math.sin(math.radians(35))
    world_cup = np.array(
        [[1, 0, 0, 830], [0, 1, 0, 20], [0, 0, 1, 330], [0, 0, 0, 1.0]]
    ) @ np.array([[c, -s, 0, -280], [s, c, 0, 250], [0, 0, 1, 62.5], [0, 0, 0, 1]])
    T = m.fk(np.radians([21.8, -52.2, 2.5, -20, -42, 15]))
    # the answer is rounded to 0.1 deg: 0.1 deg at ~700 mm reach is ~1.2 mm, and ~2e-3 in rotation
    assert np.abs(T[:3, 3] - world_cup[:3, 3]).max() < 1.5
    assert np.abs(T[:3, :3] - world_cup[:3, :3]).max() < 3e-3


def test_lecture_flange_pose_matches_lectures_0_6T(generated):
    m = generated("lecture_6r")
    flange = (
        np.linalg.inv(m.BASE)
        @ m.fk(np.radians([21.8, -52.2, 2.5, -20, -42, 15]))
        @ np.linalg.inv(m.TOOL)
    )
    lecture = np.array([[0, 0.5736, 0.8192, 381.3], [0, -0.8192, 0.5736, 151.8], [1, 0, 0, 19.5]])
    assert np.abs(flange[:3, :3] - lecture[:, :3]).max() < 3e-3
    assert np.abs(flange[:3, 3] - lecture[:, 3]).max() < 1.0


@pytest.mark.parametrize("name", BUNDLED)
def test_fk_equals_independent_numpy_fk(generated, name):
    m = generated(name)
    spec = load_spec(ROOT / "derive" / "arms" / f"{name}.toml")
    rng = np.random.default_rng(7)
    for q in rng.uniform(-math.pi, math.pi, (50, m.DOF)):
        if spec.exact is None:
            expected = reference_fk(spec.convention, m.DH, m.JOINT_TYPES, q, m.BASE, m.TOOL)
        else:  # (fk is the exact frames' T(q) = F_0 J_1(q_1) F_1 ... J_n(q_n) F_n)
            expected = frames_fk(spec.exact, m.JOINT_TYPES, q)
        assert np.abs(m.fk(q) - expected).max() < 1e-12 * max(1.0, m.REACH)


def frames_fk(frames, kinds: str, q) -> np.ndarray:
    """The pose of a chain of fixed frames (12 numbers each) and joints about or along z."""
    T = np.eye(4)
    for k, frame in enumerate(frames):
        F = np.eye(4)
        F[:3, :] = np.array(frame).reshape(3, 4)
        if k:
            J = np.eye(4)
            if kinds[k - 1] == "R":
                c, s = math.cos(q[k - 1]), math.sin(q[k - 1])
                J[:2, :2] = [[c, -s], [s, c]]
            else:
                J[2, 3] = q[k - 1]
            T = T @ J
        T = T @ F
    return T


@pytest.mark.parametrize("name", BUNDLED)
def test_fk_batch_equals_fk(generated, name):
    m = generated(name)
    Q = np.random.default_rng(3).uniform(-4, 4, (200, m.DOF))
    batch = m.fk_batch(Q)
    assert batch.shape == (200, 4, 4)
    for q, T in zip(Q, batch):
        assert np.array_equal(T, m.fk(q))


def test_both_conventions_with_prismatic_joints_and_frames(tmp_path):
    from conftest import build_module, spec_text

    rows = [(30, 0.1, 0.2, 10), (-90, 0.3, 0.0, 45), (17, -0.2, 0.4, 0)]
    frames = (
        "[base]\ntranslation = [0.1, -0.2, 0.3]\nrpy = [10.0, 20.0, 30.0]\n"
        "[tool]\ntranslation = [0.0, 0.0, 0.05]\nrpy = [0.0, 90.0, 0.0]\n"
    )
    for convention in ("standard", "modified"):
        m = build_module(spec_text("arm", convention, rows, kinds="RPR", extra=frames), tmp_path)
        for q in np.random.default_rng(1).uniform(-2, 2, (20, 3)):
            expected = reference_fk(convention, m.DH, "RPR", q, m.BASE, m.TOOL)
            assert np.abs(m.fk(q) - expected).max() < 1e-12
        from conftest import rx, rz

        R = (
            rz(math.radians(30))
            @ np.array(
                [
                    [math.cos(math.radians(20)), 0, math.sin(math.radians(20)), 0],
                    [0, 1, 0, 0],
                    [-math.sin(math.radians(20)), 0, math.cos(math.radians(20)), 0],
                    [0, 0, 0, 1],
                ]
            )
            @ rx(math.radians(10))
        )
        assert np.abs(m.BASE[:3, :3] - R[:3, :3]).max() < 1e-15


def test_general_twists_substitute_exactly():
    numbers = numbers_of(chain("puma560"))
    assert numbers[sym.cos_alpha(1)] == 0 and numbers[sym.sin_alpha(1)] == -1
    assert numbers[sym.link_a(2)] == sp.Rational(432, 1000)
    assert x_factor(chain("puma560").twists[1])[1, 1] == 0
    assert z_factor(chain("puma560").joints[2])[2, 3] == sp.Rational(149, 1000)
