"""robot_description and what robot_state_publisher gives each robot with a name.

A robot with a name (tb3_0) gets what ROBOTIS' multi_turtlebot3.launch gives
each robot: its URDF on tb3_0/robot_description and the tf tree a
robot_state_publisher with tf_prefix tb3_0 would publish from it, so that it
reads tb3_0/base_footprint -> tb3_0/base_link -> ... -> tb3_0/base_scan. The
simulator publishes that tree itself, as robot_state_publisher (1.15) does:
the fixed joints once on /tf_static (here one latched message for every
robot, as tf2's static broadcaster keeps them), the wheels with each
joint_states (sensor_io.JointStatesIO, in the step's tf message). A process
per robot cost more than the robot: Debian's robot_state_publisher asks the
master three times for its tf_prefix on every joint_states message, and
follows /clock; with ten robots that kept rosmaster at half a core and
halved the simulation's speed (doc/speed.md). Robots from a launch file, a
world file or a spawn alike. (The tutorial's robot has no name:
description.launch starts Debian's robot_state_publisher for it, as
ROBOTIS' launch files do.)
"""
import rospy
from tf2_msgs.msg import TFMessage

from . import messages


class Descriptions(object):
    """The robot_description parameters of named robots and their fixed joints on /tf_static.

    `parameters` (a dict) gets each parameter set, for the master watch to set
    again on a new master. `static_tf`: publish the fixed joints (and let
    JointStatesIO publish the wheels); false when other nodes do it.
    """

    def __init__(self, parameters, publishers, static_tf=True):
        self.parameters = parameters
        self._publishers = publishers if static_tf else None
        self._static = None  # advertised with the first robot that has a name: the tutorial's has none
        self._fixed = {}  # robot name -> its fixed joints' transforms

    def start(self, robot, stamp):
        """`stamp`: now (robot_state_publisher stamps its static transforms with the time it sends them)."""
        if not robot.name:
            return
        namespace = rospy.resolve_name(robot.name)
        name = namespace + '/robot_description'
        rospy.set_param(name, robot.model.urdf_text)
        self.parameters[name] = robot.model.urdf_text
        if self._publishers is None:
            rospy.loginfo('%s: robot_description set', namespace)
            return
        if self._static is None:
            self._static = self._publishers.advertise('tf_static', TFMessage, latch=True)
        prefix = robot.name + '/'
        fixed = []
        for joint in robot.model.joints:
            if joint.fixed:
                transform = messages.transform(prefix + joint.parent, prefix + joint.child)
                messages.fill_transform(transform, stamp, joint.pose())
                fixed.append(transform)
        self._fixed[robot.name] = fixed
        self._publish()
        rospy.loginfo('%s: robot_description set; its %d fixed joints on /tf_static, its wheels on /tf '
                      '(tf_prefix %s)', namespace, len(fixed), robot.name)

    def stop(self, name):
        if self._fixed.pop(name, None) is not None:
            self._publish()

    def _publish(self):
        self._static.publish(TFMessage(transforms=[transform for fixed in self._fixed.values()
                                                   for transform in fixed]))
