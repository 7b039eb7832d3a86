"""Orocos KDL (Debian's python3-pykdl) as an independent reference for the Python tests: a KDL
chain built with KDL's own API from a model's published parameters (KDL's DH frames, joints about
z, rigid-body inertias about the centre of mass), as tests/model/KdlChain.hpp does in C++."""
import numpy as np
import PyKDL as K


def _frame(t):
    t = np.asarray(t)
    return K.Frame(K.Rotation(*t[:3, :3].ravel()), K.Vector(*t[:3, 3]))


def chain(model):
    c = K.Chain()
    if not np.array_equal(model.base, np.eye(4)):
        c.addSegment(K.Segment(K.Joint(K.Joint.Fixed), _frame(model.base)))
    for i in range(model.dof):
        link = model.link(i)
        inertia_tensor = link["inertia"]
        inertia = K.RigidBodyInertia(
            link["mass"], K.Vector(*link["com"]),
            K.RotationalInertia(inertia_tensor[0, 0], inertia_tensor[1, 1], inertia_tensor[2, 2],
                                inertia_tensor[0, 1], inertia_tensor[0, 2], inertia_tensor[1, 2]))
        prismatic = link["type"] == "prismatic"
        if model.convention == "standard":
            joint = K.Joint(K.Joint.TransZ if prismatic else K.Joint.RotZ)
            c.addSegment(K.Segment(joint, K.Frame.DH(link["a"], link["alpha"], link["d"], link["offset"]), inertia))
        else:
            f0 = K.Frame.DH_Craig1989(link["a"], link["alpha"], link["d"], link["offset"])
            joint = K.Joint("j", f0.p, f0.M.UnitZ(), K.Joint.TransAxis if prismatic else K.Joint.RotAxis)
            c.addSegment(K.Segment(joint, f0, inertia))
    c.addSegment(K.Segment(K.Joint(K.Joint.Fixed), _frame(model.tool)))
    return c


def _joints(q):
    a = K.JntArray(len(q))
    for i, v in enumerate(q):
        a[i] = float(v)
    return a


def fk(c, q):
    f = K.Frame()
    K.ChainFkSolverPos_recursive(c).JntToCart(_joints(q), f)
    t = np.eye(4)
    for r in range(3):
        for k in range(3):
            t[r, k] = f.M[r, k]
        t[r, 3] = f.p[r]
    return t


def jacobian(c, q):
    j = K.Jacobian(len(q))
    K.ChainJntToJacSolver(c).JntToJac(_joints(q), j)
    return np.array([[j[r, k] for k in range(len(q))] for r in range(6)])


def rnea(c, gravity, q, qd, qdd):
    n = len(q)
    tau = K.JntArray(n)
    wrenches = [K.Wrench() for _ in range(c.getNrOfSegments())]
    K.ChainIdSolver_RNE(c, K.Vector(*gravity)).CartToJnt(_joints(q), _joints(qd), _joints(qdd), wrenches, tau)
    return np.array([tau[i] for i in range(n)])
