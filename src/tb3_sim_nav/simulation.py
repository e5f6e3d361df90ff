"""The simulated world of robots, stepped in integer sim time, without ROS.

The ROS edge feeds robots commands, steps the simulation, and publishes what
it reads off; everything that decides what the robots do lives here,
testable with pytest.
"""
import math

import numpy as np

from .frames import IDENTITY, compose, inverse, normalized, relative, rotate
from .params import changed
from .robot import Robot
from .world import GROUND, World

WORLD_FRAMES = ('', 'world')  # how Gazebo's requests name the world frame


class ModelStateError(ValueError):
    """A request about models that cannot be met; the message says why."""


class Simulation(object):
    """Physics steps of `1 / physics_rate` s (set_time_step changes it); time is integer nanoseconds."""

    def __init__(self, config, obstacles=(), world_class=World, cameras=False):
        """`cameras`: some robot will render images (the world then loads a faster renderer)."""
        self.config = config
        self.step_ns = int(round(1e9 / config.physics_rate))
        self.world = world_class(self.step_ns * 1e-9, obstacles, gui=config.gui, cameras=cameras)
        # One seed gives every robot's noise a stream of its own.
        self._seeds = np.random.SeedSequence(None if config.seed < 0 else config.seed)
        self.robots = {}  # name -> Robot, in the order they came
        self._spawn_poses = dict((name, body.base_pose()) for name, body in self.world.objects.items())
        self.steps = 0
        self.now_ns = 0

    def add_robot(self, name, model, pose, model_name=None):
        """A Robot of `model` (a robot_model.RobotModel) at `pose` (position, orientation),
        or ValueError naming it when its name is taken or the pose is not free.
        Its model name (Gazebo's) is `model_name`, else its name, else its URDF's."""
        if name in self.robots:
            raise ValueError('two robots are named %r' % name)
        model_name = model_name or name or model.name
        if model_name in self.model_names():
            raise ValueError('a model is already named %r' % model_name)
        config = self.config
        # The tutorial's robot has no name: its pose comes from ~x_pos and ~y_pos.
        body = self.world.add_robot(model.urdf_text, pose, name or model.name, model.casters,
                                    config.wheel_torque, config.ground_friction, config.caster_friction,
                                    "position (%s's)" % name if name else 'x_pos/y_pos')
        rng = np.random.default_rng(self._seeds.spawn(1)[0])
        robot = self.robots[name] = Robot(name, model, body, config, pose, rng)
        robot.model_name = model_name
        return robot

    def reconfigure(self, changes):
        """Live parameters {name: value} changed for every robot from the next step on;
        params.ParameterError (nothing changed) if one cannot change or is not valid."""
        self.config = changed(self.config, changes)
        for robot in self.robots.values():
            robot.configure(self.config)
        return self.config

    def remove_robot(self, name):
        self.world.remove_robot(self.robots.pop(name).body)

    def step(self):
        step_s = self.step_ns * 1e-9
        for robot in self.robots.values():
            robot.before_step(self.now_ns, step_s)
        self.world.step()
        self.steps += 1
        self.now_ns += self.step_ns
        for robot in self.robots.values():
            robot.after_step()

    def reset_world(self):
        """Every robot and object back to its spawn pose and at rest, odometry zeroed; time runs on."""
        for robot in self.robots.values():
            robot.reset()
        for name, pose in self._spawn_poses.items():
            self.world.objects[name].teleport(pose)

    def reset_simulation(self):
        """reset_world, and time back to zero; with a ~seed, every robot's noise also starts again
        from it, so that what comes after a reset does not depend on how long the simulation ran
        before it (a learning agent's episodes are then the same at any real-time factor)."""
        self.world.forget_the_past()
        self.reset_world()
        self.steps = self.now_ns = 0
        if self.config.seed >= 0:
            for robot in self.robots.values():
                robot.restart_noise()

    def set_time_step(self, seconds):
        """Physics steps of `seconds` from now on; sim time runs on without a jump."""
        self.step_ns = int(round(seconds * 1e9))
        self.world.set_time_step(self.step_ns * 1e-9)

    def close(self):
        self.world.close()

    # --- models, as Gazebo's interface names and moves them ------------------
    def model_names(self):
        return [GROUND] + list(self.world.objects) + [robot.model_name for robot in self.robots.values()]

    def model(self, name):
        """The body of model `name` (a RobotBody or an ObjectBody), None for the
        ground, or ModelStateError."""
        if name == GROUND:
            return None
        if name in self.world.objects:
            return self.world.objects[name]
        for robot in self.robots.values():
            if robot.model_name == name:
                return robot.body
        raise ModelStateError('no model is named %r (the models: %s)' % (name, ', '.join(self.model_names())))

    def robot_of(self, model_name):
        for robot in self.robots.values():
            if robot.model_name == model_name:
                return robot
        return None

    def frame(self, reference):
        """(pose, linear, angular) in the world of a reference frame: the world,
        a model (NAME) or a link (NAME::LINK), or ModelStateError."""
        if reference in WORLD_FRAMES or reference == GROUND:
            return IDENTITY, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        name, _, link = reference.partition('::')
        try:
            body = self.model(name)
        except ModelStateError:
            raise ModelStateError('reference frame %r is no model or link of the world (the models: %s)'
                                  % (reference, ', '.join(self.model_names())))
        linear, angular = body.base_velocity()
        if not link:
            return body.base_pose(), linear, angular
        if link not in body.link_names:
            raise ModelStateError('reference frame %r: model %s has no link %r (its links: %s)'
                                  % (reference, name, link, ', '.join(body.link_names)))
        return body.link_pose(link), linear, angular

    def model_state(self, name, reference=''):
        """(pose, linear, angular) of a model in the frame `reference`, its
        velocities in that frame's axes and relative to it, as Gazebo's."""
        body = self.model(name)
        frame_pose, frame_linear, frame_angular = self.frame(reference)
        if body is None:
            pose, linear, angular = IDENTITY, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        else:
            pose = body.base_pose()
            linear, angular = body.base_velocity()
        back = inverse(frame_pose)[1]
        return (relative(frame_pose, pose), rotate(back, np.subtract(linear, frame_linear)),
                rotate(back, np.subtract(angular, frame_angular)))

    def set_model_state(self, name, pose, linear, angular, reference=''):
        """Teleports a model, as Gazebo's set_model_state: `pose` and velocities
        in the frame `reference`; a zero quaternion reads as no rotation. Refused
        (ModelStateError) for the ground, non-finite numbers, and a pose inside
        another body, which leaves it where it was."""
        numbers = list(pose[0]) + list(pose[1]) + list(linear) + list(angular)
        if not all(math.isfinite(value) for value in numbers):
            raise ModelStateError('model %s: non-finite number in the state %s' % (name, numbers))
        body = self.model(name)
        if body is None:
            raise ModelStateError('the ground plane does not move here')
        frame_pose, _, _ = self.frame(reference)
        orientation = (0.0, 0.0, 0.0, 1.0) if not any(pose[1]) else normalized(pose[1])
        target = compose(frame_pose, (tuple(pose[0]), orientation))
        before, velocity = body.base_pose(), body.base_velocity()
        body.teleport(target, rotate(frame_pose[1], linear), rotate(frame_pose[1], angular))
        try:
            self.world.check_free(body, 'model %s' % name, 'pose')
        except ValueError as error:
            body.teleport(before, *velocity)
            raise ModelStateError(str(error))

    def spawn_object(self, name, shapes, pose, static, mass=1.0, frame_offset=IDENTITY, urdf=None):
        """A model of (model_files.Shape, is_visual) pairs, or of a URDF's text,
        at `pose`; ModelStateError for a name taken or a pose inside a body."""
        if name in self.model_names():
            raise ModelStateError('a model is already named %r' % name)
        try:
            if urdf is not None:
                body = self.world.add_urdf(name, urdf, pose, static)
            else:
                body = self.world.add_object(name, shapes, pose, static, mass, frame_offset)
        except ValueError as error:
            raise ModelStateError(str(error))
        self._spawn_poses[name] = body.base_pose()
        return body

    def delete_model(self, name):
        """Removes a model (a robot's Robot too; it is returned so the caller can
        close its interface), or ModelStateError."""
        body = self.model(name)
        if body is None:
            raise ModelStateError('the ground plane cannot be deleted here')
        robot = self.robot_of(name)
        if robot is not None:
            self.remove_robot(robot.name)
            return robot
        self.world.remove_object(name)
        self._spawn_poses.pop(name, None)
        return None


def build(config, obstacles, robots, world_class=World):
    """A Simulation with `robots`, a list of (name, model, pose (position, orientation)), or the error of
    the first that cannot be placed, with nothing left open."""
    simulation = Simulation(config, obstacles, world_class, cameras=any(model.cameras for _, model, _ in robots))
    try:
        for name, model, pose in robots:
            simulation.add_robot(name, model, pose)
    except Exception:
        simulation.close()
        raise
    return simulation
