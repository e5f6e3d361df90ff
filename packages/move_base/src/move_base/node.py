"""The move_base node: move_base's interface over tb3_navigation's planner, controller and state machine.

    rosrun move_base move_base      (tb3_navigation.launch starts it with TurtleBot3's param files)

The action `move_base` (move_base_msgs/MoveBaseAction: goal, cancel,
status, feedback, result) and `move_base_simple/goal` (rviz's 2D Nav Goal,
turned into an action goal as move_base does); `cmd_vel` out; the global
plan on `~NavfnROS/plan`, the local plan on `~DWAPlannerROS/local_plan`,
the costmaps and footprints (costmap_io); services `~make_plan` and
`~clear_costmaps`. In: the `map` (latched, from map_server or a SLAM),
`scan` for both costmaps, `odom` for the robot's speed, tf map ->
base_footprint and odom -> base_footprint.

One loop at controller_frequency of sim time does everything in turn:
costmaps updated with the newest scan (the scan callback only stores it),
one step of the state machine, the command published, then the plans and
costmaps. The action's callbacks hand goals and cancels to the state
machine under a lock. Nothing non-finite is ever published on cmd_vel.
"""
import threading

import actionlib
import rospy
from actionlib.goal_id_generator import GoalIDGenerator
from geometry_msgs.msg import PoseStamped, Twist
from move_base_msgs.msg import MoveBaseAction, MoveBaseActionGoal, MoveBaseFeedback, MoveBaseGoal, MoveBaseResult
from nav_msgs.msg import OccupancyGrid, Odometry, Path
from nav_msgs.srv import GetPlan, GetPlanResponse
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty, EmptyResponse

from tb3_navigation.controller import DwaConfig, DwaController
from tb3_navigation.costmap import GLOBAL_COSTMAP, LOCAL_COSTMAP
from tb3_navigation.navigator import ABORTED, PREEMPTED, SUCCEEDED, Navigator, NavigatorConfig
from tb3_navigation.planner import GlobalPlanner, PlannerConfig
from tb3_common.pose2d import compose, inverse, quaternion_of_yaw, yaw_of_quaternion
from tb3_navigation.scan import Scan
from tb3_common.ros import lifecycle, params
from .costmap_io import CostmapIO
from tb3_common.ros.frames import Frames
from tb3_common.ros.map_messages import grid_of_message

NODE = 'move_base'


def _pose_stamped(pose, frame, stamp):
    message = PoseStamped()
    message.header.frame_id, message.header.stamp = frame, stamp
    message.pose.position.x, message.pose.position.y = pose[0], pose[1]
    (message.pose.orientation.x, message.pose.orientation.y, message.pose.orientation.z,
     message.pose.orientation.w) = quaternion_of_yaw(pose[2])
    return message


def _path(poses, frame, stamp):
    path = Path()
    path.header.frame_id, path.header.stamp = frame, stamp
    path.poses = [_pose_stamped(pose, frame, stamp) for pose in poses]
    return path


def _xyz_quaternion(pose):
    p, q = pose.position, pose.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


class MoveBaseNode(object):

    def __init__(self):
        self.frames = Frames(NODE)
        self.global_io = CostmapIO(NODE, 'global_costmap', GLOBAL_COSTMAP)
        self.local_io = CostmapIO(NODE, 'local_costmap', LOCAL_COSTMAP)
        self.base_frame = self.global_io.base_frame
        self.config = params.read_or_exit(NODE, NavigatorConfig, overrides={'global_frame': self.global_io.frame})
        planner = GlobalPlanner(params.read_or_exit(NODE, PlannerConfig, 'NavfnROS'))
        self.dwa = params.read_or_exit(NODE, DwaConfig, 'DWAPlannerROS')
        controller = DwaController(self.local_io.costmap, self.dwa)
        self.navigator = Navigator(self.config, planner, controller, None, self.local_io.costmap)
        self._lock = threading.Lock()  # the state machine and costmaps, between the loop and the callbacks
        self._scan = None       # the newest scan not yet marked into the costmaps
        self._sensors = {}
        self._velocity = (0.0, 0.0)
        self.cmd_pub = rospy.Publisher('cmd_vel', Twist, queue_size=1)
        self.plan_pub = rospy.Publisher('~NavfnROS/plan', Path, queue_size=1, latch=True)
        self.local_plan_pub = rospy.Publisher('~DWAPlannerROS/local_plan', Path, queue_size=1)
        self.goal_pub = rospy.Publisher('~current_goal', PoseStamped, queue_size=1, latch=True)
        self.action_goal_pub = rospy.Publisher('~goal', MoveBaseActionGoal, queue_size=1)
        self._ids = GoalIDGenerator()
        self.server = actionlib.SimpleActionServer(rospy.get_name(), MoveBaseAction, auto_start=False)
        self.server.register_goal_callback(self._on_goal)
        self.server.register_preempt_callback(self._on_preempt)
        rospy.Subscriber('map', OccupancyGrid, self._on_map, queue_size=1)
        rospy.Subscriber('scan', LaserScan, self._on_scan, queue_size=1)
        rospy.Subscriber('odom', Odometry, self._on_odom, queue_size=1)
        rospy.Subscriber('move_base_simple/goal', PoseStamped, self._on_simple_goal, queue_size=1)
        rospy.Service('~make_plan', GetPlan, self._on_make_plan)
        rospy.Service('~clear_costmaps', Empty, self._on_clear_costmaps)
        self.server.start()
        rospy.loginfo('%s: frames %s and %s, robot %s; waiting for a map on %s', NODE, self.global_io.frame,
                      self.local_io.frame, self.base_frame, rospy.resolve_name('map'))

    # --- inputs: each callback stores or hands over, the loop does the work ---------------------
    def _on_map(self, message):
        grid, values, _ = grid_of_message(message)
        with self._lock:
            self.global_io.set_map(grid, values)
            self.navigator.global_costmap = self.global_io.costmap
        rospy.loginfo('%s: map of %d x %d cells at %.3f m in the global costmap', NODE, grid.width, grid.height,
                      grid.resolution)

    def _on_scan(self, message):
        self._scan = message

    def _on_odom(self, message):
        self._velocity = (message.twist.twist.linear.x, message.twist.twist.angular.z)

    def _on_simple_goal(self, message):
        """rviz's 2D Nav Goal: an action goal, as move_base re-sends it."""
        goal = MoveBaseActionGoal()
        goal.header.stamp = rospy.Time.now()
        goal.goal_id = self._ids.generate_ID()
        goal.goal = MoveBaseGoal(target_pose=message)
        self.action_goal_pub.publish(goal)

    def _on_goal(self):
        goal = self.server.accept_new_goal()
        target = goal.target_pose
        position, orientation = _xyz_quaternion(target.pose)
        with self._lock:
            outcomes = self.navigator.set_goal(rospy.get_time(), position, orientation, target.header.frame_id,
                                               self._frame_in_global)
        for outcome in outcomes:
            if outcome.status == ABORTED:
                rospy.logerr('%s: %s', NODE, outcome.text)
                self.server.set_aborted(MoveBaseResult(), outcome.text)
        if self.navigator.active:
            rospy.loginfo('%s: new goal (%.2f, %.2f, %.2f) in %s', NODE, *(self.navigator.goal + (self.global_io.frame,)))
            self.goal_pub.publish(_pose_stamped(self.navigator.goal, self.global_io.frame, rospy.Time.now()))

    def _on_preempt(self):
        """A cancel, or a new goal about to replace this one (accept_new_goal then preempts it)."""
        with self._lock:
            outcome = self.navigator.cancel()
        if outcome is not None and self.server.is_active():
            self.server.set_preempted(MoveBaseResult(), outcome.text)

    def _frame_in_global(self, frame):
        return self.frames.pose(self.global_io.frame, frame.lstrip('/'), rospy.Time(0))

    def _on_make_plan(self, request):
        with self._lock:
            if self.navigator.active:
                raise rospy.ServiceException('move_base must be in an inactive state to make a plan for an external '
                                             'user')
            if self.navigator.global_costmap is None:
                raise rospy.ServiceException('no map yet')
        ends = []
        for stamped in (request.start, request.goal):
            frame = stamped.header.frame_id.lstrip('/')
            if stamped is request.start and not frame:  # no start: the robot's pose
                ends.append(self.frames.pose(self.global_io.frame, self.base_frame, rospy.Time(0)))
                continue
            offset = self._frame_in_global(frame) if frame and frame != self.global_io.frame else (0.0, 0.0, 0.0)
            p, q = _xyz_quaternion(stamped.pose)
            ends.append(None if offset is None else tuple(compose(offset, (p[0], p[1], yaw_of_quaternion(*q)))))
        if None in ends:
            raise rospy.ServiceException('make_plan: the start or the goal cannot be put in %s' % self.global_io.frame)
        with self._lock:
            plan = self.navigator.make_plan(ends[0], ends[1], max(0.0, request.tolerance))
        return GetPlanResponse(plan=_path(plan or [], self.global_io.frame, rospy.Time.now()))

    def _on_clear_costmaps(self, _request):
        with self._lock:
            self.navigator.clear_costmaps()
        rospy.loginfo('%s: costmaps cleared', NODE)
        return EmptyResponse()

    # --- the loop -------------------------------------------------------------------------
    def _sensor_pose(self, frame):
        if frame not in self._sensors:
            pose = self.frames.pose(self.base_frame, frame, rospy.Time(0), timeout=1.0)
            if pose is None:
                return None
            self._sensors[frame] = pose
        return self._sensors[frame]

    def cycle(self):
        now, stamp = rospy.get_time(), rospy.Time.now()
        in_global = self.frames.pose(self.global_io.frame, self.base_frame, rospy.Time(0))
        in_local = self.frames.pose(self.local_io.frame, self.base_frame, rospy.Time(0))
        message, self._scan = self._scan, None
        scan = sensor = None
        if message is not None:
            sensor = self._sensor_pose(message.header.frame_id)
            scan = Scan.from_message(message) if sensor is not None else None
        with self._lock:
            if in_global is None or in_local is None or self.navigator.global_costmap is None:
                if self.navigator.global_costmap is None and self.navigator.active:
                    self.frames.warn('no map', 'a goal but no map on %s yet: holding still', rospy.resolve_name('map'))
                # Nothing to steer by: the state machine holds the robot still (a non-finite pose).
                step = self.navigator.step(now, (float('nan'),) * 3, self._velocity) if self.navigator.active else None
            else:
                self.local_io.update(now, in_local, scan, sensor)
                self.global_io.update(now, in_global, scan, sensor)
                global_in_local = tuple(compose(in_local, inverse(in_global)))
                step = self.navigator.step(now, in_global, self._velocity, global_in_local)
            active = self.navigator.active
        if step is not None and step.cmd is not None:
            twist = Twist()
            twist.linear.x, twist.angular.z = step.cmd  # the state machine gives finite numbers only
            self.cmd_pub.publish(twist)
        if step is not None:
            self._report(step, stamp, active, in_global)
        if in_global is not None:
            self.global_io.publish(now, stamp, in_global)
        if in_local is not None:
            self.local_io.publish(now, stamp, in_local)

    def _report(self, step, stamp, active, pose):
        if step.plan:
            self.plan_pub.publish(_path(step.plan, self.global_io.frame, stamp))
        if step.local_plan is not None and len(step.local_plan):
            self.local_plan_pub.publish(_path(step.local_plan, self.local_io.frame, stamp))
        if step.recovery:
            rospy.logwarn('%s: recovery behaviour %s (%s)', NODE, step.recovery, self.navigator.recovery_reason)
        outcome = step.outcome
        if outcome is not None and self.server.is_active():
            if outcome.status == SUCCEEDED:
                rospy.loginfo('%s: %s', NODE, outcome.text)
                self.server.set_succeeded(MoveBaseResult(), outcome.text)
            elif outcome.status == ABORTED:
                rospy.logerr('%s: %s', NODE, outcome.text)
                self.server.set_aborted(MoveBaseResult(), outcome.text)
            elif outcome.status == PREEMPTED:
                self.server.set_preempted(MoveBaseResult(), outcome.text)
        elif active and pose is not None and self.server.is_active():
            self.server.publish_feedback(MoveBaseFeedback(base_position=_pose_stamped(pose, self.global_io.frame,
                                                                                    stamp)))

    def run(self, life):
        """A cycle every 1 / controller_frequency s of sim time, until the node is asked to end."""
        period = 1.0 / self.config.controller_frequency
        while not life.stopping:
            started = rospy.get_time()
            self.cycle()
            if not life.sleep_sim(max(0.0, started + period - rospy.get_time())):
                break


def main():
    life = lifecycle.init_node(NODE)
    node = MoveBaseNode()
    node.run(life)
    life.finish()
