"""The tutorial, run as a learner runs it, recorded: for `make demo`, the bench and the tests.

run_script does what the tutorial does for one script: start the simulator
fresh (`roslaunch tb3_sim_bringup tb3_empty_world.launch`), wait for odom ->
base_footprint, `rosrun tb3_sim_nav SCRIPT`, stop the simulator (Ctrl+C to
roslaunch), while it records base_pose_ground_truth and odom. The caller is
a rospy node following /clock (a master from processes.start_master). Every
timeout here is on the wall clock, so a stopped /clock cannot hang a run.
"""
import signal
import time

from . import report
from .processes import Process, RunError, say, tail

#: The tutorial's scripts, in its order, with their expected run time in sim
#: seconds (from their constants: legs, turns, the 1 s pauses, tf's 2 s wait).
SCRIPTS = [
    ('timed_out_and_back.py', 21.0),
    ('odom_out_and_back.py', 33.0),
    ('nav_square.py', 48.0),
]
TIMEOUT_FACTOR = 4.0      # a script may take this many times its expected sim time ...
STARTUP_SLACK = 30.0      # ... plus this many wall seconds (node start-up, tf wait)
SIM_READY_TIMEOUT = 60.0  # wall s for the simulator to give odom -> base_footprint
HEARTBEAT = 15.0          # wall s between progress lines while a script runs
SETTLE = 1.5              # wall s a script started while paused gets to connect its topics
LAUNCH = ('tb3_sim_bringup', 'tb3_empty_world.launch')



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
        from tb3_common.ros.poses import plane_pose
        path.append((message.header.stamp.to_sec(),) + tuple(plane_pose(message)))

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
            raise RunError('the simulator exited (code %s) before it was ready; %s ends with:\n%s'
                            % (sim.popen.returncode, sim.log, tail(sim.log)))
        if time.monotonic() > deadline:
            raise RunError('no %s after %.0f s; %s ends with:\n%s'
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
    connect (its publisher of /cmd_vel connected to the simulator, then SETTLE
    wall seconds), and physics unpaused. The script then starts at the same sim
    time in every run, whatever the factor and however long python takes to
    start. Not its registration alone: the simulator, niced, may connect later
    than SETTLE on a loaded machine, and lockstep follows a publisher only once
    connected, so the script's first ticks would go unwaited for (a run at
    factor 0 ended 2.6 cm from the factor 1 run's end, 2026-11-30, doc/testing.md)."""
    import xmlrpc.client

    import rosgraph
    import rospy
    from std_srvs.srv import Empty
    deadline = time.monotonic() + SIM_READY_TIMEOUT
    master = rosgraph.Master(rospy.get_name())

    def wait_until(predicate, what, process=None):
        while not predicate():
            if not sim.running():
                raise RunError('the simulator exited (code %s); %s ends with:\n%s'
                                % (sim.popen.returncode, sim.log, tail(sim.log)))
            if process is not None and not process.running():
                raise RunError('%s exited (code %s) before the simulator was unpaused; %s ends with:\n%s'
                                % (script, process.popen.returncode, process.log, tail(process.log)))
            if time.monotonic() > deadline:
                raise RunError('no %s after %.0f s' % (what, SIM_READY_TIMEOUT))
            time.sleep(0.1)

    def has_service(name):
        return any(service == name for service, _ in master.getSystemState()[2])

    def cmd_vel_connected():
        """Whether a publisher of /cmd_vel but the simulator has a connection to it (its bus info)."""
        for node in set(dict(master.getSystemState()[0]).get('/cmd_vel', ())) - {'/tb3_sim'}:
            try:
                code, _, connections = xmlrpc.client.ServerProxy(master.lookupNode(node)).getBusInfo(
                    rospy.get_name())
            except Exception:  # not up yet, or gone (the process check says which)
                continue
            if code == 1 and any(entry[4] == '/cmd_vel' and entry[1] == '/tb3_sim' for entry in connections):
                return True
        return False

    wait_until(lambda: has_service('/gazebo/unpause_physics'), 'simulator (its unpause service)')
    process = Process(script[:-3], ['rosrun', 'tb3_sim_nav', script], log_dir)
    try:
        wait_until(cmd_vel_connected, 'connection of the simulator to the /cmd_vel of %s' % script, process)
        settle = time.monotonic() + SETTLE
        wait_until(lambda: time.monotonic() >= settle, 'end of the settling time', process)
        rospy.ServiceProxy('/gazebo/unpause_physics', Empty)()
    except BaseException:
        process.stop(timeout=10.0)
        raise
    return process


def watch(sim, recorder, script, process, expected, factor, wall_start, sim_start, done=None):
    """Until `process` exits, or done() is true: RunError if the simulator exits
    or the script outlives its limits (TIMEOUT_FACTOR times its `expected` sim
    seconds, in wall time at `factor`), a progress line every HEARTBEAT s."""
    sim_limit = TIMEOUT_FACTOR * expected
    wall_limit = STARTUP_SLACK + sim_limit / (factor or 1.0)
    next_beat = wall_start + HEARTBEAT
    while process.running() and not (done is not None and done()):
        now = time.monotonic()
        if not sim.running():
            raise RunError('the simulator exited (code %s) while %s ran; %s ends with:\n%s'
                            % (sim.popen.returncode, script, sim.log, tail(sim.log)))
        # As fast as possible, the script's own start-up (python, rospy: wall
        # seconds) is worth many sim seconds: there only the wall limit counts.
        sim_over = factor > 0.0 and sim_now() - sim_start > sim_limit
        if now - wall_start > wall_limit or sim_over:
            raise RunError('%s still running after %.0f s wall / %.0f s sim (limits %.0f s / %.0f s, '
                            '%.0fx its expected %.0f s sim); stopped it'
                            % (script, now - wall_start, sim_now() - sim_start, wall_limit, sim_limit,
                               TIMEOUT_FACTOR, expected))
        if now >= next_beat:
            pose = recorder.truth[-1] if recorder.truth else None
            say('%s: running, sim time %.1f s, %s' % (script, sim_now() - sim_start, 'robot at x %+.2f m, y %+.2f m'
                                                      % pose[1:3] if pose else 'no ground truth yet'))
            next_beat += HEARTBEAT
        time.sleep(0.1)


def run_script(script, expected, args, log_dir):
    """One round of the tutorial: fresh simulator, the script, simulator stopped.

    With args.paused_start the simulator starts paused and the script is
    started before time does (start_script_paused), for runs to compare."""
    paused_start = getattr(args, 'paused_start', False)
    launch_argv = ['roslaunch', '--wait'] + list(LAUNCH) + ['real_time_factor:=%g' % args.real_time_factor]
    if args.profile is not None:
        launch_argv.append('profile:=%s' % args.profile)
    if getattr(args, 'model', None) is not None:
        launch_argv.append('model:=%s' % args.model)
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
        watch(sim, recorder, script, script_process, expected, args.real_time_factor, wall_start, sim_start)
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
    except RunError as failure:
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
    return report.RunResult(script, truth, odom, wall_time, sim_time, exit_code,
                                 error.split('\n')[0] if error else None), error
