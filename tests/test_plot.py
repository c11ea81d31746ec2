"""Pictures of the solutions (issue 19): every solution drawn, end points at the target,
deterministic SVG, a clear message without matplotlib."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from derive.cli import main, resolve_spec
from derive.pipeline import build_plan
from derive.plot import arm_drawing, figure_bytes, solutions_figure

pytest.importorskip("matplotlib", reason="pictures need matplotlib (the test extra has it)")


def arm_lines(fig):
    """Per panel, the arm's polyline (the line drawn with joint markers) as (k, 3) points."""
    out = []
    for ax in fig.axes:
        for line in ax.get_lines():
            if line.get_marker() == "o":
                out.append(np.array(line.get_data_3d()).T)
    return out


def test_the_puma_pose_of_the_report_shows_eight_arms_at_the_target(generated):
    m = generated("puma560")
    q = np.radians([20.0] * 6)
    T = m.fk(q)
    sols = m.ik(T, backend="python")
    fig, drawings = solutions_figure(m, "standard", T, sols, "puma560")
    assert len(sols) == 8 and len(fig.axes) == 8
    for points, d, row in zip(arm_lines(fig), drawings, sols):
        assert np.abs(points[-1] - m.fk(row)[:3, 3]).max() <= 1e-12
        assert np.abs(points[-1] - T[:3, 3]).max() <= 1e-9
        assert np.abs(d.tool - m.fk(row)).max() <= 1e-12
    assert "20.0, 20.0, 20.0, 20.0, 20.0, 20.0" in fig.axes[0].get_title()
    figure_bytes(fig, "png")


def test_the_lecture_cup_example_shows_its_eight_solutions(generated):
    m = generated("lecture_6r")
    plan = build_plan(resolve_spec("lecture_6r"))
    assert plan.arm.example_pose is not None
    T = np.array(plan.arm.example_pose).reshape(4, 4)
    sols = m.ik(T, backend="python")
    fig, drawings = solutions_figure(m, "modified", T, sols, "lecture_6r")
    assert len(drawings) == 8 == len(arm_lines(fig))
    for points in arm_lines(fig):
        assert np.abs(points[-1] - T[:3, 3]).max() <= 1e-9 * m.REACH
    figure_bytes(fig, "svg")


@pytest.mark.parametrize("name", ["iiwa14", "panda", "parallel_6r", "planar_2r", "manocha_canny"])
def test_drawings_end_at_fk_in_both_conventions(generated, name):
    m = generated(name)
    convention = build_plan(resolve_spec(name)).arm.convention
    for q in np.random.default_rng(4).uniform(-3, 3, (5, m.DOF)):
        d = arm_drawing(m, convention, q)
        assert np.abs(d.tool - m.fk(q)).max() <= 1e-12
        assert d.outside == tuple(
            i + 1 for i, (v, (lo, hi)) in enumerate(zip(q, m.LIMITS)) if not lo <= v <= hi
        )


@pytest.mark.parametrize(
    "command",
    [
        ["plot", "puma560", "--q", *["20"] * 6],
        ["workspace", "planar_2r", "--resolution", "9"],
    ],
)
def test_svg_is_the_same_bytes_across_runs_and_hash_seeds(tmp_path, command):
    outputs = []
    for seed in ("0", "1"):
        path = tmp_path / f"figure_{len(outputs)}.svg"
        env = dict(os.environ, PYTHONHASHSEED=seed, DERIVE_BACKEND="python")
        subprocess.run(
            [sys.executable, "-m", "derive", *command, "-o", str(path)],
            check=True,
            env=env,
            capture_output=True,
        )
        outputs.append(path.read_bytes())
    assert outputs[0] == outputs[1]
    assert b"<dc:date>" not in outputs[0]


def test_without_matplotlib_plot_says_what_to_install(monkeypatch, tmp_path, capsys):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    out = tmp_path / "p.svg"
    assert main(["plot", "puma560", "--q", *["20"] * 6, "-o", str(out)]) == 2
    assert "pip install 'matplotlib==3.11.2' (the plot extra)" in capsys.readouterr().err
    assert not out.exists()


def test_plot_refuses_other_file_types(tmp_path, capsys):
    assert main(["plot", "puma560", "--q", *["20"] * 6, "-o", str(tmp_path / "p.jpg")]) == 2
    assert "must end in .svg or .png" in capsys.readouterr().err


@pytest.mark.parametrize(
    "command",
    [
        ["path", "puma560", "--from", *["5"] * 6, "--to", "10", "20", "30", "40", "50", "60"],
        ["workspace", "puma560"],
    ],
)
def test_a_figure_that_cannot_be_written_is_refused_before_the_work(tmp_path, capsys, command):
    """-o where no file can be made (below a regular file; in /proc, where the folder exists
    but takes no new files): one line naming the path the user gave, before anything is
    printed or computed (a new user's `derive path ... -o /proc/p.svg` printed its table,
    then named a temporary file)."""
    (tmp_path / "plain").write_text("not a folder")
    for out in (tmp_path / "plain" / "p.svg", Path("/proc/derive-test.svg")):
        if out.parent == Path("/proc") and not out.parent.is_dir():
            continue  # (no /proc here)
        assert main([*command, "-o", str(out)]) == 2
        captured = capsys.readouterr()
        assert captured.out == ""
        assert captured.err.startswith(f"error: {out}: ") and captured.err.count("\n") == 1
        assert "is a regular file, not a folder" in captured.err or (
            "cannot write there" in captured.err
        )


@pytest.mark.parametrize(("fmt", "ext"), [("md", "svg"), ("tex", "png")])
def test_the_report_embeds_its_figures(tmp_path, monkeypatch, fmt, ext):
    monkeypatch.setenv("DERIVE_BACKEND", "python")  # (no numba compile of a throwaway module)
    out = tmp_path / f"planar_2r.{fmt}"
    assert main(["report", "planar_2r", "--figures", "--format", fmt, "-o", str(out)]) == 0
    text = out.read_text()
    for stem in ("solutions", "workspace"):
        name = f"planar_2r_{stem}.{ext}"
        assert (tmp_path / name).stat().st_size > 1000
        link = f"]({name})" if fmt == "md" else f"\\includegraphics[width=\\linewidth]{{{name}}}"
        assert link in text
    assert "Workspace section (101 x 101): reachable 12.5" in text


def test_generate_with_figures_embeds_them_and_check_reproduces_them(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DERIVE_BACKEND", "python")
    out = tmp_path / "gen"
    assert main(["generate", "planar_2r", "--figures", "--out", str(out)]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == [
        "derive_ik_runtime.h",
        "derive_ik_runtime.py",
        "planar_2r.md",
        "planar_2r.py",
        "planar_2r_ik.c",
        "planar_2r_ik.h",
        "planar_2r_solutions.svg",
        "planar_2r_workspace.svg",
    ]
    assert "](planar_2r_workspace.svg)" in (out / "planar_2r.md").read_text()
    assert main(["check", "planar_2r", "--figures", "--out", str(out)]) == 0
    assert "up to date (8 files)" in capsys.readouterr().out


def test_panel_titles_clear_the_row_above_and_the_axes_are_labelled(generated):
    """Issue 37: the second row's titles sat on the first row's tick labels; no axis labels."""
    m = generated("puma560")
    T = m.fk(np.radians([20.0] * 6))
    fig, _ = solutions_figure(m, "standard", T, m.ik(T, backend="python"), "puma560")
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    top, bottom = fig.axes[:4], fig.axes[4:]
    for ax in bottom:
        title = ax.title.get_window_extent(renderer)
        for above in top:
            assert not title.overlaps(above.get_tightbbox(renderer)), ax.get_title()
    for ax in fig.axes:
        assert ax.get_xlabel() and ax.get_ylabel() and ax.get_zlabel()
    figure_bytes(fig, "png")


def test_the_workspace_colour_bar_ticks_whole_solution_counts(generated):
    """Issue 37: a 2R's counts (0, 1, 2) got ticks at 0.25 steps."""
    from derive.plot import workspace_figure
    from derive.workspace import workspace

    wmap = workspace(generated("planar_2r"), True, "standard", resolution=21, progress=None)
    fig = workspace_figure(wmap, "planar_2r")
    fig.canvas.draw()
    bar = fig.axes[-1]
    low, high = bar.get_ylim()
    ticks = [t for t in bar.get_yticks() if low - 1e-9 <= t <= high + 1e-9]
    assert ticks == [0.0, 1.0, 2.0]
    figure_bytes(fig, "png")
