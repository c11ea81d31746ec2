"""The general method's long run: many random arms x 200 samples each, the figures issue 17
asks for (soundness, completeness on regular samples, an answer at singular samples).

Not a test (pytest does not collect it): a script, run by hand, minutes to hours::

    python tests/long_run.py run --first 0 --count 600 --jobs 2 --out long_run.jsonl
    python tests/long_run.py summary long_run.jsonl
    python tests/long_run.py show 778            # one arm's spec and its misses

Arms are drawn with numpy, one generator per seed (seed k is the same arm on every machine),
from the distribution of ``strategies.general_arms`` (hypothesis cannot draw reproducibly
outside a test): twists mix 0, +-90, 180 and generic values, lengths and offsets are zero or
not, two arms in ten have joint 3 or 4 prismatic, sizes 1e-3..1e3. Only arms the planner
gives to the general method are run (the others are the special methods' and their tests').
Each arm's samples are ``sample_joints(module, 200, default_rng(10_000 + seed))`` solved by
the Python solver. One JSON line per arm is appended to the output file, so an interrupted run
goes on where it stopped.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from derive.emit import render_module
from derive.pipeline import build_plan
from derive.plan import Eigen
from derive.spec import parse_spec
from derive.verify import roundtrip, sample_joints

from conftest import import_path, spec_text, write_runtime

SAMPLES = 200


def _pick(rng: np.random.Generator, values: list[Any]) -> Any:
    return values[int(rng.integers(len(values)))]


def _length(rng: np.random.Generator) -> float:
    return float(rng.uniform(0.1, 1.0) if rng.integers(2) else rng.uniform(-1.0, -0.1))


def _maybe_zero(rng: np.random.Generator) -> float:
    return 0.0 if rng.integers(2) else _length(rng)


def _twist(rng: np.random.Generator) -> float:
    kind = int(rng.integers(4))
    if kind == 0:
        return float(_pick(rng, [90.0, -90.0]))
    if kind == 1:
        return float(round(rng.uniform(15.0, 165.0)))
    if kind == 2:
        return float(round(rng.uniform(-165.0, -15.0)))
    return float(_pick(rng, [0.0, 180.0]))


def _offset(rng: np.random.Generator) -> float:
    if rng.integers(2):
        return float(_pick(rng, [0.0, 90.0, -90.0, 180.0]))
    return round(float(rng.uniform(-180.0, 180.0)), 3)


def draw_arm(seed: int) -> str:
    """The spec (TOML) of the long run's arm number `seed`."""
    rng = np.random.default_rng(seed)
    slider = int(_pick(rng, [0, 0, 0, 0, 0, 0, 0, 0, 3, 4]))
    convention = str(_pick(rng, ["standard", "modified"]))
    alpha = [_twist(rng) for _ in range(7)]
    a = [_maybe_zero(rng) for _ in range(7)]
    d = [0.0] + [_maybe_zero(rng) for _ in range(6)]
    theta = [0.0] + [_offset(rng) for _ in range(6)]
    a[int(rng.integers(1, 6))] = _length(rng)  # at least one link with length
    scale = 10.0 ** int(rng.integers(-3, 4))
    a = [round(v * scale, 6) for v in a]
    d = [round(v * scale, 6) for v in d]
    if convention == "modified":
        rows = [(alpha[k - 1], a[k - 1], d[k], theta[k]) for k in range(1, 7)]
    else:
        rows = [(alpha[k], a[k], d[k], theta[k]) for k in range(1, 7)]
    if not slider:
        return spec_text(f"long_run_{seed}", convention, rows)
    kinds = "RRRRRR"[: slider - 1] + "P" + "RRRRRR"[slider:]
    text = spec_text(f"long_run_{seed}", convention, rows, kinds=kinds)
    return text.replace('type = "P"\n', f'type = "P"\nlimits = [{-scale}, {scale}]\n')


def run_arm(seed: int) -> dict[str, Any]:
    """Generate arm `seed`'s module and solve its samples: one record."""
    text = draw_arm(seed)
    started = time.perf_counter()
    plan = build_plan(parse_spec(text, f"<long run {seed}>"))
    record: dict[str, Any] = {"seed": seed, "method": plan.ik and plan.ik.method}
    if plan.ik is None or plan.ik.method != "general":
        return record
    source = render_module(plan)
    record["generation_s"] = round(time.perf_counter() - started, 3)
    eigen = next(step for step in plan.ik.steps if isinstance(step, Eigen))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"long_run_{seed}.py"
        path.write_text(source, encoding="utf-8")
        write_runtime(Path(folder))
        module = import_path(path)
        Q = sample_joints(module, SAMPLES, np.random.default_rng(10_000 + seed))
        started = time.perf_counter()
        result = roundtrip(module, Q, "python")
    record.update(
        solve_s=round(time.perf_counter() - started, 3),
        kinds="".join(module.JOINT_TYPES),
        perturbed=eigen.splits[0].singular,
        samples=result.samples,
        singular=result.singular,
        found=result.found,
        misses=result.misses,
        singular_posed=result.singular_posed,
        unsound=result.unsound,
        worst_rot=result.worst_rot,
        worst_pos=result.worst_pos,
    )
    return record


def run(first: int, count: int, jobs: int, out: Path) -> None:
    done = set()
    if out.exists():
        done = {json.loads(line)["seed"] for line in out.read_text().splitlines() if line}
    seeds = [s for s in range(first, first + count) if s not in done]
    with ProcessPoolExecutor(jobs) as pool, out.open("a") as sink:
        for k, record in enumerate(pool.map(run_arm, seeds), 1):
            sink.write(json.dumps(record) + "\n")
            sink.flush()
            print(f"\r{k}/{len(seeds)} arms (seed {record['seed']})", end="", file=sys.stderr)
    print(file=sys.stderr)


def summary(paths: list[Path]) -> str:
    records = [json.loads(line) for p in paths for line in p.read_text().splitlines() if line]
    arms = [r for r in records if r["method"] == "general"]
    lines = [f"{len(records)} arms drawn, {len(arms)} solved by the general method"]

    def share(group: list[dict[str, Any]], label: str) -> None:
        regular = sum(r["samples"] - r["singular"] for r in group)
        found = sum(r["found"] for r in group)
        singular = sum(r["singular"] for r in group)
        posed = sum(r["singular_posed"] for r in group)
        pct = 100 * found / regular if regular else math.nan
        lines.append(
            f"  {label}: {len(group)} arms, regular complete {found}/{regular} = {pct:.3f}%, "
            f"singular answered {posed}/{singular}, unsound {sum(len(r['unsound']) for r in group)}"
        )

    share(arms, "all")
    share([r for r in arms if "P" not in r["kinds"]], "revolute")
    share([r for r in arms if "P" in r["kinds"]], "prismatic")
    share([r for r in arms if r["perturbed"]], "perturbed table")
    worst = sorted(arms, key=lambda r: -len(r["misses"]))[:8]
    lines.append("  most misses: " + ", ".join(f"{r['seed']}: {len(r['misses'])}" for r in worst))
    unanswered = [r["seed"] for r in arms if r["singular_posed"] < r["singular"]]
    lines.append(f"  arms with an unanswered singular sample: {unanswered}")
    gen = sorted(r["generation_s"] for r in arms)
    if gen:
        lines.append(f"  generation: median {gen[len(gen) // 2]:.2f} s, max {gen[-1]:.2f} s")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p_run = sub.add_parser("run")
    p_run.add_argument("--first", type=int, default=0)
    p_run.add_argument("--count", type=int, default=600)
    p_run.add_argument("--jobs", type=int, default=2)
    p_run.add_argument("--out", type=Path, default=Path("long_run.jsonl"))
    p_sum = sub.add_parser("summary")
    p_sum.add_argument("files", type=Path, nargs="+")
    p_show = sub.add_parser("show")
    p_show.add_argument("seed", type=int)
    args = parser.parse_args()
    if args.command == "run":
        run(args.first, args.count, args.jobs, args.out)
    elif args.command == "summary":
        print(summary(args.files))
    else:
        print(draw_arm(args.seed))


if __name__ == "__main__":
    main()
