"""Compiling the generated C: the system compiler, the command-line harness the tests and
`derive bench --lang c` drive, and `derive build`'s shared library with its ctypes binding
(templates/binding.py.j2).

Nothing here is needed to use the C files: they compile with any C99 compiler on their own.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from derive.emit_c import render_binding, render_c, render_harness
from derive.plan import Plan

# what every build passes: the flags the tests hold the generated code to
WARNINGS = ("-std=c99", "-Wall", "-Wextra", "-Werror")
SANITIZE = ("-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-fno-sanitize-recover")


class BuildError(RuntimeError):
    """The compiler is missing or failed (the message holds its output)."""


def c_compiler() -> str | None:
    """The C compiler: $CC, else gcc, else cc on PATH; None if there is none."""
    named = os.environ.get("CC")
    if named:
        return shutil.which(named)
    return shutil.which("gcc") or shutil.which("cc")


def _compile(args: list[str]) -> None:
    compiler = c_compiler()
    if compiler is None:
        raise BuildError("no C compiler found (set CC, or install gcc)")
    done = subprocess.run([compiler, *args], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise BuildError(f"{compiler} {' '.join(args)} failed:\n{done.stderr.strip()}")


def write_sources(plan: Plan, folder: Path, harness: bool = False) -> list[Path]:
    """The arm's C files (and the harness) written into folder; the .c files' paths."""
    files = render_c(plan)
    if harness:
        files[f"{plan.arm.name}_harness.c"] = render_harness(plan)
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return [folder / name for name in files if name.endswith(".c")]


class Harness:
    """The compiled harness of one arm (see templates/harness.c.j2)."""

    def __init__(
        self,
        plan: Plan,
        folder: Path,
        sanitize: bool = False,
        opt: tuple[str, ...] = ("-O2",),
    ):
        self.dof = plan.arm.dof
        assert plan.ik is not None
        self.max = plan.ik.max_solutions
        self.path = folder / f"{plan.arm.name}_harness"
        sources = write_sources(plan, folder, harness=True)
        flags = [*WARNINGS, *opt, *(SANITIZE if sanitize else ())]
        _compile([*flags, *map(str, sources), "-o", str(self.path), "-lm"])

    def _run(self, args: list[str], data: bytes) -> bytes:
        env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1", UBSAN_OPTIONS="halt_on_error=1")
        done = subprocess.run(
            [str(self.path), *args], input=data, capture_output=True, check=False, env=env
        )
        if done.returncode != 0:
            raise BuildError(f"{self.path.name} {' '.join(args)}: {done.stderr.decode()[-2000:]}")
        return done.stdout

    def _input(self, T: np.ndarray, refs: np.ndarray) -> bytes:
        n = T.shape[0]
        rows = np.concatenate([T.reshape(n, 16), refs.reshape(n, self.dof)], axis=1)
        return np.ascontiguousarray(rows, dtype=np.float64).tobytes()

    def solve(self, T: np.ndarray, refs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """ik_ref of every pose T[i] with q_ref (and free values) refs[i]: (counts, Q)."""
        out = self._run(["solve"], self._input(T, refs))
        record = np.dtype([("n", "<i4"), ("q", "<f8", (self.max, self.dof))])
        rows = np.frombuffer(out, dtype=record)
        return rows["n"].copy(), rows["q"].copy()

    def fk(self, Q: np.ndarray) -> np.ndarray:
        out = self._run(["fk"], np.ascontiguousarray(Q, dtype=np.float64).tobytes())
        return np.frombuffer(out, dtype=np.float64).reshape(-1, 4, 4).copy()

    def bench(
        self, T: np.ndarray, refs: np.ndarray, rounds: int = 21
    ) -> tuple[float, float, float]:
        """Nanoseconds per ik call on these poses: the least and the median over the rounds of
        each round's mean, and the median over the poses of each one's least single call."""
        out = self._run(["bench", str(rounds)], self._input(T, refs)).decode().split()
        least, median, single = map(float, out)
        return least, median, single


def build(plan: Plan, out: Path) -> Path:
    """`derive build`: compile the arm's C solver into out/lib<name>_ik.so (-O2, -fPIC) and
    write its ctypes binding out/<name>_c.py beside it; the binding's path."""
    out.mkdir(parents=True, exist_ok=True)
    name = plan.arm.name
    with tempfile.TemporaryDirectory() as tmp:
        sources = write_sources(plan, Path(tmp))
        partial = Path(tmp) / f"lib{name}_ik.so"
        _compile([*WARNINGS, "-O2", "-fPIC", "-shared", *map(str, sources), "-o", str(partial)])
        shutil.copyfile(partial, out / f".lib{name}_ik.so{TMP}")
    os.replace(out / f".lib{name}_ik.so{TMP}", out / f"lib{name}_ik.so")
    binding = out / f"{name}_c.py"
    (out / f".{binding.name}{TMP}").write_text(render_binding(plan), encoding="utf-8")
    os.replace(out / f".{binding.name}{TMP}", binding)
    return binding


TMP = ".derive-tmp"
