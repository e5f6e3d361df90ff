"""The maps and the drive amcl's filter is tested on, as fixtures (no ROS): the maps made from the world
files (tb3_harness.drives.world_grid) and the loop around turtlebot3_world's pillars recorded on the
simulated Burger (profile realistic). test_localization.py, test_localization_accuracy.py,
test_slam.py and test_slam_input.py load this module as a plugin (pytest_plugins), not a conftest.py:
the unit tests of test/unit, run in the same session, import REPO from their own conftest module,
which a second conftest.py would replace.
Session-scoped, so that they share one recording of the loop; a module that defines a fixture of the
same name (test_planner.py's and the SLAM tests' world) uses its own.
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
