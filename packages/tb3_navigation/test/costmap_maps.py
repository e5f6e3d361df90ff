"""The maps and boxes the costmap tests draw on (no ROS): empty_map(), a grid of RESOLUTION (0.05 m)
filled with one occupancy value, and box(), a box obstacle standing on the floor as a world file has it.
"""
import numpy as np

from tb3_common.grid import Grid
from tb3_sim_nav.world_file import Obstacle

RESOLUTION = 0.05


def empty_map(width=80, height=80, origin=(-2.0, -2.0, 0.0), value=0):
    grid = Grid(RESOLUTION, width, height, origin)
    return grid, np.full(grid.shape, value, dtype=np.int8)


def box(x, y, size_x, size_y, yaw=0.0):
    return Obstacle('box', (size_x, size_y, 0.4), (x, y, 0.2), yaw, None)
