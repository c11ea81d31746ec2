"""The general 6R method's first step: the 14 fundamental equations, derived in symbols, hold
for random arms at random joint values (the general method itself is issue 17's next step)."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from derive import raghavan_roth as rr


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
    # l_z, p_z, p.p, p.l, (p x l)_z, v_z do not involve theta3 (ALGORITHMS.md 4.2)
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


def test_the_reference_solve_finds_all_16_solutions_of_manocha_and_canny():
    """hard_cases.yaml's 16-real-solution arm (Manocha and Canny 1994, Table III), exact pose:
    16 certified solutions, each one of the published exact ones to 1e-6 deg."""
    rows = [(0.0, d, a, np.radians(alpha)) for a, alpha, d in MANOCHA_CANNY["standard_dh"]]
    T = np.vstack((np.array(MANOCHA_CANNY["T"]), [0.0, 0.0, 0.0, 1.0]))
    found = np.degrees(np.array(rr.solve_reference(rows, T)))
    assert found.shape == (16, 6)
    for expected in MANOCHA_CANNY["solutions"]:
        gap = np.abs((found - np.array(expected) + 180.0) % 360.0 - 180.0).max(axis=1)
        assert gap.min() <= 1e-6, expected


@pytest.mark.parametrize("seed", range(50))
def test_the_reference_solve_finds_the_joint_values_of_random_arms(seed):
    rng = np.random.default_rng(100 + seed)
    rows = list(zip([0.0] * 6, rng.uniform(-1, 1, 6), rng.uniform(-1, 1, 6), rng.uniform(-3, 3, 6)))
    theta = rng.uniform(-np.pi, np.pi, 6)
    T = np.linalg.multi_dot([standard_link(t, *r[1:]) for t, r in zip(theta, rows)])
    found = np.array(rr.solve_reference(rows, T))
    gap = np.abs((found - theta + np.pi) % (2 * np.pi) - np.pi).max(axis=1)
    assert gap.min() <= 1e-6


# the published case (id manocha_canny_1994_16_real of the project's hard_cases.yaml), copied
MANOCHA_CANNY = {
    "standard_dh": [  # a_i, alpha_i [deg], d_i
        [0.3, 90.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 90.0, 0.2],
        [1.5, 1.0, 0.0],
        [0.0, 90.0, 0.0],
        [0.0, 1.0, 0.0],
    ],
    "T": [
        [-0.760167736925, -0.641625873792, 0.102280251366, -1.14004797368],
        [0.133406575395, -7.07052578278e-05, 0.991061390955, -2.70345826006e-05],
        [-0.635883399202, 0.767017752781, 0.0856508583635, 0.00018235181416],
    ],
    "solutions": [  # exact.solutions, degrees
        [
            -178.116728776,
            108.216824904,
            -147.742673593,
            -5.68734865359,
            -164.66895011,
            179.568452421,
        ],
        [
            -178.116728776,
            108.216824904,
            32.2573264067,
            -174.312651346,
            -15.3310498899,
            -0.43154757878,
        ],
        [
            -120.801949611,
            172.314182501,
            -179.059098701,
            31.3205465246,
            -146.71555608,
            142.830297525,
        ],
        [
            -120.801949611,
            172.314182501,
            0.940901298608,
            148.679453475,
            -33.2844439204,
            -37.1697024754,
        ],
        [-96.28, -6.27, -0.04, 141.52, 127.45, 140.6],
        [-96.28, -6.27, 179.96, 38.48, 52.55, -39.4],
        [-12.9480266402, -105.096580088, -114.984317234, 3.02708039963, 7.419653441, -79.425177447],
        [-12.9480266402, -105.096580088, 65.0156827661, 176.9729196, 172.580346559, 100.574822553],
        [
            2.52381109702,
            108.063424835,
            -67.9496571909,
            -169.473275632,
            -179.999479315,
            179.88966717,
        ],
        [
            2.52381109702,
            108.063424835,
            112.050342809,
            -10.5267243675,
            -0.000520685313451,
            -0.110332830362,
        ],
        [
            88.6912679915,
            -176.729863659,
            -176.718584902,
            -63.2313501358,
            157.199437355,
            140.439978619,
        ],
        [
            88.6912679915,
            -176.729863659,
            3.28141509795,
            -116.768649864,
            22.8005626449,
            -39.5600213805,
        ],
        [
            113.840461788,
            5.32280090165,
            -177.754784522,
            -55.9188937407,
            -62.9880156485,
            -43.374715635,
        ],
        [
            113.840461788,
            5.32280090165,
            2.24521547793,
            -124.081106259,
            -117.011984351,
            136.625284365,
        ],
        [
            168.317514741,
            -103.8879949,
            -33.3885472678,
            -162.755750262,
            -8.11824513443,
            -81.8409470238,
        ],
        [168.317514741, -103.8879949, 146.611452732, -17.2442497384, -171.881754866, 98.1590529762],
    ],
}
