"""The arm and its cell as a kinematic model, apart from any physics engine: the arm of a task
(robot.py: the shipped arm, arm.xml, or a lab's URDF or MJCF, with the project's jaws at G), the
cell as one MJCF tree (cell_model.py: the arm, the held object, the pads and the features, which
both simulator engines and the cell check read), forward kinematics on it (arm_kinematics.py), IK
(ik.py), and the arm's joints along a plan with the cell check (cell_path.py). MuJoCo serves here as
a kinematics library (compiling the model, forward kinematics, distances between geoms); nothing
is simulated, so a joint-level arm (stablepush.bridge) needs no simulator.
"""
from stablepush.lazy import lazy_exports

# Loaded when first used: the cell check loads MuJoCo.
_EXPORTS = {
    "CellError": "stablepush.kinematics.cell_path",
    "JointPath": "stablepush.kinematics.cell_path",
    "ModelledArm": "stablepush.kinematics.cell_path",
    "checked_path": "stablepush.kinematics.cell_path",
    "joint_path": "stablepush.kinematics.cell_path",
    "modelled": "stablepush.kinematics.cell_path",
    "ArmKinematics": "stablepush.kinematics.arm_kinematics",
    "ArmModel": "stablepush.kinematics.robot",
    "arm_model": "stablepush.kinematics.robot",
    "robot_description": "stablepush.kinematics.robot",
    "build_mjcf": "stablepush.kinematics.cell_model",
}
__all__ = list(_EXPORTS)
__getattr__ = lazy_exports(__name__, _EXPORTS)
