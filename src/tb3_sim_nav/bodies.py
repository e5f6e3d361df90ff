"""The bodies of a World: objects (obstacles, spawned models) and robots, each one pybullet multibody. No ROS here.

A body has a name, as Gazebo's models do, and a pose in the core's one
convention (frames.py). Every pybullet call goes through the world's
BulletClient `p`, which carries the client id.
"""
import os
import tempfile

import numpy as np

from .frames import IDENTITY, compose, inverse, matrix
from .model_files import urdf_collisions
from .robot_model import LEFT_WHEEL_JOINT, RIGHT_WHEEL_JOINT, urdf_text_for_pybullet

#: Plastic plates against a wall; at 0.3 a robot pushing a wall at an angle stick-slips (doc/design.md).
BODY_FRICTION = 0.2


def int32(bits):
    """`bits` (0..2**32-1) as the signed 32-bit int pybullet's C API takes."""
    return bits - (1 << 32) if bits >= 1 << 31 else bits


def load_urdf(p, text, pose=IDENTITY, **options):
    """A multibody of a URDF's text (a tiny inertial added to a root without one);
    pybullet loads from a file name: it is written in a temporary folder."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, 'model.urdf')
        with open(path, 'w') as completed:
            completed.write(urdf_text_for_pybullet(text))
        return p.loadURDF(path, pose[0], pose[1], **options)


def link_frame(p, body, link):
    """(position, orientation) in the world of link index `link`'s URDF frame, as
    the body stands now. Without computeForwardKinematics pybullet answers with
    the poses its last step computed before it moved the base: one physics step
    old, which put a turning robot's scan 0.57 degrees per rad/s behind its base
    at 100 Hz (1.6 degrees at the Burger's 2.84 rad/s). Recomputing costs 0.4 us
    a call (3.3 instead of 2.9 us, medians of 7 x 20000 calls, 2026-11-23): for a
    lidar read at 5 Hz with physics at 100 Hz, 0.02 us a step."""
    state = p.getLinkState(body, link, computeForwardKinematics=1)
    return state[4], state[5]


class Body(object):
    """What every body shares: its world, name, pybullet id, links and joints,
    poses and velocities, a bounding radius (for the rays), teleport and removal.

    `frame_offset`: where pybullet's base sits in the model frame (a URDF's
    base is put at its centre of mass; a robot's base_footprint carries a
    tiny inertial at its origin, so for a robot it is the identity).
    """

    static = False
    index = None   # an obstacle's number in its world file
    shapes = None  # (kind, size, pose in the model frame) of each collision shape, for a body built of shapes
    #: (link index, kind, size, pose in the link's frame) of each collision shape, for the rays
    #: (rays.py); link -1's frame is pybullet's base, a link's its URDF frame. None: not every
    #: shape is a box, cylinder or sphere (a mesh), and pybullet meets the body's rays.
    collisions = None

    def __init__(self, world, name, body_id, frame_offset=IDENTITY):
        self.world, self.name, self.id = world, name, body_id
        self.p = p = world.p
        self.frame_offset = frame_offset
        count = p.getNumJoints(body_id)
        infos = [p.getJointInfo(body_id, index) for index in range(count)]
        self.base_link = p.getBodyInfo(body_id)[0].decode() or name
        self.links = dict((info[12].decode(), index) for index, info in enumerate(infos))  # child link -> index
        self.joints = dict((info[1].decode(), index) for index, info in enumerate(infos))
        self.link_names = [self.base_link] + [info[12].decode() for info in infos]
        self.joint_names = [info[1].decode() for info in infos]
        base = np.array(p.getBasePositionAndOrientation(body_id)[0])
        corners = [corner for link in range(-1, count) for corner in p.getAABB(body_id, link)]
        self.radius = max(np.linalg.norm(np.array(corner) - base) for corner in corners)

    def _urdf_collisions(self, text):
        """`collisions` of the body's URDF text."""
        links = urdf_collisions(text)
        if links is None:
            return None
        # The root link's frame in pybullet's base, which is the root's inertial frame.
        root = inverse(tuple(map(tuple, self.p.getDynamicsInfo(self.id, -1)[3:5])))
        return [(self.links[name], shape.kind, shape.size, shape.pose) if name in self.links else
                (-1, shape.kind, shape.size, compose(root, shape.pose))
                for name, shapes in links.items() for shape in shapes]

    def collision_frames(self):
        """The frame of each of `collisions` in the world, where the body is now (the
        forward kinematics, as link_frame): 8 us for a Burger's 5 links, 3.8 of them
        the getLinkStates call (3.45 without the kinematics; medians, 2026-11-24)."""
        links = sorted(set(link for link, _, _, _ in self.collisions if link >= 0))
        frames = {-1: self.p.getBasePositionAndOrientation(self.id)}
        if links:
            states = self.p.getLinkStates(self.id, links, computeForwardKinematics=1)
            frames.update((link, (state[4], state[5])) for link, state in zip(links, states))
        return [frames[link] for link, _, _, _ in self.collisions]

    def base_pose(self):
        """The model frame's pose in the world."""
        pose = self.p.getBasePositionAndOrientation(self.id)
        return pose if self.frame_offset is IDENTITY else compose(pose, inverse(self.frame_offset))

    def centre(self):
        """Where pybullet's base is in the world: the centre of the bounding `radius`."""
        return self.p.getBasePositionAndOrientation(self.id)[0]

    def base_velocity(self):
        """Linear and angular velocity of the base, in world axes."""
        return self.p.getBaseVelocity(self.id)

    def link_pose(self, link):
        """A link's frame in the world (the model frame, for the base), where it is now."""
        if link == self.base_link:
            return self.base_pose()
        return link_frame(self.p, self.id, self.links[link])

    def teleport(self, pose, linear=(0.0, 0.0, 0.0), angular=(0.0, 0.0, 0.0)):
        """The model frame to `pose`, moving at `linear` and `angular` (world axes). A static body
        stays still whatever twist it is given, as in Gazebo (pybullet moved a body of mass 0 on
        at that twist forever, where the lidar did not see it go)."""
        position, orientation = compose(pose, self.frame_offset)
        self.p.resetBasePositionAndOrientation(self.id, position, orientation)
        if self.static:
            linear = angular = (0.0, 0.0, 0.0)
        self.p.resetBaseVelocity(self.id, linear, angular)
        self.wake()
        self.world.moved(self)

    def wake(self):
        """Simulate it from this step on even if it slept (after a teleport, or when gravity changed)."""
        self.p.changeDynamics(self.id, -1, activationState=self.p.ACTIVATION_STATE_WAKE_UP)

    def remove(self):
        self.p.removeBody(self.id)


class ObjectBody(Body):
    """A named body that is no robot: an obstacle of the world file or a model spawned while running."""

    def __init__(self, world, name, body_id, static, frame_offset=IDENTITY, shapes=None, urdf_text=None):
        """Built of `shapes` (in its base's frame) or of a URDF's text."""
        super(ObjectBody, self).__init__(world, name, body_id, frame_offset)
        self.static, self.shapes = static, shapes
        if shapes is not None:
            self.collisions = [(-1, kind, size, pose) for kind, size, pose in shapes]
        elif urdf_text is not None:
            self.collisions = self._urdf_collisions(urdf_text)


class RobotBody(Body):
    """One robot's multibody: its wheels' motors, its twist and joint states.

    Its links carry a collision-filter group bit of their own (`group`), so
    that its lidar's rays can pass through it.
    """

    def __init__(self, world, urdf_text, pose, name, group, casters, wheel_torque, ground_friction,
                 caster_friction):
        p = world.p
        body_id = load_urdf(p, urdf_text, pose, flags=p.URDF_USE_INERTIA_FROM_FILE)
        super(RobotBody, self).__init__(world, name, body_id)
        self.collisions = self._urdf_collisions(urdf_text)
        self.group = group
        self.wheel_torque = wheel_torque
        self.wheels = [self.joints[LEFT_WHEEL_JOINT], self.joints[RIGHT_WHEEL_JOINT]]
        self.casters = [self.links[caster] for caster in casters if caster in self.links]
        every_link = [-1] + list(range(len(self.joint_names)))
        # The plastic body slides along a wall rather than gripping it.
        for link in set(every_link) - set(self.wheels) - set(self.casters):
            p.changeDynamics(body_id, link, lateralFriction=BODY_FRICTION)
        self.set_friction(ground_friction, caster_friction)
        for link in every_link:
            p.setCollisionFilterGroupMask(body_id, link, int32(group), -1)
        self.set_wheel_speeds(0.0, 0.0)

    def set_friction(self, ground, caster):
        """Coulomb friction of the wheels and of the ball casters on the ground. Bullet
        multiplies the two bodies' coefficients, and the ground's is 1. With no
        friction a ball caster carries weight but never steers the robot."""
        for links, friction in ((self.wheels, ground), (self.casters, caster)):
            for link in links:
                self.p.changeDynamics(self.id, link, lateralFriction=friction, rollingFriction=0.0,
                                      spinningFriction=0.0)

    def set_wheel_speeds(self, left, right):
        """Target angular speeds (rad/s) of the wheel motors, each a velocity servo
        with the motor's torque, as Gazebo's diff drive and a Dynamixel in velocity
        mode are. A stopped motor is a servo at speed 0: holding the wheel's angle
        instead fights the contacts' friction and can spin a stopped robot up
        (doc/design.md, "Still means still")."""
        p = self.p
        p.setJointMotorControlArray(self.id, self.wheels, p.VELOCITY_CONTROL,
                                    targetVelocities=[left, right], forces=[self.wheel_torque] * 2)
        # A robot whose motors are stopped may sleep once Bullet finds it at rest
        # (2 s below its motion threshold): it then costs no solver time and does
        # not creep, and a body that touches it wakes it. A robot whose wheels
        # turn never sleeps, however slowly it goes. Ten robots standing: 31
        # instead of 470 us a physics step (2026-11-24, this VM).
        p.changeDynamics(self.id, -1, activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING if left == right == 0.0
                         else p.ACTIVATION_STATE_DISABLE_SLEEPING | p.ACTIVATION_STATE_WAKE_UP)

    def reset(self, pose):
        """Put the robot at `pose`, at rest, wheels at angle 0."""
        self.teleport(pose)
        for wheel in self.wheels:
            self.p.resetJointState(self.id, wheel, 0.0, 0.0)

    def base_twist(self):
        """Linear and angular velocity of base_footprint, both in its own frame."""
        linear, angular = self.base_velocity()
        base_from_world = matrix(self.base_pose()[1]).T
        return base_from_world.dot(linear), base_from_world.dot(angular)

    def wheel_states(self):
        """Wheel angles (rad) and angular speeds (rad/s), left then right."""
        states = self.p.getJointStates(self.id, self.wheels)
        return [state[0] for state in states], [state[1] for state in states]
