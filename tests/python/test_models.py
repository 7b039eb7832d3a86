"""The models from Python: against Orocos KDL (python3-pykdl), finite differences, the batched
forms, and bad input."""
import threading

import numpy as np
import pytest

import roboticplatform as rp
import kdl_reference as kdl

MODELS = [rp.Puma560Model, lambda: rp.WAMModel(7), lambda: rp.WAMModel(4)]


def random_q(model, rng, count=None):
    lo, hi = model.position_min, model.position_max
    shape = (model.dof,) if count is None else (count, model.dof)
    return rng.uniform(np.maximum(lo, -3), np.minimum(hi, 3), shape)


@pytest.mark.parametrize("make", MODELS)
def test_kinematics_and_inverse_dynamics_agree_with_kdl(make):
    model = make()
    reference = kdl.chain(model)
    rng = np.random.default_rng(7)
    for _ in range(20):
        q = random_q(model, rng)
        qd = rng.uniform(-1, 1, model.dof)
        qdd = rng.uniform(-1, 1, model.dof)
        np.testing.assert_allclose(model.fk(q), kdl.fk(reference, q), atol=1e-9)
        np.testing.assert_allclose(model.jacobian(q), kdl.jacobian(reference, q), atol=1e-9)
        np.testing.assert_allclose(model.rnea(q, qd, qdd), kdl.rnea(reference, model.gravity, q, qd, qdd), atol=1e-9)
        np.testing.assert_allclose(model.gravity_torque(q), kdl.rnea(reference, model.gravity, q, 0 * q, 0 * q),
                                   atol=1e-9)


@pytest.mark.parametrize("make", MODELS)
def test_jacobian_matches_finite_differences_of_fk(make):
    model = make()
    rng = np.random.default_rng(3)
    q = random_q(model, rng)
    h = 1e-6
    J = model.jacobian(q)
    T = model.fk(q)
    for i in range(model.dof):
        dq = np.zeros(model.dof)
        dq[i] = h
        Tp, Tm = model.fk(q + dq), model.fk(q - dq)
        np.testing.assert_allclose(J[:3, i], (Tp[:3, 3] - Tm[:3, 3]) / (2 * h), atol=1e-7)
        dR = (Tp[:3, :3] - Tm[:3, :3]) / (2 * h) @ T[:3, :3].T  # skew(omega)
        np.testing.assert_allclose(J[3:, i], [dR[2, 1], dR[0, 2], dR[1, 0]], atol=1e-7)


@pytest.mark.parametrize("make", MODELS)
def test_mass_matrix_and_forward_dynamics_are_consistent_with_rnea(make):
    model = make()
    rng = np.random.default_rng(5)
    q = random_q(model, rng)
    qd = rng.uniform(-1, 1, model.dof)
    tau = rng.uniform(-5, 5, model.dof)
    M = model.crba(q)
    # Column i of M is rnea with qdd = e_i minus the bias (gravity off, qd = 0).
    for i in range(model.dof):
        e = np.zeros(model.dof)
        e[i] = 1
        np.testing.assert_allclose(M[:, i], model.rnea(q, 0 * q, e, gravity=False), atol=1e-10)
    qdd = model.aba(q, qd, tau)
    np.testing.assert_allclose(model.rnea(q, qd, qdd), tau, atol=1e-9)


@pytest.mark.parametrize("make", MODELS)
def test_batched_calls_equal_single_calls(make):
    model = make()
    rng = np.random.default_rng(11)
    Q, QD, QDD = random_q(model, rng, 50), rng.uniform(-1, 1, (50, model.dof)), rng.uniform(-1, 1, (50, model.dof))
    fk, J, tau, M, acc = (model.fk_batch(Q), model.jacobian_batch(Q), model.rnea_batch(Q, QD, QDD), model.crba_batch(Q),
                          model.aba_batch(Q, QD, QDD))
    g = model.gravity_torque_batch(Q)
    links = model.link_transforms_batch(Q)
    assert links.shape == (50, model.dof, 4, 4)
    assert fk.shape == (50, 4, 4) and J.shape == (50, 6, model.dof) and M.shape == (50, model.dof, model.dof)
    for k in range(50):
        np.testing.assert_array_equal(fk[k], model.fk(Q[k]))
        np.testing.assert_array_equal(J[k], model.jacobian(Q[k]))
        np.testing.assert_array_equal(tau[k], model.rnea(Q[k], QD[k], QDD[k]))
        np.testing.assert_array_equal(M[k], model.crba(Q[k]))
        np.testing.assert_array_equal(acc[k], model.aba(Q[k], QD[k], QDD[k]))
        np.testing.assert_array_equal(g[k], model.gravity_torque(Q[k]))
        np.testing.assert_array_equal(links[k], model.link_transforms(Q[k]))


@pytest.mark.parametrize("make", MODELS)
def test_batched_calls_write_into_a_given_out_array(make):
    """numpy's out= convention: the results land in the caller's array, which is returned; the
    same values as a new array; a wrong shape, dtype, layout, a read-only array or one that shares
    memory with an input is a ValueError naming what is wrong, and the array is left as it was."""
    model = make()
    n = model.dof
    rng = np.random.default_rng(12)
    Q, QD, QDD = random_q(model, rng, 30), rng.uniform(-1, 1, (30, n)), rng.uniform(-1, 1, (30, n))
    calls = {
        "fk_batch": (lambda out: model.fk_batch(Q, out=out), (30, 4, 4)),
        "link_transforms_batch": (lambda out: model.link_transforms_batch(Q, out=out), (30, n, 4, 4)),
        "jacobian_batch": (lambda out: model.jacobian_batch(Q, "end_effector", out=out), (30, 6, n)),
        "rnea_batch": (lambda out: model.rnea_batch(Q, QD, QDD, out=out), (30, n)),
        "gravity_torque_batch": (lambda out: model.gravity_torque_batch(Q, out=out), (30, n)),
        "crba_batch": (lambda out: model.crba_batch(Q, out=out), (30, n, n)),
        "aba_batch": (lambda out: model.aba_batch(Q, QD, QDD, out=out), (30, n)),
    }
    for name, (call, shape) in calls.items():
        expected = call(None)
        assert expected.shape == shape, name
        out = np.full(shape, np.nan)
        returned = call(out)
        assert returned is out, name
        np.testing.assert_array_equal(out, expected, err_msg=name)
        wrong = {
            "shape": np.zeros(shape[:-1] + (shape[-1] + 1,)),
            "dtype float64": np.zeros(shape, dtype=np.float32),
            "C-contiguous": np.zeros(shape[::-1]).T,
            "read-only": np.zeros(shape),
            "shares memory": None,
        }
        wrong["read-only"].flags.writeable = False
        for what, bad in wrong.items():
            if bad is None:
                if name not in ("rnea_batch", "aba_batch"):
                    continue
                bad = QD  # an input as the output: its rows would be overwritten while read
            before = bad.copy()
            with pytest.raises(ValueError, match=f"out: .*{what}"):
                call(bad)
            np.testing.assert_array_equal(bad, before, err_msg=f"{name}: {what}")
        with pytest.raises(ValueError, match=r"out: expected a float64 array of shape"):
            call([[0.0]])


def test_batched_calls_in_threads_give_the_same_results():
    model = rp.Puma560Model()
    Q = random_q(model, np.random.default_rng(1), 20000)
    expected = model.rnea_batch(Q, Q, Q)
    results = [None, None]

    def work(k):
        results[k] = model.rnea_batch(Q, Q, Q)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        np.testing.assert_array_equal(r, expected)


def test_puma_closed_form_ik_reproduces_random_poses_on_every_branch():
    puma = rp.Puma560Model()
    rng = np.random.default_rng(2)
    for _ in range(20):
        q = random_q(puma, rng)
        pose = puma.fk(q)
        solutions = puma.ik_all(pose)
        assert len(solutions) == 8
        assert len({s["branch"] for s in solutions}) == 8
        for s in solutions:
            np.testing.assert_allclose(puma.fk(s["q"]), pose, atol=1e-9)
        status, closest = puma.ik_closest(pose, q)
        if status == "solved":
            np.testing.assert_allclose(puma.fk(closest), pose, atol=1e-9)
    far = np.eye(4)
    far[:3, 3] = [5, 0, 0]
    assert puma.ik_all(far) == []
    # Batched: each pose from its own current joints, as the single call.
    Q = random_q(puma, rng, 10)
    poses = puma.fk_batch(Q)
    solved, closest = puma.ik_closest_batch(poses, Q)
    for k in range(10):
        status, q = puma.ik_closest(poses[k], Q[k])
        assert solved[k] == (status == "solved")
        np.testing.assert_array_equal(closest[k], q)
    assert solved.any()


def test_numeric_ik_solves_reachable_wam_poses():
    wam = rp.WAMModel(7)
    rng = np.random.default_rng(4)
    for _ in range(5):
        pose = wam.fk(random_q(wam, rng))
        status, q = wam.ik(pose)
        assert status == "solved"
        np.testing.assert_allclose(wam.fk(q), pose, atol=1e-5)
        assert wam.within_limits(q)


def test_batched_ik_solves_each_pose_like_the_single_call():
    wam = rp.WAMModel(7)
    rng = np.random.default_rng(8)
    poses = wam.fk_batch(random_q(wam, rng, 4))
    solved, Q = wam.ik_batch(poses)
    assert solved.dtype == bool and solved.all()
    for k in range(4):
        np.testing.assert_allclose(wam.fk(Q[k]), poses[k], atol=1e-5)
        status, q = wam.ik(poses[k])
        np.testing.assert_array_equal(Q[k], q)
    with pytest.raises(ValueError, match=r"poses\[1\]: not a rigid transform"):
        wam.ik_batch(np.stack([np.eye(4), 2 * np.eye(4)]))


def test_bad_input_is_a_clear_python_exception():
    puma = rp.Puma560Model()
    with pytest.raises(ValueError, match=r"q: expected shape \(6,\), got \(5,\)"):
        puma.fk(np.zeros(5))
    with pytest.raises(ValueError, match=r"q: expected shape \(6,\), got \(2, 3\)"):
        puma.fk(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="real numbers"):
        puma.fk(np.array(["a"] * 6))
    with pytest.raises(ValueError, match="real numbers"):
        puma.fk(np.zeros(6, dtype=complex))
    with pytest.raises(ValueError, match="element 2 is not a finite number"):
        puma.rnea([0, 0, np.nan, 0, 0, 0], np.zeros(6), np.zeros(6))
    with pytest.raises(ValueError, match="qd: expected shape"):
        puma.rnea(np.zeros(6), np.zeros(7), np.zeros(6))
    with pytest.raises(ValueError, match=r"q: expected shape \(N, 6\)"):
        puma.fk_batch(np.zeros((10, 5)))
    with pytest.raises(ValueError, match="same number of rows"):
        puma.rnea_batch(np.zeros((10, 6)), np.zeros((9, 6)), np.zeros((10, 6)))
    with pytest.raises(ValueError, match="not a rigid transform"):
        puma.ik_all(2 * np.eye(4))
    with pytest.raises(IndexError, match="link 6 is not in 0..5"):
        puma.link(6)
    with pytest.raises(ValueError, match="frame must be"):
        puma.jacobian(puma.home, frame="elbow")
    with pytest.raises(ValueError, match="dof must be 4 or 7"):
        rp.WAMModel(5)
    # Integers are real numbers: converted, not refused.
    np.testing.assert_array_equal(puma.fk(np.zeros(6, dtype=int)), puma.fk(np.zeros(6)))


def test_urdf_models_from_a_file_or_text_and_their_errors(tmp_path):
    urdf = """<robot name="two">
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
    path = tmp_path / "two.urdf"
    path.write_text(urdf)
    from_file, from_text = rp.UrdfModel(str(path)), rp.UrdfModel(urdf)
    assert from_file.dof == from_text.dof == 2
    assert from_file.joint_names == ["j1", "j2"] and from_file.link_names == ["l1", "l2"]
    assert rp.Puma560Model().joint_names == [f"joint{i}" for i in range(1, 7)]
    q = np.array([0.3, -0.4])
    np.testing.assert_allclose(from_file.fk(q), from_text.fk(q), atol=1e-15)
    # Planar two-link arm: the tip of link 2's frame is at 0.2 (cos q1) ...
    np.testing.assert_allclose(from_file.link_transforms(q)[1][:2, 3], [0.2 * np.cos(0.3), 0.2 * np.sin(0.3)], atol=1e-12)
    with pytest.raises(rp.UrdfError, match="missing.urdf"):
        rp.UrdfModel(str(tmp_path / "missing.urdf"))
    with pytest.raises(rp.UrdfError, match="<string>"):
        rp.UrdfModel("<robot name='broken'><link name='a'/>")


def test_a_planned_joint_motion_is_time_optimal_within_the_limits_and_consistent():
    puma = rp.Puma560Model()
    start = puma.home
    target = start.copy()
    target[0] += 1.5  # joint 1 alone: the classic seven-phase S-curve
    plan = rp.plan_joint_motion(puma, np.vstack([start, target]), rate=1000)
    v, a, j = puma.velocity_limit[0], puma.acceleration_limit[0], puma.jerk_limit[0]
    # Published closed form (cruise reached): T = d / v + v / a + a / j.
    assert 1.5 / v > v / a + a / j, "the test distance reaches the cruise speed"
    assert plan["duration"] == pytest.approx(1.5 / v + v / a + a / j, rel=1e-9)
    t, q, qd, qdd = plan["time"], plan["q"], plan["qd"], plan["qdd"]
    np.testing.assert_allclose(q[0], start, atol=1e-12)
    np.testing.assert_allclose(q[-1], target, atol=1e-3 * 1.5)
    assert np.all(np.abs(qd[:, 0]) <= v * (1 + 1e-9)) and np.all(np.abs(qdd[:, 0]) <= a * (1 + 1e-9))
    # The velocity is the derivative of the position (central differences).
    np.testing.assert_allclose(np.gradient(q[:, 0], t)[1:-1], qd[1:-1, 0], atol=2e-3)
    # Through a via point, at rest there; half the speed fraction takes twice the time.
    via = start + 0.3
    slow = rp.plan_joint_motion(puma, np.vstack([start, via, target]), rate=500, speed_fraction=0.5)
    fast = rp.plan_joint_motion(puma, np.vstack([start, via, target]), rate=500)
    assert slow["duration"] == pytest.approx(2 * fast["duration"], rel=1e-9)
    with pytest.raises(ValueError, match="at least two rows"):
        rp.plan_joint_motion(puma, start[None, :])
    with pytest.raises(ValueError, match="speed_fraction"):
        rp.plan_joint_motion(puma, np.vstack([start, target]), speed_fraction=2)


def test_the_planner_samples_the_generators_cartesian_and_blended_motions():
    puma = rp.Puma560Model()
    start = np.array([0.2, -0.3, 0.8, 0.3, -0.7, 0.1])
    a = puma.fk(start)
    b = a.copy()
    b[:3, 3] += [0.1, -0.1, -0.05]
    planner = rp.Planner(puma, start)
    planner.move_to(b)
    s = planner.sample(500)
    tips = puma.fk_batch(s["q"])[:, :3, 3]
    along = (b[:3, 3] - a[:3, 3]) / np.linalg.norm(b[:3, 3] - a[:3, 3])
    off = (tips - a[:3, 3]) - np.outer((tips - a[:3, 3]) @ along, along)
    assert np.abs(off).max() < 1e-6, "the end-effector stays on the straight line"
    np.testing.assert_allclose(puma.fk(s["q"][-1]), b, atol=1e-6)
    assert s["time"][0] == 0 and s["duration"] == s["time"][-1]

    def via_plan(radius):
        p = rp.Planner(puma)
        p.set_joint_blend_radius(radius)
        p.move_radians(puma.home + [0.5, 0, 0, 0, 0, 0])
        p.move_radians(puma.home + [0.5, -0.5, 0, 0, 0, 0])
        return p.sample(1000)

    assert via_plan(0.1)["duration"] < via_plan(0.0)["duration"] - 0.05
    with pytest.raises(ValueError, match="outside the limits"):
        rp.Planner(puma).move_radians(puma.home + [0, 1, 0, 0, 0, 0])


def test_the_planner_synchronises_joints_in_time_by_default_and_offers_phase_and_none():
    # Issue 17: 'time' (the default) ends all joints together at the slowest joint's own minimum
    # time, each joint on its own profile; 'phase' keeps the straight line in joint space; 'none'
    # lets each joint arrive on its own time. The Puma's limits are in the same ratio on every
    # joint, so here the straight line is as short (rp-plan's and the C++ tests cover limits
    # that differ per joint).
    puma = rp.Puma560Model()
    start = puma.home.copy()
    target = start + np.array([1.0, -0.4, 0.3, 1.2, -0.8, 0.5])
    runs = {}
    for mode in (None, "time", "phase", "none"):
        p = rp.Planner(puma, start)
        if mode is not None:
            p.set_synchronization(mode)
        p.move_radians(target)
        runs[mode] = p.sample(1000)
    assert runs[None]["duration"] == runs["time"]["duration"]
    assert runs["phase"]["duration"] == pytest.approx(runs["time"]["duration"], abs=1e-9)
    assert runs["none"]["duration"] == pytest.approx(runs["time"]["duration"], abs=1e-9)

    def off_line(q):
        along = (q[:, 0] - start[0]) / (target[0] - start[0])
        return np.abs(q - start - np.outer(along, target - start)).max()

    assert off_line(runs["phase"]["q"]) < 1e-9, "phase: a straight line"
    assert off_line(runs["time"]["q"]) > 1e-3, "time: each joint on its own profile"
    # Without synchronisation joint 2 (the shortest motion) arrives long before the end.
    q = runs["none"]["q"]
    arrived = np.flatnonzero(np.abs(q[:, 1] - target[1]) < 1e-12)[0]
    assert arrived < 0.8 * len(q)
    for s in runs.values():
        np.testing.assert_allclose(s["q"][-1], target, atol=1e-12)
    with pytest.raises(ValueError, match="time, phase, none"):
        rp.Planner(puma).set_synchronization("fast")
