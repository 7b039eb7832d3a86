"""Every model function of the module against the C++ library's own results, to 1e-12: the Puma
560, the WAM 7 and URDF test arms (tests/model/data) at a few configurations, through

- rp-model (apps/rp-model, the installed command-line tool) for fk, jacobian, gravity, rnea (also
  with motor inertia and friction) and the mass matrix (also with motor inertia), and
- rp-python-reference (tests/python/model_reference.cpp, a test helper) for every model function
  the module binds: those, link transforms, the end-effector-frame Jacobian, ABA (forward
  dynamics by the articulated-body algorithm, which rp-model does not offer: its `fd` solves with
  the mass matrix), numeric IK and the Puma's closed-form IK.

Inputs are written with repr() and read back exactly (JSON, 17 significant digits both ways), so
the two sides compute with the same numbers."""
import json
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import roboticplatform as rp

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("RP_BIN_DIR", ROOT / "build" / "bin"))
DATA = ROOT / "tests" / "model" / "data"
TOLERANCE = 1e-12

# (name, Python model, rp-model --robot arguments)
ROBOTS = [
    ("puma560", lambda: rp.Puma560Model(), ["--robot", "puma560"]),
    ("wam7", lambda: rp.WAMModel(7), ["--robot", "wam7"]),
    ("test_arm", lambda: rp.UrdfModel(str(DATA / "test_arm.urdf"), tip="tool"),
     ["--robot", str(DATA / "test_arm.urdf"), "--tip", "tool"]),
    ("mimic_arm", lambda: rp.UrdfModel(str(DATA / "mimic_arm.urdf")), ["--robot", str(DATA / "mimic_arm.urdf")]),
]


def configurations(model, count=3, seed=21):
    """The home position, then random ones within the limits, each with qd, qdd and tau."""
    rng = np.random.default_rng(seed)
    lo, hi = np.maximum(model.position_min, -3), np.minimum(model.position_max, 3)
    cases = []
    for k in range(count):
        q = model.home.copy() if k == 0 else rng.uniform(lo, hi)
        cases.append({"q": q, "qd": rng.uniform(-1, 1, model.dof), "qdd": rng.uniform(-2, 2, model.dof),
                      "tau": rng.uniform(-5, 5, model.dof)})
    return cases


def listed(v):
    return ",".join(repr(float(x)) for x in v)


def rp_model(args, command, *options):
    out = subprocess.run([str(BIN / "rp-model"), *args, command, *options], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def reference(args, cases):
    request = json.dumps([{k: [float(x) for x in v] for k, v in c.items()} for c in cases])
    out = subprocess.run([str(BIN / "rp-python-reference"), *args], input=request, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def close(python, cpp, what):
    np.testing.assert_allclose(python, np.array(cpp, dtype=float), rtol=0, atol=TOLERANCE, err_msg=what)


@pytest.mark.parametrize("name,make,args", ROBOTS, ids=[r[0] for r in ROBOTS])
def test_python_agrees_with_rp_model(name, make, args):
    model = make()
    for case in configurations(model):
        q, qd, qdd = listed(case["q"]), listed(case["qd"]), listed(case["qdd"])
        out = rp_model(args, "fk", "--q", q)
        assert out["joints"] == model.joint_names and out["links"] == model.link_names
        close(model.fk(case["q"]), out["fk"], f"{name} fk")
        close(model.jacobian(case["q"]), rp_model(args, "jacobian", "--q", q)["jacobian"], f"{name} jacobian")
        close(model.gravity_torque(case["q"]), rp_model(args, "gravity", "--q", q)["tau"], f"{name} gravity")
        close(model.rnea(case["q"], case["qd"], case["qdd"]),
              rp_model(args, "rnea", "--q", q, "--qd", qd, "--qdd", qdd)["tau"], f"{name} rnea")
        close(model.rnea(case["q"], case["qd"], case["qdd"], motor_inertia=True, friction=True),
              rp_model(args, "rnea", "--q", q, "--qd", qd, "--qdd", qdd, "--motor-inertia", "--friction")["tau"],
              f"{name} rnea with motor inertia and friction")
        close(model.crba(case["q"]), rp_model(args, "inertia", "--q", q)["M"], f"{name} mass matrix")
        close(model.crba(case["q"], motor_inertia=True), rp_model(args, "inertia", "--q", q, "--motor-inertia")["M"],
              f"{name} mass matrix with motor inertia")


@pytest.mark.parametrize("name,make,args", ROBOTS, ids=[r[0] for r in ROBOTS])
def test_every_model_function_agrees_with_the_cpp_library(name, make, args):
    model = make()
    cases = configurations(model)
    results = reference(args, cases)
    assert len(results) == len(cases)
    Q = np.array([c["q"] for c in cases])
    QD, QDD, TAU = (np.array([c[k] for c in cases]) for k in ("qd", "qdd", "tau"))
    batched = {
        "fk": model.fk_batch(Q), "link_transforms": model.link_transforms_batch(Q), "jacobian": model.jacobian_batch(Q),
        "jacobian_end_effector": model.jacobian_batch(Q, frame="end_effector"), "rnea": model.rnea_batch(Q, QD, QDD),
        "rnea_motor_friction": model.rnea_batch(Q, QD, QDD, motor_inertia=True, friction=True),
        "rnea_no_gravity": model.rnea_batch(Q, QD, QDD, gravity=False), "gravity_torque": model.gravity_torque_batch(Q),
        "crba": model.crba_batch(Q), "crba_motor": model.crba_batch(Q, motor_inertia=True),
        "aba": model.aba_batch(Q, QD, TAU), "aba_motor_friction": model.aba_batch(Q, QD, TAU, motor_inertia=True, friction=True),
        "aba_no_gravity": model.aba_batch(Q, QD, TAU, gravity=False),
    }
    for k, (case, cpp) in enumerate(zip(cases, results)):
        q, qd, qdd, tau = case["q"], case["qd"], case["qdd"], case["tau"]
        single = {
            "fk": model.fk(q), "link_transforms": model.link_transforms(q), "jacobian": model.jacobian(q),
            "jacobian_end_effector": model.jacobian(q, frame="end_effector"), "rnea": model.rnea(q, qd, qdd),
            "rnea_motor_friction": model.rnea(q, qd, qdd, motor_inertia=True, friction=True),
            "rnea_no_gravity": model.rnea(q, qd, qdd, gravity=False), "gravity_torque": model.gravity_torque(q),
            "crba": model.crba(q), "crba_motor": model.crba(q, motor_inertia=True), "aba": model.aba(q, qd, tau),
            "aba_motor_friction": model.aba(q, qd, tau, motor_inertia=True, friction=True),
            "aba_no_gravity": model.aba(q, qd, tau, gravity=False),
        }
        for what, value in single.items():
            close(value, cpp[what], f"{name} case {k}: {what}")
            close(batched[what][k], cpp[what], f"{name} case {k}: {what}_batch")
        assert model.within_limits(q) == cpp["within_limits"]
        # Numeric IK from the home position (the default seed) to fk(q): the same iterations.
        status, solution = model.ik(model.fk(q))
        assert status == cpp["ik"]["status"]
        close(solution, cpp["ik"]["q"], f"{name} case {k}: ik")
        solved, solutions = model.ik_batch(model.fk(q)[None])
        assert solved[0] == (cpp["ik"]["status"] == "solved")
        close(solutions[0], cpp["ik"]["q"], f"{name} case {k}: ik_batch")
        if isinstance(model, rp.Puma560Model):
            python_all = model.ik_all(model.fk(q))
            assert [s["branch"] for s in python_all] == [s["branch"] for s in cpp["ik_all"]]
            assert [s["within_limits"] for s in python_all] == [s["within_limits"] for s in cpp["ik_all"]]
            for p, c in zip(python_all, cpp["ik_all"]):
                close(p["q"], c["q"], f"{name} case {k}: ik_all {c['branch']}")
            status, closest = model.ik_closest(model.fk(q), q)
            assert status == cpp["ik_closest"]["status"]
            close(closest, cpp["ik_closest"]["q"], f"{name} case {k}: ik_closest")
            assert model.branch_of(q) == cpp["branch_of"]
