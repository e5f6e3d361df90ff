"""Which topics are robots' maps, whose they are and where each robot started: map_merge's rules. No ROS here.

As the original (map_merge.cpp): a published topic is a robot's map if it
is a nav_msgs/OccupancyGrid, its last name is robot_map_topic, its name
holds robot_namespace anywhere (plain text, not a namespace), and it is not
the merged map's own topic. The robot is the topic's parent namespace
(/tb3_0 for /tb3_0/map), and with known_init_poses its pose in the world
frame is the four parameters <robot>/map_merge/init_pose_x, _y, _z and
_yaw, all required.
"""
import math
import numbers

MAP_TYPE = 'nav_msgs/OccupancyGrid'
INIT_POSE = ('init_pose_x', 'init_pose_y', 'init_pose_z', 'init_pose_yaw')


class InitPoseError(ValueError):
    """A robot without a usable init pose: its message says which parameter and why."""


def clean(name):
    """A graph name without doubled or trailing slashes (ros::names::clean)."""
    while '//' in name:
        name = name.replace('//', '/')
    return name[:-1] if len(name) > 1 and name.endswith('/') else name


def append(namespace, name):
    """`name` in `namespace` (ros::names::append)."""
    return clean(namespace + '/' + name)


def parent_namespace(name):
    """The namespace holding `name`: /tb3_0 for /tb3_0/map, / for /map (ros::names::parentNamespace)."""
    name = clean(name)
    if name in ('', '/'):
        return name
    head = name.rsplit('/', 1)[0]
    return head or '/'


def is_robot_map(topic, kind, robot_map_topic, robot_namespace, merged_topic):
    """True if the published `topic` of type `kind` is a robot's map (see the module)."""
    return (kind == MAP_TYPE and topic != merged_topic and robot_namespace in topic
            and append(parent_namespace(topic), robot_map_topic) == clean(topic))


def robot_maps(published, robot_map_topic, robot_namespace, merged_topic):
    """{robot: its map topic} of the (topic, type) pairs `published` (the master's published topics)."""
    return dict((parent_namespace(topic), topic) for topic, kind in published
                if is_robot_map(topic, kind, robot_map_topic, robot_namespace, merged_topic))


def init_pose(robot, get_param):
    """(x, y, yaw) of `robot` in the world frame from its four parameters (the height is read, as the
    original requires it, and not used: the maps are flat). `get_param(name)` raises KeyError for a
    parameter that is not set. InitPoseError naming the parameter if one is missing or no number."""
    values = []
    for name in INIT_POSE:
        full = append(append(robot, 'map_merge'), name)
        try:
            value = get_param(full)
        except KeyError:
            raise InitPoseError('parameter %s is not set' % full)
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise InitPoseError('parameter %s = %r: must be a finite number' % (full, value))
        values.append(float(value))
    x, y, _, yaw = values
    return x, y, yaw
