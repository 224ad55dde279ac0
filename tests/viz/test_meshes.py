"""Mesh safety: a URDF whose mesh resolves outside its package folders is refused (command line: test_bad_input.py)."""


import pytest

from tribokin.errors import InputError
from tribokin.robot import load_urdf
from tribokin.viz.meshes import mesh_files
from tribokin.viz.report import write_report
from tribokin.study import run_study

TETRAHEDRON_STL = """solid t
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0.05 0 0
  vertex 0 0.05 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 0 0 0.05
  vertex 0.05 0 0
 endloop
endfacet
endsolid t
"""

URDF = """<?xml version="1.0"?>
<robot name="meshy">
  <link name="base"><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>
  <joint name="x" type="prismatic"><parent link="base"/><child link="tool"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
  <link name="tool"><visual><geometry><box size="0.05 0.05 0.05"/></geometry></visual></link>
</robot>
"""


def meshy_robot(tmp_path, mesh: str):
    """``tmp_path/share/pkg/meshy.urdf`` naming ``mesh``; ``share/pkg/meshes/inside.stl`` and
    ``tmp_path/outside/evil.stl`` exist. The package folder (``package://`` root) is ``tmp_path/share``."""
    (tmp_path / "share" / "pkg" / "meshes").mkdir(parents=True)
    (tmp_path / "outside").mkdir()
    (tmp_path / "share" / "pkg" / "meshes" / "inside.stl").write_text(TETRAHEDRON_STL)
    (tmp_path / "outside" / "evil.stl").write_text(TETRAHEDRON_STL)
    urdf = tmp_path / "share" / "pkg" / "meshy.urdf"
    urdf.write_text(URDF.format(mesh=mesh.format(tmp=tmp_path)))
    return urdf


def study(urdf):
    return {"study": {"cycles": 5}, "robot": {"urdf": str(urdf), "tool_frame": "tool", "package_dirs": [".."]},
            "joints": {"friction": {"law": "uniform", "low": 0.1, "high": 0.2}, "stiffness": 1e6,
                       "normal_force_N": 50.0},
            "poses": [{"q": [0.2]}]}


def test_mesh_inside_the_package_is_accepted(tmp_path):
    robot = load_urdf(meshy_robot(tmp_path, "package://pkg/meshes/inside.stl"), "tool", [tmp_path / "share"])
    assert mesh_files(robot, robot.visual_model) == [(tmp_path / "share/pkg/meshes/inside.stl").resolve()]


@pytest.mark.parametrize("mesh", ["{tmp}/outside/evil.stl", "file://{tmp}/outside/evil.stl",
                                  "package://pkg/../../outside/evil.stl", "../outside/evil.stl"])
def test_mesh_outside_the_package_is_refused_naming_it(tmp_path, mesh):
    urdf = meshy_robot(tmp_path, mesh)
    robot = load_urdf(urdf, "tool", [tmp_path / "share"])
    assert robot.visual_model is not None and robot.visual_model.ngeoms == 2  # pinocchio did load it
    with pytest.raises(InputError) as error:
        mesh_files(robot, robot.visual_model)
    line = error.value.one_line()
    assert "evil.stl" in line and "robot.package_dirs" in line and str(urdf) in line
    with pytest.raises(InputError, match="evil.stl"):
        write_report(run_study(study(urdf)), robot, tmp_path)
    assert not (tmp_path / "report.html").exists()
