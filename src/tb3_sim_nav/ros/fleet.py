"""The robots' ROS side: a RobotIO per robot, their descriptions, what lockstep
follows of them, and publishing what their sensors have due.
"""
import threading

import rospy

from ..frames import planar, yaw_of
from ..sensors import read_all
from ..simulation import ModelStateError
from ..world_file import ROBOT_NAME
from . import messages
from .robot_io import RobotIO


class Fleet(object):

    def __init__(self, sim, publishers, throttle, descriptions, lockstep=None, world_links=None):
        self.sim = sim
        self.publishers = publishers
        self._throttle = throttle
        self.descriptions = descriptions
        self.lockstep = lockstep
        self.world_links = world_links
        self.robots = {}  # name -> RobotIO
        for robot in sim.robots.values():
            self.add(robot)

    def _command_received(self):
        self.lockstep.receive_threads.add(threading.get_native_id())

    def add(self, robot):
        io = self.robots[robot.name] = RobotIO(robot, self.sim.config, self.publishers, self._throttle,
                                               self._command_received if self.lockstep else None)
        for sensor in io.sensors:
            if self.world_links and sensor.odom_frame:
                self.world_links.parents.add(sensor.odom_frame)
            for publisher in sensor.lockstep_readers if self.lockstep else ():
                self.lockstep.follow_readers(publisher)
        if self.lockstep:
            self.lockstep.follow(io.cmd_vel)
        self.descriptions.start(robot, messages.stamp_of(self.sim.now_ns))

    def spawn(self, name, model, pose, model_name):
        """A robot spawned while running (in the step loop): it gets what a launched one has."""
        if not ROBOT_NAME.match(name):
            raise ModelStateError('robot_namespace %r must be a ROS name: a letter, then letters, digits or _' % name)
        (x, y, z), orientation = pose
        try:
            robot = self.sim.add_robot(name, model, planar(x, y, z, yaw_of(orientation)), model_name)
        except ValueError as error:
            raise ModelStateError(str(error))
        self.add(robot)
        rospy.loginfo('spawned robot %s (model %s) at (%.2f, %.2f) yaw %.2f', name, model_name, x, y,
                      yaw_of(orientation))

    def forget(self, robot):
        """A deleted robot's interface closed (in the step loop)."""
        io = self.robots.pop(robot.name)
        if self.lockstep:
            self.lockstep.forget(io.cmd_vel)
            for sensor in io.sensors:
                for publisher in sensor.lockstep_readers:
                    self.lockstep.forget_readers(publisher)
        io.close()
        self.descriptions.stop(robot.name)

    def fastest_output(self):
        """(parameter name, rate) of the fastest sensor of any robot: physics may not step slower."""
        rates = [(sensor.rate_parameter, sensor.rate) for robot in self.sim.robots.values()
                 for sensor in robot.sensors]
        return max(rates, key=lambda item: item[1]) if rates else ('physics_rate', 0.0)

    def restart_schedules(self):
        """Every output due at the next step, as at start: sim time went back to zero."""
        for io in self.robots.values():
            for sensor in io.sensors:
                sensor.restart()

    def apply_commands(self, now_ns):
        for io in self.robots.values():
            io.apply_command(now_ns)

    def publish(self, now_ns, stamp, paced=False):
        """Publishes what is due at `now_ns` (`paced`: at a real-time factor), every due
        sensor read at once. Returns the IOs that published and the transforms they
        give the step's tf message."""
        due = [sensor for io in self.robots.values() for sensor in io.sensors if sensor.due(now_ns, paced)]
        reading = [sensor for sensor in due if sensor.needs_reading()]
        readings = dict(zip(map(id, reading), read_all([io.sensor for io in reading], now_ns)))
        transforms = []
        for io in due:
            io.publish(stamp, readings.get(id(io)))
            transforms.extend(io.transforms)
        if transforms and self.world_links:
            transforms.extend(self.world_links.links([io for io in due if io.odom_frame], stamp))
        return due, transforms
