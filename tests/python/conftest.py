"""pytest setup: the installed `recruit` package, or a build tree's (RECRUIT_PYTHONPATH=
build-DIR/python, made by cmake -DRECRUIT_BUILD_PYTHON=ON)."""
import os
import pathlib
import sys

import pytest

_extra = os.environ.get("RECRUIT_PYTHONPATH")
if _extra:
    sys.path.insert(0, _extra)

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def root():
    return ROOT
