"""The compiled backend is an addition, not a replacement: the module's Python functions stay
Python, and numba's cache serves a module imported by path as well as by name."""

from __future__ import annotations

import shutil
import subprocess
import sys
import types

import numpy as np

from derive.verify import sample_joints

from conftest import GENERATED, import_path, needs_numba

# import by path under a name of its own, warm up, and say where the machine code came from
PROBE = """
import importlib.util, sys
spec = importlib.util.spec_from_file_location(sys.argv[2], sys.argv[1])
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
assert m.warmup()
kone = m._compile()[1]
print(sum(kone.stats.cache_hits.values()), sum(kone.stats.cache_misses.values()))
"""


@needs_numba
def test_python_backend_is_the_same_before_and_after_a_compiled_call(tmp_path):
    shutil.copy(GENERATED / "puma560.py", tmp_path / "puma560.py")
    m = import_path(tmp_path / "puma560.py")
    poses = m.fk_batch(sample_joints(m, 300, np.random.default_rng(3)))
    before = [m.ik(T, backend="python") for T in poses]
    batch_before = m.ik_batch(poses, backend="python")
    helpers = {n: getattr(m, n) for n in m._KERNEL}
    assert m.warmup()
    m.ik(poses[0], backend="numba")
    m.ik_batch(poses, backend="numba")
    for name, function in helpers.items():
        assert getattr(m, name) is function and type(function) is types.FunctionType, name
    after = [m.ik(T, backend="python") for T in poses]
    batch_after = m.ik_batch(poses, backend="python")
    assert all(np.array_equal(a, b) for a, b in zip(before, after))
    assert all(np.array_equal(a, b) for a, b in zip(batch_before, batch_after))


@needs_numba
def test_numba_cache_serves_a_module_imported_by_path(tmp_path):
    shutil.copy(GENERATED / "planar_2r.py", tmp_path / "planar_2r.py")
    runs = []
    for name in ("first_import_name", "another_import_name"):
        result = subprocess.run(
            [sys.executable, "-c", PROBE, str(tmp_path / "planar_2r.py"), name],
            capture_output=True,
            text=True,
            timeout=600,
        )
        assert result.returncode == 0, result.stderr
        runs.append(tuple(int(x) for x in result.stdout.split()))
    assert runs[0] == (0, 1)  # compiled, and written to __pycache__
    assert runs[1] == (1, 0)  # loaded from the cache, under another module name
    assert any((tmp_path / "__pycache__").glob("planar_2r._kone-*.nbi"))
