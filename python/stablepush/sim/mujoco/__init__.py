"""The simulated arm on MuJoCo: the arm and the grasp (arm.py), the pads' Coulomb friction
(friction.py, with the compiled _pad_friction) and videos of recorded runs, drawn with MuJoCo's
renderer (video.py). Importing this package loads no MuJoCo: its modules do."""
