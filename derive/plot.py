"""Pictures of an arm's IK solutions: every solution of a pose drawn as a 3D stick figure.

The arm is drawn from its DH table (the generated module's DH, LIMITS, BASE and TOOL and the
spec's convention): joint origins joined by links, each joint's axis as a short arrow, the
base and tool frames as small triads, and the target frame dashed. One panel per solution,
the same view and scale in every panel, the joint values in degrees in the panel's title
and joints outside their limits marked in red.

matplotlib is an optional dependency (the ``plot`` extra; without it the message names the
package to install, see derive/extras.py); SVG output is byte-deterministic (no date, fixed
ids).
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass
from types import ModuleType
from typing import Any

import numpy as np

from derive.extras import install_hint

# the panels per row, a panel's size in inches, and the view (degrees)
COLUMNS = 4
PANEL = 3.2
ELEVATION, AZIMUTH = 25.0, -60.0
# axis arrows and frame triads as shares of the arm's size (REACH)
ARROW = 0.08
TRIAD = 0.12


class PlotUnavailable(Exception):
    """matplotlib is not installed; the message says how to install it."""


@dataclass(frozen=True)
class ArmDrawing:
    """The points of one solution's drawing (world frame).

    Attributes:
        origins: (n + 2, 3) the base origin, the joint frames' origins, the tool origin.
        axes: (n, 2, 3) each joint's axis: its origin and its direction (unit).
        base: (4, 4) the base frame.
        tool: (4, 4) the tool frame (equal to fk(q)).
        outside: the joints (1-based) outside their limits.
    """

    origins: np.ndarray
    axes: np.ndarray
    base: np.ndarray
    tool: np.ndarray
    outside: tuple[int, ...]


def arm_drawing(module: ModuleType, convention: str, q: np.ndarray) -> ArmDrawing:
    """The points of the arm at joint values q, from the module's DH table."""
    base = np.array(module.BASE, dtype=float)
    frame = base
    origins = [frame[:3, 3].copy()]
    axes = []
    for (alpha, a, d, theta), kind, value in zip(module.DH, module.JOINT_TYPES, q):
        angle = theta + value if kind == "R" else theta
        offset = d + value if kind == "P" else d
        twist = _rx(alpha) @ _tx(a)
        if convention == "modified":
            frame = frame @ twist
            axes.append((frame[:3, 3].copy(), frame[:3, 2].copy()))
            frame = frame @ _rz(angle) @ _tz(offset)
        else:
            axes.append((frame[:3, 3].copy(), frame[:3, 2].copy()))
            frame = frame @ _rz(angle) @ _tz(offset) @ twist
        origins.append(frame[:3, 3].copy())
    tool = frame @ np.array(module.TOOL, dtype=float)
    origins.append(tool[:3, 3].copy())
    outside = tuple(
        i + 1 for i, (v, (lo, hi)) in enumerate(zip(q, module.LIMITS)) if not lo <= v <= hi
    )
    return ArmDrawing(np.array(origins), np.array(axes), base, tool, outside)


def _rx(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def _rz(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _tx(x: float) -> np.ndarray:
    out = np.eye(4)
    out[0, 3] = x
    return out


def _tz(z: float) -> np.ndarray:
    out = np.eye(4)
    out[2, 3] = z
    return out


def pyplot() -> Any:
    """matplotlib's pyplot on the Agg backend (no display needed), with deterministic SVG."""
    try:
        import matplotlib
    except ImportError:
        raise PlotUnavailable(f"pictures need matplotlib: {install_hint('plot')}") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams["svg.hashsalt"] = "derive-ik"
    plt.rcParams["svg.fonttype"] = "path"
    return plt


def solutions_figure(
    module: ModuleType, convention: str, pose: np.ndarray, solutions: np.ndarray, title: str
) -> tuple[Any, list[ArmDrawing]]:
    """The figure of every solution (one panel each) and the drawings it shows."""
    plt = pyplot()
    drawings = [arm_drawing(module, convention, q) for q in solutions]
    count = max(len(drawings), 1)
    cols = min(COLUMNS, count)
    rows = math.ceil(count / cols)
    # constrained layout keeps each panel's title clear of the tick labels of the row above
    fig = plt.figure(figsize=(PANEL * cols, PANEL * rows + 0.5), layout="constrained")
    fig.suptitle(title, fontsize=10)
    points = [pose[:3, 3][None]] + [d.origins for d in drawings]
    stacked = np.vstack(points)
    centre = (stacked.max(axis=0) + stacked.min(axis=0)) / 2
    half = max(float((stacked.max(axis=0) - stacked.min(axis=0)).max()) / 2, 1e-9) * 1.1
    size = float(module.REACH)
    for k in range(count):
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        ax.view_init(elev=ELEVATION, azim=AZIMUTH)
        for axis, (lo, hi) in zip("xyz", zip(centre - half, centre + half)):
            getattr(ax, f"set_{axis}lim")(lo, hi)
        ax.set_box_aspect((1, 1, 1))
        ax.tick_params(labelsize=5, pad=0)
        for axis in "xyz":
            getattr(ax, f"set_{axis}label")(f"{axis} (world)", fontsize=6, labelpad=-4)
        _triad(ax, pose, TRIAD * size, "--")
        if not drawings:
            ax.set_title("no solution", fontsize=7)
            continue
        d = drawings[k]
        _draw_arm(ax, d, size)
        values = ", ".join(
            f"{round(math.degrees(v), 1) + 0.0:.1f}" if kind == "R" else f"{v:.3g}"
            for v, kind in zip(solutions[k], module.JOINT_TYPES)
        )
        note = f"\noutside limits: {', '.join(f'q{i}' for i in d.outside)}" if d.outside else ""
        ax.set_title(f"{k + 1}: ({values}){note}", fontsize=6, color="red" if note else "black")
    return fig, drawings


def _draw_arm(ax: Any, d: ArmDrawing, size: float) -> None:
    """Links, joint axes (red where the joint is outside its limits), base and tool triads."""
    o = d.origins
    ax.plot(o[:, 0], o[:, 1], o[:, 2], color="0.25", linewidth=2.0, marker="o", markersize=2.5)
    for i, (origin, direction) in enumerate(d.axes, start=1):
        tip = origin + ARROW * size * direction
        color = "red" if i in d.outside else "tab:blue"
        ax.plot(*zip(origin, tip), color=color, linewidth=1.2)
    _triad(ax, d.base, TRIAD * size, "-")
    _triad(ax, d.tool, TRIAD * size, "-")


def _triad(ax: Any, frame: np.ndarray, length: float, style: str) -> None:
    """x, y, z axes of a frame in red, green, blue."""
    for k, color in enumerate(("tab:red", "tab:green", "tab:blue")):
        tip = frame[:3, 3] + length * frame[:3, k]
        ax.plot(*zip(frame[:3, 3], tip), color=color, linewidth=1.0, linestyle=style)


def figure_bytes(fig: Any, fmt: str) -> bytes:
    """The figure as SVG or PNG bytes, without a date (SVG: byte-deterministic)."""
    plt = pyplot()
    buffer = io.BytesIO()
    metadata = {"Date": None} if fmt == "svg" else {"Software": None}
    fig.savefig(buffer, format=fmt, metadata=metadata, dpi=110)
    plt.close(fig)
    return buffer.getvalue()


def workspace_figure(wmap: Any, title: str) -> Any:
    """Three panels of a workspace section: reachable, dexterous, solutions per position."""
    plt = pyplot()
    from matplotlib.ticker import MaxNLocator

    fig, axes = plt.subplots(1, 3, figsize=(13.5, 4.6), layout="constrained")
    fig.suptitle(title, fontsize=10)
    extent = (wmap.u[0], wmap.u[-1], wmap.v[0], wmap.v[-1])
    section = "the arm's plane" if wmap.planar else "the plane through axis 1"
    panels = (
        (wmap.reachable, "reachable (some orientation)", "Greys"),
        (wmap.dexterous, f"dexterous (all {wmap.orientations} orientations)", "Greys"),
        (wmap.counts, "solutions (most over the orientations)", "viridis"),
    )
    if wmap.orientations == 0:  # (a look-at arm: points, no orientation read)
        panels = (
            (wmap.reachable, "points the tool axis passes through", "Greys"),
            (wmap.dexterous, "dexterous: none (a look-at reads no orientation)", "Greys"),
            (wmap.counts, "solutions", "viridis"),
        )
    for ax, (values, name, cmap) in zip(axes, panels):
        image = ax.imshow(
            values.astype(float), origin="lower", extent=extent, cmap=cmap, interpolation="nearest"
        )
        ax.set_title(name, fontsize=8)
        ax.set_xlabel(f"u (in {section})", fontsize=7)
        ax.set_ylabel("v" if wmap.planar else "along axis 1", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.set_aspect("equal")
        if cmap == "viridis":  # solution counts are whole numbers: so are the ticks
            bar = fig.colorbar(image, ax=ax, shrink=0.8)
            bar.locator = MaxNLocator(integer=True)
            bar.update_ticks()
    dots = np.argwhere(wmap.dexterous)
    if 0 < len(dots) <= 20:  # a few dexterous cells: marked, or they would not show
        axes[1].plot(wmap.u[dots[:, 1]], wmap.v[dots[:, 0]], "r.", markersize=6)
    return fig


def path_figure(Q: np.ndarray, breaks: list[tuple[int, str]], kinds: str, title: str) -> Any:
    """The joint curves of a path (ik_path's rows), one line per joint (revolute in degrees),
    the breaks marked by vertical lines."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8.0, 4.2), layout="constrained")
    steps = np.arange(len(Q))
    for j, kind in enumerate(kinds):
        values = np.degrees(Q[:, j]) if kind == "R" else Q[:, j]
        ax.plot(steps, values, label=f"q{j + 1}" + (" (deg)" if kind == "R" else ""))
    for k, _ in breaks:
        ax.axvline(k, color="red", linestyle="--", linewidth=1.0)
    ax.set_xlabel("pose on the line", fontsize=8)
    ax.set_title(f"{title}: joint values along the path" + (
        f" ({len(breaks)} break(s), red)" if breaks else ""), fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, ncol=min(len(kinds), 7))
    ax.tick_params(labelsize=7)
    return fig
