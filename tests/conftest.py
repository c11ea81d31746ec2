"""Shared helpers: import generated modules, build modules from spec text, reference FK."""

from __future__ import annotations

import importlib.util
import itertools
import math
import os
import shutil
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, settings

from derive.load import solver_sources
from derive.pipeline import build_plan
from derive.spec import ArmSpec, parse_spec

ROOT = Path(__file__).resolve().parent.parent
GENERATED = ROOT / "generated"
BUNDLED = (
    "iiwa14",
    "lecture_6r",
    "lecture_rrr",
    "locobot_head",
    "manocha_canny",
    "open_manipulator_x",
    "panda",
    "parallel_6r",
    "planar_2r",
    "puma560",
    "so_arm100",
    "youbot",
)
_counter = itertools.count()

# Property-test profiles: "ci" (the default; 8 examples: 30, then 20, then 12, until the suite
# outgrew CI's time: with the axis-angle task's tests a clean-clone .ci/run took 14 min 27 s of
# its 15 here; 8 examples save 26 s of test time) keeps the suite to minutes, with a fixed seed
# and no shrinking (a failure prints its arm at once); "long" is the thorough run,
# `python -m pytest tests/test_properties.py --hypothesis-profile=long`.
settings.register_profile(
    "ci",
    max_examples=8,
    deadline=None,
    derandomize=True,
    phases=[Phase.explicit, Phase.reuse, Phase.generate],
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "long", max_examples=2000, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile("ci")


# tests of the compiled (C) solvers need a C compiler
HAVE_CC = bool(os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc"))
needs_cc = pytest.mark.skipif(not HAVE_CC, reason="no C compiler (set CC, or install cc)")


def write_runtime(folder: Path) -> None:
    """The runtime every generated module runs (derive_ik_runtime.py), written into folder."""
    from derive.assemble import RUNTIME_FILE
    from derive.emit import render_runtime

    (folder / RUNTIME_FILE).write_text(render_runtime(), encoding="utf-8")


def import_path(path: Path) -> ModuleType:
    """Import a Python file under a unique module name."""
    name = f"_derive_test_{path.stem}_{next(_counter)}"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def generated():
    """Committed generated module of a bundled arm, by name (cached per session)."""
    cache: dict[str, ModuleType] = {}

    def get(name: str) -> ModuleType:
        if name not in cache:
            cache[name] = import_path(GENERATED / f"{name}.py")
        return cache[name]

    return get


# the generated files of the specs this test process has generated, by digest and source
_SOURCES: dict[tuple[str, str], dict[str, str]] = {}


def spec_sources(spec: ArmSpec) -> dict[str, str]:
    """solver_sources(build_plan(spec)), derived once per test process and spec: the files,
    not a module (each caller writes and imports a copy of its own, so that a test patching
    its module patches no other's). Tests of the derivation itself call build_plan."""
    key = (spec.digest(), repr(spec.source))
    if key not in _SOURCES:
        _SOURCES[key] = solver_sources(build_plan(spec))
    return _SOURCES[key]


def build_module(text: str, folder: Path, c: bool = False) -> ModuleType:
    """Generate the module of a spec given as TOML text, with its C files, into a folder of
    its own in folder and import it. Its BACKEND is "python" unless c (the C solver is
    compiled on its first call: tests of it pass c=True or name backend="c")."""
    spec = parse_spec(text, "<test spec>")
    folder = folder / f"{spec.name}_{next(_counter)}"
    folder.mkdir()
    for name, content in spec_sources(spec).items():
        (folder / name).write_text(content, encoding="utf-8")
    module = import_path(folder / f"{spec.name}.py")
    if hasattr(module, "BACKEND") and not c:
        module.BACKEND = "python"
    return module


# A user's arm (modified DH, metres, spherical wrist): the CLI and wheel tests generate it
USER_ROWS = [
    (0, 0, 0, 0),
    (-90, 0.1, 0, 0),
    (0, 0.5, 0.05, 0),
    (-90, 0.04, 0.45, 0),
    (90, 0, 0, 0),
    (-90, 0, 0, 0),
]


def spec_text(
    name: str,
    convention: str,
    rows: list[tuple],
    unit: str = "deg",
    kinds: str | None = None,
    extra: str = "",
) -> str:
    """TOML for an arm; rows are (alpha, a, d, theta) in the spec's unit."""
    kinds = kinds or "R" * len(rows)
    out = (
        f'name = "{name}"\nconvention = "{convention}"\nangle_unit = "{unit}"\nlength_unit = "m"\n'
    )
    for kind, (alpha, a, d, theta) in zip(kinds, rows):
        out += (
            f'[[joint]]\ntype = "{kind}"\nalpha = {float(alpha)!r}\na = {float(a)!r}\n'
            f"d = {float(d)!r}\ntheta = {float(theta)!r}\n"
        )
    return out + extra


# an arm with no closed form and one prismatic joint (rows alpha, a, d, theta; the prismatic
# joint's theta is its fixed angle, its d its offset): the general method's joint 3 or 4
SLIDER_ROWS = [(90, 0.2, 0.3, 0), (40, 0.5, 0.1, 10), (-70, 0.3, 0.2, 30)]
SLIDER_ROWS += [(60, 0.25, 0.15, 0), (-50, 0.1, 0.2, 0), (35, 0.05, 0.1, 0)]


def slider_text(kinds: str, convention: str) -> str:
    """The slider arm with joints of these kinds (one P), its prismatic joint within +-1 m."""
    text = spec_text("slider", convention, SLIDER_ROWS, kinds=kinds)
    return text.replace('type = "P"\n', 'type = "P"\nlimits = [-1.0, 1.0]\n')


def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def tr(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def reference_fk(
    convention: str,
    dh_rad: list[tuple],
    kinds: str,
    q: np.ndarray,
    base: np.ndarray | None = None,
    tool: np.ndarray | None = None,
) -> np.ndarray:
    """Textbook FK written independently of derive: Craig's or the standard link transform."""
    T = np.eye(4) if base is None else base.copy()
    for (alpha, a, d, theta), kind, qi in zip(dh_rad, kinds, q):
        theta_i = theta + qi if kind == "R" else theta
        d_i = d + qi if kind == "P" else d
        if convention == "modified":
            T = T @ rx(alpha) @ tr(a, 0, 0) @ rz(theta_i) @ tr(0, 0, d_i)
        else:
            T = T @ rz(theta_i) @ tr(0, 0, d_i) @ tr(a, 0, 0) @ rx(alpha)
    return T if tool is None else T @ tool


def wrapped_close(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Equal modulo 2 pi within tol (radians)."""
    d = np.remainder(np.asarray(a) - np.asarray(b) + math.pi, 2 * math.pi) - math.pi
    return bool(np.all(np.abs(d) <= tol))


sys.path.insert(0, str(ROOT / "tests"))


def pytest_sessionfinish(session) -> None:
    """In a pytest-xdist worker: hand the worst degenerate-pose error to the controller."""
    from degenerate import WORST

    output = getattr(session.config, "workeroutput", None)
    if output is not None:
        output["degenerate_worst"] = WORST["error"]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node, error) -> None:
    """In the controller: the worst degenerate-pose error over the workers."""
    from degenerate import WORST

    worst = getattr(node, "workeroutput", {}).get("degenerate_worst", 0.0)
    WORST["error"] = max(WORST["error"], worst)


def pytest_terminal_summary(terminalreporter) -> None:
    """The worst pose error the degenerate-pose suites met in this run (for the notes)."""
    from degenerate import WORST

    if WORST["error"]:
        terminalreporter.write_line(
            f"degenerate-pose suites: worst pose error {WORST['error']:.1e} "
            "(rotation entries; position / REACH)"
        )
