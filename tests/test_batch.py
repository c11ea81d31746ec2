"""ik_batch and fk_batch: the same solutions as ik, pose by pose, without a loop over poses."""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from derive.verify import SINGULAR_SIGMA, jacobian_nullity, sample_joints, targets

from conftest import BUNDLED, needs_cc


def same_rows(a: np.ndarray, b: np.ndarray, revolute: np.ndarray, tol: float) -> bool:
    if a.shape != b.shape:
        return False
    d = a - b
    d[:, revolute] = np.remainder(d[:, revolute] + math.pi, 2 * math.pi) - math.pi
    return bool(np.abs(d).max(initial=0.0) <= tol)


def curve_at_singular(m) -> bool:
    """Whether the arm's solvers return their own certified points of a curve of solutions at
    a singular pose: the general method's (eigenvalues), and a nominal table's refined onto
    the exact arm (Newton's steps from each backend's seeds land on nearby points of it;
    measured: the SO-ARM100 with its roll at 90 deg, where the virtual wrist is straight)."""
    return m.METHOD == "general" or hasattr(m, "NOMINAL_DH")


@pytest.mark.parametrize("name", BUNDLED)
def test_ik_batch_equals_ik_pose_by_pose(generated, name):
    m = generated(name)
    Q = sample_joints(m, 400, np.random.default_rng(31))
    T = targets(m, Q)
    batch, valid = m.ik_batch(T, chunk=128)
    assert batch.shape == (400, valid.shape[1], m.DOF)
    revolute = np.array([k == "R" for k in m.JOINT_TYPES])
    for i in range(len(T)):
        # same set, same order; values agree to 1e-6 (at singular poses the scalar and the
        # vectorised arithmetic differ by ~1e-8)
        single, rows = m.ik(T[i]), batch[i][valid[i]]
        if same_rows(single, rows, revolute, 1e-6):
            continue
        # Except where the general method meets a curve of solutions (a singular sample,
        # axes in line): there ik and ik_batch return certified points of the curve that
        # can differ (1.2e-5 at sample 157, q4 = q5 = -90 deg, in one CI run with the tests
        # spread over worker processes; tests/test_seam.py allows the same): the same
        # number of rows, each reproducing the pose.
        assert curve_at_singular(m) and jacobian_nullity(m, Q[i])[0] < SINGULAR_SIGMA, i
        assert len(single) == len(rows), i
        for row in rows:
            np.testing.assert_allclose(m.fk(row), T[i], atol=1e-6 * max(1.0, m.REACH))


@needs_cc
@pytest.mark.parametrize("name", BUNDLED)
def test_backends_give_the_same_solutions(generated, name):
    """The C solver and the Python one: ik and ik_batch, the same rows in the
    same order, on random poses (20% of joints at degenerate values). The general method
    has no reference value to give a free joint: at a singular pose (a self-motion, e.g.
    theta3 + theta6 fixed when axes 3 and 6 line up) each backend returns its own certified
    points of the curve, so those samples are left out for it."""
    m = generated(name)
    Q = sample_joints(m, 300, np.random.default_rng(37))
    if curve_at_singular(m):
        Q = np.array([q for q in Q if jacobian_nullity(m, q)[0] > SINGULAR_SIGMA])
    T = targets(m, Q)
    revolute = np.array([k == "R" for k in m.JOINT_TYPES])
    compiled, valid_c = m.ik_batch(T, backend="c")
    python, valid_p = m.ik_batch(T, backend="python")
    assert np.array_equal(valid_c, valid_p)
    for i in range(len(T)):
        reference = m.ik(T[i], backend="python")
        assert same_rows(reference, m.ik(T[i], backend="c"), revolute, 1e-6), i
        assert same_rows(reference, compiled[i][valid_c[i]], revolute, 1e-6), i
        assert same_rows(reference, python[i][valid_p[i]], revolute, 1e-6), i
        assert not compiled[i][~valid_c[i]].any()


@needs_cc
def test_compiled_solver_takes_free_joints_from_q_ref(generated):
    """At a singular wrist theta4 is free: the C solver settles the pose itself, with
    theta4 from q_ref, exactly as the Python solver does."""
    m = generated("puma560")
    q = np.radians([20.0, -30.0, 40.0, 10.0, 0.0, 25.0])
    T = m.fk(q)
    q_ref = np.radians([0.0, 0.0, 0.0, 33.0, 0.0, 0.0])
    pose, at, out, out_at, ref, ref_at = m._scratch()
    pose[...], ref[:] = T, q_ref
    n = m._native_solver("c").ik(at, None, ref_at, m.CERTIFY_TOL, out_at)
    assert n >= 0  # settled in C (not handed to the Python solver)
    rows = out[:n].copy()
    expected = m.ik(T, q_ref=q_ref, backend="python")
    assert np.isclose(expected[:, 3], math.radians(33.0)).any()  # the singular branch
    revolute = np.ones(6, dtype=bool)
    # theta5 = acos(W33) at W33 ~ 1 is settled to sqrt(eps) only (~2e-8 here): the two
    # backends' rounding of W33 moves it by ~5e-9
    assert same_rows(expected, rows, revolute, 1e-7)
    assert same_rows(expected, m.ik(T, q_ref=q_ref, backend="c"), revolute, 1e-7)
    Qb, valid = m.ik_batch(T[None], q_ref=q_ref, backend="c")
    assert same_rows(expected, Qb[0][valid[0]], revolute, 1e-7)


@needs_cc
def test_compiled_batch_from_several_threads_at_once(generated):
    """ik_batch splits its poses over threads of its own: callers on several threads at once
    each get their own correct results (and ik's per-thread buffers stay apart)."""
    m = generated("puma560")
    T = m.fk_batch(sample_joints(m, 3000, np.random.default_rng(41)))
    expected = m.ik_batch(T, backend="c")
    with ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: m.ik_batch(T, backend="c"), range(8)))
    for Q, valid in results:
        assert np.array_equal(Q, expected[0]) and np.array_equal(valid, expected[1])
    with ThreadPoolExecutor(4) as pool:
        singles = list(pool.map(lambda i: m.ik(T[i], backend="c"), range(len(T))))
    for i, rows in enumerate(singles):
        assert np.array_equal(rows, expected[0][i][expected[1][i]]), i


@needs_cc
def test_the_plain_call_in_c_gives_what_the_checked_path_gives(generated):
    """ik(T) with no options takes a short path into C (nothing to check or choose): the same
    rows as backend="c", for any layout of a float64 T; a T it cannot take (a list, a NaN)
    goes the long way and gets its answer or its error."""
    m = generated("puma560")
    assert m.warmup()
    poses = m.fk_batch(sample_joints(m, 300, np.random.default_rng(43)))
    for T in poses:
        expected = m.ik(T, backend="c")
        assert np.array_equal(m.ik(T), expected)
        assert np.array_equal(m.ik(np.asfortranarray(T)), expected)
        assert np.array_equal(m.ik(T.tolist()), expected)
    bad = poses[0].copy()
    bad[0, 0] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        m.ik(bad)


def test_backend_argument_is_checked(generated, monkeypatch):
    m = generated("planar_2r")
    with pytest.raises(ValueError, match="backend"):
        m.ik(np.eye(4), backend="fortran")
    with pytest.raises(ValueError, match="backend"):
        m.ik_batch(np.eye(4)[None], backend="C")
    monkeypatch.setattr(m, "_native", "no C compiler")  # as in a process without one
    with pytest.raises(RuntimeError, match="backend='c': no C compiler"):
        m.ik(np.eye(4), backend="c")
    assert m.ik_batch(np.eye(4)[None])[1].any()  # "auto" falls back to the Python solver


def test_ik_batch_marks_invalid_poses_per_row(generated):
    m = generated("puma560")
    T = m.fk_batch(np.zeros((4, 6)))
    T[1, 0, 0] = np.nan
    T[2, :3, :3] *= 1.01
    T[3, 0, 3] = 50.0
    _, valid = m.ik_batch(T)
    assert valid[0].any()
    assert not valid[1:].any()
    with pytest.raises(ValueError, match="shape"):
        m.ik_batch(np.eye(4))


def test_ik_batch_slot_count_is_the_maximum(generated):
    assert generated("puma560").ik_batch(np.eye(4)[None])[0].shape == (1, 8, 6)
    assert generated("planar_2r").ik_batch(np.eye(4)[None])[0].shape == (1, 2, 2)


@pytest.mark.parametrize(
    "coeffs, roots",
    [
        ((1.0, -4.0, 6.0, -4.0, 1.0), [1.0]),  # (x - 1)^4: a cluster of four
        ((1.0, 0.0, -2.0, 0.0, 1.0), [-1.0, 1.0]),  # (x^2 - 1)^2: two double roots
        ((1.0, -2.0, 2.0, -2.0, 1.0), [1.0]),  # (x - 1)^2 (x^2 + 1)
        ((1.0, 0.0, 1.0, 0.0, 0.25), []),  # (x^2 + 1/2)^2: no real root
    ],
)
def test_multiple_roots_are_found_once(coeffs, roots):
    from derive.runtime.scalar import _poly_real

    scalar = _poly_real(coeffs)
    assert len(scalar) == len(roots)
    assert np.allclose(scalar, roots, atol=1e-9)
