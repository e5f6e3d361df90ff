"""One parent for odom: while another node publishes map -> odom, the simulator publishes no world -> odom.

The e-manual's order: the simulator first (it publishes world -> odom for
the world's markers), then a SLAM or a localizer publishing map -> odom,
then that node stopped, and started again. A stand-in publishes map -> odom
at gmapping's 20 Hz; /tf is read as it arrives, per publisher.
"""
import math
import os
import sys
import threading
import time

from tb3_system_utils import wait_until

MAP_TO_ODOM = (0.5, 0.2, 0.3)  # x, y, yaw of the stand-in's map -> odom
PUBLISHER = '''
import math, rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
rospy.init_node('map_odom_stand_in')
broadcaster = tf2_ros.TransformBroadcaster()
rate = rospy.Rate(20)
while not rospy.is_shutdown():
    transform = TransformStamped()
    transform.header.stamp = rospy.Time.now() + rospy.Duration(0.1)
    transform.header.frame_id, transform.child_frame_id = 'map', 'odom'
    transform.transform.translation.x, transform.transform.translation.y = %r, %r
    transform.transform.rotation.z, transform.transform.rotation.w = math.sin(%r / 2), math.cos(%r / 2)
    broadcaster.sendTransform(transform)
    rate.sleep()
''' % (MAP_TO_ODOM[0], MAP_TO_ODOM[1], MAP_TO_ODOM[2], MAP_TO_ODOM[2])


class Links(object):
    """The parent -> child links each publisher has sent on /tf, with when they came (wall)."""

    def __init__(self):
        import rospy
        from tf2_msgs.msg import TFMessage
        self.seen = []  # (wall time, caller id, parent, child, x, y, yaw)
        self._lock = threading.Lock()
        rospy.Subscriber('/tf', TFMessage, self._on_tf, queue_size=100)

    def _on_tf(self, message):
        caller = message._connection_header['callerid']
        with self._lock:
            for transform in message.transforms:
                t, r = transform.transform.translation, transform.transform.rotation
                self.seen.append((time.monotonic(), caller, transform.header.frame_id, transform.child_frame_id,
                                  t.x, t.y, 2 * math.atan2(r.z, r.w)))

    def since(self, start, parent, child):
        with self._lock:
            return [entry for entry in self.seen if entry[0] >= start and entry[2:4] == (parent, child)]


def test_the_simulator_gives_way_to_a_map_to_odom_and_takes_over_again(ros_port, processes):
    processes.start_master('roscore', ros_port)
    sim = processes.start('roslaunch', ['roslaunch', 'tb3_sim_bringup', 'tb3_world.launch'],
                          env=dict(os.environ, TURTLEBOT3_MODEL='burger'))
    import rospy
    rospy.init_node('tf_rule_test', anonymous=True, disable_signals=True)
    links = Links()
    start = time.monotonic()
    assert wait_until(lambda: links.since(start, 'world', 'odom'), 60.0), sim.describe()

    for round_ in range(2):  # started, stopped, and started again
        stand_in = processes.start('stand_in_%d' % round_, [sys.executable, '-c', PUBLISHER])
        assert wait_until(lambda: links.since(start, 'map', 'odom'), 30.0), stand_in.describe()
        time.sleep(1.0)
        claimed = time.monotonic()
        time.sleep(2.0)
        from_sim = [entry for entry in links.since(claimed, 'world', 'odom') if entry[1] == '/tb3_sim']
        hung = [entry for entry in links.since(claimed, 'map', 'world') if entry[1] == '/tb3_sim']
        print('MEASURED round %d: while map -> odom is published, the simulator sent %d world -> odom and %d '
              'map -> world in 2 s' % (round_, len(from_sim), len(hung)))
        assert not from_sim, 'odom got two parents: %s' % from_sim[:3]
        assert len(hung) > 30, 'the world does not hang under map: %d links' % len(hung)
        # gazebo profile, robot at rest: world -> odom is the identity, so map -> world = map -> odom.
        _, _, _, _, x, y, yaw = hung[-1]
        assert abs(x - MAP_TO_ODOM[0]) < 1e-6 and abs(y - MAP_TO_ODOM[1]) < 1e-6 and abs(yaw - MAP_TO_ODOM[2]) < 1e-6

        stand_in.stop()
        stopped = time.monotonic()
        assert wait_until(lambda: [entry for entry in links.since(stopped, 'world', 'odom') if entry[1] == '/tb3_sim'],
                          5.0), 'no world -> odom from the simulator 5 s after map -> odom stopped'
        print('MEASURED round %d: world -> odom again %.2f s after the stand-in stopped' % (
            round_, links.since(stopped, 'world', 'odom')[0][0] - stopped))
        start = time.monotonic()
    rospy.signal_shutdown('test done')
