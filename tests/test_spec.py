"""Spec validation: every bad input gets a one-line error naming file, field and what is allowed."""

from __future__ import annotations

import math

import pytest

from derive.spec import SpecError, load_spec, parse_spec

from conftest import ROOT, spec_text

GOOD = spec_text("arm", "standard", [(-90, 0, 0.5, 0), (0, 1, 0, 0)])


def test_bundled_specs_load():
    spec = load_spec(ROOT / "derive" / "arms" / "puma560.toml")
    assert spec.name == "puma560" and spec.dof == 6 and spec.joint_types == "RRRRRR"
    assert spec.joints[2].d == 0.149 and spec.joints[5].limits == (-260.0, 260.0)


def test_digest_ignores_layout_but_not_values():
    spaced = GOOD.replace("\n", "\n\n").replace(" = ", "   =   ")
    assert parse_spec(GOOD).digest() == parse_spec(spaced).digest()
    assert parse_spec(GOOD).digest() != parse_spec(GOOD.replace("a = 1.0", "a = 1.5")).digest()


BAD = [
    (GOOD.replace('name = "arm"', 'name = "Arm-1"'), "name"),
    (GOOD.replace('name = "arm"', 'name = "import os; os.system(1)"'), "name"),
    (GOOD.replace('name = "arm"', 'name = "../evil"'), "name"),
    (GOOD.replace('name = "arm"', 'name = "class"'), "name"),
    (GOOD.replace('name = "arm"', "name = 3"), "name: must be a string"),
    (GOOD.replace('name = "arm"\n', ""), "name: missing"),
    (GOOD.replace('"standard"', '"craig"'), "convention"),
    (GOOD.replace('angle_unit = "deg"', 'angle_unit = "grad"'), "angle_unit"),
    (GOOD.replace('angle_unit = "deg"', 'angle_unit = "rad"'), "joint 1: alpha: -90 is beyond"),
    (GOOD + "colour = 1\n", "colour: unknown key"),
    (GOOD.replace("a = 1.0", "a = 1.0\nb = 2.0"), "joint 2: b: unknown key"),
    (GOOD.replace("a = 1.0", 'a = "1.0"'), "joint 2: a: must be a number"),
    (GOOD.replace("a = 1.0", "a = \"__import__('os')\""), "joint 2: a: must be a number"),
    (GOOD.replace("a = 1.0", "a = true"), "joint 2: a: must be a number"),
    (GOOD.replace("a = 1.0", "a = nan"), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = inf"), "joint 2: a"),
    (GOOD.replace("a = 1.0", "a = 1e300"), "joint 2: a"),
    (GOOD.replace("a = 1.0\n", ""), "joint 2: a: missing"),
    (GOOD.replace('type = "R"', 'type = "X"', 1), "joint 1: type"),
    (GOOD + "limits = [10.0, -10.0]\n", "joint 2: limits"),
    (GOOD + "limits = [1.0]\n", "joint 2: limits"),
    (
        'name = "arm"\nconvention = "standard"\nangle_unit = "deg"\nlength_unit = "m"\n',
        "joint: missing",
    ),
    (GOOD + "[base]\nmatrix = [[1,0,0,0],[0,1,0,0],[0,0,2,0],[0,0,0,1]]\n", "base.matrix"),
    (GOOD + "[tool]\nmatrix = [[1,0,0,0],[0,1,0,0],[0,0,-1,0],[0,0,0,1]]\n", "tool.matrix"),
    (GOOD + "[tool]\nmatrix = [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,1,1]]\n", "tool.matrix"),
    (GOOD + "[tool]\nmatrix = [[1,0,0],[0,1,0],[0,0,1]]\n", "tool.matrix"),
    (GOOD + "[tool]\nrpy = [0, 0, 0]\n", "tool"),
    (GOOD + "[tool]\ntranslation = [0, 0]\n", "tool.translation"),
    (GOOD + "[tool]\ntranslation = [0, 0, 1]\nsize = 2\n", "tool.size: unknown key"),
    ("name = \n", "not valid TOML"),
    (b"\xff\xfe\x00garbage", "not UTF-8"),
    ("a = " + "[" * 2000 + "]" * 2000, "not valid TOML"),
]


@pytest.mark.parametrize("text, field", BAD)
def test_bad_spec_names_file_and_field(text, field):
    with pytest.raises(SpecError) as info:
        parse_spec(text, "arm.toml")
    message = str(info.value)
    assert message.startswith("arm.toml: ")
    assert field in message
    assert "\n" not in message


def test_missing_file_is_a_spec_error(tmp_path):
    with pytest.raises(SpecError, match="cannot read"):
        load_spec(tmp_path / "nope.toml")


def test_units_convert_to_radians():
    rad = parse_spec(
        spec_text("arm", "standard", [(-math.pi / 2, 0, 0.5, 0), (0, 1, 0, 0)], unit="rad")
    )
    deg = parse_spec(GOOD)
    assert rad.joints[0].alpha == pytest.approx(math.radians(deg.joints[0].alpha))
