"""A robot model's default tool frame, and the frames that could be one.

Many descriptions name a sensor frame last (``camera_depth_frame``, ``imu_link``), so the default is not the model's
last frame but the end of its longest chain of *moving joints* (1-DoF: revolute, continuous, prismatic; a floating
base is none):

* from the base, follow the branch with the most moving joints after it;
* where branches tie: if they are shorter than the chain followed so far (the fingers of a hand), stop there, the
  hand is the end; else they are separate limbs, and the first in model order is followed, except on a floating
  base (a legged robot, a humanoid), which is refused: tribokin needs a fixed base;
* of the frames fixed to the end (the link the last joint followed moves): the one whose name looks most like a tool
  (:data:`TOOL_WORDS`), then the deepest in the kinematic tree (most frames from the root: a tool frame hangs below
  its flange), then the first in model order; sensor frames (:data:`SENSOR_PARTS`) only if no other frame is there.
  The name comes before the depth because fixed fingers hang deeper than the end effector (Kinova's j2s6s200).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import pinocchio as pin

from tribokin.errors import RobotDescriptionError

#: Words of frame names that look like a tool, best first: ``tool0`` before ``ee_link``.
TOOL_WORDS = (("tool", "tcp", "grasping"), ("flange",), ("ee", "eef", "effector"))
#: Parts of sensor frame names: such a frame is never the default tool frame while another frame is there.
SENSOR_PARTS = ("camera", "laser", "imu", "depth", "optical", "rgb", "sensor", "lidar", "sonar", "radar",
                "ultrasound", "velodyne", "realsense", "kinect", "xtion")
#: Frame types that can be tool frames (a joint's frame coincides with the body it moves).
FRAME_TYPES = (pin.FrameType.BODY, pin.FrameType.OP_FRAME, pin.FrameType.SENSOR)


def tool_rank(name: str) -> int:
    """How much a frame name looks like a tool: the index of the first of :data:`TOOL_WORDS` among its words (split
    at non-letters and at case changes: ``EndEffector_Link`` is end, effector, link), ``len(TOOL_WORDS)`` if none."""
    words = set(re.findall(r"[a-z]+", re.sub(r"([a-z0-9])([A-Z])", r"\1 \2", name).lower()))
    return next((rank for rank, group in enumerate(TOOL_WORDS) if words & set(group)), len(TOOL_WORDS))


def is_sensor(name: str) -> bool:
    """Whether a frame's name names a sensor (one of :data:`SENSOR_PARTS` in it, any case)."""
    return any(part in name.lower() for part in SENSOR_PARTS)


@dataclass(frozen=True)
class ToolFrames:
    """The frames of a model that end a chain of moving joints, and its default tool frame.

    Attributes:
        frames: (name, number of moving joints that move it) of every frame fixed to the link that ends a chain:
            the default's link's first (the default first), then the others' (sensor frames last, then most joints
            first), each group ordered by the default's rule.
        default: the default tool frame (module docstring), or ``None`` when the model has none.
        why_none: why it has none (a floating base whose longest chains are separate limbs), else ``None``.
    """

    frames: tuple[tuple[str, int], ...]
    default: str | None
    why_none: str | None


def _moving(model: pin.Model, joint: int) -> bool:
    return model.joints[joint].nv == 1


def _joint_tree(model: pin.Model) -> tuple[dict[int, list[int]], dict[int, int]]:
    """The moving joints as a tree: each one's children (moving joints whose nearest moving ancestor it is; 0: the
    base), and the most moving joints along a branch from each (the joint included, the base not)."""
    children = {0: []}
    for joint in range(1, model.njoints):
        if _moving(model, joint):
            parent = model.parents[joint]
            while parent > 0 and not _moving(model, parent):
                parent = model.parents[parent]
            children[parent].append(joint)
            children[joint] = []
    longest = {}
    for joint in sorted(children, reverse=True):  # Pinocchio numbers a joint after its parent
        longest[joint] = (joint > 0) + max((longest[child] for child in children[joint]), default=0)
    return children, longest


def _chain_end(model: pin.Model, label: str) -> tuple[int, str | None]:
    """The last joint of the chain the default tool frame ends (module docstring), and why there is none (then 0)."""
    children, longest = _joint_tree(model)
    floating = next((name for joint, name in zip(model.joints, model.names, strict=True) if joint.shortname() ==
                     "JointModelFreeFlyer"), None)
    node = followed = 0
    while children[node]:
        best = max(longest[child] for child in children[node])
        tied = [child for child in children[node] if longest[child] == best]
        if len(tied) > 1 and best < followed:
            break  # the fingers of a hand: the hand is the end
        if len(tied) > 1 and floating is not None:
            limbs = ", ".join(f"'{model.names[joint]}'" for joint in tied)
            return 0, (f"{label} has a floating base (joint '{floating}') and its longest chains of joints are "
                       f"separate limbs (from joints {limbs}): a legged robot or a humanoid, which tribokin cannot "
                       "hold in place; tribokin needs a fixed base: a URDF without the floating joint, or "
                       "robot.tool_frame set to a frame on an arm (`tribokin robots --frames` lists them)")
        node, followed = tied[0], followed + 1
    if node == 0 and floating is not None:
        return 0, f"{label} has a floating base (joint '{floating}') and no joint moving a frame: nothing to measure"
    return node, None if node else f"no joint of {label} moves any frame"


def _depth(model: pin.Model, frame: int) -> int:
    """Frames from the root to ``frame`` in the kinematic tree."""
    depth = 0
    while frame and model.frames[frame].parentFrame != frame:
        frame, depth = model.frames[frame].parentFrame, depth + 1
    return depth


def tool_frames(model: pin.Model, label: str) -> ToolFrames:
    """The candidate tool frames of ``model`` and its default (module docstring); ``label`` names it in messages."""
    children, _ = _joint_tree(model)
    end, why_none = _chain_end(model, label)
    ends = {joint for joint, below in children.items() if joint and not below} | ({end} if end else set())
    frames = [i for i, frame in enumerate(model.frames) if frame.parentJoint in ends and frame.type in FRAME_TYPES]
    moved_by = {i: sum(_moving(model, j) for j in model.supports[model.frames[i].parentJoint][1:]) for i in frames}
    frames.sort(key=lambda i: (model.frames[i].parentJoint != end, is_sensor(model.frames[i].name), -moved_by[i],
                               tool_rank(model.frames[i].name), -_depth(model, i), i))
    candidates = tuple((model.frames[i].name, moved_by[i]) for i in frames)
    return ToolFrames(candidates, candidates[0][0] if end else None, why_none)


def default_tool_frame(model: pin.Model, label: str) -> str:
    """The default tool frame of ``model`` (module docstring); a :class:`RobotDescriptionError` when it has none."""
    frames = tool_frames(model, label)
    if frames.default is None:
        raise RobotDescriptionError(frames.why_none, "tool_frame")
    return frames.default
