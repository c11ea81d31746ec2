"""The C solver behind a generated module: compiled on the first call into the per-user cache
keyed by the C source's digest, found there by the next process (under any module name), and
without a compiler or without the C files one notice and the Python solver's answers."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest

from derive.verify import sample_joints

from conftest import GENERATED, import_path, needs_cc

# import by path under a name of its own, solve a pose in C, print the library's path
PROBE = """
import importlib.util, sys
spec = importlib.util.spec_from_file_location(sys.argv[2], sys.argv[1])
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
assert m.warmup()
T = m.fk([0.3] * m.DOF)
assert len(m.ik(T, backend="c")) >= 1
print(m._native.lib._name)
"""


def copy_arm(name: str, folder, c: bool = True):
    """The bundled arm's module with the runtime (and, with c, its C files) copied into folder."""
    files = [f"{name}.py", "derive_ik_runtime.py"]
    files += [f"{name}_ik.c", f"{name}_ik.h", "derive_ik_runtime.h"] if c else []
    for file in files:
        shutil.copy(GENERATED / file, folder / file)
    return folder / f"{name}.py"


def probe(path, name: str, env: dict) -> str:
    done = subprocess.run(
        [sys.executable, "-c", PROBE, str(path), name],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.strip()


@needs_cc
def test_the_c_solver_is_compiled_once_into_the_cache_and_found_by_the_next_process(tmp_path):
    path = copy_arm("planar_2r", tmp_path)
    env = dict(os.environ, DERIVE_IK_CACHE=str(tmp_path / "cache"))
    first = probe(path, "first_import_name", env)
    built = sorted((tmp_path / "cache").glob("planar_2r-*.so"))
    assert [str(p) for p in built] == [first]
    stamp = built[0].stat().st_mtime_ns
    assert probe(path, "another_import_name", env) == first  # the same library, not rebuilt
    assert built[0].stat().st_mtime_ns == stamp
    # a changed C source is another digest: compiled again, beside the first
    source = tmp_path / "planar_2r_ik.c"
    source.write_text(source.read_text() + "\n/* changed */\n")
    second = probe(path, "third_import_name", env)
    assert second != first and len(list((tmp_path / "cache").glob("planar_2r-*.so"))) == 2
    assert not [p for p in (tmp_path / "cache").iterdir() if p.is_dir()]  # no leftovers


@needs_cc
@pytest.mark.skipif(not Path("/proc/cpuinfo").is_file(), reason="the processor is told on Linux")
def test_the_c_solver_is_built_for_this_processor_and_keyed_by_it(tmp_path, monkeypatch):
    """Compiled with HOST_FLAGS for the processor /proc/cpuinfo names; another processor
    sharing the cache (a cluster's home folder) gets a library of its own, not this one's
    instructions."""
    m = import_path(copy_arm("planar_2r", tmp_path))
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path / "cache"))
    log, cc = logging_compiler(tmp_path, fails="--never--)\n  exit 1;;")
    monkeypatch.setenv("CC", str(cc))
    assert m._host() and "-march=native" in m.HOST_FLAGS
    here, why = m._c_library()
    assert why == "" and "-march=native" in log.read_text()
    monkeypatch.setattr(m, "_host", lambda: "model name:another processor")
    there, why = m._c_library()
    assert why == "" and there._name != here._name
    assert len(log.read_text().splitlines()) == 2  # (each built once, for its processor)
    q = np.array([0.4, -1.1])
    assert np.abs(m.ik(m.fk(q), backend="c") - m.ik(m.fk(q), backend="python")).max() < 1e-12


@needs_cc
@pytest.mark.skipif(not Path("/proc/cpuinfo").is_file(), reason="the processor is told on Linux")
def test_a_compiler_that_refuses_the_processor_s_flags_builds_the_portable_one_once(
    tmp_path, monkeypatch
):
    """A compiler that fails on HOST_FLAGS (one without -march=native): C_FLAGS alone build
    the solver, HOST_FLAGS are asked once more (a failure of the moment is not a refusal), and
    the refusal, noted in the cache, is not asked again by the next process."""
    path = copy_arm("planar_2r", tmp_path)
    log, cc = logging_compiler(tmp_path, fails="*-march=native*)\n  exit 1;;")
    env = dict(os.environ, DERIVE_IK_CACHE=str(tmp_path / "cache"), CC=str(cc))
    first = probe(path, "first", env)
    calls = ["-march=native" in call for call in log.read_text().splitlines()]
    assert calls == [True, False, True]
    assert len(list((tmp_path / "cache").glob("planar_2r-*.refused"))) == 1
    assert probe(path, "second", env) == first
    assert len(log.read_text().splitlines()) == 3  # (not asked again)


@needs_cc
@pytest.mark.skipif(not Path("/proc/cpuinfo").is_file(), reason="the processor is told on Linux")
def test_a_compiler_failing_once_is_asked_again_not_taken_for_a_refusal(tmp_path):
    """A failure of the moment with HOST_FLAGS (cc1 killed by the out-of-memory killer, say;
    a reviewer's find, helper 69, had pinned the source to the portable build for good): the
    portable build, then HOST_FLAGS again, which build; no refusal noted."""
    path = copy_arm("planar_2r", tmp_path)
    log, cc = logging_compiler(tmp_path, fails=f"*)\n  [ -e {tmp_path}/once ] || {{ touch "
                               f"{tmp_path}/once; exit 1; }};;")  # fmt: skip
    env = dict(os.environ, DERIVE_IK_CACHE=str(tmp_path / "cache"), CC=str(cc))
    first = probe(path, "first", env)
    calls = ["-march=native" in call for call in log.read_text().splitlines()]
    assert calls == [True, False, True]
    assert not list((tmp_path / "cache").glob("*.refused"))
    assert probe(path, "second", env) == first and len(log.read_text().splitlines()) == 3
    portable = [p for p in (tmp_path / "cache").glob("planar_2r-*.so") if p.name not in first]
    assert len(portable) == 1 and portable[0].name != Path(first).name


@needs_cc
@pytest.mark.skipif(not Path("/proc/cpuinfo").is_file(), reason="the processor is told on Linux")
def test_a_cache_that_cannot_be_written_serves_its_portable_library(tmp_path, monkeypatch):
    """A read-only cache prepared on another machine (a container image, a site's cache)
    holds the portable library: this processor's cannot be built there, and the portable one
    serves, not the Python solver (a reviewer's find, helper 69)."""
    m = import_path(copy_arm("planar_2r", tmp_path))
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path / "cache"))
    here = m._host
    monkeypatch.setattr(m, "_host", lambda: "")  # (the portable library, as another machine's)
    portable, why = m._c_library()
    assert why == ""
    monkeypatch.setattr(m, "_host", here)

    def read_only(*args, **kwargs):
        raise OSError(30, "Read-only file system")

    monkeypatch.setattr(m, "_build", read_only)
    loaded, why = m._c_library()
    assert why == "" and loaded._name == portable._name


def logging_compiler(folder: Path, fails: str) -> tuple[Path, Path]:
    """A compiler (the system's) that logs its arguments, one line a call, and fails where
    its arguments match the shell `case` pattern and commands in fails; the log and itself."""
    log, cc = folder / "calls.log", folder / "cc.sh"
    system = shutil.which("cc") or "gcc"
    cc.write_text(
        f'#!/bin/sh\necho "$*" >> {log}\ncase "$*" in {fails}\nesac\nexec {system} "$@"\n'
    )
    cc.chmod(0o755)
    return log, cc


@needs_cc
def test_processes_compiling_at_once_each_get_a_whole_library(tmp_path):
    path = copy_arm("lecture_rrr", tmp_path)
    env = dict(os.environ, DERIVE_IK_CACHE=str(tmp_path / "cache"))
    runs = [
        subprocess.Popen(
            [sys.executable, "-c", PROBE, str(path), f"name{k}"],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
        )
        for k in range(3)
    ]
    outputs = [run.communicate(timeout=300) for run in runs]
    assert all(run.returncode == 0 for run in runs), [err for _, err in outputs]
    assert len({out.strip() for out, _ in outputs}) == 1


def test_without_a_compiler_one_notice_and_the_python_solver(tmp_path, monkeypatch):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path / "cache"))
    m = import_path(copy_arm("puma560", tmp_path))
    with pytest.warns(RuntimeWarning, match="puma560: solving in Python") as notices:
        poses = m.fk_batch(sample_joints(m, 20, np.random.default_rng(3)))
        rows = [m.ik(T) for T in poses]
        Q, valid = m.ik_batch(poses)
        m.nearest(poses[0], np.zeros(6))
    assert len(notices) == 1
    for T, r, q, ok in zip(poses, rows, Q, valid):
        expected = m.ik(T, backend="python")
        assert np.array_equal(r, expected) and np.array_equal(q[ok], expected)
    assert not m.warmup()
    with pytest.raises(
        RuntimeError, match=r"backend='c': the C compiler .*no-such-compiler.* not found"
    ):
        m.ik(poses[0], backend="c")


def test_a_module_copied_without_its_c_files_says_so_once_and_solves_in_python(tmp_path):
    m = import_path(copy_arm("planar_2r", tmp_path, c=False))
    T = m.fk([0.4, 0.5])
    with pytest.warns(RuntimeWarning, match=r"planar_2r_ik\.c not found beside"):
        rows = m.ik(T)
    assert np.abs(rows - m.ik(T, backend="python")).max() == 0.0
    with pytest.raises(ValueError, match="backend must be 'auto', 'c' or 'python'"):
        m.ik(T, backend="numba")


def test_a_module_runs_the_runtime_of_its_version_and_says_so_where_it_is_not(tmp_path):
    """The runtime beside a module: line ends turned to CRLF by a checkout, and what a
    formatter or a linter's fix makes of it (a helper's ruff --fix rewrote an `if` as max()),
    are the same runtime; another version's, or none, is one ImportError line."""
    path = copy_arm("planar_2r", tmp_path, c=False)
    runtime = tmp_path / "derive_ik_runtime.py"
    text = runtime.read_text()
    edited = text.replace("    if disc < 0.0:\n        disc = 0.0\n", "    disc = max(disc, 0.0)\n")
    assert edited != text
    runtime.write_bytes(edited.replace("\n", "\r\n").encode())
    m = import_path(path)
    x, y = np.cos(0.4) + np.cos(0.9), np.sin(0.4) + np.sin(0.9)
    assert np.abs(m.fk([0.4, 0.5])[:2, 3] - [x, y]).max() < 1e-15
    version = m._RUNTIME_VERSION
    from derive.emit import RUNTIME_LINE  # (derive generate's check reads the line as the module)

    assert m._RUNTIME_LINE.pattern == RUNTIME_LINE.pattern
    runtime.write_text(text.replace(f'_RUNTIME_VERSION = "{version}"', '_RUNTIME_VERSION = "0f"'))
    with pytest.raises(ImportError, match=rf"is runtime version 0f, not {version} \(this"):
        import_path(path)
    runtime.unlink()
    with pytest.raises(ImportError, match=r"planar_2r: needs derive_ik_runtime\.py beside it"):
        import_path(path)


def test_the_runtime_imported_on_its_own_says_what_it_is(tmp_path):
    """A tool importing every file of a package (pytest's doctest collection, a doc builder)
    gets an ImportError saying what the runtime is, not a NameError from inside it."""
    shutil.copy(GENERATED / "derive_ik_runtime.py", tmp_path)
    with pytest.raises(ImportError, match="run by the generated modules beside it"):
        import_path(tmp_path / "derive_ik_runtime.py")


def test_modules_and_their_runtime_import_from_a_zip_archive(tmp_path):
    """A zip of the modules and the runtime (a zipapp, a frozen app's archive) imports: the
    runtime is read through the module's loader (it said "needs derive_ik_runtime.py beside
    it (Not a directory)"); the C files are not in a zip, so it solves in Python."""
    import zipfile

    archive = tmp_path / "arms.zip"
    with zipfile.ZipFile(archive, "w") as z:
        for name in ("planar_2r.py", "puma560.py", "derive_ik_runtime.py"):
            z.write(GENERATED / name, name)
    script = (
        "import sys, warnings; sys.path.insert(0, sys.argv[1]); import numpy as np;"
        "import puma560 as m, planar_2r as p; warnings.simplefilter('ignore');"
        "q = np.radians([20.0] * 6); rows = m.ik(m.fk(q));"
        "print(len(rows), float(np.abs(rows - q).max(axis=1).min()), p.DOF)"
    )
    # (by the path sys.path gives, relative here: the archive's loader knows it so)
    done = subprocess.run(
        [sys.executable, "-I", "-c", script, "arms.zip"], capture_output=True, text=True,
        cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    count, gap, dof = done.stdout.split()
    assert int(count) == 8 and float(gap) < 1e-9 and dof == "2"


def test_each_module_offers_its_own_api_and_keeps_its_own_state(generated):
    """The runtime runs in each module's own namespace: a module offers the public names of
    its __all__ (another task's function, ik_sweep of arms with free joints, are not there),
    and a setting changed in one module leaves the others as they were."""
    puma, panda, head = generated("puma560"), generated("panda"), generated("locobot_head")
    assert hasattr(panda, "ik_sweep") and not hasattr(puma, "ik_sweep")
    assert hasattr(head, "ik_lookat") and not hasattr(puma, "ik_lookat")
    for module in (puma, panda, head):
        names = vars(module)
        assert set(module.__all__) <= set(names)
        defined_here = {
            n
            for n, v in names.items()
            if isinstance(v, types.FunctionType) and v.__globals__ is names
        }
        assert {n for n in defined_here if not n.startswith("_")} <= set(module.__all__)
    was = puma.BACKEND, panda.BACKEND
    try:
        puma.BACKEND = "python"
        assert was[1] == panda.BACKEND and panda.ik.__globals__ is vars(panda)
        assert puma.ik.__globals__ is vars(puma)
    finally:
        puma.BACKEND = was[0]


@needs_cc
def test_a_failing_compiler_is_named_with_its_message(tmp_path, monkeypatch):
    path = copy_arm("planar_2r", tmp_path)
    (tmp_path / "planar_2r_ik.c").write_text("this is not C\n")
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path / "cache"))
    m = import_path(path)
    with pytest.warns(RuntimeWarning, match=r"failed \(exit \d+\) on .*planar_2r_ik\.c: .*error"):
        m.ik(m.fk([0.1, 0.2]))
    assert not list((tmp_path / "cache").glob("planar_2r-*"))  # nothing half-built kept


@needs_cc
def test_a_damaged_library_in_the_cache_is_built_again_not_loaded(tmp_path):
    """A library cut short (a crash would follow loading it) or overwritten fails the SHA-256
    recorded beside it when it was built: the next process builds it again."""
    path = copy_arm("planar_2r", tmp_path)
    env = dict(os.environ, DERIVE_IK_CACHE=str(tmp_path / "cache"))
    library = Path(probe(path, "first", env))
    whole = library.read_bytes()
    assert (library.parent / (library.name + ".sha256")).is_file()
    for damaged in (whole[:1000], b"garbage"):
        library.write_bytes(damaged)
        assert probe(path, "again", env) == str(library)
        assert library.read_bytes() != damaged  # built again


@needs_cc
def test_a_compiler_that_fails_silently_or_hangs_is_named_with_what_it_did(tmp_path, monkeypatch):
    path = copy_arm("planar_2r", tmp_path)
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CC", "false")
    m = import_path(path)
    with pytest.warns(RuntimeWarning, match=r"false failed \(exit 1\) on .*planar_2r_ik\.c"):
        assert not m.warmup()
    hang = tmp_path / "hang.sh"
    hang.write_text("#!/bin/sh\nsleep 30\n")
    hang.chmod(0o755)
    monkeypatch.setenv("CC", str(hang))
    m = import_path(path)
    monkeypatch.setattr(m, "COMPILE_TIMEOUT", 0.5)
    with pytest.warns(RuntimeWarning, match=r"hang\.sh took more than 0\.5 s"):
        assert not m.warmup()
    assert [p.name for p in (tmp_path / "cache").iterdir()] == []  # nothing left behind


def test_derive_backend_c_without_a_compiler_is_one_line(tmp_path):
    env = dict(
        os.environ,
        CC=str(tmp_path / "no-such-compiler"),
        DERIVE_IK_CACHE=str(tmp_path / "cache"),
        DERIVE_BACKEND="c",
    )
    done = subprocess.run(
        [sys.executable, "-m", "derive", "solve", "planar_2r", "--q", "10", "20"],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        f"error: DERIVE_BACKEND=c: backend='c': the C compiler "
        f"'{tmp_path / 'no-such-compiler'}' (from $CC) is not found"
    ]
