"""The platform from Python, each case in its own interpreter (rp.init() once per process): the
paper's examples in Python against the C++ ones, the simulated clock stepped from Python,
lifetimes, and errors as Python exceptions."""
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("RP_BIN_DIR", ROOT / "build" / "bin"))


def run(args, timeout=120, cwd=None):
    return subprocess.run(args, capture_output=True, text=True, timeout=timeout, cwd=cwd)


def python(script, *args, cwd=None):
    return run([sys.executable, "-c", textwrap.dedent(script), *args], cwd=cwd)


def numbers(text):
    return np.array([float(v) for v in re.findall(r"-?\d+\.?\d*(?:e-?\d+)?", text)])


def test_generic_manipulator_prints_what_the_cpp_program_prints():
    args = ["-config", str(ROOT / "examples" / "rp.cfg"), "-nogui"]
    py = run([sys.executable, str(ROOT / "examples" / "python" / "generic_manipulator.py"), *args])
    cpp = run([str(BIN / "generic_manipulator"), *args])
    assert py.returncode == 0, py.stderr
    assert cpp.returncode == 0, cpp.stderr
    assert py.stdout.splitlines()[0] == cpp.stdout.splitlines()[0] == "Current End-Effector Coordinate Frame: "
    np.testing.assert_allclose(numbers(py.stdout), numbers(cpp.stdout), atol=1e-6)
    assert len(numbers(py.stdout)) == 16


def test_pick_and_place_ends_where_the_cpp_program_ends():
    args = ["-nogui", "-simclock"]
    py = run([sys.executable, str(ROOT / "examples" / "python" / "pick_and_place.py"), *args])
    cpp = run([str(BIN / "pick_and_place"), *args])
    assert py.returncode == 0, py.stderr
    assert cpp.returncode == 0, cpp.stderr
    assert py.stdout.startswith("pick_and_place: done, end-effector at ")
    # The C++ program prints the end-effector's position, then the work piece's.
    end_py, end_cpp = numbers(py.stdout)[-3:], numbers(cpp.stdout)[:3]
    np.testing.assert_allclose(end_py, [0.6, 0.2, 0.3], atol=2e-3)
    np.testing.assert_allclose(end_py, end_cpp, atol=2e-3)


STEPPED = """
import numpy as np, roboticplatform as rp
rp.init(["-simclock", "-nogui"])
puma = rp.Puma560("arm")
rp.pause()
rp.step(1)  # a cycle already under way when the clock paused ends first
tragen = rp.TrajectoryGenerator()
puma.set_trajectory_generator(tragen)
del tragen  # the arm keeps its generator alive
c0 = puma.cycle_count
rp.step(10)
assert puma.cycle_count - c0 == 10, puma.cycle_count - c0
print(repr(puma.joint_position().tolist()))
"""


def test_the_simulated_clock_steps_exactly_from_python_and_runs_are_reproducible():
    first, second = python(STEPPED), python(STEPPED)
    assert first.returncode == 0, first.stderr
    assert second.returncode == 0, second.stderr
    assert first.stdout == second.stdout


def test_a_motion_from_python_reaches_its_target_and_the_generator_outlives_its_name():
    r = python("""
        import numpy as np, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        puma = rp.Puma560()
        tragen = rp.TrajectoryGenerator()
        puma.set_trajectory_generator(tragen)
        tragen.move([0, 45, -90, 0, 0, 0])
        del tragen
        import gc; gc.collect()
        for _ in range(200):
            rp.step(100)
            if np.abs(np.degrees(puma.joint_position()) - [0, 45, -90, 0, 0, 0]).max() < 0.01: break
        print(np.degrees(puma.joint_position()).round(2).tolist(), puma.error_code)
        puma.set_parameter("kp", puma.parameter("kp"))
        print("desired", np.degrees(puma.desired_joint_position()).tolist())
        try:
            puma.set_parameter("kp", [1e9] * 6)
        except ValueError as e:
            print("refused:", e)
        puma.close()
    """)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    np.testing.assert_allclose(numbers(lines[0])[:6], [0, 45, -90, 0, 0, 0], atol=0.01)
    assert lines[0].endswith(" 0")
    # The setpoint is the move's end exactly (the arm within the PID's dead band of it).
    assert lines[1].startswith("desired")
    np.testing.assert_allclose(numbers(lines[1]), [0, 45, -90, 0, 0, 0], atol=1e-9)
    assert "refused:" in lines[2] and "outside" in lines[2]


def test_bad_switches_and_configurations_are_python_exceptions(tmp_path):
    r = python("""
        import roboticplatform as rp
        try:
            rp.init(["-bogus"])
        except ValueError as e:
            print("ValueError:", e)
    """)
    assert r.returncode == 0, r.stderr
    assert "ValueError: unknown platform switch '-bogus'" in r.stdout
    cfg = tmp_path / "rp.cfg"
    cfg.write_text("[leader]\nclass Puma560\nposition 1 2\n")
    r = python("""
        import sys, roboticplatform as rp
        try:
            rp.init(["-config", sys.argv[1], "-nogui"])
        except rp.ConfigError as e:
            print("ConfigError:", e)
    """, str(cfg))
    assert r.returncode == 0, r.stderr
    assert f"ConfigError: {cfg}:3" in r.stdout, r.stdout
    r = python("""
        import sys, roboticplatform as rp
        rp.init(["-nogui", "-simclock"])
        try:
            rp.ObjectManager().create_derived_object("nobody")
        except rp.ObjectError as e:
            print("ObjectError:", e)
    """)
    assert r.returncode == 0, r.stderr
    assert "ObjectError:" in r.stdout and "nobody" in r.stdout


def test_step_without_the_simulated_clock_says_so():
    r = python("""
        import roboticplatform as rp
        rp.init(["-nogui"])
        try:
            rp.step(1)
        except RuntimeError as e:
            print("RuntimeError:", e)
    """)
    assert r.returncode == 0, r.stderr
    assert "RuntimeError: the platform runs on the real clock" in r.stdout


def test_logging_to_csv_from_python_keeps_every_cycle(tmp_path):
    log = tmp_path / "run.csv"
    r = python("""
        import sys, roboticplatform as rp
        rp.init(["-simclock", "-nogui", "-log", sys.argv[1]])
        puma = rp.Puma560("arm")
        rp.pause()
        rp.step(200)
        puma.close()
        print("closed")
    """, str(log))
    assert r.returncode == 0, r.stderr
    assert "closed" in r.stdout
    lines = log.read_text().splitlines()
    header = lines[0].split(",")
    assert any(h.startswith("arm.q") for h in header), header[:8]
    assert len(lines) - 1 >= 200, "a row per cycle stepped, flushed when the arm closed"


def test_the_scene_viewer_of_a_python_program_serves_its_page_and_ctrl_c_ends_it():
    import signal
    import urllib.request
    script = textwrap.dedent("""
        import time, roboticplatform as rp
        rp.init(["-gui-port", "0"])
        puma = rp.Puma560("arm")
        while not rp.is_shutdown_requested():
            time.sleep(0.05)
    """)
    child = subprocess.Popen([sys.executable, "-c", script], stderr=subprocess.PIPE, text=True)
    try:
        url = None
        for _ in range(50):
            line = child.stderr.readline()
            m = re.search(r"Scene Viewer at (http://127\.0\.0\.1:\d+/\S*)", line)
            if m:
                url = m.group(1)
                break
        assert url, "no Scene Viewer address printed"
        page = urllib.request.urlopen(url, timeout=30).read().decode()
        assert "<html" in page.lower()
        child.send_signal(signal.SIGINT)
        assert child.wait(timeout=30) == 128 + signal.SIGINT, "Ctrl-C: a safe shutdown, status 130"
    finally:
        if child.poll() is None:
            child.kill()
