"""The simulated arm on two physics engines (engines.py): MuJoCo (scene.py, arm.py, friction.py)
and Drake (drake_arm.py); the arm's IK (ik.py), the friction-fidelity contract both must pass
(fidelity.py), and the arm-protocol server (server.py) behind `stablepush sim-arm`."""
