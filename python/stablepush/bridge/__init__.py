"""Bridges from the arm port to a lab's real arm: `joint_arm.JointTrajectoryArm` over the few
methods of a `joint_arm.JointInterface` (read the joints, send joint positions over a duration,
halt). Built on the simulated arm's kinematics (MuJoCo): needs the [sim] extra."""
from stablepush.bridge.joint_arm import JointInterface, JointTrajectoryArm

__all__ = ["JointInterface", "JointTrajectoryArm"]
