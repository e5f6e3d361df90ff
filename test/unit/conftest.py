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


@pytest.fixture
def world_factory(burger_urdf):
    """make(time_step, settle, spawn_pose, obstacles): the RobotBody of a Burger in
    a World (its `world`) left to settle for `settle` s of sim time; every world
    is closed after the test."""
    from tb3_sim_nav.frames import planar
    from tb3_sim_nav.robot_model import load_model
    from tb3_sim_nav.world import World
    model = load_model(str(burger_urdf))
    worlds = []

    def make(time_step, settle, spawn_pose=(0.0, 0.0, 0.0, 0.0), obstacles=()):
        world = World(time_step, obstacles)
        worlds.append(world)
        robot = world.add_robot(model.urdf_text, planar(*spawn_pose), casters=model.casters)
        for _ in range(int(round(settle / time_step))):
            world.step()
        return robot
    yield make
    for world in worlds:
        world.close()
