"""The arm's C solver behind the generated module: the C file beside the module (`_C_SOURCE`,
written by `derive generate` with the module) compiled on first use into a per-user cache
keyed by its digest, and loaded through ctypes (no Python headers, no build step). Where the
processor can be told (Linux's /proc/cpuinfo) it is compiled for that processor (HOST_FLAGS,
the processor part of the key), else, or where the compiler refuses those flags, for any.

The compiler is $CC (split as a shell would), else cc, gcc or clang on PATH, else zig's from
the `ziglang` package (`pip install ziglang`, or derive-ik's `compiler` extra). The cache folder is
$DERIVE_IK_CACHE, else $XDG_CACHE_HOME/derive-ik, else ~/.cache/derive-ik (%LOCALAPPDATA% on
Windows). Without a compiler or the C file the module says so once and solves in Python.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import threading
import warnings
from time import time as _time
from typing import Any

import numpy as np

from derive.runtime.arm import _C_SOURCE, DOF, MAX_SOLUTIONS, NAME
from derive.runtime.constants import BACKEND

# how the C solver is compiled (part of the cache key): C99, optimised, position-independent,
# a * b + c never contracted into one rounding (the same rows on every processor)
C_FLAGS = ("-std=c99", "-O2", "-ffp-contract=off", "-fPIC", "-shared")
# ... and, where the processor can be told (_host: its model and features join the key, so a
# cache folder machines share keeps a library per processor), for this processor with small
# loops unrolled: a calibrated arm's refinement runs its seeds in vector lanes, 4 with AVX
# where the portable build has 2 with SSE2. The module's own C (least per pose of 21 calls,
# 2,000 uniform poses), the portable build against this one: calibrated UR5 4.48 -> 2.67 us,
# calibrated KR6 4.74 -> 2.94, nominal UR5 0.97 -> 0.92, Yaskawa HC10 (general method) 92 ->
# 87, each the same output bit for bit; compile time 10-50% longer (the KR6 1.5 -> 1.6-1.7 s,
# manocha_canny 2.1-2.3 -> 3.2-3.3 s). Without GCC's
# straight-line vectorizer: GCC 12 fuses a * b - c * d pairs into one FMA instruction there
# (a complex multiplication's pattern) despite -ffp-contract=off, and the C fk differed from
# the Python one by a rounding at 80 of 200 lecture_rrr joint vectors (the lanes are vectors
# of their own: the same refinement, the KR6's output the same bit for bit). A compiler that
# refuses these flags (twice, the portable build between; noted beside the library it would
# have been, so that it is asked once) gets C_FLAGS alone, and so does a cache that cannot be
# written where it holds the portable library (_c_library).
HOST_FLAGS = ("-march=native", "-fno-tree-slp-vectorize", "-fpeel-loops")
# ik_batch splits its poses over this many threads (each call releases the GIL), at least
# _BATCH_GRAIN poses each
_THREADS = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
_BATCH_GRAIN = 256
# the C solver's return value for a pose it does not settle (the Python solver does)
_UNSETTLED = -2
# a compiler that has not finished after this many seconds is given up (the Python solver
# answers); the bundled arms compile in 0.2-2.5 s
COMPILE_TIMEOUT = 120.0
_TMP_PREFIX = "building-"
# the C runtime every arm's C file includes, beside it (derive/c/, templates/runtime.h.j2)
_C_RUNTIME = "derive_ik_runtime.h"


class _Native:
    """The compiled solver's entry points, taking addresses of contiguous float64 data (see
    the C header: <NAME>_ik.h)."""

    def __init__(self, lib: Any):
        v, d, i, n = ctypes.c_void_p, ctypes.c_double, ctypes.c_int, ctypes.c_long
        self.lib = lib
        self.fk_batch = _entry(lib, "fk_batch", (v, n, v), None)
        self.ik = _entry(lib, "ik_ref", (v, v, v, d, v), i)
        self.within_limits = _entry(lib, "within_limits", (v, i, v), i)
        self.nearest = _entry(lib, "nearest", (v, v, v, v, d, v), i)
        self.ik_batch = _entry(lib, "ik_batch", (v, n, v, n, d, v, v), None)


def _entry(lib: Any, name: str, argtypes: tuple, restype: Any) -> Any:
    """The C function <NAME>_<name> with its argument and result types set."""
    function = getattr(lib, f"{NAME}_{name}")
    function.argtypes = argtypes
    function.restype = restype
    return function


_native: Any = None
_NATIVE_LOCK = threading.Lock()
_LOCAL = threading.local()


def _scratch() -> tuple[np.ndarray, int, np.ndarray, int, np.ndarray, int]:
    """This thread's buffers for one pose and their addresses: (T (4, 4), rows (MAX_SOLUTIONS,
    DOF), q_ref (DOF,)), each followed by its address (asking an array for its address costs
    more than the C solver's work on a pose: it is asked once per thread)."""
    try:
        return _LOCAL.buffers
    except AttributeError:
        T, rows, ref = np.empty((4, 4)), np.empty((MAX_SOLUTIONS, DOF)), np.empty(DOF)
        _LOCAL.buffers = (T, T.ctypes.data, rows, rows.ctypes.data, ref, ref.ctypes.data)
        return _LOCAL.buffers


def _loaded() -> _Native | None:
    """The C solver if it has been loaded (ik's fast path: None before the first call and
    where there is none)."""
    return _native if type(_native) is _Native else None


def _native_solver(backend: str | None) -> _Native | None:
    """The compiled solver for a backend argument ("auto": the C one where it compiles, "c":
    the C one or an error, "python": None; None: BACKEND)."""
    if backend is None:
        backend = BACKEND
    if backend == "python":
        return None
    if backend not in ("auto", "c"):
        raise ValueError(f"backend must be 'auto', 'c' or 'python', got {backend!r}")
    global _native
    if _native is None:
        with _NATIVE_LOCK:
            if _native is None:
                lib, why = _c_library()
                if lib is None:
                    warnings.warn(f"{NAME}: solving in Python: {why}", RuntimeWarning, 3)
                _native = _Native(lib) if lib is not None else why
    if type(_native) is str and backend == "c":
        raise RuntimeError(f"backend='c': {_native}")
    return None if type(_native) is str else _native


def _c_compiler() -> list[str] | None:
    """The compiler command: $CC, else cc, gcc or clang on PATH, else zig's (the ziglang
    package); None if there is none."""
    named = os.environ.get("CC", "").strip()
    if named:
        return shlex.split(named)
    for name in ("cc", "gcc", "clang"):
        found = shutil.which(name)
        if found:
            return [found]
    try:
        import ziglang  # type: ignore[import-not-found]  # noqa: F401
    except ImportError:
        return None
    return [sys.executable, "-m", "ziglang", "cc"]


def _cache_folder() -> str:
    """Where compiled solvers are kept: $DERIVE_IK_CACHE, $XDG_CACHE_HOME/derive-ik,
    %LOCALAPPDATA%/derive-ik or ~/.cache/derive-ik."""
    named = os.environ.get("DERIVE_IK_CACHE")
    if named:
        return named
    root = os.environ.get("XDG_CACHE_HOME") or os.environ.get("LOCALAPPDATA")
    return os.path.join(root or os.path.join(os.path.expanduser("~"), ".cache"), "derive-ik")


def _c_library() -> tuple[Any, str]:
    """The compiled C solver, loaded (compiled first where the cache holds no sound library
    for this source, compiler and flags, and processor: HOST_FLAGS), and ""; or None and why
    not."""
    if not _C_SOURCE:
        return None, "this arm has no C solver"
    source = os.path.join(os.path.dirname(os.path.abspath(__file__)), _C_SOURCE)
    texts = {}
    for name in _c_files():
        try:
            with open(os.path.join(os.path.dirname(source), name), "rb") as file:
                texts[name] = file.read()
        except OSError:
            return None, f"{name} not found beside {__file__} (with {', '.join(_c_files())})"
    compiler = _c_compiler()
    if compiler is None:
        return None, "no C compiler (set CC, install cc, or pip install ziglang)"
    if shutil.which(compiler[0]) is None:
        return None, f"the C compiler {compiler[0]!r} (from $CC) is not found"
    host = _host()
    if not host:
        target, why, _ = _cached(compiler, C_FLAGS, "", source, texts)
        return (None, why) if why else _load(target)
    tuned = C_FLAGS + HOST_FLAGS
    target, why, flagged = _cached(compiler, tuned, host, source, texts)
    if not why:
        return _load(target)
    # (the portable library: built where the compiler failed with HOST_FLAGS; else, a timeout
    # or a cache folder it cannot write, one built before serves: a read-only cache prepared
    # on another processor)
    portable, failed, _ = _cached(compiler, C_FLAGS, "", source, texts, build=flagged)
    if failed:
        return None, failed if flagged else why
    if flagged and not os.path.exists(target + _REFUSED):
        # (it built without HOST_FLAGS: asked once more, so that a failure of the moment, cc1
        # killed, is not taken for a refusal, which is noted so that it is asked once)
        again, why, flagged = _cached(compiler, tuned, host, source, texts)
        if not why:
            return _load(again)
        if flagged:
            try:
                with open(target + _REFUSED, "w", encoding="utf-8") as file:
                    file.write(shlex.join([*compiler, *HOST_FLAGS]) + "\n")
            except OSError:
                pass  # (asked again next time)
    return _load(portable)


def _cached(
    compiler: list[str],
    flags: tuple[str, ...],
    cpu: str,
    source: str,
    texts: dict[str, bytes],
    build: bool = True,
) -> tuple[str, str, bool]:
    """The cache's library of the C compiled with flags (for the processor cpu, "" for any;
    both part of its name's digest), built first where it holds no sound one (where build is
    set); its path, "" or why it cannot be had, and whether the compiler said so (a refusal
    of HOST_FLAGS noted beside the library is read as one)."""
    command = shlex.join([*compiler, *flags]).encode()
    key = hashlib.sha256(b"\0".join((*texts.values(), command, cpu.encode()))).hexdigest()
    suffix = ".dll" if os.name == "nt" else ".dylib" if sys.platform == "darwin" else ".so"
    folder = _cache_folder()
    target = os.path.join(folder, f"{NAME}-{key[:24]}{suffix}")
    if _sound(target):  # (else absent, or damaged since it was built: built again)
        return target, "", False
    if not build:
        return target, f"no compiled solver in {folder}", False
    if os.path.exists(target + _REFUSED):
        return target, "the compiler refused these flags before", True
    try:
        os.makedirs(folder, exist_ok=True)
        why, flagged = _build(compiler, flags, source, texts, folder, target)
    except OSError as exc:
        return target, f"cannot write the compiled solver into {folder}: {exc}", False
    return target, why, flagged


def _load(target: str) -> tuple[Any, str]:
    """The library at target, loaded, and ""; or None and why not."""
    try:
        return ctypes.CDLL(target), ""
    except OSError as exc:
        return None, f"cannot load {target}: {exc}"


# beside a host library's name: the compiler refused HOST_FLAGS (C_FLAGS alone built the C)
_REFUSED = ".refused"


def _host() -> str:
    """The processor, as a compiler's -march=native sees it: the first processor's model and
    features from /proc/cpuinfo, "" where they cannot be read (not Linux: the solver is then
    compiled for any processor of its kind, C_FLAGS alone)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as file:
            first = file.read().split("\n\n", 1)[0]
    except OSError:
        return ""
    fields = [line.split(":", 1) for line in first.splitlines() if ":" in line]
    return "\n".join(f"{k.strip()}:{v.strip()}" for k, v in fields if k.strip() in _CPU_FIELDS)


# the lines of /proc/cpuinfo that name a processor and its instructions (x86, then ARM)
_CPU_FIELDS = frozenset(
    (
        *("vendor_id", "cpu family", "model", "model name", "flags"),
        *("CPU implementer", "CPU architecture", "CPU variant", "CPU part", "Features"),
    )
)


def _sound(library: str) -> bool:
    """Whether a cached library is there and whole: its SHA-256 is the one recorded beside it
    when it was built (a library cut short would crash the process that loads it)."""
    try:
        with open(library, "rb") as file:
            digest = hashlib.sha256(file.read()).hexdigest()
        with open(library + ".sha256", encoding="ascii") as file:
            return file.read().strip() == digest
    except OSError:
        return False


def _c_files() -> tuple[str, str, str]:
    """The files the arm's C solver is compiled from: its .c, its .h and the C runtime."""
    return _C_SOURCE, _C_SOURCE[:-2] + ".h", _C_RUNTIME


def _build(
    compiler: list[str],
    flags: tuple[str, ...],
    source: str,
    texts: dict[str, bytes],
    folder: str,
    target: str,
) -> tuple[str, bool]:
    """Compile the C into target (with its .sha256) with flags, in a temporary folder of the
    cache (the bytes hashed are the bytes compiled; the library appears whole or not at all);
    "" or why it failed, and whether the compiler said so (not a timeout: other flags may
    do). Temporary folders a killed process left, an hour old, are removed first."""
    for name in os.listdir(folder):
        left = os.path.join(folder, name)
        stale = name.startswith(_TMP_PREFIX) and os.path.isdir(left)
        if stale and os.path.getmtime(left) < _time() - 3600.0:
            shutil.rmtree(left, ignore_errors=True)
    with tempfile.TemporaryDirectory(prefix=_TMP_PREFIX, dir=folder) as tmp:
        for name, text in texts.items():
            with open(os.path.join(tmp, name), "wb") as file:
                file.write(text)
        built = os.path.join(tmp, "built" + os.path.splitext(target)[1])
        command = [*compiler, *flags, os.path.join(tmp, _C_SOURCE), "-o", built, "-lm"]
        try:
            done = subprocess.run(
                command, capture_output=True, text=True, check=False, timeout=COMPILE_TIMEOUT
            )
        except subprocess.TimeoutExpired:
            return f"{shlex.join(compiler)} took more than {COMPILE_TIMEOUT:g} s on {source}", False
        if done.returncode != 0:
            lines = [ln for ln in done.stderr.splitlines() if ln.strip()]
            said = next((ln for ln in lines if "error" in ln), lines[0] if lines else "")
            said = said.replace(tmp + os.sep, "")[:300]
            failed = f"{shlex.join(compiler)} failed (exit {done.returncode}) on {source}: {said}"
            return failed.rstrip(": "), True
        with open(built, "rb") as file:
            digest = hashlib.sha256(file.read()).hexdigest()
        with open(built + ".sha256", "w", encoding="ascii") as file:
            file.write(digest + "\n")
        os.replace(built + ".sha256", target + ".sha256")
        os.replace(built, target)
    return "", False


def _batch_threads(call: Any, n: int) -> None:
    """call(first, count) over n poses in up to _THREADS threads (call releases the GIL)."""
    parts = max(1, min(_THREADS or 1, n // _BATCH_GRAIN))
    if parts == 1:
        call(0, n)
        return
    bounds = [n * k // parts for k in range(parts + 1)]
    threads = [
        threading.Thread(target=call, args=(bounds[k], bounds[k + 1] - bounds[k]))
        for k in range(parts)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
