"""The simulated arm on Drake (arm.py), built from the same cell (stablepush.kinematics) with
Drake's own contact solver. Importing this package loads no Drake: its module does."""
