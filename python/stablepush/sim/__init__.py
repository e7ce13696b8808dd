"""The simulated arm on two physics engines, each a sub-package: MuJoCo (mujoco/: the arm, the pads'
friction, videos of recorded runs) and Drake (drake/), both building the cell that
stablepush.kinematics describes, named in one registry (engines.py). What both share stays here:
tracking.py (IK on kinematics.ik, the servo ramp, the state), deviation.py (a world that departs
from the task), the arm behind the arm port in this process (local_arm.py) and served over TCP
(server.py, `stablepush sim-arm`), and the friction-fidelity contract both must pass (fidelity.py)."""

# How a run's video draws it (mujoco/video.py): here, so that a command line can offer the choice without
# loading the renderer's module.
VIDEO_VIEWS = ("schematic", "3d", "both")

from stablepush.lazy import lazy_exports  # noqa: E402 - after the constant the command line reads

_EXPORTS = {
    "DEFAULT_ENGINE": "stablepush.sim.engines",
    "ENGINES": "stablepush.sim.engines",
    "WorldDeviation": "stablepush.sim.deviation",
    "SimulatedArm": "stablepush.sim.local_arm",
    "SimArmServer": "stablepush.sim.server",
    "RunVideo": "stablepush.sim.mujoco.video",
    "check_fps": "stablepush.sim.mujoco.video",
    "check_size": "stablepush.sim.mujoco.video",
    "check_video_path": "stablepush.sim.mujoco.video",
    "video_directory": "stablepush.sim.mujoco.video",
}
__all__ = ["VIDEO_VIEWS", *_EXPORTS]
__getattr__ = lazy_exports(__name__, _EXPORTS)
