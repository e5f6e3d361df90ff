"""robot_description and a robot_state_publisher for each robot with a name.

A robot with a name (tb3_0) gets what ROBOTIS' multi_turtlebot3.launch gives
each robot: its URDF on tb3_0/robot_description and Debian's
robot_state_publisher in its namespace with tf_prefix tb3_0, so its tf tree
reads tb3_0/base_footprint -> tb3_0/base_link -> ... -> tb3_0/base_scan.
Robots from a launch file, a world file or a spawn alike. (The tutorial's
robot has no name: description.launch does that for it.)
"""
import ctypes
import signal
import subprocess

import roslib.packages
import rospy

PR_SET_PDEATHSIG = 1
STOP_TIMEOUT = 5.0  # wall s for a robot_state_publisher to end after SIGINT


def _die_with_parent():
    # Runs in the child between fork and exec: should the simulator be killed
    # outright, the kernel stops its robot_state_publishers too.
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)


class Descriptions(object):
    """The robot_description parameters and robot_state_publishers of named robots.

    `parameters` (a dict) gets each parameter set, for the master watch to set
    again on a new master. Start and stop from the step loop's thread: a child
    dies with the thread that started it.
    """

    def __init__(self, parameters, robot_state_publisher=True):
        self.parameters = parameters
        self._run = robot_state_publisher
        self._children = {}  # robot name -> Popen

    def start(self, robot):
        if not robot.name:
            return
        namespace = rospy.resolve_name(robot.name)
        name = namespace + '/robot_description'
        rospy.set_param(name, robot.model.urdf_text)
        self.parameters[name] = robot.model.urdf_text
        if not self._run:
            return
        executable = roslib.packages.find_node('robot_state_publisher', 'robot_state_publisher')
        if not executable:
            raise RuntimeError('robot_state_publisher not found: install ros-robot-state-publisher')
        self._children[robot.name] = subprocess.Popen(
            [executable[0], '__name:=robot_state_publisher', '__ns:=' + namespace,
             '_tf_prefix:=' + robot.name, '_publish_frequency:=50.0'],
            stdin=subprocess.DEVNULL, preexec_fn=_die_with_parent)
        rospy.loginfo('%s: robot_description set, robot_state_publisher started (pid %d, tf_prefix %s)',
                      namespace, self._children[robot.name].pid, robot.name)

    def stop(self, name):
        child = self._children.pop(name, None)
        if child is None:
            return
        child.send_signal(signal.SIGINT)
        try:
            child.wait(STOP_TIMEOUT)
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()

    def stop_all(self):
        for name in list(self._children):
            self.stop(name)
