"""The navigation chapter, run as a learner runs it, measured: for `make demo DEMO_ARGS=--nav` and the tests.

A Navigation is this process's rospy side of it (the caller is a rospy node
following /clock): rviz's two tools as rviz sends them (2D Pose Estimate on
`initialpose`, with rviz's covariance; a goal through the `move_base`
action, as rbx1's scripts and 2D Nav Goal's move_base_simple/goal end up),
and the judge's view: the true path (base_pose_ground_truth), the plans,
the particle cloud's spread. Each goal's Outcome says how the action ended
and where the robot truly stood, and clearance() how close its footprint
came to the world's obstacles.
"""
import dataclasses
import math
import threading
import time

from .report import normalize, yaw_of

RVIZ_COVARIANCE = (0.25, 0.25, (math.pi / 12.0) ** 2)  # rviz's 2D Pose Estimate: x, y, yaw variances
STATES = {0: 'PENDING', 1: 'ACTIVE', 2: 'PREEMPTED', 3: 'SUCCEEDED', 4: 'ABORTED', 5: 'REJECTED',
          6: 'PREEMPTING', 7: 'RECALLING', 8: 'RECALLED', 9: 'LOST'}


@dataclasses.dataclass
class Outcome(object):
    """How one goal ended: the action's state and text, the sim time it took, the true pose at the end
    and its distance (m) and heading error (rad) to the goal, the truth's path meanwhile."""
    goal: tuple
    state: str
    text: str
    sim_seconds: float
    truth: tuple
    xy_error: float
    yaw_error: float
    path: list


class Navigation(object):
    """The rospy side: the move_base action client, initialpose, and recorders."""

    def __init__(self, namespace=''):
        import actionlib
        import rospy
        from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped
        from move_base_msgs.msg import MoveBaseAction
        from nav_msgs.msg import Odometry, Path
        prefix = namespace.rstrip('/') + '/' if namespace else ''
        self._lock = threading.Lock()
        self.truth = []      # [t, x, y, yaw]
        self.plans = []      # (t, [(x, y), ...])
        self.spreads = []    # (t, standard deviations of x and y (m), of yaw (rad), particles)
        self.clouds = []     # (t, [(x, y), ...]): a few clouds, for pictures
        self.amcl = []       # [t, x, y, yaw] of amcl_pose
        self._subscribers = [
            rospy.Subscriber(prefix + 'base_pose_ground_truth', Odometry, self._on_truth, queue_size=100),
            rospy.Subscriber(prefix + 'move_base/NavfnROS/plan', Path, self._on_plan, queue_size=10),
            rospy.Subscriber(prefix + 'particlecloud', PoseArray, self._on_cloud, queue_size=10),
            rospy.Subscriber(prefix + 'amcl_pose', PoseWithCovarianceStamped, self._on_amcl, queue_size=10)]
        self.initialpose = rospy.Publisher(prefix + 'initialpose', PoseWithCovarianceStamped, queue_size=1,
                                           latch=True)
        self.client = actionlib.SimpleActionClient(prefix + 'move_base', MoveBaseAction)
        self.map_frame = prefix + 'map'

    def close(self):
        for subscriber in self._subscribers:
            subscriber.unregister()
        self.initialpose.unregister()

    # --- recorders --------------------------------------------------------------------------
    def _on_truth(self, message):
        pose = message.pose.pose
        with self._lock:
            self.truth.append([message.header.stamp.to_sec(), pose.position.x, pose.position.y,
                               yaw_of(pose.orientation.x, pose.orientation.y, pose.orientation.z,
                                      pose.orientation.w)])

    def _on_plan(self, message):
        with self._lock:
            self.plans.append((message.header.stamp.to_sec(),
                               [(p.pose.position.x, p.pose.position.y) for p in message.poses]))

    def _on_cloud(self, message):
        import numpy as np
        from tb3_navigation.pose2d import normalize_angle
        poses = np.array([(p.position.x, p.position.y, yaw_of(p.orientation.x, p.orientation.y, p.orientation.z,
                                                                 p.orientation.w)) for p in message.poses])
        if not len(poses):
            return
        yaw = np.arctan2(np.sin(poses[:, 2]).mean(), np.cos(poses[:, 2]).mean())
        spread = (float(poses[:, 0].std()), float(poses[:, 1].std()),
                  float(np.sqrt(np.mean(normalize_angle(poses[:, 2] - yaw) ** 2))))
        with self._lock:
            self.spreads.append((message.header.stamp.to_sec(),) + spread + (len(poses),))
            if not self.clouds or message.header.stamp.to_sec() - self.clouds[-1][0] > 10.0:
                self.clouds.append((message.header.stamp.to_sec(), poses[:, :2].tolist()))

    def _on_amcl(self, message):
        pose = message.pose.pose
        with self._lock:
            self.amcl.append([message.header.stamp.to_sec(), pose.position.x, pose.position.y,
                              yaw_of(pose.orientation.x, pose.orientation.y, pose.orientation.z,
                                     pose.orientation.w)])

    def now_truth(self):
        with self._lock:
            return tuple(self.truth[-1]) if self.truth else None

    # --- rviz's tools -----------------------------------------------------------------------
    def wait_ready(self, timeout=60.0):
        """Until the action server answers and the truth is heard."""
        import rospy
        if not self.client.wait_for_server(rospy.Duration(timeout)):
            raise RuntimeError('no move_base action server within %.0f s' % timeout)
        deadline = time.monotonic() + timeout
        while self.now_truth() is None:
            if time.monotonic() > deadline:
                raise RuntimeError('no base_pose_ground_truth within %.0f s' % timeout)
            time.sleep(0.05)

    def set_pose(self, x, y, yaw, settle=2.0):
        """2D Pose Estimate at (x, y, yaw), as rviz sends it; then `settle` s of sim time."""
        import rospy
        from geometry_msgs.msg import PoseWithCovarianceStamped
        message = PoseWithCovarianceStamped()
        message.header.frame_id, message.header.stamp = self.map_frame, rospy.Time.now()
        message.pose.pose.position.x, message.pose.pose.position.y = x, y
        message.pose.pose.orientation.z, message.pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        covariance = [0.0] * 36
        covariance[0], covariance[7], covariance[35] = RVIZ_COVARIANCE
        message.pose.covariance = covariance
        self.initialpose.publish(message)
        rospy.sleep(settle)

    def send(self, x, y, yaw, frame=None):
        import rospy
        from move_base_msgs.msg import MoveBaseGoal
        goal = MoveBaseGoal()
        goal.target_pose.header.frame_id = self.map_frame if frame is None else frame
        goal.target_pose.header.stamp = rospy.Time.now()
        goal.target_pose.pose.position.x, goal.target_pose.pose.position.y = x, y
        goal.target_pose.pose.orientation.z, goal.target_pose.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
        self.client.send_goal(goal)
        return goal

    def go(self, x, y, yaw, timeout=120.0, cancel_after=None):
        """A goal sent and its Outcome (cancelled after `cancel_after` s of sim time, if given)."""
        import rospy
        start = rospy.get_time()
        first = len(self.truth)
        self.send(x, y, yaw)
        if cancel_after is not None:
            finished = self.client.wait_for_result(rospy.Duration(cancel_after))
            if not finished:
                self.client.cancel_goal()
        self.client.wait_for_result(rospy.Duration(timeout))
        took = rospy.get_time() - start
        truth = self.now_truth()
        with self._lock:
            path = [sample[:] for sample in self.truth[first:]]
        state = STATES.get(self.client.get_state(), str(self.client.get_state()))
        return Outcome((x, y, yaw), state, self.client.get_goal_status_text(), took, truth,
                       math.hypot(truth[1] - x, truth[2] - y), abs(normalize(truth[3] - yaw)), path)


def clearance(path, obstacles, footprint):
    """The least distance (m) from the robot's footprint (a polygon [(x, y)] in base_footprint)
    to the world's obstacles (world_file Obstacles cut at the lidar's height), along `path`
    ([t, x, y, yaw] samples): the judge's check that the robot never came too close."""
    import numpy as np
    from tb3_navigation.costmap import outline as footprint_outline
    from tb3_sim_nav.world_map import in_plane, signed_distance
    outline = footprint_outline(footprint, 0.01)
    cut = in_plane(obstacles)
    least = math.inf
    for sample in path:
        cos, sin = math.cos(sample[3]), math.sin(sample[3])
        points = np.stack((sample[1] + cos * outline[:, 0] - sin * outline[:, 1],
                           sample[2] + sin * outline[:, 0] + cos * outline[:, 1]), axis=-1)
        least = min(least, float(signed_distance(cut, points).min()))
    return least

