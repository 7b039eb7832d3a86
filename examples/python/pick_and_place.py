"""Simple pick and place operation: the paper's Figure 21 in Python.

Run: PYTHONPATH=build/python python3 examples/python/pick_and_place.py -nogui [-simclock]

Changes from the paper's C++ (besides those of examples/pick_and_place.cpp, whose positions
it uses): Python names; poses are 4 x 4 numpy arrays built with numpy; no work piece and no
gripper mount (the Python module has no WorkPiece and no setConnection yet): the arm makes the
C++ program's motions with nothing in the gripper.
"""
import sys

import numpy as np

import roboticplatform as rp


def translation(x, y, z):
    t = np.eye(4)
    t[:3, 3] = [x, y, z]
    return t


# Initialize the Robotic Platform framework
rp.init(sys.argv[1:])

# Create the objects required for the task
puma = rp.Puma560()
gripper = rp.DefaultGripper()

# Create the trajectory generator and connect it to the Puma object
tragen = rp.TrajectoryGenerator()
puma.set_trajectory_generator(tragen)

# A transform that represents the end-effector orientation: pointing down
down = np.diag([1.0, -1.0, -1.0, 1.0])

# Move to the object and pick it up
gripper.open()
tragen.move_to(translation(0, 0.5, 0.12) @ down)
tragen.stop(1)
gripper.close()
tragen.stop(1)

# Move to the target position and drop the object
tragen.move_to(translation(0.5, 0.5, 0.3) @ down)
tragen.move_to(translation(0.6, 0.2, 0.3) @ down)
tragen.stop(1)
gripper.open()
tragen.stop(1)

if rp.is_shutdown_requested():  # a fault, an emergency stop or Ctrl-C ended the motion
    print("pick_and_place: stopped by a system shutdown: " + rp.shutdown_reason(), file=sys.stderr)
    sys.exit(3)
print("pick_and_place: done, end-effector at", " ".join(f"{v:g}" for v in puma.end_effector_transform()[:3, 3]))
