#!/usr/bin/env python3
"""Three TurtleBot3s in one world (multi_tb3.launch), checked on each one's ground truth.

multi_tb3.launch's defaults put three Burgers in turtlebot3_world: tb3_0 at
(-2.0, -0.5) and tb3_1 at (-2.0, 0.5), both facing +x, and tb3_2 at (-1.5, 1.6)
facing -0.8 rad. In turn:

1. each robot is at its spawn pose, and its topics and frames carry its name;
2. tf resolves per robot: tb3_N/odom -> tb3_N/base_scan, where the URDF puts
   base_scan (0.032 m behind base_footprint, 0.182 m up) on the true pose;
3. tb3_0's lidar sees tb3_1: the beam towards tb3_1's lidar housing (a
   cylinder of radius 0.055 m, 0.015 m ahead of its base_scan) reads the
   distance to it, about 0.95 m, where the wall beyond is 2.2 m away;
4. each robot driven alone moves alone (the others within 1 mm); then every
   link of tb3_1 (wheels turned) is where Debian's robot_state_publisher,
   run on tb3_1's description and joint states with tf_prefix `reference`,
   puts it: the simulator publishes each named robot's tree itself;
5. /gazebo/reset_world puts each robot back at its own spawn pose;
6. tb3_0 and tb3_1, turned to face each other and driven at 0.2 m/s for 6 s
   (1.2 m each, with 1 m between them), stop against each other: their
   base_footprints never come closer than their two front faces allow
   (0.038 m ahead of each, and further when turned; 1 cm of contact slop for
   two motors pushing), neither gets past the other, and in the last 2 s they
   still stand against each other. (Pushing on, they twist against each
   other, as two real robots would: their wheels' stall torque exceeds what
   the tyres can hold.)
"""
import math
import signal
import subprocess
import unittest
import xml.etree.ElementTree as ElementTree

import roslib.packages
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState, LaserScan
from std_srvs.srv import Empty

from tb3_test_utils import (
    GroundTruth,
    Repeater,
    init_test_node,
    report,
    turn_to,
    wait_for,
    wait_for_simulator,
    wall_budget,
    wrap,
)

SPAWN = {'tb3_0': (-2.0, -0.5, 0.0), 'tb3_1': (-2.0, 0.5, 0.0), 'tb3_2': (-1.5, 1.6, -0.8)}
ROBOTS = sorted(SPAWN)
SCAN_X, SCAN_Z = -0.032, 0.182      # base_scan in base_footprint (Burger URDF)
HOUSING_X, HOUSING_RADIUS = 0.015, 0.055  # the lidar housing's cylinder, in base_scan
FRONT_EXTENT = 0.038                # base_footprint to the Burger's front face
PENETRATION = 0.01                  # contact slop, two motors pushing
PUSH_SPEED, PUSH_SECONDS = 0.2, 6.0
CONTACT_WINDOW = 2.0                # sim s at the end of the push
CONTACT_DISTANCE = 0.12             # base_footprints closer than this: the robots touch


def scan_origin(pose):
    """(x, y) of a robot's base_scan, for its (x, y, yaw) on ground truth."""
    x, y, yaw = pose
    return x + SCAN_X * math.cos(yaw), y + SCAN_X * math.sin(yaw)


def triple(sample):
    return sample.x, sample.y, sample.yaw


class MultiRobot(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.truth = dict((name, GroundTruth('/%s/base_pose_ground_truth' % name)) for name in ROBOTS)
        cls.cmd_vel = dict((name, rospy.Publisher('/%s/cmd_vel' % name, Twist, queue_size=10)) for name in ROBOTS)
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.errors = {}
        cls.reference = None
        try:
            for phase in ('ready', 'tf', 'scan', 'alone', 'tree', 'reset', 'collision'):
                try:
                    getattr(cls, '_phase_' + phase)()
                except AssertionError as error:
                    cls.errors[phase] = str(error)
                    break
        finally:
            if cls.reference is not None:
                cls.reference.send_signal(signal.SIGINT)
                try:
                    cls.reference.wait(10.0)
                except subprocess.TimeoutExpired:
                    cls.reference.kill()
                    cls.reference.wait()
        for publisher in cls.cmd_vel.values():
            publisher.publish(Twist())

    def need(self, phase):
        if phase in self.errors or not hasattr(self, 'ran_' + phase):
            self.fail('phase %s did not run: %s' % (phase, self.errors or 'an earlier phase failed'))

    @classmethod
    def _rest(cls):
        rest = {}
        for name in ROBOTS:
            rest[name] = cls.truth[name].wait_at_rest(timeout=wall_budget(5.0))
            if rest[name] is None:
                raise AssertionError('%s did not come to rest' % name)
        return rest

    # --- phases ----------------------------------------------------------------
    @classmethod
    def _phase_ready(cls):
        cls.spawned = dict((name, wait_for_simulator(cls.truth[name], cls.cmd_vel[name])) for name in ROBOTS)
        cls.odom = dict((name, rospy.wait_for_message('/%s/odom' % name, Odometry, wall_budget(2.0)))
                        for name in ROBOTS)
        # Debian's robot_state_publisher on tb3_1's description (set by now) and
        # joint states, under another prefix: the tree the simulator publishes
        # must be its tree (phase tree).
        cls.reference = subprocess.Popen(
            [roslib.packages.find_node('robot_state_publisher', 'robot_state_publisher')[0],
             '__name:=reference_state_publisher', '__ns:=/tb3_1', '_tf_prefix:=reference'],
            stdin=subprocess.DEVNULL)
        cls.ran_ready = True

    @classmethod
    def _phase_tf(cls):
        cls.scan_transforms = {}
        cls.at_tf = cls._rest()
        for name in ROBOTS:
            try:
                cls.scan_transforms[name] = cls.buffer.lookup_transform(
                    '%s/odom' % name, '%s/base_scan' % name, rospy.Time(0), rospy.Duration(wall_budget(5.0)))
            except tf2_ros.TransformException as error:
                raise AssertionError('no tf %s/odom -> %s/base_scan: %s' % (name, name, error))
        cls.ran_tf = True

    @classmethod
    def _phase_scan(cls):
        cls.scan = rospy.wait_for_message('/tb3_0/scan', LaserScan, wall_budget(2.0))
        cls.ran_scan = True

    @classmethod
    def _phase_alone(cls):
        cls.moves = {}
        for driven in ROBOTS:
            before = cls._rest()
            forward = Twist()
            forward.linear.x = 0.1
            repeater = Repeater(cls.cmd_vel[driven], forward)
            try:
                cls.truth[driven].wait_sim(1.5)
            finally:
                repeater.stop()
                cls.cmd_vel[driven].publish(Twist())
            after = cls._rest()
            cls.moves[driven] = dict((name, math.hypot(after[name].x - before[name].x, after[name].y - before[name].y))
                                     for name in ROBOTS)
            report('driven_alone_' + driven, **cls.moves[driven])
        cls.ran_alone = True

    @classmethod
    def _phase_tree(cls):
        """tb3_1's links in its base_footprint, from the simulator's tf and from the reference's,
        at the stamp of one joint_states message (both stamp the wheels with it)."""
        urdf = ElementTree.fromstring(rospy.get_param('/tb3_1/robot_description'))
        links = sorted(joint.find('child').get('link') for joint in urdf.findall('joint'))
        states = rospy.wait_for_message('/tb3_1/joint_states', JointState, wall_budget(2.0))
        cls.wheel_angles = dict(zip(states.name, states.position))
        cls.tree = {}
        for link in links:
            pair = []
            for prefix in ('tb3_1', 'reference'):
                try:
                    pair.append(cls.buffer.lookup_transform('%s/base_footprint' % prefix, '%s/%s' % (prefix, link),
                                                            states.header.stamp,
                                                            rospy.Duration(wall_budget(5.0))).transform)
                except tf2_ros.TransformException as error:
                    raise AssertionError('no tf %s/base_footprint -> %s/%s at %s: %s'
                                         % (prefix, prefix, link, states.header.stamp.to_sec(), error))
            cls.tree[link] = pair
        cls.ran_tree = True

    @classmethod
    def _phase_reset(cls):
        rospy.wait_for_service('/gazebo/reset_world', wall_budget(2.0))
        rospy.ServiceProxy('/gazebo/reset_world', Empty)()
        cls.after_reset = {}
        for name in ROBOTS:
            back = wait_for(lambda: math.dist(triple(cls.truth[name].latest())[:2], SPAWN[name][:2]) < 0.002,
                            wall_budget(2.0))
            if not back:
                raise AssertionError('%s not back at its spawn pose after reset_world: %s'
                                     % (name, cls.truth[name].latest()))
        cls.after_reset = cls._rest()
        cls.ran_reset = True

    @classmethod
    def _phase_collision(cls):
        for name, heading in (('tb3_0', math.pi / 2), ('tb3_1', -math.pi / 2)):
            if not turn_to(cls.truth[name], cls.cmd_vel[name], heading, wall_budget(10.0)):
                raise AssertionError('%s could not turn to %.2f rad' % (name, heading))
        cls._rest()
        start = max(cls.truth[name].now() for name in ('tb3_0', 'tb3_1'))
        forward = Twist()
        forward.linear.x = PUSH_SPEED
        repeaters = [Repeater(cls.cmd_vel[name], forward) for name in ('tb3_0', 'tb3_1')]
        try:
            if not cls.truth['tb3_0'].wait_until(start + PUSH_SECONDS, wall_budget(PUSH_SECONDS)):
                raise AssertionError('ground truth stopped during the push')
        finally:
            for repeater in repeaters:
                repeater.stop()
        end = start + PUSH_SECONDS
        lower = dict((s.t, s) for s in cls.truth['tb3_0'].samples(start, end))
        upper = dict((s.t, s) for s in cls.truth['tb3_1'].samples(start, end))
        cls.pairs = [(lower[t], upper[t]) for t in sorted(set(lower) & set(upper))]
        if len(cls.pairs) < 100:
            raise AssertionError('only %d simultaneous samples of the two robots' % len(cls.pairs))
        cls.ran_collision = True

    # --- tests -----------------------------------------------------------------
    def test_each_robot_is_at_its_spawn_pose_with_its_own_frames(self):
        self.need('ready')
        for name in ROBOTS:
            x, y, yaw = triple(self.spawned[name])
            self.assertAlmostEqual(x, SPAWN[name][0], delta=0.01, msg=name)
            self.assertAlmostEqual(y, SPAWN[name][1], delta=0.01, msg=name)
            self.assertLess(abs(wrap(yaw - SPAWN[name][2])), math.radians(1.0), name)
            self.assertEqual(self.odom[name].header.frame_id, '%s/odom' % name)
            self.assertEqual(self.odom[name].child_frame_id, '%s/base_footprint' % name)

    def test_tf_resolves_per_robot_from_odom_to_base_scan(self):
        self.need('tf')
        for name in ROBOTS:
            translation = self.scan_transforms[name].transform.translation
            expected = scan_origin(triple(self.at_tf[name]))
            self.assertAlmostEqual(translation.x, expected[0], delta=0.005, msg=name)
            self.assertAlmostEqual(translation.y, expected[1], delta=0.005, msg=name)
            self.assertAlmostEqual(translation.z, SCAN_Z, delta=0.005, msg=name)

    def test_the_lidar_of_tb3_0_sees_tb3_1(self):
        self.need('scan')
        observer, target = triple(self.spawned['tb3_0']), triple(self.spawned['tb3_1'])
        origin = scan_origin(observer)
        housing = scan_origin(target)
        housing = (housing[0] + HOUSING_X * math.cos(target[2]), housing[1] + HOUSING_X * math.sin(target[2]))
        bearing = math.atan2(housing[1] - origin[1], housing[0] - origin[0]) - observer[2]
        beam = int(round(wrap(bearing) / self.scan.angle_increment)) % len(self.scan.ranges)
        expected = math.dist(origin, housing) - HOUSING_RADIUS
        got = self.scan.ranges[beam]
        report('tb3_0_sees_tb3_1', beam=beam, expected_m=expected, got_m=got)
        self.assertEqual(self.scan.header.frame_id, 'tb3_0/base_scan')
        self.assertTrue(math.isfinite(got), 'beam %d reads %r: tb3_1 is not seen' % (beam, got))
        self.assertAlmostEqual(got, expected, delta=0.04, msg='beam %d' % beam)

    def test_each_robot_driven_alone_moves_alone(self):
        self.need('alone')
        for driven, moves in self.moves.items():
            self.assertGreater(moves[driven], 0.1, '%s did not move when driven' % driven)
            for name, moved in moves.items():
                if name != driven:
                    self.assertLess(moved, 0.001, '%s moved %.4f m while %s was driven' % (name, moved, driven))

    def test_each_link_is_where_robot_state_publisher_puts_it(self):
        self.need('tree')
        turned = [name for name, angle in self.wheel_angles.items() if abs(angle) > 0.5]
        self.assertEqual(len(turned), 2, 'the wheels did not turn: %s' % self.wheel_angles)
        self.assertGreaterEqual(len(self.tree), 6)
        for link, (ours, reference) in self.tree.items():
            for field in ('translation', 'rotation'):
                a, b = getattr(ours, field), getattr(reference, field)
                keys = 'xyz' if field == 'translation' else 'xyzw'
                sign = -1.0 if field == 'rotation' and sum(getattr(a, k) * getattr(b, k) for k in keys) < 0 else 1.0
                for key in keys:
                    self.assertAlmostEqual(getattr(a, key), sign * getattr(b, key), delta=1e-6,
                                           msg='%s %s.%s: %s against %s' % (link, field, key, a, b))

    def test_reset_world_puts_each_robot_back_at_its_own_spawn_pose(self):
        self.need('reset')
        for name in ROBOTS:
            x, y, yaw = triple(self.after_reset[name])
            self.assertAlmostEqual(x, SPAWN[name][0], delta=0.002, msg=name)
            self.assertAlmostEqual(y, SPAWN[name][1], delta=0.002, msg=name)
            self.assertLess(abs(wrap(yaw - SPAWN[name][2])), math.radians(0.2), name)

    def test_two_robots_driven_into_each_other_stop_without_passing_through(self):
        self.need('collision')
        distances = [math.hypot(upper.x - lower.x, upper.y - lower.y) for lower, upper in self.pairs]
        closest = min(distances)
        end_time = self.pairs[-1][0].t
        end = [d for (lower, _), d in zip(self.pairs, distances) if lower.t >= end_time - CONTACT_WINDOW]
        report('collision', start_distance=distances[0], closest=closest, end_min=min(end), end_max=max(end),
               end_yaw_0_deg=math.degrees(self.pairs[-1][0].yaw), end_yaw_1_deg=math.degrees(self.pairs[-1][1].yaw))
        self.assertGreaterEqual(closest, 2 * FRONT_EXTENT - PENETRATION,
                                'base_footprints %.3f m apart: the robots went into each other' % closest)
        swapped = [lower.t for lower, upper in self.pairs if upper.y <= lower.y]
        self.assertFalse(swapped, 'tb3_0 got past tb3_1 at t = %s' % swapped[:1])
        self.assertLess(max(end), CONTACT_DISTANCE, 'they parted: %.3f m apart in the last %.0f s'
                        % (max(end), CONTACT_WINDOW))


if __name__ == '__main__':
    init_test_node('test_multi_tb3')
    rostest.rosrun('tb3_sim_nav', 'multi_tb3', MultiRobot)
