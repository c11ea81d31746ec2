"""Generated solvers imported in this process: the module and the C files it runs, written into
the per-user solver cache under their digest and imported from there (the CLI's commands, the
reports' examples and the reach map's workers all load solvers this way).

Files keyed by their digest are written once and never change, so a solver's compiled C
(cached by the module itself, derive/runtime/native.py) is found again on the next run, by
every process of a machine and every Dask worker sharing the folder.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import tempfile
import warnings
from pathlib import Path
from types import ModuleType

from derive.plan import Plan
from derive.runtime.native import _cache_folder

# a solver's files: {file name: text}; the module is "<name>.py", the C "<name>_ik.c" and .h
Sources = dict[str, str]
BACKENDS = ("auto", "c", "python")

_LOADED: dict[str, ModuleType] = {}


class LoadError(ValueError):
    """A setting of the environment the loader cannot use (one line)."""


def solver_sources(plan: Plan) -> Sources:
    """The generated module of a plan, the runtime it runs, and, for an arm with IK, the C solver
    it runs."""
    from derive.assemble import RUNTIME_FILE
    from derive.emit import render_module, render_runtime
    from derive.emit_c import render_c

    files = {f"{plan.arm.name}.py": render_module(plan), RUNTIME_FILE: render_runtime()}
    if plan.ik is not None:
        files.update(render_c(plan))
    return files


def solver_cache() -> Path:
    """The per-user cache the generated modules compile their C into (their own rule:
    DERIVE_IK_CACHE, else $XDG_CACHE_HOME/derive-ik, else ~/.cache/derive-ik)."""
    return Path(_cache_folder())


def digest(sources: Sources) -> str:
    """The SHA-256 of a solver's files (names and texts, in name order)."""
    h = hashlib.sha256()
    for name in sorted(sources):
        h.update(name.encode() + b"\0" + sources[name].encode() + b"\0")
    return h.hexdigest()


def load_solver(name: str, sources: Sources) -> ModuleType:
    """Import the solver `name` from its files (once per process), written into the solver
    cache in a folder named by their digest. DERIVE_BACKEND in the environment ("auto", "c"
    or "python") sets the module's BACKEND.

    Raises:
        LoadError: DERIVE_BACKEND holds another value, or is "c" where the C solver cannot
            be had.
    """
    backend = os.environ.get("DERIVE_BACKEND")
    if backend is not None and backend not in BACKENDS:
        raise LoadError(f"DERIVE_BACKEND={backend[:20]!r}; allowed: {', '.join(BACKENDS)}")
    key = f"{name}_{digest(sources)[:16]}"
    if key not in _LOADED:
        folder = solver_cache() / "solvers" / key
        folder.mkdir(parents=True, exist_ok=True)
        for file, text in sources.items():
            path = folder / file
            if not path.exists() or path.read_text(encoding="utf-8") != text:
                fd, tmp = tempfile.mkstemp(prefix=f".{file}.", suffix=".tmp", dir=folder)
                with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as handle:
                    handle.write(text)
                os.replace(tmp, path)  # atomic: processes sharing the folder see all or none
        loader_spec = importlib.util.spec_from_file_location(
            f"derive_ik_{key}", folder / f"{name}.py"
        )
        assert loader_spec is not None and loader_spec.loader is not None
        module = importlib.util.module_from_spec(loader_spec)
        loader_spec.loader.exec_module(module)
        _LOADED[key] = module
    module = _LOADED[key]
    if backend is not None and hasattr(module, "BACKEND"):
        setattr(module, "BACKEND", backend)  # noqa: B010 (a generated module's setting)
        if backend == "c":
            try:
                with warnings.catch_warnings():  # (the error below says it once)
                    warnings.simplefilter("ignore")
                    module.warmup()
            except RuntimeError as exc:  # (no compiler, or no C for this arm)
                raise LoadError(f"DERIVE_BACKEND=c: {exc}") from None
    return module
