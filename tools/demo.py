"""`make demo`: the tutorial's three scripts, end to end, on the pybullet TurtleBot3.

Run inside `source setup.bash`. Starts one master on a free loopback port, then
for each script does what the tutorial does: start the simulator fresh
(`roslaunch tb3_sim_bringup tb3_empty_world.launch`), wait for odom ->
base_footprint, `rosrun tb3_sim_nav SCRIPT`, stop the simulator (Ctrl+C to
roslaunch). Meanwhile it records base_pose_ground_truth and odom, and at the end
prints a table per script, writes it to OUTPUT/summary.txt and draws the paths
to OUTPUT/demo_paths.png. Each process's output goes to OUTPUT/logs/.

Exit status 0 if every script ran and exited 0; everything started here is
stopped by its process group, also on error, Ctrl+C and SIGTERM.

Time: the simulator sets /use_sim_time true, and so does this program before its
own node starts, so the recorder's rospy clock follows /clock like every other
node's (it restarts from 0 with each simulator). Every timeout here is on the
wall clock (time.monotonic), so a stopped /clock cannot hang the demo.
"""
import argparse
import os
import signal
import socket
import subprocess
import sys
import time

import demo_report

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

#: The tutorial's scripts, in its order, with their expected run time in sim
#: seconds (from their constants: legs, turns, the 1 s pauses, tf's 2 s wait).
SCRIPTS = [
    ('timed_out_and_back.py', 21.0),
    ('odom_out_and_back.py', 33.0),
    ('nav_square.py', 48.0),
]
TIMEOUT_FACTOR = 4.0      # a script may take this many times its expected sim time ...
STARTUP_SLACK = 30.0      # ... plus this many wall seconds (node start-up, tf wait)
MASTER_TIMEOUT = 30.0     # wall s for roscore to answer
SIM_READY_TIMEOUT = 60.0  # wall s for the simulator to give odom -> base_footprint
STOP_TIMEOUT = 30.0       # wall s for a process group to end after SIGINT (roslaunch escalates after 15 s)
HEARTBEAT = 15.0          # wall s between progress lines while a script runs
SETTLE = 1.5              # wall s a script started while paused gets to connect its topics
LAUNCH = ('tb3_sim_bringup', 'tb3_empty_world.launch')


class DemoError(Exception):
    pass


class Interrupted(BaseException):
    """SIGTERM, turned into an exception so the clean-up runs."""


_T0 = time.monotonic()


def say(message):
    print('[%6.1fs] %s' % (time.monotonic() - _T0, message), flush=True)


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def tail(filename, lines=15):
    try:
        with open(filename, errors='replace') as log:
            return ''.join(log.readlines()[-lines:]).rstrip()
    except OSError:
        return '(no log)'


class Process(object):
    """A child in its own process group, output to a log file, stopped by group."""

    def __init__(self, name, argv, log_dir):
        self.name = name
        self.log = os.path.join(log_dir, name + '.log')
        with open(self.log, 'w') as log:
            self.popen = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=log,
                                          stderr=subprocess.STDOUT, start_new_session=True)

    def running(self):
        return self.popen.poll() is None

    def _group_alive(self):
        try:
            os.killpg(self.popen.pid, 0)
            return True
        except ProcessLookupError:
            return False
        except PermissionError:
            return True

    def _signal_group(self, sig):
        try:
            os.killpg(self.popen.pid, sig)
        except ProcessLookupError:
            pass

    def _wait_group(self, timeout):
        """Wait for the leader and every other member of the group to end."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            self.popen.poll()
            if self.popen.returncode is not None and not self._group_alive():
                return True
            time.sleep(0.1)
        return False

    def stop(self, timeout=STOP_TIMEOUT):
        """SIGINT to the group (as Ctrl+C would), then SIGTERM, then SIGKILL."""
        previous = None
        for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
            if self.popen.poll() is not None and not self._group_alive():
                break
            if previous is not None:
                say('%s did not stop after %s: sending %s' % (self.name, previous, sig.name))
            self._signal_group(sig)
            if self._wait_group(wait):
                break
            previous = sig.name
        return self.popen.poll()


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--real-time-factor', type=float, default=1.0, metavar='F',
                        help='launch arg real_time_factor (default 1.0; 0 = as fast as possible)')
    parser.add_argument('--profile', metavar='NAME',
                        help='launch arg profile (passed only if given)')
    parser.add_argument('--output', default=os.path.join(ROOT, 'demo_output'), metavar='DIR',
                        help='folder for demo_paths.png, summary.txt and logs/ (default: %(default)s)')
    parser.add_argument('--scripts', nargs='+', choices=[name for name, _ in SCRIPTS], metavar='SCRIPT',
                        help='run only these scripts (default: all three, in the tutorial\'s order)')
    args = parser.parse_args(argv)
    if not args.real_time_factor >= 0.0:
        parser.error('--real-time-factor must be >= 0, not %r' % args.real_time_factor)
    return args


def check_environment(args):
    """Fail early, with the fix, if we are not inside `source setup.bash`."""
    for tool in ('roscore', 'roslaunch', 'rosrun'):
        if subprocess.call(['which', tool], stdout=subprocess.DEVNULL) != 0:
            raise DemoError('%s not found: run `source setup.bash` (or `make demo`) first' % tool)
    for package in ('tb3_sim_nav', LAUNCH[0]):
        if subprocess.call(['rospack', 'find', package], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL) != 0:
            raise DemoError('ROS package %s not found: run `make setup` and `source setup.bash`' % package)
    if args.profile is not None:
        listing = subprocess.run(['roslaunch', '--ros-args'] + list(LAUNCH), stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, universal_newlines=True, timeout=60).stdout
        names = [line.split()[0] for line in listing.splitlines() if line.startswith('  ') and line.split()]
        if 'profile' not in names:
            raise DemoError('--profile given, but %s has no `profile` argument (it has: %s)'
                            % (LAUNCH[1], ', '.join(names)))


class Recorder(object):
    """Ground truth and odometry of one run, as (stamp, x, y, yaw) lists."""

    def __init__(self):
        import rospy
        from nav_msgs.msg import Odometry
        self.truth, self.odom = [], []
        self.subscribers = [rospy.Subscriber('base_pose_ground_truth', Odometry, self._on_message,
                                             callback_args=self.truth, queue_size=100),
                            rospy.Subscriber('odom', Odometry, self._on_message,
                                             callback_args=self.odom, queue_size=100)]

    @staticmethod
    def _on_message(message, path):
        pose = message.pose.pose
        q = pose.orientation
        path.append((message.header.stamp.to_sec(), pose.position.x, pose.position.y,
                     demo_report.yaw_of(q.x, q.y, q.z, q.w)))

    def close(self):
        for subscriber in self.subscribers:
            subscriber.unregister()


def sim_now():
    import rospy
    return rospy.get_rostime().to_sec()


def wait_for_sim(sim, recorder):
    """Until both topics have spoken, our clock follows this simulator's, and
    odom -> base_footprint is in tf."""
    import rospy
    import tf2_ros
    deadline = time.monotonic() + SIM_READY_TIMEOUT

    def check(what):
        if not sim.running():
            raise DemoError('the simulator exited (code %s) before it was ready; %s ends with:\n%s'
                            % (sim.popen.returncode, sim.log, tail(sim.log)))
        if time.monotonic() > deadline:
            raise DemoError('no %s after %.0f s; %s ends with:\n%s'
                            % (what, SIM_READY_TIMEOUT, sim.log, tail(sim.log)))
        time.sleep(0.1)

    # The tf listener clears its buffer when time jumps back: start it only
    # once /clock has restarted from this simulator's zero.
    while not (recorder.truth and recorder.odom and abs(sim_now() - recorder.truth[-1][0]) < 1.0):
        check('odom, base_pose_ground_truth and /clock')
    buffer = tf2_ros.Buffer()
    listener = tf2_ros.TransformListener(buffer)
    try:
        while not buffer.can_transform('odom', 'base_footprint', rospy.Time(0)):
            check('odom -> base_footprint transform')
    finally:
        listener.unregister()


def start_script_paused(sim, script, log_dir):
    """With the simulator paused at time 0: the script started, given time to
    connect (its publisher of /cmd_vel registered, then SETTLE wall seconds),
    and physics unpaused. The script then starts at the same sim time in every
    run, whatever the factor and however long python takes to start."""
    import rosgraph
    import rospy
    from std_srvs.srv import Empty
    deadline = time.monotonic() + SIM_READY_TIMEOUT
    master = rosgraph.Master(rospy.get_name())

    def wait_until(predicate, what, process=None):
        while not predicate():
            if not sim.running():
                raise DemoError('the simulator exited (code %s); %s ends with:\n%s'
                                % (sim.popen.returncode, sim.log, tail(sim.log)))
            if process is not None and not process.running():
                raise DemoError('%s exited (code %s) before the simulator was unpaused; %s ends with:\n%s'
                                % (script, process.popen.returncode, process.log, tail(process.log)))
            if time.monotonic() > deadline:
                raise DemoError('no %s after %.0f s' % (what, SIM_READY_TIMEOUT))
            time.sleep(0.1)

    def has_service(name):
        return any(service == name for service, _ in master.getSystemState()[2])

    def publishes_cmd_vel():
        return any(topic == '/cmd_vel' and set(nodes) - {'/tb3_sim'}
                   for topic, nodes in master.getSystemState()[0])

    wait_until(lambda: has_service('/gazebo/unpause_physics'), 'simulator (its unpause service)')
    process = Process(script[:-3], ['rosrun', 'tb3_sim_nav', script], log_dir)
    try:
        wait_until(publishes_cmd_vel, 'publisher of /cmd_vel from %s' % script, process)
        settle = time.monotonic() + SETTLE
        wait_until(lambda: time.monotonic() >= settle, 'end of the settling time', process)
        rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
    except BaseException:
        process.stop(timeout=10.0)
        raise
    return process


def run_script(script, expected, args, log_dir):
    """One round of the tutorial: fresh simulator, the script, simulator stopped.

    With args.paused_start the simulator starts paused and the script is
    started before time does (start_script_paused), for runs to compare."""
    paused_start = getattr(args, 'paused_start', False)
    launch_argv = ['roslaunch', '--wait'] + list(LAUNCH) + ['real_time_factor:=%g' % args.real_time_factor]
    if args.profile is not None:
        launch_argv.append('profile:=%s' % args.profile)
    if paused_start:
        launch_argv.append('paused:=true')
    sim = script_process = recorder = start_index = None
    truth = odom = []
    wall_time = sim_time = exit_code = error = None
    try:
        say('%s: starting the simulator: %s' % (script, ' '.join(launch_argv)))
        sim = Process(script[:-3] + '.sim', launch_argv, log_dir)
        recorder = Recorder()
        wall_start = time.monotonic()
        if paused_start:
            say('%s: simulator paused at time 0; rosrun tb3_sim_nav %s, then unpause' % (script, script))
            script_process = start_script_paused(sim, script, log_dir)
            sim_start, start_index = 0.0, (0, 0)
        else:
            wait_for_sim(sim, recorder)
            say('%s: simulator ready (odom -> base_footprint), sim time %.2f s; rosrun tb3_sim_nav %s'
                % (script, sim_now(), script))
            wall_start, sim_start = time.monotonic(), sim_now()
            start_index = (len(recorder.truth) - 1, len(recorder.odom) - 1)
            script_process = Process(script[:-3], ['rosrun', 'tb3_sim_nav', script], log_dir)
        sim_limit = TIMEOUT_FACTOR * expected
        wall_limit = STARTUP_SLACK + sim_limit / (args.real_time_factor or 1.0)
        next_beat = wall_start + HEARTBEAT
        while script_process.running():
            now = time.monotonic()
            if not sim.running():
                raise DemoError('the simulator exited (code %s) while %s ran; %s ends with:\n%s'
                                % (sim.popen.returncode, script, sim.log, tail(sim.log)))
            # As fast as possible, the script's own start-up (python, rospy: wall
            # seconds) is worth many sim seconds: there only the wall limit counts.
            sim_over = args.real_time_factor > 0.0 and sim_now() - sim_start > sim_limit
            if now - wall_start > wall_limit or sim_over:
                raise DemoError('%s still running after %.0f s wall / %.0f s sim (limits %.0f s / %.0f s, '
                                '%.0fx its expected %.0f s sim); stopped it'
                                % (script, now - wall_start, sim_now() - sim_start, wall_limit, sim_limit,
                                   TIMEOUT_FACTOR, expected))
            if now >= next_beat:
                pose = recorder.truth[-1]
                say('%s: running, sim time %.1f s, robot at x %+.2f m, y %+.2f m'
                    % (script, sim_now() - sim_start, pose[1], pose[2]))
                next_beat += HEARTBEAT
            time.sleep(0.1)
        exit_code = script_process.popen.returncode
        wall_time, sim_time = time.monotonic() - wall_start, sim_now() - sim_start
        # One more ground truth sample from after the exit: the pose it left the robot in.
        sim_end, deadline = sim_now(), time.monotonic() + 5.0
        while recorder.truth[-1][0] < sim_end and time.monotonic() < deadline and sim.running():
            time.sleep(0.05)
        say('%s: exited with code %s after %.1f s wall, %.1f s sim' % (script, exit_code, wall_time, sim_time))
        if exit_code != 0:
            error = 'exit code %s; %s ends with: %s' % (exit_code, script_process.log,
                                                       tail(script_process.log, 5))
    except DemoError as failure:
        error = str(failure)
        say('%s: FAILED: %s' % (script, error))
    finally:
        if script_process is not None and script_process.running():
            say('%s: stopping the script' % script)
            script_process.stop(timeout=10.0)
        if recorder is not None:
            recorder.close()
            truth, odom = list(recorder.truth), list(recorder.odom)
            if start_index is not None:
                truth, odom = truth[start_index[0]:], odom[start_index[1]:]
        if sim is not None:
            say('%s: stopping the simulator (SIGINT to roslaunch)' % script)
            code = sim.stop()
            if code not in (0, -signal.SIGINT) and error is None:
                say('%s: note: roslaunch ended with code %s (see %s)' % (script, code, sim.log))
    return demo_report.RunResult(script, truth, odom, wall_time, sim_time, exit_code,
                                 error.split('\n')[0] if error else None), error


def start_master(log_dir):
    import rosgraph
    port = free_port()
    os.environ['ROS_MASTER_URI'] = 'http://localhost:%d' % port
    os.environ['ROS_HOSTNAME'] = 'localhost'
    os.environ.pop('ROS_IP', None)
    say('starting roscore -p %d (ROS_MASTER_URI=%s)' % (port, os.environ['ROS_MASTER_URI']))
    master = Process('roscore', ['roscore', '-p', str(port)], log_dir)
    proxy = rosgraph.Master('/tb3_demo_probe', master_uri=os.environ['ROS_MASTER_URI'])
    deadline = time.monotonic() + MASTER_TIMEOUT
    while True:
        if not master.running():
            raise DemoError('roscore exited (code %s); %s ends with:\n%s'
                            % (master.popen.returncode, master.log, tail(master.log)))
        try:
            proxy.getPid()
            break
        except Exception:
            if time.monotonic() > deadline:
                raise DemoError('roscore on port %d did not answer within %.0f s' % (port, MASTER_TIMEOUT))
            time.sleep(0.2)
    # As every node of the tutorial's world does: follow /clock.
    proxy.setParam('/use_sim_time', True)
    return master


def main(argv=None):
    args = parse_args(argv)
    log_dir = os.path.join(args.output, 'logs')
    os.makedirs(log_dir, exist_ok=True)

    def on_sigterm(signum, _frame):
        raise Interrupted('signal %d' % signum)
    signal.signal(signal.SIGTERM, on_sigterm)
    signal.signal(signal.SIGINT, signal.default_int_handler)  # even if started with SIGINT ignored

    scripts = [(name, expected) for name, expected in SCRIPTS if not args.scripts or name in args.scripts]
    master = None
    results, failures = [], []
    rospy_up = False
    try:
        check_environment(args)
        master = start_master(log_dir)
        import rospy
        rospy.init_node('tb3_demo', anonymous=True, argv=[sys.argv[0]], disable_signals=True)
        rospy_up = True
        if rospy.rostime.is_wallclock():
            raise DemoError('the demo node did not pick up /use_sim_time')
        for script, expected in scripts:
            result, error = run_script(script, expected, args, log_dir)
            results.append(result)
            if error:
                failures.append('%s: %s' % (script, error))
    except DemoError as failure:
        failures.append(str(failure))
    except (KeyboardInterrupt, Interrupted) as interruption:
        failures.append('interrupted (%s)' % (type(interruption).__name__ if isinstance(interruption, KeyboardInterrupt)
                                              else interruption))
    finally:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl+C must not cut the clean-up short
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        if rospy_up:
            import rospy
            rospy.signal_shutdown('demo done')
        if master is not None:
            say('stopping roscore')
            master.stop()
        signal.signal(signal.SIGINT, signal.default_int_handler)

    total = time.monotonic() - _T0
    if results:
        header = ['tb3_sim_nav demo: the tutorial\'s scripts on the pybullet TurtleBot3 Burger',
                  'real_time_factor %g%s, total wall time %.1f s'
                  % (args.real_time_factor, ', profile %s' % args.profile if args.profile else '', total), '']
        lines = header
        for result in results:
            lines += demo_report.table(result) + ['']
        text = '\n'.join(lines)
        print('\n' + text, flush=True)
        summary_file = os.path.join(args.output, 'summary.txt')
        with open(summary_file, 'w') as summary:
            summary.write(text)
        picture = os.path.join(args.output, 'demo_paths.png')
        demo_report.plot_paths(results, picture,
                               'TurtleBot3 Burger in pybullet, real_time_factor %g%s' % (args.real_time_factor,
                                                          ', profile %s' % args.profile if args.profile else ''))
        say('wrote %s and %s (process logs in %s)' % (picture, summary_file, log_dir))
    if failures:
        print('\ndemo FAILED:\n  ' + '\n  '.join(failure.replace('\n', '\n    ') for failure in failures),
              file=sys.stderr, flush=True)
        return 1
    say('demo done: %d scripts, all exited 0' % len(results))
    return 0


if __name__ == '__main__':
    sys.exit(main())
