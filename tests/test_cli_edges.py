"""The command line at its edges: file modes, leftovers, encodings, pipes, unwritable paths,
names that would shadow modules, and templates that must come from the package only."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from derive.cli import main

from conftest import ROOT, spec_text

ARM = spec_text("edge_arm", "standard", [(0, 1, 0, 0), (0, 1, 0, 0)])


def run(*args: str, cwd: Path, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "derive", *args], capture_output=True, text=True, cwd=cwd, env=env
    )


def mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def test_new_files_get_the_umask_mode_and_existing_files_keep_theirs(tmp_path):
    spec = tmp_path / "edge_arm.toml"
    spec.write_text(ARM)
    out = tmp_path / "out"
    old = os.umask(0o022)
    try:
        assert main(["generate", str(spec), "--out", str(out)]) == 0
        assert mode(out / "edge_arm.py") == 0o644
        assert mode(out / "edge_arm.md") == 0o644
        os.chmod(out / "edge_arm.py", 0o640)
        assert main(["generate", str(spec), "--out", str(out)]) == 0
        assert mode(out / "edge_arm.py") == 0o640
        os.umask(0o077)
        (out / "edge_arm.md").unlink()
        assert main(["generate", str(spec), "--out", str(out)]) == 0
        assert mode(out / "edge_arm.md") == 0o600
    finally:
        os.umask(old)


def test_leftovers_of_a_killed_run_are_removed(tmp_path):
    spec = tmp_path / "edge_arm.toml"
    spec.write_text(ARM)
    out = tmp_path / "out"
    out.mkdir()
    leftover = out / ".edge_arm.py.k2j3h4.derive-tmp"
    leftover.write_text("partial")
    other = out / ".other.py.x.derive-tmp"  # another arm's, possibly in flight: kept
    other.write_text("partial")
    assert main(["generate", str(spec), "--out", str(out)]) == 0
    assert not leftover.exists() and other.exists()
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "edge_arm.md",
        "edge_arm.py",
    ]


def test_a_spec_with_a_byte_order_mark_loads(tmp_path):
    spec = tmp_path / "edge_arm.toml"
    spec.write_bytes(b"\xef\xbb\xbf" + ARM.encode())
    assert main(["generate", str(spec), "--out", str(tmp_path / "out")]) == 0


def test_check_compares_bytes_and_says_so(tmp_path, capsys):
    spec = tmp_path / "edge_arm.toml"
    spec.write_text(ARM)
    out = tmp_path / "out"
    assert main(["generate", str(spec), "--out", str(out)]) == 0
    assert main(["check", str(spec), "--out", str(out)]) == 0
    path = out / "edge_arm.py"
    path.write_bytes(path.read_bytes().replace(b"\n", b"\r\n"))
    capsys.readouterr()
    assert main(["check", str(spec), "--out", str(out)]) == 1
    assert "in bytes, not in lines (line endings" in capsys.readouterr().out


@pytest.mark.parametrize("name", ["numpy", "numba", "typing", "token", "math", "json", "derive"])
def test_names_that_shadow_modules_are_refused(tmp_path, name):
    spec = tmp_path / "arm.toml"
    spec.write_text(ARM.replace('name = "edge_arm"', f'name = "{name}"'))
    result = run("generate", str(spec), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert f"name: '{name}' is the name of a module" in lines[0]
    assert not (tmp_path / "out").exists()


def test_one_bad_spec_is_one_line(tmp_path):
    spec = tmp_path / "bad.toml"
    spec.write_text("name = 1")
    result = run("generate", str(spec), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "other arms" not in result.stderr


def test_report_to_an_unwritable_path_is_one_line(tmp_path):
    result = run(
        "report", "planar_2r", "-o", str(tmp_path / "missing" / "x" / "r.md"), cwd=tmp_path
    )
    # the folder is created; a path under a file cannot be
    assert result.returncode == 0
    blocker = tmp_path / "file"
    blocker.write_text("")
    result = run("report", "planar_2r", "-o", str(blocker / "r.md"), cwd=tmp_path)
    assert result.returncode == 2
    assert result.stderr.startswith("error: ") and result.stderr.count("\n") == 1
    assert "Traceback" not in result.stderr


def test_a_closed_pipe_is_no_traceback(tmp_path):
    """`derive solve ... | head -1`: the reader is gone before the output is written."""
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "derive",
            "solve",
            "puma560",
            "--q",
            "20",
            "20",
            "20",
            "20",
            "20",
            "20",
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait() == 141
    assert err == ""


def test_templates_come_from_the_package_only(tmp_path):
    """A `templates/` folder with a module.py.j2 on sys.path, first in line, changes nothing."""
    poisoned = tmp_path / "site" / "templates"
    poisoned.mkdir(parents=True)
    for name in ("module.py.j2", "report.md.j2"):
        (poisoned / name).write_text("import os  # injected\n")
    (poisoned / "__init__.py").write_text("")
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "site"))
    out = tmp_path / "out"
    result = run("generate", "planar_2r", "--out", str(out), cwd=tmp_path / "site", env=env)
    assert result.returncode == 0, result.stderr
    for name in ("planar_2r.py", "planar_2r.md"):
        assert (out / name).read_bytes() == (ROOT / "generated" / name).read_bytes()
