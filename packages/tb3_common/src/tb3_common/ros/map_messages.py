"""nav_msgs/OccupancyGrid and MapMetaData from a Grid and its values, and back. Messages only (and rospy's
numpy_msg for the subscribers' class).

OccupancyGrid's data is row-major from cell (0, 0), the lowest y: the same
order as the values' [iy, ix] array, so a flat copy is the whole conversion.
"""
import numpy as np
from geometry_msgs.msg import Point, Pose, Quaternion
from nav_msgs.msg import MapMetaData, OccupancyGrid
from rospy.numpy_msg import numpy_msg

from ..grid import Grid
from ..pose2d import quaternion_of_yaw, yaw_of_quaternion

#: The class a map's subscriber reads OccupancyGrid as: its data a numpy array made from the message's
#: bytes, where genpy makes a tuple of python ints, one per cell, that grid_of_message then copies again:
#: what the SLAM's map cost explore and move_base each time it came (doc/speed.md).
MapMessage = numpy_msg(OccupancyGrid)


def map_metadata(grid, load_time, orientation=None):
    """MapMetaData of `grid`; `orientation` (x, y, z, w) defaults to the grid's yaw's."""
    x, y, z, w = quaternion_of_yaw(grid.origin[2]) if orientation is None else orientation
    return MapMetaData(map_load_time=load_time, resolution=grid.resolution, width=grid.width, height=grid.height,
                       origin=Pose(Point(grid.origin[0], grid.origin[1], 0.0), Quaternion(x, y, z, w)))


def occupancy_grid(grid, values, frame_id, stamp, load_time=None, orientation=None):
    """The OccupancyGrid of int8 `values` [iy, ix] on `grid`, stamped `stamp` in `frame_id`."""
    message = OccupancyGrid()
    message.header.frame_id = frame_id
    message.header.stamp = stamp
    message.info = map_metadata(grid, stamp if load_time is None else load_time, orientation)
    # genpy packs int8[] from a sequence of python ints: a list is the fastest it takes.
    message.data = np.asarray(values, dtype=np.int8).ravel().tolist()
    return message


def grid_of_message(message):
    """(Grid, int8 values [iy, ix], origin quaternion (x, y, z, w)) of an OccupancyGrid."""
    info = message.info
    q = info.origin.orientation
    orientation = (q.x, q.y, q.z, q.w)
    yaw = yaw_of_quaternion(*orientation) if any(orientation) else 0.0
    grid = Grid(info.resolution, info.width, info.height,
                (info.origin.position.x, info.origin.position.y, yaw))
    data = message.data
    values = (np.frombuffer(data, dtype=np.int8) if isinstance(data, bytes)
              else np.asarray(data, dtype=np.int8)).reshape(info.height, info.width)
    return grid, values, orientation
