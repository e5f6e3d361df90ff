"""The turtlebot3_drive node: ROBOTIS' wandering (turtlebot3_gazebo.drive) over scan and odom.

    roslaunch turtlebot3_gazebo turtlebot3_world.launch
    roslaunch turtlebot3_gazebo turtlebot3_simulation.launch     (in a second terminal)

In: `scan` (sensor_msgs/LaserScan), `odom` (nav_msgs/Odometry). Out:
geometry_msgs/Twist on the topic `cmd_vel_topic_name` names (a parameter
of the node's namespace, as ROBOTIS reads it; turtlebot3_simulation.launch
sets it to its `cmd_vel` argument). The loop runs ROBOTIS' 125 times a
second of ROS time (under the simulator's /clock, once a physics step, 100
Hz), one step of the state machine each; the robot is sent a stop when the
node ends, as ROBOTIS' destructor does.
"""
import dataclasses
import threading
import time

import rospy
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from tb3_common.ros import lifecycle, params

from .drive import STATE_NAMES, Drive, DriveConfig

NODE = 'turtlebot3_drive'
LOOP_RATE = 125.0   # Hz, ROBOTIS' ros::Rate
SEND_WAIT = 0.1     # wall s for rospy's writer thread to send the final stop
WARN_EVERY = 10.0   # s between repeats of one warning


def from_namespace(config_class):
    """The fields of `config_class` set in the node's namespace (ROBOTIS' nodes read theirs there),
    unless set privately too, as overrides for params.read_or_exit."""
    return dict((field.name, rospy.get_param(field.name)) for field in dataclasses.fields(config_class)
                if rospy.has_param(field.name) and not rospy.has_param('~' + field.name))


def pace(life, seconds):
    """Waits `seconds` of ROS time, as ros::Rate does: sim time under /clock, else wall time."""
    return life.sleep(seconds) if rospy.rostime.is_wallclock() else life.sleep_sim(seconds)


class DriveNode(object):

    def __init__(self, life):
        self.config = params.read_or_exit(NODE, DriveConfig, overrides=from_namespace(DriveConfig))
        self.drive = Drive()
        self._lock = threading.Lock()   # the state machine, between rospy's callbacks and the loop
        self.publisher = rospy.Publisher(self.config.cmd_vel_topic_name, Twist, queue_size=10)
        rospy.Subscriber('scan', LaserScan, life.callback(self._on_scan), queue_size=10)
        rospy.Subscriber('odom', Odometry, life.callback(self._on_odom), queue_size=10)
        rospy.loginfo('%s: TurtleBot3 Simulation Node Init: speeds on %s', NODE,
                      rospy.resolve_name(self.config.cmd_vel_topic_name))

    def _on_scan(self, message):
        with self._lock:
            self.drive.on_scan(message.ranges, message.angle_min, message.angle_increment, message.range_max)
            missing = list(self.drive.missing)
        if missing:
            rospy.logwarn_throttle(WARN_EVERY, '%s: the scan has no beam at %s degrees: those readings stay as '
                                   'they were' % (NODE, ', '.join('%g' % angle for angle in missing)))

    def _on_odom(self, message):
        orientation = message.pose.pose.orientation
        with self._lock:
            good = self.drive.on_odom(orientation.x, orientation.y, orientation.z, orientation.w)
        if not good:
            rospy.logwarn_throttle(WARN_EVERY, '%s: ignoring odometry with a non-finite orientation' % NODE)

    def send(self, linear, angular):
        twist = Twist()
        twist.linear.x, twist.angular.z = linear, angular
        self.publisher.publish(twist)

    def run(self, life):
        state = None
        while not life.stopping:
            with self._lock:
                command = self.drive.step()
                if self.drive.state != state:
                    state = self.drive.state
                    rospy.logdebug('%s: %s', NODE, STATE_NAMES[state])
            if command is not None:
                self.send(*command)
            pace(life, 1.0 / LOOP_RATE)
        try:
            self.send(0.0, 0.0)
            time.sleep(SEND_WAIT)
        except rospy.ROSException:   # rospy already shut down (rosnode kill): its topics are closed
            pass
        life.finish()


def main():
    life = lifecycle.init_node(NODE)
    DriveNode(life).run(life)
