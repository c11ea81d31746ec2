"""The command line at its edges: file modes, leftovers, encodings, pipes, unwritable paths,
names that would shadow modules, and templates that must come from the package only."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import time
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
    old = time.time() - 120.0  # (a minute old: a killed run's; younger, another run's now)
    os.utime(leftover, (old, old))
    young = out / ".edge_arm.md.x7.derive-tmp"  # another run writing it now: kept
    young.write_text("partial")
    other = out / ".other.py.x.derive-tmp"  # another arm's, possibly in flight: kept
    other.write_text("partial")
    os.utime(other, (old, old))
    assert main(["generate", str(spec), "--out", str(out)]) == 0
    assert not leftover.exists() and other.exists() and young.exists()
    assert sorted(p.name for p in out.iterdir() if not p.name.startswith(".")) == [
        "derive_ik_runtime.h",
        "derive_ik_runtime.py",
        "edge_arm.md",
        "edge_arm.py",
        "edge_arm_ik.c",
        "edge_arm_ik.h",
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


@pytest.mark.parametrize(
    "name", ["numpy", "numba", "typing", "token", "math", "json", "derive", "derive_ik_runtime"]
)
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


URDF = ROOT / "tests" / "data" / "urdf" / "ur5.urdf"


def not_regular(tmp_path: Path, kind: str, name: str) -> tuple[Path, Path]:
    """(the path given to -o, the node that must stay as it is) for a kind of node that is not
    a regular file: a named pipe, a link to one, a link to a character device, a socket, a
    folder."""
    path = tmp_path / name
    node = path
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "link to a fifo":
        node = tmp_path / f"pipe-{name}"
        os.mkfifo(node)
        path.symlink_to(node)
    elif kind == "link to a device":
        node = Path(os.devnull)
        path.symlink_to(node)
    elif kind == "socket":
        import socket

        server = socket.socket(socket.AF_UNIX)
        server.bind(str(path))
        server.close()
    else:
        path.mkdir()
    return path, node


def node_kind(path: Path) -> int:
    return stat.S_IFMT(path.stat().st_mode)


KINDS = ["fifo", "link to a fifo", "link to a device", "socket", "folder"]
FILE_COMMANDS = {
    "report": ["report", "planar_2r", "-o"],
    "import-urdf": ["import-urdf", str(URDF), "--base", "world", "--tip", "tool0", "-o"],
    "plot": ["plot", "planar_2r", "--q", "30", "40", "-o"],
    "generate": ["generate", "planar_2r", "--out"],
}


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("command", sorted(FILE_COMMANDS))
def test_output_onto_a_pipe_socket_device_or_folder_is_refused_not_replaced(
    command, kind, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    name = "planar_2r.md" if command == "generate" else "out.svg"  # (.md: the arm's second)
    if command == "generate":
        (tmp_path / "gen").mkdir()
        path, node = not_regular(tmp_path / "gen", kind, name)
        target = str(tmp_path / "gen")
    else:
        path, node = not_regular(tmp_path, kind, name)
        target = str(path)
    before = node_kind(node), sorted(p.name for p in tmp_path.rglob("*"))
    assert main([*FILE_COMMANDS[command], target]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"error: {path}: is a "), err
    assert "regular files only" in err
    assert (node_kind(node), sorted(p.name for p in tmp_path.rglob("*"))) == before
    assert path.is_symlink() == kind.startswith("link")


def test_output_through_a_symbolic_link_replaces_its_target_and_keeps_the_link(tmp_path, capsys):
    target = tmp_path / "docs" / "report.md"
    target.parent.mkdir()
    target.write_text("old")
    os.chmod(target, 0o640)
    link = tmp_path / "report.md"
    link.symlink_to(Path("docs") / "report.md")
    assert main(["report", "planar_2r", "-o", str(link)]) == 0
    assert link.is_symlink() and os.readlink(link) == str(Path("docs") / "report.md")
    assert target.read_text().startswith("<!-- Generated by derive-ik") and mode(target) == 0o640
    # a dangling link: its file is created, in a folder that exists (none is made where a
    # link points: the red team's link to /nonexistent/dir/x.toml made /nonexistent/dir)
    nowhere = tmp_path / "nowhere.toml"
    nowhere.symlink_to(tmp_path / "missing" / "deeper" / "ur5.toml")
    argv = ["import-urdf", str(URDF), "--base", "world", "--tip", "tool0", "-o", str(nowhere)]
    assert main(argv) == 2
    assert "whose folder does not exist" in capsys.readouterr().err
    nowhere.unlink()
    (tmp_path / "specs").mkdir()
    dangling = tmp_path / "spec.toml"
    dangling.symlink_to(tmp_path / "specs" / "ur5.toml")
    argv = ["import-urdf", str(URDF), "--base", "world", "--tip", "tool0", "-o", str(dangling)]
    assert main(argv) == 0
    assert dangling.is_symlink() and 'name = "ur5"' in (tmp_path / "specs" / "ur5.toml").read_text()
    assert sorted(p.name for p in tmp_path.rglob("*")) == [
        "docs", "report.md", "report.md", "spec.toml", "specs", "ur5.toml"
    ]  # fmt: skip


def test_dash_output_is_standard_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["report", "planar_2r", "-o", "-"]) == 0
    assert capsys.readouterr().out.startswith("<!-- Generated by derive-ik")
    assert main(["import-urdf", str(URDF), "--base", "world", "--tip", "tool0", "-o", "-"]) == 0
    assert 'name = "ur5"' in capsys.readouterr().out
    # a figure or a folder cannot go to standard output: refused, no file named -
    for argv in (["plot", "planar_2r", "--q", "1", "2", "-o", "-"], ["generate", "--out", "-"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "-" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        ["generate", "planar_2r", "--out"],
        ["check", "planar_2r", "--out"],
        ["build", "planar_2r", "-o"],
        ["reach", "puma560", "--resolution", "0.3", "--directions", "6", "-o"],
    ],
)
def test_a_file_where_the_output_folder_belongs_is_named(argv, tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("mine")
    assert main([*argv, str(afile)]) == 2
    err = capsys.readouterr().err
    option = argv[-1]
    assert err == f"error: {option} {afile}: is a regular file, not a folder; {option} names " \
        "the folder to write into (created if missing)\n", err  # fmt: skip
    assert afile.read_text() == "mine" and sorted(tmp_path.iterdir()) == [afile]


@pytest.mark.parametrize(
    "argv",
    [
        ["report", "puma560", "--format", "pdf"],
        ["import-urdf"],
        ["import-urdf", str(URDF), "--base", "world", "--tip", "tool0", "--angle-tol", "0x1p-3"],
        ["bench", "puma560", "--samples", "0"],
        ["bench", "puma560", "--batch", "-1"],
        ["nonsense"],
    ],
)
def test_argument_errors_are_one_line(argv, capsys):
    """argparse printed its usage and the error (6 lines); `bench --samples 0` a traceback."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    err = capsys.readouterr().err
    assert stop.value.code == 2 and err.count("\n") == 1 and "--help" in err, err


def test_solve_names_free_when_a_free_value_is_out_of_range(capsys):
    argv = ["solve", "iiwa14", "--q", "0", "0", "0", "0", "0", "0", "0", "--free", "1e17"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --free: q7 = 1e+17: allowed: within +-") and "deg" in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (
            ["generate", "puma560", "--task", "direction"],
            "puma560: --task: options of a URDF or MJCF file's conversion",
        ),
        (
            ["solve", "puma560", "--base", "a", "--tip", "b", "--q", "0", "0", "0", "0", "0", "0"],
            "puma560: --base, --tip: options of a URDF or MJCF file's conversion",
        ),
        (["generate", "arm.sdf"], "arm.sdf: an SDFormat (.sdf) file; derive reads spec files"),
        (["generate", "arm.model"], "arm.model: an SDFormat file (its root element is <sdf>)"),
    ],
)
def test_input_that_is_not_read_as_given_is_one_line(argv, message, tmp_path, capsys):
    """A conversion's options on a spec would be ignored, an SDFormat file read as TOML (or, of
    another suffix, as XML: as MJCF): each is refused in one line that says what is read."""
    for name in ("arm.sdf", "arm.model"):
        (tmp_path / name).write_text("<sdf version='1.7'><model name='m'/></sdf>\n")
    argv = [str(tmp_path / a) if a.startswith("arm.") else a for a in argv]
    assert main([*argv, "--out", str(tmp_path / "out")] if argv[0] == "generate" else argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_a_urdf_s_options_apply_to_it_and_not_to_a_bundled_arm_named_beside_it(tmp_path):
    """`derive bench robot.urdf puma560 --base b --tip t --lang c` was refused ("puma560:
    --base, --tip: options of a URDF or MJCF file's conversion"), so a task arm could not be
    timed against the PUMA in one run as issue 40 measures it: a conversion's options now go to
    the URDF and MJCF files named, and the specs beside them keep their own. The PUMA's module
    is the bundled one, byte for byte; the URDF's is its conversion with those options."""
    out = tmp_path / "out"
    argv = ["generate", str(URDF), "puma560", "--base", "world", "--tip", "tool0"]
    assert main([*argv, "--task", "position", "--out", str(out)]) == 0
    puma = (out / "puma560.py").read_bytes()
    assert puma == (ROOT / "generated" / "puma560.py").read_bytes()
    ur5 = next(p for p in out.glob("*.py") if p.name not in ("puma560.py", "derive_ik_runtime.py"))
    assert "ik_position" in ur5.read_text()
    assert main(["generate", "puma560", "--task", "position", "--out", str(out)]) == 2


def test_arm_names_after_a_urdf_s_options_are_taken_as_arms(tmp_path, capsys):
    """`derive bench robot.urdf --base b --tip t puma560 --lang c` exited 2 with
    "unrecognized arguments: puma560" (a new user's find: argparse takes the names only before
    the options). Names after options now join the ones before them, in order; an unknown
    option is still refused in one line, and so is a name where a command takes none."""
    out = tmp_path / "out"
    argv = ["generate", str(URDF), "--base", "world", "--tip", "tool0", "puma560"]
    assert main([*argv, "--out", str(out)]) == 0
    assert (out / "puma560.py").read_bytes() == (ROOT / "generated" / "puma560.py").read_bytes()
    assert len(list(out.glob("*.py"))) == 3  # (the UR5's, the PUMA's and the runtime)
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_:
        main(["generate", "puma560", "--bogus", "--out", str(out)])
    assert exit_.value.code == 2
    assert "unrecognized arguments: --bogus" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit_:
        main(["report", "puma560", "--format", "md", "lecture_6r"])
    assert exit_.value.code == 2
    assert "unrecognized arguments: lecture_6r" in capsys.readouterr().err


def test_a_spec_s_method_is_the_only_one_tried():
    """[ik] method = "general" gives an arm the general method (a calibrated arm's complete
    solution set); an unknown method is refused with the allowed ones."""
    from derive.pipeline import METHODS, build_plan
    from derive.spec import IK_METHODS, SpecError, parse_spec

    assert tuple(METHODS) == IK_METHODS
    rows = [(0, 0, 0, 0), (-90, 0, 0, 0), (0, 0.4, 0.1, 0), (-90, 0.02, 0.43, 0)]
    rows += [(90, 0, 0, 0), (-90, 0, 0, 0)]
    text = spec_text("six_r", "modified", rows)
    assert build_plan(parse_spec(text, "<six_r>")).ik.method == "pieper"
    general = parse_spec(text + '\n[ik]\nmethod = "general"\n', "<six_r>")
    assert build_plan(general).ik.method == "general"
    with pytest.raises(
        SpecError, match=r'six_r.toml: ik.method: \'fast\' is not allowed; one of "pieper"'
    ):
        parse_spec(text + '\n[ik]\nmethod = "fast"\n', "six_r.toml")


def test_an_empty_picture_name_and_a_joint_value_past_precision_are_refused(tmp_path, capsys):
    """A new user's attack on `derive path`: `-o ""` exited 0 with no picture and no word,
    and `--from 1e308 ...` printed 300-digit angles and a break blamed on Newton's iteration.
    Each is now one line naming the option and exit 2; `derive generate -o DIR` is taken as
    `--out DIR`, as `build`, `path` and `report` take -o."""
    rows = [(0, 0, 0, 0), (0, 1, 0, 0)]
    spec = tmp_path / "two.toml"
    spec.write_text(spec_text("two", "modified", rows), encoding="utf-8")
    args = ["path", "puma560", "--from", *["20"] * 6, "--to", *["0"] * 6]
    assert main([*args, "-o", ""]) == 2
    assert capsys.readouterr().err.strip() == (
        "error: -o: an empty file name; give FILE.svg or FILE.png"
    )
    assert main(["path", "puma560", "--from", "1e308", *["0"] * 5, "--to", *["0"] * 6]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: q1: 1e+308 deg is beyond") and "\n" not in err
    assert main(["fk", "puma560", "--rad", "2e6", *["0"] * 5]) == 2
    assert "q1: 2e+06 rad is beyond" in capsys.readouterr().err
    assert main(["fk", "puma560", "1e7", *["0"] * 5]) == 0  # (1.7e5 rad: taken)
    assert main(["generate", str(spec), "-o", str(tmp_path / "g")]) == 0
    assert (tmp_path / "g" / "two.py").is_file()


def test_derive_path_says_where_it_stopped_once(capsys):
    """A PUMA line through the base's far side (out of reach at pose 3): the last line said
    "stopped at pose 3 of 10: pose 3: out of reach" (a new user's attack); the pose is named
    once now."""
    args = ["path", "puma560", "--from", "0", "-10", "0", "0", "30", "0"]
    assert main([*args, "--to", "180", "-10", "0", "0", "30", "0", "--steps", "10"]) == 1
    out = capsys.readouterr().out
    assert "stopped at pose 3 of 10: out of reach; sigma_min" in out and "pose 3: " not in out


@pytest.mark.parametrize("lang", ["python", "c"])
def test_bench_of_an_fk_only_arm_says_so_in_one_line(tmp_path, capsys, lang):
    """An arm with no IK (axes 5 and 6 coincide: a redundant joint) gets a line naming why,
    beside the figures of the arms that have one: `derive bench` ended in a traceback
    (AssertionError in C's harness, AttributeError in Python's figures)."""
    spec = tmp_path / "twin_axes.toml"
    rows = [(90, 0, 0.3, 0), (180, 0.4, 0, 0), (90, 0, 0, 0), (90, 0, 0.2, 0), (0, 0, 0, 0),
            (0, 0, 0.1, 0)]  # fmt: skip
    spec.write_text(spec_text("twin_axes", "standard", rows))
    assert main(["bench", str(spec), "planar_2r", "--lang", lang, "--samples", "20"]) == 0
    out = capsys.readouterr().out
    assert "twin_axes: no " in out and "FK only, no IK: axes 5 and 6 coincide" in out, out
    assert "planar_2r:" in out
