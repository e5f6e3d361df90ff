"""The ROS edge's message filling and robot list, without a master."""
import math
from types import SimpleNamespace

import numpy as np
import rospy

from tb3_sim_nav.params import resolve
from tb3_sim_nav.ros import messages
from tb3_sim_nav.ros.node import robot_specs
from tb3_sim_nav.sensors import ImuReading
from tb3_sim_nav.world_file import RobotSpec, WorldSpec

STAMP = rospy.Time(12, 340000000)
POSE = ((1.0, -2.0, 0.0), (0.0, 0.0, math.sin(0.25), math.cos(0.25)))
TWIST = ((0.2, 0.0, 0.0), (0.0, 0.0, -0.5))


def test_odom_carries_frames_gazebos_covariance_pose_and_twist():
    odom = messages.odometry('tb3_0/odom', 'tb3_0/base_footprint')
    messages.fill_odometry(odom, STAMP, POSE, TWIST)
    assert (odom.header.frame_id, odom.child_frame_id) == ('tb3_0/odom', 'tb3_0/base_footprint')
    assert odom.header.stamp == STAMP
    pose, twist = odom.pose.pose, odom.twist.twist
    assert (pose.position.x, pose.position.y, pose.orientation.z, pose.orientation.w) == (
        1.0, -2.0, math.sin(0.25), math.cos(0.25))
    assert (twist.linear.x, twist.angular.z) == (0.2, -0.5)
    diagonal = [odom.pose.covariance[index * 7] for index in range(6)]
    assert diagonal == list(messages.ODOM_COVARIANCE) == [odom.twist.covariance[index * 7] for index in range(6)]
    assert sum(odom.pose.covariance) == sum(messages.ODOM_COVARIANCE)  # nothing off the diagonal


def test_ground_truth_claims_no_covariance():
    assert not any(messages.odometry('odom', 'base_footprint', covariance=False).pose.covariance)


def test_the_transform_is_the_pose_with_the_same_stamp():
    transform = messages.transform('odom', 'base_footprint')
    messages.fill_transform(transform, STAMP, POSE)
    assert transform.header.stamp == STAMP and transform.child_frame_id == 'base_footprint'
    assert (transform.transform.translation.x, transform.transform.rotation.w) == (1.0, math.cos(0.25))


def test_joint_states_name_the_wheel_joints():
    joints = messages.joint_states()
    messages.fill_joint_states(joints, STAMP, [1.0, 2.0], [0.5, -0.5])
    assert joints.name == ['wheel_left_joint', 'wheel_right_joint']
    assert (joints.position, joints.velocity, joints.header.stamp) == ([1.0, 2.0], [0.5, -0.5], STAMP)


def test_a_scan_covers_the_full_turn_of_the_lidar():
    lidar = SimpleNamespace(samples=360, angle_increment=2 * math.pi / 360, range_min=0.12, range_max=3.5)
    scan = messages.scan('base_scan', lidar, 5.0)
    messages.fill_scan(scan, STAMP, np.full(360, math.inf))
    assert scan.angle_min == 0.0 and scan.angle_max == math.radians(359)
    assert scan.scan_time == 0.2 and (scan.range_min, scan.range_max) == (0.12, 3.5)
    assert len(scan.ranges) == 360 and scan.header.frame_id == 'base_scan'


def test_imu_covariances_follow_the_noise_with_a_floor():
    imu = messages.imu('imu_link', 0.02, 0.0)
    messages.fill_imu(imu, STAMP, ImuReading((0, 0, 0, 1), (0.0, 0.0, 1.0), (0.0, 0.0, 9.81)))
    assert imu.angular_velocity_covariance[0] == 0.02 ** 2
    assert imu.linear_acceleration_covariance[0] == 1e-6  # no noise still claims no perfect sensor
    assert (imu.angular_velocity.z, imu.linear_acceleration.z) == (1.0, 9.81)


def test_the_robots_are_the_tutorials_one_or_those_listed_then_the_worlds(burger_urdf):
    listed = [dict(name='tb3_0', model='burger', position=[1, 2], yaw=0.5)]
    world = WorldSpec([], [RobotSpec('guest', 'waffle', (3.0, 3.0, 0.0), 0.0)])
    single = resolve(lambda name, default: dict(model=str(burger_urdf), x_pos=-2.0).get(name, default))
    multi = resolve(lambda name, default: dict(robots=listed).get(name, default))
    assert robot_specs(single, world) == [RobotSpec('', str(burger_urdf), (-2.0, 0.0, 0.0), 0.0), world.robots[0]]
    assert robot_specs(multi, world) == [RobotSpec('tb3_0', 'burger', (1.0, 2.0, 0.0), 0.5), world.robots[0]]
