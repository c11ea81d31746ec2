"""Arms of more than 6 joints (issue 18): free joints, ik(T, free=...), ik_batch with a free
value per pose, ik_sweep, the searching nearest, the spec's [ik] free, refusals."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from derive.cli import main
from derive.pipeline import build_plan
from derive.spec import SpecError, parse_spec
from derive.verify import roundtrip, sample_joints

from conftest import build_module, needs_cc, spec_text
from strategies import LENGTH, OFFSETS, SCALE, rows_for, scaled

REDUNDANT = ("iiwa14", "panda")
SIGN = st.sampled_from([90.0, -90.0])


def within_limits(m, n: int, rng: np.random.Generator) -> np.ndarray:
    """n joint vectors inside the arm's limits (a margin of 1e-3)."""
    lo = np.array([lo for lo, _ in m.LIMITS]) + 1e-3
    hi = np.array([hi for _, hi in m.LIMITS]) - 1e-3
    return rng.uniform(lo, hi, (n, m.DOF))


def wrapped_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.abs((a - b + math.pi) % (2 * math.pi) - math.pi)


@pytest.mark.parametrize("name", REDUNDANT)
def test_bundled_arms_free_the_last_joint(generated, name):
    m = generated(name)
    assert m.DOF == 7 and m.FREE == (7,) and m.METHOD == "pieper" and m.MAX_SOLUTIONS == 8
    assert "Free joints: q7" in m.__doc__


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
@pytest.mark.parametrize("name", REDUNDANT)
def test_bundled_round_trips(generated, name, backend):
    m = generated(name)
    result = roundtrip(m, sample_joints(m, 300, np.random.default_rng(18)), backend)
    assert result.unsound == [], result.summary()
    assert result.misses == [], result.summary()
    assert result.singular_posed == result.singular, result.summary()


def test_panda_with_q7_given_has_up_to_eight_solutions(generated):
    """Franka's own analytic solver returns at most 4; with q7 given a pose has up to 8."""
    m = generated("panda")
    Q = within_limits(m, 200, np.random.default_rng(7))
    counts = [len(m.ik(m.fk(q), free=q[6], backend="python")) for q in Q]
    assert max(counts) == 8
    assert np.mean(counts) > 5.0  # measured 6.4-6.8 on random poses; EAIK measured 6.4
    for q in Q[:20]:
        for row in m.ik(m.fk(q), free=q[6], backend="python"):
            assert row[6] == q[6]
            assert np.abs(m.fk(row) - m.fk(q)).max() <= 1e-9


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
@pytest.mark.parametrize("name", REDUNDANT)
def test_ik_batch_takes_a_free_value_per_pose(generated, name, backend):
    m = generated(name)
    Q = sample_joints(m, 64, np.random.default_rng(3))
    T = m.fk_batch(Q)
    S, valid = m.ik_batch(T, free=Q[:, 6], backend=backend)
    for i in range(len(Q)):
        rows = S[i][valid[i]]
        single = m.ik(T[i], free=Q[i, 6], backend="python")
        assert rows.shape == single.shape
        assert np.abs(wrapped_gap(rows, single)).max(initial=0.0) <= 1e-9
        assert (rows[:, 6] == Q[i, 6]).all()


def test_free_values_are_checked(generated):
    m, puma = generated("iiwa14"), generated("puma560")
    T = m.fk(np.zeros(7))
    with pytest.raises(ValueError, match="free must be 1 finite"):
        m.ik(T, free=[0.1, 0.2])
    with pytest.raises(ValueError, match="free must be 1 finite"):
        m.ik(T, free=math.nan)
    with pytest.raises(ValueError, match=r"shape \(2, 1\)"):
        m.ik_batch(np.stack([T, T]), free=[0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match="no free joints"):
        puma.ik(puma.fk(np.zeros(6)), free=0.1)
    assert not hasattr(puma, "ik_sweep")


@pytest.mark.parametrize("name", REDUNDANT)
def test_ik_sweep_gives_certified_rows_for_every_sample(generated, name):
    m = generated(name)
    q = within_limits(m, 1, np.random.default_rng(11))[0]
    T = m.fk(q)
    values, rows = m.ik_sweep(T, n=64, backend="python")
    lo, hi = m.LIMITS[6]
    samples = np.linspace(lo, hi, 64)
    assert len(rows) == len(values) > 0
    assert np.isin(values[:, 0], samples).all()
    assert (rows[:, 6] == values[:, 0]).all()
    for row in rows:
        assert np.abs(m.fk(row) - T).max() <= 1e-9
        assert all(a - 1e-9 <= v <= b + 1e-9 for v, (a, b) in zip(row, m.LIMITS))
    values, rows = m.ik_sweep(T, step=0.05, backend="python")
    k = (values[:, 0] - lo) / 0.05
    assert len(rows) > 0 and np.abs(k - np.rint(k)).max() <= 1e-9
    with pytest.raises(ValueError, match="not both"):
        m.ik_sweep(T, n=4, step=0.1)


@pytest.mark.parametrize("metric", ["l2", "max"])
@pytest.mark.parametrize("name", REDUNDANT)
def test_nearest_returns_q_for_regular_q(generated, name, metric):
    m = generated(name)
    for q in within_limits(m, 30, np.random.default_rng(5)):
        found = m.nearest(m.fk(q), q, metric=metric)
        assert found is not None
        assert np.abs(found - q).max() <= 1e-9


@pytest.mark.parametrize("name", REDUNDANT)
def test_nearest_searches_the_free_joint(generated, name):
    """From a reference whose q7 is off by 0.3 rad, the search finds a solution at least as
    close as the one with the reference's own q7 (q itself is 0.3 away in q7 alone)."""
    m = generated(name)
    for q in within_limits(m, 10, np.random.default_rng(8)):
        ref = q.copy()
        ref[6] = q[6] + 0.3 if q[6] + 0.3 < m.LIMITS[6][1] else q[6] - 0.3
        T = m.fk(q)
        found = m.nearest(T, ref)
        assert found is not None and np.abs(m.fk(found) - T).max() <= 1e-9
        at_ref = m.ik(T, free=ref[6], within_limits=True, q_ref=ref)
        best_fixed = min((((r - ref) ** 2).sum() for r in at_ref), default=math.inf)
        assert ((found - ref) ** 2).sum() <= min(best_fixed, ((q - ref) ** 2).sum()) + 1e-12


# the largest joint step along the straight-line path below (200 points, 0.17 m in all):
# measured 0.0032 rad (iiwa14) and 0.0065 rad (panda), with q7 kept at its start value; the
# path stays away from singularities and limits
PATH_JUMP = 0.02


@pytest.mark.parametrize("name", REDUNDANT)
def test_nearest_along_a_straight_line_gives_a_smooth_joint_path(generated, name):
    m = generated(name)
    q = np.radians([10.0, 30.0, -10.0, -70.0, 15.0, 60.0, 20.0])
    if name == "panda":
        q = np.radians([0.0, -30.0, 0.0, -120.0, 0.0, 100.0, 45.0])
    start = m.fk(q)
    path = []
    for t in np.linspace(0.0, 1.0, 200):
        T = start.copy()
        T[:3, 3] += t * np.array([0.1, -0.1, -0.1])
        q = m.nearest(T, q)
        assert q is not None
        assert np.abs(m.fk(q) - T).max() <= 1e-9
        path.append(q)
    jumps = np.abs(np.diff(np.array(path), axis=0)).max()
    assert jumps <= PATH_JUMP, jumps


def srs_arm(draw) -> str:
    """S-R-S: standard DH, every a = 0, d2 = d4 = d6 = 0, twists +-90 (axes 1-3, 3-5, 5-7
    meet)."""
    alpha = [0.0] + [draw(SIGN) for _ in range(6)] + [0.0]
    d = [None, draw(LENGTH), 0.0, draw(LENGTH), 0.0, draw(LENGTH), 0.0, draw(LENGTH)]
    theta = [None] + [draw(OFFSETS) for _ in range(7)]
    a = [0.0] * 8
    return "standard", alpha, a, d, theta


def panda_like_arm(draw) -> str:
    """Panda-like: modified DH, axes 1-3 meet, an offset elbow (a3, a4) and an offset flange."""
    alpha = [0.0] + [draw(SIGN) for _ in range(6)] + [0.0]
    a = [0.0, 0.0, 0.0, draw(LENGTH), draw(LENGTH), 0.0, draw(LENGTH), 0.0]
    d = [None, draw(LENGTH), 0.0, draw(LENGTH), 0.0, draw(LENGTH), 0.0, draw(LENGTH)]
    theta = [None] + [draw(OFFSETS) for _ in range(7)]
    return "modified", alpha, a, d, theta


def gen3_like_arm(draw) -> str:
    """Gen3-like: standard DH, every a = 0, offsets d1..d5 and d7, wrist 5-6-7 spherical."""
    alpha = [0.0] + [draw(SIGN) for _ in range(6)] + [draw(st.sampled_from([0.0, 180.0]))]
    d = [None] + [draw(LENGTH) for _ in range(5)] + [0.0, draw(LENGTH)]
    theta = [None] + [draw(OFFSETS) for _ in range(7)]
    return "standard", alpha, [0.0] * 8, d, theta


@st.composite
def redundant_arms(draw) -> tuple[str, str]:
    family = draw(st.sampled_from(["srs", "panda", "gen3"]))
    convention, alpha, a, d, theta = {
        "srs": srs_arm,
        "panda": panda_like_arm,
        "gen3": gen3_like_arm,
    }[family](draw)
    scale = draw(SCALE)
    rows = rows_for(convention, alpha, scaled(a, scale), scaled(d, scale), theta)
    return family, spec_text("arm7", convention, rows)


@settings(max_examples=15, deadline=None, suppress_health_check=list(HealthCheck))
@given(arm=redundant_arms())
def test_random_redundant_arms(arm, tmp_path_factory):
    family, text = arm
    plan = build_plan(parse_spec(text, "<hypothesis>"))
    assert plan.ik is not None, (plan.refusal, text)
    assert plan.ik.method == "pieper", text
    assert plan.ik.free == ((1,) if family == "gen3" else (7,)), text
    m = build_module(text, tmp_path_factory.mktemp("arm7"))
    rng = np.random.default_rng(zlib.crc32(text.encode()))
    result = roundtrip(m, sample_joints(m, 30, rng), "python")
    assert result.unsound == [], (result.summary(), text)
    assert result.misses == [], (result.summary(), text)
    assert result.singular_posed == result.singular, (result.summary(), text)


SRS = spec_text(
    "srs",
    "standard",
    [
        (-90, 0, 0.36, 0),
        (90, 0, 0, 0),
        (90, 0, 0.42, 0),
        (-90, 0, 0, 0),
        (-90, 0, 0.4, 0),
        (90, 0, 0, 0),
        (0, 0, 0.126, 0),
    ],
)


def test_the_spec_names_the_free_joint(tmp_path):
    plan = build_plan(parse_spec(SRS + "[ik]\nfree = [1]\n"))
    assert plan.ik is not None and plan.ik.free == (1,) and plan.ik.method == "pieper"
    m = build_module(SRS + "[ik]\nfree = [1]\n", tmp_path)
    result = roundtrip(m, sample_joints(m, 50, np.random.default_rng(1)), "python")
    assert result.unsound == [] and result.misses == [], result.summary()


@pytest.mark.parametrize(
    ("free", "message"),
    [
        ("[4]", "free q4: with these joints fixed the other joints move the tool in 5 directions"),
        ("[3]", "free joint 3 is a middle joint"),
    ],
)
def test_a_middle_joint_is_refused_with_the_reason(free, message):
    plan = build_plan(parse_spec(SRS + f"[ik]\nfree = {free}\n"))
    assert plan.ik is None and message in plan.refusal


@pytest.mark.parametrize(
    ("table", "message"),
    [
        ("[ik]\nfree = [8]\n", "ik.free: [8] is not allowed; allowed: a list of 1 distinct"),
        ("[ik]\nfree = [1, 7]\n", "ik.free: [1, 7] is not allowed"),
        ("[ik]\nfree = 7\n", "ik.free: 7 is not allowed"),
        ('[ik]\nfree = ["7"]\n', "ik.free: ['7'] is not allowed"),
        ('[ik]\nfree = "7"\n', "ik.free: '7' is not allowed"),  # (a string, shown as one)
        ("[ik]\nlock = [7]\n", "ik.lock: unknown key; allowed keys: free"),
    ],
)
def test_bad_ik_tables_are_clear_errors(table, message):
    with pytest.raises(SpecError, match=message.replace("[", r"\[").replace("]", r"\]")):
        parse_spec(SRS + table, "arm.toml")
    with pytest.raises(SpecError, match=r"arm\.toml: ik: must be a table"):
        parse_spec("ik = 3\n" + SRS, "arm.toml")


def test_a_six_joint_arm_has_no_free_joints():
    text = spec_text("six_joints", "standard", [(90, 0, 0, 0)] * 6)
    with pytest.raises(SpecError, match=r"ik\.free: the arm has 6 joints"):
        parse_spec(text + "[ik]\nfree = [6]\n", "arm.toml")


def test_a_redundant_arm_without_a_closed_form_uses_the_general_method(tmp_path):
    """Rethink Sawyer (docs/algorithms.md, "Free joints of 7-joint arms"): every lock leaves a
    general 6R."""
    rows = [(-90, 81, 317, 0), (-90, 0, 192.5, 0), (-90, 0, 400, 0), (-90, 0, 168.5, 0)]
    rows += [(-90, 0, 400, 0), (-90, 0, 136.3, 0), (0, 0, 133.75, 0)]
    text = spec_text("sawyer", "standard", rows)
    m = build_module(text, tmp_path)
    assert m.METHOD == "general" and m.FREE == (7,)
    result = roundtrip(m, sample_joints(m, 20, np.random.default_rng(2)), "python")
    assert result.unsound == [] and result.misses == [], result.summary()


def test_solve_takes_the_free_values(capsys):
    assert main(["solve", "panda", "--q", "0", "-45", "0", "-135", "0", "90", "45"]) == 0
    out = capsys.readouterr().out
    assert "free joints: q7 = 45" in out and "8 solution(s)" in out
    assert (
        main(["solve", "panda", "--q", "0", "-45", "0", "-135", "0", "90", "45", "--free", "30"])
        == 0
    )
    out = capsys.readouterr().out
    assert "free joints: q7 = 30" in out
    assert "    30.0000  residual" in out
    assert main(["solve", "puma560", "--q", "0", "0", "0", "0", "0", "0", "--free", "3"]) == 2
    assert "--free: puma560 has no free joints" in capsys.readouterr().err


def newton_solutions(m, T: np.ndarray, q7: float, starts: int, rng) -> list[np.ndarray]:
    """Solutions of fk(q) = T with q7 fixed, by damped Newton steps on joints 1-6 from random
    starts (an independent check of completeness: no closed form involved)."""
    found: list[np.ndarray] = []
    h = 1e-7
    for _ in range(starts):
        q = np.append(rng.uniform(-math.pi, math.pi, 6), q7)
        for _ in range(60):
            e = (m.fk(q) - T)[:3].ravel()
            if np.abs(e).max() < 1e-12:
                break
            J = np.empty((12, 6))
            for j in range(6):
                dq = np.zeros(7)
                dq[j] = h
                J[:, j] = ((m.fk(q + dq) - m.fk(q - dq))[:3].ravel()) / (2 * h)
            step = np.linalg.lstsq(J, -e, rcond=None)[0]
            q[:6] += step * min(1.0, 0.5 / max(np.abs(step).max(), 1e-300))
        if np.abs(m.fk(q) - T).max() < 1e-10 and not any(
            wrapped_gap(q, p).max() < 1e-6 for p in found
        ):
            found.append(q.copy())
    return found


def test_panda_solutions_are_all_that_newton_finds(generated):
    """Multistart Newton (200 starts per pose, q7 fixed) finds no solution ik misses; on
    these poses it finds them all (4, 8, 8 and 8)."""
    m = generated("panda")
    rng = np.random.default_rng(12)
    for q in within_limits(m, 4, rng):
        T = m.fk(q)
        rows = m.ik(T, free=q[6], backend="python")
        newton = newton_solutions(m, T, q[6], 200, rng)
        for p in newton:
            assert any(wrapped_gap(p, r).max() < 1e-6 for r in rows), (p, rows)
        assert len(newton) == len(rows)


# a PUMA 560 on a linear track (a 7-joint cell, joint 1 sliding along the floor): issue 37
RAIL = spec_text(
    "rail_puma",
    "standard",
    [
        (-90, 0, 0, 0),
        (-90, 0, 0, 0),
        (0, 0.432, 0, 0),
        (90, -0.02, 0.149, 0),
        (-90, 0, 0.433, 0),
        (90, 0, 0, 0),
        (0, 0, 0, 0),
    ],
    kinds="PRRRRRR",
).replace('type = "P"\n', 'type = "P"\nlimits = [0.0, 3.0]\n', 1)


@pytest.mark.parametrize("extra", ["", "[ik]\nfree = [1]\n"])
def test_a_six_joint_arm_on_a_rail_is_solved_with_the_rail_free(extra, tmp_path):
    m = build_module(RAIL + extra, tmp_path)
    assert m.FREE == (1,) and m.METHOD == "pieper" and m.JOINT_TYPES[0] == "P"
    result = roundtrip(m, sample_joints(m, 300, np.random.default_rng(37)), "python")
    assert result.unsound == [] and result.misses == [], result.summary()
    assert result.singular_posed == result.singular, result.summary()
    q = np.array([1.7, 0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    assert np.allclose(m.nearest(m.fk(q), q + 0.01), q, atol=1e-6)


def test_telescoping_joints_on_one_axis_are_refused_in_one_line(tmp_path, capsys):
    """Hello Robot Stretch from link_lift to link_wrist_roll: four sliding joints on one axis
    and a wrist; no choice of free joints leaves six degrees of freedom."""
    rows = [(0, 0, 0.1, 0)] * 4 + [(90, 0, 0.1, 0), (-90, 0, 0, 0), (0, 0, 0.1, 0)]
    spec = tmp_path / "tele.toml"
    spec.write_text(spec_text("tele", "standard", rows, kinds="PPPPRRR"))
    assert main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1 and "FK only, no IK" in out
    assert "the remainder loses a degree of freedom" in out


@pytest.mark.parametrize("name", REDUNDANT)
def test_every_row_reproduces_the_pose_with_the_free_value_returned(generated, name):
    """Issue 37 item 1: rows were certified with cos(1e17) (reduced exactly by libm) and
    returned with 1e17 reduced modulo the double nearest 2 pi (4 rad off)."""
    m = generated(name)
    q0 = np.array([0.3, 0.5, -0.2, -1.0, 0.4, 0.6, 0.2])
    T = m.fk(q0)
    for value in (0.2 + 2 * math.pi * 1000, 0.2 - 2 * math.pi * 150_000):
        rows = m.ik(T, free=[value], backend="python")
        Q, valid = m.ik_batch(T[None], free=[value], backend="python")
        assert len(rows) and valid.sum() == len(rows)
        for q in [*rows, *Q[valid]]:
            assert np.abs(m.fk(q) - T).max() < 1e-9
            assert abs(q[6] - math.remainder(value, 2 * math.pi)) < 1e-15
    for value in (1e17, 1e300, -2e6):
        with pytest.raises(ValueError, match=r"within \+-1e\+06 rad"):
            m.ik(T, free=[value], backend="python")
        with pytest.raises(ValueError, match=r"within \+-1e\+06 rad"):
            m.ik_batch(T[None], free=[value], backend="python")


@pytest.mark.parametrize("name", REDUNDANT)
def test_nearest_with_q_ref_far_outside_the_limits(generated, name, monkeypatch):
    """Issue 37 item 3: a free joint's q_ref half a turn or more outside its limits gave an
    IndexError (an empty search window) or numpy's 'Maximum allowed size exceeded'."""
    m = generated(name)
    monkeypatch.setattr(m, "BACKEND", "python")  # (nearest has no backend argument)
    q0 = np.array([0.3, 0.5, -0.2, -1.0, 0.4, 0.6, 0.2])
    T = m.fk(q0)
    for ref in (q0 + 2 * math.pi, np.full(7, 1e6), np.full(7, 1e300), np.full(7, -1e300)):
        q = m.nearest(T, ref)
        assert q is not None and np.abs(m.fk(q) - T).max() < 1e-9
        lo, hi = np.array(m.LIMITS).T
        assert ((lo - 1e-9 <= q) & (q <= hi + 1e-9)).all()
    q = m.nearest(T, q0 + 2 * math.pi, within_limits=False)
    assert q is not None and np.abs(m.fk(q) - T).max() < 1e-9


def test_too_many_free_values_are_refused_before_their_grid_is_built(tmp_path, monkeypatch):
    """A mobile base's three free joints (x and y slides over +-10 m, a turn) at the default
    free_step gave nearest a grid of 2,001 x 2,001 x 629 values, 19 GiB an array, built before
    its size was checked (a new user's attack). The count is checked first now: here the
    PUMA on its rail turned about a column (two free joints, 629 x 301 values with
    free_step 0.01), and numpy's grid builder made to fail if it is reached."""
    column = RAIL.replace('type = "P"\n', 'type = "R"\nalpha = 0.0\na = 0.0\nd = 0.5\n'
                          'theta = 0.0\n[[joint]]\ntype = "P"\n', 1)  # fmt: skip
    module = build_module(column + "[ik]\nfree = [1, 2]\n", tmp_path)
    assert module.FREE == (1, 2)
    q = np.array([0.2, 1.5, 0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    T = module.fk(q)

    def no_grid(*args, **kwargs):
        raise AssertionError("the grid was built before its size was checked")

    monkeypatch.setattr(module.np, "meshgrid", no_grid)
    with pytest.raises(ValueError, match=r"nearest: 189329 free values \(629 x 301 at"):
        module.nearest(T, q)
    with pytest.raises(ValueError, match=r"ik_sweep: 160000 samples \(400 x 400\); at most"):
        module.ik_sweep(T, n=400)
