"""The command line: exit codes, atomic writes, check, fk and solve."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from derive.cli import main

from conftest import GENERATED, ROOT, USER_ROWS, spec_text

USER_ARM = spec_text("user_arm", "modified", USER_ROWS)


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "derive", *args], capture_output=True, text=True, cwd=cwd or ROOT
    )


def test_generate_writes_module_and_reports_structure(tmp_path, capsys):
    spec = tmp_path / "user_arm.toml"
    spec.write_text(USER_ARM)
    assert main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith("user_arm: spherical wrist at joints 4-6; IK pieper")
    assert line.endswith(" s")
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "derive_ik_runtime.h",
        "derive_ik_runtime.py",
        "user_arm.md",
        "user_arm.py",
        "user_arm_ik.c",
        "user_arm_ik.h",
    ]


def test_bad_spec_exits_2_without_traceback_or_file(tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text(USER_ARM.replace("a = 0.5", 'a = "0.5"'))
    result = run("generate", str(spec), "--out", str(tmp_path / "out"))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert f"{spec}: joint 3: a: must be a number" in result.stderr
    assert not (tmp_path / "out").exists()


def test_failure_part_way_keeps_earlier_files(tmp_path, capsys):
    good = tmp_path / "user_arm.toml"
    good.write_text(USER_ARM)
    bad = tmp_path / "bad.toml"
    bad.write_text("name = 1")
    out = tmp_path / "out"
    assert main(["generate", str(good), str(bad), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"1 arm(s) failed ({bad}); the other arms were written" in err
    assert (out / "user_arm.py").is_file()
    assert sorted(p.name for p in out.iterdir()) == [
        "derive_ik_runtime.h",
        "derive_ik_runtime.py",
        "user_arm.md",
        "user_arm.py",
        "user_arm_ik.c",
        "user_arm_ik.h",
    ]


def test_unknown_arm_name_exits_2(capsys):
    assert main(["fk", "no_such_arm", "0"]) == 2
    assert "bundled arms: iiwa14, lecture_6r, lecture_rrr, locobot_head, manocha_canny" in (
        capsys.readouterr().err
    )


def test_require_ik_exits_3_for_fk_only_arm(tmp_path):
    # (three joints whose axes meet at the tool point: it cannot move, so no task fits; a
    # four-joint arm that had none gets the position, one joint free, since that fallback)
    spec = tmp_path / "four.toml"
    rows = [(90, 0, 0, 0), (-90, 0, 0, 0), (0, 0, 0, 0)]
    spec.write_text(spec_text("four", "standard", rows))
    assert main(["generate", str(spec), "--out", str(tmp_path)]) == 0
    assert main(["generate", str(spec), "--out", str(tmp_path), "--require-ik"]) == 3


def test_check_detects_edited_removed_and_extra_files(tmp_path, capsys):
    # the committed output (test_regeneration checks it is today's), copied: one whole
    # generation fewer); a two-joint arm's check regenerates in a third of a PUMA's time)
    out = tmp_path / "gen"
    shutil.copytree(GENERATED, out, ignore=shutil.ignore_patterns("__pycache__"))
    assert main(["check", "planar_2r", "--out", str(out)]) == 0
    target = out / "planar_2r.py"
    original = target.read_text()
    target.write_text(original.replace("DOF = 2", "DOF = 3"))
    before = target.read_bytes()
    capsys.readouterr()
    assert main(["check", "planar_2r", "--out", str(out)]) == 1
    report = capsys.readouterr().out
    assert (
        f"{target}: differs" in report
        and "-DOF = 3" in report
        and "to update: derive generate" in report
    )
    assert target.read_bytes() == before
    target.unlink()
    assert main(["check", "planar_2r", "--out", str(out)]) == 1
    assert "planar_2r.py: missing" in capsys.readouterr().out
    target.write_text(original)
    # the C files the module runs are checked with it
    c_file = out / "planar_2r_ik.c"
    c_text = c_file.read_text()
    c_file.write_text(c_text.replace("#define DK_MAX 2", "#define DK_MAX 3"))
    assert main(["check", "planar_2r", "--out", str(out)]) == 1
    report = capsys.readouterr().out
    assert f"{c_file}: differs" in report and "to update: derive generate planar_2r" in report
    c_file.write_text(c_text)
    (out / "old_arm.py").write_text("")
    (out / "old_arm_ik.c").write_text("")
    assert main(["check", "--out", str(out)]) == 1
    report = capsys.readouterr().out
    assert "old_arm.py: not generated" in report and "old_arm_ik.c: not generated" in report


def test_fk_command_prints_report_pose():
    result = run("fk", "puma560", "20", "20", "20", "20", "20", "20")
    assert result.returncode == 0
    first = [float(x) for x in result.stdout.splitlines()[0].split()]
    assert first == pytest.approx(
        [0.1057541557, -0.6425141384, 0.7589411311, 0.5776495331], abs=1e-9
    )


def test_solve_command_lists_eight_solutions_with_limits():
    result = run("solve", "puma560", "--q", "20", "20", "20", "20", "20", "20")
    assert result.returncode == 0, result.stderr
    assert "8 solution(s)" in result.stdout
    rows = [ln for ln in result.stdout.splitlines() if "residual" in ln]
    assert len(rows) == 8
    assert any("out of limits" in r for r in rows)
    assert all(float(r.split("residual")[1].split()[0]) < 1e-9 for r in rows)
    # (each row's branch: the signs of the q3, q2 and q5 steps, the 8 configurations)
    assert "(branch: the signs of the steps of q3, q2, q5; 0 at a fold)" in result.stdout
    assert {r.split("branch ")[1].split()[0] for r in rows} == {
        a + b + c for a in "+-" for b in "+-" for c in "+-"
    }


def test_solve_rejects_non_rigid_pose():
    result = run("solve", "puma560", "--pose", "1 0 0 0.5 0 2 0 0 0 0 1 0.2")
    assert result.returncode == 2 and "not orthonormal" in result.stderr
    assert "Traceback" not in result.stderr


def test_bench_reports_round_trip_figures(capsys):
    import json

    # --n: --samples; a small --batch (its timing is not what is tested)
    assert main(["bench", "puma560", "--n", "30", "--batch", "2000", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)[0]
    assert figures["name"] == "puma560" and figures["samples"] == 30
    assert figures["unsound"] == 0 and figures["completeness"] == 1.0
    assert figures["ik_us"] > 0 and figures["generate_s"] > 0
    # which numpy and BLAS ran (issue 37 item 19: the general method's last bits hang on them)
    assert f"numpy {np.__version__}" in figures["machine"] and "CPU" in figures["machine"]


def test_solve_residual_is_over_what_the_solver_reproduces(capsys):
    """A positioning arm (planar_2r) reproduces the tool point, not its heading: its second
    solution printed 'residual 1.0e+00' (the rotation entries) though it is exact."""
    assert main(["solve", "planar_2r", "--q", "0", "90"]) == 0
    residuals = [float(r) for r in re.findall(r"residual (\S+)", capsys.readouterr().out)]
    assert len(residuals) == 2 and max(residuals) < 1e-12
