"""map_merge's parameters by hrnr/m-explore's names and defaults (noetic), each checked. No ROS here.

ROBOTIS' multi_map_merge.launch sets robot_map_topic map, robot_namespace
tb3, merged_map_topic map, world_frame map, known_init_poses true,
merging_rate 0.5, discovery_rate 0.05, estimation_rate 0.1 and
estimation_confidence 1.0.
"""
import dataclasses

from tb3_common.params import Checked, fail, frame_id, non_negative, parameter, positive


def topic_name(value):
    """A topic's name: not empty, no spaces."""
    if not value or any(character.isspace() for character in value):
        return 'must be a topic name (not empty, no spaces)'
    return None


@dataclasses.dataclass(frozen=True)
class MapMergeConfig(Checked):
    """map_merge's parameters (the node's private ones; each robot's init pose is in its own namespace)."""
    robot_map_topic: str = parameter('map', "the last part of every robot's map topic (<robot>/map)", topic_name)
    robot_map_updates_topic: str = parameter('map_updates', "the last part of every robot's map updates topic "
                                             '(map_msgs/OccupancyGridUpdate)', topic_name)
    robot_namespace: str = parameter('', "only map topics whose name holds this text anywhere are robots' maps")
    merged_map_topic: str = parameter('map', 'where the merged map is published, latched', topic_name)
    world_frame: str = parameter('world', "the merged map's frame, the one the init poses are given in", frame_id)
    known_init_poses: bool = parameter(True, "robots' poses in world_frame come from <robot>/map_merge/init_pose_*;"
                                       ' false: estimated in the original (not here: see the node)')
    merging_rate: float = parameter(4.0, 'merges (and publications of the merged map) a second', positive, 'Hz')
    discovery_rate: float = parameter(0.05, 'looks for new robots a second', positive, 'Hz')
    estimation_rate: float = parameter(0.5, "the original's pose estimations a second (unknown poses only): "
                                       'no effect here', positive, 'Hz')
    estimation_confidence: float = parameter(1.0, "the original's confidence for estimated poses: no effect here",
                                             non_negative)
    tf_placement: bool = parameter(True, "ours: a robot's map goes where tf puts its frame in world_frame, when tf "
                                   'has that transform (as rviz draws it); false: by the init pose alone, as the '
                                   'original')

    def check_together(self):
        if '/' in self.robot_map_topic.strip('/'):
            fail('robot_map_topic', self.robot_map_topic, "must be one name, the last part of a topic's name")
