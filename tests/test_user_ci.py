"""Regeneration checks in a user's project: `derive check SPEC --out DIR`, the pre-commit hook."""

from __future__ import annotations

import re
import shlex
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
import yaml

from derive.cli import main

from conftest import ROOT, spec_text

USER_ARM = spec_text(
    "user_arm",
    "standard",
    [
        (-90, 0, 0.3, 0),
        (0, 0.4, 0, 0),
        (-90, 0.05, 0, 0),
        (90, 0, 0.35, 0),
        (-90, 0, 0, 0),
        (0, 0, 0.08, 0),
    ],
)
OTHER_ARM = spec_text("other_arm", "standard", [(0, 0.3, 0, 0), (0, 0.2, 0, 0)])


def project(tmp_path: Path) -> tuple[Path, Path, Path]:
    """A user's project: arms/user_arm.toml, arms/other_arm.toml and generated/ for both."""
    arms, out = tmp_path / "arms", tmp_path / "generated"
    arms.mkdir()
    (arms / "user_arm.toml").write_text(USER_ARM)
    (arms / "other_arm.toml").write_text(OTHER_ARM)
    assert (
        main(
            [
                "generate",
                str(arms / "user_arm.toml"),
                str(arms / "other_arm.toml"),
                "--out",
                str(out),
            ]
        )
        == 0
    )
    return arms / "user_arm.toml", arms / "other_arm.toml", out


def check(capsys, *args: str) -> tuple[int, str]:
    capsys.readouterr()
    code = main(["check", *args])
    return code, capsys.readouterr().out


def test_fresh_user_arm_passes_and_check_writes_nothing(tmp_path, capsys):
    spec, _, out = project(tmp_path)
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    code, text = check(capsys, str(spec), "--out", str(out))
    assert code == 0, text
    assert "up to date (6 files)" in text
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_edited_generated_file_is_named(tmp_path, capsys):
    spec, _, out = project(tmp_path)
    module = out / "user_arm.py"
    module.write_text(module.read_text().replace("REACH = ", "REACH = 2 * "))
    code, text = check(capsys, str(spec), "--out", str(out))
    assert code == 1
    assert f"{module}: differs from the regenerated file" in text
    assert "-REACH = 2 * " in text
    assert f"to update: derive generate {spec} --out {out}" in text


def test_deleted_generated_file_is_named(tmp_path, capsys):
    spec, _, out = project(tmp_path)
    (out / "user_arm.md").unlink()
    code, text = check(capsys, str(spec), "--out", str(out))
    assert code == 1
    assert f"{out / 'user_arm.md'}: missing" in text


def test_changed_spec_makes_the_committed_files_stale(tmp_path, capsys):
    spec, _, out = project(tmp_path)
    spec.write_text(USER_ARM.replace("a = 0.4", "a = 0.45"))
    code, text = check(capsys, str(spec), "--out", str(out))
    assert code == 1
    assert f"{out / 'user_arm.py'}: differs" in text
    assert f"{out / 'user_arm.md'}: differs" in text


def test_other_arms_files_are_ignored_when_only_one_spec_is_named(tmp_path, capsys):
    spec, other, out = project(tmp_path)
    (out / "other_arm.py").write_text("# edited by hand\n")
    (out / "unrelated.py").write_text("")
    code, text = check(capsys, str(spec), "--out", str(out))
    assert code == 0, text
    code, text = check(capsys, str(other), "--out", str(out))
    assert code == 1 and "other_arm.py: differs" in text


def test_bad_spec_in_check_exits_2(tmp_path, capsys):
    spec = tmp_path / "arms" / "bad.toml"
    spec.parent.mkdir()
    spec.write_text(USER_ARM.replace('convention = "standard"', 'convention = "craig"'))
    assert main(["check", str(spec), "--out", str(tmp_path / "generated")]) == 2
    assert f"{spec}: convention:" in capsys.readouterr().err


ISOLATED = textwrap.dedent("""
    import sys
    sys.modules["derive"] = None          # `import derive` now fails: derive-ik is not there
    sys.path.insert(0, sys.argv[1])
    import numpy as np
    import user_arm
    q = np.radians([10.0, -35.0, 50.0, 20.0, 40.0, -60.0])
    T = user_arm.fk(q)
    sols = user_arm.ik(T)
    hit = min(np.abs(np.angle(np.exp(1j * (s - q)))).max() for s in sols)
    print(len(sols), hit, max(np.abs(user_arm.fk(s) - T).max() for s in sols))
""")


def test_generated_module_runs_where_derive_is_not_importable(tmp_path):
    _, _, out = project(tmp_path)
    elsewhere = tmp_path / "robot_package" / "kinematics"
    elsewhere.mkdir(parents=True)
    for name in ("user_arm.py", "derive_ik_runtime.py"):
        shutil.copy(out / name, elsewhere / name)
    result = subprocess.run(
        [sys.executable, "-I", "-c", ISOLATED, str(elsewhere)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
    assert result.returncode == 0, result.stderr
    count, hit, residual = result.stdout.split()
    assert int(count) >= 1 and float(hit) < 1e-9 and float(residual) < 1e-9


def derive_command() -> list[str]:
    """The `derive` console script of this environment (what pre-commit would run)."""
    script = Path(sys.executable).parent / "derive"
    found = str(script) if script.is_file() else shutil.which("derive")
    if found is None:
        pytest.fail("the `derive` console script is not installed; install the project first")
    return [found]


def hook() -> dict:
    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    (entry,) = [h for h in hooks if h["id"] == "derive-ik-check"]
    assert entry["pass_filenames"] is True and entry["language"] == "python"
    return entry


def git(repo: Path, *args: str) -> str:
    result = subprocess.run(
        ["git", "-c", "user.name=t", "-c", "user.email=t@t", *args],
        cwd=repo,
        capture_output=True,
        text=True,
        check=True,
    )
    return result.stdout


def run_hook(repo: Path, entry: dict) -> subprocess.CompletedProcess | None:
    """What pre-commit does: the entry with the staged files matching `files` appended."""
    staged = git(repo, "diff", "--cached", "--name-only").split()
    files = [f for f in staged if re.search(entry["files"], f)]
    if not files:
        return None
    command = derive_command() + shlex.split(entry["entry"])[1:] + entry.get("args", []) + files
    return subprocess.run(command, cwd=repo, capture_output=True, text=True)


@pytest.mark.skipif(shutil.which("git") is None, reason="the hook test needs git")
def test_pre_commit_hook_entry_on_a_temporary_repository(tmp_path):
    entry = hook()
    repo = tmp_path / "repo"
    (repo / "arms").mkdir(parents=True)
    git(repo, "init", "-q")
    (repo / "arms" / "user_arm.toml").write_text(USER_ARM)
    (repo / "pyproject.toml").write_text("[project]\nname = 'robot'\n")
    git(repo, "add", "arms/user_arm.toml", "pyproject.toml")
    stale = run_hook(repo, entry)  # spec committed, nothing generated
    assert stale is not None and stale.returncode == 1, stale.stderr
    assert "generated/user_arm.py: missing" in stale.stdout
    assert "Traceback" not in stale.stderr
    subprocess.run(
        [*derive_command(), "generate", "arms/user_arm.toml"],
        cwd=repo,
        check=True,
        capture_output=True,
    )
    git(repo, "add", "generated")
    fresh = run_hook(repo, entry)
    assert fresh is not None and fresh.returncode == 0, fresh.stdout + fresh.stderr
    git(repo, "commit", "-q", "-m", "arm")
    (repo / "arms" / "user_arm.toml").write_text(USER_ARM.replace("d = 0.35", "d = 0.36"))
    git(repo, "add", "arms/user_arm.toml")
    edited = run_hook(repo, entry)  # spec changed, solver not regenerated
    assert edited is not None and edited.returncode == 1
    assert "generated/user_arm.py: differs" in edited.stdout
    git(repo, "reset", "-q", "--hard")
    (repo / "README.md").write_text("robot\n")
    git(repo, "add", "README.md")
    assert run_hook(repo, entry) is None  # no spec touched: the hook is not run
