"""A friction law of your own, used like the built-in ones.

``Triangular`` subclasses ``tribokin.FrictionLaw``: it names its parameters and makes its frozen scipy
distribution (``scipy.stats.triang``), the base class gives the rest (draws, moments, support, ``describe()``).
The gantry's x guide gets it through ``tribokin.joint_models``; a pose's test then draws its friction
coefficients from it. The script prints the law's mean and standard deviation, the mean of the coefficients
drawn, and the pose's RP_l in µm beside the same pose with the x guide's preset law.
"""

from pathlib import Path

import pinocchio as pin
from scipy import stats

import tribokin


class Triangular(tribokin.FrictionLaw):
    """mu triangular on [low, high], most likely at ``mode``."""

    law = "triangular"  # setting law registers it: study files could name it too
    parameters = ("low", "mode", "high")

    def __init__(self, low: float, mode: float, high: float, provenance: str | None = None):
        if not 0 <= low <= mode <= high or low == high:
            raise ValueError("need 0 <= low <= mode <= high and low < high")
        super().__init__({"low": float(low), "mode": float(mode), "high": float(high)}, provenance)

    def _distribution(self):
        low, mode, high = self.params["low"], self.params["mode"], self.params["high"]
        return stats.triang((mode - low) / (high - low), loc=low, scale=high - low)


URDF = Path(__file__).resolve().parent.parent / "urdf" / "cartesian_xyz.urdf"
robot = tribokin.Robot.from_pinocchio(pin.buildModelFromUrdf(str(URDF)), tool_frame="tool")
law = Triangular(0.08, 0.10, 0.16, provenance="made up for this example")
print(f"law: {law!r}, mean mu = {law.mean():.4f}, std = {law.std():.4f}")

results = {}
for name, x_friction in (("triangular", law), ("preset", tribokin.preset("42CD4-raw"))):
    joints = tribokin.joint_models(robot, friction=tribokin.preset("42CD4-raw"), stiffness=2.0e7,  # N/m
                                   bearing_span_m=0.2, joints={"x": {"friction": x_friction}})
    results[name] = tribokin.pose_test(robot, joints, [0.3, 0.2, 0.1], cycles=200, seed=3, payload_kg=5.0)

pose = results["triangular"]
print(f"mu drawn on x over {pose.cycles} cycles: mean {pose.mu[:, 0].mean():.4f}, std {pose.mu[:, 0].std():.4f}")
for name, result in results.items():
    print(f"x guide {name}: RP_l = {result.report_row()['directions']['+']['RP_l_um']:.3f} um")
