"""Shared paths and settings of the unit tests (pytest, no ROS master)."""
from pathlib import Path

import pytest
from hypothesis import settings

REPO = Path(__file__).resolve().parents[2]

# No example database: it would write .hypothesis/ into the repo's root.
# No deadline: the first call of a function can be slow on a busy CI machine.
settings.register_profile('unit', database=None, deadline=None)
settings.load_profile('unit')


@pytest.fixture
def repo():
    return REPO


@pytest.fixture
def burger_urdf():
    return REPO / 'urdf' / 'turtlebot3_burger.urdf'


@pytest.fixture
def worlds_folder():
    return REPO / 'worlds'
