"""A pinhole camera on a robot's link, rendered by pybullet on the CPU. No ROS here.

It looks along its link's x axis (REP 103: x forward, y left, z up), as
Gazebo's cameras do from camera_rgb_frame; images come out in the optical
frame's terms (x right, y down, z forward). Square pixels, no distortion,
the principal point at the image's centre.
"""
import math
import time

import numpy as np

from .frames import matrix
from .sensors import Sensor

#: Without a width asked for, a camera gets its model's size scaled down to at
#: most this wide, and without a rate, its model's at most this often (Hz of
#: sim time). Every frame costs about 40 ms of CPU here, whatever its size up
#: to 640 x 480: Gazebo's 30 Hz takes one and a half cores, and with rviz
#: showing the image the simulator fell to 0.67 of real time; 15 Hz kept it at
#: real time (bench, 2026-11-23). The R200's 1920 x 1080 costs 65 ms a frame.
DEFAULT_MAX_WIDTH = 640
DEFAULT_MAX_RATE = 15.0


def camera_size(spec, width=None, height=None):
    """(width, height) of a camera: as asked, the missing one from the model's
    aspect; neither asked: the model's, scaled to at most DEFAULT_MAX_WIDTH wide."""
    aspect = spec.height / float(spec.width)
    if width is None and height is None:
        width = min(spec.width, DEFAULT_MAX_WIDTH)
    if height is None:
        return width, max(1, int(round(width * aspect)))
    if width is None:
        return max(1, int(round(height / aspect))), height
    return width, height


class Camera(Sensor):
    """A camera of the robot's model (its URDF's Gazebo sensor blocks); read() renders it."""

    name, rate_parameter = 'camera', 'camera_rate'

    def __init__(self, body, spec, width, height, horizontal_fov, rate):
        """`spec` a robot_model.CameraSpec; size, field of view (rad) and rate
        (Hz of sim time) may differ from its own."""
        super(Camera, self).__init__(body, rate)
        self.spec = spec
        self.width, self.height = width, height
        self.horizontal_fov = horizontal_fov
        self.fx = self.fy = width / (2.0 * math.tan(horizontal_fov / 2.0))
        self.cx, self.cy = (width - 1) / 2.0, (height - 1) / 2.0  # pixel centres at integer coordinates
        vertical_fov = 2.0 * math.atan(height / (2.0 * self.fy))
        self.render_seconds = 0.0  # wall time the last render() took
        self._projection = body.p.computeProjectionMatrixFOV(math.degrees(vertical_fov), width / float(height),
                                                              spec.near, spec.far)

    @classmethod
    def build(cls, body, model, config, rng):
        return [cls(body, spec, *camera_size(spec, config.camera_width, config.camera_height),
                    horizontal_fov=config.camera_horizontal_fov or spec.horizontal_fov,
                    rate=config.camera_rate or min(spec.rate, DEFAULT_MAX_RATE))
                for spec in model.cameras]

    def read(self, now_ns=None):
        return self.render()

    def render(self):
        """(rgb, depth): H x W x 3 uint8 and H x W float32 metres along the
        optical axis, NaN where nothing is within the far clip or a depth
        camera's cutoff."""
        started = time.perf_counter()
        position, orientation = self.body.link_pose(self.spec.link)
        axes = matrix(orientation)
        view = self.body.p.computeViewMatrix(position, np.add(position, axes[:, 0]), axes[:, 2])
        rgba, buffer = self.body.world.render(self.width, self.height, view, self._projection)
        near, far = self.spec.near, self.spec.far
        buffer = np.asarray(buffer, dtype=np.float32)
        depth = (near * far / (far - (far - near) * buffer)).astype(np.float32)
        depth[(buffer >= 1.0) | (depth < self.spec.cutoff)] = np.nan
        rgb = np.ascontiguousarray(rgba[:, :, :3])
        self.render_seconds = time.perf_counter() - started
        return rgb, depth

    def points(self, depth):
        """The organised cloud of a depth image: H x W x 3 float32 (x right, y
        down, z forward, metres), NaN where the depth is."""
        rows, columns = np.indices(depth.shape, dtype=np.float32)
        return np.stack([(columns - self.cx) * depth / self.fx, (rows - self.cy) * depth / self.fy, depth], axis=-1)

    def intrinsics(self):
        """The camera matrix K, row by row."""
        return (self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
