"""The runtime every generated module shares, and what each module takes from it.

The runtime (:mod:`derive.runtime`) is written once, as ordinary Python that is linted,
type-checked and tested here, and shipped once per output folder as ``derive_ik_runtime.py``
(:data:`RUNTIME_FILE`): its modules' top-level pieces (a function, a class or an assignment,
with the comment lines just above it) in the order of :data:`MODULES`, under one import block.
A generated module defines its arm's names (derive/runtime/arm.py lists them) and then runs
that file in its own namespace, as if its text were written there. The runtime's public
names the module does not offer (another task's function, ik_sweep where no joint is free, the
inverse kinematics of an arm without) are removed again: what a module offers is its
``__all__``, the public names of the pieces its printed code and its public functions use,
with everything those use in turn (:func:`closure`).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from importlib import resources

from derive.runtime import MODULES

# the runtime's files, written beside every generated module and C solver
RUNTIME_FILE = "derive_ik_runtime.py"
C_RUNTIME_FILE = "derive_ik_runtime.h"

# the names the generated module imports, as (import statement, name bound), in the order
# ruff's isort puts them (standard library, then numpy)
IMPORTS = (
    ("import cmath", "cmath"),
    ("import ctypes", "ctypes"),
    ("import hashlib", "hashlib"),
    ("import math", "math"),
    ("import os", "os"),
    ("import re", "re"),
    ("import shlex", "shlex"),
    ("import shutil", "shutil"),
    ("import subprocess", "subprocess"),
    ("import sys", "sys"),
    ("import tempfile", "tempfile"),
    ("import threading", "threading"),
    ("import warnings", "warnings"),
    ("from importlib.machinery import SourceFileLoader", "SourceFileLoader"),
    ("from math import {}", "acos"),
    ("from math import {}", "atan2"),
    ("from math import {}", "cos"),
    ("from math import {}", "sin"),
    ("from math import {}", "sqrt"),
    ("from operator import mul as _mul", "_mul"),
    ("from operator import sub as _sub", "_sub"),
    ("from time import time as _time", "_time"),
    ("from typing import {}", "TYPE_CHECKING"),
    ("from typing import {}", "Any"),
    ("import numpy as np", "np"),
    ("from numpy.typing import ArrayLike", "ArrayLike"),
)
# the public names of a module with forward kinematics only, and with inverse kinematics
FK_ROOTS = ("fk", "fk_batch", "link_transform", "jacobian", "manipulability", "ik_velocity")
IK_ROOTS = (
    *FK_ROOTS, "ik", "ik_batch", "ik_approximate", "nearest", "ik_path", "straight_line",
    "branch", "warmup", "CERTIFY_TOL", "BACKEND",
)  # fmt: skip
# the public names a module with free joints adds
FREE_ROOTS = ("ik_sweep",)
# the public names a module solved for a task adds (derive/tasks.py)
TASK_ROOTS = {
    "position": ("ik_position",),  # (a three-joint arm's: a planar one has "xy" instead)
    "direction": ("ik_direction",),
    "lookat": ("ik_lookat",),
    "pointing": ("ik_pointing",),
    "axisangle": ("ik_axis_angle",),
    "xy_heading": ("ik_xy_heading",),  # (a planar arm's plane task: tasks.Plane)
    "xy": ("ik_xy",),
}


@dataclass(frozen=True)
class Piece:
    """One top-level statement of a runtime module (or of the arm's printed code).

    Attributes:
        module: the runtime module's name ("arm" for the printed code).
        defines: the global names it binds.
        uses: every name it reads (globals and, harmlessly, locals).
        source: its text, with the comment lines just above it.
        function: whether it is a function definition.
    """

    module: str
    defines: frozenset[str]
    uses: frozenset[str]
    source: str
    function: bool


def split(module: str, source: str) -> tuple[Piece, ...]:
    """The pieces of a module's source, in order; imports, docstrings and ``if`` blocks are
    left out."""
    tree = ast.parse(source)
    lines = source.split("\n")
    pieces = []
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.ClassDef):
            defines = {node.name}
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            defines = {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
        else:
            continue
        start = node.lineno - 1
        while start > 0 and lines[start - 1].startswith("#"):
            start -= 1
        assert node.end_lineno is not None
        uses = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)} - defines
        pieces.append(
            Piece(
                module=module,
                defines=frozenset(defines),
                uses=frozenset(uses),
                source="\n".join(lines[start : node.end_lineno]),
                function=isinstance(node, ast.FunctionDef),
            )
        )
    return tuple(pieces)


@cache
def runtime_pieces() -> tuple[Piece, ...]:
    """Every piece of the runtime, in copy order."""
    package = resources.files("derive.runtime")
    pieces: list[Piece] = []
    for module in MODULES:
        pieces += split(module, package.joinpath(f"{module}.py").read_text(encoding="utf-8"))
    return tuple(pieces)


def closure(roots: Iterable[str], pieces: tuple[Piece, ...]) -> tuple[Piece, ...]:
    """The pieces defining the roots and, in turn, every name they use, in the pieces' order."""
    by_name = {name: p for p in pieces for name in p.defines}
    wanted: set[int] = set()
    todo = [n for n in roots if n in by_name]
    while todo:
        piece = by_name[todo.pop()]
        if id(piece) in wanted:
            continue
        wanted.add(id(piece))
        todo += [n for n in piece.uses if n in by_name]
    return tuple(p for p in pieces if id(p) in wanted)


def import_block(source: str) -> str:
    """The import statements binding exactly the imported names a module's source uses (the
    names of one ``from X import {}`` merged into one statement, as ruff's isort wants)."""
    used = {n.id for n in ast.walk(ast.parse(source)) if isinstance(n, ast.Name)}
    lines: list[str] = []
    merged: dict[str, list[str]] = {}
    for stmt, name in IMPORTS:
        if name in used and "{}" in stmt:
            merged.setdefault(stmt, []).append(name)
    for stmt, name in IMPORTS:
        if name not in used:
            continue
        if "{}" in stmt:
            if name == merged[stmt][0]:
                lines.append(stmt.format(", ".join(merged[stmt])))
            continue
        if stmt.startswith("import numpy") and lines:
            lines.append("")
        lines.append(stmt)
    return "\n".join(lines)


def _natural(name: str) -> tuple[tuple[int, int | str], ...]:
    """A name's natural-order key: digit runs compare as numbers (x9 before x10)."""
    return tuple((1, int(c)) if c.isdigit() else (0, c) for c in re.findall(r"\d+|\D+", name))


def _kind(name: str) -> int:
    """ruff's isort order of imported names: constants, classes, then the rest."""
    if len(name) > 1 and name.isupper():
        return 0
    return 1 if name[0].isupper() else 2


def import_order(names: Iterable[str]) -> tuple[str, ...]:
    """Names in the order ruff's isort sorts them inside one ``from X import (...)``."""
    return tuple(sorted(set(names), key=lambda n: (_kind(n), _natural(n.lower()), n)))


def all_order(names: Iterable[str]) -> tuple[str, ...]:
    """Names in the order ruff sorts an ``__all__`` (RUF022)."""
    return tuple(sorted(set(names), key=lambda n: (_kind(n), _natural(n))))


@dataclass(frozen=True)
class Assembly:
    """What a generated module takes from the runtime.

    Attributes:
        offered: the runtime's public names the module offers (in its ``__all__``).
        used: the runtime's names the arm's printed code calls.
    """

    offered: tuple[str, ...]
    used: tuple[str, ...]


def arm_names() -> frozenset[str]:
    """The names a generated module defines for its arm before it runs the runtime (the
    stand-ins of derive/runtime/arm.py)."""
    text = resources.files("derive.runtime").joinpath("arm.py").read_text(encoding="utf-8")
    return frozenset(n for p in split("arm", text) for n in p.defines) - {"_missing"}


def runtime_names() -> frozenset[str]:
    """Every name the runtime defines."""
    return frozenset(n for p in runtime_pieces() for n in p.defines)


def assemble(arm_source: str, has_ik: bool, free: bool = False, task: str = "pose") -> Assembly:
    """What a module whose arm-specific code is arm_source takes from the runtime (free: the
    arm has free joints, and ik_sweep; task: what its ik solves for, and its task function)."""
    roots = set(IK_ROOTS if has_ik else FK_ROOTS)
    if has_ik and free:
        roots |= set(FREE_ROOTS)
    if has_ik:
        roots |= set(TASK_ROOTS.get(task, ()))
    arm = split("arm", arm_source)
    for piece in arm:
        roots |= piece.uses
    defined = runtime_names()
    offered = {
        n for p in closure(roots, runtime_pieces()) for n in p.defines if not n.startswith("_")
    }
    used = {n for p in arm for n in p.uses} & defined
    return Assembly(offered=all_order(offered), used=import_order(used))


def runtime_source() -> tuple[str, tuple[str, ...], tuple[str, ...]]:
    """The runtime's pieces as one source, separated by two blank lines, with the arm's
    names they read (in import order) and the runtime's public names (in ``__all__`` order)."""
    pieces = runtime_pieces()
    text = "\n\n\n".join(p.source for p in pieces)
    read = {n for p in pieces for n in p.uses} & arm_names()
    public = {n for p in pieces for n in p.defines if not n.startswith("_")}
    return text, import_order(read), all_order(public)


# --- the C runtime (derive/c/): one header for every arm's C file ---------------------------

C_MODULES = ("runtime", "general")


def c_runtime_source() -> tuple[str, str]:
    """The C runtime's text for its shared header: derive/c/runtime.c and general.c as they
    are, without their file comments and includes (the header has its own)."""
    package = resources.files("derive.c")
    texts = []
    for module in C_MODULES:
        text = package.joinpath(f"{module}.c").read_text(encoding="utf-8")
        body = text[text.index("*/") + 2 :].lstrip("\n")  # (the file's comment)
        lines = [line for line in body.split("\n") if not line.startswith("#include")]
        texts.append("\n".join(lines).strip("\n"))
    return texts[0], texts[1]
