"""The simulated world of robots, stepped in integer sim time, without ROS.

The ROS edge feeds robots commands, steps the simulation, and publishes what
it reads off; everything that decides what the robots do lives here,
testable with pytest.
"""
import numpy as np

from .robot import Robot
from .world import World


class Simulation(object):
    """Physics steps of `1 / physics_rate` s; time is an integer count of steps."""

    def __init__(self, config, obstacles=(), world_class=World, cameras=False):
        """`cameras`: some robot will render images (the world then loads a faster renderer)."""
        self.config = config
        self.step_ns = int(round(1e9 / config.physics_rate))
        self.world = world_class(self.step_ns * 1e-9, obstacles, gui=config.gui, cameras=cameras)
        # One seed gives every robot's noise a stream of its own.
        self._seeds = np.random.SeedSequence(None if config.seed < 0 else config.seed)
        self.robots = {}  # name -> Robot, in the order they came
        self.steps = 0

    @property
    def now_ns(self):
        return self.steps * self.step_ns

    def add_robot(self, name, model, pose):
        """A Robot of `model` (a robot_model.RobotModel) at `pose` (x, y, z, yaw),
        or ValueError naming it when its name is taken or the pose is not free."""
        if name in self.robots:
            raise ValueError('two robots are named %r' % name)
        config = self.config
        # The tutorial's robot has no name: its pose comes from ~x_pos and ~y_pos.
        body = self.world.add_robot(model.urdf_file, pose, name or model.name, model.casters,
                                    config.wheel_torque, config.ground_friction, config.caster_friction,
                                    "position (%s's)" % name if name else 'x_pos/y_pos')
        rng = np.random.default_rng(self._seeds.spawn(1)[0])
        robot = self.robots[name] = Robot(name, model, body, config, tuple(pose), rng)
        return robot

    def remove_robot(self, name):
        self.world.remove_robot(self.robots.pop(name).body)

    def step(self):
        step_s = self.step_ns * 1e-9
        for robot in self.robots.values():
            robot.before_step(self.now_ns, step_s)
        self.world.step()
        self.steps += 1
        for robot in self.robots.values():
            robot.after_step()

    def reset_world(self):
        """Every robot back to its spawn pose and at rest, odometry zeroed; time runs on."""
        for robot in self.robots.values():
            robot.reset()

    def reset_simulation(self):
        """reset_world, and time back to zero."""
        self.reset_world()
        self.steps = 0

    def close(self):
        self.world.close()


def build(config, obstacles, robots, world_class=World):
    """A Simulation with `robots`, a list of (name, model, pose), or the error of
    the first that cannot be placed, with nothing left open."""
    simulation = Simulation(config, obstacles, world_class, cameras=any(model.cameras for _, model, _ in robots))
    try:
        for name, model, pose in robots:
            simulation.add_robot(name, model, pose)
    except Exception:
        simulation.close()
        raise
    return simulation
