#!/usr/bin/env python3
r"""rviz with the tutorial's demo.rviz, on a screen of its own, shows what the learner must see.

The .test includes tb3_world.launch (arena, pillars, spawn at (-2, -0.5)). This
node starts Xvfb on a free display (Xvfb picks it: -displayfd) and rviz as the
tutorial does (`rosrun rviz rviz -d \`rospack find tb3_sim_bringup\`/rviz/demo.rviz`),
polls screenshots of the root window until the 3D view shows the robot and the
scan, then checks one screenshot after a settling time:

- the 3D view is not blank (many colours, non-trivial variance);
- the robot is there (its orange lidar, the URDF's only orange);
- the scan is there (the LaserScan display's flat colour, read from demo.rviz);
- no display is in Error or Warn state (see ERROR_COLOURS for how);
- driving the tutorial's circle adds red /odom arrows to the trail.

Screenshots: tb3_harness.screen (imagemagick's import, decoded with numpy,
so no imaging library is needed); the last run's
are kept in ~/.ros/test_results/tb3_sim_nav/rviz_renders/. rviz and Xvfb are
stopped by process group (their PIDs) as soon as the screenshots are taken,
in a `finally` (so also on failure), at rospy shutdown and at exit;
PR_SET_PDEATHSIG kills them if this node is killed outright.

Parameter ~rviz_config: the configuration under test (default: the
tutorial's demo.rviz); `rostest tb3_sim_nav rviz_renders.test
rviz_config:=/path/to/other.rviz` shows that a broken one fails. With
~camera true (rviz_camera.test: a Waffle Pi and camera.rviz) the camera's
image must also be shown beside the 3D view: its Image panel, in the left
dock, holds the pillars' green, which nothing else in the dock is.
"""
import os
import sys
import time
import unittest

import numpy
import rospkg
import rospy
import rostest
import yaml
from geometry_msgs.msg import Twist

sys.path.insert(0, os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', 'tools'))  # the harness
from tb3_harness.screen import green_pixels, save_png, screen_env, screenshot, start_xvfb

from tb3_test_utils import Child, init_test_node, report, wait_for

RENDER_TIMEOUT = 90.0     # wall s from rviz's start to a 3D view with robot and scan
SETTLE = 3.0              # wall s after that for transient start-up statuses to clear
DRIVE_SECONDS = 6.0       # sim s of the tutorial's circle command
DRIVE_TIMEOUT = 60.0      # wall s for them to pass
TRAIL_WITHIN = 10.0       # wall s after the stop for rviz to have drawn the trail
MIN_COLOURS = 50          # distinct colours in the 3D view (a blank view has 1-3)
MIN_STDDEV = 5.0          # standard deviation of the 3D view's channel values
MIN_ROBOT_PIXELS = 40     # orange pixels of the lidar (about 200 at the spawn pose)
MIN_SCAN_PIXELS = 1000    # scan-coloured pixels (several thousand in the arena)
MIN_NEW_TRAIL_PIXELS = 100  # red arrow pixels added by DRIVE_SECONDS of driving
MIN_NAME_PIXELS = 100     # display names in rviz's "enabled, OK" blue: the panel is there
MIN_CAMERA_GREEN = 300    # pillar-green pixels of the camera image in the left dock (thousands with a Waffle Pi)
COLOUR_TOLERANCE = 12     # per channel, for the exact colours below

# How "no display shows an error" is checked. rviz reports a display's status
# only in its Displays panel: a display in Error state gets a red icon and its
# name drawn in StatusProperty's error colour, (192, 32, 32); Warn in
# (192, 128, 0); an enabled display that is OK has its name in (40, 120, 197).
# Nothing of it reaches stderr or /rosout (checked: a RobotModel whose
# robot_description parameter does not exist turns red in the panel and
# prints nothing), so reading rviz's output alone would miss it. The panel's
# pixels are the one reliable source: the left dock (everything left of the 3D
# view) must hold none of the two status colours in the names' column (the
# MarkerArray display's icon has red dots of its own), and must hold the OK
# blue, or we would be looking at the wrong place. rviz's output is checked as
# well, for [ERROR] lines (a plugin's ROS_ERROR, a bad URDF).
ERROR_COLOURS = {'Error': (192, 32, 32), 'Warn': (192, 128, 0)}
OK_NAME_COLOUR = (40, 120, 197)
ROBOT_ORANGE_MIN_RED = 120  # lit orange: red high, green about half of it, little blue

CIRCLE = Twist()
CIRCLE.linear.x, CIRCLE.angular.z = 0.1, -0.5


# --- screenshots -------------------------------------------------------------
def near(image, colour, tolerance=COLOUR_TOLERANCE):
    """Boolean mask of the pixels within `tolerance` of `colour` on every channel."""
    return (numpy.abs(image - numpy.array(colour)).max(axis=2) <= tolerance)


def longest_run(flags):
    """(start, stop) of the longest run of True in a 1-D boolean array, or None."""
    best, start = None, None
    for index, flag in enumerate(list(flags) + [False]):
        if flag and start is None:
            start = index
        elif not flag and start is not None:
            if best is None or index - start > best[1] - best[0]:
                best = (start, index)
            start = None
    return best


def find_3d_view(image, background):
    """(top, bottom, left, right) of the 3D view: the largest block of rows and
    columns mostly in the configured background colour, or None."""
    mask = near(image, background, 2)
    columns = longest_run(mask.mean(axis=0) > 0.3)
    rows = longest_run(mask.mean(axis=1) > 0.3)
    if columns is None or rows is None or columns[1] - columns[0] < 200 or rows[1] - rows[0] < 200:
        return None
    return rows[0], rows[1], columns[0], columns[1]


class Frame(object):
    """One screenshot cut into what the checks look at."""

    def __init__(self, image, config):
        self.image = image
        self.view_box = find_3d_view(image, config.background)
        if self.view_box is None:
            self.view = self.panel = None
            return
        top, bottom, left, right = self.view_box
        self.view = image[top:bottom, left:right]
        self.panel = image[top:bottom, :left]  # the left dock: Displays (and Views)

    @property
    def rendered(self):
        return self.view is not None

    def colours(self):
        return len(numpy.unique(self.view.reshape(-1, 3), axis=0))

    def stddev(self):
        return float(self.view.std())

    def scan_pixels(self, config):
        return int(near(self.view, config.scan_colour, 30).sum())

    def robot_pixels(self):
        r, g, b = self.view[..., 0], self.view[..., 1], self.view[..., 2]
        return int(((r >= ROBOT_ORANGE_MIN_RED) & (g > 0.3 * r) & (g < 0.7 * r) & (b < 0.3 * r)).sum())

    def trail_pixels(self):
        """Red of the /odom arrows (and of the TF x axes, a constant)."""
        r, g, b = self.view[..., 0], self.view[..., 1], self.view[..., 2]
        return int(((r > 120) & (g < 0.25 * r) & (b < 0.25 * r)).sum())

    def camera_green_pixels(self):
        """The world file's pillar green in the left dock."""
        return green_pixels(self.panel)

    def status_pixels(self):
        """Pixels of the status colours in the column of the display names (where the OK
        names' blue starts), not in the icons left of it: a MarkerArray's icon has red dots."""
        columns = numpy.nonzero(near(self.panel, OK_NAME_COLOUR).any(axis=0))[0]
        names = self.panel[:, columns.min():] if len(columns) else self.panel
        return dict((name, int(near(names, colour).sum())) for name, colour in ERROR_COLOURS.items())

    def ok_name_pixels(self):
        return int(near(self.panel, OK_NAME_COLOUR).sum())

    def shows_robot_and_scan(self, config):
        return (self.rendered and self.colours() >= MIN_COLOURS
                and self.robot_pixels() >= MIN_ROBOT_PIXELS and self.scan_pixels(config) >= MIN_SCAN_PIXELS)


class RvizConfig(object):
    """The colours the checks need, read from demo.rviz itself."""

    def __init__(self, path):
        with open(path) as stream:
            config = yaml.safe_load(stream)
        manager = config['Visualization Manager']
        self.background = self._colour(manager['Global Options']['Background Color'])
        displays = dict((display['Class'], display) for display in manager['Displays'])
        self.displays = sorted(displays)
        scan = displays['rviz/LaserScan']
        if scan.get('Color Transformer') != 'FlatColor':
            raise ValueError('the test finds the scan by its flat colour; demo.rviz uses %r'
                             % scan.get('Color Transformer'))
        self.scan_colour = self._colour(scan['Color'])
        self.fixed_frame = manager['Global Options']['Fixed Frame']

    @staticmethod
    def _colour(text):
        return tuple(int(part) for part in str(text).split(';'))


class RvizRenders(unittest.TestCase):
    circle = CIRCLE  # what is driven for the trail: the tutorial's circle, 0.2 m across

    @classmethod
    def setUpClass(cls):
        cls.xvfb = cls.rviz = None
        cls.setup_error = None
        cls.frame = cls.driven = None
        cls.not_rendered = ''
        # The latest run's screenshots, overwritten by the next run.
        cls.shots = os.path.join(rospkg.get_ros_home(), 'test_results', 'tb3_sim_nav', 'rviz_renders')
        os.makedirs(cls.shots, exist_ok=True)
        started = time.monotonic()
        try:
            cls._run()
        except Exception as error:  # reported by every test, with its cause
            cls.setup_error = '%s: %s' % (type(error).__name__, error)
        finally:
            cls.rviz_output = cls.rviz.output(None) if cls.rviz else ''
            for child in (cls.rviz, cls.xvfb):
                if child is not None:
                    child.stop()
        report('rviz_renders', wall_seconds=time.monotonic() - started, screenshots=cls.shots)

    @classmethod
    def _run(cls):
        path = rospy.get_param('~rviz_config', '') or os.path.join(
            rospkg.RosPack().get_path('tb3_sim_bringup'), 'rviz', 'demo.rviz')
        cls.config = RvizConfig(path)
        cls.xvfb, display = start_xvfb(die_with_parent=True)
        os.environ.update(screen_env(display))  # rviz inherits it (Child passes the environment on)
        cls.rviz = Child(['rosrun', 'rviz', 'rviz', '-d', path])
        started = time.monotonic()
        frames = []

        def rendered():
            if not cls.rviz.running():
                raise AssertionError('rviz exited: %s' % cls.rviz.describe())
            frames[:] = [Frame(screenshot(display), cls.config)]
            return frames[0].shows_robot_and_scan(cls.config)
        if not wait_for(rendered, RENDER_TIMEOUT, poll=1.0):
            # Each test then judges this last screenshot and says what is missing.
            cls.frame = frames[0]
            cls.not_rendered = ('; rviz showed no robot and scan within %.0f s; rviz output:\n%s'
                                % (RENDER_TIMEOUT, cls.rviz.output()))
            save_png(cls.frame.image, os.path.join(cls.shots, 'not_rendered.png'))
            return
        cls.render_seconds = time.monotonic() - started
        time.sleep(SETTLE)
        cls.frame = Frame(screenshot(display), cls.config)
        save_png(cls.frame.image, os.path.join(cls.shots, 'settled.png'))

        # The tutorial's circle, published from here at 10 Hz for DRIVE_SECONDS of sim
        # time (on a busy machine the simulator runs slower than the wall clock, and
        # rviz draws later): the trail grows.
        publisher = rospy.Publisher('/cmd_vel', Twist, queue_size=1)
        wait_for(lambda: publisher.get_num_connections() > 0, 10.0)
        end, deadline = rospy.get_time() + DRIVE_SECONDS, time.monotonic() + DRIVE_TIMEOUT
        while rospy.get_time() < end and time.monotonic() < deadline and not rospy.is_shutdown():
            publisher.publish(cls.circle)
            time.sleep(0.1)
        publisher.publish(Twist())
        driven = []

        def trail_grown():
            driven[:] = [Frame(screenshot(display), cls.config)]
            return driven[0].trail_pixels() - cls.frame.trail_pixels() >= MIN_NEW_TRAIL_PIXELS
        time.sleep(1.0)
        wait_for(trail_grown, TRAIL_WITHIN, poll=1.0)
        cls.driven = driven[0]
        save_png(cls.driven.image, os.path.join(cls.shots, 'driven.png'))
        report('rviz_renders_frame', render_seconds=cls.render_seconds, colours=cls.frame.colours(),
               stddev=cls.frame.stddev(), robot_pixels=cls.frame.robot_pixels(),
               scan_pixels=cls.frame.scan_pixels(cls.config), trail_pixels_before=cls.frame.trail_pixels(),
               trail_pixels_after=cls.driven.trail_pixels(), ok_name_pixels=cls.frame.ok_name_pixels(),
               **dict(('%s_pixels' % name.lower(), count)
                      for name, count in cls.frame.status_pixels().items()))

    def setUp(self):
        if self.setup_error:
            self.fail(self.setup_error)

    def where(self):
        return ' (screenshots in %s)%s' % (self.shots, self.not_rendered)

    def rendered_frame(self):
        self.assertTrue(self.frame.rendered, 'no 3D view (no block of the background colour %s) '
                        'in the screenshot%s' % (self.config.background, self.where()))
        return self.frame

    def test_3d_view_is_not_blank(self):
        frame = self.rendered_frame()
        self.assertGreaterEqual(frame.colours(), MIN_COLOURS, 'colours in the 3D view' + self.where())
        self.assertGreaterEqual(frame.stddev(), MIN_STDDEV, 'variance of the 3D view' + self.where())

    def test_robot_model_is_visible(self):
        self.assertGreaterEqual(self.rendered_frame().robot_pixels(), MIN_ROBOT_PIXELS,
                                'the robot (its orange lidar) is not in the 3D view' + self.where())

    def test_scan_is_visible(self):
        self.assertGreaterEqual(self.rendered_frame().scan_pixels(self.config), MIN_SCAN_PIXELS,
                                'too few pixels of the scan colour %s in the 3D view%s'
                                % (self.config.scan_colour, self.where()))

    def test_no_display_in_error_or_warn_state(self):
        self.rendered_frame()
        for frame, when in ((self.frame, 'after start-up'), (self.driven, 'after driving')):
            if frame is None:
                continue
            self.assertGreaterEqual(frame.ok_name_pixels(), MIN_NAME_PIXELS,
                                    'no display names in the Displays panel %s%s' % (when, self.where()))
            self.assertEqual(frame.status_pixels(), dict((name, 0) for name in ERROR_COLOURS),
                             'a display shows an error or warning status %s%s' % (when, self.where()))

    def test_rviz_prints_no_error(self):
        errors = [line for line in self.rviz_output.splitlines() if '[ERROR]' in line]
        self.assertEqual(errors, [], 'rviz printed errors')

    def test_odometry_trail_grows_when_driving(self):
        self.assertIsNotNone(self.driven, 'the robot was not driven' + self.where())
        added = self.driven.trail_pixels() - self.frame.trail_pixels()
        self.assertGreaterEqual(added, MIN_NEW_TRAIL_PIXELS,
                                'driving added only %d red pixels of /odom arrows%s' % (added, self.where()))


class RvizCameraRenders(RvizRenders):
    """The same, and the camera image beside the 3D view. The Waffle (Pi) is
    0.27 m wide: on the tutorial's circle of 0.2 m it would cover its own trail."""
    circle = Twist()
    circle.linear.x, circle.angular.z = 0.2, -0.4

    def test_camera_image_is_shown_beside_the_3d_view(self):
        green = self.rendered_frame().camera_green_pixels()
        report('rviz_camera', camera_green_pixels=green)
        self.assertGreaterEqual(green, MIN_CAMERA_GREEN, 'the Camera panel shows no image of the pillars '
                                '(%d green pixels in the left dock)%s' % (green, self.where()))


if __name__ == '__main__':
    init_test_node('test_rviz_renders')
    camera = rospy.get_param('~camera', False)
    rostest.rosrun('tb3_sim_nav', 'rviz_renders', RvizCameraRenders if camera else RvizRenders)
