"""The tutorial's calibration, done as a learner does it, with ground truth as the tape measure.

`make demo DEMO_ARGS="--calibrate"` runs, in one simulator
(`roslaunch tb3_sim_bringup tb3_empty_world.launch profile:=realistic`, with
a fixed ~seed), each step a learner takes:

1. odom_out_and_back.py, before calibrating;
2. calibrate_linear.py: odometry drives 1 m; ground truth says how far it went;
3. calibrate_angular.py: odometry turns 360 degrees; ground truth says how far;
4. the corrections, truth / odometry, set with `rosrun dynamic_reconfigure
   dynparam set /tb3_sim ...`;
5. odom_out_and_back.py again.

Between two steps /gazebo/reset_world puts the robot back at its spawn pose,
with odometry zeroed there. The half without rospy (`measure`, `correction`,
`table`) is what the unit tests check; `calibrate` runs the walkthrough.
"""
import math
import subprocess
import time

from tb3_common.pose2d import normalize_angle

from . import report
from .processes import Process, RunError, say, tail
from .tutorial import LAUNCH, Recorder, sim_now, wait_for_sim, watch

SEED = 7                   # the simulator's ~seed: the same noise in every demo
SCRIPT_EXPECTED = {'odom_out_and_back.py': 33.0, 'calibrate_linear.py': 10.0, 'calibrate_angular.py': 16.0}
SETTLE = 1.5               # sim s after a calibration script says it is done: the robot comes to rest
STEP_TIMEOUT = 60.0        # wall s for a reset, a dynparam or a sample to arrive
CORRECTIONS = ('odom_linear_scale_correction', 'odom_angular_scale_correction')


def _between(path, start, end):
    return [sample for sample in path if start <= sample[0] <= end]


def measure(path, start, end):
    """(straight-line distance m, angle turned rad: the yaws' wrapped steps summed)
    of a path of (stamp, x, y, yaw) between two stamps."""
    samples = _between(path, start, end)
    if len(samples) < 2:
        raise RunError('fewer than 2 samples between sim time %.2f and %.2f s' % (start, end))
    first, last = samples[0], samples[-1]
    turned = sum(normalize_angle(after[3] - before[3]) for before, after in zip(samples, samples[1:]))
    return math.hypot(last[1] - first[1], last[2] - first[2]), turned


def correction(current, truth, odometry):
    """A base controller's new scale correction: the present one times truth / odometry."""
    if not odometry:
        raise RunError('odometry measured nothing: no correction can be computed')
    return current * abs(truth) / abs(odometry)


def table(before, after, linear, angular, corrections, real_time_factor):
    """The lines of the walkthrough's table. `linear` and `angular` are
    (odometry, truth) as measured; before and after report.RunResults."""
    rows = [
        ('calibrate_linear.py: odometry says', '%.4f m' % linear[0]),
        ('  ground truth says', '%.4f m' % linear[1]),
        ('calibrate_angular.py: odometry says', '%.2f deg' % math.degrees(angular[0])),
        ('  ground truth says', '%.2f deg' % math.degrees(angular[1])),
        ('odom_linear_scale_correction', '%.4f' % corrections[0]),
        ('odom_angular_scale_correction', '%.4f' % corrections[1]),
    ]
    lines = ['tb3_sim_nav calibration walkthrough: TurtleBot3 in profile realistic, seed %d, '
             'real_time_factor %g' % (SEED, real_time_factor), '']
    lines += ['%-40s %12s' % row for row in rows]
    lines += ['', '%-40s %12s %12s' % ('odom_out_and_back.py', 'before', 'after')]
    summaries = [report.summarize(run) for run in (before, after)]
    for label, value in (('odometry off the truth at the end (m)', lambda s: '%.4f' % s.drift_distance),
                         ('odometry heading off the truth (deg)',
                          lambda s: '%+.2f' % math.degrees(s.drift_heading)),
                         ('true end off the start (m)', lambda s: '%.4f' % s.error_distance),
                         ('true end heading off the start (deg)',
                          lambda s: '%+.2f' % math.degrees(s.error_heading))):
        lines.append('%-40s %12s %12s' % ((label,) + tuple(
            value(summary) if summary is not None and summary.odom_end is not None else 'n/a'
            for summary in summaries)))
    return lines


class Walkthrough(object):
    """One simulator and the scripts run in it, one after another."""

    def __init__(self, real_time_factor, log_dir):
        import rospy
        self.factor = real_time_factor
        self.log_dir = log_dir
        rospy.set_param('/tb3_sim/seed', SEED)  # roslaunch keeps it: the node reads it at start-up
        argv = ['roslaunch', '--wait'] + list(LAUNCH) + ['profile:=realistic',
                                                        'real_time_factor:=%g' % real_time_factor]
        say('calibration: starting the simulator: %s' % ' '.join(argv))
        self.sim = Process('calibration.sim', argv, log_dir)
        self.recorder = Recorder()
        wait_for_sim(self.sim, self.recorder)

    def close(self):
        self.recorder.close()
        say('calibration: stopping the simulator (SIGINT to roslaunch)')
        self.sim.stop()

    def _wait(self, predicate, what):
        deadline = time.monotonic() + STEP_TIMEOUT
        while not predicate():
            if not self.sim.running():
                raise RunError('the simulator exited (code %s) while waiting for %s; %s ends with:\n%s'
                               % (self.sim.popen.returncode, what, self.sim.log, tail(self.sim.log)))
            if time.monotonic() > deadline:
                raise RunError('no %s within %.0f s' % (what, STEP_TIMEOUT))
            time.sleep(0.05)

    def _sample_after(self, stamp):
        """Until both recordings have a sample stamped at or after `stamp`."""
        self._wait(lambda: self.recorder.truth[-1][0] >= stamp and self.recorder.odom[-1][0] >= stamp,
                   'ground truth and odometry after sim time %.2f s' % stamp)

    def reset_world(self):
        import rospy
        from std_srvs.srv import Empty
        say('calibration: rosservice call /gazebo/reset_world')
        rospy.ServiceProxy('/gazebo/reset_world', Empty)()
        self._sample_after(sim_now() + 0.2)

    def set_corrections(self, corrections):
        import rospy
        for name, value in zip(CORRECTIONS, corrections):
            argv = ['rosrun', 'dynamic_reconfigure', 'dynparam', 'set', '/tb3_sim', name, '%.4f' % value]
            say('calibration: %s' % ' '.join(argv))
            subprocess.run(argv, check=True, timeout=STEP_TIMEOUT, stdout=subprocess.DEVNULL)
            self._wait(lambda: abs(rospy.get_param('/tb3_sim/' + name) - value) < 1e-4,
                       '/tb3_sim/%s to read %.4f' % (name, value))

    def run(self, script, done_parameter=None):
        """`rosrun tb3_sim_nav SCRIPT` until it exits, or until its ~start_test
        turns false (then it is stopped once the robot has settled): the
        recorded (truth, odom) from its start, and the wall and sim time."""
        import rospy
        if done_parameter is not None and rospy.has_param(done_parameter):
            rospy.delete_param(done_parameter)

        def done():
            return done_parameter is not None and rospy.get_param(done_parameter, True) is False
        say('calibration: rosrun tb3_sim_nav %s' % script)
        wall_start, sim_start = time.monotonic(), sim_now()
        self._sample_after(sim_start)
        process = Process(script[:-3], ['rosrun', 'tb3_sim_nav', script], self.log_dir)
        try:
            watch(self.sim, self.recorder, script, process, SCRIPT_EXPECTED[script], self.factor,
                  wall_start, sim_start, done)
            if process.running():   # done: let the robot come to rest, then Ctrl+C
                settled = sim_now() + SETTLE
                self._wait(lambda: sim_now() >= settled, 'sim time %.1f s' % settled)
            elif process.popen.returncode != 0:
                raise RunError('%s exited with code %s; %s ends with:\n%s' % (
                    script, process.popen.returncode, process.log, tail(process.log)))
            sim_end = sim_now()
            self._sample_after(sim_end)
        finally:
            process.stop(timeout=10.0)
        wall_time, sim_time = time.monotonic() - wall_start, sim_end - sim_start
        say('%s: done after %.1f s wall, %.1f s sim' % (script, wall_time, sim_time))
        truth, odom = (_between(path, sim_start, sim_end) for path in (self.recorder.truth, self.recorder.odom))
        return truth, odom, wall_time, sim_time


def calibrate(real_time_factor, log_dir):
    """The walkthrough: (before, after) report.RunResults of odom_out_and_back.py,
    the (odometry, truth) of the linear and the angular test, and the corrections."""
    walkthrough = Walkthrough(real_time_factor, log_dir)
    try:
        runs = []

        def out_and_back(label):
            truth, odom, wall_time, sim_time = walkthrough.run('odom_out_and_back.py')
            runs.append(report.RunResult('odom_out_and_back.py (%s)' % label, truth, odom, wall_time, sim_time,
                                         0, None))

        out_and_back('before calibration')
        walkthrough.reset_world()
        truth, odom, _, _ = walkthrough.run('calibrate_linear.py', '/calibrate_linear/start_test')
        linear = (measure(odom, odom[0][0], odom[-1][0])[0], measure(truth, odom[0][0], odom[-1][0])[0])
        walkthrough.reset_world()
        truth, odom, _, _ = walkthrough.run('calibrate_angular.py', '/calibrate_angular/start_test')
        angular = (measure(odom, odom[0][0], odom[-1][0])[1], measure(truth, odom[0][0], odom[-1][0])[1])
        corrections = (correction(1.0, linear[1], linear[0]), correction(1.0, angular[1], angular[0]))
        say('calibration: linear %.4f m by odometry, %.4f m true; angular %.2f deg by odometry, %.2f deg true'
            % (linear[0], linear[1], math.degrees(angular[0]), math.degrees(angular[1])))
        walkthrough.set_corrections(corrections)
        walkthrough.reset_world()
        out_and_back('after calibration')
    finally:
        walkthrough.close()
    return runs[0], runs[1], linear, angular, corrections
