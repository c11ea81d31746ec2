"""The generated module's arguments: what is checked, and limits that span many turns."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

from conftest import build_module, needs_cc

UR5_ROWS = [
    (90.0, 0.0, 0.089159),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (90.0, 0.0, 0.10915),
    (-90.0, 0.0, 0.09465),
    (0.0, 0.0, 0.0823),
]


def spec_with_limits(name: str, rows: list[tuple[float, float, float]], limit: float) -> str:
    """Standard-DH revolute arm (degrees, metres) with limits +-limit on every joint."""
    out = f'name = "{name}"\nconvention = "standard"\nangle_unit = "deg"\nlength_unit = "m"\n'
    for alpha, a, d in rows:
        out += (
            f'[[joint]]\ntype = "R"\nalpha = {alpha!r}\na = {a!r}\nd = {d!r}\n'
            f"theta = 0.0\nlimits = [{-limit!r}, {limit!r}]\n"
        )
    return out


@pytest.fixture(scope="module")
def ur5(tmp_path_factory):
    return build_module(spec_with_limits("ur5", UR5_ROWS, 360.0), tmp_path_factory.mktemp("ur5"))


@pytest.fixture(scope="module")
def wide_2r(tmp_path_factory):
    rows = [(0.0, 1.0, 0.0), (0.0, 1.0, 0.0)]
    return build_module(spec_with_limits("wide_2r", rows, 1e7), tmp_path_factory.mktemp("w2r"))


def test_within_limits_gives_each_solution_once(ur5):
    q = np.radians([30.0, -60.0, 45.0, -20.0, 70.0, 10.0])
    T = ur5.fk(q)
    plain = ur5.ik(T)
    assert len(plain) == 8
    inside = ur5.ik(T, within_limits=True)
    assert inside.shape == plain.shape  # +-360 deg: every solution, once (was 512 rows)
    np.testing.assert_array_equal(inside, plain)  # q_ref = 0: the wrapped values
    ref = q + 2 * math.pi * np.array([-1, 0, -1, 0, 0, -1])
    near = ur5.ik(T, within_limits=True, q_ref=ref)
    assert np.abs(near - ref).max(axis=1).min() < 1e-9  # q's variant next to q_ref
    limit = math.radians(360.0)
    for shift in (-2 * math.pi, 2 * math.pi):  # no other variant inside is nearer q_ref
        other = near + shift
        assert ((np.abs(other) > limit) | (np.abs(other - ref) >= np.abs(near - ref))).all()
    assert ur5.ik(T, within_limits=True, all_turns=True).shape == (8 * 2**6, 6)


def test_nearest_takes_each_joint_nearest_variant(ur5):
    q = np.radians([30.0, -60.0, 45.0, -20.0, 70.0, 10.0])
    ref = q + 2 * math.pi * np.array([-1, 0, -1, 0, 0, -1]) + 0.01
    best = ur5.nearest(ur5.fk(q), ref)
    np.testing.assert_allclose(best, q + 2 * math.pi * np.array([-1, 0, -1, 0, 0, -1]), atol=1e-9)
    weights = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    assert ur5.nearest(ur5.fk(q), ref, weights=weights) is not None


def test_limits_of_many_turns_stay_cheap(wide_2r):
    """+-1e7 deg (27,778 turns per joint): the nearest variant is computed, not enumerated."""
    T = wide_2r.fk([0.3, 0.4])
    tracemalloc.start()
    inside = wide_2r.ik(T, within_limits=True)
    best = wide_2r.nearest(T, [1000.0, -1000.0])
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert inside.shape == (2, 2)
    assert peak < 1_000_000
    assert abs(best[0] - 1000.0) <= math.pi and abs(best[1] + 1000.0) <= math.pi
    with pytest.raises(ValueError, match="MAX_TURN_ROWS"):
        wide_2r.ik(T, within_limits=True, all_turns=True)


@pytest.mark.parametrize("tol", [-1e-6, 0.0, math.nan, math.inf, "x", True])
def test_tol_must_be_positive_and_finite(ur5, tol):
    T = ur5.fk(np.zeros(6))
    with pytest.raises(ValueError, match="tol must be a positive finite number"):
        ur5.ik(T, tol=tol)
    with pytest.raises(ValueError, match="tol must be a positive finite number"):
        ur5.ik_batch(T[None], tol=tol)


@pytest.mark.parametrize("chunk", [-5, 0, 2.5, "10", True])
def test_chunk_must_be_a_positive_integer(ur5, chunk):
    with pytest.raises(ValueError, match="chunk must be a positive integer"):
        ur5.ik_batch(ur5.fk(np.zeros(6))[None], chunk=chunk)


def test_numpy_integer_chunk_is_fine(ur5):
    _, valid = ur5.ik_batch(ur5.fk(np.zeros(6))[None], chunk=np.int64(3))
    assert valid.sum() >= 1


@pytest.mark.parametrize(
    "weights", [[1.0] * 5, [1.0] * 5 + [math.nan], [1.0] * 5 + [-1.0], [1j] * 6]
)
def test_weights_must_be_finite_and_non_negative(ur5, weights):
    with pytest.raises(ValueError, match=r"weights must be 6 finite non-negative numbers|real"):
        ur5.nearest(ur5.fk(np.zeros(6)), np.zeros(6), weights=weights)


def test_complex_input_is_refused(ur5):
    T = ur5.fk(np.zeros(6)).astype(complex)
    T[0, 3] += 1e-3j
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik(T)
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik_batch(T[None])
    with pytest.raises(ValueError, match="real numbers"):
        ur5.fk(np.zeros(6, dtype=complex))
    with pytest.raises(ValueError, match="q_ref must be 6 finite real numbers"):
        ur5.ik(ur5.fk(np.zeros(6)), q_ref=np.zeros(6, dtype=complex))


@pytest.mark.parametrize(
    "q_ref", [np.zeros((1, 6)), np.zeros(5), [0.0] * 5 + [math.inf], "abcdef", [[0.0] * 6]]
)
def test_q_ref_shape_and_values_are_checked(ur5, q_ref):
    T = ur5.fk(np.zeros(6))
    with pytest.raises(ValueError, match=r"q_ref must be 6 finite real numbers"):
        ur5.ik(T, q_ref=q_ref)
    with pytest.raises(ValueError, match=r"q_ref must be 6 finite real numbers"):
        ur5.nearest(T, q_ref)


@needs_cc
def test_compiled_limits_and_nearest_match_python(ur5):
    """within_limits and nearest run in C when it is there: the same rows and picks."""
    rng = np.random.default_rng(5)
    for q in rng.uniform(-2 * math.pi, 2 * math.pi, (50, 6)):
        T = ur5.fk(q)
        ref = q + rng.normal(0.0, 0.01, 6)
        rows = {b: ur5.ik(T, within_limits=True, q_ref=ref, backend=b) for b in ("python", "c")}
        assert rows["python"].shape == rows["c"].shape
        assert np.abs(rows["python"] - rows["c"]).max(initial=0.0) < 1e-9
        ur5.BACKEND = "c"
        try:
            compiled = ur5.nearest(T, ref)
            wrapped = ur5.nearest(T, ref, within_limits=False)
        finally:
            ur5.BACKEND = "python"
        np.testing.assert_allclose(compiled, ur5.nearest(T, ref), atol=1e-9)
        np.testing.assert_allclose(wrapped, ur5.nearest(T, ref, within_limits=False), atol=1e-9)
        np.testing.assert_allclose(compiled, q, atol=1e-6)  # q itself is inside +-360 deg


# issue 37 item 17: strings, booleans and nested free values are not numbers
@pytest.mark.parametrize(
    "T", [np.full((4, 4), "1.0"), np.eye(4, dtype=bool), np.array([[None] * 4] * 4)]
)
def test_strings_and_booleans_are_not_poses(ur5, T):
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik(T)
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik_batch(T[None])
    with pytest.raises(ValueError, match="real numbers"):
        ur5.fk(T[0, :4].tolist() + T[1, :2].tolist())


def test_a_boolean_among_numbers_is_not_a_number(ur5):
    """numpy reads [True, 0.5] as floats; ik, ik_batch and fk (and a position arm's
    ik_position, through the same _real) took True as 1.0 (a new user's attack). A list or
    tuple holding a boolean at any depth is refused."""
    T = ur5.fk(np.full(6, 0.3)).tolist()
    T[0][3] = True
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik(T)
    with pytest.raises(ValueError, match="real numbers"):
        ur5.ik_batch([T])
    with pytest.raises(ValueError, match="real numbers"):
        ur5.fk((0.1, np.True_, 0.2, 0.3, 0.4, 0.5))
    T[0][3] = 1  # (ints are numbers)
    assert ur5.ik(T).shape[1] == 6


@pytest.mark.parametrize("free", ["0.5", [True], [[0.5]], np.array([[0.5]])])
def test_free_values_must_be_numbers_one_per_free_joint(generated, free):
    m = generated("iiwa14")
    T = m.fk(np.zeros(7))
    with pytest.raises(ValueError, match=r"free must be (1 finite|an array of real numbers)"):
        m.ik(T, free=free, backend="python")


# issue 37 item 4: poses far out of reach are answered with no row, without warnings
FAR = [1e155, 1e200, 1.7e308]


@pytest.mark.parametrize("name", ["parallel_6r", "manocha_canny", "puma560", "iiwa14"])
def test_poses_far_out_of_reach_give_no_solution(generated, name, recwarn):
    m = generated(name)
    T = np.tile(np.eye(4), (len(FAR) + 1, 1, 1))
    T[:-1, 0, 3] = FAR
    T[-1] = m.fk(np.full(m.DOF, 0.3))
    q = np.zeros(m.DOF)
    for pose in T[:-1]:
        assert m.ik(pose, backend="python").shape == (0, m.DOF)
        assert m.nearest(pose, q) is None
    _, valid = m.ik_batch(T, backend="python")
    assert not valid[:-1].any() and valid[-1].any()
    assert [str(w.message) for w in recwarn] == []


def test_fk_refuses_what_ik_refuses(ur5):
    """fk([nan] * 6) gave a NaN matrix and ik(T, tol="1e-6") took a string."""
    for q in ([math.nan] * 6, [math.inf] + [0.0] * 5):
        with pytest.raises(ValueError, match="finite"):
            ur5.fk(q)
        with pytest.raises(ValueError, match="finite"):
            ur5.fk_batch([q])
    with pytest.raises(ValueError, match="tol must be a positive finite number"):
        ur5.ik(ur5.fk(np.zeros(6)), tol="1e-6")
