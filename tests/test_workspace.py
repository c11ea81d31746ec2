"""Workspace maps (issue 19): the lecture's RR cases, a spatial arm, the command."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest

from derive.cli import main
from derive.workspace import orientations, workspace

from conftest import build_module, spec_text

pytest.importorskip("matplotlib", reason="pictures need matplotlib (the test extra has it)")


def test_rr_with_l1_longer_than_l2_reaches_an_annulus_and_no_dexterous_point(tmp_path):
    """The lecture's RR example, l1 = 1 > l2 = 0.5: the annulus 0.5 <= r <= 1.5."""
    text = spec_text("rr_long", "standard", [(0, 1.0, 0, 0), (0, 0.5, 0, 0)])
    m = build_module(text, tmp_path)
    wmap = workspace(m, True, "standard", progress=None)
    exact = math.pi * (1.5**2 - 0.5**2)
    assert abs(wmap.area(wmap.reachable) - exact) <= 0.01 * exact, wmap.summary()
    assert not wmap.dexterous.any()
    r = np.hypot(*np.meshgrid(wmap.u, wmap.v))
    assert not wmap.reachable[r < 0.47].any()
    assert wmap.reachable[(r > 0.53) & (r < 1.47)].all()


def test_rr_with_equal_links_reaches_the_disk_and_is_dexterous_at_the_origin_only(generated):
    m = generated("planar_2r")
    out = io.StringIO()
    wmap = workspace(m, True, "standard", progress=out)
    exact = math.pi * 2.0**2
    assert abs(wmap.area(wmap.reachable) - exact) <= 0.01 * exact, wmap.summary()
    (row, col), *others = np.argwhere(wmap.dexterous)
    assert others == [] and wmap.u[col] == 0.0 and wmap.v[row] == 0.0
    assert "ETA" in out.getvalue()


def test_a_spatial_arm_solved_for_its_position_reaches_its_shell(tmp_path):
    """A 3-joint elbow arm (d1 0.3, a2 0.4, a3 0.3), solved for the position: its section
    through axis 1 is the annulus 0.1 <= r <= 0.7 about the shoulder. Its solutions are sorted
    by the 24 rotations of the cube, which the map's array had sized by the planar headings
    (36): a traceback on every spatial position arm (a new user's attack)."""
    text = spec_text("elbow3", "standard", [(90, 0.0, 0.3, 0), (0, 0.4, 0, 0), (0, 0.3, 0, 0)])
    m = build_module(text, tmp_path)
    assert m.IK_COMPONENTS == "position"
    wmap = workspace(m, False, "standard", resolution=61, progress=None)
    exact = math.pi * (0.7**2 - 0.1**2)
    assert abs(wmap.area(wmap.reachable) - exact) <= 0.02 * exact, wmap.summary()
    U, V = np.meshgrid(wmap.u, wmap.v)  # (the section: x along u, z along v)
    r = np.hypot(U, V - 0.3)
    assert wmap.reachable[(r > 0.13) & (r < 0.67)].all()
    assert not wmap.reachable[(r < 0.07) | (r > 0.73)].any()
    assert not wmap.dexterous.any()  # (three joints take a position, not every rotation)


def test_a_look_at_head_maps_the_points_it_sees_and_no_dexterous_workspace(generated):
    """A look-at reads a point only, so every sampled orientation of a point it sees had a
    row: the map called every such point dexterous, "all 24 orientations" (a new user's
    attack on a GR3 head). Now it samples no orientation and says so: the points its camera
    axis passes through (those farther from its pan axis than the axes' offset), no
    dexterous workspace."""
    m = generated("locobot_head")
    wmap = workspace(m, False, "modified", resolution=21, progress=None)
    assert wmap.orientations == 0 and not wmap.dexterous.any()
    assert 0.5 * wmap.reachable.size < wmap.reachable.sum() < wmap.reachable.size
    assert "no dexterous workspace" in wmap.summary() and "orientations per" not in wmap.summary()


def test_the_orientations_are_the_24_rotations_of_the_cube():
    R = orientations(False, np.array([0.0, 0.0, 1.0]), 0)
    assert R.shape == (24, 3, 3)
    assert np.allclose(np.einsum("kij,kil->kjl", R, R), np.eye(3))
    assert len({tuple(np.round(r, 9).ravel()) for r in R}) == 24


def test_a_tool_offset_makes_the_dexterous_section_smaller(generated):
    """PUMA (no tool: the orientation never moves the wrist centre) is dexterous wherever it
    reaches; the lecture's arm, with its tool frame, is not."""
    puma = workspace(generated("puma560"), False, "standard", resolution=41, progress=None)
    assert puma.reachable.any() and (puma.dexterous == puma.reachable).all()
    cup = workspace(generated("lecture_6r"), False, "modified", resolution=41, progress=None)
    assert 0 < cup.dexterous.sum() < cup.reachable.sum()
    assert cup.volume(cup.dexterous) < cup.volume(cup.reachable)


def test_the_workspace_command_writes_its_figure_and_figures(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("DERIVE_BACKEND", "python")
    out = tmp_path / "ws.svg"
    assert main(["workspace", "planar_2r", "--resolution", "41", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "planar_2r: reachable" in printed and "dexterous" in printed
    assert out.read_bytes().startswith(b"<?xml")
    assert main(["workspace", "planar_2r", "--resolution", "40"]) == 2
    assert "--resolution: an odd number" in capsys.readouterr().err


def test_the_progress_line_is_ended_before_the_summary(generated):
    """Issue 37: the summary was printed on the progress line, after "ETA 0 s"."""
    out = io.StringIO()
    workspace(generated("planar_2r"), True, "standard", resolution=21, progress=out)
    assert "ETA" in out.getvalue() and out.getvalue().endswith("\n")
