"""report.html in headless Chromium, offline: the 3-D view renders the robot and the heat map.

Needs Debian's ``chromium`` (``apt-get install chromium``). Outside CI the test
is skipped when it is missing; with ``CI=true`` it fails instead.
"""

import copy
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from helpers.viz_layers import CUBE, UNIFORM_AXIS, grid_layers
from tribokin.output.writers import write_results
from tribokin.run import run_study
from tribokin.viz.colours import ColourScale

CHROMIUM = Path("/usr/bin/chromium")
OFFLINE_FLAGS = ["--headless", "--no-sandbox", "--enable-unsafe-swiftshader", "--disable-background-networking",
                 "--no-first-run", "--disable-component-update", "--disable-sync", "--window-size=1200,900",
                 "--virtual-time-budget=5000", "--proxy-server=127.0.0.1:9", "--proxy-bypass-list=<-loopback>",
                 "--host-resolver-rules=MAP * ~NOTFOUND"]
SEGMENT_RGB = (0.80, 0.45, 0.15)  # the axis's orange segment, urdf/prismatic_axis.urdf


@pytest.fixture(scope="module")
def chromium():
    if not CHROMIUM.exists():
        if os.environ.get("CI", "").lower() == "true":
            pytest.fail(f"{CHROMIUM} is missing on CI: .ci/run must install it (apt-get install -y chromium)")
        pytest.skip(f"{CHROMIUM} not found: install it (apt-get install chromium) to run the browser test")
    return CHROMIUM


def run_chromium(chromium, profile: Path, *args) -> subprocess.CompletedProcess:
    shutil.rmtree(profile, ignore_errors=True)
    return subprocess.run([str(chromium), *OFFLINE_FLAGS, f"--user-data-dir={profile}", *args],
                          capture_output=True, text=True, timeout=60)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("browser") / "out"
    write_results(run_study(copy.deepcopy(UNIFORM_AXIS)), out, map_layers=grid_layers(), cube=CUBE)
    return out / "report.html"


def fraction_near(pixels: np.ndarray, rgb, tolerance: float) -> float:
    return float(np.mean(np.all(np.abs(pixels - np.asarray(rgb)) < tolerance, axis=-1)))


def test_3d_view_renders_robot_and_heat_map(chromium, report, tmp_path):
    screenshot = tmp_path / "report.png"
    done = run_chromium(chromium, tmp_path / "profile", f"--screenshot={screenshot}", report.as_uri())
    assert screenshot.exists(), done.stderr[-2000:]
    pixels = imread(screenshot)[..., :3]
    view = pixels[260:840, 40:1140]  # inside the scene's iframe (the colour bar is below the fold)
    red, green, blue = view[..., 0], view[..., 1], view[..., 2]
    orange = np.mean((red - blue > 0.3) & (red > green + 0.12) & (green > blue))  # the segment, shaded
    assert orange > 0.0005, f"robot not drawn: {orange:.4%} orange pixels"
    scale = ColourScale.spanning(*[layer.values_um for layer in grid_layers().values()])
    yellow, purple = scale.rgb(np.array([scale.high_um, scale.low_um]))
    assert fraction_near(view, yellow, 0.08) > 0.0003, "heat map's high end (viridis yellow) missing"
    assert fraction_near(view, purple, 0.08) > 0.0001, "heat map's low end (viridis purple) missing"


def test_page_text_has_legend_and_table(chromium, report, tmp_path):
    done = run_chromium(chromium, tmp_path / "profile", "--dump-dom", report.as_uri())
    dom = done.stdout
    assert "<b>RP_l [µm]</b> (viridis)" in dom and "unreachable target" in dom
    assert "ISO 9283 figures per pose" in dom and "AP_p [µm]" in dom and "<td>P1</td>" in dom
    assert "Map statistics" not in dom  # drawn layers, but no map among the results to give statistics of


#: A two-joint arm whose meshes are not at hand (as most vendor descriptions' package:// meshes).
MESHLESS_ARM = """<?xml version="1.0"?>
<robot name="arm">
  <link name="base"><visual><geometry><mesh filename="package://arm/meshes/base.stl"/></geometry></visual></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="100" velocity="1"/></joint>
  <link name="upper"><visual><geometry><mesh filename="package://arm/meshes/upper.stl"/></geometry></visual></link>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.4 0 0"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="100" velocity="1"/></joint>
  <link name="fore"/>
  <joint name="tool_joint" type="fixed"><parent link="fore"/><child link="tool"/><origin xyz="0.35 0 0"/></joint>
  <link name="tool"/>
</robot>
"""


def spread(mask: np.ndarray) -> tuple[float, float]:
    """The fraction of the view's width and of its height that the pixels of ``mask`` span."""
    rows, columns = np.nonzero(mask)
    return (np.ptp(columns) + 1) / mask.shape[1], (np.ptp(rows) + 1) / mask.shape[0]


def test_a_robot_whose_meshes_are_missing_is_drawn_as_a_skeleton_filling_the_view(chromium, tmp_path):
    """The view opens framed on the robot and its results: the skeleton (orange joints on grey links) and the
    cycle clouds span most of it."""
    (tmp_path / "arm").mkdir()
    (tmp_path / "arm" / "arm.urdf").write_text(MESHLESS_ARM)
    study = copy.deepcopy(UNIFORM_AXIS)
    study["robot"] = {"urdf": str(tmp_path / "arm" / "arm.urdf"), "tool_frame": "tool"}
    study["study"]["cycles"] = 5
    study["poses"] = [{"name": "P1", "q": [0.3, 0.6]}]
    write_results(run_study(study), tmp_path / "out")
    page = (tmp_path / "out" / "report.html").read_text()
    assert ("Robot drawn as a skeleton (links as segments, joints as cylinders on their axes): its meshes were not "
            "found in its package folders (arm/meshes/base.stl and 1 other).") in page
    screenshot = tmp_path / "report.png"
    done = run_chromium(chromium, tmp_path / "profile", f"--screenshot={screenshot}", report_uri(tmp_path / "out"))
    assert screenshot.exists(), done.stderr[-2000:]
    view = imread(screenshot)[..., :3][300:800, 40:1140]  # inside the scene's iframe
    red, green, blue = view[..., 0], view[..., 1], view[..., 2]
    joints = (red - blue > 0.3) & (red > green + 0.1)  # JOINT_COLOUR, shaded
    links = (np.abs(red - green) < 0.06) & (blue - red > 0.02) & (red < 0.6)  # LINK_COLOUR, a bluish grey, shaded
    assert joints.mean() > 0.002, f"joints not drawn: {joints.mean():.4%} orange pixels"
    assert links.mean() > 0.002, f"links not drawn: {links.mean():.4%} grey pixels"
    width, height = spread(joints | links)
    assert max(width / 1.5, height) > 0.4, f"the robot spans {width:.0%} x {height:.0%} of the view"


def report_uri(folder: Path) -> str:
    return (folder / "report.html").as_uri()
