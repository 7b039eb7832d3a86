"""Lifetimes and reference counts of the module's objects and arrays:

- a closed arm raises RuntimeError on every method and property (close() itself excepted: a no-op
  the second time);
- a trajectory generator, a gripper and a model stay alive while an arm or the program uses them,
  even after their Python name is deleted (del + gc.collect()), and are freed once nothing uses
  them (no leak either);
- numpy arrays passed in keep their reference count over many calls, and the arrays returned hold
  no extra references;
- returned arrays own their data: changing or deleting the source object leaves them as they were;
  a large result's buffer is kept for the next large result once Python frees the array, never
  while it lives, and what is kept stays within its bound.

The cases that need rp.init() run in their own interpreter (once per process, as in
test_platform.py)."""
import gc
import sys
import textwrap
import threading
import weakref
import subprocess

import numpy as np
import pytest

import roboticplatform as rp


def python(script, timeout=60):
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(script)], capture_output=True, text=True,
                       timeout=timeout)
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


# Every public member of rp.Manipulator and how to call it; the test fails when the class gains a
# member this list does not name.
CLOSED_ARM = """
import numpy as np, roboticplatform as rp
rp.init(["-simclock", "-nogui"])
tragen = rp.TrajectoryGenerator()
calls = {
    "name": lambda a: a.name, "dof": lambda a: a.dof, "model": lambda a: a.model,
    "joint_position": lambda a: a.joint_position(), "joint_velocity": lambda a: a.joint_velocity(),
    "desired_joint_position": lambda a: a.desired_joint_position(),
    "control_output": lambda a: a.control_output(), "end_effector_transform": lambda a: a.end_effector_transform(),
    "enable_arm_power": lambda a: a.enable_arm_power(), "disable_arm_power": lambda a: a.disable_arm_power(),
    "arm_power": lambda a: a.arm_power, "set_gravity_compensation": lambda a: a.set_gravity_compensation(True),
    "set_zero_gravity_mode": lambda a: a.set_zero_gravity_mode(True),
    "apply_external_wrench": lambda a: a.apply_external_wrench(np.zeros(6)),
    "set_transform": lambda a: a.set_transform(np.eye(4)), "set_simulation_mode": lambda a: a.set_simulation_mode(True),
    "simulation_mode": lambda a: a.simulation_mode, "uses_hardware": lambda a: a.uses_hardware,
    "error_code": lambda a: a.error_code, "error_message": lambda a: a.error_message,
    "cycle_count": lambda a: a.cycle_count, "parameter": lambda a: a.parameter("kp"),
    "set_parameter": lambda a: a.set_parameter("kp", [1.0] * 6), "parameters": lambda a: a.parameters(),
    "set_trajectory_generator": lambda a: a.set_trajectory_generator(tragen),
    "clear_trajectory_generator": lambda a: a.clear_trajectory_generator(), "run_cycles": lambda a: a.run_cycles(1),
    "rp.step(arm=...)": lambda a: rp.step(1, a),
}
members = {n for n in dir(rp.Manipulator) if not n.startswith("_")} - {"close"}
missing = members - set(calls)
assert not missing, f"add these members to the test: {sorted(missing)}"
for how, arm in (("own", rp.Puma560("arm")), ("manager", rp.ObjectManager().create_derived_object("leader"))):
    arm.set_trajectory_generator(tragen)
    for name, call in calls.items():
        call(arm)  # works while open
    arm.close()
    for name, call in calls.items():
        try:
            call(arm)
            print("FAIL", how, name, "did not raise")
        except RuntimeError as e:
            print("ok", how, name, e)
        except Exception as e:
            print("FAIL", how, name, type(e).__name__, e)
    arm.close()  # a second close is a no-op
print("done", len(calls))
"""


def test_a_closed_arm_raises_runtime_error_on_every_method(tmp_path):
    cfg = tmp_path / "rp.cfg"
    cfg.write_text("[leader]\nclass Puma560\n")
    out = python(CLOSED_ARM.replace('["-simclock", "-nogui"]', f'["-simclock", "-nogui", "-config", {str(cfg)!r}]'))
    lines = out.splitlines()
    assert lines[-1].startswith("done ")
    failures = [line for line in lines if line.startswith("FAIL")]
    assert failures == []
    oks = [line for line in lines if line.startswith("ok")]
    assert len(oks) == 2 * int(lines[-1].split()[1]) >= 2 * 27
    assert all(line.endswith("the manipulator was closed") for line in oks), oks


def test_the_arm_keeps_its_generator_alive_and_lets_it_go_when_done():
    out = python("""
        import gc, weakref, numpy as np, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        arm = rp.Puma560("arm")
        rp.pause()
        rp.step(1)
        tragen = rp.TrajectoryGenerator()
        alive = weakref.ref(tragen)
        tragen_done = lambda g: g.is_done()
        arm.set_trajectory_generator(tragen)
        target = arm.joint_position() + [0.2, -0.1, 0.1, 0, 0, 0]
        tragen.move_radians(target)
        del tragen
        gc.collect()
        assert alive() is not None, "the arm holds its generator"
        for _ in range(100):
            rp.step(100)
            if tragen_done(alive()): break
        # The motion ran to its end (the servo loop's steady error under gravity is a few mrad).
        print("reached", alive().is_done() and np.abs(arm.joint_position() - target).max() < 0.02)
        arm.clear_trajectory_generator()
        gc.collect()
        print("freed after clear", alive() is None)

        # One generator driving two arms (the paper's Figure 23): alive until both let it go.
        other = rp.Puma560("other")
        shared = rp.TrajectoryGenerator()
        alive = weakref.ref(shared)
        arm.set_trajectory_generator(shared)
        other.set_trajectory_generator(shared)
        del shared
        gc.collect()
        arm.close()
        gc.collect()
        print("alive after the first arm closed", alive() is not None)
        del other  # the last reference to the second arm: it closes and lets the generator go
        gc.collect()
        print("freed after the second arm went", alive() is None)
        # Replaced by another generator: the first one goes.
        third = rp.Puma560("third")
        first, second = rp.TrajectoryGenerator(), rp.TrajectoryGenerator()
        alive_first, alive_second = weakref.ref(first), weakref.ref(second)
        third.set_trajectory_generator(first)
        third.set_trajectory_generator(second)
        del first, second
        gc.collect()
        print("replaced", alive_first() is None, alive_second() is not None)
    """)
    assert out.split() == ["reached", "True", "freed", "after", "clear", "True", "alive", "after", "the", "first", "arm",
                           "closed", "True", "freed", "after", "the", "second", "arm", "went", "True", "replaced",
                           "True", "True"], out


def test_a_gripper_stays_alive_while_a_thread_uses_it_and_goes_when_nothing_does():
    out = python("""
        import gc, threading, weakref, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        gripper = rp.DefaultGripper("hand")
        alive = weakref.ref(gripper)
        started, proceed, states = threading.Event(), threading.Event(), []

        def work(g):
            g.close()  # releases the GIL: the main thread may run meanwhile
            started.set()
            proceed.wait()
            for _ in range(50):
                g.open()
                g.close()
            g.open()
            states.append(g.state)

        worker = threading.Thread(target=work, args=(gripper,))
        worker.start()
        started.wait()
        del gripper
        gc.collect()
        print("alive while used", alive() is not None)
        proceed.set()
        worker.join()
        del worker  # its arguments go with it
        gc.collect()
        print("state", states[0], "freed", alive() is None)
        # Freed where the last reference goes: in a thread, with the GIL released for the destructor.
        g = rp.DefaultGripper("hand2")
        alive = weakref.ref(g)
        box = [g]
        del g
        t = threading.Thread(target=box.clear)
        t.start(); t.join()
        print("freed in a thread", alive() is None)
    """)
    assert out.split() == ["alive", "while", "used", "True", "state", "open", "freed", "True", "freed", "in", "a",
                           "thread", "True"], out


TWO_LINKS = """<robot name="two">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="l2"><inertial><mass value="0.5"/><origin xyz="0.1 0 0"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
</robot>"""


def test_a_model_lives_as_long_as_a_planner_or_a_batched_call_needs_it():
    wam = rp.WAMModel(7)
    target = 0.5 * (wam.home + 0.5 * (wam.position_min + wam.position_max))  # within the limits
    del wam
    expected = rp.Planner(rp.WAMModel(7))
    expected.move_radians(target)
    expected = expected.sample(200)
    model = rp.WAMModel(7)
    alive = weakref.ref(model)
    planner = rp.Planner(model)
    del model
    gc.collect()
    assert alive() is None, "the Python object goes; the planner keeps the C++ model"
    planner.move_radians(target)
    got = planner.sample(200)
    for k in ("time", "q", "qd", "qdd"):
        np.testing.assert_array_equal(got[k], expected[k])
    # A URDF model from text (loaded through a temporary file): the planner outlives it too.
    urdf = rp.UrdfModel(TWO_LINKS)
    alive = weakref.ref(urdf)
    planner = rp.Planner(urdf)
    del urdf
    gc.collect()
    assert alive() is None
    planner.move_radians([0.5, -0.5])
    np.testing.assert_allclose(planner.sample(100)["q"][-1], [0.5, -0.5], atol=1e-12)
    # A batched call in a thread while the main thread drops its name of the model.
    model = rp.Puma560Model()
    Q = np.random.default_rng(0).uniform(-1, 1, (20000, 6))
    reference = model.rnea_batch(Q, Q, Q)
    alive = weakref.ref(model)
    result = []
    worker = threading.Thread(target=lambda m: result.append(m.rnea_batch(Q, Q, Q)), args=(model,))
    worker.start()
    del model
    gc.collect()
    worker.join()
    np.testing.assert_array_equal(result[0], reference)
    del worker
    gc.collect()
    assert alive() is None


def test_a_model_copied_from_an_arm_outlives_the_arm():
    out = python("""
        import gc, numpy as np, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        arm = rp.Puma560("arm")
        model = arm.model
        q = arm.joint_position()
        pose = arm.end_effector_transform()
        arm.close()
        del arm
        gc.collect()
        print(np.abs(model.fk(q) - pose).max() < 1e-12, model.dof)
    """)
    assert out.split() == ["True", "6"], out


def planned(model, start, target, pose):
    planner = rp.Planner(model, start)
    planner.move_radians(target)
    planner.move_to_through_joint_space(pose)
    return planner.sample(50)


def model_calls(model):
    """Each call of the model, its array arguments and its returned arrays."""
    n = model.dof
    rng = np.random.default_rng(1)
    q, qd, qdd = rng.uniform(-0.5, 0.5, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    Q = rng.uniform(-0.5, 0.5, (4, n))
    pose = model.fk(model.home)
    poses = model.fk_batch(Q)
    calls = {
        "fk": (lambda: model.fk(q), [q]),
        "link_transforms": (lambda: model.link_transforms(q), [q]),
        "jacobian": (lambda: model.jacobian(q), [q]),
        "rnea": (lambda: model.rnea(q, qd, qdd), [q, qd, qdd]),
        "gravity_torque": (lambda: model.gravity_torque(q), [q]),
        "crba": (lambda: model.crba(q), [q]),
        "aba": (lambda: model.aba(q, qd, qdd), [q, qd, qdd]),
        "within_limits": (lambda: model.within_limits(q), [q]),
        "ik": (lambda: model.ik(pose, q, max_attempts=1), [pose, q]),
        "fk_batch": (lambda: model.fk_batch(Q), [Q]),
        "link_transforms_batch": (lambda: model.link_transforms_batch(Q), [Q]),
        "jacobian_batch": (lambda: model.jacobian_batch(Q), [Q]),
        "rnea_batch": (lambda: model.rnea_batch(Q, Q, Q), [Q]),
        "gravity_torque_batch": (lambda: model.gravity_torque_batch(Q), [Q]),
        "crba_batch": (lambda: model.crba_batch(Q), [Q]),
        "aba_batch": (lambda: model.aba_batch(Q, Q, Q), [Q]),
        "ik_batch": (lambda: model.ik_batch(poses, Q, max_attempts=1), [poses, Q]),
        "link": (lambda: model.link(0), []),
        "plan_joint_motion": (lambda: rp.plan_joint_motion(model, Q[:2], rate=50), [Q]),
        "Planner": (lambda: rp.Planner(model, q), [q]),
        "Planner.sample": (lambda: planned(model, q, 0.5 * q, pose), [q, pose]),
    }
    for name in ("home", "position_min", "position_max", "velocity_limit", "acceleration_limit", "jerk_limit",
                 "torque_limit", "base", "tool", "gravity"):
        calls[name] = (lambda name=name: getattr(model, name), [])
    if isinstance(model, rp.Puma560Model):
        calls.update({
            "ik_all": (lambda: model.ik_all(pose), [pose]),
            "ik_closest": (lambda: model.ik_closest(pose, q), [pose, q]),
            "ik_closest_batch": (lambda: model.ik_closest_batch(poses, Q), [poses, Q]),
            "branch_of": (lambda: model.branch_of(q), [q]),
        })
    return calls


def arrays_in(value):
    """The numpy arrays of a result (itself, or in a tuple, list or dict)."""
    if isinstance(value, np.ndarray):
        return [value]
    if isinstance(value, (tuple, list)):
        return [a for v in value for a in arrays_in(v)]
    if isinstance(value, dict):
        return [a for v in value.values() for a in arrays_in(v)]
    return []


MODELS = [rp.Puma560Model, lambda: rp.WAMModel(7)]


@pytest.mark.parametrize("make", MODELS, ids=["puma560", "wam7"])
def test_arrays_passed_in_keep_their_reference_count_over_many_calls(make):
    model = make()
    for name, (call, inputs) in model_calls(model).items():
        call()  # anything created once (caches) before counting
        before = [sys.getrefcount(a) for a in inputs]
        for _ in range(200):
            call()
        after = [sys.getrefcount(a) for a in inputs]
        assert after == before, f"{name}: reference counts of the inputs {before} -> {after}"


@pytest.mark.parametrize("make", MODELS, ids=["puma560", "wam7"])
def test_returned_arrays_hold_no_extra_references_and_own_their_data(make):
    model = make()
    for name, (call, _) in model_calls(model).items():
        result = call()
        arrays = arrays_in(result)
        for a in arrays:
            # Held by `result` (or its tuple, list or dict), `arrays`, `a` and getrefcount's argument.
            assert sys.getrefcount(a) == 4, f"{name}: {sys.getrefcount(a) - 4} references too many"
            assert a.flags.owndata and a.base is None, f"{name}: returns a view of memory it does not own"
            assert a.dtype in (np.float64, np.bool_), name
        del result, arrays


def test_results_are_not_freed_or_leaked_over_many_calls():
    # A leaked array per call would show here (numpy reports its allocations to tracemalloc).
    import tracemalloc
    model = rp.WAMModel(7)
    calls = model_calls(model)
    tracemalloc.start()
    try:
        for call, _ in calls.values():
            call()
        gc.collect()
        before = tracemalloc.get_traced_memory()[0]
        for _ in range(300):
            for call, _ in calls.values():
                call()
        gc.collect()
        grown = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert grown < 64 * 1024, f"{grown} bytes more after {300 * len(calls)} calls"


@pytest.mark.parametrize("make", MODELS, ids=["puma560", "wam7"])
def test_returned_arrays_stay_valid_when_the_source_changes_or_goes(make):
    model = make()
    q = model.home + 0.1
    results = {name: call() for name, (call, _) in model_calls(model).items()}
    copies = {name: [a.copy() for a in arrays_in(r)] for name, r in results.items()}
    # The model's own vectors are copies: writing into them changes neither the model nor others.
    home = model.home
    home[:] = 123.0
    assert not np.any(model.home == 123.0)
    # Later calls do not write into earlier results (each result has its own memory).
    T = model.fk(q)
    T_copy = T.copy()
    model.fk(q + 0.2)
    model.fk_batch(np.tile(q, (3, 1)))
    np.testing.assert_array_equal(T, T_copy)
    # Nor do changes of the inputs.
    q_in = q.copy()
    J = model.jacobian(q_in)
    q_in[:] = 0
    np.testing.assert_array_equal(J, model.jacobian(q))
    # The model gone, every result is as it was.
    del model
    gc.collect()
    for name, r in results.items():
        for a, c in zip(arrays_in(r), copies[name]):
            np.testing.assert_array_equal(a, c, err_msg=name)


def test_arm_arrays_and_generator_inputs_keep_their_counts_and_stay_valid():
    out = python("""
        import gc, sys, numpy as np, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        arm = rp.Puma560("arm")
        rp.pause()
        tragen = rp.TrajectoryGenerator()
        arm.set_trajectory_generator(tragen)
        pose, wrench = arm.end_effector_transform(), np.zeros(6)
        target = arm.joint_position()
        inputs = [pose, wrench, target]
        before = [sys.getrefcount(a) for a in inputs]
        for _ in range(200):
            arm.apply_external_wrench(wrench)
            tragen.move_radians(target)
            arm.joint_position(); arm.joint_velocity(); arm.control_output(); arm.end_effector_transform()
        after = [sys.getrefcount(a) for a in inputs]
        print("counts", before == after)
        results = [arm.joint_position(), arm.joint_velocity(), arm.control_output(), arm.end_effector_transform()]
        print("own", all(a.flags.owndata and a.base is None and sys.getrefcount(a) == 3 for a in results))
        copies = [a.copy() for a in results]
        rp.step(50)
        arm.close()
        del arm
        gc.collect()
        print("valid", all(np.array_equal(a, c) for a, c in zip(results, copies)))
    """)
    assert out.split() == ["counts", "True", "own", "True", "valid", "True"], out


def test_large_results_reuse_freed_buffers_never_while_alive_and_within_the_bound():
    # Results of 1 MiB or more come from buffers kept when Python frees an array (so a loop of
    # large batched calls does not have the kernel zero fresh pages each time); see ResultBuffers.hpp.
    model = rp.WAMModel(7)
    rng = np.random.default_rng(3)
    rows = 20000  # a 20000 x 6 x 7 Jacobian: 6.7 MB
    Q1, Q2 = rng.uniform(-1, 1, (rows, 7)), rng.uniform(-1, 1, (rows, 7))
    expected1 = model.jacobian_batch(Q1, out=np.empty((rows, 6, 7)))
    expected2 = model.jacobian_batch(Q2, out=np.empty((rows, 6, 7)))
    for r in (0, 777, rows - 1):  # out= itself against single calls
        np.testing.assert_array_equal(expected2[r], model.jacobian(Q2[r]))

    gc.collect()
    kept = rp._roboticplatform._kept_result_bytes()
    J1 = model.jacobian_batch(Q1)
    J2 = model.jacobian_batch(Q2)
    assert not np.shares_memory(J1, J2), "two live results share a buffer"
    np.testing.assert_array_equal(J1, expected1)
    np.testing.assert_array_equal(J2, expected2)
    assert sys.getrefcount(J1) == 2 and J1.flags.c_contiguous and J1.flags.writeable and J1.dtype == np.float64

    del J1
    freed = rp._roboticplatform._kept_result_bytes()
    assert freed >= kept + rows * 6 * 7 * 8, f"the freed result was not kept: {kept} -> {freed} bytes"
    # The next result of that size takes the freed buffer, and every value is the new call's.
    J3 = model.jacobian_batch(Q2)
    assert rp._roboticplatform._kept_result_bytes() == freed - rows * 6 * 7 * 8, "the freed buffer was not reused"
    assert not np.shares_memory(J2, J3)
    np.testing.assert_array_equal(J3, expected2)
    # A result outlives its model.
    del model
    gc.collect()
    np.testing.assert_array_equal(J3, expected2)
    del J2, J3

    # Freed results of many sizes: at most 256 MiB stays kept.
    wam = rp.WAMModel(7)
    for k in range(12):
        big = wam.fk_batch(np.zeros((30000 + 5000 * k, 7)))  # 3.8 to 10.9 MB each ... held together:
        held = [big] + [wam.jacobian_batch(np.zeros((40000 + 1000 * k, 7))) for _ in range(2)]
        del big, held
    assert rp._roboticplatform._kept_result_bytes() <= 256 << 20
