"""The pybullet world: a ground plane, named obstacles and objects, and robot bodies, stepped on request.

The world knows nothing of ROS, time pacing or I/O; callers set wheel speeds,
step, and read poses and joint states. Every body has a name, as Gazebo's
models do: `ground_plane`, the world file's obstacles (their own names, or
KIND_N for the Nth), objects spawned while running, and robots.

Each robot's links carry a collision-filter group bit of their own (bits 2 to
31: Bullet's default groups are 1 for dynamic and 2 for static bodies), and
nothing else changes what collides with what. A robot's lidar casts its rays
with every bit but its own, so it sees the ground, obstacles and the other
robots, never itself. The rays of all lidars of a step are its `rays`'
(world_rays.py).
"""
import math
import pkgutil

import numpy as np
import pybullet
from pybullet_utils.bullet_client import BulletClient

from .bodies import ObjectBody, RobotBody, link_frame, load_urdf
from .frames import IDENTITY, compose, inverse, planar, yaw_of
from .model_files import Shape
from .world_file import models_of
from .world_rays import WorldRays

GRAVITY = 9.81           # m/s^2
GROUND_FRICTION = 1.0    # rubber tyre on a hard floor
GROUND_COLOR = (0.72, 0.70, 0.66, 1.0)  # a light grey floor, for cameras
GROUND_SIZE = 100.0      # m, the ground's visual square
SOLVER_ITERATIONS = 100  # Bullet's default 50 lets stopped wheels creep (0.1 mm/s, 0.6 deg/min)
GROUND = 'ground_plane'  # Gazebo's name for it
SHAPE_COLOR = (0.75, 0.75, 0.72, 1.0)  # a shape with no colour of its own
LINK_MASS = 0.001        # kg of each link that carries a shape of a dynamic model (its base has the mass)
ROBOT_GROUPS = tuple(1 << bit for bit in range(2, 32))  # the collision groups robots get, one each
MAX_ROBOTS = len(ROBOT_GROUPS)


class World(object):
    """Ground, obstacles and robots, in a pybullet client of their own (`p`, a BulletClient).

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
        self.robots = []
        self.p = p = BulletClient(pybullet.GUI if gui else pybullet.DIRECT)
        if p._client < 0:
            raise RuntimeError('pybullet could not open a %s connection' % ('GUI' if gui else 'DIRECT'))
        self.renderer = p.ER_BULLET_HARDWARE_OPENGL if gui or (cameras and self._load_egl()) \
            else p.ER_TINY_RENDERER
        if gui:  # building a world while it renders takes many seconds
            p.configureDebugVisualizer(p.COV_ENABLE_RENDERING, 0)
        self.set_gravity((0.0, 0.0, -GRAVITY))
        self.set_time_step(time_step)
        p.setPhysicsEngineParameter(numSolverIterations=SOLVER_ITERATIONS)
        ground = p.createVisualShape(p.GEOM_BOX, halfExtents=[GROUND_SIZE / 2, GROUND_SIZE / 2, 0.0005],
                                     visualFramePosition=[0, 0, -0.0005], rgbaColor=GROUND_COLOR)
        self.plane = p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE), ground)
        p.changeDynamics(self.plane, -1, lateralFriction=1.0)
        self.objects = {}  # name -> ObjectBody: the world file's obstacles, then what was spawned
        for index, name, parts in models_of(obstacles):
            self.objects[name] = self._model(name, parts)
            self.objects[name].index = index + 1
        self.rays = WorldRays(self)

    # --- objects: obstacles and spawned models ---------------------------------
    def _shape(self, shape, visual):
        """Keyword arguments of pybullet's shape calls for a model_files.Shape."""
        p, kind, size = self.p, shape.kind, shape.size
        arguments = {'box': dict(shapeType=p.GEOM_BOX, halfExtents=[edge / 2.0 for edge in size]),
                     'sphere': dict(shapeType=p.GEOM_SPHERE, radius=size[0])}.get(kind)
        if arguments is None:  # cylinder: pybullet calls its length "length" in visuals, "height" in collisions
            arguments = dict(shapeType=p.GEOM_CYLINDER, radius=size[0],
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
        p = self.p
        collisions = [self._shape(shape, False) for shape, visual in shapes if not visual]
        visuals = [self._shape(shape, True) for shape, visual in shapes if visual]
        if not visuals:  # the EGL renderer fails on a body without one: show its collisions
            visuals = [self._shape(shape._replace(color=None), True) for shape, _ in shapes]
        collision = self._compound(p.createCollisionShape, p.createCollisionShapeArray, collisions)
        visual = self._compound(p.createVisualShape, p.createVisualShapeArray, visuals)
        base = compose(pose, frame_offset)
        body = p.createMultiBody(0.0 if static else mass, collision, visual, base[0], base[1])
        p.changeDynamics(body, -1, lateralFriction=GROUND_FRICTION)
        return ObjectBody(self, name, body, static, frame_offset,
                          [(shape.kind, shape.size, shape.pose) for shape, visual in shapes if not visual])

    def _model(self, name, parts):
        """The ObjectBody of a world file's model: its obstacles (world_file.Obstacle, in the world),
        static, or dynamic with their model's mass, its base (centre of mass) at their centroid."""
        first = parts[0]
        if len(parts) == 1 and not first.mass:
            shape = Shape(first.kind, first.size, IDENTITY, first.color)
            return self._build(name, [(shape, False), (shape, True)], planar(*first.position, yaw=first.yaw),
                               static=True)
        centre = tuple(np.mean([part.position for part in parts], axis=0))
        shapes = [Shape(part.kind, part.size, planar(*np.subtract(part.position, centre), yaw=part.yaw), part.color)
                  for part in parts]
        if len(parts) > 1 and first.mass:
            body = self._build_linked(name, shapes, centre, first.mass)
        else:
            body = self._build(name, [(shape, visual) for shape in shapes for visual in (False, True)],
                               (centre, IDENTITY[1]), static=not first.mass, mass=first.mass)
        if first.inertia is not None:
            self.p.changeDynamics(body.id, -1, localInertiaDiagonal=first.inertia)
        return body

    def _build_linked(self, name, shapes, centre, mass):
        """A dynamic ObjectBody of several shapes: a base of `mass` at `centre` that carries each shape
        on a link of its own, fixed to it. One compound shape would do, but its bounding box (stage 3's
        four cylinders: 1.5 x 1.5 m) holds the robot between them, and Bullet then solves the two
        bodies together: a step cost 1.0-1.2 ms instead of 0.17-0.22 (2026-11-27, this VM)."""
        p = self.p
        links = len(shapes)
        body = p.createMultiBody(
            mass, -1, -1, centre, IDENTITY[1], linkMasses=[LINK_MASS] * links,
            linkCollisionShapeIndices=[p.createCollisionShape(**self._shape(shape._replace(pose=IDENTITY), False))
                                       for shape in shapes],
            linkVisualShapeIndices=[p.createVisualShape(**self._shape(shape._replace(pose=IDENTITY), True))
                                    for shape in shapes],
            linkPositions=[shape.pose[0] for shape in shapes], linkOrientations=[shape.pose[1] for shape in shapes],
            linkInertialFramePositions=[(0.0, 0.0, 0.0)] * links, linkInertialFrameOrientations=[IDENTITY[1]] * links,
            linkParentIndices=[0] * links, linkJointTypes=[p.JOINT_FIXED] * links,
            linkJointAxis=[(0.0, 0.0, 1.0)] * links)
        for link in range(links):
            p.changeDynamics(body, link, lateralFriction=GROUND_FRICTION)
        placed = ObjectBody(self, name, body, False)
        # One link, as the model's SDF has it: the fixed links are how pybullet holds its shapes.
        placed.links, placed.joints, placed.link_names, placed.joint_names = {}, {}, [name], []
        placed.collisions = [(link, shape.kind, shape.size, IDENTITY) for link, shape in enumerate(shapes)]
        return placed

    @staticmethod
    def _compound(single, array, shapes):
        """One shape by `single`, several by `array` (pybullet's *ShapeArray calls), none: -1."""
        if not shapes:
            return -1
        if len(shapes) == 1:
            return single(**shapes[0])
        plural = dict(shapeType='shapeTypes', halfExtents='halfExtents', radius='radii', length='lengths',
                      height='lengths', rgbaColor='rgbaColors', collisionFramePosition='collisionFramePositions',
                      collisionFrameOrientation='collisionFrameOrientations',
                      visualFramePosition='visualFramePositions', visualFrameOrientation='visualFrameOrientations')
        defaults = dict(halfExtents=[0.0, 0.0, 0.0], radius=0.0, length=0.0, height=0.0, rgbaColor=SHAPE_COLOR)
        keys = sorted(set(key for shape in shapes for key in shape))
        return array(**dict((plural[key], [shape.get(key, defaults.get(key)) for shape in shapes]) for key in keys))

    def add_object(self, name, shapes, pose, static, mass=1.0, frame_offset=IDENTITY):
        """Spawns an ObjectBody of (model_files.Shape, is_visual) pairs at `pose`,
        or ValueError when its collision shapes would be inside another body
        (the message names it)."""
        return self._place(self._build(name, shapes, pose, static, mass, frame_offset))

    def add_urdf(self, name, text, pose, static):
        """Spawns an ObjectBody of a URDF's text at `pose`, or ValueError as add_object."""
        body = load_urdf(self.p, text, useFixedBase=static)
        if body < 0:
            raise ValueError('model %s: pybullet could not build its URDF' % name)
        # pybullet puts a base at its centre of mass: the model frame is the root link's.
        inertia = self.p.getDynamicsInfo(body, -1)
        placed = ObjectBody(self, name, body, static, (tuple(inertia[3]), tuple(inertia[4])), urdf_text=text)
        placed.teleport(pose)
        return self._place(placed)

    def _place(self, body):
        try:
            self.check_free(body, 'model %s' % body.name, 'pose')
        except ValueError:
            body.remove()
            raise
        self.objects[body.name] = body
        self.moved(body)
        return body

    def remove_object(self, name):
        body = self.objects.pop(name)
        body.remove()
        self.moved(body)

    def moved(self, body):
        """A body came, went or was teleported."""
        self.rays.moved(body)

    def visual_shapes(self):
        """(model name, model_files.Shape in the world) of every visual shape of
        every object (not the robots, not the ground): what rviz should draw."""
        p = self.p
        kinds = {p.GEOM_BOX: 'box', p.GEOM_CYLINDER: 'cylinder', p.GEOM_SPHERE: 'sphere'}
        shapes = []
        for name, body in self.objects.items():
            inertia = p.getDynamicsInfo(body.id, -1)
            # Visual frames are given in each link's URDF frame; the base's is its
            # centre of mass, less the inertial offset.
            frames = {-1: compose(p.getBasePositionAndOrientation(body.id), inverse((inertia[3], inertia[4])))}
            for data in p.getVisualShapeData(body.id):
                link, kind, dimensions = data[1], kinds.get(data[2]), data[3]
                if kind is None:
                    continue
                if link not in frames:
                    frames[link] = link_frame(p, body.id, link)
                size = {'box': tuple(dimensions[:3]), 'cylinder': (dimensions[1], dimensions[0]),
                        'sphere': (dimensions[0],)}[kind]
                shapes.append((name, Shape(kind, size, compose(frames[link], (data[5], data[6])), tuple(data[7]))))
        return shapes

    def check_free(self, body, what, pose_names):
        """ValueError naming the first body that `body` is inside of."""
        (x, y, _z), _ = self.p.getBasePositionAndOrientation(body.id)
        for other in list(self.objects.values()) + self.robots:
            if other is body or not self.p.getClosestPoints(body.id, other.id, 0.0):
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
        """A RobotBody loaded at `pose`, or ValueError when the pose puts it inside
        an obstacle or another robot (the message names both, and says to change
        `pose_names`)."""
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
        p = self.p
        p.configureDebugVisualizer(p.COV_ENABLE_GUI, 0)
        p.configureDebugVisualizer(p.COV_ENABLE_RENDERING, 1)
        (x, y, _z), orientation = spawn_pose
        yaw = yaw_of(orientation)
        ahead = [x + 0.5 * math.cos(yaw), y + 0.5 * math.sin(yaw), 0.0]
        p.resetDebugVisualizerCamera(cameraDistance=3.0, cameraYaw=math.degrees(yaw) - 70.0, cameraPitch=-35.0,
                                     cameraTargetPosition=ahead)

    # --- stepping and sensing ---------------------------------------------------
    def step(self):
        self.p.stepSimulation()

    def forget_the_past(self):
        """Every body that moves lifted clear of everything (and of each other) and woken for one physics
        step; the caller then puts each where it belongs. Bullet starts each contact's solve from its last
        impulses (warm starting) and wakes a sleeping robot's link colliders only at the end of a step, so a
        robot reset where it stood kept its contacts' past, and one that had slept lost the first step after
        the reset: the same episode then ended up to 0.1 mm elsewhere, and a learning agent's episodes at
        factors 1 and 0 drifted apart (issue 30). Without contacts, nothing of the past is left to Bullet."""
        p = self.p
        moving = self.robots + [body for body in self.objects.values() if not body.static]
        for index, body in enumerate(moving):
            p.resetBasePositionAndOrientation(body.id, (0.0, 0.0, 1000.0 + 10.0 * index), IDENTITY[1])
            p.changeDynamics(body.id, -1, activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING
                             | p.ACTIVATION_STATE_WAKE_UP)
        p.stepSimulation()
        for body in moving:  # they may sleep again (a robot's motors say when: bodies.RobotBody)
            p.changeDynamics(body.id, -1, activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING)

    def set_gravity(self, gravity):
        self.gravity = tuple(gravity)
        self.p.setGravity(*self.gravity)
        for body in self.robots:  # a sleeping robot would not feel it
            body.wake()

    def set_time_step(self, seconds):
        self.time_step = seconds
        self.p.setTimeStep(seconds)

    def _load_egl(self):
        """True if pybullet's EGL renderer plugin loaded."""
        plugin = pkgutil.get_loader('eglRenderer')
        return plugin is not None and self.p.loadPlugin(plugin.get_filename(), '_eglRendererPlugin') >= 0

    def render(self, width, height, view, projection):
        """(rgba H x W x 4 uint8, OpenGL depth buffer H x W in 0..1) of a view."""
        _, _, rgba, depth, _ = self.p.getCameraImage(width, height, view, projection, renderer=self.renderer,
                                                     flags=self.p.ER_NO_SEGMENTATION_MASK)
        return rgba, depth

    def close(self):
        if self.p.isConnected():
            self.p.disconnect()
