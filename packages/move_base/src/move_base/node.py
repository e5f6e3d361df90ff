"""The move_base node: move_base's interface over tb3_navigation's planner, controller and state machine.

    rosrun move_base move_base      (tb3_navigation.launch starts it with TurtleBot3's param files)

The action `move_base` (move_base_msgs/MoveBaseAction: goal, cancel,
status, feedback, result) and `move_base_simple/goal` (rviz's 2D Nav Goal,
turned into an action goal as move_base does); `cmd_vel` out; the global
plan on `~NavfnROS/plan` (or `~GlobalPlanner/plan`), the local plan and the
part of the global plan it follows on `~DWAPlannerROS/local_plan` and
`global_plan` (or `~TrajectoryPlannerROS/...`), the costmaps and footprints
(costmap_io); services `~make_plan` and `~clear_costmaps`. In: each static
costmap's map (`map`, latched, from map_server or a SLAM), the scans of the
costmaps' observation sources (`scan`), `odom` for the robot's speed, tf
from each costmap's frame to the robot's. Parameters as move_base and its
plugins read them (move_base.settings); live ones through
dynamic_reconfigure (move_base.live).

One loop at controller_frequency of sim time does everything in turn:
costmaps updated with the newest scans (the scan callbacks only store them),
one step of the state machine, the command published, then the plans and
costmaps. The action's callbacks hand goals and cancels to the state
machine under a lock. Nothing non-finite is ever published on cmd_vel.
"""
import sys
import threading

import actionlib
import rospy
import tf2_ros
from actionlib.goal_id_generator import GoalIDGenerator
from geometry_msgs.msg import PoseStamped, Twist
from move_base_msgs.msg import MoveBaseAction, MoveBaseActionGoal, MoveBaseFeedback, MoveBaseGoal, MoveBaseResult
from nav_msgs.msg import Odometry, Path
from nav_msgs.srv import GetPlan, GetPlanResponse
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty, EmptyResponse

from tb3_common.params import ParameterError
from tb3_common.pose2d import compose, inverse, yaw_of_quaternion
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import Frames
from tb3_common.ros.map_messages import MapMessage, grid_of_message
from tb3_common.ros.poses import plane_pose, pose_stamped
from tb3_navigation.controller import DwaController
from tb3_navigation.navigator import ABORTED, PREEMPTED, SUCCEEDED, Navigator
from tb3_navigation.planner import GlobalPlanner
from tb3_navigation.scan import Scan

from . import live
from . import settings as move_base_settings
from .costmap_io import CostmapIO

NODE = 'move_base'


def _path(poses, frame, stamp):
    path = Path()
    path.header.frame_id, path.header.stamp = frame, stamp
    path.poses = [pose_stamped(pose, frame, stamp) for pose in poses]
    return path


def _xyz_quaternion(pose):
    p, q = pose.position, pose.orientation
    return (p.x, p.y, p.z), (q.x, q.y, q.z, q.w)


def _read(config_class, namespace, values, unhonoured):
    """move_base.settings' `read`: the config checked, named with its namespace if refused, and logged."""
    try:
        move_base_settings.construct(config_class, namespace, values)
    except ParameterError as error:
        _refuse(error)
    return params.read_or_exit(NODE, config_class, namespace, overrides=values, unhonoured=unhonoured)


def _refuse(error):
    rospy.logfatal('%s cannot start: %s', NODE, error)
    rospy.signal_shutdown('bad parameter')
    sys.exit(2)


class MoveBaseNode(object):

    def __init__(self):
        self.name, self.frames = NODE, Frames(NODE)
        namespace = rospy.get_namespace()
        try:
            resolved = move_base_settings.resolve(move_base_settings.Parameters(rospy.get_param('~', {})), _read)
        except ParameterError as error:
            _refuse(error)
        for note in resolved.notes + resolved.global_costmap.notes + resolved.local_costmap.notes:
            rospy.logwarn('%s: %s', NODE, note)
        self.resolved = resolved
        self.global_io = CostmapIO(resolved.global_costmap, namespace)
        self.local_io = CostmapIO(resolved.local_costmap, namespace)
        self.base_frame = self.global_io.base_frame
        self.config = resolved.navigator.replace(global_frame=self.global_io.frame)
        self.controller = DwaController(self.local_io.costmap, resolved.dwa)
        self.navigator = Navigator(self.config, GlobalPlanner(resolved.planner), self.controller,
                                   self.global_io.costmap, self.local_io.costmap, resolved.rotation)
        self.lock = threading.Lock()  # the state machine and costmaps, between the loop and the callbacks
        self._scans = {}        # topic -> (number, the newest scan message)
        self._converted = {}    # topic -> (number, Scan, sensor pose) of the newest scan the loop has read
        self._sensors = {}
        self._velocity = (0.0, 0.0)
        self.cmd_pub = rospy.Publisher('cmd_vel', Twist, queue_size=1)
        self.plan_pub = rospy.Publisher('~%s/plan' % resolved.global_namespace, Path, queue_size=1, latch=True)
        self.local_plan_pub = rospy.Publisher('~%s/local_plan' % resolved.local_namespace, Path, queue_size=1)
        self.followed_pub = rospy.Publisher('~%s/global_plan' % resolved.local_namespace, Path, queue_size=1)
        self.goal_pub = rospy.Publisher('~current_goal', PoseStamped, queue_size=1, latch=True)
        self.action_goal_pub = rospy.Publisher('~goal', MoveBaseActionGoal, queue_size=1)
        self._ids = GoalIDGenerator()
        self.server = actionlib.SimpleActionServer(rospy.get_name(), MoveBaseAction, auto_start=False)
        self.server.register_goal_callback(self._on_goal)
        self.server.register_preempt_callback(self._on_preempt)
        for io in (self.global_io, self.local_io):
            if io.ros.static_map:
                rospy.Subscriber(io.ros.map_topic, MapMessage, self._on_map, io, queue_size=1)
        for topic in sorted(set(source.topic for io in (self.global_io, self.local_io) for _, source in io.sources)):
            rospy.Subscriber(topic, LaserScan, self._on_scan, topic, queue_size=1)
        rospy.Subscriber('odom', Odometry, self._on_odom, queue_size=1)
        rospy.Subscriber('move_base_simple/goal', PoseStamped, self._on_simple_goal, queue_size=1)
        rospy.Service('~make_plan', GetPlan, self._on_make_plan)
        rospy.Service('~clear_costmaps', Empty, self._on_clear_costmaps)
        self.live = live.serve(self, resolved)
        self.server.start()
        rospy.loginfo('%s: %s and %s; frames %s and %s, robot %s; waiting for a map on %s', NODE,
                      resolved.move_base.base_global_planner, resolved.move_base.base_local_planner,
                      self.global_io.frame, self.local_io.frame, self.base_frame,
                      rospy.resolve_name(self.global_io.ros.map_topic))

    # --- inputs: each callback stores or hands over, the loop does the work ---------------------
    def _on_map(self, message, io):
        grid, values, _ = grid_of_message(message)
        with self.lock:
            io.set_map(grid, values)
            self._costmaps_changed()
        rospy.loginfo('%s: map of %d x %d cells at %.3f m in the %s', NODE, grid.width, grid.height,
                      grid.resolution, io.name.replace('_', ' '))

    def _costmaps_changed(self):
        """The navigator and the controller on the costmaps as they are now (a static map makes one anew)."""
        self.navigator.global_costmap, self.navigator.local_costmap = self.global_io.costmap, self.local_io.costmap
        self.controller.costmap = self.controller.scorer.costmap = self.local_io.costmap

    def _on_scan(self, message, topic):
        number = self._scans.get(topic, (0, None))[0] + 1
        self._scans[topic] = (number, message)

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
        with self.lock:
            outcomes = self.navigator.set_goal(rospy.get_time(), position, orientation, target.header.frame_id,
                                               self._frame_in_global)
        for outcome in outcomes:
            if outcome.status == ABORTED:
                rospy.logerr('%s: %s', NODE, outcome.text)
                self.server.set_aborted(MoveBaseResult(), outcome.text)
        if self.navigator.active:
            rospy.loginfo('%s: new goal (%.2f, %.2f, %.2f) in %s', NODE,
                          *(self.navigator.goal + (self.global_io.frame,)))
            self.goal_pub.publish(pose_stamped(self.navigator.goal, self.global_io.frame, rospy.Time.now()))

    def _on_preempt(self):
        """A cancel, or a new goal about to replace this one (accept_new_goal then preempts it)."""
        with self.lock:
            outcome = self.navigator.cancel()
        if outcome is not None and self.server.is_active():
            self.server.set_preempted(MoveBaseResult(), outcome.text)

    def _frame_in_global(self, frame):
        return self.frames.pose(self.global_io.frame, frame.lstrip('/'), rospy.Time(0))

    def _on_make_plan(self, request):
        with self.lock:
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
        with self.lock:
            plan = self.navigator.make_plan(ends[0], ends[1], max(0.0, request.tolerance),
                                            self.resolved.move_base.make_plan_add_unreachable_goal)
        return GetPlanResponse(plan=_path(plan or [], self.global_io.frame, rospy.Time.now()))

    def _on_clear_costmaps(self, _request):
        with self.lock:
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

    def _robot(self, io, now):
        """The robot's pose (x, y, yaw) in the costmap's frame, None if tf has none newer than the
        costmap's transform_tolerance (costmap_2d's getRobotPose: move_base then holds still)."""
        try:
            transform = self.frames.buffer.lookup_transform(io.frame, self.base_frame, rospy.Time(0))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as error:
            self.frames.warn((io.frame, self.base_frame), 'waiting for tf %s -> %s: %s', io.frame, self.base_frame,
                             error)
            return None
        age = now - transform.header.stamp.to_sec()
        if transform.header.stamp.to_sec() > 0 and age > io.ros.transform_tolerance:
            self.frames.warn(('old', io.frame), 'tf %s -> %s is %.3f s old, more than the %s\'s '
                             'transform_tolerance %.3f s: holding still', io.frame, self.base_frame, age, io.name,
                             io.ros.transform_tolerance)
            return None
        return plane_pose(transform)

    def _newest_scans(self):
        """{topic: (number, Scan, the sensor's pose in the base frame)} of the newest scan of each topic
        (a source's sensor_frame, if it names one, else the scan's own frame), each converted once."""
        frames = {**self.global_io.sensor_frames, **self.local_io.sensor_frames}
        for topic, (number, message) in list(self._scans.items()):
            if self._converted.get(topic, (None,))[0] != number:
                sensor = self._sensor_pose(frames.get(topic) or message.header.frame_id)
                if sensor is not None:
                    self._converted[topic] = (number, Scan.from_message(message), sensor)
        return self._converted

    def cycle(self):
        now, stamp = rospy.get_time(), rospy.Time.now()
        in_global, in_local = self._robot(self.global_io, now), self._robot(self.local_io, now)
        scans = self._newest_scans()
        with self.lock:
            ready = self.navigator.global_costmap is not None and self.navigator.local_costmap is not None
            if in_global is None or in_local is None or not ready:
                if not ready and self.navigator.active:
                    self.frames.warn('no map', 'a goal but no map on %s yet: holding still',
                                     rospy.resolve_name(self.global_io.ros.map_topic))
                # Nothing to steer by: the state machine holds the robot still (a non-finite pose).
                step = self.navigator.step(now, (float('nan'),) * 3, self._velocity) if self.navigator.active else None
            else:
                self.local_io.update(now, in_local, scans)
                self.global_io.update(now, in_global, scans)
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
        if step.followed is not None and len(step.followed) and self.followed_pub.get_num_connections():
            self.followed_pub.publish(_path(step.followed, self.local_io.frame, stamp))
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
            self.server.publish_feedback(MoveBaseFeedback(base_position=pose_stamped(pose, self.global_io.frame,
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
