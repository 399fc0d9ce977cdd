"""recruit.__version__ and the MuJoCo versions, against CMakeLists.txt read here."""
import re

import mujoco
import recruit

from conftest import ROOT


def _cmake(pattern):
    m = re.search(pattern, (ROOT / "CMakeLists.txt").read_text(), re.MULTILINE)
    assert m, pattern
    return m.group(1)


def test_version_is_the_cmake_project_version():
    assert recruit.__version__ == _cmake(r"^project\(recruit VERSION ([0-9.]+)")


def test_mujoco_versions():
    pinned = _cmake(r"^set\(RECRUIT_MUJOCO_VERSION ([0-9.]+)\)")
    assert recruit.MUJOCO_BUILD_VERSION == pinned  # the headers compiled against
    assert recruit.MUJOCO_VERSION == mujoco.__version__ == pinned  # the library running
