"""The pybullet world: a ground plane and the robot, stepped on request.

The world knows nothing of ROS, time pacing or I/O; callers set wheel speeds,
step, and read poses and joint states.
"""
import math
import os
import tempfile

import numpy as np
import pybullet

from .diff_drive import yaw_to_quaternion
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, urdf_for_pybullet

GRAVITY = 9.81           # m/s^2
GROUND_FRICTION = 1.0    # rubber tyre on a hard floor
CASTER_LINK = 'caster_back_link'
BODY_FRICTION = 0.3      # plastic plates against a wall
STATIC_BODIES = 2        # Bullet's collision group of bodies with mass 0


class SimWorld(object):
    """A TurtleBot3 on a plane, in its own pybullet client."""

    def __init__(self, urdf_path, spawn_pose=(0.0, 0.0, 0.0, 0.0), time_step=1.0 / 200,
                 wheel_torque=1.5, gui=False, obstacles=(), ground_friction=GROUND_FRICTION,
                 caster_friction=0.0):
        self.time_step = time_step
        self.wheel_torque = wheel_torque
        self._spawn_pose = spawn_pose
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError('pybullet could not open a %s connection'
                               % ('GUI' if gui else 'DIRECT'))
        self._call = dict(physicsClientId=self.client)
        if gui:  # building a world while it renders takes many seconds
            pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 0, **self._call)
        pybullet.setGravity(0, 0, -GRAVITY, **self._call)
        pybullet.setTimeStep(time_step, **self._call)
        plane_shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, **self._call)
        self.plane = pybullet.createMultiBody(0, plane_shape, **self._call)
        pybullet.changeDynamics(self.plane, -1, lateralFriction=1.0, **self._call)
        self.obstacles = [self._add_obstacle(obstacle) for obstacle in obstacles]
        # Obstacles never move: their bounding boxes, once, for cast_rays.
        boxes = [pybullet.getAABB(body, **self._call) for body in self.obstacles]
        self._obstacle_boxes = tuple(np.array([box[end] for box in boxes]).reshape(-1, 3) for end in (0, 1))
        self.robot = self._load_robot(urdf_path, spawn_pose)
        links = self._link_indices()
        self.wheels = [links[LEFT_WHEEL_JOINT], links[RIGHT_WHEEL_JOINT]]
        # Bullet multiplies the two bodies' coefficients: the plane's is 1, so
        # these are the coefficients of wheel and caster on the ground.
        for wheel in self.wheels:
            pybullet.changeDynamics(self.robot, wheel, lateralFriction=ground_friction,
                                    rollingFriction=0.0, spinningFriction=0.0, **self._call)
        # The plastic body slides along a wall rather than gripping it.
        for link in [-1] + [index for name, index in links.items()
                            if index not in self.wheels and name != CASTER_LINK]:
            pybullet.changeDynamics(self.robot, link, lateralFriction=BODY_FRICTION, **self._call)
        # With no friction the ball caster carries weight but never steers the robot.
        pybullet.changeDynamics(self.robot, links[CASTER_LINK], lateralFriction=caster_friction,
                                rollingFriction=0.0, spinningFriction=0.0, **self._call)
        self.links = links
        self.set_wheel_speeds(0.0, 0.0)
        if gui:
            self._aim_camera(spawn_pose)
        try:
            self._check_spawn_is_clear(spawn_pose)
        except ValueError:
            self.close()
            raise

    def _add_obstacle(self, obstacle):
        """A static body (mass 0) for a world_file.Obstacle."""
        if obstacle.kind == 'box':
            half = [edge / 2.0 for edge in obstacle.size]
            shape = dict(shapeType=pybullet.GEOM_BOX, halfExtents=half)
            collision = pybullet.createCollisionShape(halfExtents=half, shapeType=pybullet.GEOM_BOX,
                                                      **self._call)
        else:
            radius, height = obstacle.size
            shape = dict(shapeType=pybullet.GEOM_CYLINDER, radius=radius, length=height)
            collision = pybullet.createCollisionShape(pybullet.GEOM_CYLINDER, radius=radius,
                                                      height=height, **self._call)
        visual = pybullet.createVisualShape(rgbaColor=obstacle.color, **dict(shape, **self._call))
        body = pybullet.createMultiBody(0, collision, visual, obstacle.position,
                                        yaw_to_quaternion(obstacle.yaw), **self._call)
        pybullet.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION, **self._call)
        return body

    def _aim_camera(self, spawn_pose):
        """pybullet's window: no side panels, looking over the robot's shoulder, as demo.rviz."""
        pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0, **self._call)
        pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 1, **self._call)
        x, y, _z, yaw = spawn_pose
        ahead = [x + 0.5 * math.cos(yaw), y + 0.5 * math.sin(yaw), 0.0]
        pybullet.resetDebugVisualizerCamera(cameraDistance=3.0, cameraYaw=math.degrees(yaw) - 70.0,
                                            cameraPitch=-35.0, cameraTargetPosition=ahead, **self._call)

    def _check_spawn_is_clear(self, spawn_pose):
        for index, body in enumerate(self.obstacles):
            if pybullet.getClosestPoints(self.robot, body, 0.0, **self._call):
                x, y = spawn_pose[:2]
                raise ValueError('the spawn pose (%.2f, %.2f) puts the robot inside obstacle %d of '
                                 'the world, centred at (%.2f, %.2f): choose another x_pos/y_pos'
                                 % ((x, y, index + 1) + tuple(
                                     pybullet.getBasePositionAndOrientation(body, **self._call)[0][:2])))

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

    def reset_robot(self, pose):
        """Put the robot at `pose` (x, y, z, yaw), at rest, wheels at angle 0."""
        x, y, z, yaw = pose
        pybullet.resetBasePositionAndOrientation(self.robot, [x, y, z], yaw_to_quaternion(yaw),
                                                 **self._call)
        pybullet.resetBaseVelocity(self.robot, [0, 0, 0], [0, 0, 0], **self._call)
        for wheel in self.wheels:
            pybullet.resetJointState(self.robot, wheel, 0.0, 0.0, **self._call)

    def base_pose(self):
        """Position (x, y, z) and orientation (x, y, z, w) of base_footprint in the world."""
        return pybullet.getBasePositionAndOrientation(self.robot, **self._call)

    def base_twist(self):
        """Linear and angular velocity of base_footprint, both in its own frame."""
        linear, angular = self.base_velocity()
        _, orientation = self.base_pose()
        world_from_base = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3))
        return world_from_base.T.dot(linear), world_from_base.T.dot(angular)

    def base_velocity(self):
        """Linear and angular velocity of base_footprint in world axes."""
        return pybullet.getBaseVelocity(self.robot, **self._call)

    def link_pose(self, link):
        """Position and orientation (x, y, z, w) of a robot link's frame in the world."""
        state = pybullet.getLinkState(self.robot, self.links[link], **self._call)
        return state[4], state[5]

    def cast_rays(self, origin, ends):
        """Hit fraction of each ray from `origin` (3) to `ends` (N x 3) against the
        static bodies, inf where it hits none: the robot's links are dynamic, so
        the robot never sees itself.

        Rays that cannot reach a static body are not cast: pybullet builds
        python tuples for every ray, which in the open costs more than the cast.
        """
        fractions = np.full(len(ends), math.inf)
        cast = self._may_hit(np.asarray(origin, dtype=float), ends)
        if cast.any():
            starts = np.broadcast_to(origin, ends.shape)[cast]
            hits = pybullet.rayTestBatch(starts, ends[cast], numThreads=1,
                                         collisionFilterMask=STATIC_BODIES, **self._call)
            fractions[cast] = [hit[2] if hit[0] >= 0 else math.inf for hit in hits]
        return fractions

    def _may_hit(self, origin, ends):
        """Per ray, False only if it can hit no static body: with an obstacle's
        bounding box within reach, every ray may (most then hit something);
        without, only those that reach the ground plane (z = 0)."""
        low, high = self._obstacle_boxes  # K x 3 each
        gaps = np.linalg.norm(np.maximum(np.maximum(low - origin, origin - high), 0.0), axis=1)
        reach = np.sqrt(((ends - origin) ** 2).sum(axis=1).max())
        if origin[2] <= 0.0 or np.any(gaps <= reach):
            return np.ones(len(ends), dtype=bool)
        return ends[:, 2] <= 0.0

    def wheel_states(self):
        """Wheel angles (rad) and angular speeds (rad/s), left then right."""
        states = pybullet.getJointStates(self.robot, self.wheels, **self._call)
        return [state[0] for state in states], [state[1] for state in states]

    def close(self):
        if pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)
