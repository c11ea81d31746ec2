"""Golden check: the committed generated/ is exactly what the generator writes today.

Kept apart from behaviour tests. To update after an intended change: `derive generate`.
"""

from __future__ import annotations

import os
import subprocess
import sys

from derive.cli import main

from conftest import ROOT


def test_committed_generated_is_up_to_date(capsys):
    code = main(["check", "--out", str(ROOT / "generated")])
    out = capsys.readouterr().out
    assert code == 0, f"generated/ is stale; run `derive generate` to update:\n{out}"


def test_output_is_identical_under_different_hash_seeds(tmp_path):
    outputs = []
    for seed in ("0", "12345"):
        folder = tmp_path / seed
        env = {**os.environ, "PYTHONHASHSEED": seed}
        subprocess.run(
            [sys.executable, "-m", "derive", "generate", "--out", str(folder)],
            check=True,
            env=env,
            cwd=ROOT,
            capture_output=True,
        )
        outputs.append({p.name: p.read_bytes() for p in sorted(folder.iterdir())})
    assert outputs[0] == outputs[1]
    assert len(outputs[0]) >= 5
