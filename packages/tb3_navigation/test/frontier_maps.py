"""The maps the frontier and exploration tests draw (no ROS): picture() reads a map drawn in text, one
character a cell, and room() makes a walled room of free cells whose east part may be unknown, both on
RESOLUTION's grid.
"""
import numpy as np

from tb3_common.grid import Grid

RESOLUTION = 0.05
SYMBOLS = {'.': 0, '#': 100, '?': -1, 'R': 0}


def picture(text):
    """(Grid at the origin, int8 values, robot pose) of a map drawn in text, one character a
    cell, the top line the highest y: '.' free, '#' occupied, '?' unknown, 'R' the robot (free)."""
    lines = [line.strip() for line in text.strip().splitlines()][::-1]
    values = np.array([[SYMBOLS[c] for c in line] for line in lines], dtype=np.int8)
    grid = Grid(RESOLUTION, values.shape[1], values.shape[0])
    robot = [(ix, iy) for iy, line in enumerate(lines) for ix, c in enumerate(line) if c == 'R']
    pose = tuple(grid.centres(np.array(robot[0]))) + (0.0,) if robot else None
    return grid, values, pose


def room(width, height, unknown_from=None):
    """A walled room of free cells (`width` x `height` m inside); the columns from x =
    `unknown_from` on are unknown (its east part not yet seen)."""
    columns, rows = int(round(width / RESOLUTION)) + 2, int(round(height / RESOLUTION)) + 2
    values = np.zeros((rows, columns), dtype=np.int8)
    values[[0, -1], :] = 100
    values[:, [0, -1]] = 100
    grid = Grid(RESOLUTION, columns, rows, (-RESOLUTION, -RESOLUTION, 0.0))
    if unknown_from is not None:
        values[:, int(round(unknown_from / RESOLUTION)) + 1:] = -1
    return grid, values
