"""Benchmark figures of one generated solver: timings and round-trip soundness/completeness.

Pure measurement: the caller generates and imports the module (the CLI does), this module
only calls it. Timings are medians over repeated calls on this machine.
"""

from __future__ import annotations

import statistics
import time
from types import ModuleType

import numpy as np

from derive.verify import roundtrip, sample_joints


def median_us(call, args_list: list) -> float:
    """Median wall time of call(*args) in microseconds over the argument list."""
    times = []
    for args in args_list:
        start = time.perf_counter()
        call(*args)
        times.append(time.perf_counter() - start)
    return 1e6 * statistics.median(times)


def measure(module: ModuleType, samples: int, seed: int = 0) -> dict:
    """Timings and round-trip figures of a generated module.

    Args:
        module: the imported generated module.
        samples: joint vectors for the round trip (20% of joints at degenerate values).
        seed: the random seed.

    Returns:
        A dict of figures (JSON-serialisable).
    """
    rng = np.random.default_rng(seed)
    Q = sample_joints(module, samples, rng)
    poses = [module.fk(q) for q in Q[: min(samples, 2000)]]
    figures = {
        "name": module.NAME,
        "fk_us": median_us(module.fk, [(q,) for q in Q[:2000]]),
    }
    if hasattr(module, "ik"):
        module.ik(poses[0])
        figures["ik_us"] = median_us(module.ik, [(T,) for T in poses])
        result = roundtrip(module, Q)
        figures.update(
            samples=result.samples, singular=result.singular, found=result.found,
            completeness=result.completeness, singular_found=result.singular_found,
            singular_posed=result.singular_posed,
            unsound=len(result.unsound), worst_rot=result.worst_rot, worst_pos=result.worst_pos,
            worst_singular=result.worst_singular,
            counts={str(k): v for k, v in sorted(result.counts.items())},
            summary=result.summary(),
        )
    return figures
