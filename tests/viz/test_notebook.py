"""A result in a notebook: ``_repr_html_`` is report.html's 3-D scene in an ``<iframe srcdoc>`` (the same page, no
server), ``figures()`` the output folder's figures as matplotlib Figures (saved, the same PNG bytes)."""

from __future__ import annotations

import dataclasses
import html
import re

import numpy as np
import pytest

from helpers.map_studies import gantry_map_study
from tribokin.run import run_study
from tribokin.viz.canvas import save_png
from tribokin.viz.contents import figure_names, map_scene_layers
from tribokin.viz.report import static_scene
from tribokin.viz.static import viewer_js

#: the gantry's plane map with two scenarios, a pose and the ISO cube: every kind of figure but the placement's
STUDY = gantry_map_study() | {
    "scenarios": [{"name": "raw"}, {"name": "oiled", "joints": {"friction": {"law": "constant", "mu": 0.05}}}],
    "poses": [{"name": "P", "q": [0.3, 0.2, 0.1]}], "iso_cube": {"center_m": [0.5, 0.3, 0.4], "side_m": 0.2}}


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    result = run_study(STUDY)
    return result, result.write(tmp_path_factory.mktemp("notebook") / "out")


@pytest.fixture(scope="module")
def figures(written):
    """``figures()`` of the study's result (drawn once for the tests that look at them)."""
    return written[0].figures()


def frame_page(frame: str) -> str:
    """The page an ``<iframe srcdoc>`` holds."""
    return html.unescape(re.fullmatch(r'<iframe title="3-D scene" [^>]*srcdoc="([^"]*)"></iframe>', frame)[1])


def test_a_study_shows_the_report_s_scene_inline(written):
    result, folder = written
    report = (folder / "report.html").read_text(encoding="utf-8")
    scene = html.unescape(re.search(r'<iframe title="3-D scene" srcdoc="([^"]*)"></iframe>', report)[1])
    page = frame_page(result._repr_html_())
    assert page == scene and viewer_js() in page
    assert page.count("set_object") >= scene.count("set_object") > 0


def test_a_pose_and_a_map_show_their_own_scenes_and_none_without_a_robot(written):
    result, _ = written
    pose, workspace, robot = result.poses[0], result.map, result.robot
    assert pose.robot is robot and workspace.robot is robot
    pose_page, map_page = frame_page(pose._repr_html_()), frame_page(workspace._repr_html_())
    assert pose_page == static_scene(robot, pose.q, [pose])[0] != static_scene(robot, pose.q, [])[0]  # its cloud
    assert map_page == static_scene(robot, workspace.first_reachable_q(), [], map_scene_layers(workspace))[0]
    assert dataclasses.replace(pose, robot=None)._repr_html_() is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        pose.robot = None


def test_the_figures_are_the_folder_s_pngs(written, figures, tmp_path):
    result, folder = written
    # the report's order: poses (P, then the cube's P1-P5), the map's (its directional figures included)
    assert list(figures) == figure_names(result)
    assert set(figures) == {p.name for p in folder.glob("*.png")} and len(figures) == 6 + 9
    for name, figure in figures.items():
        save_png(figure, tmp_path / name)
        assert (tmp_path / name).read_bytes() == (folder / name).read_bytes(), name


def test_a_pose_s_and_a_map_s_own_figures_are_titled_by_them(written, figures):
    result, _ = written
    (name, field), = result.poses[0].figures().items()
    assert name == "field_P.png" and field._suptitle.get_text() == "P"
    maps = result.map.figures("plane")
    assert list(maps) == [name for name in figures if name.startswith("map_")]
    assert all(figure._suptitle.get_text().startswith("plane: ") for figure in maps.values())
    assert np.all([len(figure.axes) >= 2 for figure in maps.values()])  # panels and colour bar
