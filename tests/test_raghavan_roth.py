"""The general 6R method's first step: the 14 fundamental equations, derived in symbols, hold
for random arms at random joint values, and the run-time steps find the joint values."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from derive import raghavan_roth as rr
from derive.methods.general import split_link
from derive.runtime import general


def standard_link(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0, sa, ca, d],
            [0, 0, 0, 1],
        ]
    )


@pytest.fixture(scope="module")
def matrices():
    f = rr.fundamental()
    args = (*rr.c[:5], *rr.s[:5], *rr.a[:5], *rr.d[:5], *rr.lam[:5], *rr.mu[:5], *rr.L, *rr.P)
    return [sp.lambdify(args, m, "numpy") for m in (f.P0, f.Ps, f.Pc, f.Q)], f


def test_the_shape_the_literature_gives(matrices):
    _, f = matrices
    assert (f.P0.shape, f.Ps.shape, f.Pc.shape, f.Q.shape) == ((14, 9), (14, 9), (14, 9), (14, 8))
    # l_z, p_z, p.p, p.l, (p x l)_z, v_z do not involve theta3 (docs/algorithms.md, "The
    # split and the 14 fundamental equations")
    free_of_theta3 = [i for i in range(14) if not any(f.Ps.row(i)) and not any(f.Pc.row(i))]
    assert free_of_theta3 == [2, 5, 6, 7, 10, 13]
    operations = sum(e.count_ops() for m in (f.P0, f.Ps, f.Pc, f.Q) for e in m)
    assert 4000 < operations < 6000  # "about 4 800 operations"


@pytest.mark.parametrize("seed", range(20))
def test_the_fourteen_equations_hold_at_random_arms_and_joint_values(matrices, seed):
    functions, _ = matrices
    rng = np.random.default_rng(seed)
    theta = rng.uniform(-np.pi, np.pi, 6)
    d = rng.uniform(-1, 1, 6)
    a = rng.uniform(-1, 1, 6)
    alpha = rng.uniform(-np.pi, np.pi, 6)
    if seed % 4 == 0:  # right angles and zeros, as real arms have them
        alpha = np.round(alpha / (np.pi / 2)) * (np.pi / 2)
        a[rng.random(6) < 0.5] = 0.0
    links = [standard_link(*row) for row in zip(theta, d, a, alpha)]
    T = np.linalg.multi_dot(links)
    M = T @ np.linalg.inv(links[5])
    args = (
        *np.cos(theta[:5]), *np.sin(theta[:5]), *a[:5], *d[:5], *np.cos(alpha[:5]),
        *np.sin(alpha[:5]), *M[:3, 2], *M[:3, 3],
    )  # fmt: skip
    P0, Ps, Pc, Q = (np.array(f(*args), dtype=float) for f in functions)
    c, s = np.cos(theta), np.sin(theta)
    m45 = np.array([s[3] * s[4], s[3] * c[4], c[3] * s[4], c[3] * c[4], s[3], c[3], s[4], c[4], 1])
    m12 = np.array([s[0] * s[1], s[0] * c[1], c[0] * s[1], c[0] * c[1], s[0], c[0], s[1], c[1]])
    residual = (P0 + Ps * s[2] + Pc * c[2]) @ m45 - Q @ m12
    assert np.abs(residual).max() <= 1e-12 * (1 + np.abs(Q @ m12).max())


@pytest.mark.parametrize("seed", range(30))
def test_the_run_time_steps_find_the_joint_values_of_random_arms(seed):
    """derive/runtime/general.py's steps on the generic matrices: the generating joint
    values are among the candidates (flange-frame rows: d1 = 0, A6 = Rz(theta6))."""
    rng = np.random.default_rng(100 + seed)
    d, a, alpha = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6)
    d[0] = d[5] = a[5] = alpha[5] = 0.0
    rows = [(d[i], a[i], np.cos(alpha[i]), np.sin(alpha[i])) for i in range(6)]
    theta = rng.uniform(-np.pi, np.pi, 6)
    F = np.linalg.multi_dot([split_link(t, r) for t, r in zip(theta, rows)])
    args = (*a[:5], *d[:5], *np.cos(alpha[:5]), *np.sin(alpha[:5]), *F[:3, 2], *F[:3, 3])
    f = rr.fundamental()
    P0, Ps, Pc, Q = (
        np.array(sp.lambdify(rr.GENS, m)(*args), dtype=float) for m in (f.P0, f.Ps, f.Pc, f.Q)
    )
    candidates, _, _, _ = general._rr_candidates(P0, Ps, Pc, Q, F, rows)
    gap = [np.abs((c - theta + np.pi) % (2 * np.pi) - np.pi).max() for c in candidates]
    assert min(gap) <= 1e-6


def test_the_stored_derivation_is_the_one_derived_today():
    """derive/data/fundamental.json (read at generation) equals a fresh derivation; rewrite
    it with `python -m derive.raghavan_roth` when the derivation changes."""
    assert rr.to_terms(rr.derive_fundamental()) == rr.to_terms(rr.fundamental())


@pytest.mark.parametrize("seed", range(12))
def test_the_deflated_eigenvalues_are_the_full_problems_less_the_known_ones(seed):
    """Split.spurious (derive.methods.general.spurious_vectors) of random arms (every other
    one with two right-angle twists and a zero length): at random poses the pencil at y+ (the
    image of x3 = i) annihilates them, the full companion matrix has 2r eigenvalues at y+ and
    its conjugate, and the deflated one (_rr_deflated) has exactly the others. (Arms whose own
    pencil is singular, solved on a perturbed table, have a nearly singular one, whose
    eigenvalues move with rounding in either computation: their test is their solutions',
    tests/test_general.py.)"""
    from derive.methods.general import spurious_vectors

    f = rr.fundamental()
    functions = [sp.lambdify(rr.GENS, m) for m in (f.P0, f.Ps, f.Pc, f.Q)]
    rng = np.random.default_rng(300 + seed)
    d, a, alpha = rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6)
    if seed % 2:  # two right-angle twists and a zero length, as real arms have them
        alpha[[1, 3]] = np.round(alpha[[1, 3]] / (np.pi / 2)) * (np.pi / 2)
        a[2] = 0.0
    d[0] = d[5] = a[5] = alpha[5] = 0.0
    rows = [(d[i], a[i], np.cos(alpha[i]), np.sin(alpha[i])) for i in range(6)]
    numbers = tuple(r[k] for k in (1, 0, 2, 3) for r in rows[:5])
    # (Ps and Pc do not depend on the pose: any pose gives the arm's)
    fill = [functions[k](*numbers, 0.0, 0.0, 1.0, 0.1, 0.2, 0.3) for k in range(4)]
    vectors, pivots = spurious_vectors(tuple(float(x) for m in fill for x in np.ravel(m)))
    assert vectors, "every arm has them"
    V = np.array(vectors)
    assert V.shape == (12, 2 * len(pivots))
    known = V.shape[1]
    v = V[:, 0::2] + 1j * V[:, 1::2]
    checked = 0
    for _ in range(5):
        theta = rng.uniform(-np.pi, np.pi, 6)
        F = np.linalg.multi_dot([split_link(t, r) for t, r in zip(theta, rows)])
        P0, Ps, Pc, Q = (
            np.array(fn(*numbers, *F[:3, 2], *F[:3, 3]), dtype=float) for fn in functions
        )
        full = general._rr_eigenvalues(P0, Ps, Pc, Q)
        deflated = general._rr_eigenvalues(P0, Ps, Pc, Q, (V, np.array(pivots)))
        if full is None:
            assert deflated is None
            continue
        values, (A, B, C), (ma, mb, mc, md) = full
        y = complex(-mb, md) / complex(ma, -mc)
        scale = max(np.abs(A).max(), np.abs(B).max(), np.abs(C).max())
        assert np.abs((A * y * y + B * y + C) @ v).max() <= 1e-10 * scale
        near = np.minimum(abs(values - y), abs(values - y.conjugate())) <= 1e-6
        assert near.sum() == known
        rest = list(values[~near])
        got = deflated[0]
        assert len(got) == len(rest) == 24 - known
        # each deflated eigenvalue is one of the others (nearest first; a multiple root's
        # copies split by the square root of rounding in either computation)
        for z in sorted(got, key=lambda z: min(abs(z - w) for w in rest)):
            k = int(np.argmin([abs(z - w) for w in rest]))
            assert abs(z - rest.pop(k)) <= 1e-6 * (1 + abs(z)), (z, values)
        checked += 1
    assert checked, "some pose had a usable pencil"
