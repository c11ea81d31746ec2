"""Benchmark figures of one generated solver: timings and round-trip soundness/completeness.

Pure measurement: the caller generates and imports the module (the CLI does), this module
only calls it. Timings are medians over the poses of each pose's least of three calls (see
median_us) and the best of five calls for batches, on this machine.
"""

from __future__ import annotations

import math
import statistics
import time
import tracemalloc
from functools import partial
from types import ModuleType
from typing import Any, TextIO

import numpy as np

from derive.verify import roundtrip, sample_joints, targets


def machine() -> str:
    """One line naming what ran: Python, numpy and the BLAS behind numpy's linear algebra
    (whose kernels, chosen per CPU at run time, decide the last bits of the general method's
    SVDs and eigenvalues), and the CPU model."""
    import platform

    blas = "BLAS unknown"
    try:
        config = np.show_config(mode="dicts")
        found = config["Build Dependencies"]["blas"]
        blas = f"{found.get('name', '?')} {found.get('version', '?')}"
        detail = str(found.get("openblas configuration", ""))
        if detail:
            blas += f" ({detail.split('  ', 1)[-1].strip()})"
    except (KeyError, TypeError, ValueError):
        pass
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as info:
            cpu = next(
                (line.split(":", 1)[1].strip() for line in info if line.startswith("model name")),
                cpu,
            )
    except OSError:
        pass
    return f"Python {platform.python_version()}, numpy {np.__version__}, {blas}; CPU {cpu}"


def median_us(call, args_list: list, passes: int = 3) -> float:
    """Median over the argument list of call(*args)'s wall time in microseconds, each call's
    time the least of `passes` passes over the whole list.

    This machine (a KVM guest) runs at two speeds about 1.6x apart and switches between them
    every 0.1-0.3 s (the C harness's per-round times show it: 0.81-0.84 us and 1.25-1.54 us
    a PUMA pose, in runs of 5-30 rounds). A call timed once measures the speed of its moment;
    the least of a few calls a whole pass apart measures the code (as `timeit` advises).
    """
    best = [math.inf] * len(args_list)
    for _ in range(passes):
        for k, args in enumerate(args_list):
            start = time.perf_counter()
            call(*args)
            best[k] = min(best[k], time.perf_counter() - start)
    return 1e6 * statistics.median(best)


def batch_agreement(module: ModuleType, poses: np.ndarray) -> int:
    """How many poses get exactly the Python ik's solutions (same rows, same order, 1e-6)
    from ik_batch (default backend)."""
    Q, valid = module.ik_batch(poses)
    revolute = np.array([k == "R" for k in module.JOINT_TYPES])
    agree = 0
    for T, rows, ok in zip(poses, Q, valid):
        single = module.ik(T, backend="python")
        batch = rows[ok]
        if single.shape == batch.shape:
            d = single - batch
            d[:, revolute] = np.remainder(d[:, revolute] + math.pi, 2 * math.pi) - math.pi
            agree += bool(np.abs(d).max(initial=0.0) <= 1e-6)
    return agree


def compiled_backend(module: ModuleType, pose: np.ndarray) -> dict:
    """Whether the C solver is there: ik_batch's threads and the seconds the first calls took
    (compiling the C, or loading it from the cache); empty without it."""
    start = time.perf_counter()
    if not module.warmup():
        return {}
    module.ik(pose, backend="c")
    module.ik_batch(pose[None], backend="c")
    return {"threads": module._THREADS, "compile_s": time.perf_counter() - start}


# the longest one timed ik_batch call may take (seconds): a backend's batch is timed on at most
# as many poses as fit in it by a first call's pace. At the default 100,000 poses the general
# method's Python ik_batch (about 3 ms a pose on a cobot) took 5 minutes a call, and `derive
# bench` of such an arm did not end in 24 minutes (six calls, and the C ones)
BATCH_BUDGET_S = 2.0


def batch_us(module: ModuleType, poses: np.ndarray, **options) -> tuple[float, int]:
    """ik_batch microseconds per pose: the best of five calls after a warm-up call (single
    calls on this kind of machine vary by up to 2x, the best one is repeatable), on the first
    poses that fit BATCH_BUDGET_S by the warm-up call's pace (100 poses); and how many."""
    probe = poses[:100]
    start = time.perf_counter()
    module.ik_batch(probe, **options)
    pace = (time.perf_counter() - start) / len(probe)
    n = min(len(poses), max(len(probe), int(BATCH_BUDGET_S / max(pace, 1e-9))))
    poses = poses[:n]
    best = math.inf
    for _ in range(5):
        start = time.perf_counter()
        module.ik_batch(poses, **options)
        best = min(best, time.perf_counter() - start)
    return 1e6 * best / len(poses), n


def batch_figures(module: ModuleType, n: int, seed: int, memory_n: int, threads: int) -> dict:
    """ik_batch microseconds per pose at up to n poses (default backend; with the compiled one
    also on one thread, and the Python backend; each on the poses batch_us times it on, their
    count beside it), and its peak memory at memory_n poses."""
    rng = np.random.default_rng(seed + 1)
    poses = targets(module, sample_joints(module, n, rng))
    figures: dict = {}
    figures["ik_batch_us"], figures["batch_n"] = batch_us(module, poses)
    python = batch_us(module, poses, backend="python")
    figures["ik_batch_python_us"], figures["batch_python_n"] = python
    if threads:
        setattr(module, "_THREADS", 1)  # noqa: B010 (the generated module's setting)
        try:
            one = batch_us(module, poses)
            figures["ik_batch_1thread_us"], figures["batch_1thread_n"] = one
        finally:
            setattr(module, "_THREADS", threads)  # noqa: B010
    if memory_n:
        big = targets(module, sample_joints(module, memory_n, rng))
        tracemalloc.start()
        module.ik_batch(big)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        figures.update(
            memory_n=memory_n, ik_batch_peak_mb=peak / 2**20, input_mb=big.nbytes / 2**20
        )
    return figures


def eaik_figures(module: ModuleType, poses: np.ndarray) -> dict:
    """EAIK's single and batched IK on the same poses, if eaik is installed (revolute, DH)."""
    try:
        from eaik.IK_DH import DhRobot
    except ImportError:
        return {}
    if set(module.JOINT_TYPES) != {"R"} or module.DOF != 6:
        return {}
    if "modified DH" in (module.__doc__ or ""):
        return {"eaik_skipped": "EAIK's DhRobot takes standard DH; this arm is modified DH"}
    dh = np.array(module.DH)
    flange = [np.linalg.inv(module.BASE) @ T @ np.linalg.inv(module.TOOL) for T in poses]
    try:
        robot = DhRobot(dh[:, 0], dh[:, 1], dh[:, 2])
        single = median_us(robot.IK, [(T,) for T in flange[:2000]])
        best = math.inf
        for _ in range(5):
            start = time.perf_counter()
            robot.IK_batched(flange)
            best = min(best, time.perf_counter() - start)
    except (RuntimeError, ValueError) as exc:  # EAIK refuses arms it cannot decompose
        return {"eaik_skipped": f"EAIK: {exc}"}
    batch = 1e6 * best / len(flange)
    return {"eaik_ik_us": single, "eaik_batch_us": batch}


def measure(
    module: ModuleType,
    samples: int,
    seed: int = 0,
    batch_n: int = 100_000,
    memory_n: int = 0,
    progress: TextIO | None = None,
) -> dict:
    """Timings and round-trip figures of a generated module.

    Args:
        module: the imported generated module.
        samples: joint vectors for the round trip (20% of joints at degenerate values).
        seed: the random seed.
        batch_n: the most poses for the ik_batch timing (batch_us: fewer where a call would
            take over BATCH_BUDGET_S).
        memory_n: poses for the ik_batch peak-memory figure (0: skip).
        progress: where to say which step runs (a line rewritten in place; a general arm's
            steps take up to a minute each), or None.

    Returns:
        A dict of figures (JSON-serialisable).
    """
    stage = partial(_stage, progress, module.NAME)
    rng = np.random.default_rng(seed)
    Q = sample_joints(module, samples, rng)
    # (a look-at's poses carry its point one REACH ahead: targets)
    poses = list(targets(module, Q[: min(samples, 2000)]))
    figures = {
        "name": module.NAME,
        "fk_us": median_us(module.fk, [(q,) for q in Q[:2000]]),
    }
    if hasattr(module, "ik"):
        stage("first calls (compiling the C solver or loading it)")
        figures.update(compiled_backend(module, poses[0]))
        figures["backend"] = "c" if "threads" in figures else "python"
        module.ik(poses[0])
        stage(f"ik on {len(poses)} poses, 3 passes (default and Python backends)")
        figures["ik_us"] = median_us(module.ik, [(T,) for T in poses])
        figures["ik_python_us"] = median_us(
            partial(module.ik, backend="python"), [(T,) for T in poses]
        )
        stage(f"nearest on {len(poses)} poses")
        # nearest (within the limits, every 2 pi variant considered) against the same poses
        figures["nearest_us"] = median_us(module.nearest, list(zip(poses, Q)))
        if getattr(module, "FREE", ()):
            # the free joints sampled 64 times over their limits (default backend)
            figures["ik_sweep_us"] = median_us(
                partial(module.ik_sweep, n=64), [(T,) for T in poses[:200]]
            )
        stage(f"round trip of {len(Q)} samples")
        result = roundtrip(module, Q)
        stage(f"ik_batch of up to {batch_n} poses, a call at most {BATCH_BUDGET_S:.0f} s")
        figures.update(batch_figures(module, batch_n, seed, memory_n, figures.get("threads", 0)))
        stage(f"ik_batch against the Python ik on {len(Q)} poses")
        figures["batch_agrees"] = batch_agreement(module, targets(module, Q))
        if module.JOINT_TYPES == "RRRRRR" and module.DOF == 6:
            figures.update(eaik_figures(module, module.fk_batch(Q)))
        figures.update(
            samples=result.samples,
            singular=result.singular,
            found=result.found,
            completeness=result.completeness,
            singular_found=result.singular_found,
            singular_posed=result.singular_posed,
            unsound=len(result.unsound),
            worst_rot=result.worst_rot,
            worst_pos=result.worst_pos,
            worst_singular=result.worst_singular,
            counts={str(k): v for k, v in sorted(result.counts.items())},
            summary=result.summary(),
        )
    stage("")
    return figures


def _stage(out: TextIO | None, name: str, what: str) -> None:
    """The step of an arm's benchmark now running, on one line rewritten in place (what empty:
    the line cleared), where out is not None."""
    if out is None:
        return
    text = f"bench {name}: {what}..." if what else ""
    out.write(f"\r{text:<100.100}\r")
    out.flush()


def solve_with(module: ModuleType, T: Any, values: dict) -> Any:
    """module.ik(T, **values) (a named function: the benchmark's callable)."""
    return module.ik(T, **values)


def versus(ours: float, theirs: float) -> str:
    """How our time compares with another solver's: "ours 4.1x faster" or "ours 2.3x slower"."""
    if ours <= theirs:
        return f"ours {theirs / ours:.1f}x faster"
    return f"ours {ours / theirs:.1f}x slower"


def bench_text(name: str, f: dict) -> str:
    """The human-readable lines of one arm's benchmark figures."""
    line = (
        f"{name}: generate {f['generate_s']:.2f} s; fk {f['fk_us']:.1f} us (single calls: "
        "the median over the poses of each pose's least of 3 calls)"
    )
    if "ik_us" not in f:
        return line
    if f["backend"] == "c":
        line += (
            f"\n  compiled (C, ik_batch on {f['threads']} "
            f"thread{'' if f['threads'] == 1 else 's'}; first calls {f['compile_s']:.1f} s): "
            f"ik {f['ik_us']:.1f} us/pose (median); ik_batch "
            f"{f['ik_batch_us']:.2f} us/pose at N = {f['batch_n']}, "
            f"{f['ik_batch_1thread_us']:.2f} on one thread (N = {f['batch_1thread_n']})"
        )
    line += f"\n  nearest (within limits) {f['nearest_us']:.1f} us/pose (median)"
    if "ik_sweep_us" in f:
        line += f"; ik_sweep (64 free values) {f['ik_sweep_us']:.1f} us/pose (median)"
    line += (
        f"\n  python: ik {f['ik_python_us']:.1f} us/pose (median); ik_batch "
        f"{f['ik_batch_python_us']:.2f} us/pose at N = {f['batch_python_n']}"
    )
    if "ik_batch_peak_mb" in f:
        line += (
            f"\n  ik_batch peak {f['ik_batch_peak_mb']:.0f} MB for {f['memory_n']} poses "
            f"(input {f['input_mb']:.0f} MB)"
        )
    if "eaik_skipped" in f:
        line += f"\n  {f['eaik_skipped']}"
    if "eaik_ik_us" in f:
        line += (
            f"\n  EAIK on the same poses: ik {f['eaik_ik_us']:.1f} us "
            f"({versus(f['ik_us'], f['eaik_ik_us'])}), batch {f['eaik_batch_us']:.2f} "
            f"us/pose ({versus(f['ik_batch_us'], f['eaik_batch_us'])})"
        )
    return (
        line + f"\n  ik_batch equals the Python ik on {f['batch_agrees']}/{f['samples']} poses"
        f"\n  {f['summary']}"
    )
