"""The pybullet world: a ground plane, named obstacles and objects, and robot bodies, stepped on request.

The world knows nothing of ROS, time pacing or I/O; callers set wheel speeds,
step, and read poses and joint states. Every body has a name, as Gazebo's
models do: `ground_plane`, the world file's obstacles (their own names, or
KIND_N for the Nth), objects spawned while running, and robots.

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
from .frames import IDENTITY, compose, inverse
from .model_files import Shape
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, urdf_text_for_pybullet

GRAVITY = 9.81           # m/s^2
GROUND_FRICTION = 1.0    # rubber tyre on a hard floor
GROUND_COLOR = (0.72, 0.70, 0.66, 1.0)  # a light grey floor, for cameras
GROUND_SIZE = 100.0      # m, the ground's visual square
BODY_FRICTION = 0.2      # plastic plates against a wall; at 0.3 a robot pushing a wall at an angle stick-slips (doc/design.md)
SOLVER_ITERATIONS = 100  # Bullet's default 50 lets stopped wheels creep (0.1 mm/s, 0.6 deg/min)
STATIC_BODIES = 2        # Bullet's collision group of bodies with mass 0
GROUND = 'ground_plane'  # Gazebo's name for it
SHAPE_COLOR = (0.75, 0.75, 0.72, 1.0)  # a shape with no colour of its own
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
        self.gui = gui
        self.client = pybullet.connect(pybullet.GUI if gui else pybullet.DIRECT)
        if self.client < 0:
            raise RuntimeError('pybullet could not open a %s connection' % ('GUI' if gui else 'DIRECT'))
        self._call = dict(physicsClientId=self.client)
        self.renderer = pybullet.ER_BULLET_HARDWARE_OPENGL if gui or (cameras and self._load_egl()) \
            else pybullet.ER_TINY_RENDERER
        if gui:  # building a world while it renders takes many seconds
            pybullet.configureDebugVisualizer(pybullet.COV_ENABLE_RENDERING, 0, **self._call)
        self.set_gravity((0.0, 0.0, -GRAVITY))
        self.set_time_step(time_step)
        pybullet.setPhysicsEngineParameter(numSolverIterations=SOLVER_ITERATIONS, **self._call)
        plane_shape = pybullet.createCollisionShape(pybullet.GEOM_PLANE, **self._call)
        ground = pybullet.createVisualShape(pybullet.GEOM_BOX, halfExtents=[GROUND_SIZE / 2, GROUND_SIZE / 2, 0.0005],
                                            visualFramePosition=[0, 0, -0.0005], rgbaColor=GROUND_COLOR, **self._call)
        self.plane = pybullet.createMultiBody(0, plane_shape, ground, **self._call)
        pybullet.changeDynamics(self.plane, -1, lateralFriction=1.0, **self._call)
        self.robots = []
        self.objects = {}  # name -> ObjectBody: the world file's obstacles, then what was spawned
        for index, obstacle in enumerate(obstacles):
            name = obstacle.name or '%s_%d' % (obstacle.kind, index + 1)
            if name in self.objects:
                raise ValueError('obstacle %d: two obstacles are named %r' % (index + 1, name))
            shape = Shape(obstacle.kind, obstacle.size, IDENTITY, obstacle.color)
            self.objects[name] = self._build(name, [(shape, False), (shape, True)],
                                             (obstacle.position, yaw_to_quaternion(obstacle.yaw)), static=True)
            self.objects[name].index = index + 1
        self._refresh_boxes()

    # --- objects: obstacles and spawned models ---------------------------------
    def _shape(self, shape, visual):
        """Keyword arguments of pybullet's shape calls for a model_files.Shape."""
        kind, size = shape.kind, shape.size
        arguments = {'box': dict(shapeType=pybullet.GEOM_BOX, halfExtents=[edge / 2.0 for edge in size]),
                     'sphere': dict(shapeType=pybullet.GEOM_SPHERE, radius=size[0])}.get(kind)
        if arguments is None:  # cylinder: pybullet calls its length "length" in visuals, "height" in collisions
            arguments = dict(shapeType=pybullet.GEOM_CYLINDER, radius=size[0],
                             **{('length' if visual else 'height'): size[1]})
        position, orientation = shape.pose
        frame = 'visualFrame' if visual else 'collisionFrame'
        arguments.update({frame + 'Position': position, frame + 'Orientation': orientation})
        if visual:
            arguments['rgbaColor'] = shape.color or SHAPE_COLOR
        return arguments

    def _build(self, name, shapes, pose, static, mass=0.0, frame_offset=IDENTITY):
        """An ObjectBody of (Shape, is_visual) pairs, in its model frame at `pose`:
        static, or of `mass` with its base at `frame_offset` in the model frame."""
        collisions = [self._shape(shape, False) for shape, visual in shapes if not visual]
        visuals = [self._shape(shape, True) for shape, visual in shapes if visual]
        if not visuals:  # the EGL renderer fails on a body without one: show its collisions
            visuals = [self._shape(shape._replace(color=None), True) for shape, _ in shapes]
        collision = self._compound(pybullet.createCollisionShape, pybullet.createCollisionShapeArray, collisions)
        visual = self._compound(pybullet.createVisualShape, pybullet.createVisualShapeArray, visuals)
        base = compose(pose, frame_offset)
        body = pybullet.createMultiBody(0.0 if static else mass, collision, visual, base[0], base[1], **self._call)
        pybullet.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION, **self._call)
        return ObjectBody(self, name, body, static, frame_offset)

    def _compound(self, single, array, shapes):
        """One shape by `single`, several by `array` (pybullet's *ShapeArray calls), none: -1."""
        if not shapes:
            return -1
        if len(shapes) == 1:
            return single(**dict(shapes[0], **self._call))
        plural = dict(shapeType='shapeTypes', halfExtents='halfExtents', radius='radii', length='lengths',
                      height='lengths', rgbaColor='rgbaColors', collisionFramePosition='collisionFramePositions',
                      collisionFrameOrientation='collisionFrameOrientations',
                      visualFramePosition='visualFramePositions', visualFrameOrientation='visualFrameOrientations')
        defaults = dict(halfExtents=[0.0, 0.0, 0.0], radius=0.0, length=0.0, height=0.0, rgbaColor=SHAPE_COLOR)
        keys = sorted(set(key for shape in shapes for key in shape))
        return array(**dict(dict((plural[key], [shape.get(key, defaults.get(key)) for shape in shapes])
                                 for key in keys), **self._call))

    def add_object(self, name, shapes, pose, static, mass=1.0, frame_offset=IDENTITY):
        """Spawns an ObjectBody of (model_files.Shape, is_visual) pairs at `pose`
        (position, orientation), or ValueError when its collision shapes would be
        inside another body (the message names it)."""
        return self._place(self._build(name, shapes, pose, static, mass, frame_offset))

    def add_urdf(self, name, text, pose, static):
        """Spawns an ObjectBody of a URDF's text at `pose`, or ValueError as add_object."""
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, 'model.urdf')
            with open(path, 'w') as completed:
                completed.write(urdf_text_for_pybullet(text))
            body = pybullet.loadURDF(path, useFixedBase=static, **self._call)
        if body < 0:
            raise ValueError('model %s: pybullet could not build its URDF' % name)
        # pybullet puts a base at its centre of mass: the model frame is the root link's.
        inertia = pybullet.getDynamicsInfo(body, -1, **self._call)
        placed = ObjectBody(self, name, body, static, (tuple(inertia[3]), tuple(inertia[4])))
        placed.teleport(pose)
        return self._place(placed)

    def _place(self, body):
        try:
            self.check_free(body, 'model %s' % body.name, 'pose')
        except ValueError:
            body.remove()
            raise
        self.objects[body.name] = body
        self._refresh_boxes()
        return body

    def remove_object(self, name):
        self.objects.pop(name).remove()
        self._refresh_boxes()

    def visual_shapes(self):
        """(model name, model_files.Shape in the world) of every visual shape of
        every object (not the robots, not the ground): what rviz should draw."""
        kinds = {pybullet.GEOM_BOX: 'box', pybullet.GEOM_CYLINDER: 'cylinder', pybullet.GEOM_SPHERE: 'sphere'}
        shapes = []
        for name, body in self.objects.items():
            inertia = pybullet.getDynamicsInfo(body.id, -1, **self._call)
            # Visual frames are given in each link's URDF frame; the base's is its
            # centre of mass, less the inertial offset.
            frames = {-1: compose(pybullet.getBasePositionAndOrientation(body.id, **self._call),
                                  inverse((inertia[3], inertia[4])))}
            for data in pybullet.getVisualShapeData(body.id, **self._call):
                link, kind, dimensions = data[1], kinds.get(data[2]), data[3]
                if kind is None:
                    continue
                if link not in frames:
                    state = pybullet.getLinkState(body.id, link, **self._call)
                    frames[link] = (state[4], state[5])
                size = {'box': tuple(dimensions[:3]), 'cylinder': (dimensions[1], dimensions[0]),
                        'sphere': (dimensions[0],)}[kind]
                shapes.append((name, Shape(kind, size, compose(frames[link], (data[5], data[6])), tuple(data[7]))))
        return shapes

    def _refresh_boxes(self):
        """The static objects' bounding boxes, for cast_rays: anew whenever they change."""
        boxes = [pybullet.getAABB(body.id, **self._call) for body in self.objects.values() if body.static]
        self._static_boxes = tuple(np.array([box[end] for box in boxes]).reshape(-1, 3) for end in (0, 1))

    def check_free(self, body, what, pose_names):
        """ValueError naming the first body that `body` is inside of."""
        (x, y, _z), _ = pybullet.getBasePositionAndOrientation(body.id, **self._call)
        for other in list(self.objects.values()) + self.robots:
            if other is body or not pybullet.getClosestPoints(body.id, other.id, 0.0, **self._call):
                continue
            (ox, oy, _oz), _ = other.base_pose()
            if isinstance(other, RobotBody):
                inside = 'robot %s, at (%.2f, %.2f)' % (other.name, ox, oy)
            elif other.index:
                inside = 'obstacle %d of the world (%s), centred at (%.2f, %.2f)' % (other.index, other.name, ox, oy)
            else:
                inside = 'model %s, at (%.2f, %.2f)' % (other.name, ox, oy)
            raise ValueError('%s: the spawn pose (%.2f, %.2f) puts it inside %s: choose another %s'
                             % (what, x, y, inside, pose_names))

    # --- robots ---------------------------------------------------------------
    def add_robot(self, urdf_text, pose, name='robot', casters=(), wheel_torque=1.5,
                  ground_friction=GROUND_FRICTION, caster_friction=0.0, pose_names='its position'):
        """A RobotBody loaded at `pose` (x, y, z, yaw), or ValueError when the pose
        puts it inside an obstacle or another robot (the message names both, and
        says to change `pose_names`)."""
        used = set(robot.group for robot in self.robots)
        free = [group for group in ROBOT_GROUPS if group not in used]
        if not free:
            raise ValueError('robot %s: a world holds at most %d robots' % (name, MAX_ROBOTS))
        body = RobotBody(self, urdf_text, pose, name, free[0], casters, wheel_torque,
                         ground_friction, caster_friction)
        try:
            self.check_free(body, 'robot %s' % name, pose_names)
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

    def set_gravity(self, gravity):
        self.gravity = tuple(gravity)
        pybullet.setGravity(*self.gravity, **self._call)

    def set_time_step(self, seconds):
        self.time_step = seconds
        pybullet.setTimeStep(seconds, **self._call)

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
        """Per ray, False only if it can hit nothing: with a static object's
        bounding box or a moving body's bounding sphere within reach, every ray
        may (most then hit something); without, only those that reach the
        ground (z = 0)."""
        reach = np.sqrt(((ends - origin) ** 2).sum(axis=1).max())
        low, high = self._static_boxes  # K x 3 each
        gaps = np.linalg.norm(np.maximum(np.maximum(low - origin, origin - high), 0.0), axis=1)
        movers = [body for body in self.robots if body is not ignore] + [
            body for body in self.objects.values() if not body.static]
        near = origin[2] <= 0.0 or np.any(gaps <= reach) or any(
            math.dist(origin, body.base_pose()[0]) - body.radius <= reach for body in movers)
        if near:
            return np.ones(len(ends), dtype=bool)
        return ends[:, 2] <= 0.0

    def close(self):
        if pybullet.isConnected(self.client):
            pybullet.disconnect(self.client)


def _bounding_radius(client, body, links):
    """Distance from a body's base to the furthest corner of any of its links' bounding boxes."""
    base = np.array(pybullet.getBasePositionAndOrientation(body, physicsClientId=client)[0])
    corners = [corner for link in links for corner in pybullet.getAABB(body, link, physicsClientId=client)]
    return max(np.linalg.norm(np.array(corner) - base) for corner in corners)


class ObjectBody(object):
    """A named body that is no robot: an obstacle of the world file or a model
    spawned while running. Its pose is its model frame's, in which pybullet's
    base sits at `frame_offset`."""

    index = None  # the obstacle's number in its world file, if it is one

    def __init__(self, world, name, body_id, static, frame_offset=IDENTITY):
        self.world, self.name, self.id, self.static = world, name, body_id, static
        self.frame_offset = frame_offset
        self._call = world._call
        count = pybullet.getNumJoints(body_id, **self._call)
        self.base_link = pybullet.getBodyInfo(body_id, **self._call)[0].decode() or name
        self.links = dict((pybullet.getJointInfo(body_id, link, **self._call)[12].decode(), link)
                          for link in range(count))
        self.joint_names = [pybullet.getJointInfo(body_id, link, **self._call)[1].decode() for link in range(count)]
        self.radius = _bounding_radius(world.client, body_id, range(-1, count))

    @property
    def link_names(self):
        return [self.base_link] + sorted(self.links, key=self.links.get)

    def link_pose(self, link):
        """Position and orientation of a link's frame in the world (the model's, for its base)."""
        if link == self.base_link:
            return self.base_pose()
        state = pybullet.getLinkState(self.id, self.links[link], **self._call)
        return state[4], state[5]

    def base_pose(self):
        """Position and orientation of the model frame in the world."""
        return compose(pybullet.getBasePositionAndOrientation(self.id, **self._call), inverse(self.frame_offset))

    def base_velocity(self):
        return pybullet.getBaseVelocity(self.id, **self._call)

    def teleport(self, pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
        """The model frame to `pose`, moving at `linear` and `angular` (world axes)."""
        position, orientation = compose(pose, self.frame_offset)
        pybullet.resetBasePositionAndOrientation(self.id, position, orientation, **self._call)
        pybullet.resetBaseVelocity(self.id, linear, angular, **self._call)
        if self.static and self.world.objects.get(self.name) is self:
            self.world._refresh_boxes()

    def remove(self):
        pybullet.removeBody(self.id, **self._call)


class RobotBody(object):
    """One robot's multibody in a World: its wheels' motors, its poses and joint states."""

    static = False

    def __init__(self, world, urdf_text, pose, name, group, casters, wheel_torque, ground_friction,
                 caster_friction):
        self.world = world
        self.name = name
        self.group = group
        self.wheel_torque = wheel_torque
        self._call = world._call
        self.id = self._load(urdf_text, pose)
        links = self._link_indices()
        self.links = links
        self.base_link = pybullet.getBodyInfo(self.id, **self._call)[0].decode()
        self.wheels = [links[LEFT_WHEEL_JOINT], links[RIGHT_WHEEL_JOINT]]
        self.casters = [links[name] for name in casters if name in links]
        # The plastic body slides along a wall rather than gripping it.
        for link in set([-1] + list(links.values())) - set(self.wheels) - set(self.casters):
            pybullet.changeDynamics(self.id, link, lateralFriction=BODY_FRICTION, **self._call)
        self.set_friction(ground_friction, caster_friction)
        for link in set([-1] + list(links.values())):
            pybullet.setCollisionFilterGroupMask(self.id, link, _int32(group), -1, **self._call)
        self.radius = _bounding_radius(world.client, self.id, [-1] + sorted(set(links.values())))
        self.set_wheel_speeds(0.0, 0.0)

    def _load(self, urdf_text, pose):
        x, y, z, yaw = pose
        # pybullet loads from a file name: write the completed URDF in a temporary folder.
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, 'robot.urdf')
            with open(path, 'w') as completed:
                completed.write(urdf_text_for_pybullet(urdf_text))
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

    def remove(self):
        pybullet.removeBody(self.id, **self._call)

    def set_friction(self, ground, caster):
        """Coulomb friction of the wheels and of the ball casters on the ground. Bullet
        multiplies the two bodies' coefficients, and the ground's is 1. With no
        friction a ball caster carries weight but never steers the robot."""
        for links, friction in ((self.wheels, ground), (self.casters, caster)):
            for link in links:
                pybullet.changeDynamics(self.id, link, lateralFriction=friction, rollingFriction=0.0,
                                        spinningFriction=0.0, **self._call)

    def set_wheel_speeds(self, left, right):
        """Target angular speeds (rad/s) of the wheel motors, each a velocity servo
        with the motor's torque, as Gazebo's diff drive and a Dynamixel in velocity
        mode are. A stopped motor is a servo at speed 0: holding the wheel's angle
        instead fights the contacts' friction and can spin a stopped robot up
        (doc/design.md, "Still means still")."""
        pybullet.setJointMotorControlArray(
            self.id, self.wheels, pybullet.VELOCITY_CONTROL,
            targetVelocities=[left, right], forces=[self.wheel_torque] * 2, **self._call)

    def reset(self, pose):
        """Put the robot at `pose` (x, y, z, yaw), at rest, wheels at angle 0."""
        x, y, z, yaw = pose
        pybullet.resetBasePositionAndOrientation(self.id, [x, y, z], yaw_to_quaternion(yaw), **self._call)
        pybullet.resetBaseVelocity(self.id, [0, 0, 0], [0, 0, 0], **self._call)
        for wheel in self.wheels:
            pybullet.resetJointState(self.id, wheel, 0.0, 0.0, **self._call)

    def teleport(self, pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
        """base_footprint to `pose`, moving at `linear` and `angular` (world axes); the wheels as they are."""
        pybullet.resetBasePositionAndOrientation(self.id, pose[0], pose[1], **self._call)
        pybullet.resetBaseVelocity(self.id, linear, angular, **self._call)

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
        if link == self.base_link:
            return self.base_pose()
        state = pybullet.getLinkState(self.id, self.links[link], **self._call)
        return state[4], state[5]

    @property
    def link_names(self):
        """The base link, then the links of the joints, in pybullet's order."""
        count = pybullet.getNumJoints(self.id, **self._call)
        return [self.base_link] + [pybullet.getJointInfo(self.id, index, **self._call)[12].decode()
                                   for index in range(count)]

    @property
    def joint_names(self):
        return [pybullet.getJointInfo(self.id, index, **self._call)[1].decode()
                for index in range(pybullet.getNumJoints(self.id, **self._call))]

    def wheel_states(self):
        """Wheel angles (rad) and angular speeds (rad/s), left then right."""
        states = pybullet.getJointStates(self.id, self.wheels, **self._call)
        return [state[0] for state in states], [state[1] for state in states]
