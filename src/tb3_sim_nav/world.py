"""The pybullet world: a ground plane, static obstacles and robot bodies, stepped on request.

The world knows nothing of ROS, time pacing or I/O; callers set wheel speeds,
step, and read poses and joint states.

Each robot's links carry a collision-filter group bit of their own (bits 2 to
31: Bullet's default groups are 1 for dynamic and 2 for static bodies), and
nothing else changes what collides with what. A robot's lidar casts its rays
with every bit but its own, so it sees the ground, obstacles and the other
robots, never itself.
"""
import math
import os
import pkgutil
import tempfile

import numpy as np
import pybullet

from .diff_drive import yaw_to_quaternion
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, urdf_for_pybullet

GRAVITY = 9.81           # m/s^2
GROUND_FRICTION = 1.0    # rubber tyre on a hard floor
GROUND_COLOR = (0.72, 0.70, 0.66, 1.0)  # a light grey floor, for cameras
GROUND_SIZE = 100.0      # m, the ground's visual square
BODY_FRICTION = 0.3      # plastic plates against a wall
STATIC_BODIES = 2        # Bullet's collision group of bodies with mass 0
ROBOT_GROUPS = tuple(1 << bit for bit in range(2, 32))  # the collision groups robots get, one each
MAX_ROBOTS = len(ROBOT_GROUPS)


def _int32(bits):
    """`bits` (0..2**32-1) as the signed 32-bit int pybullet's C API takes."""
    return bits - (1 << 32) if bits >= 1 << 31 else bits


class World(object):
    """Ground, obstacles and robots, in a pybullet client of their own.

    With `cameras`, images are rendered by pybullet's EGL plugin on Mesa's
    software rasteriser (llvmpipe, on every core: at 640 x 480 in half the
    wall time of pybullet's own TinyRenderer, for the same CPU; at 1920 x 1080
    in a sixth); where EGL does not load, TinyRenderer renders them. Once
    loaded, the plugin renders every image of the client. It must be loaded
    before any body is made, and fails on a body without a visual shape: the
    ground has one.
    """

    def __init__(self, time_step=1.0 / 200, obstacles=(), gui=False, cameras=False):
        self.time_step = time_step
        self.gui = gui
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError('pybullet could not open a %s connection' % ('GUI' if gui else 'DIRECT'))
        self._call = dict(physicsClientId=self.client)
        self.renderer = pybullet.ER_BULLET_HARDWARE_OPENGL if gui or (cameras and self._load_egl()) \
            else pybullet.ER_TINY_RENDERER
        if gui:  # building a world while it renders takes many seconds
            pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 0, **self._call)
        pybullet.setGravity(0, 0, -GRAVITY, **self._call)
        pybullet.setTimeStep(time_step, **self._call)
        plane_shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, **self._call)
        ground = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[GROUND_SIZE / 2, GROUND_SIZE / 2, 0.0005],
                                            visualFramePosition=[0, 0, -0.0005], rgbaColor=GROUND_COLOR, **self._call)
        self.plane = pybullet.createMultiBody(0, plane_shape, ground, **self._call)
        pybullet.changeDynamics(self.plane, -1, lateralFriction=1.0, **self._call)
        self.obstacles = [self._add_obstacle(obstacle) for obstacle in obstacles]
        self.obstacle_specs = list(obstacles)
        # Obstacles never move: their bounding boxes, once, for cast_rays.
        boxes = [pybullet.getAABB(body, **self._call) for body in self.obstacles]
        self._obstacle_boxes = tuple(np.array([box[end] for box in boxes]).reshape(-1, 3) for end in (0, 1))
        self.robots = []

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

    # --- robots ---------------------------------------------------------------
    def add_robot(self, urdf_path, pose, name='robot', casters=(), wheel_torque=1.5,
                  ground_friction=GROUND_FRICTION, caster_friction=0.0, pose_names='its position'):
        """A RobotBody loaded at `pose` (x, y, z, yaw), or ValueError when the pose
        puts it inside an obstacle or another robot (the message names both, and
        says to change `pose_names`)."""
        used = set(robot.group for robot in self.robots)
        free = [group for group in ROBOT_GROUPS if group not in used]
        if not free:
            raise ValueError('robot %s: a world holds at most %d robots' % (name, MAX_ROBOTS))
        body = RobotBody(self, urdf_path, pose, name, free[0], casters, wheel_torque,
                         ground_friction, caster_friction)
        try:
            self._check_clear(body, pose, pose_names)
        except ValueError:
            body.remove()
            raise
        self.robots.append(body)
        if self.gui and len(self.robots) == 1:
            self._aim_camera(pose)
        return body

    def remove_robot(self, body):
        self.robots.remove(body)
        body.remove()

    def _check_clear(self, body, pose, pose_names):
        x, y = pose[:2]
        for index, obstacle in enumerate(self.obstacles):
            if pybullet.getClosestPoints(body.id, obstacle, 0.0, **self._call):
                centre = pybullet.getBasePositionAndOrientation(obstacle, **self._call)[0]
                raise ValueError('robot %s: the spawn pose (%.2f, %.2f) puts it inside obstacle %d of '
                                 'the world, centred at (%.2f, %.2f): choose another %s'
                                 % (body.name, x, y, index + 1, centre[0], centre[1], pose_names))
        for other in self.robots:
            if pybullet.getClosestPoints(body.id, other.id, 0.0, **self._call):
                there = other.base_pose()[0]
                raise ValueError('robot %s: the spawn pose (%.2f, %.2f) puts it inside robot %s, '
                                 'at (%.2f, %.2f): choose another %s'
                                 % (body.name, x, y, other.name, there[0], there[1], pose_names))

    def _aim_camera(self, spawn_pose):
        """pybullet's window: no side panels, looking over the robot's shoulder, as demo.rviz."""
        pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_GUI, 0, **self._call)
        pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 1, **self._call)
        x, y, _z, yaw = spawn_pose
        ahead = [x + 0.5 * math.cos(yaw), y + 0.5 * math.sin(yaw), 0.0]
        pybullet.resetDebugVisualizerCamera(cameraDistance=3.0, cameraYaw=math.degrees(yaw) - 70.0,
                                            cameraPitch=-35.0, cameraTargetPosition=ahead, **self._call)

    # --- stepping and sensing ---------------------------------------------------
    def step(self):
        pybullet.stepSimulation(**self._call)

    def _load_egl(self):
        """True if pybullet's EGL renderer plugin loaded."""
        plugin = pkgutil.get_loader('eglRenderer')
        return plugin is not None and pybullet.loadPlugin(plugin.get_filename(), '_eglRendererPlugin',
                                                          **self._call) >= 0

    def render(self, width, height, view, projection):
        """(rgba H x W x 4 uint8, OpenGL depth buffer H x W in 0..1) of a view."""
        _, _, rgba, depth, _ = pybullet.getCameraImage(width, height, view, projection, renderer=self.renderer,
                                                       flags=pybullet.ER_NO_SEGMENTATION_MASK, **self._call)
        return rgba, depth

    def cast_rays(self, origin, ends, ignore=None):
        """Hit fraction of each ray from `origin` (3) to `ends` (N x 3), inf where it
        hits nothing; the robot body `ignore` is transparent to them.

        Rays that cannot reach anything are not cast: pybullet builds python
        tuples for every ray, which in the open costs more than the cast.
        """
        fractions = np.full(len(ends), math.inf)
        cast = self._may_hit(np.asarray(origin, dtype=float), ends, ignore)
        if cast.any():
            mask = _int32(0xFFFFFFFF & ~(ignore.group if ignore is not None else 0))
            starts = np.broadcast_to(origin, ends.shape)[cast]
            hits = pybullet.rayTestBatch(starts, ends[cast], numThreads=1, collisionFilterMask=mask,
                                         **self._call)
            fractions[cast] = [hit[2] if hit[0] >= 0 else math.inf for hit in hits]
        return fractions

    def _may_hit(self, origin, ends, ignore):
        """Per ray, False only if it can hit nothing: with an obstacle's bounding
        box or another robot's bounding sphere within reach, every ray may (most
        then hit something); without, only those that reach the ground (z = 0)."""
        reach = np.sqrt(((ends - origin) ** 2).sum(axis=1).max())
        low, high = self._obstacle_boxes  # K x 3 each
        gaps = np.linalg.norm(np.maximum(np.maximum(low - origin, origin - high), 0.0), axis=1)
        near = origin[2] <= 0.0 or np.any(gaps <= reach) or any(
            math.dist(origin, robot.base_pose()[0]) - robot.radius <= reach
            for robot in self.robots if robot is not ignore)
        if near:
            return np.ones(len(ends), dtype=bool)
        return ends[:, 2] <= 0.0

    def close(self):
        if pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)


class RobotBody(object):
    """One robot's multibody in a World: its wheels' motors, its poses and joint states."""

    def __init__(self, world, urdf_path, pose, name, group, casters, wheel_torque, ground_friction,
                 caster_friction):
        self.world = world
        self.name = name
        self.group = group
        self.wheel_torque = wheel_torque
        self._call = world._call
        self.id = self._load(urdf_path, pose)
        links = self._link_indices()
        self.links = links
        self.wheels = [links[LEFT_WHEEL_JOINT], links[RIGHT_WHEEL_JOINT]]
        # Bullet multiplies the two bodies' coefficients: the plane's is 1, so
        # these are the coefficients of wheel and caster on the ground.
        for wheel in self.wheels:
            pybullet.changeDynamics(self.id, wheel, lateralFriction=ground_friction,
                                    rollingFriction=0.0, spinningFriction=0.0, **self._call)
        caster_links = [links[name] for name in casters if name in links]
        # The plastic body slides along a wall rather than gripping it.
        for link in set([-1] + list(links.values())) - set(self.wheels) - set(caster_links):
            pybullet.changeDynamics(self.id, link, lateralFriction=BODY_FRICTION, **self._call)
        # With no friction a ball caster carries weight but never steers the robot.
        for link in caster_links:
            pybullet.changeDynamics(self.id, link, lateralFriction=caster_friction,
                                    rollingFriction=0.0, spinningFriction=0.0, **self._call)
        for link in set([-1] + list(links.values())):
            pybullet.setCollisionFilterGroupMask(self.id, link, _int32(group), -1, **self._call)
        self.radius = self._bounding_radius()
        self.set_wheel_speeds(0.0, 0.0)

    def _load(self, urdf_path, pose):
        x, y, z, yaw = pose
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
        for index in range(pybullet.getNumJoints(self.id, **self._call)):
            info = pybullet.getJointInfo(self.id, index, **self._call)
            indices[info[1].decode()] = index
            indices[info[12].decode()] = index
        return indices

    def _bounding_radius(self):
        """Distance from base_footprint to the furthest corner of any link's bounding box."""
        base = np.array(self.base_pose()[0])
        corners = [corner for link in [-1] + sorted(set(self.links.values()))
                   for corner in pybullet.getAABB(self.id, link, **self._call)]
        return max(np.linalg.norm(np.array(corner) - base) for corner in corners)

    def remove(self):
        pybullet.removeBody(self.id, **self._call)

    def set_wheel_speeds(self, left, right):
        """Target angular speeds (rad/s) of the wheel motors.

        A motor told to stop holds its wheel's angle, as a servo does: a zero
        velocity target alone lets Bullet's iterative solver creep under load.
        """
        torques = [self.wheel_torque] * 2
        if left == 0.0 and right == 0.0:
            pybullet.setJointMotorControlArray(
                self.id, self.wheels, pybullet.POSITION_CONTROL,
                targetPositions=self.wheel_states()[0], forces=torques, **self._call)
        else:
            pybullet.setJointMotorControlArray(
                self.id, self.wheels, pybullet.VELOCITY_CONTROL,
                targetVelocities=[left, right], forces=torques, **self._call)

    def reset(self, pose):
        """Put the robot at `pose` (x, y, z, yaw), at rest, wheels at angle 0."""
        x, y, z, yaw = pose
        pybullet.resetBasePositionAndOrientation(self.id, [x, y, z], yaw_to_quaternion(yaw), **self._call)
        pybullet.resetBaseVelocity(self.id, [0, 0, 0], [0, 0, 0], **self._call)
        for wheel in self.wheels:
            pybullet.resetJointState(self.id, wheel, 0.0, 0.0, **self._call)

    def base_pose(self):
        """Position (x, y, z) and orientation (x, y, z, w) of base_footprint in the world."""
        return pybullet.getBasePositionAndOrientation(self.id, **self._call)

    def base_twist(self):
        """Linear and angular velocity of base_footprint, both in its own frame."""
        linear, angular = self.base_velocity()
        _, orientation = self.base_pose()
        world_from_base = np.reshape(pybullet.getMatrixFromQuaternion(orientation), (3, 3))
        return world_from_base.T.dot(linear), world_from_base.T.dot(angular)

    def base_velocity(self):
        """Linear and angular velocity of base_footprint in world axes."""
        return pybullet.getBaseVelocity(self.id, **self._call)

    def link_pose(self, link):
        """Position and orientation (x, y, z, w) of a link's frame in the world."""
        state = pybullet.getLinkState(self.id, self.links[link], **self._call)
        return state[4], state[5]

    def wheel_states(self):
        """Wheel angles (rad) and angular speeds (rad/s), left then right."""
        states = pybullet.getJointStates(self.id, self.wheels, **self._call)
        return [state[0] for state in states], [state[1] for state in states]
