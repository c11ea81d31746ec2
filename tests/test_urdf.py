"""URDF in: real robots' URDFs (kinematics-only copies in tests/data/urdf) convert to specs
whose FK is the URDF's, generate solvers that find the URDF's joint values, and bad or hostile
files get one line and exit 2 with nothing written."""

from __future__ import annotations

import math
import os
import random
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from derive import cli, urdf
from derive.emit import render_module
from derive.pipeline import build_plan

from conftest import ROOT, write_runtime

DATA = ROOT / "tests" / "data" / "urdf"
# (file, base link, tip link, a method solves it)
FIXTURES = (
    ("ur3", "world", "tool0", True),
    ("ur5", "world", "tool0", True),
    ("ur10", "world", "tool0", True),
    ("kr16_2", "base_link", "tool0", True),
    ("kr120r2500pro", "base_link", "tool0", True),
    ("kr210l150", "base_link", "tool0", True),
    ("puma560", "link1", "link7", True),
    ("kinova_j2s6s200", "base", "j2s6s200_end_effector", True),
    # joint 6's axis is 0.02 off the wrist centre in this file: no special structure (general 6R)
    ("irb140", "base_link", "tool0", True),
    ("al5d", "base", "link4", False),
    ("panda", "panda_link0", "panda_hand_tcp", False),
    ("lbr_iiwa_14_r820", "base_link", "tool0", False),
    ("xarm7", "world", "link_eef", False),
    ("z1", "world", "gripperMover", False),
)
# fixtures whose exact conversion is refused (nearly parallel axes give offsets of 1e8 m)
NOT_EXACT = ("al5d",)


def options(base: str, tip: str, **kw) -> urdf.Options:
    return urdf.Options(base=base, tip=tip, **kw)


@pytest.mark.parametrize(("name", "base", "tip", "solved"), FIXTURES)
def test_every_fixture_converts_with_fk_equal_to_the_urdf(name, base, tip, solved):
    path = DATA / f"{name}.urdf"
    if name in NOT_EXACT:  # pi written as 3.14159265: axes 1e-9 rad from parallel
        with pytest.raises(urdf.UrdfError, match="nearly parallel"):
            urdf.import_urdf(path, options(base, tip, exact=True))
    else:
        _, exact = urdf.import_urdf(path, options(base, tip, exact=True))
        assert exact.deviation <= 1e-9 and not exact.snaps
    text, snapped = urdf.import_urdf(path, options(base, tip))
    assert snapped.deviation <= urdf.MAX_DEVIATION
    assert f"largest difference {snapped.deviation:.2g}\n" in text
    for snap in snapped.snaps:
        assert f"# snapped: {snap}" in text


def random_joint_values(chain: list[urdf.UrdfJoint], rng: random.Random) -> list[float]:
    q = []
    for joint in chain:
        if joint.kind not in urdf.MOVING:
            continue
        lo, hi = (
            joint.limits if joint.limits and joint.kind != "continuous" else (-math.pi, math.pi)
        )
        q.append(rng.uniform(max(lo, -math.pi), min(hi, math.pi)))
    return q


def generated_module(path: Path, base: str, tip: str, tmp_path: Path):
    import importlib.util

    spec = urdf.load_urdf(path, options(base, tip))
    file = tmp_path / f"{spec.name}.py"
    file.write_text(render_module(build_plan(spec)))
    write_runtime(tmp_path)
    loaded = importlib.util.spec_from_file_location(f"urdf_{spec.name}", file)
    assert loaded is not None and loaded.loader is not None
    module = importlib.util.module_from_spec(loaded)
    loaded.loader.exec_module(module)
    # the Python solver: numba would compile each arm's solver (seconds to a minute)
    module.BACKEND = "python"
    return module


def test_a_mount_written_with_cad_decimals_keeps_the_table_exact(tmp_path):
    """A KR210 (its URDF exact) on a mount turned by 1.5708 rad about z and tilted by 1e-5
    about x (CAD decimals), with a tool turned by 3.1416 about z and 2e-5 about x: a pose's
    closed form solves B^-1 T E^-1 for any rigid B and E, so the mount and the tool are not
    snapped. Before, they were taken as right-angle rotations, the arm went nominal (deviation
    2e-5) and every row was refined by Newton's steps; and kept, their entries of 1e-11 (the
    two turns' products) were written as 0, which moved FK by 1.7e-10 and kept [exact] frames.
    Now the table is the file's, with no [exact] frames."""
    extra = (
        '<link name="mount"/><link name="tcp"/>'
        '<joint name="mount_joint" type="fixed"><parent link="mount"/><child link="base_link"/>'
        '<origin xyz="0.1 0.2 0.3" rpy="1e-5 0 1.5708"/></joint>'
        '<joint name="tcp_joint" type="fixed"><parent link="tool0"/><child link="tcp"/>'
        '<origin xyz="0 0.01 0.1" rpy="0.00002 0 3.1416"/></joint></robot>'
    )
    text = (DATA / "kr210l150.urdf").read_text()
    path = tmp_path / "kr210_mounted.urdf"
    path.write_text(text.replace("</robot>", extra))
    spec_text, conversion = urdf.import_urdf(path, options("mount", "tcp"))
    assert not conversion.snaps and "[exact]" not in spec_text, conversion.snaps
    assert conversion.deviation <= 1e-13
    chain = urdf.chain_between(urdf.read_urdf(path), "mount", "tcp", str(path))
    module = generated_module(path, "mount", "tcp", tmp_path)
    rng = random.Random(3)
    for _ in range(100):
        q = random_joint_values(chain, rng)
        T = np.array(urdf.urdf_fk(chain, q))
        assert np.abs(module.fk(q) - T).max() <= 1e-12
        rows = module.ik(T)
        assert len(rows) and np.abs(rows - np.array(q)).max(axis=1).min() <= 1e-9
        for row in rows:
            assert np.abs(np.array(urdf.urdf_fk(chain, list(row))) - T).max() <= 1e-12


@pytest.mark.parametrize(("name", "base", "tip"), [f[:3] for f in FIXTURES if f[3]])
def test_the_solver_of_a_urdf_finds_the_urdf_joint_values(name, base, tip, tmp_path):
    """ik(FK_urdf(q)) contains q (to 1e-8) on 1,000 random q within the limits; where it does
    not (a singular pose, whose free joint takes q_ref's value) every solution reproduces the
    pose. The generated FK is the URDF's own to 1e-12 and every row reproduces the URDF's
    pose to 1e-10: the spec keeps the URDF's frames ([exact]) and the solver's rows are
    refined onto them (issue 39; before, the snapped table's rows missed by up to 1e-5)."""
    path = DATA / f"{name}.urdf"
    chain = urdf.chain_between(urdf.read_urdf(path), base, tip, str(path))
    module = generated_module(path, base, tip, tmp_path)
    assert module.IK_COMPONENTS == "pose"
    # the generated FK (derived by SymPy from the spec) against the URDF's own
    rng = random.Random(5)
    revolute = np.array([c == "R" for c in module.JOINT_TYPES])
    missed = []
    for _ in range(1000):
        q = random_joint_values(chain, rng)
        T = np.array(urdf.urdf_fk(chain, q))
        assert np.abs(module.fk(q) - T).max() <= 1e-12 * max(1.0, module.REACH)
        sols = module.ik(T)
        for s in sols:
            assert np.abs(np.array(urdf.urdf_fk(chain, list(s))) - T).max() <= 1e-10 * max(
                1.0, module.REACH
            )
        d = sols - np.array(q)
        d[:, revolute] = np.remainder(d[:, revolute] + np.pi, 2 * np.pi) - np.pi
        if len(sols) == 0 or np.abs(d).max(axis=1).min() > 1e-8:
            missed.append((q, T, sols))
    for _q, _T, sols in missed:
        assert len(sols) > 0
    assert len(missed) <= 5, f"{len(missed)} of 1000 joint vectors not among the solutions"


def run(*args: str, cwd: Path, env: dict | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "derive", *args], cwd=cwd, capture_output=True, text=True, env=env
    )


def test_import_urdf_is_byte_identical_across_hash_seeds(tmp_path):
    outs = []
    for seed in ("0", "12345"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        out = tmp_path / f"ur5_{seed}.toml"
        result = run(
            "import-urdf", str(DATA / "ur5.urdf"), "--base", "world", "--tip", "tool0", "-o",
            str(out), cwd=tmp_path, env=env,
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]
    generated = run(
        "generate", str(DATA / "ur5.urdf"), "--base", "world", "--tip", "tool0", "--out", "g",
        cwd=tmp_path,
    )  # fmt: skip
    assert generated.returncode == 0, generated.stderr
    from_spec = run("generate", str(tmp_path / "ur5_0.toml"), "--out", "h", cwd=tmp_path)
    assert from_spec.returncode == 0, from_spec.stderr
    assert (tmp_path / "g" / "ur5.py").read_bytes() == (tmp_path / "h" / "ur5.py").read_bytes()


JOINT = (
    '<joint name="{name}" type="{type}"><parent link="{parent}"/><child link="{child}"/>'
    '<origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="0 0 1"/>'
    '<limit lower="-1" upper="1"/>{extra}</joint>'
)


def urdf_text(joints: list[dict], links: list[str], head: str = "") -> str:
    body = "".join(f'<link name="{name}"/>' for name in links)
    for j in joints:
        body += JOINT.format(**{"type": "revolute", "xyz": "0 0 0.1", "extra": "", **j})
    return f'<?xml version="1.0"?>{head}<robot name="bad">{body}</robot>'


def two_joints(**changes) -> list[dict]:
    joints = [
        {"name": "j1", "parent": "a", "child": "b"},
        {"name": "j2", "parent": "b", "child": "c"},
    ]
    joints[1].update(changes)
    return joints


BOMB = (
    '<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">'
    '<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">]>'
)
HOSTILE = {
    "entity bomb": (urdf_text(two_joints(), ["a", "b", "c"], BOMB), "c", "DTDs and entities"),
    "external entity": (
        urdf_text(
            two_joints(), ["a", "b", "c"], '<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/passwd">]>'
        ),
        "c",
        "DTDs and entities",
    ),
    "missing tip": (urdf_text(two_joints(), ["a", "b", "c"]), "nowhere", "no such link"),
    "cycle": (
        urdf_text([*two_joints(), {"name": "j3", "parent": "c", "child": "a"}], ["a", "b", "c"]),
        "c",
        "cycle",
    ),
    "mimic joint in the chain": (
        urdf_text(two_joints(extra='<mimic joint="j1"/>'), ["a", "b", "c"]),
        "c",
        "mimic",
    ),
    "NaN origin": (urdf_text(two_joints(xyz="0 nan 0"), ["a", "b", "c"]), "c", "finite"),
    "non-numeric origin": (urdf_text(two_joints(xyz="0 x 0"), ["a", "b", "c"]), "c", "numbers"),
    "floating joint": (urdf_text(two_joints(type="floating"), ["a", "b", "c"]), "c", "floating"),
    "unknown link": (urdf_text(two_joints(child="zz"), ["a", "b", "c"]), "c", "unknown link"),
    "duplicate link": (urdf_text(two_joints(), ["a", "b", "c", "a"]), "c", "defined twice"),
    "not below the base": (urdf_text(two_joints(), ["a", "b", "c", "d"]), "d", "not below"),
    "xacro": (
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="x">'
        '<xacro:macro name="m"/></robot>',
        "c",
        "xacro",
    ),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_bad_and_hostile_urdfs_get_one_line_and_exit_2(case, tmp_path):
    text, tip, words = HOSTILE[case]
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    out = tmp_path / "out.toml"
    for args in (
        ("import-urdf", str(path), "--base", "a", "--tip", tip, "-o", str(out)),
        ("generate", str(path), "--base", "a", "--tip", tip, "--out", str(tmp_path / "g")),
    ):
        result = run(*args, cwd=tmp_path)
        assert result.returncode == 2, (case, result.stdout, result.stderr)
        lines = result.stderr.strip().split("\n")
        assert len(lines) == 1 and words in lines[0] and "Traceback" not in result.stderr, lines
    assert not out.exists() and not (tmp_path / "g").exists()


def test_a_urdf_without_base_or_tip_is_told_its_root_and_leaf_links(tmp_path, capsys):
    # (a new user's first try names only the file; the message names the usual base and tip)
    path = DATA / "irb140.urdf"
    for args in ([], ["--base", "base_link"], ["--tip", "tool0"]):
        assert cli.main(["generate", str(path), *args, "--out", str(tmp_path / "g")]) == 2
        err = capsys.readouterr().err
        assert err == (
            f"error: {path}: a URDF needs --base LINK and --tip LINK (its root links: "
            "'base_link'; its leaf links: 'base', 'tool0')\n"
        )
    assert not (tmp_path / "g").exists()


def test_a_50_mb_urdf_is_refused_unread(tmp_path):
    path = tmp_path / "big.urdf"
    with path.open("wb") as f:
        f.write(b"<robot>" + b" " * 50_000_000 + b"</robot>")
    result = run("import-urdf", str(path), "--base", "a", "--tip", "b", cwd=tmp_path)
    assert result.returncode == 2 and "at most" in result.stderr
    assert len(result.stderr.strip().split("\n")) == 1


def calibrated_pair_urdf(tmp_path: Path) -> Path:
    """A two-joint URDF whose axes are 1e-3 rad from parallel (a calibrated arm's)."""
    joints = [
        {"name": "j1", "parent": "a", "child": "b"},
        {"name": "j2", "parent": "b", "child": "c", "xyz": "0.4 0 0"},
    ]
    text = urdf_text(joints, ["a", "b", "c"]).replace(
        '<axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint></robot>',
        '<axis xyz="0.001 0 1"/><limit lower="-1" upper="1"/></joint></robot>',
    )
    path = tmp_path / "cal.urdf"
    path.write_text(text)
    return path


def test_nearly_parallel_axes_are_snapped_or_refused_never_huge_offsets(tmp_path):
    """A calibrated arm: axes 2 and 3 are 1e-3 rad from parallel. Without snapping the
    common normal is hundreds of lengths away: taken as parallel for that (urdf._far_normal),
    which moves this arm by 9.5e-4, beyond --max-deviation, so refused with both reasons;
    with --angle-tol above 1e-3 they are parallel, and the deviation is reported (and bounded
    by --max-deviation)."""
    path = calibrated_pair_urdf(tmp_path)
    with pytest.raises(urdf.UrdfError, match=r"differs .* after snapping \(axes 1 and 2: .*common"):
        urdf.import_urdf(path, options("a", "c"))
    with pytest.raises(urdf.UrdfError, match="differs from the URDF's"):
        urdf.import_urdf(path, options("a", "c", angle_tol=2e-3))
    spec, conversion = urdf.import_urdf(path, options("a", "c", angle_tol=2e-3, max_deviation=1e-2))
    assert conversion.deviation > 1e-4 and "taken as parallel" in spec
    assert all(abs(row[2]) < 1.0 and abs(row[3]) < 1.0 for row in conversion.rows)


def test_a_refusal_for_the_deviation_names_the_max_deviation_that_accepts_the_file(tmp_path):
    """A URDF refused because snapping moved its FK beyond --max-deviation: the message names
    the --max-deviation that accepts it (just above the measured deviation), and that value
    does, keeping the file's exact frames for fk; --exact stays named as the other way."""
    path = calibrated_pair_urdf(tmp_path)
    with pytest.raises(urdf.UrdfError) as refused:
        urdf.import_urdf(path, options("a", "c"))
    message = str(refused.value)
    found = re.search(r"by ([0-9.e-]+) after .*--max-deviation ([0-9.e-]+) accepts it", message)
    assert found and "--exact switches snapping off" in message
    deviation, advised = float(found.group(1)), float(found.group(2))
    assert deviation < advised <= 1.1 * deviation
    spec, conversion = urdf.import_urdf(path, options("a", "c", max_deviation=advised))
    assert conversion.deviation <= advised and "[exact]" in spec


def random_chain(rng: random.Random) -> tuple[str, str, str]:
    """A random URDF chain: 2-7 moving joints (revolute, continuous, prismatic) with fixed
    joints between; consecutive axes parallel, antiparallel, intersecting or skew; random link
    frames."""
    links = ["l0"]
    joints = []
    axes = [(0, 0, 1), (0, 0, -1), (1, 0, 0), (0, 1, 0)]
    for k in range(rng.randint(2, 7)):
        if rng.random() < 0.3:
            links.append(f"f{k}")
            joints.append(("fixed", links[-2], links[-1], (1, 0, 0)))
        links.append(f"l{k + 1}")
        kind = rng.choice(("revolute", "revolute", "continuous", "prismatic"))
        axis = rng.choice(axes) if rng.random() < 0.7 else tuple(rng.gauss(0, 1) for _ in range(3))
        joints.append((kind, links[-2], links[-1], axis))
    body = "".join(f'<link name="{n}"/>' for n in links)
    for k, (kind, parent, child, axis) in enumerate(joints):
        special = rng.random() < 0.6
        xyz = [rng.choice((0.0, 0.0, 0.3)) if special else rng.uniform(-0.5, 0.5) for _ in range(3)]
        rpy = [
            rng.choice((0.0, math.pi / 2, -math.pi / 2, math.pi)) if special else rng.uniform(-3, 3)
            for _ in range(3)
        ]
        limit = '<limit lower="-2" upper="2"/>' if kind != "continuous" else ""
        body += (
            f'<joint name="j{k}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{" ".join(map(repr, xyz))}" rpy="{" ".join(map(repr, rpy))}"/>'
            f'<axis xyz="{" ".join(map(repr, axis))}"/>{limit}</joint>'
        )
    return f'<robot name="chain">{body}</robot>', links[0], links[-1]


@pytest.mark.parametrize("seed", range(60))
def test_random_chains_convert_with_equal_fk(seed, tmp_path):
    text, base, tip = random_chain(random.Random(seed))
    path = tmp_path / "random.urdf"
    path.write_text(text)
    _, exact = urdf.import_urdf(path, options(base, tip, exact=True))
    assert exact.deviation <= 1e-9
    _, snapped = urdf.import_urdf(path, options(base, tip))
    assert snapped.deviation <= urdf.MAX_DEVIATION


def test_the_report_of_a_urdf_arm_says_where_it_came_from(tmp_path):
    result = run(
        "report", str(DATA / "ur5.urdf"), "--base", "world", "--tip", "tool0", cwd=tmp_path
    )
    assert result.returncode == 0, result.stderr
    section = result.stdout.split("### From the URDF", 1)[1]
    assert "| 2 | shoulder_lift_joint |" in section and "link world to link tool0" in section
    assert "Snaps applied: row 2 (shoulder_lift_joint) theta:" in section
    assert "largest difference 1.4e-11" in section


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ('joints = ["a"]', "array of 6 strings"),
        ('urdf = "x$y"', "source.urdf"),
        ('sha256 = "xyz"', "16 hex digits"),
        ("deviation = -1.0", "0 or more"),
        ('color = "red"', "unknown key"),
    ],
)
def test_a_bad_source_table_is_refused_naming_the_field(change, words, tmp_path):
    from derive.spec import SpecError, parse_spec

    text, _ = urdf.import_urdf(DATA / "ur5.urdf", options("world", "tool0"))
    key = change.split(" = ")[0]
    lines = [ln for ln in text.split("\n") if not ln.startswith(f"{key} = ")]
    at = lines.index("[source]") + 1
    lines.insert(at, change)
    with pytest.raises(SpecError, match=words):
        parse_spec("\n".join(lines), "ur5.toml")


@pytest.mark.parametrize(
    ("name", "base", "tip"), [("ur5", "world", "tool0"), ("puma560", "link1", "link7")]
)
def test_the_standard_convention_gives_the_same_arm(name, base, tip, tmp_path):
    """--convention standard: the same FK as the URDF and as the modified spec's module."""
    path = DATA / f"{name}.urdf"
    modules = []
    for convention in ("modified", "standard"):
        text, conversion = urdf.import_urdf(path, options(base, tip, convention=convention))
        assert f'convention = "{convention}"' in text and conversion.deviation <= 1e-8
        spec = tmp_path / f"{name}_{convention}.toml"
        spec.write_text(text.replace(f'name = "{name}"', f'name = "{name}_{convention}"'))
        import importlib.util

        from derive.spec import load_spec

        file = tmp_path / f"{name}_{convention}.py"
        file.write_text(render_module(build_plan(load_spec(spec))))
        write_runtime(tmp_path)
        loaded = importlib.util.spec_from_file_location(file.stem, file)
        assert loaded is not None and loaded.loader is not None
        module = importlib.util.module_from_spec(loaded)
        loaded.loader.exec_module(module)
        modules.append(module)
    Q = np.random.default_rng(2).uniform(-np.pi, np.pi, size=(50, 6))
    assert np.abs(modules[0].fk_batch(Q) - modules[1].fk_batch(Q)).max() <= 1e-12
    assert modules[1].ik(modules[1].fk(Q[0])).shape[0] >= 1


SCARA = """<robot name="scara"><link name="base"/><link name="l1"/><link name="l2"/>
<link name="l3"/><link name="l4"/><link name="flange"/>
<joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
<origin xyz="0 0 0.4" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2"/></joint>
<joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
<origin xyz="0.35 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-2" upper="2"/></joint>
<joint name="j3" type="prismatic"><parent link="l2"/><child link="l3"/>
<origin xyz="0.3 0.05 -0.1" rpy="0 0 0"/><axis xyz="0 0 -1"/><limit lower="0" upper="0.2"/></joint>
<joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>
<origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3"/></joint>
<joint name="tool" type="fixed"><parent link="l4"/><child link="flange"/>
<origin xyz="0.02 0 -0.05" rpy="3.141592653589793 0 0"/></joint>
</robot>"""


def test_a_scara_urdf_with_a_prismatic_joint_gets_its_solver(tmp_path):
    """A SCARA (RRPR, the sliding axis pointing down, a fixed flange after it): the planar
    method solves the converted spec, and ik(FK_urdf(q)) contains q."""
    path = tmp_path / "scara.urdf"
    path.write_text(SCARA)
    module = generated_module(path, "base", "flange", tmp_path)
    assert module.JOINT_TYPES == "RRPR" and hasattr(module, "ik")
    chain = urdf.chain_between(urdf.read_urdf(path), "base", "flange", str(path))
    rng = random.Random(9)
    for _ in range(200):
        q = [rng.uniform(-2, 2), rng.uniform(-2, 2), rng.uniform(0, 0.2), rng.uniform(-3, 3)]
        T = np.array(urdf.urdf_fk(chain, q))
        sols = module.ik(T, backend="python")
        d = sols - np.array(q)
        d[:, [0, 1, 3]] = np.remainder(d[:, [0, 1, 3]] + np.pi, 2 * np.pi) - np.pi
        assert len(sols) and np.abs(d).max(axis=1).min() <= 1e-9, (q, sols)


def test_a_robot_named_with_no_letter_or_digit_is_named_after_its_file(tmp_path):
    """<robot name="  "> gave the spec name "arm_" (a new user's attack); now the file's."""
    text, base, tip = random_chain(random.Random(1))
    path = tmp_path / "left_leg.urdf"
    path.write_text(text.replace('<robot name="chain">', '<robot name="  ">'))
    assert urdf.load_urdf(path, options(base, tip)).name == "left_leg"
    path.write_text(text)
    assert urdf.load_urdf(path, options(base, tip)).name == "chain"


NAMES = [("class", "class_arm"), ("site", "site_arm"), ("numpy", "numpy_arm"),
         ("2-finger pro", "arm_2_finger_pro")]  # fmt: skip


@pytest.mark.parametrize(("robot", "name"), NAMES)
def test_a_robot_named_as_a_keyword_or_a_module_gets_a_spec_name_it_may_have(robot, name, tmp_path):
    """<robot name="class"> (or "site", "numpy") was refused in a spec's words, naming neither
    the URDF nor --name (a new user's attack); the user did not choose the name, so the
    conversion makes it one a spec takes, as it does for "2-finger pro"."""
    text, base, tip = random_chain(random.Random(1))
    path = tmp_path / "finger.urdf"
    path.write_text(text.replace('<robot name="chain">', f'<robot name="{robot}">'))
    assert urdf.load_urdf(path, options(base, tip)).name == name


@pytest.mark.parametrize("tilt", [0.0015509, 1e-4, 1e-7, 1e-16, 0.3, 1.0])
def test_a_joint_axis_near_minus_z_gets_an_orthonormal_frame(tilt):
    """The rotation taking e_z onto a joint's axis (urdf._onto_z) for axes near -e_z: 1 + z
    lost its digits there, and a DClaw finger's axis "0 -0.0015509 -1" (mani-skill's
    dclaw_gripper_glb.urdf) made [exact] frames 9.2e-11 from orthonormal and the module's fk
    8e-11 from the URDF's (a new user's attack). Orthonormal and onto the axis to 1e-15."""
    norm = math.sqrt(1.0 + tilt * tilt)
    for axis in ((0.0, -tilt / norm, -1.0 / norm), (tilt / norm, 0.0, -1.0 / norm)):
        R = np.array(urdf._onto_z(axis))[:3, :3]
        assert np.abs(R.T @ R - np.eye(3)).max() <= 1e-15
        assert np.abs(R[:, 2] - axis).max() <= 1e-15 and np.linalg.det(R) > 0.0
