"""The explore node: explore_lite's interface over tb3_navigation.exploration.

    roslaunch tb3_sim_bringup tb3_slam.launch explore:=true      (or: rosrun explore_lite explore)

explore_lite's parameters (planner_frequency, progress_timeout,
potential_scale, orientation_scale, gain_scale, min_frontier_size,
visualize, robot_base_frame, costmap_topic, transform_tolerance), its
`~frontiers` markers, its goals on the `move_base` action. In: the map on
costmap_topic (the SLAM's `map`; its frame_id is the global frame), tf
global frame -> robot_base_frame. `~costmap/` takes the costmap's
footprint and inflation (tb3_slam.launch loads the robot's
costmap_common_params there), so that reachability is judged as move_base's
global planner will judge it.

It prints a line per goal (sim time, goal, the frontier's size, distance and
cost, the area mapped) and one when it is done, with the explored area;
then it stays, idle, as explore_lite does, until asked to end. It never
touches the simulator: the map, tf and the action are all it sees.
"""
import dataclasses
import queue
import threading
import time

import actionlib
import rospy
from geometry_msgs.msg import Point
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker, MarkerArray

from tb3_common.params import Checked, frame_id, non_negative, parameter
from tb3_common.ros import lifecycle, params
from tb3_common.ros.frames import Frames, namespaced
from tb3_common.ros.map_messages import MapMessage, grid_of_message
from tb3_common.ros.poses import fill_pose
from tb3_navigation.costmap import CostmapConfig
from tb3_navigation.exploration import DONE, SEND, WAIT, Explorer
from tb3_navigation.frontiers import BLACKLISTED, CANDIDATE, ExploreConfig, explored_area

NODE = 'explore'
SERVER_WARN_PERIOD = 5.0  # wall s between "waiting for move_base" warnings (explore_lite's)
COLORS = {CANDIDATE: (0.0, 0.0, 1.0), BLACKLISTED: (1.0, 0.0, 0.0)}  # explore_lite's blue and red
OTHER_COLOR = (0.5, 0.5, 0.5)  # too small, no room, unreachable
GOAL_COLOR = (0.0, 1.0, 0.0)


@dataclasses.dataclass(frozen=True)
class NodeConfig(Checked):
    """explore_lite's parameters of the node itself (the rule's are ExploreConfig's)."""
    robot_base_frame: str = parameter('base_footprint', "the robot's frame (in a namespace: NAMESPACE/...)", frame_id)
    costmap_topic: str = parameter('map', 'the map (an OccupancyGrid; its frame_id is the global frame)')
    costmap_updates_topic: str = parameter('map_updates', "explore_lite's: map_msgs updates, not read here")
    visualize: bool = parameter(True, 'publish the frontiers as markers on ~frontiers')
    transform_tolerance: float = parameter(0.3, 'how old the robot pose may be', non_negative, 's')


class ExploreNode(object):

    def __init__(self):
        node = params.read_or_exit(NODE, NodeConfig)
        self.base_frame = namespaced(node.robot_base_frame, rospy.get_namespace())
        self.topic, self.visualize, self.transform_tolerance = (node.costmap_topic, node.visualize,
                                                                node.transform_tolerance)
        self.config = params.read_or_exit(NODE, ExploreConfig)
        self.explorer = Explorer(self.config, params.read_or_exit(NODE, CostmapConfig, 'costmap'))
        rospy.loginfo('%s: robot_base_frame %s, costmap_topic %s, visualize %s', NODE, self.base_frame,
                      rospy.resolve_name(self.topic), self.visualize)
        self.frames = Frames(NODE)
        self._map = None         # (grid, values, frame, stamp in s) of the newest map
        self._map_lock = threading.Lock()
        self._results = queue.Queue()  # (sim time, goal, state) of the goals move_base ended
        self._markers = 0
        self.started = None      # sim time of the first decision: the exploration's start
        # actionlib's plain client: the simple one logs an error for every status of a goal it
        # replaced (a new goal every few seconds here); the Explorer ignores those anyway.
        self.client = actionlib.ActionClient('move_base', MoveBaseAction)
        self._handle = None      # the current goal's handle (kept, or its callbacks stop)
        self.marker_pub = rospy.Publisher('~frontiers', MarkerArray, queue_size=1, latch=True) \
            if self.visualize else None
        rospy.Subscriber(self.topic, MapMessage, self._on_map, queue_size=1)

    def _on_map(self, message):
        grid, values, _ = grid_of_message(message)
        with self._map_lock:
            self._map = (grid, values, message.header.frame_id.lstrip('/'), message.header.stamp.to_sec())

    def _on_transition(self, goal):
        def transition(handle):
            if handle.get_comm_state() == actionlib.CommState.DONE:
                self._results.put((rospy.get_time(), goal, handle.get_goal_status()))
        return transition

    # --- the loop -------------------------------------------------------------------------
    def wait_for_move_base(self, life):
        """Until the move_base action server answers (False if asked to end first). The wait
        runs in a thread of its own: actionlib's sleeps in sim time, which stands still while
        the simulation is paused, and this loop must see the end flag whatever time does."""
        ready = threading.Event()
        threading.Thread(target=lambda: self.client.wait_for_server() and ready.set(), name='wait_for_move_base',
                         daemon=True).start()
        rospy.loginfo('%s: waiting to connect to the move_base action server (%s)', NODE,
                      rospy.resolve_name('move_base'))
        warned = time.monotonic()
        while not life.stopping and not ready.is_set():
            if time.monotonic() - warned > SERVER_WARN_PERIOD:
                rospy.logwarn('%s: still waiting for the move_base action server %s', NODE,
                              rospy.resolve_name('move_base'))
                warned = time.monotonic()
            life.sleep(0.05)
        if ready.is_set():
            rospy.loginfo('%s: connected to move_base', NODE)
        return ready.is_set()

    def run(self, life):
        if not self.wait_for_move_base(life):
            return
        period = 1.0 / self.config.planner_frequency
        next_decision = None
        while not life.stopping:
            now = rospy.get_time()
            ended = False
            while not self._results.empty():
                when, goal, state = self._results.get()
                self.explorer.result(when, goal, state)
                ended = True
            if next_decision is not None and next_decision - now > period:
                next_decision = now  # time went back (a simulation reset)
            if not self.explorer.done and (ended or next_decision is None or now >= next_decision):
                wait = self.decide(now)
                next_decision = now + (0.1 if wait else period)
            life.sleep(0.02)
        if self.explorer.goal is not None:
            self.client.cancel_all_goals()  # as explore_lite's stop(): the robot is not left driving

    def decide(self, now):
        """One decision; True if it must be asked again soon (no map or pose yet, or WAIT)."""
        with self._map_lock:
            current = self._map
        if current is None:
            self.frames.warn('map', 'waiting for a map on %s', rospy.resolve_name(self.topic))
            return True
        grid, values, frame, stamp = current
        pose = self.frames.pose(frame, self.base_frame, rospy.Time(0), timeout=self.transform_tolerance)
        if pose is None:
            return True
        if self.started is None:
            self.started = now
        decision = self.explorer.decide(now, grid, values, pose, stamp)
        for note in self.explorer.take_notes():
            rospy.logwarn('%s: %s', NODE, note)
        if decision.search is not None and self.marker_pub is not None:
            self.publish_markers(decision.search, frame)
        if decision.action == SEND:
            self.send(decision, frame, now, grid, values)
        elif decision.action == DONE:
            self.client.cancel_all_goals()
            free, occupied, known = explored_area(grid, values)
            took = now - self.started
            rospy.loginfo('%s: [%.1f s] exploration done: %s. Explored %.1f m2 free and %.1f m2 occupied, %.0f %% '
                          'of the known part\'s bounding box known; %d goals sent in %.1f s, %d blacklisted',
                          NODE, now, decision.text, free, occupied, 100.0 * known, self.explorer.goals_sent, took,
                          len(self.explorer.blacklist))
        return decision.action == WAIT

    def send(self, decision, frame, now, grid, values):
        goal = MoveBaseGoal()
        goal.target_pose.header.frame_id, goal.target_pose.header.stamp = frame, rospy.Time.now()
        x, y, _ = decision.goal
        fill_pose(goal.target_pose.pose, decision.goal)
        self._handle = self.client.send_goal(goal, transition_cb=self._on_transition(decision.goal))
        frontier = decision.frontier
        free, occupied, known = explored_area(grid, values)
        rospy.loginfo('%s: [%.1f s] goal %d (%.2f, %.2f): frontier of %.2f m, %.2f m away, cost %.2f; %d candidates; '
                      'mapped %.1f m2 free, %.1f m2 occupied', NODE, now, self.explorer.goals_sent, x, y, frontier.size,
                      frontier.distance, frontier.cost, len(decision.search.candidates), free, occupied)

    def publish_markers(self, search, frame):
        """explore_lite's markers: each frontier's cells as POINTS (blue, red if blacklisted, grey
        if not worth visiting) and for a candidate a green SPHERE at its goal, bigger the cheaper."""
        stamp = rospy.Time.now()
        markers = MarkerArray()
        lowest = min([f.cost for f in search.candidates] or [0.0])
        for frontier in search.frontiers:
            points = Marker(type=Marker.POINTS, action=Marker.ADD, ns='frontiers', id=len(markers.markers))
            points.header.frame_id, points.header.stamp = frame, stamp
            points.pose.orientation.w = 1.0
            points.scale.x = points.scale.y = points.scale.z = 0.05
            points.color = ColorRGBA(*(COLORS.get(frontier.status, OTHER_COLOR) + (1.0,)))
            points.points = [Point(x, y, 0.0) for x, y in frontier.points]
            points.frame_locked = True
            markers.markers.append(points)
            if frontier.goal is not None:
                sphere = Marker(type=Marker.SPHERE, action=Marker.ADD, ns='frontiers', id=len(markers.markers))
                sphere.header.frame_id, sphere.header.stamp = frame, stamp
                sphere.pose.position.x, sphere.pose.position.y = frontier.goal[:2]
                sphere.pose.orientation.w = 1.0
                scale = min(abs(lowest * 0.4 / frontier.cost), 0.5) if frontier.cost else 0.5
                sphere.scale.x = sphere.scale.y = sphere.scale.z = max(scale, 0.05)
                sphere.color = ColorRGBA(*(GOAL_COLOR + (1.0,)))
                markers.markers.append(sphere)
        count = len(markers.markers)
        for index in range(count, self._markers):  # the ones of the last decision not used again
            gone = Marker(action=Marker.DELETE, ns='frontiers', id=index)
            gone.header.frame_id, gone.header.stamp = frame, stamp
            markers.markers.append(gone)
        self._markers = count
        self.marker_pub.publish(markers)


def main():
    life = lifecycle.init_node(NODE)
    node = ExploreNode()
    node.run(life)
    life.finish()
