"""`make soak`: the simulator under random and hostile commands for a long time.

Run inside `source setup.bash`. Starts a master on a free loopback port and
the tutorial's launch as fast as possible (real_time_factor 0), then sends
bursts of random commands - in range, out of range, NaN, +-Inf, 1e308, -0.0,
in every field - until `--sim-seconds` of simulated time have passed, while it
checks every odom and tf message. It reports, and with --check exits 1 when a
target is missed:

- memory growth of the simulator node (VmRSS after warm-up to the end): < 10 MiB
- spread of the tf odom->base_footprint rate, per simulated second: within 10 %
- non-finite numbers in odom or tf: none
- ground-truth speeds never beyond the limits (5 % margin for physics)

    python3 tools/soak.py [--sim-seconds 3600] [--check]
"""
import argparse
import math
import os
import random
import statistics
import sys
import time

import bench_sim

from tb3_harness import leftovers
from tb3_harness.measure import machine, memory_mib, sim_pid
from tb3_harness.processes import Process, RunError, say, start_master, wait_until

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

LIMIT_MARGIN = 1.05
HOSTILE = [float('nan'), float('inf'), -float('inf'), 1e308, -1e308, -0.0, 5.0, -5.0, 40.0]


def random_twist(rng):
    from geometry_msgs.msg import Twist
    twist = Twist()
    fields = [twist.linear, twist.angular]
    if rng.random() < 0.2:  # a hostile message: any field, any awful value
        vector = rng.choice(fields)
        setattr(vector, rng.choice('xyz'), rng.choice(HOSTILE))
    else:
        twist.linear.x = rng.uniform(-0.3, 0.3)
        twist.angular.z = rng.uniform(-3.5, 3.5)
    return twist


class Checker(object):
    """Counts tf per simulated second and looks for any non-finite number."""

    def __init__(self):
        import rospy
        from nav_msgs.msg import Odometry
        from rosgraph_msgs.msg import Clock
        from tf2_msgs.msg import TFMessage
        self.clock = None
        self.tf_per_second = {}
        self.non_finite = []
        self.fastest = (0.0, 0.0)  # |v|, |w| of ground truth
        self.subscribers = [rospy.Subscriber('tf', TFMessage, self._on_tf, queue_size=1000),
                            rospy.Subscriber('odom', Odometry, self._on_odom, queue_size=1000),
                            rospy.Subscriber('base_pose_ground_truth', Odometry, self._on_truth,
                                             queue_size=1000),
                            rospy.Subscriber('clock', Clock, self._on_clock, queue_size=1)]

    def _on_clock(self, message):
        self.clock = message.clock.to_sec()

    def _finite(self, what, numbers):
        if not all(math.isfinite(number) for number in numbers):
            self.non_finite.append((what, numbers))

    def _on_tf(self, message):
        for transform in message.transforms:
            if transform.child_frame_id != 'base_footprint':
                continue
            second = transform.header.stamp.secs
            self.tf_per_second[second] = self.tf_per_second.get(second, 0) + 1
            t, r = transform.transform.translation, transform.transform.rotation
            self._finite('tf', (t.x, t.y, t.z, r.x, r.y, r.z, r.w))

    def _on_odom(self, message):
        p, q = message.pose.pose.position, message.pose.pose.orientation
        v, w = message.twist.twist.linear, message.twist.twist.angular
        self._finite('odom', (p.x, p.y, p.z, q.x, q.y, q.z, q.w, v.x, v.y, v.z, w.x, w.y, w.z))

    def _on_truth(self, message):
        v, w = message.twist.twist.linear, message.twist.twist.angular
        self._finite('base_pose_ground_truth', (v.x, v.y, w.z))
        self.fastest = (max(self.fastest[0], math.hypot(v.x, v.y)), max(self.fastest[1], abs(w.z)))

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()


def flood(burst, seed):
    """The command source, in a process of its own so the checker keeps up."""
    import rospy
    from geometry_msgs.msg import Twist
    rospy.init_node('tb3_soak_flood', anonymous=True, argv=[sys.argv[0]])
    publisher = rospy.Publisher('cmd_vel', Twist, queue_size=burst)
    rng = random.Random(seed)
    while not rospy.is_shutdown():
        for _ in range(burst):
            publisher.publish(random_twist(rng))
        time.sleep(0.01)
    return 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--sim-seconds', type=float, default=3600.0, help='simulated time to run')
    parser.add_argument('--burst', type=int, default=50, help='commands per burst (one burst every 10 ms wall)')
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--check', action='store_true', help='exit 1 if a target is missed')
    parser.add_argument('--flood', action='store_true', help=argparse.SUPPRESS)
    parser.add_argument('--output', default=os.path.join(ROOT, 'soak_output'))
    args = parser.parse_args(argv)
    if args.flood:
        return flood(args.burst, args.seed)
    log_dir = os.path.join(args.output, 'logs')
    os.makedirs(log_dir, exist_ok=True)
    master = sim = checker = commands = None
    try:
        master = start_master(log_dir)
        import rospy
        from geometry_msgs.msg import Twist
        rospy.init_node('tb3_soak', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        checker = Checker()
        clock = checker  # its /clock subscriber tells sim time
        sim = bench_sim.start_sim('soak', log_dir, 0.0)
        wait_until(lambda: clock.clock is not None and clock.clock > 2.0, 60, '/clock')
        pid = sim_pid()
        warm = memory_mib(pid, 'VmRSS')
        commands = Process('flood', [sys.executable, __file__, '--flood', '--burst', str(args.burst),
                                          '--seed', str(args.seed)], log_dir)
        received = []
        counter = rospy.Subscriber('cmd_vel', Twist, received.append, queue_size=1)
        wall_start, sim_start, next_report = time.monotonic(), clock.clock, 0.0
        say('soak: %g s of sim time at factor 0, bursts of %d commands; VmRSS after warm-up %.1f MiB'
            % (args.sim_seconds, args.burst, warm))
        while clock.clock - sim_start < args.sim_seconds:
            for process in (sim, commands):
                if not process.running():
                    raise RunError('%s exited (code %s); see %s'
                                         % (process.name, process.popen.returncode, process.log))
            if clock.clock - sim_start >= next_report:
                say('soak: sim %.0f s, VmRSS %.1f MiB' % (clock.clock - sim_start, memory_mib(pid, 'VmRSS')))
                next_report += max(60.0, args.sim_seconds / 10)
            time.sleep(0.1)
        counter.unregister()
        sent = len(received)
        growth = memory_mib(pid, 'VmRSS') - warm
        wall = time.monotonic() - wall_start
        # Whole simulated seconds, leaving out the first and last (partly seen).
        counts = [count for second, count in sorted(checker.tf_per_second.items())][2:-1]
        rate = statistics.median(counts) if counts else float('nan')
        spread = max(abs(count - rate) for count in counts) / rate if counts else float('nan')
        limits_ok = (checker.fastest[0] <= 0.22 * LIMIT_MARGIN and checker.fastest[1] <= 2.84 * LIMIT_MARGIN)
        results = [
            ('simulated time / wall time', '%.0f s / %.0f s' % (clock.clock - sim_start, wall), True),
            ('commands seen on cmd_vel (about 1 in 5 hostile)', '%d' % sent, sent > 0),
            ('memory growth of the simulator (VmRSS)', '%+.1f MiB' % growth, growth < 10.0),
            ('tf odom->base_footprint per sim second: median, worst spread',
             '%.0f Hz, %.1f %%' % (rate, 100 * spread), spread <= 0.10),
            ('non-finite numbers in odom, tf, ground truth', '%d' % len(checker.non_finite),
             not checker.non_finite),
            ('fastest ground truth |v|, |w|', '%.3f m/s, %.2f rad/s' % checker.fastest, limits_ok),
        ]
        print('\ntb3_sim_nav soak, machine: %s' % machine())
        for name, value, ok in results:
            print('%-62s %22s  %s' % (name, value, 'ok' if ok else 'MISSED'))
        failed = [name for name, _, ok in results if not ok]
        if counts and spread > 0.10:
            print('tf messages per sim second: %s' % (sorted(checker.tf_per_second.items())[:40],))
        if checker.non_finite:
            print('first non-finite: %r' % (checker.non_finite[0],))
        return 1 if failed and args.check else 0
    except RunError as error:
        print('soak FAILED: %s' % error, file=sys.stderr)
        return 1
    finally:
        if checker is not None:
            checker.close()
        if commands is not None:
            commands.stop()
        if sim is not None:
            sim.stop()
        if master is not None:
            import rospy
            rospy.signal_shutdown('soak done')
            master.stop()


if __name__ == '__main__':
    sys.exit(leftovers.run('make soak', main))
