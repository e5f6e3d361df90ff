"""nav_msgs/OccupancyGrid to and from a core's (Grid, values): the only place that knows the message."""
import numpy as np
from nav_msgs.msg import MapMetaData, OccupancyGrid

from ..grid import Grid
from ..pose2d import quaternion_of_yaw, yaw_of_quaternion


def metadata(grid, stamp=None):
    info = MapMetaData(resolution=grid.resolution, width=grid.width, height=grid.height)
    if stamp is not None:
        info.map_load_time = stamp
    info.origin.position.x, info.origin.position.y = grid.origin[0], grid.origin[1]
    (info.origin.orientation.x, info.origin.orientation.y, info.origin.orientation.z,
     info.origin.orientation.w) = quaternion_of_yaw(grid.origin[2])
    return info


def to_message(grid, values, frame, stamp):
    """An OccupancyGrid of `values` (int8 [iy, ix]; or 0..255 costs already translated)."""
    message = OccupancyGrid()
    message.header.frame_id, message.header.stamp = frame, stamp
    message.info = metadata(grid, stamp)
    message.data = np.ascontiguousarray(values, dtype=np.int8).ravel().tolist()
    return message


def from_message(message):
    """(Grid, int8 values [iy, ix]) of an OccupancyGrid; ValueError if its data does not fit its size."""
    info = message.info
    origin = info.origin
    grid = Grid(info.resolution, info.width, info.height,
                (origin.position.x, origin.position.y,
                 yaw_of_quaternion(origin.orientation.x, origin.orientation.y, origin.orientation.z,
                                   origin.orientation.w)))
    data = message.data
    values = np.frombuffer(data, dtype=np.int8) if isinstance(data, bytes) else np.asarray(data, dtype=np.int8)
    if values.size != grid.width * grid.height:
        raise ValueError('map of %d x %d cells carries %d values' % (grid.width, grid.height, values.size))
    return grid, values.reshape(grid.shape)
