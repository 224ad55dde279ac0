"""Mesh safety: a URDF mesh outside the package folders is refused while loading, before Pinocchio
reads any file (through the command line, and a map study watched for any opening of the mesh:
test_bad_input.py)."""

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import meshcat
import pinocchio as pin
import pytest
from meshcat.servers.tree import find_node

from tribokin.cli import main
from tribokin.errors import InputError, RobotDescriptionError
from tribokin.kinematics.robot import load_urdf
from tribokin.kinematics.urdf_meshes import confine_meshes, resolve_mesh
from tribokin.output.writers import write_results
from tribokin.run import run_study
from tribokin.study.assembly import load_robot_spec
from tribokin.study.spec import RobotSpec
from tribokin.viz.scene import build_scene
from tribokin.viz.scene_file import load_scene_inputs
from tribokin.viz.static import static_visualizer

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
  <link name="base"><visual><geometry><mesh filename="{mesh}"/></geometry></visual>
    <collision><geometry><mesh filename="{collision}"/></geometry></collision></link>
  <joint name="x" type="prismatic"><parent link="base"/><child link="tool"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
  <link name="tool"><visual><geometry><box size="0.05 0.05 0.05"/></geometry></visual></link>
</robot>
"""

INSIDE = "package://pkg/meshes/inside.stl"

#: A one-triangle Collada mesh showing the image ``{image}``.
TRIANGLE_DAE = """<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_images><image id="texture"><init_from>{image}</init_from></image></library_images>
  <library_geometries><geometry id="g"><mesh>
    <source id="p"><float_array id="a" count="9">0 0 0 0.1 0 0 0 0.1 0</float_array><technique_common>
      <accessor source="#a" count="3" stride="3"><param name="X" type="float"/><param name="Y" type="float"/>
        <param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
    <triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def meshy_urdf(tmp_path, mesh: str, collision: str = INSIDE) -> Path:
    """``tmp_path/share/pkg/meshy.urdf`` whose base link shows ``mesh`` and collides as ``collision``
    (``{tmp}`` stands for ``tmp_path``). ``share/pkg/meshes/inside.stl``, ``outside/evil.stl``,
    ``outside/evil`` (no extension) and ``share/pkg/meshes/link.stl`` (a symlink to ``outside/evil.stl``)
    exist. The package folder is ``tmp_path/share``."""
    meshes, outside = tmp_path / "share" / "pkg" / "meshes", tmp_path / "outside"
    meshes.mkdir(parents=True)
    outside.mkdir()
    for file in (meshes / "inside.stl", outside / "evil.stl", outside / "evil"):
        file.write_text(TETRAHEDRON_STL)
    (meshes / "link.stl").symlink_to(outside / "evil.stl")
    urdf = tmp_path / "share" / "pkg" / "meshy.urdf"
    urdf.write_text(URDF.format(mesh=mesh.format(tmp=tmp_path), collision=collision.format(tmp=tmp_path)))
    return urdf


def test_meshes_inside_the_package_load_from_their_real_paths(tmp_path):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/alias.stl", "package://pkg/meshes/../meshes/inside.stl")
    (tmp_path / "share/pkg/meshes/alias.stl").symlink_to("inside.stl")  # a symlink inside is fine
    robot = load_urdf(urdf, "tool", [tmp_path / "share"])
    inside = str((tmp_path / "share/pkg/meshes/inside.stl").resolve())
    assert [g.meshPath for g in robot.visual_model.geometryObjects] == [inside, "BOX"]
    assert [g.meshPath for g in robot.collision_model.geometryObjects] == [inside]


@pytest.mark.parametrize("mesh", ["{tmp}/outside/evil.stl", "file://{tmp}/outside/evil.stl",
                                  "package://pkg/../../outside/evil.stl", "../outside/evil.stl",
                                  "{tmp}/outside/evil", "package://pkg/../../outside/evil",
                                  "package://pkg/meshes/link.stl", "{tmp}/outside/missing.stl"],
                         ids=["absolute", "file-uri", "package-dotdot", "relative-dotdot", "no-extension",
                              "package-no-extension", "symlink-out", "missing"])
@pytest.mark.parametrize("element", ["visual", "collision"])
def test_mesh_outside_the_package_is_refused_while_loading(tmp_path, monkeypatch, mesh, element):
    urdf = meshy_urdf(tmp_path, mesh) if element == "visual" else meshy_urdf(tmp_path, INSIDE, mesh)
    read = []
    for loader in ("buildModelFromUrdf", "buildModelFromXML", "buildGeomFromUrdf", "buildGeomFromUrdfString"):
        monkeypatch.setattr(pin, loader, lambda *args, name=loader: read.append(name))
    with pytest.raises(InputError) as error:
        load_robot_spec(RobotSpec(str(urdf), None, "tool", (str(tmp_path / "share"),), 0.0), "study.toml")
    line = error.value.one_line()
    assert line.startswith("study.toml: robot.package_dirs: mesh ") and mesh.split("/")[-1] in line
    assert str(urdf) in line and str((tmp_path / "share").resolve()) in line
    assert read == []  # refused before Pinocchio read the URDF or any mesh


@pytest.mark.parametrize("image", ["{tmp}/outside/evil.png", "../../../outside/evil.png"])
def test_collada_mesh_whose_image_lies_outside_is_refused(tmp_path, image):
    """The viewers read a Collada mesh's images and embed them in the report."""
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/textured.dae")
    (tmp_path / "outside" / "evil.png").write_bytes(b"secret")
    (tmp_path / "share/pkg/meshes/textured.dae").write_text(TRIANGLE_DAE.format(image=image.format(tmp=tmp_path)))
    with pytest.raises(RobotDescriptionError, match="textured.dae.* reads the image '.*/outside/evil.png', outside"):
        load_urdf(urdf, "tool", [tmp_path / "share"])


def test_collada_mesh_whose_image_lies_inside_loads(tmp_path):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/textured.dae")
    (tmp_path / "share/pkg/meshes/texture.png").write_bytes(b"fine")
    (tmp_path / "share/pkg/meshes/textured.dae").write_text(TRIANGLE_DAE.format(image="texture.png"))
    robot = load_urdf(urdf, "tool", [tmp_path / "share"])
    assert robot.visual_model.geometryObjects[0].meshPath.endswith("textured.dae")


def test_view_refuses_a_mesh_moved_outside_before_starting_its_server(tmp_path, capsys, monkeypatch):
    urdf = meshy_urdf(tmp_path, INSIDE)
    study = {"study": {"cycles": 5}, "robot": {"urdf": str(urdf), "tool_frame": "tool", "package_dirs": ["share"]},
             "joints": {"friction": {"law": "uniform", "low": 0.1, "high": 0.2}, "stiffness": 1e6,
                        "normal_force_N": 50.0}, "poses": [{"q": [0.2]}]}
    monkeypatch.chdir(tmp_path)
    write_results(run_study(study), tmp_path / "out", report="light")
    urdf.write_text(urdf.read_text().replace(INSIDE, str(tmp_path / "outside" / "evil")))
    monkeypatch.setattr(meshcat, "Visualizer", lambda *args, **kwargs: pytest.fail("meshcat-server started"))
    assert main(["view", str(tmp_path / "out")]) == 2
    assert capsys.readouterr().err.startswith(f"tribokin: error: {tmp_path / 'out' / 'summary.json'}: "
                                              f"robot.package_dirs: mesh '{tmp_path / 'outside' / 'evil'}'")


def test_default_package_folders_are_the_urdf_folder_and_its_parent(tmp_path):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/inside.stl")
    assert load_urdf(urdf, "tool").visual_model.ngeoms == 2
    with pytest.raises(RobotDescriptionError, match="evil.stl"):
        load_urdf(meshy_urdf(tmp_path / "t", "package://pkg/../../outside/evil.stl"), "tool")


def test_a_missing_mesh_leaves_the_robot_without_geometry_and_names_it(tmp_path):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/none.stl", "package://pkg/meshes/gone.stl")
    robot = load_urdf(urdf, "tool", [tmp_path / "share", tmp_path / "outside"])
    assert robot.joint_names == ["x"] and robot.visual_model is None and robot.collision_model is None
    assert robot.missing_meshes == ("pkg/meshes/none.stl", "pkg/meshes/gone.stl")  # relative to the package folder
    assert load_urdf(urdf, "tool", [tmp_path / "share"], meshes=False).missing_meshes == robot.missing_meshes
    assert load_urdf(meshy_urdf(tmp_path / "found", INSIDE), "tool").missing_meshes == ()


def test_a_missing_mesh_named_by_its_path_is_named_within_its_package_folder(tmp_path):
    urdf = meshy_urdf(tmp_path, INSIDE, "file://{tmp}/share/pkg/meshes/gone.stl")
    robot = load_urdf(urdf, "tool", [tmp_path / "share"])
    assert robot.missing_meshes == ("pkg/meshes/gone.stl",) and robot.visual_model is None


def test_a_missing_example_robot_mesh_is_an_error_naming_it(tmp_path):
    """example-robot-data's meshes are its own files: one missing is a broken installation, not a choice."""
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/none.stl")
    with pytest.raises(RobotDescriptionError) as error:
        confine_meshes(ET.parse(urdf).getroot(), urdf, [tmp_path / "share", tmp_path / "outside"], required=True)
    assert error.value.argument == "package_dirs" and error.value.message == (
        f"mesh 'package://pkg/meshes/none.stl' of {urdf} is not found in the package folders ({tmp_path / 'share'}, "
        f"{tmp_path / 'outside'}): no {tmp_path / 'share/pkg/meshes/none.stl'}, "
        f"{tmp_path / 'outside/pkg/meshes/none.stl'}; correct its path in the URDF or list the folder that holds it in "
        "robot.package_dirs")


def test_an_unreadable_mesh_is_an_error_naming_it_unless_the_meshes_are_not_needed(tmp_path):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/broken.stl")
    broken = tmp_path / "share/pkg/meshes/broken.stl"
    broken.write_text("solid x\nendsolid x\n")  # no facet: assimp loads no mesh
    with pytest.raises(RobotDescriptionError) as error:
        load_urdf(urdf, "tool", [tmp_path / "share"])
    assert error.value.argument == "path" and error.value.message.startswith(
        f"cannot read the meshes of URDF '{urdf}': Could not load resource {broken.resolve()}")
    assert error.value.message.endswith(" (meshes=False reads no mesh)")  # the library's argument, not an option
    assert "\n" not in error.value.message and "assimp.cpp" not in error.value.message
    assert load_urdf(urdf, "tool", [tmp_path / "share"], meshes=False).joint_names == ["x"]


def test_the_commands_name_their_option_for_an_unreadable_mesh(tmp_path, capsys, monkeypatch):
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/broken.stl")
    (tmp_path / "share/pkg/meshes/broken.stl").write_text("solid x\nendsolid x\n")
    study = _meshy_study(tmp_path, urdf)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(study), "--out", "out"]) == 2
    error = capsys.readouterr().err
    assert error.startswith(f"tribokin: error: {study}: robot.urdf: cannot read the meshes of URDF '{urdf}': ")
    assert error.endswith(" (--report none reads no mesh)\n") and "meshes=False" not in error
    assert main(["run", str(study), "--out", "out", "--report", "none"]) == 0


def test_ros_package_path_is_never_searched(tmp_path, monkeypatch):
    """Pinocchio also searches ROS_PACKAGE_PATH for a package URI it does not find; tribokin hands it
    the checked path only, so a mesh there is never read (and it is missing where tribokin looks)."""
    (tmp_path / "ros" / "pkg" / "meshes").mkdir(parents=True)
    (tmp_path / "ros" / "pkg" / "meshes" / "elsewhere.stl").write_text(TETRAHEDRON_STL)
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ros"))
    urdf = meshy_urdf(tmp_path, "package://pkg/meshes/elsewhere.stl")
    robot = load_urdf(urdf, "tool", [tmp_path / "share"])
    assert robot.missing_meshes == ("pkg/meshes/elsewhere.stl",) and robot.visual_model is None


def _meshy_study(tmp_path, urdf: Path) -> Path:
    study = tmp_path / "study.toml"
    study.write_text(f'[study]\ncycles = 5\n\n[robot]\nurdf = "{urdf}"\ntool_frame = "tool"\n'
                     'package_dirs = ["share"]\n\n'
                     '[joints]\nfriction = { law = "uniform", low = 0.1, high = 0.2 }\nstiffness = 1e6\n'
                     'normal_force_N = 50.0\n\n[[poses]]\nq = [0.2]\n')
    return study


def test_a_misspelt_mesh_folder_draws_a_skeleton_and_says_so(tmp_path, capsys, monkeypatch):
    """Before, a run with a report (--report full or light) was refused: only --report none ran, with no report
    and no scene for `tribokin view`."""
    urdf = meshy_urdf(tmp_path, "package://pkg/mehses/inside.stl")
    study = _meshy_study(tmp_path, urdf)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(study), "--out", "out", "--report", "light"]) == 0
    said = ("robot drawn as a skeleton (links as segments, joints as cylinders on their axes): its meshes were not "
            "found in its package folders (pkg/mehses/inside.stl)")
    assert f"note: {said}\n" in capsys.readouterr().out
    page = (tmp_path / "out" / "report.html").read_text()
    assert f"<p>R{said[1:]}.</p>" in page and TETRAHEDRON_STL.splitlines()[1] not in page
    assert (tmp_path / "out" / "scene.npz").is_file()
    inputs = load_scene_inputs(tmp_path / "out")  # what `tribokin view` draws
    vis = static_visualizer()
    info = build_scene(vis, inputs.robot, inputs.q, inputs.poses, inputs.map_layers, inputs.cube,
                       inputs.magnification)
    assert info.robot.geometry == "skeleton" and info.robot.missing == ("pkg/mehses/inside.stl",)
    robot = find_node(vis.window.tree, ["meshcat", "tribokin", "robot"])
    assert sorted(robot) == ["joints", "links"] and list(robot["joints"]) == ["0"]  # no mesh: a joint and links


@pytest.mark.parametrize("report, drawn", [
    ("full", "Robot drawn from its visual geometry (--report full): 1 mesh and 1 box."),
    ("light", "Robot drawn from its collision geometry (--report light): 1 mesh."),
])
def test_the_report_says_which_meshes_it_drew(tmp_path, monkeypatch, report, drawn):
    urdf = meshy_urdf(tmp_path, INSIDE)
    study = _meshy_study(tmp_path, urdf)
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(study), "--out", "out", "--report", report]) == 0
    page = (tmp_path / "out" / "report.html").read_text()
    inside = (tmp_path / "share/pkg/meshes/inside.stl").resolve()
    assert f"<p>{drawn}</p><details><summary>Mesh files drawn</summary><ul><li>{inside}</li></ul></details>" in page


def test_resolve_mesh_searches_the_package_folders_in_order(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / folder / "pkg").mkdir(parents=True)
    (tmp_path / "b" / "pkg" / "m.stl").write_text("")
    dirs = [tmp_path / "a", tmp_path / "b"]
    assert resolve_mesh("package://pkg/m.stl", dirs) == tmp_path.resolve() / "b/pkg/m.stl"
    assert resolve_mesh("model://pkg/m.stl", dirs) == tmp_path.resolve() / "b/pkg/m.stl"
    assert resolve_mesh("pkg/m.stl", dirs) == tmp_path.resolve() / "b/pkg/m.stl"
    assert resolve_mesh("package://pkg/none.stl", dirs) == tmp_path.resolve() / "a/pkg/none.stl"
    assert resolve_mesh("package:///pkg/m.stl", dirs) == tmp_path.resolve() / "b/pkg/m.stl"
    assert resolve_mesh("file://m.stl", dirs) == Path(os.getcwd()).resolve() / "m.stl"
    assert resolve_mesh("https://example.org/m.stl", dirs) is None  # Pinocchio refuses the scheme
