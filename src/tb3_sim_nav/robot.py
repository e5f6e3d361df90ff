"""One simulated robot: its model, body, drive, odometry source and sensors. No ROS here.

The simulation steps it (`before_step`, the world's step, `after_step`); the
ROS edge commands it and reads it off.
"""
from .camera import DEFAULT_MAX_RATE, Camera, camera_size
from .diff_drive import Limits
from .drive import Drive
from .odometry import WheelOdometry, WorldOdometry
from .sensors import Imu, Lidar

LIDAR_LINK = 'base_scan'


class Robot(object):

    def __init__(self, name, model, body, config, spawn_pose, rng):
        """`spawn_pose` is (x, y, z, yaw); `config` a params.Config."""
        self.name = name
        self.model = model
        self.body = body
        self.spawn_pose = spawn_pose
        self.limits = Limits(config.max_linear_speed or model.limits.max_linear,
                             config.max_angular_speed or model.limits.max_angular)
        self.drive = Drive(model.geometry)
        if config.odom_source == 'world':
            self.odometry_source = WorldOdometry()
        else:
            self.odometry_source = WheelOdometry(body, model.geometry, config, rng)
        self.lidar = Lidar(body, LIDAR_LINK, config.scan_samples, config.scan_range_min, config.scan_range_max,
                           config.scan_noise, rng) if config.scan else None
        self.imu = Imu(body, config.imu_gyro_noise, config.imu_accel_noise, rng) if config.imu else None
        self.cameras = [Camera(body, spec, *camera_size(spec, config.camera_width, config.camera_height),
                               horizontal_fov=config.camera_horizontal_fov or spec.horizontal_fov,
                               rate=config.camera_rate or min(spec.rate, DEFAULT_MAX_RATE))
                        for spec in model.cameras]
        self.configure(config)
        self.reset()

    def configure(self, config):
        """The realism knobs of a params.Config, at start-up or while running."""
        self.drive.configure(config.wheel_acceleration, config.cmd_vel_timeout,
                             (config.left_motor_error, config.right_motor_error))
        self.odometry_source.configure(config)
        self.body.set_friction(config.ground_friction, config.caster_friction)
        if self.lidar:
            self.lidar.noise_stddev = config.scan_noise
        if self.imu:
            self.imu.gyro_noise, self.imu.accel_noise = config.imu_gyro_noise, config.imu_accel_noise

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
        self.odometry_source.update()

    def reset(self):
        """Back to the spawn pose, at rest, odometry zeroed there."""
        x, y, z, yaw = self.spawn_pose
        self.body.reset(self.spawn_pose)
        self.drive.reset()
        self.body.set_wheel_speeds(0.0, 0.0)
        self.odometry_source.reset(x, y, yaw)
        if self.imu:
            self.imu.reset()

    # --- readings ---------------------------------------------------------------
    def truth(self):
        """((position, orientation), (linear, angular)) of base_footprint: its true
        pose in the world and its twist in its own frame."""
        return self.body.base_pose(), self.body.base_twist()

    def odometry(self, truth=None):
        """odom's (pose, twist), given the true ones if already read."""
        return self.odometry_source.read(truth if truth is not None else self.truth())

    def wheel_states(self):
        return self.body.wheel_states()

    def scan(self):
        return self.lidar.scan()

    def imu_reading(self, now_s):
        return self.imu.read(now_s)
