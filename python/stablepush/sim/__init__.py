"""The simulated arm on two physics engines (engines.py): MuJoCo (scene.py, arm.py, friction.py)
and Drake (drake_arm.py); what both share (tracking.py: IK on ik.py, the servo ramp, the state;
deviation.py: a world that departs from the task), the arm behind the arm port in this process
(local_arm.py) and served over TCP (server.py, `stablepush sim-arm`), the friction-fidelity
contract both must pass (fidelity.py), and videos of recorded runs (video.py)."""
