"""Reachability maps (issue 20): the map against a direct loop over poses calling ik, the
symmetry reduction against the unreduced map, resuming after an interruption (also a real
kill), Dask against the local run, the Reuleaux export and the command."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from derive import reach
from derive.cli import main, resolve_spec
from derive.load import solver_sources
from derive.pipeline import build_plan

pytest.importorskip("zarr", reason="reach maps need zarr (the scale and test extras have it)")

# small maps: 9^3 voxels (resolution 0.3 for the PUMA's reach of 1.03) x 6 directions x 3 rolls
SMALL = {"resolution": 0.3, "directions": 6, "rolls": 3}
# the same grid for any arm: a resolution of its reach / 3.2


@pytest.fixture(autouse=True)
def _python_solver(monkeypatch, tmp_path_factory):
    """The maps here are small: numpy's batch solver (no compile); solver files in a
    temporary cache."""
    monkeypatch.setenv("DERIVE_BACKEND", "python")
    monkeypatch.setenv("DERIVE_IK_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))


def arm(name: str) -> tuple[str, str, str, str]:
    spec = resolve_spec(name)
    return spec.name, spec.digest(), solver_sources(build_plan(spec)), spec.convention


def make(path: Path, name: str, processes: int = 1, **params) -> reach.ReachMap:
    reach.run(path, *arm_args(name), small(name, **params), processes=processes, progress=None)
    return reach.load(path)


def small(name: str, **params) -> reach.Parameters:
    """SMALL's map for any arm (9 voxels a side), with params."""
    reach_of = build_plan(resolve_spec(name)).arm.reach
    return reach.Parameters(**{**SMALL, "resolution": reach_of / 3.2, **params})


def arm_args(name: str) -> tuple[str, str, str, str]:
    return _ARMS.setdefault(name, arm(name))


_ARMS: dict[str, tuple[str, str, str, str]] = {}


def direct_counts(rmap: reach.ReachMap, module, within_limits: bool) -> np.ndarray:
    """The map's definition, pose by pose: position F c, rotation R_F Rz(azimuth) O(d, r),
    each solved by ik."""
    F, c = rmap.frame, rmap.centres
    directions = rmap.group["directions"][:]
    rolls = rmap.group["rolls"][:]
    out = np.zeros((len(c), len(c), len(c), len(directions), len(rolls)), dtype=np.uint8)
    for i, j, k in np.ndindex(len(c), len(c), len(c)):
        az = math.atan2(c[j], c[i])
        spin = np.array(
            [[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]]
        )
        for d, r in np.ndindex(len(directions), len(rolls)):
            z = directions[d]
            O = reach.tool_rotations(z[None], rolls[r : r + 1])[0, 0]
            T = np.eye(4)
            T[:3, :3] = F[:3, :3] @ spin @ O
            T[:3, 3] = F[:3, :3] @ [c[i], c[j], c[k]] + F[:3, 3]
            out[i, j, k, d, r] = len(module.ik(T, within_limits=within_limits))
    return out


@pytest.mark.parametrize(
    ("name", "limits"),
    [("puma560", False), ("puma560", True), ("lecture_6r", False), ("panda", True)],
)
def test_the_map_equals_a_direct_loop_over_poses_calling_ik(name, limits, tmp_path, generated):
    rmap = make(tmp_path / "m.zarr", name, within_limits=limits)
    counts = rmap.counts()
    expected = direct_counts(rmap, generated(name), limits)
    assert counts.shape == expected.shape
    assert (counts > 0).any() and (counts == 0).any()
    assert np.array_equal(counts, expected), int((counts != expected).sum())
    index = (expected > 0).mean(axis=(3, 4))
    assert np.allclose(rmap.index, index, atol=1e-6)


@pytest.mark.parametrize("name", ["puma560", "panda", "iiwa14"])
def test_the_interval_limits_check_agrees_with_the_modulo(name, generated):
    """workspace.inside_limits (comparisons with each joint's allowed intervals) against the
    definition, some q + 2 pi k in [lo, hi], on values inside (-pi, pi] and far outside."""
    from derive.workspace import allowed, inside_limits

    module = generated(name)
    rng = np.random.default_rng(5)
    Q = rng.uniform(-math.pi, math.pi, (20000, module.DOF))
    Q[:500] *= 7.0
    assert allowed(module)
    inside = inside_limits(module, Q)
    assert 0 < inside.mean() < 1
    expected = np.ones(len(Q), dtype=bool)
    for j, ((lo, hi), kind) in enumerate(zip(module.LIMITS, module.JOINT_TYPES)):
        if kind == "R" and math.isfinite(lo) and hi - lo < 2.0 * math.pi:
            expected &= np.mod(Q[:, j] - lo, 2.0 * math.pi) <= hi - lo + 1e-12
    assert np.array_equal(inside, expected)


def test_the_orientations_are_rotations_with_the_asked_approach_and_roll():
    z = reach.fibonacci_directions(50)
    assert np.allclose(np.linalg.norm(z, axis=1), 1.0)
    assert abs(z.mean(axis=0)).max() < 0.05  # spread evenly: no side favoured
    R = reach.tool_rotations(z, np.array([0.0, 0.7]))
    assert np.allclose(R[..., 2], z[:, None])
    assert np.allclose(np.einsum("dkij,dkil->dkjl", R, R), np.eye(3))
    assert np.allclose(np.linalg.det(R), 1.0)
    turned = np.einsum("dij,j->di", R[:, 0], [math.cos(0.7), math.sin(0.7), 0.0])
    assert np.allclose(turned, R[:, 1, :, 0])


@pytest.mark.parametrize(
    ("name", "limits", "joint1", "roll"),
    [
        ("puma560", False, True, True),
        ("puma560", True, False, True),  # q1 in +-160 deg: no joint-1 symmetry
        ("lecture_6r", False, True, False),  # the tool frame is off axis 6
        ("iiwa14", False, True, False),  # q7 is free: it does not roll the tool
    ],
)
def test_the_symmetry_reduction_gives_the_unreduced_map(name, limits, joint1, roll, tmp_path):
    reduced = make(tmp_path / "r.zarr", name, within_limits=limits)
    full = make(tmp_path / "f.zarr", name, within_limits=limits, symmetry=False)
    a = reduced.attrs
    assert (a["joint1_symmetry"], a["roll_symmetry"]) == (joint1, roll)
    assert a["reduction"] == full.attrs["poses"] / a["poses_solved"]
    assert a["reduction"] > 1.0 if joint1 or roll else a["reduction"] == 1.0
    assert np.array_equal(reduced.counts(), full.counts())
    assert np.array_equal(reduced.index, full.index)


def test_an_interrupted_run_continues_without_redoing_its_chunks(tmp_path, monkeypatch):
    args = arm_args("puma560")
    params = small("puma560", symmetry=False, chunk=500)  # 27 chunks
    path = tmp_path / "m.zarr"
    with pytest.raises(KeyboardInterrupt):
        reach.run(path, *args, params, processes=1, progress=None, stop_after=2)
    solved: list[int] = []
    original = reach.solve_chunk

    def spy(module, layout, p, chunk):
        solved.append(chunk)
        return original(module, layout, p, chunk)

    monkeypatch.setattr(reach, "solve_chunk", spy)
    done = reach.run(path, *args, params, processes=1, progress=None)
    layout = reach.make_layout(reach.load_solver(args[0], args[2]), args[3], params)
    assert done.skipped == 2 and done.computed == layout.n_chunks - 2 > 0
    assert sorted(solved) == list(range(2, layout.n_chunks))
    whole = make(tmp_path / "w.zarr", "puma560", symmetry=False)
    assert whole.attrs["block"] != reach.load(path).attrs["block"]
    assert np.array_equal(reach.load(path).counts(), whole.counts())


def test_a_killed_command_finishes_with_the_same_map_when_run_again(tmp_path):
    """derive reach killed (SIGKILL) after its first chunks, then run again."""
    path = tmp_path / "k.zarr"
    command = [sys.executable, "-m", "derive", "reach", "puma560", "-o", str(path)]
    command += ["--resolution", "0.15", "--directions", "24", "--rolls", "2", "--no-symmetry"]
    command += ["--chunk", "5400"]  # 30 chunks
    env = {**os.environ, "DERIVE_BACKEND": "python"}
    # killed: the command's own process (--processes 1); run again: one worker per core
    killed = [*command, "--processes", "1"]
    run = subprocess.Popen(killed, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    marks = path / "done" / "c"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and run.poll() is None:
        if marks.exists() and len(list(marks.iterdir())) >= 3:
            break
        time.sleep(0.02)
    assert run.poll() is None, "the run ended before it could be killed: make it longer"
    run.send_signal(signal.SIGKILL)
    run.wait()
    group = reach._zarr().open_group(str(path), mode="r")
    first = int(group["done"][:].sum())
    assert 0 < first < group["done"].shape[0] and not group.attrs.get("complete")
    again = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    assert f"{first} done before" in again.stdout
    whole = make(
        tmp_path / "w.zarr", "puma560", resolution=0.15, directions=24, rolls=2, symmetry=False
    )
    assert whole.attrs["block"] != reach.load(path).attrs["block"]
    assert np.array_equal(reach.load(path).counts(), whole.counts())


def test_worker_processes_end_when_the_command_is_killed(tmp_path):
    """SIGKILL reaches the command only: its worker processes see it gone and end."""
    psutil = pytest.importorskip("psutil")  # (distributed's dependency)
    path = tmp_path / "k.zarr"
    command = [sys.executable, "-m", "derive", "reach", "puma560", "-o", str(path)]
    command += ["--resolution", "0.1", "--no-symmetry", "--processes", "2"]
    env = {**os.environ, "DERIVE_BACKEND": "python"}
    run = subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    parent = psutil.Process(run.pid)
    deadline = time.monotonic() + 60
    workers: list = []
    while time.monotonic() < deadline and len(workers) < 2 and run.poll() is None:
        workers = [p for p in parent.children() if "spawn_main" in " ".join(p.cmdline())]
        time.sleep(0.05)
    assert len(workers) == 2, "the command started no worker processes"
    run.send_signal(signal.SIGKILL)
    run.wait()
    _, alive = psutil.wait_procs(workers, timeout=30)
    assert not alive, f"{len(alive)} worker process(es) outlived the command"


def test_dask_local_workers_give_the_local_map(tmp_path):
    pytest.importorskip("distributed")
    local = make(tmp_path / "l.zarr", "lecture_6r")
    args = arm_args("lecture_6r")
    reach.run(tmp_path / "d.zarr", *args, small("lecture_6r"), dask="local:2", progress=None)
    remote = reach.load(tmp_path / "d.zarr")
    assert np.array_equal(remote.counts(), local.counts())
    assert np.array_equal(remote.index, local.index)


def test_a_dask_scheduler_address_gives_the_local_map(tmp_path):
    """--dask tcp://...: a cluster started apart (here a LocalCluster on the loopback)."""
    distributed = pytest.importorskip("distributed")
    local = make(tmp_path / "l.zarr", "puma560")
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        path = tmp_path / "d.zarr"
        reach.run(
            path, *arm_args("puma560"), small("puma560"), dask=cluster.scheduler_address,
            progress=None,
        )  # fmt: skip
    assert np.array_equal(reach.load(path).counts(), local.counts())


def test_worker_processes_give_the_map_of_one_process(tmp_path):
    one = make(tmp_path / "one.zarr", "lecture_6r", chunk=200)
    two = make(tmp_path / "two.zarr", "lecture_6r", chunk=200, processes=2)
    assert one.attrs["block"] == two.attrs["block"] and one.group["done"].shape[0] > 2
    assert np.array_equal(one.counts(), two.counts())
    assert np.array_equal(one.index, two.index)


def test_first_solutions_reach_their_poses(tmp_path, generated):
    rmap = make(tmp_path / "m.zarr", "puma560", first=True)
    first = rmap.group["first"][:]
    counts = rmap.group["counts"][:]
    assert np.array_equal(np.isnan(first).all(axis=-1), counts == 0)
    layout = reach.make_layout(generated("puma560"), "standard", small("puma560", first=True))
    T = np.concatenate(
        [reach.chunk_poses(layout, c).reshape(-1, 4, 4) for c in range(layout.n_chunks)]
    )
    Q = first.reshape(-1, 6)
    has = ~np.isnan(Q).any(axis=1)
    fk = generated("puma560").fk_batch(Q[has].astype(float))
    assert np.abs(fk - T[has]).max() < 1e-5  # float32 storage


def test_the_hdf5_export_has_reuleaux_layout(tmp_path, generated):
    h5py = pytest.importorskip("h5py")
    rmap = make(tmp_path / "m.zarr", "puma560")
    poses = reach.export_hdf5(rmap, tmp_path / "m.h5", progress=None)
    with h5py.File(tmp_path / "m.h5", "r") as h5:
        spheres = h5["/Spheres/sphere_dataset"][:]
        rows = h5["/Poses/poses_dataset"][:]
        resolution = h5["/Spheres/sphere_dataset"].attrs["Resolution"]
    assert resolution == rmap.attrs["parameters"]["resolution"]
    assert spheres.shape == (int((rmap.index > 0).sum()), 4)
    assert rows.dtype == np.float32 and rows.shape == (poses, 10)
    assert poses == int((rmap.counts() > 0).sum())
    module = generated("puma560")
    for row in rows[:: max(1, len(rows) // 25)]:
        x, y, z, w = (float(v) for v in row[6:])
        R = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        )
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, row[3:6]
        assert len(module.ik(T, tol=1e-5)) > 0  # (float32 rows)


def test_quaternions_round_trip():
    rng = np.random.default_rng(3)
    q = rng.normal(size=(200, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    q[:4] = [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]  # 180-degree turns, identity
    x, y, z, w = q.T
    R = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )
    got = reach.quaternions(R)
    assert np.allclose(got, q * np.where(q[:, 3:] < 0, -1, 1), atol=1e-12)


def test_the_command_writes_the_map_its_sections_and_says_what_it_did(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    out = tmp_path / "m.zarr"
    code = main(
        ["reach", "puma560", "-o", str(out), "--resolution", "0.3", "--directions", "6",
         "--rolls", "3", "--plot", str(tmp_path / "m.png")]
    )  # fmt: skip
    assert code == 0
    text = capsys.readouterr().out
    assert "reduction x" in text and "joint-1 symmetry" in text and "voxels reached" in text
    assert (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG"
    # the same command again: nothing left to do
    assert main(["reach", "puma560", "-o", str(out), "--resolution", "0.3", "--directions", "6",
                 "--rolls", "3"]) == 0  # fmt: skip
    assert "0 chunk(s) computed" in capsys.readouterr().out
    # --bench on a finished map says there is nothing to time
    argv = ["reach", "puma560", "-o", str(out), "--resolution", "0.3", "--directions", "6"]
    assert main([*argv, "--rolls", "3", "--bench"]) == 0
    assert "bench: nothing was computed" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--resolution", "0"], "--resolution: a positive length"),
        (["--directions", "0"], "--directions: from 1"),
        (["--plot", "m.pdf"], "--plot: m.pdf: the file must end in .svg or .png"),
        (["--dask", "local:0"], "--dask local:0: local:N with N >= 1"),
        (["--dask", "local:two"], "--dask local:two: local:N with N >= 1"),
        (["--hdf5", "-"], "-: this output cannot go to standard output"),
    ],
)
def test_bad_options_are_named_before_anything_is_written(
    argv, message, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    assert main(["reach", "puma560", "-o", "m.zarr", *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_another_map_in_the_folder_is_refused_by_name(tmp_path, capsys):
    make(tmp_path / "m.zarr", "puma560")
    assert main(["reach", "puma560", "-o", str(tmp_path / "m.zarr"), "--resolution", "0.2"]) == 2
    err = capsys.readouterr().err
    assert "m.zarr: holds another map (it differs in" in err and "parameters" in err
    (tmp_path / "x").mkdir()
    (tmp_path / "x" / "junk").write_text("not zarr")
    assert main(["reach", "puma560", "-o", str(tmp_path / "x"), "--resolution", "0.3"]) == 2
    assert "x: " in capsys.readouterr().err


def test_a_position_only_arm_is_sent_to_the_workspace_command(capsys):
    assert main(["reach", "planar_2r", "-o", "never.zarr"]) == 2
    assert "use derive workspace" in capsys.readouterr().err
    assert not Path("never.zarr").exists()


@pytest.mark.parametrize(("module", "option"), [("zarr", []), ("h5py", ["--hdf5", "m.h5"])])
def test_without_the_scale_extra_the_message_says_what_to_install(
    module, option, tmp_path, monkeypatch, capsys
):
    monkeypatch.setitem(sys.modules, module, None)
    assert main(["reach", "puma560", "-o", str(tmp_path / "m.zarr"), *option]) == 2
    assert "pip install 'zarr>=3.1' 'dask>=2025.1'" in capsys.readouterr().err  # (not on PyPI)
    assert not (tmp_path / "m.zarr").exists()  # said before any work


# a small map of several chunks, through the command
SMALL_ARGV = ["puma560", "--resolution", "0.3", "--directions", "6", "--rolls", "3"]
SMALL_ARGV += ["--chunk", "200", "--processes", "1"]


def test_a_chunk_file_lost_from_a_finished_map_is_computed_again_not_read_as_zeros(
    tmp_path, capsys
):
    path = tmp_path / "m.zarr"
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 0
    summary = capsys.readouterr().out.splitlines()[0]
    assert " 88 voxels reached" in summary
    whole = reach.load(path)
    counts, index = whole.counts().copy(), whole.index.copy()
    lost = sorted(p for p in (path / "counts" / "c").rglob("*") if p.is_file())
    assert len(lost) == whole.group["done"].shape[0]  # every chunk is stored, zeros too
    for chunk in lost:
        chunk.unlink()
    with pytest.raises(reach.ReachError, match="damaged"):
        whole.counts()  # never zeros that were not computed
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == summary
    assert f"{len(lost)} damaged chunk(s) computed again" in lines[1]
    again = reach.load(path)
    assert np.array_equal(again.counts(), counts) and np.array_equal(again.index, index)


def break_done(path: Path) -> None:
    (path / "done" / "zarr.json").write_text("[]")


def reshape_counts(path: Path) -> None:
    meta = path / "counts" / "zarr.json"
    import json

    document = json.loads(meta.read_text())
    document["shape"][0] += 1
    meta.write_text(json.dumps(document))


def lose_an_index_chunk(path: Path) -> None:
    next(p for p in (path / "index" / "c").rglob("*") if p.is_file()).unlink()


@pytest.mark.parametrize(
    ("damage", "message"),
    [
        (break_done, "done: unreadable"),
        (reshape_counts, "counts: shape (16, 9, 6, 1) where the map's is (15, 9, 6, 1)"),
    ],
)
def test_a_damaged_store_is_refused_in_one_line(damage, message, tmp_path, capsys):
    path = tmp_path / "m.zarr"
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 0
    damage(path)
    capsys.readouterr()
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}: damaged: {message}") and err.count("\n") == 1, err
    assert "remove" in err


def test_a_lost_index_chunk_is_no_zeros_and_the_command_rewrites_it(tmp_path, capsys):
    path = tmp_path / "m.zarr"
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 0
    index = reach.load(path).index.copy()
    lose_an_index_chunk(path)
    with pytest.raises(reach.ReachError, match="damaged: index"):
        reach.load(path)
    assert main(["reach", *SMALL_ARGV, "-o", str(path)]) == 0
    assert np.array_equal(reach.load(path).index, index)


def test_dask_missing_is_said_before_the_store_is_written(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    assert main(["reach", *SMALL_ARGV, "-o", str(tmp_path / "m.zarr"), "--dask", "local:1"]) == 2
    assert "--dask needs dask.distributed" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_direction_task_s_map_counts_ik_direction(tmp_path, generated):
    """A five-joint arm's map (derive/tasks.py): positions x directions of its tool axis (the
    youBot's x), the roll about it ignored (one stored); each count is ik_direction's."""
    rmap = make(tmp_path / "m.zarr", "youbot")
    assert rmap.attrs["tool_axis"] == 0 and rmap.attrs["roll_symmetry"]
    module = generated("youbot")
    counts = rmap.counts()
    F, c = rmap.frame, rmap.centres
    directions = rmap.group["directions"][:]
    for i, j, k in np.ndindex(len(c), len(c), len(c)):
        az = math.atan2(c[j], c[i])
        spin = np.array(
            [[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]]
        )
        point = F[:3, :3] @ [c[i], c[j], c[k]] + F[:3, 3]
        for d, u in enumerate(directions):
            expected = len(module.ik_direction(point, F[:3, :3] @ spin @ u))
            assert (counts[i, j, k, d] == expected).all(), (i, j, k, d)
    assert (counts > 0).any() and (counts == 0).any()


def test_a_look_at_arm_is_sent_to_the_workspace_command(capsys):
    assert main(["reach", "locobot_head", "-o", "never.zarr"]) == 2
    assert "looks at a point" in capsys.readouterr().err
    assert not Path("never.zarr").exists()
