"""The printers and the generated module's form: every step kind printed by every backend,
modules that pass ruff with no finding, hold no function they never call, keep lines within
100 characters, and whose layout changes nothing but the layout."""

from __future__ import annotations

import ast
import importlib
import re
import shutil
import subprocess
import sys

import pytest

from derive.layout import wrap_code
from derive.plan import SOLVE_KINDS, Solve
from derive.printers import BACKENDS

from conftest import BUNDLED, ROOT


def all_subclasses(cls: type) -> set[type]:
    out = set()
    for sub in cls.__subclasses__():
        out |= {sub} | all_subclasses(sub)
    return out


def test_every_step_kind_is_listed_and_has_a_printer_in_every_backend():
    assert set(SOLVE_KINDS) == all_subclasses(Solve)
    for backend in BACKENDS:
        module = importlib.import_module(f"derive.printers.{backend}")
        missing = [k.__name__ for k in SOLVE_KINDS if k not in module.SOLVES]
        assert not missing, f"derive/printers/{backend}.py has no printer for {missing}"


def test_solve_is_abstract_and_checks_its_arguments():
    import sympy as sp

    from derive.plan import Atan2, Poly

    with pytest.raises(TypeError):
        Solve(1, (sp.S.One, sp.S.One), "", 1)
    with pytest.raises(ValueError, match="atan2 takes 2 arguments"):
        Atan2(1, (sp.S.One,), "", 1)
    with pytest.raises(ValueError, match="at least two"):
        Poly(1, (sp.S.One,), "", 1)


def module_source(name: str) -> str:
    return (ROOT / "generated" / f"{name}.py").read_text()


@pytest.mark.parametrize("name", BUNDLED)
def test_generated_lines_fit_in_100_characters(name):
    long = [n for n, line in enumerate(module_source(name).split("\n"), 1) if len(line) > 100]
    assert not long, f"{name}.py lines {long[:5]} are longer than 100 characters"


@pytest.mark.parametrize("name", BUNDLED)
def test_generated_c_lines_fit_in_100_characters(name):
    for suffix in ("_ik.c", "_ik.h", "derive_ik_runtime.h"):
        file = suffix if suffix.startswith("derive") else f"{name}{suffix}"
        text = (ROOT / "generated" / file).read_text()
        long = [n for n, line in enumerate(text.split("\n"), 1) if len(line) > 100]
        assert not long, f"{name}{suffix} lines {long[:5]} are longer than 100 characters"


def test_c_lines_break_between_tokens_only():
    from derive.layout import wrap_c

    table = "static const double X[40] = {" + ", ".join(repr(k / 7) for k in range(40)) + "};"
    wrapped = wrap_c("    " + table)
    assert max(map(len, wrapped.split("\n"))) <= 100
    assert wrapped.split() == ("    " + table).split()  # the same tokens, only new breaks
    define = "#define LONG " + " + ".join(["1.0"] * 40)
    assert wrap_c(define) == define  # a preprocessor line stays whole


def _names(tree: ast.AST) -> tuple[set[str], set[str]]:
    """The functions and classes a module defines at its top level, and every name it reads
    (or names in a string)."""
    body = tree.body if isinstance(tree, ast.Module) else []
    defined = {n.name for n in body if isinstance(n, ast.FunctionDef | ast.ClassDef)}
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    used |= {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)}
    return defined, used


@pytest.mark.parametrize("name", BUNDLED)
def test_generated_modules_hold_no_function_they_never_call(name):
    """Each function of an arm's module is called by the module, by the runtime it runs, or
    is public (in its __all__)."""
    defined, used = _names(ast.parse(module_source(name)))
    _, runtime_uses = _names(ast.parse(module_source("derive_ik_runtime")))
    unused = sorted(defined - used - runtime_uses)
    assert not unused, f"{name}.py never calls {unused}"


def test_the_runtime_holds_no_function_nothing_calls():
    """Each function of the shared runtime is called by the runtime, is public, or is named
    by the printers of arm code (derive/printers/, templates/arm.py.j2, derive/emit.py: the
    step routines a printed solver calls)."""
    defined, used = _names(ast.parse(module_source("derive_ik_runtime")))
    public = {n for n in defined if not n.startswith("_")}
    printers = [*(ROOT / "derive" / "printers").glob("*.py"), ROOT / "derive" / "emit.py"]
    printers.append(ROOT / "templates" / "arm.py.j2")
    named = set(re.findall(r"\w+", "".join(f.read_text() for f in printers)))
    unused = sorted(defined - used - public - named)
    assert not unused, f"derive_ik_runtime.py: nothing calls {unused}"


@pytest.mark.parametrize("name", BUNDLED)
def test_wrapping_changes_only_the_layout(name):
    source = module_source(name)
    narrow = wrap_code(source, width=60)
    assert ast.dump(ast.parse(narrow)) == ast.dump(ast.parse(source))
    assert narrow.count("\n") > source.count("\n")  # and it did wrap


def test_generated_modules_pass_ruff(tmp_path, generated_user_modules):
    """ruff check with the project's configuration finds nothing in the bundled arms' modules
    and in user arms' (copied out of the checkout, so the configuration is passed along)."""
    ruff = shutil.which("ruff") or (shutil.which("ruff", path=str(ROOT / ".venv" / "bin")))
    if ruff is None:
        pytest.skip("ruff is not installed (pip install -e '.[lint]')")
    files = [ROOT / "generated" / f"{name}.py" for name in BUNDLED] + generated_user_modules
    result = subprocess.run(
        [ruff, "check", "--no-cache", "--config", str(ROOT / "pyproject.toml")]
        + [str(f) for f in files],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.fixture
def generated_user_modules(tmp_path):
    """Modules of user arms (a prismatic Pieper arm and a three-parallel arm), written to tmp."""
    from conftest import USER_ROWS, spec_text

    paths = []
    for name, rows, kinds in (
        ("user_six", USER_ROWS, None),
        ("user_prismatic", USER_ROWS, "RRPRRR"),
    ):
        spec = tmp_path / f"{name}.toml"
        spec.write_text(spec_text(name, "modified", rows, kinds=kinds))
        out = tmp_path / "out"
        result = subprocess.run(
            [sys.executable, "-m", "derive", "generate", str(spec), "--out", str(out)],
            capture_output=True,
            text=True,
        )
        assert result.returncode == 0, result.stderr
        paths.append(out / f"{name}.py")
    return paths


def test_a_new_method_is_one_file_and_one_registration_line(tmp_path, monkeypatch):
    """tests/example_method.py is a method as a file under derive/methods/ would be; the
    monkeypatch below is the one line that registers it in derive/pipeline.py's METHODS."""
    import importlib.util

    import numpy as np

    from derive import pipeline
    from derive.emit import render_module
    from derive.spec import load_spec

    import example_method
    from conftest import spec_text, write_runtime

    monkeypatch.setattr(
        pipeline, "METHODS", pipeline.METHODS | {example_method.NAME: example_method.derive}
    )
    spec = tmp_path / "pan_tilt.toml"
    spec.write_text(spec_text("pan_tilt", "modified", [(0, 0, 0, 0), (-90, 0.05, 0.1, 30)]))
    plan = pipeline.build_plan(load_spec(spec))
    assert plan.ik is not None and plan.ik.method == "pan-tilt", plan.refusal
    path = tmp_path / "pan_tilt.py"
    path.write_text(render_module(plan))
    write_runtime(tmp_path)
    loaded = importlib.util.spec_from_file_location("pan_tilt", path)
    assert loaded is not None and loaded.loader is not None
    module = importlib.util.module_from_spec(loaded)
    loaded.loader.exec_module(module)
    Q = np.random.default_rng(3).uniform(-np.pi, np.pi, size=(200, 2))
    T = module.fk_batch(Q)
    for backend in ("python", "auto"):
        for q, pose in zip(Q, T):
            sols = module.ik(pose, backend=backend)
            assert len(sols) == 1 and np.allclose(sols[0], q, atol=1e-9), (q, sols)
        found, valid = module.ik_batch(T, backend=backend)
        assert valid[:, 0].all() and np.allclose(found[:, 0], Q, atol=1e-9)


def test_the_pose_and_the_jacobian_are_reduced_once_for_both_printers(monkeypatch):
    """The pose's and the Jacobian's entries are printed by the Python and the C printer
    alike: their CSE (a third of a calibrated arm's printing time) runs once per process and
    stream of names, and the printed module is the same either way."""
    import sympy as sp

    from derive.emit import render_module
    from derive.emit_c import render_c
    from derive.inputs import resolve_spec
    from derive.pipeline import build_plan
    from derive.printers import common

    plan = build_plan(resolve_spec("puma560"))
    pose = tuple(plan.fk_pose[i, j] for i in range(3) for j in range(4))
    jacobian = tuple(plan.jacobian)
    first = render_module(plan), render_c(plan)
    calls: list[tuple] = []
    original = sp.cse

    def counted(exprs, *args, **kwargs):
        calls.append(tuple(exprs))
        return original(exprs, *args, **kwargs)

    monkeypatch.setattr(sp, "cse", counted)
    assert (render_module(plan), render_c(plan)) == first
    assert calls and pose not in calls and jacobian not in calls
    common._fresh_cse.cache_clear()
    assert (render_module(plan), render_c(plan)) == first
    # (the pose twice: as x0, x1, ... for fk, and as C's pose hoisted into the solve)
    assert calls.count(pose) == 2 and calls.count(jacobian) == 1
