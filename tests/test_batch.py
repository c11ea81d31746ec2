"""ik_batch and fk_batch: the same solutions as ik, pose by pose, without a loop over poses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from derive.verify import sample_joints
from conftest import BUNDLED


def same_rows(a: np.ndarray, b: np.ndarray, revolute: np.ndarray, tol: float) -> bool:
    if a.shape != b.shape:
        return False
    d = a - b
    d[:, revolute] = np.remainder(d[:, revolute] + math.pi, 2 * math.pi) - math.pi
    return bool(np.abs(d).max(initial=0.0) <= tol)


@pytest.mark.parametrize("name", BUNDLED)
def test_ik_batch_equals_ik_pose_by_pose(generated, name):
    m = generated(name)
    Q = sample_joints(m, 400, np.random.default_rng(31))
    T = m.fk_batch(Q)
    batch, valid = m.ik_batch(T, chunk=128)
    assert batch.shape == (400, valid.shape[1], m.DOF)
    revolute = np.array([k == "R" for k in m.JOINT_TYPES])
    for i in range(len(T)):
        # same set, same order; values agree to 1e-6 (at singular poses the scalar and the
        # vectorised arithmetic differ by ~1e-8)
        assert same_rows(m.ik(T[i]), batch[i][valid[i]], revolute, 1e-6), i


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


@pytest.mark.parametrize("coeffs, roots", [
    ((1.0, -4.0, 6.0, -4.0, 1.0), [1.0]),                       # (x - 1)^4: a cluster of four
    ((1.0, 0.0, -2.0, 0.0, 1.0), [-1.0, 1.0]),                  # (x^2 - 1)^2: two double roots
    ((1.0, -2.0, 2.0, -2.0, 1.0), [1.0]),                       # (x - 1)^2 (x^2 + 1)
    ((1.0, 0.0, 1.0, 0.0, 0.25), []),                           # (x^2 + 1/2)^2: no real root
])
def test_multiple_roots_are_found_by_scalar_and_vectorised_routines(generated, coeffs, roots):
    m = generated("puma560")
    scalar = m._poly_real(coeffs)
    assert len(scalar) == len(roots)
    assert np.allclose(scalar, roots, atol=1e-9)
    x, ok, free = m._vpoly(tuple(np.array([c]) for c in coeffs), 0, np.ones(1, bool), False)
    assert not free.any()
    assert np.allclose(np.sort(x[ok]), roots, atol=1e-9)
