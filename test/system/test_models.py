"""The TurtleBot3 family, each chosen as TurtleBot3 users choose it: TURTLEBOT3_MODEL alone.

One master of this module's own and this process as a rospy node following
/clock. For each model, `roslaunch tb3_sim_bringup tb3_empty_world.launch`
with TURTLEBOT3_MODEL set and no model argument, in a world of a wall (its
face at x = WALL_X) and a red box ahead-left of the spawn pose, then:

- robot_description is the model's URDF;
- its URDF's geometry drives its kinematics: on ground truth, a turn in place
  at 1 rad/s turns 1 rad per second and a straight run at 0.15 m/s covers
  0.15 m per second (a steady window of 2 s, within 2 %);
- commands beyond its limits are clamped at its own (ROBOTIS' numbers:
  burger 0.22 m/s and 2.84 rad/s, waffle and waffle_pi 0.26 and 1.82);
- the Waffle and Waffle Pi's camera: camera_info's K follows ROBOTIS' field
  of view (Waffle Pi 1.085595 rad, Waffle 1.3439) and the image size (640 x
  480, and the Waffle's 1920 x 1080 scaled to 640 x 360 by default); the red
  box appears in the image at the columns its corners project to, from the
  camera's pose in tf; the Waffle's depth at the image centre is the lidar's
  range to the wall (both as distances from base_footprint) within 2 cm.
"""
import math
import os
import sys
import threading
import time

import numpy as np
import pytest

from tb3_harness.processes import Process, start_master

FOV = {'waffle': 1.3439, 'waffle_pi': 1.085595}          # ROBOTIS' Gazebo cameras (rad)
SIZE = {'waffle': (640, 360), 'waffle_pi': (640, 480)}    # defaults: at most 640 wide
LIMITS = {'burger': (0.22, 2.84), 'waffle': (0.26, 1.82), 'waffle_pi': (0.26, 1.82)}
WALL_X = 2.0
BOX = (1.2, 0.3, 0.1)     # centre x, y and edge of the red box (0.4 m high)
WINDOW = 2.0              # sim s of steady motion measured
TIMEOUT = 60.0            # wall s for anything to arrive
WORLD = ('obstacles:\n'
         '  - box: {size: [0.1, 3.0, 0.5], position: [%g, 0.0], color: [0.6, 0.6, 0.6, 1]}\n'
         '  - box: {size: [%g, %g, 0.4], position: [%g, %g], color: [1, 0, 0, 1]}\n'
         % (WALL_X + 0.05, BOX[2], BOX[2], BOX[0], BOX[1]))

pytestmark = pytest.mark.filterwarnings('ignore:notifyAll:DeprecationWarning')


@pytest.fixture(scope='module')
def node(tmp_path_factory):
    """A master and this process as a rospy node following /clock; the world file."""
    folder = tmp_path_factory.mktemp('models')
    world = folder / 'wall_and_red_box.yaml'
    world.write_text(WORLD)
    master = start_master(str(folder))
    try:
        import rospy
        rospy.init_node('tb3_models_test', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        yield folder, str(world)
    finally:
        import rospy
        if rospy.core.is_initialized():
            rospy.signal_shutdown('models test done')
        master.stop()


class Truth(object):
    """Ground truth as (t, x, y, yaw, v, w) tuples."""

    def __init__(self):
        import rospy
        from nav_msgs.msg import Odometry
        self.samples, self._lock = [], threading.Lock()
        self._sub = rospy.Subscriber('/base_pose_ground_truth', Odometry, self._on, queue_size=None)

    def _on(self, message):
        p, q, t = message.pose.pose.position, message.pose.pose.orientation, message.twist.twist
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        with self._lock:
            self.samples.append((message.header.stamp.to_sec(), p.x, p.y, yaw, t.linear.x, t.angular.z))

    def latest(self):
        with self._lock:
            return self.samples[-1] if self.samples else None

    def between(self, start, end):
        with self._lock:
            return [s for s in self.samples if start <= s[0] <= end]

    def close(self):
        self._sub.unregister()


def wait(predicate, what, timeout=TIMEOUT):
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, 'no %s within %.0f s' % (what, timeout)
        time.sleep(0.02)


def drive(truth, publisher, v, w, seconds):
    """Command (v, w) at 20 Hz until `seconds` of sim time have passed, then stop."""
    from geometry_msgs.msg import Twist
    command = Twist()
    command.linear.x, command.angular.z = v, w
    end = truth.latest()[0] + seconds
    while truth.latest()[0] < end:
        publisher.publish(command)
        time.sleep(0.05)
    publisher.publish(Twist())


def steady(truth, publisher, v, w):
    """Command (v, w) for 1 s to settle and WINDOW s more: the samples of the window."""
    start = truth.latest()[0] + 1.0
    drive(truth, publisher, v, w, 1.0 + WINDOW)
    window = truth.between(start, start + WINDOW)
    assert len(window) > 30, 'ground truth too sparse: %d samples' % len(window)
    return window


def turned(window):
    return sum(math.remainder(b[3] - a[3], 2 * math.pi) for a, b in zip(window, window[1:]))


def latest(topic, message_class):
    import rospy
    return rospy.wait_for_message(topic, message_class, TIMEOUT)


def pose_in(buffer, parent, child):
    """(translation xyz, 3 x 3 rotation) of `child` in `parent`, from tf."""
    import rospy
    transform = buffer.lookup_transform(parent, child, rospy.Time(0), rospy.Duration(TIMEOUT)).transform
    q, t = transform.rotation, transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    rotation = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                         [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                         [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return np.array([t.x, t.y, t.z]), rotation


def check_camera(model, buffer):
    """K, the red box's columns and (Waffle) depth against the lidar."""
    from sensor_msgs.msg import CameraInfo, Image, LaserScan
    info = latest('/camera/rgb/camera_info', CameraInfo)
    width, height = SIZE[model]
    fx = width / (2 * math.tan(FOV[model] / 2))
    assert (info.width, info.height, info.header.frame_id) == (width, height, 'camera_rgb_optical_frame')
    assert info.K[0] == pytest.approx(fx) and info.K[4] == pytest.approx(fx)
    assert (info.K[2], info.K[5]) == pytest.approx(((width - 1) / 2, (height - 1) / 2))
    image = latest('/camera/rgb/image_raw', Image)
    assert (image.encoding, image.width, image.height) == ('rgb8', width, height)
    pixels = np.frombuffer(image.data, np.uint8).reshape(height, width, 3).astype(int)
    red = (pixels[..., 0] > 150) & (pixels[..., 1] < 80) & (pixels[..., 2] < 80)
    columns = np.nonzero(red.any(axis=0))[0]
    assert len(columns), 'the red box is not in the image'
    # The box's vertical edges, in the optical frame (x right, y down, z ahead): u = cx + fx x / z.
    origin, rotation = pose_in(buffer, 'odom', 'camera_rgb_optical_frame')
    x0, y0, edge = BOX
    predicted = []
    for x in (x0 - edge / 2, x0 + edge / 2):
        for y in (y0 - edge / 2, y0 + edge / 2):
            point = rotation.T.dot(np.array([x, y, origin[2]]) - origin)
            predicted.append(info.K[2] + info.K[0] * point[0] / point[2])
    print('MEASURED %s red box columns %d-%d, predicted %.1f-%.1f'
          % (model, columns.min(), columns.max(), min(predicted), max(predicted)))
    assert columns.min() == pytest.approx(min(predicted), abs=2.0)
    assert columns.max() == pytest.approx(max(predicted), abs=2.0)
    if model != 'waffle':
        return
    depth_image = latest('/camera/depth/image_raw', Image)
    assert depth_image.encoding == '32FC1'
    depth = np.frombuffer(depth_image.data, '<f4').reshape(height, width)
    # The lidar's beam ahead, the median of ten scans: each reading has Gazebo's 1 cm of noise.
    ahead = float(np.median([latest('/scan', LaserScan).ranges[0] for _ in range(10)]))
    camera_x = pose_in(buffer, 'base_footprint', 'camera_rgb_optical_frame')[0][0]
    lidar_x = pose_in(buffer, 'base_footprint', 'base_scan')[0][0]
    # The centre pixel looks straight ahead below the red box, at the wall.
    centre = float(depth[int(info.K[5]), int(info.K[2])])
    print('MEASURED waffle wall: depth %.4f + %.4f, lidar %.4f + %.4f' % (centre, camera_x, ahead, lidar_x))
    assert centre + camera_x == pytest.approx(ahead + lidar_x, abs=0.02)
    assert centre + camera_x == pytest.approx(WALL_X, abs=0.02)


@pytest.mark.parametrize('model', ['burger', 'waffle', 'waffle_pi'])
def test_each_model_from_turtlebot3_model_alone(model, node):
    import rospy
    import tf2_ros
    from geometry_msgs.msg import Twist
    folder, world = node
    environment = dict(os.environ, TURTLEBOT3_MODEL=model)
    sim = Process('sim_' + model, ['roslaunch', '--wait', 'tb3_sim_bringup', 'tb3_empty_world.launch',
                                   'world:=' + world], str(folder), env=environment)
    truth = Truth()
    publisher = rospy.Publisher('/cmd_vel', Twist, queue_size=1)
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    try:
        wait(lambda: truth.latest() is not None and truth.latest()[0] > 1.0 or not sim.running(), 'ground truth')
        assert sim.running(), sim.describe()
        wait(lambda: publisher.get_num_connections() > 0, 'subscriber of /cmd_vel')
        assert '<robot name="turtlebot3_%s">' % model in rospy.get_param('/robot_description')
        if model in FOV:
            check_camera(model, buffer)
        turning = steady(truth, publisher, 0.0, 1.0)
        straight = steady(truth, publisher, 0.15, 0.0)
        span = turning[-1][0] - turning[0][0]
        assert turned(turning) == pytest.approx(1.0 * span, rel=0.02)
        covered = math.hypot(straight[-1][1] - straight[0][1], straight[-1][2] - straight[0][2])
        assert covered == pytest.approx(0.15 * (straight[-1][0] - straight[0][0]), rel=0.02)
        backwards = steady(truth, publisher, -1.0, 0.0)    # nothing behind the robot
        spinning = steady(truth, publisher, 0.0, 5.0)
        linear, angular = LIMITS[model]
        print('MEASURED %s: turned %.4f rad in %.2f s, covered %.4f m in %.2f s, clamped at %.4f m/s and %.3f rad/s'
              % (model, turned(turning), span, covered, straight[-1][0] - straight[0][0],
                 np.median([s[4] for s in backwards]), np.median([s[5] for s in spinning])))
        assert np.median([s[4] for s in backwards]) == pytest.approx(-linear, rel=0.02)
        assert np.median([s[5] for s in spinning]) == pytest.approx(angular, rel=0.02)
    finally:
        publisher.publish(Twist())
        listener.unregister()
        truth.close()
        publisher.unregister()
        sim.stop()
