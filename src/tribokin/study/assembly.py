"""Assembly of a study's parts: its robot, one joint error model per joint, the poses to run."""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

from tribokin.errors import InputError, closest_hint, located
from tribokin.iso9283.cube import APPROACH_DIRECTIONS, UnreachableCube, place_cube
from tribokin.kinematics.robot import Robot, load_example_robot, load_urdf, rigid_placement
from tribokin.simulation.joint_errors import JointErrorModel
from tribokin.simulation.joint_errors import joint_models as joint_error_models
from tribokin.simulation.pose_test import PoseRunner, PoseTask, TestSettings, pose_task
from tribokin.study.names import (
    CHANGE_MAP_FILES,
    EXPECTED_MAP_FILES,
    check_file_name_part,
    check_files_apart,
    check_name,
    pose_figure_file,
    scenario_files,
)
from tribokin.study.series_spec import law_table
from tribokin.study.spec import FRICTION_KEYS, FRICTION_SCALE, RobotSpec, Study, check_motion
from tribokin.tribology.friction_series import TIME_KEYS, FrictionSeries, latent_correlation
from tribokin.tribology.spec import law_from_spec, scaled_law_from_spec


def robot_spec(study: Study) -> RobotSpec:
    """The study's ``[robot]`` with absolute paths: loads the same robot from any folder."""
    return study.robot.absolute(study.base_dir)


#: The key of a ``[robot]`` table that sets each argument of the robot loaders (``None``: the robot as a whole);
#: any other argument (``xacro_args.<name>``) is the key ``robot.<argument>``.
ROBOT_KEYS = {"name": "robot.name", "path": "robot.urdf", "tool_frame": "robot.tool_frame",
              "package_dirs": "robot.package_dirs", None: "robot"}


def load_robot_spec(spec: RobotSpec, source=None, meshes: bool = True) -> Robot:
    """The robot a ``[robot]`` spec with absolute paths names (see :func:`robot_spec`); an error names
    ``source`` and the key at fault. ``meshes``: load a URDF's meshes (to draw it; each must then be found), else
    its kinematics only."""
    offset = rigid_placement(spec.tool_offset_m, spec.tool_offset_rpy_deg)
    base = rigid_placement(spec.base_xyz_m, spec.base_rpy_deg)
    with located(source, lambda error: ROBOT_KEYS.get(error.argument, f"robot.{error.argument}")):
        if spec.name is not None:
            robot = load_example_robot(spec.name, spec.tool_frame, offset, base)
        else:
            robot = load_urdf(spec.urdf, spec.tool_frame, list(spec.package_dirs), offset, meshes, spec.xacro_args,
                              base)
    robot.origin = spec.as_settings()
    return robot


def load_robot(study: Study, meshes: bool = True) -> Robot:
    """The robot a study names, reduced to its tool frame's chain; ``meshes`` as for :func:`load_robot_spec`."""
    return load_robot_spec(robot_spec(study), study.source, meshes)


def kinematic_spec(study: Study) -> RobotSpec:
    """The study's robot spec (:func:`robot_spec`) without its payload: what fixes its kinematics, hence its IK."""
    return replace(robot_spec(study), payload_kg=0.0)


@dataclass(frozen=True)
class MapRobots:
    """The robots a map's scenarios measure with, each once: ``specs`` (:func:`kinematic_spec`) and ``robots``,
    the study's own first (the reference scenario's); ``places``: each scenario's robot, its index in them."""

    specs: tuple[RobotSpec, ...]
    robots: tuple[Robot, ...]
    places: tuple[int, ...]


def map_robots(study: Study, robot: Robot) -> MapRobots:
    """The robots of the study's scenarios (the study alone without scenarios), ``robot`` (the study's, loaded) for
    those with its kinematics, the others loaded without meshes (nothing draws them); one that does not load is an
    :class:`InputError` naming ``scenarios[i].robot.<key>``."""
    specs, robots, places = [kinematic_spec(study)], [robot], []
    for i, scenario in enumerate(s.study for s in study.scenarios):
        spec = kinematic_spec(scenario)
        if spec not in specs:
            try:
                robots.append(load_robot_spec(spec, scenario.source, meshes=False))
            except InputError as error:
                raise InputError(error.message, error.source, f"scenarios[{i}].{error.key}") from None
            specs.append(spec)
        places.append(specs.index(spec))
    return MapRobots(tuple(specs), tuple(robots), tuple(places) or (0,))


def joint_models(study: Study, robot: Robot) -> list[JointErrorModel]:
    """One error model per active joint (:func:`tribokin.simulation.joint_errors.joint_models`): the ``[joints]``
    defaults with ``[joints.<name>]`` overrides; a joint's friction is the one its override gives (any of
    ``FRICTION_KEYS``), else the defaults'; with its time keys (its ``series``) and ``travel_per_cycle``."""
    names = robot.joint_names
    check_motion(study, names)
    for joint in study.joint_overrides:
        if joint not in names:
            raise InputError(f"unknown joint '{joint}'{closest_hint(joint, names)}; joints of {robot.label}: "
                             f"{', '.join(names)}", study.source, f"joints.{joint}")
    values = {}
    for name, prismatic in zip(names, robot.joint_is_prismatic, strict=True):
        spec = study.joint(name)
        if spec.stiffness is None:
            raise InputError(f"joint '{name}' has no stiffness: set joints.stiffness or joints.{name}.stiffness",
                             study.source, "joints.stiffness")
        given, own = spec.friction_key, "friction_force_N" if prismatic else "friction_torque_Nm"
        if given is None:
            raise InputError(f"joint '{name}' has no friction: set joints.friction (a law of mu), joints.{own} or "
                             f"the same keys in [joints.{name}]", study.source, "joints.friction")
        key = study.joint_key(name, given)
        if given not in ("friction", own):
            raise InputError(f"joint '{name}' is {'prismatic' if prismatic else 'revolute'}: give its friction as "
                             f"joints.{name}.{own} [{'N' if prismatic else 'N·m'}]", study.source, key)
        table = law_table(getattr(spec, given))
        if given == "friction":
            law = law_from_spec(table, study.source, key, study.base_dir, study.data_roots)
        else:
            law = scaled_law_from_spec(table, FRICTION_SCALE[given], given, study.source, key)
        check_series(law, spec.series, study.source, key)
        values[name] = {"friction": law, "series": spec.series, "travel_per_cycle": spec.travel_per_cycle,
                        **{k: v for k, v in asdict(spec).items() if k not in JOINT_MOTION_KEYS}}
    with located(study.source, JointKeys(study)):
        return joint_error_models(robot, joints=values)


#: A joint's keys that are not its error model's: its friction's (the law made of them) and its motion.
JOINT_MOTION_KEYS = (*FRICTION_KEYS, "travel_per_cycle")


def check_series(law, series: FrictionSeries | None, source, key: str) -> None:
    """Refuse the time keys of a joint's friction ``law`` (at ``key``) that it cannot take (an ``ar1`` it cannot
    reach, :func:`~tribokin.tribology.friction_series.latent_correlation`)."""
    if series is not None:
        with located(source, f"{key}.ar1"):
            latent_correlation(law, series.ar1)


def refuse_series(study: Study, what: str, fix: str) -> None:
    """Refuse a study whose joints' friction gives time keys where ``what`` (a map, a calibration) does not simulate
    them yet: one line naming the first such key and how to ``fix`` it, rather than running without them. Its
    scenarios' own keys too (``scenarios[i].joints...``)."""
    for i, scenario in enumerate([study, *(s.study for s in study.scenarios)]):
        for name in (None, *scenario.joint_overrides):
            spec = scenario.joints if name is None else scenario.joint(name)
            key = spec.friction_key
            if key is None or (name is not None and key not in scenario.joint_overrides[name]):
                continue
            given = next((k for k in TIME_KEYS if k in getattr(spec, key)), None)
            if given is not None:
                at = ("joints" if name is None else f"joints.{name}") + f".{key}.{given}"
                raise InputError(f"{what} does not simulate friction time keys yet (it would draw every cycle "
                                 f"independently; only the study's poses and ISO cube draw them): {fix}",
                                 scenario.source, at if i == 0 else f"scenarios[{i - 1}].{at}")


def friction_groups(study: Study, joint_names) -> list[tuple[str, tuple[str, ...]]]:
    """The study's joint friction groups, each the joints whose friction one study key gives: ``joints.<key>``,
    the ``[joints]`` friction, for the joints without their own (first, if any), then ``joints.<joint>.<key>`` for
    each joint of ``joint_names`` whose own table gives one, in their order. A joint without friction is in none."""
    own = [name for name in joint_names if study.joint_overrides.get(name, {}).keys() & set(FRICTION_KEYS)]
    shared = tuple(name for name in joint_names if name not in own)
    key = study.joints.friction_key
    groups = [(f"joints.{key}", shared)] if key is not None and shared else []
    return groups + [(f"joints.{name}.{study.joint(name).friction_key}", (name,)) for name in own]


@dataclass(frozen=True)
class JointKeys:
    """The study key of a joint's value: called with a :class:`~tribokin.errors.JointRangeError` (or
    :class:`~tribokin.errors.JointModelError`), the key that sets the part at fault (:meth:`Study.joint_key`);
    :meth:`locate` makes of it an error naming the study's file and that key (a :class:`PoseRunner`'s ``locate``)."""

    study: Study

    def __call__(self, error) -> str:
        return self.study.joint_key(error.joint, error.part)

    def locate(self, error) -> InputError:
        """``error`` as an :class:`~tribokin.errors.InputError` naming the study's file and the key at fault."""
        return InputError(error.message, self.study.source, self(error))


def study_runner(study: Study, robot: Robot, models: list[JointErrorModel]) -> PoseRunner:
    """A :class:`PoseRunner` of the study's settings (:meth:`TestSettings.of`), whose joint range errors name the
    study's file and key."""
    return PoseRunner(TestSettings.of(study), robot, models, JointKeys(study).locate)


def pose_tasks(study: Study, robot: Robot) -> tuple[list[PoseTask], dict | None]:
    """The study's poses (joint space, or approached along their ``directions``), then the ISO cube's P1-P5
    (solved by IK)."""
    tasks = []
    for i, p in enumerate(study.poses):
        with located(study.source, f"poses[{i}].q"):
            q = robot.check_configuration(p.q)
        friction = None if p.friction is None else law_from_spec(p.friction, study.source, f"poses[{i}].friction",
                                                                study.base_dir, study.data_roots)
        tasks.append(pose_task(robot, p.name, q, p.directions, p.normal_force_N, friction))
    cube = None
    if study.iso_cube is not None:
        try:
            cube_poses, cube = place_cube(robot, study.iso_cube.center_m, study.iso_cube.side_m, study.iso_cube.rpy_deg)
        except UnreachableCube as error:
            raise InputError(str(error), study.source, "iso_cube") from None
        tasks += [PoseTask(p.name, p.q, p.approach_signs, tuple(APPROACH_DIRECTIONS)) for p in cube_poses]
    return tasks, cube


def check_names(study: Study, tasks: list[PoseTask]) -> None:
    """Refuse names that cannot name what they name (:mod:`tribokin.study.names`), and poses (``tasks``: the study's
    poses, then the ISO cube's) or scenarios whose files would be the same (a clash with an ISO cube pose
    names the study's pose, the one to rename)."""
    check_name(study.name, study.source, "study.name")
    poses = [(f"poses[{i}].name", pose.name) for i, pose in enumerate(study.poses)]
    scenarios = [(f"scenarios[{i}].name", scenario.name) for i, scenario in enumerate(study.scenarios)]
    for key, name in poses + scenarios:
        check_file_name_part(name, study.source, key)
    cube = [("iso_cube", task.name) for task in tasks[len(study.poses):]]
    files = [(key, pose_figure_file(name)) for key, name in cube + poses]
    change = study.map is not None and study.map.compare is not None  # every scenario's change maps too
    if study.map is not None:  # the reference's own heat maps, which a scenario named "hi" or "multi" would write
        files = [("map.statistic", file) for file in EXPECTED_MAP_FILES.get(study.map.figure_set, ())] + files
        if change:  # and its change maps: a scenario renames
            files = [("map.compare", file) for file in CHANGE_MAP_FILES] + files
    # [0]: the reference; a scenario "change_b" writes map_RP_l_change_b.png, as scenario "b"'s change map
    files += [(key, file) for key, name in scenarios[1:] for file in scenario_files(name, change)]
    check_files_apart(files, study.source)
