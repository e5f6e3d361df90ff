"""One robot's ROS interface: cmd_vel in; each of its sensors out through its IO (sensor_io.py).

A robot with a name lives in its namespace, as ROBOTIS' multi-robot set-up
does (tb3_0/cmd_vel); the tutorial's robot has no name: cmd_vel.
"""
import rospy
from geometry_msgs.msg import Twist

from ..diff_drive import sanitize_twist
from .sensor_io import IO_CLASSES


class RobotIO(object):

    def __init__(self, robot, config, publishers, throttle, on_command=None):
        """`config`: the simulation's (frames, rates); `on_command()` is called from the
        thread that received a command."""
        self.robot = robot
        self.prefix = prefix = robot.name + '/' if robot.name else ''
        self._throttle = throttle
        self._on_command = on_command
        self._command = (0.0, 0.0, 0)  # v, w, count of commands received
        self._applied = 0
        self.sensors = [IO_CLASSES[type(sensor)](sensor, prefix, publishers, config) for sensor in robot.sensors]
        self.cmd_vel = rospy.Subscriber(prefix + 'cmd_vel', Twist, self._on_cmd_vel, queue_size=10,
                                        tcp_nodelay=True)

    def _on_cmd_vel(self, twist):
        v, w, complaints = sanitize_twist((twist.linear.x, twist.linear.y, twist.linear.z),
                                          (twist.angular.x, twist.angular.y, twist.angular.z),
                                          self.robot.limits)
        for complaint in complaints:
            # Throttled per robot and kind (its first word), so that a flood of
            # one kind of bad command cannot hide another.
            if self._throttle.allow((self.prefix, complaint.split()[0])):
                rospy.logwarn('%scmd_vel: %s (at most one such warning per %g s)', self.prefix, complaint,
                              self._throttle.period)
        self._command = (v, w, self._command[2] + 1)  # one assignment; the step loop picks it up
        if self._on_command:
            self._on_command()

    def apply_command(self, now_ns):
        """Hand the robot the newest command, if one came since the last step."""
        v, w, count = self._command
        if count != self._applied:
            self.robot.command(v, w, now_ns)
            self._applied = count

    def close(self):
        self.cmd_vel.unregister()
        for io in self.sensors:
            io.close()
