"""MJCF in (derive/mjcf.py): MuJoCo's compiler reads the file; the chain is checked against
MuJoCo's own forward kinematics, converted as a URDF is, and the generated module's fk and ik
are MuJoCo's arm's (tests/data/mjcf/SOURCES.md: the files and their licences)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from derive import cli, mjcf
from derive.inputs import resolve_spec
from derive.pipeline import build_plan
from derive.spec import SpecError, parse_spec
from derive.urdf import Options

from conftest import build_module, needs_cc

mujoco = pytest.importorskip("mujoco")

DATA = Path(__file__).parent / "data" / "mjcf"


def mujoco_pose(path: Path, base: str, tip: str, joints: list[str], q: np.ndarray) -> np.ndarray:
    """The tip body's pose in the base body's frame, by MuJoCo (meshes left out)."""
    model = mjcf.compile_model(path)
    data = mujoco.MjData(model)
    data.qpos[:] = model.qpos0
    for name, value in zip(joints, q):
        data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
    mujoco.mj_kinematics(model, data)
    frames = []
    for body in (base, tip):
        i = model.body(body).id
        frame = np.eye(4)
        frame[:3, :3] = data.xmat[i].reshape(3, 3)
        frame[:3, 3] = data.xpos[i]
        frames.append(frame)
    return np.linalg.inv(frames[0]) @ frames[1]


def test_the_so_arm100_with_euler_1_57079_keeps_its_exact_frames(tmp_path):
    """Its base body is turned by euler 1.57079: the base frame is 4.2e-6 from a right-angle
    rotation. A tool axis's task does not read the base's frame, so the conversion keeps it
    (before, it was snapped, the arm went nominal, and poses with the roll within 1e-4 of
    90 deg got no row: tests/test_tasks.py), and the table is the file's."""
    path = DATA / "so_arm100.xml"
    options = Options(base="so_arm100_right", tip="so_arm100_right/Fixed_Jaw")
    text, conversion = mjcf.import_mjcf(path, options)
    assert len(conversion.rows) == 5 and not conversion.snaps and "[exact]" not in text
    assert abs(abs(conversion.base[1][2]) - 4.2426e-6) <= 1e-9
    assert 'format = "MJCF"' in text and "# row 1: MJCF joint 'so_arm100_right/Rotation'" in text
    spec = parse_spec(text, "<so_arm100>")
    assert spec.origin is not None and spec.origin.format == "MJCF"
    module = build_module(text, tmp_path)
    rng = np.random.default_rng(1)
    for q in rng.uniform(-math.pi, math.pi, (20, 5)):
        expected = mujoco_pose(path, options.base, options.tip, list(spec.origin.joints), q)
        assert np.max(np.abs(module.fk(q) - expected)) <= 1e-12


def test_an_exact_table_whose_task_link_is_snapped_says_nominal_table():
    """The SO-101's MJCF converts with no snapping, but its tool axis's virtual link is
    snapped (by 5e-4) and its rows are refined: the summary said nothing of it (a new user's
    attack; its URDF, whose rows are snapped, said "(nominal table)")."""
    text, conversion = mjcf.import_mjcf(
        DATA / "so101_new_calib.xml", Options(base="base", tip="gripperframe")
    )
    assert not conversion.snaps
    plan = build_plan(parse_spec(text, "<so101>"))
    assert plan.ik is not None and plan.ik.task_snap > 1e-4
    assert plan.structure[0].endswith("(nominal table)")


def test_the_so101_keeps_both_rows_of_its_elbow_near_the_fold(tmp_path):
    """LeRobot's SO-101 (tests/data/mjcf/SOURCES.md) is solved on a nominal table 5e-4 from
    its MJCF frames. Near the elbow's fold the nominal acos argument is just above 1 (1.0018
    at the helper's pose), so both of its values were one seed, refined onto one of the exact
    arm's two rows: the other, 0.03-0.12 rad away, was lost (17 of 3,000 samples within the
    limits, 13 with sigma >= 1e-3). Now the fold's angle +- 0.03 seed the refinement too
    (_FOLD_SEEDS): that pose gives its 4 rows, and 600 samples lose none, in C and Python."""
    path = DATA / "so101_new_calib.xml"
    text, _ = mjcf.import_mjcf(path, Options(base="base", tip="gripperframe"))
    module = build_module(text, tmp_path, c=True)
    assert module.NOMINAL_DEVIATION > 1e-4 and module.IK_COMPONENTS == "direction"
    q = np.radians([102.2202, -50.8923, -70.4601, 46.4970, 59.4411])
    T = module.fk(q)
    for backend in ("c", "python"):
        rows = module.ik_direction(T[:3, 3], T[:3, 2], backend=backend)
        assert len(rows) == 4 and np.min(np.abs(rows - q).max(axis=1)) <= 1e-9, backend
    rng = np.random.default_rng(2)
    lo, hi = np.array(module.LIMITS).T
    for q in rng.uniform(lo, hi, (600, 5)):
        T = module.fk(q)
        rows = module.ik_direction(T[:3, 3], T[:3, 2], backend="c")
        gaps = np.abs(np.remainder(rows - q + math.pi, 2 * math.pi) - math.pi)
        assert len(rows) and np.min(np.max(gaps, axis=1)) <= 1e-8, q


def test_the_jaco_arm_is_solved_against_mujoco_s_own_kinematics(tmp_path):
    path = DATA / "jaco_arm.xml"
    options = Options(base="b_base", tip="b_6")
    text, conversion = mjcf.import_mjcf(path, options)
    assert len(conversion.rows) == 6 and conversion.deviation <= 1e-12
    spec = parse_spec(text, "<jaco>")
    assert spec.origin is not None
    module = build_module(text, tmp_path)
    assert module.METHOD == "general"
    joints = list(spec.origin.joints)
    rng = np.random.default_rng(2)
    found = 0
    for q in rng.uniform(-math.pi, math.pi, (12, 6)):
        T = mujoco_pose(path, options.base, options.tip, joints, q)
        rows = module.ik(T)
        assert len(rows) > 0
        for row in rows:
            E = mujoco_pose(path, options.base, options.tip, joints, row)
            assert np.max(np.abs(E[:3, :3] - T[:3, :3])) <= 1e-9
            assert np.max(np.abs(E[:3, 3] - T[:3, 3])) <= 1e-9 * module.REACH
        gaps = np.abs(np.remainder(rows - q + math.pi, 2 * math.pi) - math.pi)
        found += bool(np.min(np.max(gaps, axis=1)) <= 1e-7)
    assert found == 12


def test_ref_slide_anchors_and_two_joints_in_one_body_mean_what_mujoco_means(tmp_path):
    xml = tmp_path / "odd.xml"
    xml.write_text(
        '<mujoco><worldbody><body name="a"><joint name="h" axis="0 1 0" ref="0.3" '
        'pos="0.1 0 0"/><geom size="0.1"/><body name="b" pos="0 0 1"><joint name="s" '
        'type="slide" axis="1 0 0" ref="0.05"/><geom size="0.1"/><body name="c" pos="0 0 1" '
        'euler="0.3 0.2 0.1"><joint name="h2" axis="1 1 0"/><joint name="h3" axis="0 0 1" '
        'pos="0.2 0 0"/><geom size="0.1"/></body></body></body></worldbody></mujoco>'
    )
    text, _ = mjcf.import_mjcf(xml, Options(base="world", tip="c"))
    module = build_module(text, tmp_path)
    rng = np.random.default_rng(3)
    for q in rng.uniform(-1.0, 1.0, (20, 4)):
        expected = mujoco_pose(xml, "world", "c", ["h", "s", "h2", "h3"], q)
        assert np.max(np.abs(module.fk(q) - expected)) <= 1e-12


def test_a_site_is_a_tip(tmp_path):
    """A gripper's tool frame is often a site: --tip takes it (the jaco's wristsite, turned
    on its body b_6), and fk is MuJoCo's site pose."""
    path = DATA / "jaco_arm.xml"
    text, _ = mjcf.import_mjcf(path, Options(base="b_base", tip="wristsite"))
    spec = parse_spec(text, "<jaco site>")
    assert spec.origin is not None
    module = build_module(text, tmp_path)
    model = mjcf.compile_model(path)
    data = mujoco.MjData(model)
    rng = np.random.default_rng(4)
    for q in rng.uniform(-math.pi, math.pi, (10, 6)):
        data.qpos[:] = model.qpos0
        for name, value in zip(spec.origin.joints, q):
            data.qpos[model.jnt_qposadr[model.joint(name).id]] = value
        mujoco.mj_kinematics(model, data)
        base, site = np.eye(4), np.eye(4)
        i, k = model.body("b_base").id, model.site("wristsite").id
        base[:3, :3], base[:3, 3] = data.xmat[i].reshape(3, 3), data.xpos[i]
        site[:3, :3], site[:3, 3] = data.site_xmat[k].reshape(3, 3), data.site_xpos[k]
        assert np.max(np.abs(module.fk(q) - np.linalg.inv(base) @ site)) <= 1e-12


def test_a_site_as_the_base_is_refused_in_one_line(capsys):
    path = DATA / "jaco_arm.xml"
    assert cli.main(["import-mjcf", str(path), "--base", "wristsite", "--tip", "b_6"]) == 2
    err = capsys.readouterr().err
    assert "--base 'wristsite': a site; the chain starts from a body" in err
    assert err.count("\n") == 1


def test_task_tool_axis_and_method_options_reach_the_spec(tmp_path, capsys):
    """--task, --tool-axis and --method of a conversion are the spec's [ik] keys."""
    chain = ["--base", "so_arm100_right", "--tip", "so_arm100_right/Fixed_Jaw"]
    spec_file = tmp_path / "so.toml"
    options = ["--task", "direction", "--tool-axis", "x", "--method", "general"]
    command = ["import-mjcf", str(DATA / "so_arm100.xml"), *chain, *options, "-o"]
    assert cli.main([*command, str(spec_file)]) == 0
    spec = resolve_spec(str(spec_file))
    assert (spec.task, spec.tool_axis, spec.method) == ("direction", "x", "general")
    plan = build_plan(spec)
    assert plan.ik is not None and plan.ik.tool_axis == 0 and plan.ik.method == "general"


@pytest.mark.parametrize(
    ("xml", "base", "tip", "message"),
    [
        ("jaco_arm.xml", "b_base", "nope", "--tip 'nope': no such body or site; bodies: 'b_1'"),
        (  # (a misspelt body: the nearest names first, as for a URDF's links)
            "jaco_arm.xml",
            "b_base",
            "wristsight",
            "--tip 'wristsight': no such body or site; did you mean 'wristsite'? bodies: 'b_1'",
        ),
        ("not xml", "a", "b", "MuJoCo cannot compile it: XML parse error"),
        (
            '<mujoco><worldbody><body name="a"><joint type="ball"/><body name="b"/></body>'
            "</worldbody></mujoco>",
            "world",
            "b",
            "a ball joint between base and tip; allowed: hinge, slide",
        ),
        (  # (MJCF's words, not URDF's: a new user's attack)
            '<mujoco><worldbody><body name="a"><freejoint/><body name="b"/></body>'
            "</worldbody></mujoco>",
            "world",
            "b",
            "a free joint between base and tip; allowed: hinge, slide",
        ),
        (  # (its meshes absent: the message is the kinematics', not the missing mesh's, as
            # a new user's WidowX AI MJCF got)
            '<mujoco><asset><mesh name="m" file="absent.stl"/></asset><worldbody>'
            '<body name="a"><joint name="j" axis="0 0 0"/><geom type="mesh" mesh="m"/>'
            '<body name="b"/></body></worldbody></mujoco>',
            "world",
            "b",
            "MuJoCo cannot compile it: Error: axis too small in joint",
        ),
    ],
)
def test_bad_mjcf_input_is_one_line_naming_the_file(xml, base, tip, message, tmp_path, capsys):
    path = DATA / xml if xml.endswith(".xml") else tmp_path / "bad.xml"
    if not xml.endswith(".xml"):
        path.write_text(xml)
    assert cli.main(["import-mjcf", str(path), "--base", base, "--tip", tip]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}: ") and message in err and err.count("\n") == 1


def test_an_mjcf_without_base_or_tip_is_told_the_bodies_on_its_world_and_its_leaves(
    tmp_path, capsys
):
    path = DATA / "jaco_arm.xml"
    assert cli.main(["generate", str(path), "--tip", "wristsite", "--out", str(tmp_path)]) == 2
    assert capsys.readouterr().err == (
        f"error: {path}: an MJCF needs --base BODY and --tip BODY (the bodies and sites on "
        "its world: 'b_base'; its leaf bodies and sites: 'wristsite')\n"
    )


THREE = (
    '<mujoco model="m"><worldbody><body name="b0"><body name="b1" pos="0 0 0.1">'
    '<joint name="j1" axis="0 0 1" RANGE/><geom size="0.01"/>'
    '<body name="b2" pos="0 0 0.1"><joint name="j2" axis="AXIS"/><geom size="0.01"/>'
    '<body name="b3" pos="POS"><joint name="j3" axis="0 1 0" REF/><geom size="0.01"/>'
    '<body name="b4" pos="0.2 0 0"><geom size="0.01"/></body></body></body></body></body>'
    "</worldbody>TAIL</mujoco>"
)


def three_joints(pos="0.3 0 0", axis="0 1 0", range_="", ref="", tail="") -> str:
    """A three-joint MJCF (bodies b0 .. b4) with one field written as given."""
    text = THREE.replace("POS", pos).replace("AXIS", axis).replace("TAIL", tail)
    return text.replace("RANGE", range_).replace("REF", ref)


@pytest.mark.parametrize(
    ("xml", "message"),
    [
        (three_joints(pos="nan 0 0"), "joint 'j3': frame (its body's pos and quat, its own pos)"),
        (three_joints(pos="inf 0 0"), "allowed: finite numbers of magnitude at most 1e+06"),
        (three_joints(pos="1e300 0 0"), "1e+300 0 1 0 0 0 0 1 0; allowed: finite numbers"),
        (three_joints(ref='ref="nan"'), "joint 'j3': frame"),
        (three_joints(range_='range="nan 1"'), "joint 'j1': range nan 1; allowed: finite"),
        (
            three_joints(tail='<equality><joint joint1="j3" joint2="j2"/></equality>'),
            "equality number 1 (unnamed), a joint constraint, ties the chain's joints",
        ),
        (
            three_joints(
                tail='<equality><connect name="loop" body1="b4" body2="b0" anchor="0 0 0"/>'
                "</equality>"
            ),
            "equality 'loop', a connect constraint, ties",
        ),
        (
            three_joints(tail='<equality><weld body1="b3" body2="b0"/></equality>'),
            "a weld constraint, ties",
        ),
        (
            three_joints(
                tail='<tendon><fixed name="t"><joint joint="j2" coef="1"/>'
                '<joint joint="j3" coef="-1"/></fixed></tendon>'
                '<equality><tendon tendon1="t"/></equality>'
            ),
            "a tendon constraint, ties",
        ),
    ],
)
def test_mjcf_numbers_and_couplings_are_refused_as_a_urdf_s_are(
    xml, message, tmp_path, capfd, monkeypatch
):
    """What MuJoCo compiles but the chain cannot be (a helper's attack: nan and inf gave a
    traceback, 1e300 "a converter error", a nan range no limits, couplings nothing): one
    line naming the file, and nothing written. The base welded to the world, an inactive
    weld and a weld to a mocap body are not loops, and are not refused."""
    monkeypatch.chdir(tmp_path)  # (MuJoCo's warnings went to MUJOCO_LOG.TXT here, and stderr)
    path, out = tmp_path / "m.xml", tmp_path / "m.toml"
    path.write_text(xml)
    args = ["import-mjcf", str(path), "--base", "b0", "--tip", "b4", "-o", str(out)]
    assert cli.main(args) == 2
    err = capfd.readouterr().err
    assert err.startswith(f"error: {path}: ") and message in err and err.count("\n") == 1
    assert not out.exists() and not (tmp_path / "MUJOCO_LOG.TXT").exists()
    for free in (
        '<equality><weld body1="b0"/></equality>',  # (the base to the world)
        '<equality><weld body1="b4" body2="b0" active="false"/></equality>',  # (inactive)
    ):
        path.write_text(three_joints(tail=free))
        assert cli.main(args) == 0 and out.exists()
        out.unlink()
    # a mocap body welded to the tip (a controller's handle, as gym-xarm's): not a loop
    mocap = three_joints().replace("</worldbody>", '<body name="handle" mocap="true"/></worldbody>')
    path.write_text(
        mocap.replace(
            "</mujoco>", '<equality><weld body1="handle" body2="b4"/></equality></mujoco>'
        )
    )
    assert cli.main(args) == 0 and out.exists()


def test_without_mujoco_the_reader_says_which_extra_to_install(monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "mujoco", None)
    with pytest.raises(SpecError, match=r"MuJoCo's compiler: pip install 'mujoco==4\.0\.1'"):
        mjcf.import_mjcf(DATA / "jaco_arm.xml", Options(base="b_base", tip="b_6"))


def test_derive_generate_takes_an_mjcf_file(tmp_path, capsys):
    out = tmp_path / "out"
    chain = ["--base", "so_arm100_right", "--tip", "so_arm100_right/Fixed_Jaw"]
    code = cli.main(["generate", str(DATA / "so_arm100.xml"), *chain, "--out", str(out)])
    assert code == 0
    assert (out / "so_arm100.py").exists() and (out / "so_arm100.md").exists()


def test_a_urdf_named_xml_is_read_as_a_urdf(tmp_path):
    copy = tmp_path / "ur5.xml"
    copy.write_bytes((DATA.parent / "urdf" / "ur5.urdf").read_bytes())
    options = Options(base="world", tip="tool0")
    spec = resolve_spec(str(copy), options)
    assert spec.origin is not None and spec.origin.format == "URDF"
    mj = resolve_spec(str(DATA / "jaco_arm.xml"), Options(base="b_base", tip="b_6"))
    assert mj.origin is not None and mj.origin.format == "MJCF"


def test_the_spec_is_named_after_the_model_else_the_file(tmp_path):
    """<mujoco model="ur5e"> names the arm as a URDF's <robot name> does (robosuite's arms are
    all robot.xml: each generated robot.py over the last, a new user's attack); a model
    without a name (MuJoCo's "MuJoCo Model"), or one with no letter or digit (it was named
    "arm_"), is named after its file."""
    named = tmp_path / "robot.xml"
    named.write_text(three_joints().replace('model="m"', 'model="UR5e arm"'))
    unnamed = tmp_path / "left_arm.xml"
    unnamed.write_text(three_joints().replace(' model="m"', ""))
    blank = tmp_path / "right_arm.xml"
    blank.write_text(three_joints().replace('model="m"', 'model="  "'))
    for path, name in ((named, "ur5e_arm"), (unnamed, "left_arm"), (blank, "right_arm")):
        spec = mjcf.load_mjcf(path, Options(base="b0", tip="b4"))
        assert spec.name == name


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_a_thin_reach_s_poses_near_its_edge_are_answered(backend, tmp_path):
    """robosuite's Kinova Gen3, joints 3-6 (HalfArm1_Link to SphericalWrist2_Link; tip on
    axis 6, so joint 6 is free): the tip lies 0.175 mm from axis 5, so what joints 3-5 reach
    is a shell 14 um thick, and the MJCF's twists (90.00024 deg, snapped) move its edge.
    Near the edge (joint 5 within 0.14 rad of 180 deg) the nominal table's quadratic in
    tan(theta3/2) has an imaginary pair 0.041-0.062 from real, beyond the near-double root's
    window (sqrt(_SEED_TOL) = 0.039): 265 of 400 such poses got no row in either backend (a
    new user's attack). The second pass now seeds every complex root's real part: each sample
    answered, every row on the pose."""
    path = DATA / "kinova3_robot.xml"
    text, _ = mjcf.import_mjcf(path, Options(base="HalfArm1_Link", tip="SphericalWrist2_Link"))
    module = build_module(text, tmp_path, c=backend == "c")
    assert module._SEED_TOL > 0.0 and module.FREE == (4,)  # (refined; joint 4 free)
    rng = np.random.default_rng(1)
    Q = rng.uniform(-2.0, 2.0, (300, 4))
    Q[:200, 2] = rng.uniform(3.0, math.pi, 200) * rng.choice([-1.0, 1.0], 200)
    for q in Q:
        T = module.fk(q)
        rows = module.ik(T, free=[q[3]], backend=backend)
        assert len(rows) > 0, q
        E = module.fk_batch(rows)
        assert np.abs(E[:, :3, 3] - T[:3, 3]).max() <= 1e-9 * module.REACH, q


# joint vectors of robosuite's ARX5 (tests/data/mjcf/arx5_robot.xml) near two singular
# configurations at once: the wrist within 1e-9 to 1.6e-2 of straight (q5 near +-90 deg) and
# the shoulder singular to 5e-9 or less (a new user's attack, helper 70)
ARX5_SINGULAR = [
    (
        -0.5149758458112705,
        -1.8351569028065982,
        2.542959785740689,
        -0.8874420176801667,
        1.5705173691381287,
        -0.8897610397278859,
    ),  # band_ws #1826
    (
        -2.928771916559219,
        1.1373720466332822,
        2.2119781896394937,
        0.04038574375219328,
        1.5708380160737496,
        0.9171205874867692,
    ),  # root_q5 #1166
    (
        0.924934078482849,
        1.416312784049393,
        2.7060202207150192,
        0.18355447734553687,
        1.5671357930071546,
        1.6299390597029975,
    ),  # wrist+shoulder #699
    (
        0.94044033647143,
        -1.145781240135167,
        -2.7540853768392193,
        0.733129427511217,
        -1.5819225007667932,
        -2.8952576469244486,
    ),  # wrist+shoulder #717
    (
        1.0278932304685844,
        -1.191156924307522,
        -2.8731681404886986,
        0.9618699450059784,
        -1.587087814187476,
        2.15136378859233,
    ),  # wrist+shoulder #723
    (
        2.848386801359835,
        -2.0274660379637885,
        2.0284678553023108,
        0.16209671333882403,
        -1.5718449952028242,
        -3.0739779555265874,
    ),  # wrist+shoulder #758
    (
        2.349801103476641,
        1.1147010797919794,
        2.1645796326281683,
        0.21215397093060817,
        1.5707909561078672,
        2.3077785227484977,
    ),  # grid d1=1e-7 d2=1e-9
    (
        2.7498374541761894,
        1.2618120376437414,
        2.399515706762137,
        0.3457285292389565,
        -1.5707017974819264,
        2.6649548929573212,
    ),  # grid d1=1e-4 d2=1e-9
    (
        -1.8056692344730865,
        1.2543038516197198,
        2.4488584998218474,
        -0.10213435219762257,
        -1.5707017974819264,
        0.3456141235779775,
    ),  # grid d1=1e-4 d2=1e-3
    (
        2.0702297126875786,
        -1.9304158742341713,
        2.203241249117334,
        0.17682166060631488,
        -1.5718017974819263,
        2.292555757927868,
    ),  # grid d1=1e-3 d2=0
    (
        -0.661326454343075,
        1.3993366873682236,
        2.651011744447822,
        0.29811212820352795,
        -1.5808017974819264,
        2.9308875726356733,
    ),  # grid d1=1e-2 d2=1e-9
    (
        -1.6485851943294751,
        1.6793280556230874,
        -3.0518764509746075,
        -0.02489596591731713,
        -1.5808017974819264,
        -2.6951864803381334,
    ),  # grid d1=1e-2 d2=1e-5
]


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_poses_near_two_singular_configurations_at_once_are_answered(backend, tmp_path):
    """robosuite's ARX5 (axes 2-4 parallel, the table 1.4e-5 from the MJCF, refined onto its
    frames): at these poses the nominal table's closed form gives no seed in the first pass
    and seeds 1e-2 to 0.15 from the pose in the second, beyond _SEED_TOL (1.4e-3), where
    ik_approximate's refinement of the same seeds reached the pose to 1e-15: ik answered
    nothing at all 12 (both backends). The second pass now refines such a seed for a trial
    (_TRIAL_SEED, _TRIAL_PATIENCE) and in full where the trial brings it within _SEED_TOL:
    each answered, every row on the pose to 1e-9 (the second pass's bound, _REFINE_STALL: a
    row 1.5e-10 off is one)."""
    text, _ = mjcf.import_mjcf(DATA / "arx5_robot.xml", Options(base="base", tip="right_hand"))
    module = build_module(text, tmp_path, c=backend == "c")
    assert module._SEED_TOL > 0.0 and module.METHOD == "three-parallel"
    for q in ARX5_SINGULAR:
        T = module.fk(np.array(q))
        rows = module.ik(T, backend=backend)
        assert len(rows) > 0, q
        E = module.fk_batch(rows)
        assert np.abs(E[:, :3, :3] - T[:3, :3]).max() <= 1e-9, q
        assert np.abs(E[:, :3, 3] - T[:3, 3]).max() <= 1e-9 * module.REACH, q


# UFACTORY Lite 6 (MuJoCo Menagerie): poses 3e-9 to 1.3e-8 from singular (wrist centre near
# axis 1) where C's rows filled the room for rows and missed the sampled vector (a new user's
# attack, helper 73)
LITE6_NEAR_SINGULAR = [
    [0.9475511127238638, -1.49394932943911, 0.32257708566619187, 2.7947892862492676,
     -0.5223529383851859, -1.1997567961397333],
    [0.32484051483736653, 1.4093776475475064, 0.09856154599834485, 1.4315739179568965,
     -2.0974020667674416, -2.4482125928125313],
    [-2.785284931105098, -0.12060784864773724, 2.5568792232958777, -0.3443589353055061,
     -1.8938744835728667, 1.1492778791038605],
    [-2.2888732699064427, 1.7907054534211166, 0.4952870332491348, -1.3613689303802803,
     1.998462425388178, -2.9795411829008196],
    [-1.11093713890103, 1.8219120966859943, 0.5364385486980631, -2.472935130180477,
     0.853271508192996, 1.6112935421266048],
]  # fmt: skip


@pytest.mark.parametrize("backend", ["python", pytest.param("c", marks=needs_cc)])
def test_rows_stalled_on_a_valley_near_a_singular_pose_leave_room_for_the_others(backend, tmp_path):
    """At these poses the Lite 6's exact arm (its table 1.2e-5 from the MJCF, refined onto its
    frames) has a valley of points within the row limit of the pose: seeds stalled at points of
    it (5.5e-11 and 1.2e-11 off, 3.6e-3 and 9e-4 from a row within 5.6e-16) and C kept 16 such
    rows, all on one elbow, the other elbow's lost with the sampled vector (3 rad from the
    nearest row). A row that is a point its refinement stalled at beside another, where J is
    so singular that the valley between them is within the row limit and their midpoint refined
    lands on the other, is that row (_stalled_beside, dk_stalled_beside): both elbows are
    answered, the sampled vector among the rows, with room to spare."""
    text, _ = mjcf.import_mjcf(DATA / "lite6.xml", Options(base="link_base", tip="link6"))
    module = build_module(text, tmp_path, c=backend == "c")
    assert module._SEED_TOL > 0.0
    for q in LITE6_NEAR_SINGULAR:
        T = module.fk(np.array(q))
        rows = module.ik(T, backend=backend)
        assert len(rows) < module.MAX_SOLUTIONS, q
        assert (rows[:, 1] > 0).any() and (rows[:, 1] < 0).any(), q
        gap = np.abs(np.remainder(rows - np.array(q) + np.pi, 2 * np.pi) - np.pi).max(axis=1)
        assert gap.min() <= 1e-6, q
        # (rows on the pose to 1e-9: a point of the valley the last Newton step leaves
        # unmeasured can end a little beyond 1e-10, 1.08e-10 here; README, poses singular)
        E = module.fk_batch(rows)
        assert np.abs(E[:, :3, :3] - T[:3, :3]).max() <= 1e-9, q
        assert np.abs(E[:, :3, 3] - T[:3, 3]).max() <= 1e-9 * module.REACH, q
