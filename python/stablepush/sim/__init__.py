"""The simulated arm (MuJoCo): scene building (scene.py), the arm and its IK (arm.py), and the
arm-protocol server (server.py) behind `stablepush sim-arm`."""
