"""Velocities (issue 41): the geometric Jacobian each module derives (derive/jacobian.py)
against central differences of its own fk, in Python and in C, in the world and the tool
frame, and the manipulability measures."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from conftest import BUNDLED


def differences(module, q: np.ndarray, step: float = 1e-6) -> np.ndarray:
    """(6, DOF): central differences of fk at q: the tool point's d p / d q_i over the axis of
    d R / d q_i R^T (the angular velocity's)."""
    R = module.fk(q)[:3, :3]
    out = np.zeros((6, module.DOF))
    for i in range(module.DOF):
        dq = np.zeros(module.DOF)
        dq[i] = step
        A, B = module.fk(q + dq), module.fk(q - dq)
        out[:3, i] = (A[:3, 3] - B[:3, 3]) / (2 * step)
        W = (A[:3, :3] - B[:3, :3]) / (2 * step) @ R.T
        out[3:, i] = (W[2, 1], W[0, 2], W[1, 0])
    return out


@pytest.mark.parametrize("name", BUNDLED)
def test_the_jacobian_is_fk_s_derivative_in_python_and_in_c(generated, name):
    """Every bundled arm (calibrated, task and redundant arms among them), 20 random joint
    vectors: the Python jacobian within 1e-7 (relative to its largest entry) of fk's central
    differences; the tool frame's is the world's rotated by R^T; the C function's equals the
    Python one's to 1e-12."""
    module = generated(name)
    lib, why = module._c_library()
    assert lib is not None, why
    call = lib[f"{name}_jacobian"]
    double_p = ctypes.POINTER(ctypes.c_double)
    rng = np.random.default_rng(41)
    for q in rng.uniform(-np.pi, np.pi, (20, module.DOF)):
        J = module.jacobian(q)
        assert J.shape == (6, module.DOF)
        scale = max(1.0, float(np.abs(J).max()))
        assert np.abs(J - differences(module, q)).max() <= 1e-7 * scale
        R = module.fk(q)[:3, :3]
        tool = module.jacobian(q, frame="tool")
        assert np.allclose(tool, np.vstack([R.T @ J[:3], R.T @ J[3:]]), atol=1e-13)
        values = np.ascontiguousarray(q)
        for frame, expected in ((0, J), (1, tool)):
            out = np.zeros((6, module.DOF))
            call(values.ctypes.data_as(double_p), frame, out.ctypes.data_as(double_p))
            assert np.abs(out - expected).max() <= 1e-12 * scale


def test_manipulability_is_zero_where_the_wrist_is_singular(generated):
    """The PUMA's smallest singular value and Yoshikawa's measure: numpy's SVD of the
    Jacobian at a regular configuration; both 0 (to rounding) with theta5 = 0 (axes 4 and 6
    in line)."""
    module = generated("puma560")
    q = np.radians([20.0, -30.0, 40.0, 50.0, 60.0, 70.0])
    sigma = np.linalg.svd(module.jacobian(q), compute_uv=False)
    least, w = module.manipulability(q)
    assert least == pytest.approx(sigma[-1], rel=1e-12) and w == pytest.approx(np.prod(sigma))
    assert least > 1e-2 and w > 1e-4
    q[4] = 0.0
    least, w = module.manipulability(q)
    assert least < 1e-12 and w < 1e-12
    five = generated("youbot")  # (fewer than 6 joints: the product of its 5 singular values)
    sigma = np.linalg.svd(five.jacobian(np.full(5, 0.3)), compute_uv=False)
    assert five.manipulability(np.full(5, 0.3))[1] == pytest.approx(np.prod(sigma))


@pytest.mark.parametrize(
    ("q", "frame", "message"),
    [
        ([0.0] * 5, "base", r"q must have shape \(6,\)"),
        ([0.0] * 5 + [float("nan")], "base", "q must be 6 finite numbers"),
        ([0.0] * 6, "world", 'frame must be "base" or "tool"'),
    ],
)
def test_bad_jacobian_arguments_are_refused(generated, q, frame, message):
    with pytest.raises(ValueError, match=message):
        generated("puma560").jacobian(q, frame=frame)


def test_velocity_ik_reproduces_the_twist_and_bounds_the_rates_near_singularities(generated):
    """ik_velocity on the PUMA: at the regular ones of 200 random configurations (smallest
    singular value at least the damping band), J dq within 1e-9 of the twist; at the wrist
    singularity (theta5 = 1e-9), every joint rate within |twist| / (2 damping), where the
    undamped least-squares inverse's exceed 1e6."""
    module = generated("puma560")
    rng = np.random.default_rng(42)
    tested = 0
    for q in rng.uniform(-np.pi, np.pi, (200, 6)):
        if module.manipulability(q)[0] < module.VELOCITY_BAND:
            continue
        twist = rng.normal(size=6)
        dq = module.ik_velocity(q, twist)
        assert np.abs(module.jacobian(q) @ dq - twist).max() <= 1e-9
        tested += 1
    assert tested >= 100  # (116 of the 200 are regular by this band)
    twist = np.array([0.1, -0.2, 0.05, 0.3, 0.1, -0.2])
    bound = np.linalg.norm(twist) / (2 * module.VELOCITY_DAMPING)
    q = np.radians([20.0, 30.0, -40.0, 50.0, 0.0, 70.0])
    q[4] = 1e-9
    assert np.abs(module.ik_velocity(q, twist)).max() <= bound
    undamped = np.linalg.solve(module.jacobian(q), twist)
    assert np.abs(undamped).max() > 1e6


def test_velocity_ik_moves_free_joints_without_moving_the_tool(generated):
    """The iiwa14's self-motion: with a zero twist and a preferred configuration the joints
    drift toward it while the tool's twist stays 0 (1e-12); with a twist, J dq is the twist."""
    module = generated("iiwa14")
    rng = np.random.default_rng(43)
    for q in rng.uniform(-2.0, 2.0, (50, 7)):
        if module.manipulability(q)[0] < module.VELOCITY_BAND:
            continue
        preferred = np.zeros(7)
        dq = module.ik_velocity(q, np.zeros(6), preferred=preferred, gain=0.5)
        assert np.abs(module.jacobian(q) @ dq).max() <= 1e-12
        assert dq @ (preferred - q) > 0.0
        twist = rng.normal(size=6)
        dq = module.ik_velocity(q, twist, preferred=preferred)
        assert np.abs(module.jacobian(q) @ dq - twist).max() <= 1e-9
