#!/usr/bin/env python3
"""A goal box for the robot to reach, placed as ROBOTIS' machine-learning stages
place theirs, through Gazebo's interface only (rospy and gazebo_msgs): the same
script runs under Gazebo.

    rosrun tb3_sim_nav goal_box.py      # with a simulator running

It spawns a small red box named `goal` (to see, not to hit: it has no
collision) ~side metres ahead of the robot with /gazebo/spawn_sdf_model,
reads the robot's pose on /gazebo/model_states, and each time the robot
comes within ~reach of the goal, moves the goal with /gazebo/set_model_state
to the next corner of a square on the robot's left. Ctrl+C deletes it with
/gazebo/delete_model.

Private parameters: ~robot, the robot's model name (default
turtlebot3_$TURTLEBOT3_MODEL, else turtlebot3_burger); ~side (1.0 m);
~reach (0.2 m).
"""
import math
import os
import signal
import sys

import rospy
from gazebo_msgs.msg import ModelState, ModelStates
from gazebo_msgs.srv import DeleteModel, SetModelState, SpawnModel
from geometry_msgs.msg import Pose

from tb3_common.ros.poses import plane_pose

GOAL = 'goal'
GOAL_SDF = """<?xml version="1.0"?>
<sdf version="1.6">
  <model name="goal">
    <static>true</static>
    <link name="goal">
      <visual name="goal">
        <geometry><box><size>0.15 0.15 0.15</size></box></geometry>
        <material><diffuse>1 0 0 1</diffuse></material>
      </visual>
    </link>
  </model>
</sdf>
"""
SERVICE_WAIT = 30.0   # s for Gazebo's services to appear

quit_requested = False


def request_quit(signal_number, frame):
    global quit_requested
    quit_requested = True


class RobotPose(object):
    """The robot's (x, y, yaw) from /gazebo/model_states: the callback only stores it."""

    def __init__(self, robot):
        self.robot = robot
        self.names = []
        self.pose = None
        rospy.Subscriber('/gazebo/model_states', ModelStates, self.on_states, queue_size=1)

    def on_states(self, states):
        self.names = list(states.name)
        if self.robot in states.name:
            self.pose = plane_pose(states.pose[states.name.index(self.robot)])


def corners(start, side):
    """The four corners of a square of `side` on the left of the robot's start pose, ahead first."""
    x, y, yaw = start
    ahead, left = (math.cos(yaw), math.sin(yaw)), (-math.sin(yaw), math.cos(yaw))
    return [(x + side * (a * ahead[0] + b * left[0]), y + side * (a * ahead[1] + b * left[1]))
            for a, b in ((1, 0), (1, 1), (0, 1), (0, 0))]


def nap(rate):
    """rate.sleep(), through a reset_simulation's jump of sim time back to zero."""
    try:
        rate.sleep()
    except rospy.ROSTimeMovedBackwardsException:
        pass


def pose_at(x, y):
    pose = Pose()
    pose.position.x, pose.position.y, pose.position.z = x, y, 0.075
    pose.orientation.w = 1.0
    return pose


def main():
    rospy.init_node('goal_box', disable_signals=True)  # Ctrl+C is ours: delete the goal first
    robot = rospy.get_param('~robot', 'turtlebot3_' + (os.environ.get('TURTLEBOT3_MODEL') or 'burger'))
    side, reach = float(rospy.get_param('~side', 1.0)), float(rospy.get_param('~reach', 0.2))
    for signal_number in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signal_number, request_quit)
    try:
        for name in ('/gazebo/spawn_sdf_model', '/gazebo/set_model_state', '/gazebo/delete_model'):
            rospy.wait_for_service(name, SERVICE_WAIT)
    except rospy.ROSException:
        print('goal_box: no Gazebo services (%s): start a simulator first' % name, file=sys.stderr)
        return 1
    spawn = rospy.ServiceProxy('/gazebo/spawn_sdf_model', SpawnModel)
    move = rospy.ServiceProxy('/gazebo/set_model_state', SetModelState)
    delete = rospy.ServiceProxy('/gazebo/delete_model', DeleteModel)

    robot_pose = RobotPose(robot)
    rate = rospy.Rate(10)
    while robot_pose.pose is None and not quit_requested:
        if robot_pose.names:
            print('goal_box: no model named %s; the models are %s (set ~robot)'
                  % (robot, ', '.join(robot_pose.names)), file=sys.stderr)
            return 1
        nap(rate)
    if quit_requested:
        return 0
    if GOAL in robot_pose.names:  # left behind by an earlier run, as ROBOTIS' respawn checks
        delete(GOAL)

    goals = corners(robot_pose.pose, side)
    answer = spawn(model_name=GOAL, model_xml=GOAL_SDF, robot_namespace='', initial_pose=pose_at(*goals[0]),
                   reference_frame='world')
    if not answer.success:
        print('goal_box: cannot spawn the goal: %s' % answer.status_message, file=sys.stderr)
        return 1
    print('goal at (%.2f, %.2f): drive %s there' % (goals[0] + (robot,)), flush=True)
    reached = 0
    try:
        while not quit_requested and not rospy.is_shutdown():
            x, y, _ = robot_pose.pose
            goal = goals[reached % len(goals)]
            if math.hypot(goal[0] - x, goal[1] - y) < reach:
                reached += 1
                goal = goals[reached % len(goals)]
                answer = move(ModelState(model_name=GOAL, pose=pose_at(*goal), reference_frame='world'))
                print('goal %d reached; the next one is at (%.2f, %.2f)%s'
                      % (reached, goal[0], goal[1], '' if answer.success else ': ' + answer.status_message),
                      flush=True)
            nap(rate)
    finally:
        answer = delete(GOAL)
        print('goal deleted' if answer.success else 'goal not deleted: %s' % answer.status_message, flush=True)
        rospy.signal_shutdown('goal_box done')
    return 0


if __name__ == '__main__':
    sys.exit(main())
