"""pytest settings of tests/python: temporary files never stay behind in /tmp.

CTest (tests/CMakeLists.txt) gives --basetemp inside the build tree. Run by hand without it, the
tests' tmp_path folders go to a private folder in the system's temporary folder that is removed
when pytest ends (pytest's default, /tmp/pytest-of-$USER, would keep the last three runs)."""
import shutil
import tempfile

import pytest

_own_basetemp = None


@pytest.hookimpl(tryfirst=True)
def pytest_configure(config):
    global _own_basetemp
    if config.option.basetemp is None:
        _own_basetemp = tempfile.mkdtemp(prefix="rp-pytest-")
        config.option.basetemp = _own_basetemp


def pytest_unconfigure(config):
    if _own_basetemp is not None:
        shutil.rmtree(_own_basetemp, ignore_errors=True)
