"""Golden check: the committed generated/ is exactly what the generator writes today.

Kept apart from behaviour tests. To update after an intended change: `derive generate` (and
`derive generate puma560 iiwa14 --lang cpp-ikfast` for the IKFast shims).
"""

from __future__ import annotations

import os
import subprocess
import sys

from conftest import ROOT


def test_committed_generated_is_up_to_date_under_another_hash_seed():
    """`derive check` regenerates every committed file (Python, Markdown, C, header and IKFast
    shim) under PYTHONHASHSEED=12345 and compares bytes. generated/ was written under some
    other seed (and CI's own `derive check` runs under a random one), so a pass says both that
    generated/ is current and that the output does not depend on the hash seed."""
    env = {**os.environ, "PYTHONHASHSEED": "12345"}
    result = subprocess.run(
        [sys.executable, "-m", "derive", "check", "--out", str(ROOT / "generated")],
        env=env,
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, f"generated/ is stale or seed-dependent:\n{result.stdout}"
    committed = len([p for p in (ROOT / "generated").iterdir() if p.suffix != ".svg"])
    assert f"up to date ({committed} files)" in result.stdout, result.stdout
