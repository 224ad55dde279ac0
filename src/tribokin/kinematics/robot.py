"""Load a robot: a URDF file or an example-robot-data name, reduced to the tool's chain.

The joints that move the tool frame (its kinematic chain from the base) are
the robot's *active joints*; every other joint (gripper fingers, a floating
base) is locked at the robot's reference posture. Only one-degree-of-freedom
joints (revolute, continuous, prismatic) may be active. The default tool frame
is the end of the model's longest chain (:mod:`tribokin.kinematics.tool_frames`).

tribokin gives a configuration as one value per active joint (``q``, length nv: [m] or [rad]). Pinocchio gives a
continuous joint (a revolute joint without limits, ``JointModelRUBX/Y/Z``) two: the cosine and sine of its angle
(nq = 2, nv = 1). :meth:`Robot.configuration` turns tribokin's ``q`` into Pinocchio's wherever Pinocchio is called, so
``q + dq`` is Pinocchio's ``integrate`` for every joint, and a continuous joint's angle is never clipped, only wrapped
into [-π, π] by the IK (:meth:`Robot.wrapped`).

A *tool offset* (:func:`rigid_placement`) places a tool point (a probe's tip, a tracker's reflector) on the tool
frame: a translation [m] and a rotation from roll, pitch, yaw [deg], both expressed in the tool frame. The
loaders add it to the reduced model as an operational frame ``<tool_frame>_tool_point`` fixed to the tool
frame, and it becomes the robot's ``tool_frame``: poses, Jacobians, IK and the payload's point are then the
tool point's. A *base* placement (the same form) puts the robot in a world frame: every placement, Jacobian and
target is then the world's (the base's own frame when none is given), and gravity acts along the world's -z.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import io
import math
import warnings
import xml.etree.ElementTree as ET
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from tribokin.errors import ConfigurationError, RobotDescriptionError, closest_hint
from tribokin.kinematics.tool_frames import ToolFrames, default_tool_frame, tool_frames
from tribokin.kinematics.urdf_meshes import WITHOUT_MESHES, confine_meshes
from tribokin.kinematics.urdf_xacro import urdf_text

#: example-robot-data names tested with tribokin (any fixed-base arm it ships should load).
TESTED_ROBOTS = ("ur3", "ur5", "ur10", "panda", "xarm7", "z1", "so100", "kinova")


def example_robot_names() -> list[str]:
    """Every robot name example-robot-data can load."""
    from example_robot_data.robots_loader import ROBOTS

    return sorted(ROBOTS)


def wrap_angles(angles):
    """``angles`` [rad] shifted by whole turns into [-π, π] (unchanged, to the bit, within it)."""
    return angles - 2 * math.pi * np.round(np.asarray(angles) / (2 * math.pi))


def kinematics_sha256(model: pin.Model) -> str:
    """A hash of ``model``'s kinematic parameters: its joints' kinds, placements and limits, its frames' names,
    parents and placements, and the inertias the bearing loads are computed from (bytes of float64 arrays)."""
    digest = hashlib.sha256()
    for joint, name, placement, inertia in zip(model.joints, model.names, model.jointPlacements, model.inertias,
                                               strict=True):
        digest.update(f"{name}:{joint.shortname()}:{joint.nq}:{joint.nv};".encode())
        digest.update(np.ascontiguousarray(placement.homogeneous, dtype=float).tobytes())
        digest.update(np.array([inertia.mass, *inertia.lever, *np.asarray(inertia.inertia).ravel()]).tobytes())
    digest.update(np.array(model.parents, dtype=np.int64).tobytes())
    for limits in (model.lowerPositionLimit, model.upperPositionLimit):
        digest.update(np.ascontiguousarray(limits, dtype=float).tobytes())
    for frame in model.frames:
        digest.update(f"{frame.name}:{frame.parentJoint};".encode())
        digest.update(np.ascontiguousarray(frame.placement.homogeneous, dtype=float).tobytes())
    return digest.hexdigest()


def model_origin(model: pin.Model, tool_frame: str, label: str, whole: pin.Model | None = None,
                 source: str = "pinocchio model") -> dict:
    """Where a robot came from, as ``summary.json`` records a robot a study did not load (``robot_spec``): its
    ``source`` (``"pinocchio model"``, ``"urdf"``, ``"example-robot-data"``), ``name`` (the model's name, the URDF's
    path or the robot's name), the whole model's ``nq`` and ``nv`` (``whole``, else ``model``), the ``tool_frame``, the
    active ``joints`` and ``kinematics_sha256`` (:func:`kinematics_sha256`) of the reduced model. A robot a study loads
    records its ``[robot]`` table instead."""
    whole = model if whole is None else whole
    return {"source": source, "name": label, "nq": whole.nq, "nv": whole.nv, "tool_frame": tool_frame,
            "joints": list(model.names)[1:], "kinematics_sha256": kinematics_sha256(model)}


@dataclass
class Robot:
    """A Pinocchio model reduced to the chain that moves ``tool_frame``.

    Attributes:
        model: the reduced model; its joints are the active joints, in chain order.
        tool_frame: name of the frame whose pose is measured (``<frame>_tool_point`` when a tool offset is given).
        label: robot name or URDF path, for reports.
        reference_q: (nv,) a typical working posture [m or rad] (example-robot-data's, else mid-range), within the
            limits (:func:`_within_limits`).
        read_geometry: ``read_geometry(kind)``, the geometry model of a ``pin.GeometryType`` (VISUAL, COLLISION) of
            the reduced model; ``None``: none. :attr:`visual_model` and :attr:`collision_model` call it once each, when
            first asked for (an example-robot-data robot's meshes are read only then: its visual meshes take a
            third of a second).
        missing_meshes: the meshes its description names that were not found, by their path in their package folder
            (:func:`~tribokin.kinematics.urdf_meshes.confine_meshes`); the robot then has no geometry (``read_geometry``
            is ``None``) and the views draw it as a skeleton.
        joint_is_prismatic: (nv,) True for prismatic joints (deviations in [m]), False for revolute ([rad]).
        continuous: (nv,) True for continuous joints (revolute, no limits; two values in Pinocchio's configuration).
        motion_axes: (nv, 3) unit motion axis of each joint in its own frame (linear or angular).
        origin: where it came from, as ``summary.json`` records it (``robot_spec``): a study's ``[robot]`` table
            for a robot a study loads, else :func:`model_origin`'s (``source = "pinocchio model"``).
        base: the base's placement in the world, which ``model`` already carries (:func:`_place_base`); ``None``:
            the base at the world's origin (:attr:`base_m`).

    Construct it with :meth:`from_pinocchio`, :meth:`from_urdf` or :meth:`from_example_robot_data`. Pickled, it
    keeps its kinematics only (:meth:`__reduce__`).
    """

    model: pin.Model
    tool_frame: str
    label: str
    reference_q: np.ndarray
    read_geometry: Callable[[pin.GeometryType], pin.GeometryModel] | None = None
    missing_meshes: tuple[str, ...] = ()
    origin: dict | None = None
    base: pin.SE3 | None = None

    def __post_init__(self):
        self._geometries = {}
        self.tool_frame_id = self.model.getFrameId(self.tool_frame)
        self.data = self.model.createData()
        pin.forwardKinematics(self.model, self.data, pin.neutral(self.model))
        subspaces = np.array([np.asarray(self.data.joints[i].S).reshape(6) for i in range(1, self.model.njoints)])
        self.joint_is_prismatic = np.linalg.norm(subspaces[:, :3], axis=1) > 0
        axes = np.where(self.joint_is_prismatic[:, None], subspaces[:, :3], subspaces[:, 3:])
        self.motion_axes = axes / np.linalg.norm(axes, axis=1, keepdims=True)
        joints = list(self.model.joints)[1:]
        self.continuous = np.array([joint.nq == 2 for joint in joints], dtype=bool)
        self._has_continuous = bool(self.continuous.any())
        q_index = np.array([joint.idx_q for joint in joints], dtype=int)  # a joint's value (or cosine) in nq
        self._plain, self._turning = np.flatnonzero(~self.continuous), np.flatnonzero(self.continuous)
        self._plain_q, self._cosine_q = q_index[self._plain], q_index[self._turning]
        self._lower = np.where(self.continuous, -np.inf, np.asarray(self.model.lowerPositionLimit)[q_index])
        self._upper = np.where(self.continuous, np.inf, np.asarray(self.model.upperPositionLimit)[q_index])
        self._drawn = (np.where(self.continuous, -math.pi, self._lower),
                       np.where(self.continuous, math.pi, self._upper))
        if self.origin is None:
            self.origin = model_origin(self.model, self.tool_frame, self.label)

    def __reduce__(self):
        """Pickled as its kinematics (model, tool frame, label, reference posture, missing meshes, origin, base),
        without its geometry: what a map's workers measure with."""
        return Robot, (self.model, self.tool_frame, self.label, self.reference_q, None, self.missing_meshes,
                       self.origin, self.base)

    @property
    def base_m(self) -> np.ndarray:
        """(3,) where the base's origin lies in the world [m] (zero when the base is not placed)."""
        return np.zeros(3) if self.base is None else self.base.translation.copy()

    @classmethod
    def from_pinocchio(cls, model: pin.Model, tool_frame: str | None = None,
                       visual_model: pin.GeometryModel | None = None, collision_model: pin.GeometryModel | None = None,
                       reference_q=None, tool_offset: pin.SE3 | None = None, base: pin.SE3 | None = None) -> Robot:
        """A robot of any Pinocchio model (``pin.buildModelFromUrdf``, ``robot_descriptions``' loaders...), reduced to
        the tool's chain as a URDF is (:func:`reduce_to_chain`); ``model`` itself is left as it is.

        Args:
            model: the whole model (a fixed base; a free flyer is locked at ``reference_q``).
            tool_frame: the frame whose pose is measured (``None``: the end of the longest chain).
            visual_model: its visual geometry model, to draw it (``None``: none).
            collision_model: its collision geometry model (``None``: none).
            reference_q: (nq,) Pinocchio's configuration of the whole model, at which the joints off the tool's
                chain are locked and from which the robot's reference posture is taken (``None``: each 1-DoF joint
                at mid-range, the rest neutral, as for a URDF: :func:`reference_posture`).
            tool_offset: the tool point's placement in ``tool_frame`` (:func:`rigid_placement`; ``None``: none).
            base: the base's placement in the world (:func:`rigid_placement`; ``None``: the world is the base frame).

        Returns:
            the robot; its :attr:`origin` records the model's name, sizes, joints and a hash of its kinematics
            (:func:`model_origin`), as ``summary.json`` can.

        Raises:
            RobotDescriptionError: ``reference_q`` of the wrong size or not finite, an unknown tool frame, a joint
                moving the tool that is not 1-DoF or has no travel.
        """
        model = pin.Model(model)
        if reference_q is None:
            reference_q = reference_posture(model)
        else:
            reference_q = np.array(reference_q, dtype=float)
            if reference_q.shape != (model.nq,) or not np.all(np.isfinite(reference_q)):
                raise RobotDescriptionError(f"reference_q must be {model.nq} finite numbers, the model's configuration "
                                            f"(nq = {model.nq}); got shape {reference_q.shape}", "reference_q")
        geometries = {pin.GeometryType.VISUAL: visual_model, pin.GeometryType.COLLISION: collision_model}
        read_geometry = None if visual_model is None and collision_model is None else geometries.__getitem__
        robot = reduce_to_chain(model, reference_q, tool_frame, read_geometry, model.name or "pinocchio model",
                                tool_offset, base)
        robot.origin = model_origin(robot.model, robot.tool_frame, robot.label, model)
        return robot

    @classmethod
    def from_urdf(cls, path, tool_frame: str | None = None, package_dirs=(), xacro_args: dict[str, str] | None = None,
                  meshes: bool = True, tool_offset: pin.SE3 | None = None, base: pin.SE3 | None = None) -> Robot:
        """A robot of a URDF (or xacro) file: :func:`load_urdf`."""
        return load_urdf(path, tool_frame, package_dirs, tool_offset, meshes, xacro_args, base)

    @classmethod
    def from_example_robot_data(cls, name: str, tool_frame: str | None = None, tool_offset: pin.SE3 | None = None,
                                base: pin.SE3 | None = None) -> Robot:
        """A robot example-robot-data ships, by name (``"ur5"``): :func:`load_example_robot`."""
        return load_example_robot(name, tool_frame, tool_offset, base)

    def geometry_model(self, kind: pin.GeometryType) -> pin.GeometryModel | None:
        """The geometry model of ``kind`` (``pin.GeometryType.VISUAL`` or ``COLLISION``), read when first asked for;
        ``None`` for a robot loaded without its meshes."""
        if kind not in self._geometries:
            self._geometries[kind] = None if self.read_geometry is None else self.read_geometry(kind)
        return self._geometries[kind]

    @property
    def visual_model(self) -> pin.GeometryModel | None:
        """The visual geometry model (:meth:`geometry_model`)."""
        return self.geometry_model(pin.GeometryType.VISUAL)

    @property
    def collision_model(self) -> pin.GeometryModel | None:
        """The collision geometry model (:meth:`geometry_model`)."""
        return self.geometry_model(pin.GeometryType.COLLISION)

    @property
    def joint_names(self) -> list[str]:
        """Active joint names, in the order of ``q``."""
        return list(self.model.names)[1:]

    @property
    def lower_limits(self) -> np.ndarray:
        """(nv,) lower position limits [m or rad] (``-inf`` for a continuous joint)."""
        return self._lower

    @property
    def upper_limits(self) -> np.ndarray:
        """(nv,) upper position limits [m or rad] (``inf`` for a continuous joint)."""
        return self._upper

    def configuration(self, q) -> np.ndarray:
        """Pinocchio's configuration (..., nq) of joint values ``q`` (..., nv) [m or rad]: a continuous joint's angle
        becomes its cosine and sine; ``q`` itself (as a float array) when the robot has no continuous joint."""
        q = np.asarray(q, dtype=float)
        if not self._has_continuous:
            return q
        configuration = np.empty(q.shape[:-1] + (self.model.nq,))
        configuration[..., self._plain_q] = q[..., self._plain]
        angles = q[..., self._turning]
        configuration[..., self._cosine_q] = np.cos(angles)
        configuration[..., self._cosine_q + 1] = np.sin(angles)
        return configuration

    def wrapped(self, q) -> np.ndarray:
        """``q`` (..., nv) [m or rad], each continuous joint's angle brought into [-π, π] (:func:`wrap_angles`)."""
        return np.where(self.continuous, wrap_angles(q), q) if self._has_continuous else q

    def random_configuration(self, rng: np.random.Generator) -> np.ndarray:
        """(nv,) a configuration drawn uniformly within the joint limits [m or rad], a continuous joint's angle in
        [-π, π] (one ``rng.uniform`` call over the joints)."""
        return rng.uniform(*self._drawn)

    def tool_placement(self, q) -> pin.SE3:
        """Pose of the tool frame in the world (base) frame at configuration ``q``."""
        pin.forwardKinematics(self.model, self.data, self.configuration(q))
        return pin.updateFramePlacement(self.model, self.data, self.tool_frame_id).copy()

    def tool_jacobian(self, q) -> np.ndarray:
        """(6, nv) Jacobian of the tool frame, LOCAL_WORLD_ALIGNED: rows (linear [m/unit], angular [rad/unit])."""
        jacobian = pin.computeFrameJacobian(self.model, self.data, self.configuration(q), self.tool_frame_id,
                                            pin.LOCAL_WORLD_ALIGNED)
        return np.asarray(jacobian).reshape(6, self.model.nv)

    def check_configuration(self, q) -> np.ndarray:
        """``q`` as an array, or a :class:`ConfigurationError` if its length or limits are wrong (a continuous
        joint's angle has none)."""
        try:
            q = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise ConfigurationError(f"must be a list of numbers (got {q!r})") from None
        names = self.joint_names
        if q.shape != (len(names),):
            raise ConfigurationError(f"needs {len(names)} values, one per joint ({', '.join(names)}); got {q.size}")
        if not np.all(np.isfinite(q)):
            raise ConfigurationError("must be finite numbers")
        for i, name in enumerate(names):
            if not self.lower_limits[i] <= q[i] <= self.upper_limits[i]:
                unit = "m" if self.joint_is_prismatic[i] else "rad"
                raise ConfigurationError(f"joint '{name}' = {q[i]:g} {unit} is outside its limits "
                                         f"[{self.lower_limits[i]:g}, {self.upper_limits[i]:g}] {unit} (q is in "
                                         "metres for prismatic joints, radians for revolute ones)")
        return q


def _quiet(call, *args):
    """Call a loader, hiding the chatter some URDF parsers print or warn."""
    with contextlib.redirect_stdout(io.StringIO()), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args)


def _loader_message(error: Exception) -> str:
    """A Pinocchio or coal loader's error on one line: its ``message:`` part when it has one (not where in
    their C++ it was raised, nor their hint)."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip() and not line.strip().startswith("Hint:")]
    start = next((i for i, line in enumerate(lines) if line.startswith("message:")), 0)
    return " ".join(lines[start:]).removeprefix("message: ") or "unreadable"


def _make_frame_names_unique(model: pin.Model) -> None:
    """Rename a body frame that shares its name with a joint to ``<name>_link``.

    Some URDFs (so100) name a link and a joint alike; Pinocchio's
    ``buildReducedModel`` then cannot tell their frames apart.
    """
    counts = Counter(frame.name for frame in model.frames)
    for index, frame in enumerate(model.frames):
        if counts[frame.name] > 1 and frame.type == pin.FrameType.BODY:
            frame.name = f"{frame.name}_link"
            model.frames[index] = frame


def rigid_placement(offset_m=None, rpy_deg=None) -> pin.SE3 | None:
    """A placement (a tool point's in its tool frame, a base's in the world): translation ``offset_m`` [m] and
    rotation from roll, pitch, yaw ``rpy_deg`` [deg] (``pin.rpy.rpyToMatrix``, as ``iso_cube.rpy_deg``), either zero
    when not given; ``None`` (none: no tool point, the base at the world's origin) when neither is."""
    if offset_m is None and rpy_deg is None:
        return None
    rotation = np.eye(3) if rpy_deg is None else pin.rpy.rpyToMatrix(*np.radians(rpy_deg))
    return pin.SE3(rotation, np.zeros(3) if offset_m is None else np.asarray(offset_m, dtype=float))


def _add_tool_point(model: pin.Model, tool_frame: str, offset: pin.SE3) -> str:
    """Add the operational frame ``<tool_frame>_tool_point`` at ``offset`` in ``tool_frame``; return its name."""
    name = f"{tool_frame}_tool_point"
    if model.existFrame(name):
        raise RobotDescriptionError(f"the model already has a frame '{name}', the name of the tool point; rename "
                                    "that frame", "tool_frame")
    parent = model.getFrameId(tool_frame)
    frame = model.frames[parent]
    model.addFrame(pin.Frame(name, frame.parentJoint, parent, frame.placement * offset, pin.FrameType.OP_FRAME))
    return name


def _place_base(model: pin.Model, base: pin.SE3) -> None:
    """Put the robot's base at ``base`` in the world: what hangs from the world (the first joints' placements, the
    base's frames but the world's own) moved by ``base``; gravity stays the world's -z."""
    for joint in range(1, model.njoints):
        if model.parents[joint] == 0:
            model.jointPlacements[joint] = base * model.jointPlacements[joint]
    for index in range(1, len(model.frames)):
        frame = model.frames[index]
        if frame.parentJoint == 0:
            frame.placement = base * frame.placement
            model.frames[index] = frame


def _placed_geometry(geometry: pin.GeometryModel, base: pin.SE3) -> pin.GeometryModel:
    """A copy of ``geometry`` whose objects hanging from the world are moved by ``base`` (:func:`_place_base`)."""
    geometry = geometry.copy()
    for item in geometry.geometryObjects:
        if item.parentJoint == 0:
            item.placement = base * item.placement
    return geometry


def _joint_value(joint, q) -> float:
    """A 1-DoF joint's value [m or rad] in Pinocchio's configuration ``q``: a continuous joint's angle from its
    cosine and sine."""
    return math.atan2(q[joint.idx_q + 1], q[joint.idx_q]) if joint.nq == 2 else float(q[joint.idx_q])


def reduce_to_chain(model: pin.Model, reference_q: np.ndarray, tool_frame: str | None = None,
                    read_geometry: Callable[[pin.GeometryType], pin.GeometryModel | None] | None = None,
                    label: str = "robot", offset: pin.SE3 | None = None, base: pin.SE3 | None = None,
                    missing_meshes: tuple[str, ...] = ()) -> Robot:
    """The robot of a whole Pinocchio model: the step every loader ends with (a URDF, example-robot-data,
    :meth:`Robot.from_pinocchio`).

    Locks every joint that does not move ``tool_frame``, and a free flyer, at ``reference_q``; checks the rest are 1-DoF
    with some travel; brings the reference posture within their limits (:func:`_within_limits`); adds the tool point
    at ``offset`` in ``tool_frame``, if given; puts the base at ``base`` in the world (:func:`_place_base`), if given.
    ``model`` is changed (a frame named as a joint renamed ``<name>_link``): pass a copy to keep it.

    Args:
        model: the whole model.
        reference_q: (nq,) Pinocchio's configuration of the whole model (:func:`reference_posture` for a URDF's).
        tool_frame: the frame whose pose is measured (``None``: :func:`~.tool_frames.default_tool_frame`).
        read_geometry: ``read_geometry(kind)``, the whole model's geometry model of a ``pin.GeometryType`` (``None``
            for none of that kind), which the robot reduces and places the same way when first asked for; ``None``:
            no geometry.
        label: the robot's name in reports and messages.
        offset: the tool point's placement in ``tool_frame`` (:func:`rigid_placement`; ``None``: none).
        base: the base's placement in the world (:func:`rigid_placement`; ``None``: the world is the base frame).
        missing_meshes: the meshes its description names that were not found (:attr:`Robot.missing_meshes`).

    Raises:
        RobotDescriptionError: an unknown tool frame, no default one, a joint moving the tool that is not 1-DoF or
            has no travel.
    """
    _make_frame_names_unique(model)
    frames = [f.name for f in model.frames]
    if tool_frame is None:
        tool_frame = default_tool_frame(model, label)
    elif tool_frame not in frames:
        raise RobotDescriptionError(f"unknown frame '{tool_frame}'{closest_hint(tool_frame, frames)}; frames of "
                                    f"{label}: {', '.join(frames[1:])}", "tool_frame")
    full = model
    chain = set(model.supports[model.frames[model.getFrameId(tool_frame)].parentJoint])
    locked = [j for j in range(1, model.njoints)
              if j not in chain or model.joints[j].shortname() == "JointModelFreeFlyer"]
    if locked:
        model = pin.buildReducedModel(model, locked, reference_q)
    for joint, name in zip(model.joints[1:], list(model.names)[1:], strict=True):
        if joint.nv != 1 or joint.nq > 2:
            raise RobotDescriptionError(f"joint '{name}' ({joint.shortname()}) moves the tool but is not a 1-DoF "
                                        "revolute, continuous or prismatic joint; tribokin cannot model it")
    if model.nq == 0:
        raise RobotDescriptionError(f"frame '{tool_frame}' is not moved by any joint", "tool_frame")
    kept_q = np.array([_joint_value(full.joints[full.getJointId(name)], reference_q) for name in list(model.names)[1:]])
    if offset is not None:
        tool_frame = _add_tool_point(model, tool_frame, offset)
    if base is not None:
        _place_base(model, base)

    def reduced_geometry(kind: pin.GeometryType) -> pin.GeometryModel | None:
        geometry = read_geometry(kind)
        if geometry is None:
            return None
        if locked:
            geometry = pin.buildReducedModel(full, [geometry], locked, reference_q)[1][0]
        return geometry if base is None else _placed_geometry(geometry, base)

    robot = Robot(model, tool_frame, label, kept_q, None if read_geometry is None else reduced_geometry,
                  missing_meshes, base=base)
    for name, low, high in zip(robot.joint_names, robot.lower_limits, robot.upper_limits, strict=True):
        if not high > low:
            raise RobotDescriptionError(f"joint '{name}' moves the tool, but its limits [{low:g}, {high:g}] leave it "
                                        "no travel; give it a range (the URDF's <limit lower=... upper=...>), or make "
                                        "it continuous")
    robot.reference_q = _within_limits(kept_q, robot)
    return robot


def _within_limits(q: np.ndarray, robot: Robot) -> np.ndarray:
    """``q`` (nv,) [m or rad] within ``robot``'s limits: a revolute joint's angle outside them moved by whole turns
    where that lands inside (kinova's reference posture gives -π/2 rad to a joint limited to [0.33, 5.95] rad), else
    clipped."""
    lower, upper = robot.lower_limits, robot.upper_limits
    outside = (q < lower) | (q > upper)
    if not outside.any():
        return q
    turned = q + 2 * math.pi * np.ceil((np.where(outside, lower, q) - q) / (2 * math.pi))  # the first turn above lower
    return np.clip(np.where(outside & ~robot.joint_is_prismatic & (turned <= upper), turned, q), lower, upper)


def load_urdf(path, tool_frame: str | None = None, package_dirs=(), tool_offset: pin.SE3 | None = None,
              meshes: bool = True, xacro_args: dict[str, str] | None = None, base: pin.SE3 | None = None) -> Robot:
    """Load a robot from a URDF file (or a xacro file, expanded), after checking its meshes lie inside
    ``package_dirs``.

    Args:
        path: the URDF file.
        tool_frame: frame whose pose is measured (default: the end of the model's longest chain,
            :mod:`tribokin.kinematics.tool_frames`).
        package_dirs: folders that ``package://`` mesh URIs resolve against, and the only folders
            meshes may be read from (default: the URDF's folder and its parent).
        tool_offset: placement of the tool point in ``tool_frame`` (translation [m], rotation;
            :func:`rigid_placement`), which becomes the robot's tool frame; ``None``: the tool frame itself.
        meshes: load the visual and collision meshes (to draw the robot); if one is not found, none is loaded
            (:attr:`Robot.missing_meshes` names them: the views draw a skeleton). ``False``: kinematics only (no
            geometry models), no mesh read.
        xacro_args: arguments of a ``.xacro`` file by name (:func:`tribokin.kinematics.urdf_xacro.expand_xacro`).
        base: the base's placement in the world (:func:`rigid_placement`); ``None``: the world is the base frame.

    Raises:
        RobotDescriptionError: a missing or malformed URDF (or xacro), a mesh outside ``package_dirs``
            (:func:`tribokin.kinematics.urdf_meshes.confine_meshes`, before Pinocchio reads any file), with
            ``meshes`` a mesh that is not readable, an unknown tool frame, a joint moving the tool that is
            not 1-DoF, no default tool frame (a floating base whose longest chains are separate limbs).
    """
    model, read_geometry, reference_q, missing = _read_urdf(path, package_dirs, meshes, xacro_args)
    robot = reduce_to_chain(model, reference_q, tool_frame, read_geometry, str(path), tool_offset, base, missing)
    robot.origin = model_origin(robot.model, robot.tool_frame, robot.label, model, "urdf")
    return robot


def _read_urdf(path, package_dirs=(), meshes: bool = True, xacro_args: dict[str, str] | None = None
               ) -> tuple[pin.Model, Callable[[pin.GeometryType], pin.GeometryModel] | None, np.ndarray,
                          tuple[str, ...]]:
    """The whole model of the URDF (or xacro) at ``path`` (:func:`load_urdf`), its geometry models by kind (read now,
    so that a mesh that cannot be read is an error before any work; ``None`` without ``meshes``, or when a mesh is
    not found), its reference posture (each 1-DoF joint at mid-range, the rest neutral) and the meshes not found
    (:func:`~tribokin.kinematics.urdf_meshes.confine_meshes`)."""
    path = Path(path)
    if not path.is_file():
        raise RobotDescriptionError(f"URDF file '{path}' not found", "path")
    dirs = [Path(p) for p in package_dirs] or [path.parent, path.parent.parent]
    try:
        urdf = ET.fromstring(urdf_text(path, dirs, xacro_args))
    except ET.ParseError as error:
        raise RobotDescriptionError(f"cannot read URDF '{path}': {error}", "path") from None
    missing = confine_meshes(urdf, path, dirs)
    text = ET.tostring(urdf, encoding="unicode")
    try:
        model = _quiet(pin.buildModelFromXML, text)
    except (RuntimeError, ValueError) as error:
        first = str(error).strip().splitlines()[0] if str(error).strip() else "unreadable"
        raise RobotDescriptionError(f"cannot read URDF '{path}': {first}", "path") from None
    geometries = None
    if meshes and not missing:
        try:
            geometries = {kind: _quiet(pin.buildGeomFromUrdfString, model, text, kind, None, list(map(str, dirs)))
                          for kind in (pin.GeometryType.VISUAL, pin.GeometryType.COLLISION)}
        except (RuntimeError, ValueError) as error:
            raise RobotDescriptionError(f"cannot read the meshes of URDF '{path}': {_loader_message(error)} "
                                        f"({WITHOUT_MESHES})", "path") from None
    return model, None if geometries is None else geometries.__getitem__, reference_posture(model), missing


def reference_posture(model: pin.Model) -> np.ndarray:
    """(nq,) a URDF's reference posture: each 1-DoF joint at mid-range (finite limits less than 1000 apart), the
    rest (a continuous joint's cosine and sine, a free flyer) neutral."""
    mid_range = pin.neutral(model)
    for joint in model.joints[1:]:
        low, high = model.lowerPositionLimit[joint.idx_q], model.upperPositionLimit[joint.idx_q]
        if joint.nq == 1 and np.isfinite(low) and np.isfinite(high) and high - low < 1e3:
            mid_range[joint.idx_q] = (low + high) / 2
    return mid_range


def load_example_robot(name: str, tool_frame: str | None = None, tool_offset: pin.SE3 | None = None,
                       base: pin.SE3 | None = None) -> Robot:
    """Load a robot that example-robot-data ships, by name (e.g. ``"ur5"``); ``tool_frame``, ``tool_offset`` and
    ``base`` as for :func:`load_urdf`."""
    _check_robot_name(name)
    model, read_geometry, reference_q = _example_robot(name)
    robot = reduce_to_chain(pin.Model(model), reference_q.copy(), tool_frame, read_geometry, name, tool_offset, base)
    robot.origin = model_origin(robot.model, robot.tool_frame, robot.label, model, "example-robot-data")
    return robot


def _check_robot_name(name: str) -> None:
    """Refuse a name example-robot-data does not know, listing those it does."""
    names = example_robot_names()
    if name not in names:
        raise RobotDescriptionError(f"unknown robot '{name}'{closest_hint(name, names)}; valid names: "
                                    f"{', '.join(names)}", "name")


def candidate_tool_frames(robot: str) -> ToolFrames:
    """The frames that could be the tool frame of ``robot`` (an example-robot-data name, or a URDF file's path), and
    its default (:func:`~tribokin.kinematics.tool_frames.tool_frames`)."""
    if robot.lower().endswith(".urdf") or Path(robot).is_file():
        model = _read_urdf(Path(robot), meshes=False)[0]
    else:
        _check_robot_name(robot)
        model = pin.Model(_example_robot(robot)[0])
    _make_frame_names_unique(model)
    return tool_frames(model, robot)


@functools.cache
def _example_robot(name: str):
    """(model, ``read_geometry(kind)``, reference posture) of an example-robot-data robot, read once per process;
    callers copy the model (:func:`_read_example_robot`)."""
    try:
        return _read_example_robot(name)
    except (ImportError, OSError, RuntimeError, ValueError) as error:
        reason = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        if "SDF" in reason and not pin.WITH_SDFORMAT:
            reason = f"its description is an SDF file, and this Pinocchio ({pin.__version__}) was built without SDF"
        raise RobotDescriptionError(f"example-robot-data cannot load '{name}': {reason}", "name") from None


def _read_example_robot(name: str):
    """:func:`_example_robot` uncached and unchecked.

    A robot whose loader is example-robot-data's plain URDF loader (``RobotLoader``'s ``__init__``: the arms, and the
    legged robots and humanoids with a free flyer) is read as that loader reads it, from its class's attributes: the
    URDF through Pinocchio (with a free-flyer root joint, its 7 coordinates limited to ±1, as the loader's
    ``addFreeFlyerJointLimits``), the reference posture from its SRDF (example-robot-data's ``readParamsFromSrdf``),
    but no mesh; each kind of geometry is read when first asked for (a floating-base robot, refused, never reads
    one). Its meshes must lie inside example-robot-data's ``robots`` folder, checked before any is read. Any other
    loader (its own ``__init__``, an SDF file) is run whole, meshes included, and its meshes checked after (its own
    files, named by no user input).
    """
    from example_robot_data.robots_loader import ROBOTS, loader
    from example_robot_data.utils import RobotLoader, getModelPath, readParamsFromSrdf

    attributes = ROBOTS[name]  # the loader's class
    if attributes.__init__ is not RobotLoader.__init__ or not attributes.urdf_filename:
        robot_loader = _quiet(loader, name)
        wrapper = robot_loader.robot
        _confine_example_meshes(Path(robot_loader.df_path), Path(robot_loader.model_path))
        geometries = {pin.GeometryType.VISUAL: wrapper.visual_model,
                      pin.GeometryType.COLLISION: wrapper.collision_model}
        reference_q = wrapper.q0 if wrapper.q0 is not None else pin.neutral(wrapper.model)
        return wrapper.model, geometries.__getitem__, np.asarray(reference_q)
    description = f"{attributes.path}/{attributes.urdf_subpath}/{attributes.urdf_filename}"
    robots = Path(attributes.model_path or getModelPath(description))
    urdf = robots / description
    _confine_example_meshes(urdf, robots)
    root_joint = [pin.JointModelFreeFlyer()] if attributes.free_flyer else []
    model = _quiet(pin.buildModelFromUrdf, str(urdf), *root_joint)
    reference_q = pin.neutral(model)
    if attributes.srdf_filename:
        srdf = robots / attributes.path / attributes.srdf_subpath / attributes.srdf_filename
        reference_q = readParamsFromSrdf(model, str(srdf), False, attributes.has_rotor_parameters,
                                         attributes.ref_posture)
    if attributes.free_flyer:  # the loader's addFreeFlyerJointLimits: the free flyer's 7 coordinates within ±1
        upper, lower = model.upperPositionLimit, model.lowerPositionLimit
        upper[:7], lower[:7] = 1, -1
        model.upperPositionLimit, model.lowerPositionLimit = upper, lower

    @functools.cache
    def read_geometry(geometry_type: pin.GeometryType) -> pin.GeometryModel:
        return _quiet(pin.buildGeomFromUrdf, model, str(urdf), geometry_type, None, [str(robots.parent.parent)])

    return model, read_geometry, np.asarray(reference_q)


def _confine_example_meshes(urdf: Path, robots: Path) -> None:
    """Check that the meshes of example-robot-data's URDF ``urdf`` are files inside its ``robots`` folder (a URDF may
    lie in a robots folder inside it) (:func:`~tribokin.kinematics.urdf_meshes.confine_meshes`): read only when
    drawn, they are checked before any work."""
    urdf, robots = urdf.resolve(), robots.resolve()
    confine_meshes(ET.parse(urdf).getroot(), urdf, [robots.parent.parent], allowed_dirs=[robots], required=True)
