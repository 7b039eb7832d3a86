"""The paper's generic-manipulator excerpt (section 3.6) in Python.

Run: PYTHONPATH=build/python python3 examples/python/generic_manipulator.py -config examples/rp.cfg -nogui

Changes from the paper's C++: Python names (create_derived_object, enable_arm_power,
end_effector_transform); the platform's switches are passed to rp.init().
"""
import sys

import numpy as np

import roboticplatform as rp

rp.init(sys.argv[1:])

om = rp.ObjectManager()  # The object manager
manipulator = om.createDerivedObject("leader")
# Creates either a Puma or a WAM object, depending on
# what is specified in the global configuration file under the name "leader"

# Now, we can do generic operations
manipulator.enable_arm_power()
print("Current End-Effector Coordinate Frame: ")
with np.printoptions(precision=6, suppress=True):
    print(manipulator.end_effector_transform())
