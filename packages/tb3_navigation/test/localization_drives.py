"""The maps and the drive amcl's filter is tested on, as fixtures (no ROS): the maps made from the world
files (tb3_harness.drives.world_grid) and the loop around turtlebot3_world's pillars recorded on the
simulated Burger (profile realistic). test_localization.py and test_localization_accuracy.py load this
module as a plugin (pytest_plugins), not a conftest.py: the unit tests of test/unit, run in the same
session, import REPO from their own conftest module, which a second conftest.py would replace.
Session-scoped, so the two share one recording, as when they were one module; a module that defines a
fixture of the same name (test_planner.py's world, test_slam.py's world and loop) uses its own.
"""
import pytest

from tb3_harness.drives import WORLD_LOOP, WORLD_LOOP_START, record_drive, world_grid


@pytest.fixture(scope='session')
def world():
    return world_grid('turtlebot3_world')


@pytest.fixture(scope='session')
def loop():
    return record_drive('turtlebot3_world', WORLD_LOOP_START, WORLD_LOOP)


@pytest.fixture(scope='session')
def house():
    return world_grid('turtlebot3_house')
