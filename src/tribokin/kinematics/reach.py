"""The reach of a robot's chain: a sphere the tool point never leaves, whatever the joints do within their limits.

The bound follows the chain from the tool point back to the base, keeping the set of tool points the
joints beyond each one can produce inside the convex hull of a few circles (a point is a circle of radius 0):

* a prismatic joint sweeps every circle along its travel: the hull of the circles at both ends of the travel
  contains the swept set;
* a revolute joint turns the set about its axis (a full turn, whatever its limits): every circle stays within
  the cylinder about the axis of radius the circles' largest distance from the axis and of axial span their
  axial span, the hull of two circles about the axis;
* each joint's placement in its parent carries the circles into the parent's frame.

At the first joint the sphere is centred on its origin when it is revolute (distances from a point of the axis
do not change as the joint turns, so its own turn costs nothing), else on the mean of the circles' centres; its
radius is the circles' largest distance from that centre. Every step only enlarges the set, so the bound
holds for every configuration within the limits (revolute limits are not used).

When a target holds the tool's orientation as well as its position, the whole tool pose is fixed, and so is the
frame of the last joint of the chain (the joint that carries the tool frame, after its own motion: the tool frame
is fixed in it). Its origin then lies at ``p + R · offset`` (tool point ``p`` [m], tool orientation ``R``, the
origin's position ``offset`` [m] from the tool point in the tool frame, a constant of the model), and the same
construction, started from that origin instead of the tool point, bounds where the rest of the chain can bring it
(:func:`last_joint_sphere`): a target pose that puts it beyond that sphere is unreachable with that orientation,
whatever the joints (revolute or prismatic) and however many.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.kinematics.robot import Robot

#: Angles at which the distance of a circle from an axis is evaluated; the largest distance is bounded by the
#: largest sampled one plus radius · π / AXIS_SAMPLES (the distance changes by at most the radius per radian).
AXIS_SAMPLES = 1024
#: Margin [m] beyond the bound before a target is declared out of reach: rounding in the bound and the forward
#: kinematics (~1e-15 m) and the IK's tolerances (1e-9 m; 1e-8 rad, which moves the last joint's origin by
#: 1e-8 rad times its distance from the tool point, ~1e-9 m) lie far below it.
REACH_MARGIN_M = 1e-6


@dataclass(frozen=True)
class ReachSphere:
    """A sphere in the world frame that contains a point of the chain (the tool point, or the origin of the last
    joint's frame) at every configuration within the joint limits.

    Attributes:
        centre_m: (3,) centre [m] (the first joint's origin when it is revolute).
        radius_m: radius [m] (``inf`` when a prismatic joint's travel is unbounded).
        offset_m: (3,) position [m] of the bounded point from the tool point in the tool frame, when it is not
            the tool point: a target tool pose then fixes it (:meth:`bounded_points_m`); ``None``: the tool point.
        point: the bounded point, for messages (``"the tool point"``).
    """

    centre_m: np.ndarray
    radius_m: float
    offset_m: np.ndarray | None = None
    point: str = "the tool point"

    def bounded_points_m(self, tool_positions_m, rotation: np.ndarray | None) -> np.ndarray:
        """(k, 3) positions [m] of the bounded point when the tool point is at ``tool_positions_m`` (k, 3) [m] with
        the tool frame turned by ``rotation`` (3, 3) in the world frame (``None``: not held, for the tool point)."""
        positions = np.asarray(tool_positions_m, dtype=float).reshape(-1, 3)
        if self.offset_m is None:
            return positions
        if rotation is None:
            raise ValueError(f"{self.point} is placed by the tool's orientation, and none is held")
        return positions + rotation @ self.offset_m

    def distances_m(self, positions_m) -> np.ndarray:
        """(k,) distances [m] of ``positions_m`` (k, 3) [m] from the centre."""
        return np.linalg.norm(np.asarray(positions_m, dtype=float).reshape(-1, 3) - self.centre_m, axis=1)

    def beyond_m(self, positions_m) -> np.ndarray:
        """(k,) how far [m] each of ``positions_m`` (k, 3) [m] lies beyond the sphere, NaN for those not more than
        ``REACH_MARGIN_M`` beyond it: no configuration within the limits brings the tool point nearer than that."""
        gaps = self.distances_m(positions_m) - self.radius_m
        return np.where(gaps > REACH_MARGIN_M, gaps, np.nan)


def _circle_points(centres: np.ndarray, normals: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """(k, AXIS_SAMPLES, 3) points [m] evenly spaced around each circle (centres (k, 3) [m], unit normals (k, 3),
    radii (k,) [m])."""
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(normals, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(normals, u)
    angles = np.linspace(0.0, 2 * np.pi, AXIS_SAMPLES, endpoint=False)[None, :, None]
    return centres[:, None] + radii[:, None, None] * (np.cos(angles) * u[:, None] + np.sin(angles) * v[:, None])


def _farthest_m(centres: np.ndarray, normals: np.ndarray, radii: np.ndarray, point: np.ndarray) -> float:
    """Largest distance [m] of ``point`` (3,) [m] from the circles (centres (k, 3) [m], unit normals (k, 3),
    radii (k,) [m]), exact: for each, √(offset along its normal² + (offset in its plane + radius)²)."""
    offsets = centres - point
    across = np.sum(offsets * normals, axis=1)
    within = np.linalg.norm(offsets - across[:, None] * normals, axis=1)
    return float(np.max(np.hypot(across, within + radii)))


def _turned(centres: np.ndarray, normals: np.ndarray, radii: np.ndarray, axis: np.ndarray, ball_radius: float):
    """The two circles about ``axis`` (unit, through the origin) whose hull contains the circles (centres (k, 3)
    [m], unit normals (k, 3), radii (k,) [m]) turned by any angle about it, given that they lie in a ball of
    radius ``ball_radius`` [m] centred on the axis at the origin: (centres (2, 3), normals, radii)."""
    along = centres @ axis
    spread = radii * np.sqrt(np.maximum(0.0, 1.0 - (normals @ axis) ** 2))  # a circle's axial half-span [m]
    points = _circle_points(centres, normals, radii)
    from_axis = np.linalg.norm(points - (points @ axis)[..., None] * axis, axis=2).max(axis=1)
    radius = min(float(np.max(from_axis + radii * np.pi / AXIS_SAMPLES)), ball_radius)
    ends = np.clip([np.min(along - spread), np.max(along + spread)], -ball_radius, ball_radius)
    return ends[:, None] * axis, np.tile(axis, (2, 1)), np.full(2, radius)


def _chain_sphere(robot: Robot, joint: int, point: np.ndarray) -> tuple[np.ndarray, float]:
    """Centre (3,) [m] in the world frame and radius [m] of a sphere that ``point`` (3,) [m], fixed in the frame of
    ``joint`` (after its own motion), never leaves within the joint limits (the construction above)."""
    model = robot.model
    centres, normals, radii = point[None], np.array([[0.0, 0.0, 1.0]]), np.zeros(1)
    centre, radius = point, 0.0  # the ball
    while joint > 0:
        axis, lower, upper = robot.motion_axes[joint - 1], robot.lower_limits[joint - 1], robot.upper_limits[joint - 1]
        if robot.joint_is_prismatic[joint - 1]:
            if not np.isfinite(upper - lower):
                return np.asarray(model.jointPlacements[joint].translation, dtype=float), np.inf
            centres = np.concatenate([centres + lower * axis, centres + upper * axis])
            normals, radii = np.tile(normals, (2, 1)), np.tile(radii, 2)
            centre, radius = centre + (lower + upper) / 2 * axis, radius + (upper - lower) / 2
        else:
            on_axis = (centre @ axis) * axis
            radius = min(np.linalg.norm(centre - on_axis) + radius, _farthest_m(centres, normals, radii, on_axis))
            centre = on_axis
            if model.parents[joint] > 0:  # the first joint's turn leaves distances from its axis's points alone
                centres, normals, radii = _turned(centres - centre, normals, radii, axis, radius)
                centres = centres + centre
        placement = model.jointPlacements[joint]
        centres = centres @ placement.rotation.T + placement.translation
        normals = normals @ placement.rotation.T
        centre = placement.rotation @ centre + placement.translation
        joint = model.parents[joint]
    return centre, float(min(radius, _farthest_m(centres, normals, radii, centre)))


def reach_sphere(robot: Robot) -> ReachSphere:
    """The sphere (:class:`ReachSphere`) the tool point of ``robot`` never leaves within the joint limits."""
    frame = robot.model.frames[robot.tool_frame_id]
    return ReachSphere(*_chain_sphere(robot, frame.parentJoint, np.array(frame.placement.translation)))


def last_joint_sphere(robot: Robot) -> ReachSphere:
    """The sphere (:class:`ReachSphere`) the origin of the frame of the tool's joint (the last of the chain: the
    frame after that joint's own motion, which carries the tool frame) never leaves within the joint limits;
    ``offset_m`` places that origin from the tool point in the tool frame, for targets that hold the tool's
    orientation (:meth:`ReachSphere.bounded_points_m`)."""
    frame = robot.model.frames[robot.tool_frame_id]
    placement = frame.placement  # the tool frame in the joint's frame
    return ReachSphere(*_chain_sphere(robot, frame.parentJoint, np.zeros(3)),
                       offset_m=-placement.rotation.T @ placement.translation,
                       point=f"the origin of joint '{robot.model.names[frame.parentJoint]}'")
