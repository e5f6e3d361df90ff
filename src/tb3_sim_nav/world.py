"""The pybullet world: a ground plane and the robot, stepped on request.

The world knows nothing of ROS, time pacing or I/O; callers set wheel speeds,
step, and read poses and joint states.
"""
import os
import tempfile

import numpy as np
import pybullet

from .diff_drive import yaw_to_quaternion
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, urdf_for_pybullet

GRAVITY = 9.81           # m/s^2
GROUND_FRICTION = 1.0    # rubber tyre on a hard floor
CASTER_LINK = 'caster_back_link'


class SimWorld(object):
    """A TurtleBot3 on a plane, in its own pybullet client."""

    def __init__(self, urdf_path, spawn_pose=(0.0, 0.0, 0.0, 0.0), time_step=1.0 / 200,
                 wheel_torque=1.5, gui=False):
        self.time_step = time_step
        self.wheel_torque = wheel_torque
        self._spawn_pose = spawn_pose
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError('pybullet could not open a %s connection'
                               % ('GUI' if gui else 'DIRECT'))
        self._call = dict(physicsClientId=self.client)
        pybullet.setGravity(0, 0, -GRAVITY, **self._call)
        pybullet.setTimeStep(time_step, **self._call)
        plane_shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, **self._call)
        self.plane = pybullet.createMultiBody(0, plane_shape, **self._call)
        pybullet.changeDynamics(self.plane, -1, lateralFriction=GROUND_FRICTION, **self._call)
        self.robot = self._load_robot(urdf_path, spawn_pose)
        links = self._link_indices()
        self.wheels = [links[LEFT_WHEEL_JOINT], links[RIGHT_WHEEL_JOINT]]
        for wheel in self.wheels:
            pybullet.changeDynamics(self.robot, wheel, lateralFriction=GROUND_FRICTION,
                                    rollingFriction=0.0, spinningFriction=0.0, **self._call)
        # The ball caster carries weight but must never steer the robot.
        pybullet.changeDynamics(self.robot, links[CASTER_LINK], lateralFriction=0.0,
                                rollingFriction=0.0, spinningFriction=0.0, **self._call)
        self.set_wheel_speeds(0.0, 0.0)

    def _load_robot(self, urdf_path, spawn_pose):
        x, y, z, yaw = spawn_pose
        # pybullet loads from a file name: write the completed URDF beside the original's
        # name in a temporary folder (mesh paths, if any, would be absolute).
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, os.path.basename(urdf_path))
            with open(path, 'w') as completed:
                completed.write(urdf_for_pybullet(urdf_path))
            return pybullet.loadURDF(path, [x, y, z], yaw_to_quaternion(yaw),
                                     flags=pybullet.URDF_USE_INERTIA_FROM_FILE, **self._call)

    def _link_indices(self):
        """Joint name -> index, and child link name -> index (they coincide in pybullet)."""
        indices = {}
        for index in range(pybullet.getNumJoints(self.robot, **self._call)):
            info = pybullet.getJointInfo(self.robot, index, **self._call)
            indices[info[1].decode()] = index
            indices[info[12].decode()] = index
        return indices

    def set_wheel_speeds(self, left, right):
        """Target angular speeds (rad/s) of the wheel motors.

        A motor told to stop holds its wheel's angle, as a servo does: a zero
        velocity target alone lets Bullet's iterative solver creep under load.
        """
        torques = [self.wheel_torque] * 2
        if left == 0.0 and right == 0.0:
            pybullet.setJointMotorControlArray(
                self.robot, self.wheels, pybullet.POSITION_CONTROL,
                targetPositions=self.wheel_states()[0], forces=torques, **self._call)
        else:
            pybullet.setJointMotorControlArray(
                self.robot, self.wheels, pybullet.VELOCITY_CONTROL,
                targetVelocities=[left, right], forces=torques, **self._call)

    def step(self):
        pybullet.stepSimulation(**self._call)

    def base_pose(self):
        """Position (x, y, z) and orientation (x, y, z, w) of base_footprint in the world."""
        return pybullet.getBasePositionAndOrientation(self.robot, **self._call)

    def base_twist(self):
        """Linear and angular velocity of base_footprint, both in its own frame."""
        linear, angular = pybullet.getBaseVelocity(self.robot, **self._call)
        _, orientation = self.base_pose()
        world_from_base = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3))
        return world_from_base.T.dot(linear), world_from_base.T.dot(angular)

    def wheel_states(self):
        """Wheel angles (rad) and angular speeds (rad/s), left then right."""
        states = pybullet.getJointStates(self.robot, self.wheels, **self._call)
        return [state[0] for state in states], [state[1] for state in states]

    def close(self):
        if pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)
