"""Reachability maps: how many IK solutions every pose of a voxel grid of tool poses has, and
per voxel the share of orientations reached, computed with a generated solver's ``ik_batch``.

The grid: voxels of side ``resolution`` in a cube around axis 1, in the *axis-1 frame* F: its
origin on axis 1 (where the arm's drawing puts it at the zero pose), z along the axis, x the
base's x direction made normal to the axis. There are n voxels per side (n odd, the middle
column on axis 1) covering the arm's REACH. Voxel (i, j, k) is centred at F (c_i, c_j, c_k),
c_i = (i - (n - 1) / 2) resolution.

The orientations of a voxel: ``directions`` approach directions (the tool's z axis), spread
evenly over the sphere (a Fibonacci lattice), times ``rolls`` turns of the tool about that
axis (every 360 / rolls degrees). They are stated in the voxel's *cylindrical frame*: F
turned about axis 1 by the voxel's azimuth atan2(c_j, c_i) (0 on the axis). So a pose's
rotation is R_F Rz(azimuth) O(direction, roll), and the map is exactly invariant under turns
of the arm about axis 1 (below).

Symmetry, decided from the DH table (checked on the solver's FK) and the limits:

* joint 1 revolute, not free, and turning a whole revolution (or limits not asked for): the
  poses of a voxel are those of a voxel on the x axis of F at the same distance from axis 1,
  turned about the axis, and their solutions differ by q1 only. One *column* of voxels is
  solved per distinct distance (i - c)^2 + (j - c)^2 and shared by every voxel at it.
* the last joint revolute, not free, a whole revolution (or no limits), and rolling the tool
  about its z axis the same as turning the last joint (the tool frame's z on that axis): the
  rolls of a pose have the same solutions but for q_n; one roll is solved.

Without symmetry every (i, j) is its own column. The results are the same either way (a
test compares them on a small grid).

The store (zarr; ``derive-ik[scale]``), one group:

* ``counts`` (columns, n, directions, rolls stored) uint8: the solutions of each pose (inside
  the limits when asked); ``column_of`` (n, n) int32 names the column of voxel (i, j), and
  rolls stored is 1 where the roll symmetry holds (every roll has that count).
* ``first`` (columns, n, directions, rolls stored, DOF) float32, with ``--first``: each pose's
  first solution (NaN where none).
* ``column_index`` (columns, n) float32 and ``index`` (n, n, n) float32: the reachability
  index, the share of a voxel's orientations with a solution.
* ``centres`` (n,), ``directions`` (directions, 3), ``rolls`` (rolls,) radians, ``columns``
  (columns, 2): the points of the solved columns in F.
* ``done`` (chunks,) uint8: 1 when a chunk's arrays are written. A chunk is a block of
  columns x heights with all their orientations; it is computed and written as one unit, and
  a run that finds a store with the same parameters writes only the chunks not done.

Attributes: the arm's name and spec digest, the solver source's SHA-256, the parameters, F
(``frame``, 4x4 row-major, world), the symmetries used and the reduction factor,
``complete``.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import sys
import threading
import time
from collections.abc import Iterable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from types import ModuleType
from typing import Any, TextIO

import numpy as np

from derive.assemble import RUNTIME_FILE
from derive.load import Sources, load_solver
from derive.load import digest as sources_digest
from derive.workspace import inside_limits, progress_line, section

# 2: counts' fill value NOT_COMPUTED, index and column_index created with the other arrays
FORMAT = 2
RESOLUTION = 0.05
DIRECTIONS = 200
ROLLS = 8
# poses per chunk, at most: the unit of work, storage and resuming (memory: a chunk's counts,
# 1 byte a pose, and first solutions, 4 bytes a joint; the poses and solutions of one PIECE)
CHUNK_POSES = 262_144
# chunks per Dask task, at most
DASK_CHUNKS_PER_TASK = 8
# poses per ik_batch call inside a chunk (see solve_chunk)
PIECE = 8192
# how often (seconds) a local worker process checks that the command that started it lives
PARENT_POLL = 0.5
# the largest grid side accepted (voxels)
MAX_SIDE = 1001
# what a count not computed reads as (counts' fill value: a chunk file lost from the store);
# a pose's count is at most its solver's MAX_SOLUTIONS (16)
NOT_COMPUTED = 255
# symmetry checks on the FK: random configurations, and the agreement asked (of REACH)
SYMMETRY_SAMPLES = 8
SYMMETRY_TOL = 1e-9


class ReachError(Exception):
    """A reach map cannot be made or read as asked; the message says why."""


@dataclass(frozen=True)
class Parameters:
    """What a map is made of (stored as the store's attributes)."""

    resolution: float = RESOLUTION
    directions: int = DIRECTIONS
    rolls: int = ROLLS
    within_limits: bool = False
    first: bool = False
    symmetry: bool = True
    # poses per chunk, at most (a chunk has at least one column's height)
    chunk: int = CHUNK_POSES


@dataclass(frozen=True)
class Layout:
    """The grid and the columns solved for an arm and parameters.

    Attributes:
        frame: (4, 4) F, the axis-1 frame in the world.
        centres: (n,) voxel centres along each axis of F.
        columns: (m, 2) the (x, y) in F of the solved columns.
        column_of: (n, n) the column of voxel (i, j).
        rotations: (directions, rolls stored, 3, 3) the orientations O in the cylindrical frame.
        rolls: the roll angles (all of them, also where one is stored).
        block: (columns, heights) per chunk.
        joint1, roll: the symmetries used.
        axis: the tool axis the directions are of: z, or a direction task's (TOOL_AXIS,
            derive/tasks.py), whose roll about it the task ignores.
    """

    frame: np.ndarray
    centres: np.ndarray
    columns: np.ndarray
    column_of: np.ndarray
    rotations: np.ndarray
    rolls: np.ndarray
    block: tuple[int, int]
    joint1: bool
    roll: bool
    axis: int = 2

    @property
    def side(self) -> int:
        return len(self.centres)

    @property
    def chunks(self) -> tuple[int, int]:
        """Chunks along the columns and along the heights."""
        return (
            -(-len(self.columns) // self.block[0]),
            -(-self.side // self.block[1]),
        )

    @property
    def n_chunks(self) -> int:
        a, b = self.chunks
        return a * b

    @property
    def poses(self) -> int:
        """The poses of the whole map (what an unreduced computation solves)."""
        return self.side**3 * len(self.rotations) * len(self.rolls)

    @property
    def solved(self) -> int:
        """The poses solved."""
        return len(self.columns) * self.side * self.rotations.shape[0] * self.rotations.shape[1]

    @property
    def reduction(self) -> float:
        return self.poses / self.solved

    def chunk_slices(self, chunk: int) -> tuple[slice, slice]:
        """The columns and heights of a chunk."""
        a, b = divmod(chunk, self.chunks[1])
        bc, bz = self.block
        return (
            slice(a * bc, min(len(self.columns), (a + 1) * bc)),
            slice(b * bz, min(self.side, (b + 1) * bz)),
        )


def fibonacci_directions(count: int) -> np.ndarray:
    """count unit vectors spread evenly over the sphere (a Fibonacci lattice)."""
    k = np.arange(count, dtype=float)
    z = 1.0 - (2.0 * k + 1.0) / count
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)


def tool_rotations(directions: np.ndarray, rolls: np.ndarray) -> np.ndarray:
    """(D, K, 3, 3): the rotation whose z axis is each direction, turned about it by each
    roll (roll 0: x the unit vector nearest to x or, for directions near x, to y)."""
    z = directions / np.linalg.norm(directions, axis=1)[:, None]
    helper = np.where(np.abs(z[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    x0 = helper - np.sum(helper * z, axis=1)[:, None] * z
    x0 /= np.linalg.norm(x0, axis=1)[:, None]
    y0 = np.cross(z, x0)
    c, s = np.cos(rolls)[None, :, None], np.sin(rolls)[None, :, None]
    x = c * x0[:, None] + s * y0[:, None]
    y = np.cross(np.broadcast_to(z[:, None], x.shape), x)
    return np.stack([x, y, np.broadcast_to(z[:, None], x.shape)], axis=-1)


def axis_frame(module: ModuleType, convention: str) -> np.ndarray:
    """F: origin on axis 1, z along it, x the base's x made normal to it."""
    start, x, axis = section(module, False, convention)
    frame = np.eye(4)
    frame[:3, 0], frame[:3, 1], frame[:3, 2], frame[:3, 3] = x, np.cross(axis, x), axis, start
    return frame


def _full_turn(module: ModuleType, joint: int, within_limits: bool) -> bool:
    """Joint (1-based) is revolute, not free, and turns a whole revolution where it counts."""
    if module.JOINT_TYPES[joint - 1] != "R" or joint in getattr(module, "FREE", ()):
        return False
    lo, hi = module.LIMITS[joint - 1]
    return not within_limits or hi - lo >= 2.0 * math.pi - 1e-12


def _turn(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation by angle about a unit axis (3x3)."""
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def symmetries(module: ModuleType, frame: np.ndarray, within_limits: bool) -> tuple[bool, bool]:
    """(joint-1 symmetry, roll symmetry) of the module docstring, each also checked on the FK
    at random configurations: turning joint 1 turns the tool about axis 1; turning the last
    joint rolls the tool about its own z axis."""
    rng = np.random.default_rng(0)
    dof = module.DOF
    joint1 = _full_turn(module, 1, within_limits)
    roll = _full_turn(module, dof, within_limits)
    tol = SYMMETRY_TOL * max(float(module.REACH), 1.0)
    for _ in range(SYMMETRY_SAMPLES):
        q = rng.uniform(-math.pi, math.pi, dof)
        angle = float(rng.uniform(-math.pi, math.pi))
        T = module.fk(q)
        if joint1:
            turn = np.eye(4)
            turn[:3, :3] = _turn(frame[:3, 2], angle)
            turn[:3, 3] = frame[:3, 3] - turn[:3, :3] @ frame[:3, 3]
            joint1 = bool(np.abs(module.fk(q + angle * np.eye(dof)[0]) - turn @ T).max() < tol)
        if roll:
            spin = np.eye(4)
            spin[:3, :3] = _turn(np.array([0.0, 0.0, 1.0]), angle)
            roll = bool(np.abs(module.fk(q + angle * np.eye(dof)[-1]) - T @ spin).max() < tol)
    return joint1, roll


def make_layout(module: ModuleType, convention: str, params: Parameters) -> Layout:
    """The grid, the columns and the chunks of a map (see the module docstring)."""
    half = math.ceil(float(module.REACH) / params.resolution)
    side = 2 * half + 1
    if side > MAX_SIDE:
        raise ReachError(
            f"--resolution {params.resolution:g}: {side} voxels per side for a reach of "
            f"{float(module.REACH):g}; at most {MAX_SIDE} (a coarser resolution)"
        )
    centres = (np.arange(side) - half) * params.resolution
    frame = axis_frame(module, convention)
    joint1, roll = (
        symmetries(module, frame, params.within_limits) if params.symmetry else (False, False)
    )
    i, j = np.meshgrid(np.arange(side) - half, np.arange(side) - half, indexing="ij")
    if joint1:
        keys, column_of = np.unique(i * i + j * j, return_inverse=True)
        columns = np.stack([np.sqrt(keys) * params.resolution, np.zeros(len(keys))], axis=1)
    else:
        column_of = np.arange(side * side)
        columns = np.stack([i.ravel(), j.ravel()], axis=1) * params.resolution
    rolls = 2.0 * math.pi * np.arange(params.rolls) / params.rolls
    axis = 2
    if getattr(module, "IK_COMPONENTS", "pose") == "direction":  # (derive/tasks.py)
        axis, roll = int(module.TOOL_AXIS), True  # (the task ignores the roll about its axis)
    rotations = aimed(
        tool_rotations(fibonacci_directions(params.directions), rolls[:1] if roll else rolls),
        axis,
    )
    per_cell = rotations.shape[0] * rotations.shape[1]
    cells = max(1, params.chunk // per_cell)
    bz = min(side, cells)
    bc = max(1, min(len(columns), cells // bz))
    return Layout(
        frame,
        centres,
        columns,
        column_of.reshape(side, side).astype(np.int32),
        rotations,
        rolls,
        (bc, bz),
        joint1,
        roll,
        axis,
    )


def aimed(rotations: np.ndarray, axis: int) -> np.ndarray:
    """Rotations (..., 3, 3) with their columns turned cyclically so that the z column becomes
    column axis (a direction task's tool axis; right-handed still)."""
    out = np.empty_like(rotations)
    for k in range(3):
        out[..., (axis + k) % 3] = rotations[..., (2 + k) % 3]
    return out


def chunk_poses(layout: Layout, chunk: int) -> np.ndarray:
    """The world poses of a chunk, (columns, heights, directions, rolls stored, 4, 4)."""
    cols, heights = layout.chunk_slices(chunk)
    D, K = layout.rotations.shape[:2]
    shape = (cols.stop - cols.start, heights.stop - heights.start, D, K, 4, 4)
    return np.concatenate([T.copy() for _, T in pieces(layout, chunk, 1 << 62)]).reshape(shape)


def pieces(layout: Layout, chunk: int, size: int) -> Iterable[tuple[slice, np.ndarray]]:
    """A chunk's poses, made from the grid's indices about size at a time (whole voxels):
    (rows of the chunk's flat pose list, (rows, 4, 4) poses). The poses are in a reused
    buffer, valid until the next piece: a piece that fits the cache is made and solved
    while it is there (a whole chunk's poses made first cost 38 ns a pose, against 11)."""
    cols, heights = layout.chunk_slices(chunk)
    xy = layout.columns[cols]
    z = layout.centres[heights]
    azimuth = np.arctan2(xy[:, 1], xy[:, 0])
    c, s = np.cos(azimuth), np.sin(azimuth)
    spin = np.zeros((len(xy), 3, 3))
    spin[:, 0, 0], spin[:, 0, 1], spin[:, 1, 0], spin[:, 1, 1] = c, -s, s, c
    spin[:, 2, 2] = 1.0
    D, K = layout.rotations.shape[:2]
    # each column's poses without their positions, copied to each of its voxels
    column = np.zeros((len(xy), D, K, 4, 4))
    column[..., :3, :3] = (layout.frame[:3, :3] @ spin)[:, None, None] @ layout.rotations[None]
    column[..., 3, 3] = 1.0
    points = np.empty((len(xy), len(z), 3))
    points[:, :, 0] = xy[:, None, 0]
    points[:, :, 1] = xy[:, None, 1]
    points[:, :, 2] = z[None, :]
    world = (points @ layout.frame[:3, :3].T + layout.frame[:3, 3]).reshape(-1, 3)
    per_cell = D * K
    step = max(1, size // per_cell)
    for first in range(0, len(world), step):
        cells = np.arange(first, min(len(world), first + step))
        T = _scratch(len(cells) * per_cell * 16).reshape(len(cells), D, K, 4, 4)
        np.take(column, cells // len(z), axis=0, out=T, mode="clip")  # (unbuffered)
        T[..., :3, 3] = world[cells][:, None, None, :]
        yield slice(first * per_cell, (first + len(cells)) * per_cell), T.reshape(-1, 4, 4)


_SCRATCH: list[np.ndarray] = []


def _scratch(size: int) -> np.ndarray:
    """A reused float64 buffer of size numbers for a chunk's poses (fresh memory for every
    chunk costs its page faults: about a fifth of the time of making the poses). One per
    process: chunks are made one at a time in a process (the local run's main thread, a Dask
    worker with one task thread)."""
    if not _SCRATCH or _SCRATCH[0].size < size:
        _SCRATCH[:] = [np.empty(size)]
    return _SCRATCH[0][:size]


def solve_chunk(
    module: ModuleType, layout: Layout, params: Parameters, chunk: int
) -> dict[str, np.ndarray]:
    """A chunk's arrays: counts and (with params.first) first. ik_batch gets about PIECE
    poses at a time: its solutions array then stays under 32 MB, which the C allocator keeps
    for reuse (larger ones are mapped afresh each call and cost their page faults again)."""
    cols, heights = layout.chunk_slices(chunk)
    shape = (cols.stop - cols.start, heights.stop - heights.start, *layout.rotations.shape[:2])
    n = math.prod(shape)
    counts = np.empty(n, dtype=np.uint8)
    first = np.full((n, module.DOF), np.nan, dtype=np.float32) if params.first else None
    ones = np.ones(module.MAX_SOLUTIONS, dtype=np.uint8)
    for rows, T in pieces(layout, chunk, PIECE):
        Q, valid = module.ik_batch(T)
        if params.within_limits:  # (the solutions only, as rows: most slots are empty)
            slots = np.flatnonzero(valid)
            solutions = np.take(Q.reshape(-1, module.DOF), slots, axis=0)
            valid.reshape(-1)[slots[~inside_limits(module, solutions)]] = False
        # (a uint8 product: 5 ns a pose, against 20 for sum or count_nonzero)
        counts[rows] = valid.view(np.uint8) @ ones
        if first is not None:
            has = np.flatnonzero(valid.any(axis=1))
            first[rows.start + has] = Q[has, np.argmax(valid[has], axis=1)]
    out = {"counts": counts.reshape(shape)}
    if first is not None:
        out["first"] = first.reshape(*shape, module.DOF)
    return out


# --- loading the solver in any process (the local run and Dask workers) -------------------

# --- the store --------------------------------------------------------------------------


def _zarr() -> Any:
    try:
        import zarr
    except ImportError:
        from derive.extras import install_hint

        raise ReachError(f"reach maps need zarr: {install_hint('scale')}") from None
    return zarr


def _attributes(
    name: str, digest: str, source: Sources, params: Parameters, layout: Layout
) -> dict[str, Any]:
    return {
        "format": FORMAT,
        "arm": name,
        "spec_digest": digest,
        "solver_sha256": sources_digest(source),
        "parameters": asdict(params),
        "frame": [float(v) for v in layout.frame.ravel()],
        "side": layout.side,
        "joint1_symmetry": layout.joint1,
        "roll_symmetry": layout.roll,
        "poses": layout.poses,
        "poses_solved": layout.solved,
        "reduction": layout.reduction,
        "block": list(layout.block),
    } | ({"tool_axis": layout.axis} if layout.axis != 2 else {})


def open_store(
    path: Path, name: str, digest: str, source: Sources, params: Parameters, layout: Layout
) -> Any:
    """The store at path: created for these parameters, or an existing one made with the
    same (a resumed run, which also completes a store killed while it was being created);
    another map there is an error."""
    zarr = _zarr()
    attrs = _attributes(name, digest, source, params, layout)
    if path.exists():
        try:
            group = zarr.open_group(str(path), mode="r+")
            old = dict(group.attrs)
        except Exception as exc:  # zarr raises several kinds for a folder that is not a map
            raise ReachError(f"{path}: exists and is not a reach map ({exc})") from None
        differ = sorted(k for k in attrs if old.get(k) != attrs[k])
        if differ:
            raise ReachError(
                f"{path}: holds another map (it differs in {', '.join(differ)}); "
                "choose another -o or remove it"
            )
    else:
        group = zarr.create_group(str(path), attributes=attrs)
    for key, data in _fixed_arrays(layout).items():
        array = _member(path, group, key)
        if array is None:
            group.create_array(key, data=data, chunks=data.shape)
            continue
        _check_array(path, key, array, (data.shape, data.shape, data.dtype.name, 0))
        if not np.array_equal(array[...], data):  # (a lost chunk file reads as zeros)
            array[...] = data
    # the done marks last: a store whose done array exists has every array
    for key, spec in _chunked_arrays(layout, params, _dof(source)).items():
        array = _member(path, group, key)
        if array is None:
            shape, chunks, dtype, fill = spec
            group.create_array(key, shape=shape, chunks=chunks, dtype=dtype, fill_value=fill)
        else:
            _check_array(path, key, array, spec)
    return group


def _fixed_arrays(layout: Layout) -> dict[str, np.ndarray]:
    """The arrays a layout gives (one chunk each; rewritten when a run finds them changed)."""
    return {
        "centres": layout.centres,
        "columns": layout.columns,
        "column_of": layout.column_of,
        "directions": layout.rotations[:, 0, :, layout.axis],
        "rolls": layout.rolls,
    }


# an array's shape, chunks, dtype and fill value
ArraySpec = tuple[tuple[int, ...], tuple[int, ...], str, float]


def _chunked_arrays(layout: Layout, params: Parameters, dof: int) -> dict[str, ArraySpec]:
    """The computed arrays, done last. Fill values say "not computed" where they can: a
    count NOT_COMPUTED, an index NaN (a first solution's NaN is also "none": counts tell)."""
    side, m = layout.side, len(layout.columns)
    D, K = layout.rotations.shape[:2]
    bc, bz = layout.block
    slab = max(1, min(side, 4_000_000 // (side * side)))  # the index's heights per chunk
    chunked: dict[str, ArraySpec] = {
        "counts": ((m, side, D, K), (bc, bz, D, K), "uint8", NOT_COMPUTED),
        "column_index": ((m, side), (m, side), "float32", math.nan),
        "index": ((side, side, side), (side, side, slab), "float32", math.nan),
    }
    if params.first:
        chunked["first"] = ((m, side, D, K, dof), (bc, bz, D, K, dof), "float32", math.nan)
    chunked["done"] = ((layout.n_chunks,), (1,), "uint8", 0)
    return chunked


def damaged(path: Path | str, what: str) -> ReachError:
    """The error of a store damaged after it was written (files lost or changed)."""
    return ReachError(
        f"{path}: damaged: {what}; remove it (or that array's folder: what is lost is "
        "computed again) and run the same command"
    )


def store_name(group: Any) -> str:
    """Where a store's group is, for messages: its folder (a local store), else zarr's URL."""
    return str(getattr(group.store, "root", group.store_path))


def _member(path: Path, group: Any, key: str) -> Any:
    """The array key of a store, None where it is missing; unreadable metadata is damage."""
    try:
        return group[key]
    except KeyError:
        return None
    except Exception as exc:  # zarr raises several kinds for a document it cannot read
        problem = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise damaged(path, f"{key}: unreadable ({problem[:120]})") from None


def _check_array(path: Path, key: str, array: Any, spec: ArraySpec) -> None:
    """Refuse an array of the store whose shape, chunks, dtype or fill value is not the map's."""
    shape, chunks, dtype, fill = spec
    found = tuple(getattr(array, "shape", ())), tuple(getattr(array, "chunks", ()))
    if found[0] != shape:
        raise damaged(path, f"{key}: shape {found[0]} where the map's is {shape}")
    if found[1] != chunks:
        raise damaged(path, f"{key}: chunks {found[1]} where the map's are {chunks}")
    old = float(array.fill_value)
    if np.dtype(array.dtype).name != dtype or not (
        old == fill or (math.isnan(old) and math.isnan(fill))
    ):
        raise damaged(
            path,
            f"{key}: {array.dtype} filled with {old:g} where the map's is {dtype} with {fill:g}",
        )


def _dof(source: Sources) -> int:
    """DOF of a generated module's source (its `DOF = n` line)."""
    module = next(
        text
        for name, text in sorted(source.items())
        if name.endswith(".py") and name != RUNTIME_FILE
    )
    for line in module.splitlines():
        if line.startswith("DOF = "):
            return int(line.split("=")[1])
    raise ReachError("the solver source has no DOF")  # pragma: no cover (generated always has)


def pending(path: Path, group: Any, layout: Layout) -> tuple[list[int], int]:
    """The chunks to compute: those not marked done, and those marked done whose arrays were
    lost since (a chunk file deleted or unreadable: counts that read NOT_COMPUTED, or no first
    solution where there are solutions), which are unmarked (the map is then not complete).
    Returns the chunks and how many of them were lost."""
    try:
        done = group["done"][:]
    except Exception as exc:  # (a mark's chunk file that cannot be decoded)
        raise damaged(path, f"done: unreadable ({type(exc).__name__})") from None
    counts = group["counts"]
    first = group.get("first")
    lost = [int(c) for c in np.flatnonzero(done) if _lost(layout, int(c), counts, first)]
    if lost:
        group.attrs["complete"] = False
        marks = group["done"]
        for chunk in lost:
            marks[chunk] = 0
    return sorted([int(c) for c in np.flatnonzero(done == 0)] + lost), len(lost)


def _lost(layout: Layout, chunk: int, counts: Any, first: Any) -> bool:
    """A chunk marked done whose counts (or first solutions) are not all there."""
    cols, heights = layout.chunk_slices(chunk)
    try:
        block = counts[cols, heights]
        if (block == NOT_COMPUTED).any():
            return True
        return first is not None and bool(np.isnan(first[cols, heights][block > 0]).any())
    except Exception:  # a chunk file that cannot be decoded: computed again, rewritten
        return True


def write_chunk(
    store: dict[str, Any], layout: Layout, chunk: int, data: dict[str, np.ndarray]
) -> None:
    """A chunk's arrays, then its done mark (last: a chunk killed half way is redone).
    store: the group's arrays by name (opening one reads its metadata: once per run)."""
    cols, heights = layout.chunk_slices(chunk)
    for key, values in data.items():
        store[key][cols, heights] = values
    store["done"][chunk] = 1


def arrays(group: Any) -> dict[str, Any]:
    """A store's arrays by name."""
    return {key: group[key] for key in group.array_keys()}


def finish(path: Path, group: Any, layout: Layout) -> None:
    """The reachability index (per column and height, then per voxel) from the counts, read
    chunk by chunk, and the store marked complete. (The per-voxel arrays are small: a voxel
    has directions x rolls poses.) Counts lost while the map was made are an error."""
    counts = group["counts"]
    column_index = np.zeros(counts.shape[:2], dtype=np.float32)
    for chunk in range(layout.n_chunks):
        cols, heights = layout.chunk_slices(chunk)
        block = counts[cols, heights]
        if (block == NOT_COMPUTED).any():
            raise damaged(path, f"chunk {chunk}'s counts were lost while the map was made")
        column_index[cols, heights] = (block > 0).mean(axis=(2, 3))
    group["column_index"][:] = column_index
    index = group["index"]
    slab = index.chunks[2]
    for k in range(0, layout.side, slab):
        index[:, :, k : k + slab] = column_index[:, k : k + slab][layout.column_of]
    group.attrs["complete"] = True


# --- running the chunks -----------------------------------------------------------------


def _chunk_task(
    path: str,
    name: str,
    source: Sources,
    convention: str,
    params: Parameters,
    chunks: list[int],
    threads: int,
) -> list[int]:
    """Chunks in a Dask worker: the solver, layout and arrays set up on the worker's first
    task of a map (opening a store's arrays reads their metadata: about 10 ms), then each
    chunk solved and written. Returns the chunks."""
    key = (path, name, sources_digest(source), convention, params)
    if _WORKER.get("key") != key:
        _start_worker(path, name, source, convention, params, threads)
        _WORKER["key"] = key
    return [_worker_chunk(chunk) for chunk in chunks]


# a local worker process's solver, layout and arrays (set once by _start_worker)
_WORKER: dict[str, Any] = {}
_SOLVER_MODULES: list[ModuleType] = []


def _start_worker(
    path: str, name: str, source: Sources, convention: str, params: Parameters, threads: int
) -> None:
    """A worker process: the solver, its ik_batch threads (0: as they are), the layout, the
    store."""
    module = load_solver(name, source)
    _SOLVER_MODULES.append(module)
    if threads > 0:
        _set_threads(threads)
    elif _THREADS[0]:
        setattr(module, "_THREADS", _THREADS[0])  # noqa: B010 (the module's setting)
    layout = _layouts(module, convention, params)
    store = arrays(_zarr().open_group(path, mode="r+"))
    _WORKER.update(module=module, layout=layout, params=params, store=store, key=None)


def _start_local_worker(
    path: str, name: str, source: Sources, convention: str, params: Parameters, threads: int
) -> None:
    """A local worker process: as _start_worker, and it ends itself when the command that
    started it is gone (a command killed by SIGKILL leaves its workers waiting on a queue no
    one writes to: they would wait for ever)."""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()
    _start_worker(path, name, source, convention, params, threads)


def _worker_chunk(chunk: int) -> int:
    """One chunk in a local worker process."""
    w = _WORKER
    data = solve_chunk(w["module"], w["layout"], w["params"], chunk)
    write_chunk(w["store"], w["layout"], chunk, data)
    return chunk


_LAYOUTS: dict[tuple[str, str, Parameters], Layout] = {}


def _layouts(module: ModuleType, convention: str, params: Parameters) -> Layout:
    """The layout, made once per process per module and parameters."""
    key = (module.__name__, convention, params)  # (a solver's name holds its source's hash)
    if key not in _LAYOUTS:
        _LAYOUTS[key] = make_layout(module, convention, params)
    return _LAYOUTS[key]


# the threads the solvers' ik_batch uses in this process (0: as the module chooses)
_THREADS: list[int] = [0]


def _set_threads(threads: int) -> None:
    """The threads of the solvers' ik_batch in this process (each splits its poses over
    them: the module's _THREADS), from now on."""
    _THREADS[0] = max(1, threads)
    for module in _SOLVER_MODULES:
        setattr(module, "_THREADS", _THREADS[0])  # noqa: B010 (the module's setting)


@dataclass(frozen=True)
class Run:
    """What a run did: chunks computed now and before, the poses solved now, seconds, and of
    the chunks computed those that had been done but were lost from the store since."""

    computed: int
    skipped: int
    poses: int
    seconds: float
    repaired: int = 0


def run(
    path: Path,
    name: str,
    digest: str,
    source: Sources,
    convention: str,
    params: Parameters,
    dask: str | None = None,
    worker_threads: int = 0,
    processes: int = 0,
    progress: TextIO | None = sys.stderr,
    stop_after: int | None = None,
) -> Run:
    """Make (or finish) the map at path. dask: None runs here on all cores; "local:N" on a
    LocalCluster of N worker processes; an address ("tcp://host:port") on that cluster.
    worker_threads: ik_batch's threads in each Dask worker (0: its cores / N for local:N, else
    the worker machine's cores / the worker's task threads).
    processes: without dask, worker processes here (0: one per core), each with ik_batch's
    threads = cores / processes; 1 solves in this process. Processes rather than threads:
    a process's Python work (making poses, counting, writing) then overlaps the others'
    solving (measured here: two 1-thread processes 4.4 M poses/s together, one 2-thread
    process 3.2). Started with "spawn": a script calling run needs the
    ``if __name__ == "__main__":`` guard.
    stop_after: stop (with KeyboardInterrupt) after this many chunks (for tests of resuming)."""
    module = load_solver(name, source)
    layout = _layouts(module, convention, params)
    # the Dask cluster first: an address it refuses leaves nothing written
    with _dask_client(dask, worker_threads) as session:
        group = open_store(path, name, digest, source, params, layout)
        todo, lost = pending(path, group, layout)
        ticker = _Progress(progress, len(todo), stop_after)
        if session is not None:
            chunks = _dask_chunks(session, str(path), name, source, convention, params, todo)
            for done, _ in enumerate(chunks, 1):
                ticker.tick(done)
        else:
            _run_here(
                path, (name, source, convention), module, layout, params, todo, processes, ticker
            )
    if progress is not None and todo:
        progress.write("\n")
    finish(path, group, layout)
    per_chunk = layout.solved / layout.n_chunks
    seconds = time.perf_counter() - ticker.start
    return Run(len(todo), layout.n_chunks - len(todo), round(per_chunk * len(todo)), seconds, lost)


@dataclass
class _Progress:
    """A run's progress line (drawn at most every half second, and at the end) and the
    tests' interruption after stop_after chunks."""

    stream: TextIO | None
    total: int
    stop_after: int | None
    start: float = field(default_factory=time.perf_counter)
    shown: float = 0.0

    def tick(self, done: int) -> None:
        now = time.perf_counter()
        if self.stream is not None and (now - self.shown > 0.5 or done == self.total):
            progress_line(self.stream, "reach", done, self.total, self.start, "chunks")
            self.shown = now
        if self.stop_after is not None and done >= self.stop_after:
            raise KeyboardInterrupt


def _run_here(
    path: Path,
    arm: tuple[str, Sources, str],
    module: ModuleType,
    layout: Layout,
    params: Parameters,
    todo: list[int],
    processes: int,
    ticker: _Progress,
) -> None:
    """The chunks on this machine (see run): in worker processes, or in this one. arm: the
    name, solver source and convention (what a worker process starts from)."""
    cores = os.cpu_count() or 1
    processes = min(processes or cores, len(todo))
    if processes > 1:
        threads = max(1, cores // processes)
        pool = ProcessPoolExecutor(
            max_workers=processes,
            mp_context=multiprocessing.get_context("spawn"),
            initializer=_start_local_worker,
            initargs=(str(path), *arm, params, threads),
        )
        try:
            futures = [pool.submit(_worker_chunk, chunk) for chunk in todo]
            for done, future in enumerate(as_completed(futures), 1):
                future.result()
                ticker.tick(done)
        except BaseException:
            pool.shutdown(wait=True, cancel_futures=True)  # the chunks started are finished
            raise
        pool.shutdown()
        return
    # writes go to a thread (zarr's compression and I/O overlap the next chunk's solve);
    # at most two chunks wait to be written
    store = arrays(_zarr().open_group(str(path), mode="r+"))
    with ThreadPoolExecutor(max_workers=1) as writer:
        waiting: list[Future[None]] = []
        for done, chunk in enumerate(todo, 1):
            data = solve_chunk(module, layout, params, chunk)
            waiting.append(writer.submit(write_chunk, store, layout, chunk, data))
            if len(waiting) > 2:
                waiting.pop(0).result()
            ticker.tick(done)
        for write in waiting:
            write.result()


def dask_workers(address: str) -> int:
    """The worker processes of ``--dask local:N`` (0 for a scheduler's address), checked with
    dask.distributed's presence before anything is made or written."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        from derive.extras import install_hint

        raise ReachError(f"--dask needs dask.distributed: {install_hint('scale')}") from None
    if not address.startswith("local:"):
        return 0
    try:
        workers = int(address.split(":", 1)[1])
    except ValueError:
        workers = 0
    if workers < 1:
        raise ReachError(f"--dask {address}: local:N with N >= 1 worker processes")
    return workers


@contextmanager
def _dask_client(address: str | None, worker_threads: int) -> Iterator[tuple[Any, int] | None]:
    """A Dask client of address (a LocalCluster of N worker processes for local:N) and
    ik_batch's threads per worker (0: each worker's cores / its task threads), closed on exit;
    None without an address. (A map already complete still starts the cluster.)"""
    if address is None:
        yield None
        return
    from distributed import Client, LocalCluster

    workers = dask_workers(address)
    cluster = None
    if workers:
        threads = worker_threads or max(1, (os.cpu_count() or 1) // workers)
        import dask

        # dask starts workers with MALLOC_TRIM_THRESHOLD_=65536; any fixed threshold turns
        # off glibc's adaptive mmap threshold, so every array of ik_batch is mapped afresh
        # and page-faults (measured: half the throughput). Workers here start without it.
        with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=40,
            )
        client = Client(cluster)
    else:
        threads = worker_threads
        try:
            client = Client(address, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ReachError(f"--dask {address}: cannot reach the scheduler ({exc})") from None
    try:
        yield client, threads
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _dask_chunks(
    session: tuple[Any, int],
    path: str,
    name: str,
    source: Sources,
    convention: str,
    params: Parameters,
    todo: list[int],
) -> Iterable[int]:
    """Run the chunks as Dask tasks on session's client; yields each chunk as it is written."""
    from distributed import as_completed as completed

    client, threads = session
    if not todo:
        return
    shared = client.scatter(source, broadcast=True)
    if threads == 0:
        client.run(_worker_threads)  # the setting stays with each worker process
    # tasks of a few chunks (each task costs the scheduler a few ms), about 8 a task thread
    slots = max(1, sum(client.nthreads().values()))
    size = max(1, min(DASK_CHUNKS_PER_TASK, len(todo) // (8 * slots)))
    futures = [
        client.submit(
            _chunk_task,
            path,
            name,
            shared,
            convention,
            params,
            todo[first : first + size],
            threads,
            pure=False,
        )
        for first in range(0, len(todo), size)
    ]
    for future in completed(futures):
        yield from future.result()


def _worker_threads(dask_worker: Any = None) -> int:
    """On a worker: ik_batch's threads set to its cores divided by the worker's task threads."""
    nthreads = getattr(getattr(dask_worker, "state", dask_worker), "nthreads", 1) or 1
    threads = max(1, (os.cpu_count() or 1) // int(nthreads))
    _set_threads(threads)
    return threads


def batch_alone(name: str, source: Sources, convention: str, params: Parameters) -> Run:
    """ik_batch alone on a map's solved poses, chunk by chunk as the run makes them (the
    poses made outside the timing): what the run's throughput is measured against."""
    module = load_solver(name, source)
    layout = _layouts(module, convention, params)
    seconds = 0.0
    for chunk in range(layout.n_chunks):
        for _, T in pieces(layout, chunk, PIECE):  # as solve_chunk calls it
            start = time.perf_counter()
            module.ik_batch(T)
            seconds += time.perf_counter() - start
    return Run(layout.n_chunks, 0, layout.solved, seconds)


# --- reading a map ----------------------------------------------------------------------


@dataclass(frozen=True)
class ReachMap:
    """A finished map, read back (arrays small enough to hold: not counts)."""

    group: Any
    frame: np.ndarray
    centres: np.ndarray
    index: np.ndarray
    column_of: np.ndarray
    attrs: dict[str, Any]

    def counts(self) -> np.ndarray:
        """Every pose's count, (n, n, n, directions, rolls): the columns' spread to the
        voxels and rolls (for small maps: this holds the whole map)."""
        stored = self.group["counts"][:]
        if (stored == NOT_COMPUTED).any():
            raise damaged(store_name(self.group), "counts lost (run derive reach again)")
        full = stored[self.column_of]
        rolls = len(self.group["rolls"][:])
        return np.broadcast_to(full, (*full.shape[:-1], rolls)) if full.shape[-1] != rolls else full

    def summary(self) -> str:
        a = self.attrs
        reached = self.index > 0
        mean = float(self.index[reached].mean()) if reached.any() else 0.0
        return (
            f"{a['arm']}: {a['side']}^3 voxels of {a['parameters']['resolution']:g}, "
            f"{a['parameters']['directions']} directions x {a['parameters']['rolls']} rolls = "
            f"{a['poses']:,} poses ({a['poses_solved']:,} solved, reduction x{a['reduction']:.3g}"
            f"{': joint-1 symmetry' if a['joint1_symmetry'] else ''}"
            f"{', roll symmetry' if a['roll_symmetry'] else ''}); "
            f"{int(reached.sum())} voxels reached, {int((self.index >= 1.0).sum())} in every "
            f"orientation, mean index of those reached {mean:.3f}"
        )


def load(path: Path) -> ReachMap:
    """A complete map from its store."""
    zarr = _zarr()
    try:
        group = zarr.open_group(str(path), mode="r")
        attrs = dict(group.attrs)
    except Exception as exc:
        raise ReachError(f"{path}: not a reach map ({exc})") from None
    if not attrs.get("complete"):
        raise ReachError(f"{path}: the map is not complete (run derive reach again to finish it)")
    try:
        read = {key: group[key][:] for key in ("centres", "index", "column_of")}
    except Exception as exc:  # (zarr's kinds of error for a document it cannot read)
        raise damaged(path, f"unreadable ({type(exc).__name__})") from None
    if np.isnan(read["index"]).any():
        raise damaged(path, "index lost (run derive reach again to write it)")
    return ReachMap(
        group,
        np.array(attrs["frame"]).reshape(4, 4),
        read["centres"],
        read["index"],
        read["column_of"],
        attrs,
    )


def quaternions(R: np.ndarray) -> np.ndarray:
    """Unit quaternions (x, y, z, w) of rotations R (..., 3, 3), w >= 0."""
    m = R.reshape(-1, 3, 3)
    trace = m[:, 0, 0] + m[:, 1, 1] + m[:, 2, 2]
    q = np.empty((len(m), 4))
    # each row from the largest of w, x, y, z (the well-conditioned one)
    big = np.stack([trace, m[:, 0, 0], m[:, 1, 1], m[:, 2, 2]], axis=1).argmax(axis=1)
    for case in range(4):
        rows = big == case
        a = m[rows]
        if case == 0:
            s = 2.0 * np.sqrt(1.0 + trace[rows])
            q[rows] = np.stack(
                [
                    (a[:, 2, 1] - a[:, 1, 2]) / s,
                    (a[:, 0, 2] - a[:, 2, 0]) / s,
                    (a[:, 1, 0] - a[:, 0, 1]) / s,
                    0.25 * s,
                ],
                axis=1,
            )
            continue
        i = case - 1
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + a[:, i, i] - a[:, j, j] - a[:, k, k])
        part = np.empty((len(a), 4))
        part[:, i] = 0.25 * s
        part[:, j] = (a[:, j, i] + a[:, i, j]) / s
        part[:, k] = (a[:, k, i] + a[:, i, k]) / s
        part[:, 3] = (a[:, k, j] - a[:, j, k]) / s
        q[rows] = part
    q *= np.where(q[:, 3:] < 0.0, -1.0, 1.0)
    return q.reshape(*R.shape[:-2], 4)


def h5py_module() -> Any:
    """h5py, or a ReachError saying how to install it."""
    try:
        import h5py
    except ImportError:
        from derive.extras import install_hint

        raise ReachError(f"the HDF5 export needs h5py: {install_hint('scale')}") from None
    return h5py


def export_hdf5(rmap: ReachMap, path: Path, progress: TextIO | None = sys.stderr) -> int:
    """Write the map in Reuleaux's layout: /Spheres/sphere_dataset (x, y, z, index) of the
    voxels reached, attribute Resolution, and /Poses/poses_dataset, float32 rows (voxel x, y,
    z, pose x, y, z, quaternion x, y, z, w) of every pose with a solution; world coordinates.
    Written through a temporary file beside path (removed if the export fails). Returns the
    poses."""
    h5py = h5py_module()
    tmp = path.with_name(f".{path.name}.derive-tmp")
    try:
        with h5py.File(tmp, "w") as h5:
            written = _reuleaux(h5, rmap, progress)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    os.replace(tmp, path)
    return written


def _reuleaux(h5: Any, rmap: ReachMap, progress: TextIO | None) -> int:
    """export_hdf5's datasets, written height by height (memory: one horizontal slab of the
    map). Returns the poses."""
    group = rmap.group
    counts = group["counts"]
    side = len(rmap.centres)
    directions = group["directions"][:]
    rolls = group["rolls"][:]
    rotations = aimed(tool_rotations(directions, rolls), int(rmap.attrs.get("tool_axis", 2)))
    stored_rolls = counts.shape[3]
    c = rmap.centres
    i, j = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    azimuth = np.arctan2(c[j], c[i])
    frame = rmap.frame
    written = 0
    start = time.perf_counter()
    spheres = h5.create_group("Spheres").create_dataset(
        "sphere_dataset", shape=(0, 4), maxshape=(None, 4), dtype="float64", chunks=True
    )
    spheres.attrs["Resolution"] = float(rmap.attrs["parameters"]["resolution"])
    poses = h5.create_group("Poses").create_dataset(
        "poses_dataset", shape=(0, 10), maxshape=(None, 10), dtype="float32", chunks=True
    )
    for k in range(side):
        slab = counts[:, k][rmap.column_of]  # (side, side, D, rolls stored)
        if (slab == NOT_COMPUTED).any():
            raise damaged(store_name(group), "counts lost (run derive reach again)")
        if stored_rolls != len(rolls):
            slab = np.broadcast_to(slab, (*slab.shape[:3], len(rolls)))
        points = np.stack([c[i], c[j], np.full(i.shape, c[k])], axis=-1)
        world = points @ frame[:3, :3].T + frame[:3, 3]
        reached = rmap.index[:, :, k] > 0
        rows = np.concatenate([world[reached], rmap.index[:, :, k][reached][:, None]], axis=1)
        spheres.resize(len(spheres) + len(rows), axis=0)
        spheres[len(spheres) - len(rows) :] = rows
        vi, vj, d, r = np.nonzero(slab > 0)
        if len(vi):
            spin = np.zeros((len(vi), 3, 3))
            az = azimuth[vi, vj]
            spin[:, 0, 0], spin[:, 0, 1] = np.cos(az), -np.sin(az)
            spin[:, 1, 0], spin[:, 1, 1] = np.sin(az), np.cos(az)
            spin[:, 2, 2] = 1.0
            R = frame[:3, :3] @ spin @ rotations[d, r]
            xyz = world[vi, vj]
            block = np.concatenate([xyz, xyz, quaternions(R)], axis=1).astype(np.float32)
            poses.resize(len(poses) + len(block), axis=0)
            poses[len(poses) - len(block) :] = block
            written += len(block)
        if progress is not None:
            progress_line(progress, "hdf5", k + 1, side, start, "heights")
    if progress is not None:
        progress.write("\n")
    return written


def reach_figure(rmap: ReachMap, title: str) -> Any:
    """Two sections of the reachability index: the vertical plane through axis 1 (x-z of F)
    and the horizontal plane where the most voxels are reached."""
    from derive.plot import pyplot

    plt = pyplot()
    side = len(rmap.centres)
    middle = side // 2
    height = int(np.argmax((rmap.index > 0).sum(axis=(0, 1))))
    c = rmap.centres
    step = float(c[1] - c[0]) if side > 1 else 1.0
    extent = (c[0] - step / 2, c[-1] + step / 2, c[0] - step / 2, c[-1] + step / 2)
    fig, axes = plt.subplots(1, 2, figsize=(10.5, 4.6), layout="constrained")
    panels = (
        (rmap.index[:, middle, :].T, "x (axis-1 frame)", "z (along axis 1)", "through axis 1"),
        (rmap.index[:, :, height].T, "x (axis-1 frame)", "y", f"at z = {c[height]:.3g}"),
    )
    image = None
    for ax, (data, xlabel, ylabel, label) in zip(axes, panels):
        shown = np.ma.masked_where(data <= 0, data)
        image = ax.imshow(shown, origin="lower", extent=extent, vmin=0.0, vmax=1.0, cmap="viridis")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.set_title(label, fontsize=10)
        ax.set_aspect("equal")
        ax.set_facecolor("#eeeeee")
    fig.colorbar(image, ax=list(axes), label="reachability index (share of orientations)")
    fig.suptitle(title)
    return fig
