"""The emitter's structure: no import cycles in derive/, and expressions a backend cannot
evaluate stop generation with a message instead of becoming invalid code."""

from __future__ import annotations

import ast
import inspect
import typing
from dataclasses import replace
from pathlib import Path

import pytest
import sympy as sp

from derive import symbols as sym
from derive.emit import GenerationError, render_module
from derive.pipeline import build_plan
from derive.plan import Solve
from derive.spec import load_spec

from conftest import BUNDLED, ROOT


def derive_imports() -> dict[str, set[str]]:
    """module -> the derive modules it imports anywhere in its source (also inside functions)."""
    graph: dict[str, set[str]] = {}
    for path in sorted((ROOT / "derive").rglob("*.py")):
        name = ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.ImportFrom)
                and node.module
                and node.module.startswith("derive")
            ):
                found |= {f"{node.module}.{a.name}" for a in node.names} | {node.module}
            elif isinstance(node, ast.Import):
                found |= {a.name for a in node.names if a.name.startswith("derive")}
        graph[name] = found
    return {m: {d for d in deps if d in graph and d != m} for m, deps in graph.items()}


def test_no_import_cycle_in_derive():
    graph = derive_imports()
    assert "derive.printers.common" in graph["derive.printers.scalar"]  # the graph sees imports
    state: dict[str, int] = {}

    def visit(module: str, path: tuple[str, ...]) -> None:
        if state.get(module) == 2:
            return
        assert state.get(module) != 1, " -> ".join((*path, module))
        state[module] = 1
        for dep in sorted(graph[module]):
            visit(dep, (*path, module))
        state[module] = 2

    for module in sorted(graph):
        visit(module, ())


@pytest.mark.parametrize("function", [sp.tan, sp.Function("besselj")])
def test_an_unprintable_function_stops_generation_with_its_name(function):
    plan = build_plan(load_spec(Path(ROOT / "derive" / "arms" / "planar_2r.toml")))
    assert plan.ik is not None
    steps = list(plan.ik.steps)
    k = next(i for i, s in enumerate(steps) if isinstance(s, Solve))
    broken = replace(steps[k], args=(function(sym.named("x")), *steps[k].args[1:]))
    steps[k] = broken
    plan = replace(plan, ik=replace(plan.ik, steps=tuple(steps)))
    with pytest.raises(GenerationError) as info:
        render_module(plan)
    message = str(info.value)
    assert message.startswith("planar_2r: ") and broken.note in message
    assert f"no function {function.__name__}" in message
    assert "\n" not in message


@pytest.mark.parametrize("name", BUNDLED)
def test_public_functions_of_generated_modules_carry_type_hints(generated, name):
    m = generated(name)
    public = ["fk", "fk_batch"] + (
        ["ik", "ik_batch", "nearest", "warmup"] if hasattr(m, "ik") else []
    )
    for function in public:
        hints = typing.get_type_hints(getattr(m, function))
        assert "return" in hints, function
        params = inspect.signature(getattr(m, function)).parameters
        assert set(params) <= set(hints), function
