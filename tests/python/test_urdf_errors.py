"""URDF errors from Python carry the C++ loader's message unchanged: the file (or "<string>" for
URDF text), the line and column of malformed XML, and the joint or link named by the loader or by
urdfdom. Compared with what rp-model (the C++ library, apps/rp-model) prints for the same file."""
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import roboticplatform as rp

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("RP_BIN_DIR", ROOT / "build" / "bin"))
DATA = ROOT / "tests" / "model" / "data"

WRITTEN = {
    "spherical.urdf": '<robot name="r"><link name="a"/><link name="b"/>\n'
                      '<joint name="ball" type="spherical"><parent link="a"/><child link="b"/></joint></robot>\n',
    "no_limits.urdf": '<robot name="r"><link name="a"/><link name="b"/>\n'
                      '<joint name="elbow" type="revolute"><parent link="a"/><child link="b"/></joint></robot>\n',
    "unclosed.urdf": '<robot name="r">\n  <link name="a">\n  <link name="b"/>\n</robot>\n',
    "bad_limit.urdf": '<robot name="r"><link name="a"/><link name="b"/>\n<joint name="knee" type="revolute">'
                      '<parent link="a"/><child link="b"/><limit lower="nan" upper="1" effort="1" velocity="1"/>'
                      '</joint></robot>\n',
}

# (file, UrdfModel keyword arguments, rp-model arguments after --robot FILE, what the message must name)
CASES = [
    ("missing.urdf", {}, ["fk"], "cannot read the file"),
    ("bad_xml.urdf", {}, ["fk"], ":3:1: not a valid URDF document: malformed XML"),
    ("unclosed.urdf", {}, ["fk"], ":4:1: not a valid URDF document: malformed XML"),
    ("floating.urdf", {}, ["fk"], "joint 'free' is floating or planar"),
    ("kinematic_loop.urdf", {}, ["fk"], "a kinematic loop"),
    ("nan_mass.urdf", {}, ["fk"], "link '"),
    ("no_inertia.urdf", {"require_dynamics": True}, ["inertia"], "link 'b' has no inertial data"),
    ("test_arm.urdf", {"tip": "gripper"}, ["--tip", "gripper", "fk"], "there is no link 'gripper'"),
    ("spherical.urdf", {}, ["fk"], "Joint [ball] has no known type [spherical]"),
    ("no_limits.urdf", {}, ["fk"], "Joint [elbow] is of type REVOLUTE but it does not specify limits"),
    ("bad_limit.urdf", {}, ["fk"], "joint 'knee': <limit> lower is not a finite number ('nan')"),
]


def path_of(name, tmp_path):
    if name in WRITTEN:
        path = tmp_path / name
        path.write_text(WRITTEN[name])
        return path
    return DATA / name


def cpp_message(path, args):
    out = subprocess.run([str(BIN / "rp-model"), "--robot", str(path), *args], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2, out.stdout + out.stderr
    last = out.stderr.strip().splitlines()[-1]
    assert last.startswith("rp-model: ")
    return last[len("rp-model: "):]


@pytest.mark.parametrize("name,kwargs,args,names", CASES, ids=[c[0] for c in CASES])
def test_a_urdf_error_in_python_is_the_cpp_loaders_message(name, kwargs, args, names, tmp_path):
    path = path_of(name, tmp_path)
    expected = cpp_message(path, args)
    assert expected.startswith(f"{path}:") and names in expected, expected
    with pytest.raises(rp.UrdfError) as error:
        rp.UrdfModel(str(path), **kwargs)
    assert str(error.value) == expected
    assert isinstance(error.value, RuntimeError)
    # The same document as text: the same message, the file called "<string>".
    if path.exists():
        with pytest.raises(rp.UrdfError) as error:
            rp.UrdfModel(path.read_text(), **kwargs)
        assert str(error.value) == expected.replace(str(path), "<string>")


def test_urdfdoms_errors_do_not_also_go_to_stderr(tmp_path):
    path = path_of("spherical.urdf", tmp_path)
    r = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import sys, roboticplatform as rp
        try:
            rp.UrdfModel(sys.argv[1])
        except rp.UrdfError as e:
            print(e)
    """), str(path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == f"{path}: not a valid URDF document: Joint [ball] has no known type [spherical]"
    assert "Joint [ball]" not in r.stderr, "reported once, in the exception"


def test_an_arm_from_a_bad_urdf_raises_the_same_error(tmp_path):
    path = path_of("spherical.urdf", tmp_path)
    r = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import sys, roboticplatform as rp
        rp.init(["-simclock", "-nogui"])
        try:
            rp.UrdfManipulator("arm", sys.argv[1])
        except rp.UrdfError as e:
            print("UrdfError:", e)
    """), str(path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "UrdfError: " + cpp_message(path, ["fk"])
