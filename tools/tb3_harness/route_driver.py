"""A node that drives a robot through waypoints on its true pose and records what each frame believed.

    python3 -m tb3_harness.route_driver world_loop [--map-frame map] [--out FILE]

The tests' and the demo's driver (not a learner's tool): it steers on
base_pose_ground_truth (tb3_harness.waypoints), so the route is the same
whatever the code under test believes, and every 0.5 s of sim time it
records the true pose, odometry's, and the pose in the map frame (tf map ->
base_footprint, when there is one). At the end it stops the robot, waits a
second of sim time, and writes one JSON document: the three paths (lists
of [t, x, y, yaw]) and the sim time the route took. In lockstep the
simulator waits for it as for any node that publishes cmd_vel.
"""
import argparse
import json
import sys

RECORD_PERIOD = 0.5  # sim s between two recorded poses
ROUTES = {'world_loop': 'WORLD_LOOP'}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('route', help='a route of tb3_harness.waypoints (%s)' % ', '.join(ROUTES))
    parser.add_argument('--map-frame', default='map')
    parser.add_argument('--base-frame', default='base_footprint')
    parser.add_argument('--out', default='-', help='where the JSON goes (- : standard output)')
    args = parser.parse_args(argv)

    import rospy
    import tf2_ros
    from geometry_msgs.msg import Twist
    from nav_msgs.msg import Odometry

    from tb3_common.ros import lifecycle
    from tb3_common.ros.poses import plane_pose

    from . import waypoints
    route = waypoints.Route(getattr(waypoints, ROUTES[args.route]))
    life = lifecycle.init_node('route_driver', anonymous=True)
    latest = {}

    def keep(name):
        def store(message):
            pose = message.pose.pose
            latest[name] = plane_pose(pose)
        return store
    rospy.Subscriber('base_pose_ground_truth', Odometry, keep('truth'), queue_size=1)
    rospy.Subscriber('odom', Odometry, keep('odom'), queue_size=1)
    cmd_vel = rospy.Publisher('cmd_vel', Twist, queue_size=1)
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    paths = {'truth': [], 'odom': [], 'map': []}

    def record(now):
        for name in ('truth', 'odom'):
            paths[name].append([now] + list(latest[name]))
        try:
            transform = buffer.lookup_transform(args.map_frame, args.base_frame, rospy.Time(0))
            paths['map'].append([now] + list(plane_pose(transform)))
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException):
            pass

    period = 1.0 / 30
    while not life.stopping and not ('truth' in latest and 'odom' in latest):
        life.sleep(0.05)
    start = next_record = rospy.get_time()
    twist = Twist()
    while not life.stopping and not route.done:
        now = rospy.get_time()
        twist.linear.x, twist.angular.z = route.command(latest['truth'])
        cmd_vel.publish(twist)
        if now >= next_record:
            record(now)
            next_record = now + RECORD_PERIOD
        life.sleep_sim(max(0.0, now + period - rospy.get_time()))
    cmd_vel.publish(Twist())
    end = rospy.get_time()
    if life.sleep_sim(1.0):
        record(rospy.get_time())
    document = dict(paths, sim_seconds=end - start, finished=route.done)
    text = json.dumps(document)
    if args.out == '-':
        print(text, flush=True)
    else:
        with open(args.out, 'w') as stream:
            stream.write(text)
    life.finish()
    return 0 if route.done else 1


if __name__ == '__main__':
    sys.exit(main())
