"""Robotic Platform from Python: ``import roboticplatform as rp``.

Models (``rp.Puma560Model()``, ``rp.WAMModel(7)``, ``rp.UrdfModel(path)``) with forward kinematics,
Jacobians, inverse and forward dynamics and inverse kinematics on numpy arrays, in single and
batched forms (the batched ones release the GIL); manipulators whose servo loops run in C++
(``rp.Puma560("leader")``), the paper's motion commands (``rp.TrajectoryGenerator``) and the
simulated clock stepped from Python (``rp.step(cycles)``). See docs/python.md.
"""
from ._roboticplatform import *  # noqa: F401,F403
from ._roboticplatform import __doc__  # noqa: F401
