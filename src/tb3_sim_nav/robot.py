"""One simulated robot: its model, body, drive and sensors. No ROS here.

The simulation steps it (`before_step`, the world's step, `after_step`); the
ROS edge commands it and reads its sensors.
"""
from .camera import Camera
from .diff_drive import Limits
from .drive import Drive
from .sensors import Imu, Lidar, Odometry, WheelEncoders

#: Every kind of sensor, in the order a robot holds them: each kind's build()
#: gives a robot its sensors of that kind (none if the config switches it off).
KINDS = (Odometry, WheelEncoders, Lidar, Imu, Camera)


class Robot(object):

    def __init__(self, name, model, body, config, spawn_pose, rng):
        """`spawn_pose` is (position, orientation); `config` a params.Config."""
        self.name = name
        self.model = model
        self.body = body
        self.spawn_pose = spawn_pose
        self.limits = Limits(config.max_linear_speed or model.limits.max_linear,
                             config.max_angular_speed or model.limits.max_angular)
        self.drive = Drive(model.geometry)
        self.rng, self._rng_start = rng, rng.bit_generator.state
        self.sensors = [sensor for kind in KINDS for sensor in kind.build(body, model, config, rng)]
        self.configure(config)
        self.reset()

    def configure(self, config):
        """The realism knobs of a params.Config, at start-up or while running."""
        self.drive.configure(config.wheel_acceleration, config.cmd_vel_timeout,
                             (config.left_motor_error, config.right_motor_error))
        self.body.set_friction(config.ground_friction, config.caster_friction)
        for sensor in self.sensors:
            sensor.configure(config)

    def sensor(self, name):
        """The first sensor named `name`, or None."""
        return next((sensor for sensor in self.sensors if sensor.name == name), None)

    lidar = property(lambda self: self.sensor('scan'))
    imu = property(lambda self: self.sensor('imu'))
    cameras = property(lambda self: [sensor for sensor in self.sensors if sensor.name == 'camera'])

    # --- commands and stepping ------------------------------------------------
    def command(self, v, w, now_ns):
        """A sanitised body command (m/s, rad/s) given at sim time `now_ns`."""
        self.drive.command(v, w, now_ns)

    def before_step(self, now_ns, step_s):
        before = self.drive.speeds
        speeds = self.drive.step(now_ns, step_s)
        if speeds != before:
            self.body.set_wheel_speeds(*speeds)

    def after_step(self):
        for sensor in self.sensors:
            sensor.update()

    def reset(self):
        """Back to the spawn pose, at rest, odometry zeroed there."""
        self.body.reset(self.spawn_pose)
        self.drive.reset()
        self.body.set_wheel_speeds(0.0, 0.0)
        for sensor in self.sensors:
            sensor.reset()

    def restart_noise(self):
        """Every noise source of the robot (one stream) back to where it started."""
        self.rng.bit_generator.state = self._rng_start

    # --- readings, for tests and tools: the ROS edge reads the sensors ---------
    def truth(self):
        """((position, orientation), (linear, angular)) of base_footprint: its true
        pose in the world and its twist in its own frame."""
        return self.body.base_pose(), self.body.base_twist()

    def odometry(self, truth=None):
        """odom's (pose, twist), given the true ones if already read."""
        return self.sensor('odom').source.read(truth if truth is not None else self.truth())

    def wheel_states(self):
        return self.body.wheel_states()

    def scan(self):
        return self.lidar.read()
