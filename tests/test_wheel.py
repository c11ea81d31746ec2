"""derive-ik as users install it: the wheel, in a fresh virtual environment, away from the
source tree. Slow (it builds the wheel and installs its dependencies): about a minute."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT, USER_ROWS, spec_text

USER_ARM = spec_text("wheel_arm", "modified", USER_ROWS)


def call(command: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    return subprocess.run(command, capture_output=True, text=True, cwd=cwd, env=env, timeout=900)


@pytest.fixture(scope="module")
def venv(tmp_path_factory) -> Path:
    """A fresh virtual environment with the wheel built from this checkout installed, and a
    poisoned top-level `templates/` folder in its site-packages."""
    base = tmp_path_factory.mktemp("wheel")
    # pip builds a local folder in place (its build/ folder): a copy, so that two test workers
    # building at once do not share one build/ (CI failed on 'File exists: build/bdist...'),
    # and the checkout is left as it was
    source = base / "source"
    shutil.copytree(
        ROOT,
        source,
        ignore=shutil.ignore_patterns(
            ".git", ".venv", "build", "*.egg-info", "__pycache__", ".pytest_cache", "generated"
        ),
    )
    built = call(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "--no-deps",
            "--quiet",
            "--disable-pip-version-check",
            str(source),
            "-w",
            str(base / "dist"),
        ],
        base,
    )
    assert built.returncode == 0, built.stderr
    wheels = list((base / "dist").glob("derive_ik-*.whl"))
    assert len(wheels) == 1
    env = base / "env"
    assert call([sys.executable, "-m", "venv", str(env)], base).returncode == 0
    installed = call(
        [
            str(env / "bin" / "python"),
            "-m",
            "pip",
            "install",
            "--quiet",
            "--disable-pip-version-check",
            str(wheels[0]),
        ],
        base,
    )
    assert installed.returncode == 0, installed.stderr
    purelib = call(
        [
            str(env / "bin" / "python"),
            "-c",
            "import sysconfig; print(sysconfig.get_paths()['purelib'])",
        ],
        base,
    )
    poisoned = Path(purelib.stdout.strip()) / "templates"
    poisoned.mkdir()
    for name in ("module.py.j2", "report.md.j2", "__init__.py"):
        (poisoned / name).write_text("import os  # injected\n")
    return env


def test_the_wheel_generates_checks_reports_and_solves(venv, tmp_path):
    derive = str(venv / "bin" / "derive")
    work = tmp_path / "project"
    work.mkdir()
    where = call(
        [str(venv / "bin" / "python"), "-c", "import derive; print(derive.__file__)"], work
    )
    assert str(ROOT) not in where.stdout and "site-packages" in where.stdout
    # a bundled arm: the same bytes as the committed files, poisoned templates ignored
    result = call([derive, "generate", "puma560", "--out", "g"], work)
    assert result.returncode == 0, result.stderr
    for name in ("puma560.py", "puma560.md", "derive_ik_runtime.py"):
        assert (work / "g" / name).read_bytes() == (ROOT / "generated" / name).read_bytes()
    # a user's spec
    (work / "arms").mkdir()
    spec = work / "arms" / "wheel_arm.toml"
    spec.write_text(USER_ARM)
    assert call([derive, "generate", str(spec), "--out", "g"], work).returncode == 0
    assert call([derive, "check", str(spec), "--out", "g"], work).returncode == 0
    module = work / "g" / "wheel_arm.py"
    module.write_text(module.read_text() + "# edited\n")
    stale = call([derive, "check", str(spec), "--out", "g"], work)
    assert stale.returncode == 1 and "differs from the regenerated file" in stale.stdout
    bad = work / "arms" / "bad.toml"
    bad.write_text(USER_ARM.replace("a = 0.5", 'a = "0.5"'))
    refused = call([derive, "check", str(bad), "--out", "g"], work)
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1
    report = call([derive, "report", "puma560", "-o", "puma.md"], work)
    assert report.returncode == 0 and "Pieper" in (work / "puma.md").read_text()
    solve = call([derive, "solve", "puma560", "--q", "20", "20", "20", "20", "20", "20"], work)
    assert solve.returncode == 0 and "8 solution(s)" in solve.stdout
    assert call([derive, "fk", "planar_2r", "30", "40"], work).returncode == 0


def test_the_generated_module_works_from_another_folder(venv, tmp_path):
    derive = str(venv / "bin" / "derive")
    assert call([derive, "generate", "puma560", "--out", "vendored"], tmp_path).returncode == 0
    elsewhere = tmp_path / "robot_code"
    elsewhere.mkdir()
    script = (
        "import sys; sys.path.insert(0, sys.argv[1]); import numpy as np, puma560 as m;"
        "q = np.radians([20.0] * 6); sols = m.ik(m.fk(q), backend='python');"
        "print(len(sols), min(np.abs(s - q).max() for s in sols) < 1e-9)"
    )
    result = call(
        [str(venv / "bin" / "python"), "-c", script, str(tmp_path / "vendored")], elsewhere
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["8", "True"]
