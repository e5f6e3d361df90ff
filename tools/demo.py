"""`make demo`: the tutorial's three scripts, end to end, on the pybullet TurtleBot3.

With --calibrate (`make demo DEMO_ARGS="--calibrate"`) it runs the calibration
walkthrough instead (tb3_harness/calibration.py): odom_out_and_back.py, the two
calibration scripts measured against ground truth, the corrections set with
dynparam, odom_out_and_back.py again; table in OUTPUT/calibration.txt, paths in
OUTPUT/calibration_paths.png.

With --slam (`make demo DEMO_ARGS="--slam"`) it maps turtlebot3_world
(tb3_harness/mapping.py): tb3_world.launch (profile realistic), tb3_slam.launch,
a drive around the pillars, map_saver; the map in OUTPUT/map.yaml and .pgm, a
table in OUTPUT/slam.txt and the map under the world's outline with the paths
in OUTPUT/slam_map.png.

With --nav (`make demo DEMO_ARGS="--nav"`) it navigates turtlebot3_world
(tb3_harness/navigating.py): tb3_world.launch (profile realistic),
tb3_navigation.launch on the shipped map, a 2D Pose Estimate at the spawn
pose, four goals around and between the pillars; a table in OUTPUT/nav.txt
and the map with the true path, the plans and amcl's particles in
OUTPUT/nav_paths.png.

With --explore (`make demo DEMO_ARGS="--explore"`) the robot maps
turtlebot3_house alone (tb3_harness/exploring.py): tb3_house.launch (profile
realistic), tb3_slam.launch explore:=true until the explore node is done,
map_saver; then tb3_house.launch afresh and tb3_navigation.launch on the saved
map, a 2D Pose Estimate at the spawn pose and a goal in each of four rooms. A
line per frontier and per goal as it goes; a table in OUTPUT/explore.txt; the
map under the house's outline with the exploration's and the navigation's true
paths in OUTPUT/explore.png.

With --dqn (`make demo DEMO_ARGS="--dqn"`) ROBOTIS' DQN agent trains in stage
1 for a few episodes (tb3_harness/dqn.py): turtlebot3_stage_1.launch and
turtlebot3_dqn_stage_1.launch; a table in OUTPUT/dqn.txt, the graph of score
and average max Q per episode in OUTPUT/dqn_result.png, models in OUTPUT/dqn/.

Every walkthrough runs as fast as possible unless --real-time-factor says
(`--real-time-factor 1`: at real time): it is headless, and lockstep makes a
script's path the same at every factor (the speed-agreement test checks it).

Run inside `source setup.bash`. Starts one master on a free loopback port, then
for each script does what the tutorial does: start the simulator fresh
(`roslaunch tb3_sim_bringup tb3_empty_world.launch real_time_factor:=F
paused:=true`), `rosrun tb3_sim_nav SCRIPT`, unpause once the script has
connected, stop the simulator (Ctrl+C to roslaunch). Meanwhile it records
base_pose_ground_truth and odom, and at the end prints a table per script, writes it to OUTPUT/summary.txt
and draws the paths
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
import subprocess
import sys
import time

from tb3_harness import calibration, dqn, exploring, leftovers, mapping, navigating, report
from tb3_harness.processes import RunError, say, start_master
from tb3_harness.tutorial import LAUNCH, SCRIPTS, run_script
from tb3_sim_nav.robot_model import TURTLEBOT3_MODELS

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXPLORE_TIMEOUT = 3600.0  # wall s for the house's exploration
_T0 = time.monotonic()


class Interrupted(BaseException):
    """SIGTERM, turned into an exception so the clean-up runs."""


def parse_args(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--real-time-factor', type=float, default=0.0, metavar='F',
                        help='launch arg real_time_factor (default 0 = as fast as possible: nothing is '
                             'shown, and lockstep makes the paths the same at every factor)')
    parser.add_argument('--profile', metavar='NAME',
                        help='launch arg profile (passed only if given)')
    parser.add_argument('--model', choices=TURTLEBOT3_MODELS,
                        help='launch arg model (default: $TURTLEBOT3_MODEL, else burger)')
    parser.add_argument('--output', default=os.path.join(ROOT, 'demo_output'), metavar='DIR',
                        help='folder for demo_paths.png, summary.txt and logs/ (default: %(default)s)')
    parser.add_argument('--scripts', nargs='+', choices=[name for name, _ in SCRIPTS], metavar='SCRIPT',
                        help='run only these scripts (default: all three, in the tutorial\'s order)')
    parser.add_argument('--calibrate', action='store_true',
                        help='the calibration walkthrough (profile realistic) instead of the tutorial\'s scripts')
    parser.add_argument('--slam', action='store_true',
                        help='map turtlebot3_world (profile realistic) and save the map, instead of the tutorial')
    parser.add_argument('--nav', action='store_true',
                        help='navigate turtlebot3_world to four goals (profile realistic), instead of the tutorial')
    parser.add_argument('--explore', action='store_true',
                        help='map turtlebot3_house alone, save the map, navigate four rooms on it (profile realistic)')
    parser.add_argument('--dqn', action='store_true',
                        help='train ROBOTIS\' DQN agent in stage 1 for %d episodes, headless' % dqn.DEMO_EPISODES)
    args = parser.parse_args(argv)
    mapping_chapters = args.slam or args.nav or args.explore or args.dqn
    if args.calibrate + args.slam + args.nav + args.explore + args.dqn > 1:
        parser.error('--calibrate, --slam, --nav, --explore and --dqn are walkthroughs of their own: one at a time')
    if mapping_chapters and (args.scripts or args.profile not in (None, 'realistic')):
        parser.error('--slam, --nav and --explore run their own drives in profile realistic: no --scripts, '
                     'no other --profile')
    if args.calibrate and (args.scripts or args.profile not in (None, 'realistic')):
        parser.error('--calibrate runs its own scripts in profile realistic: no --scripts, no other --profile')
    if not args.real_time_factor >= 0.0:
        parser.error('--real-time-factor must be >= 0, not %r' % args.real_time_factor)
    return args


def check_environment(args):
    """Fail early, with the fix, if we are not inside `source setup.bash`."""
    for tool in ('roscore', 'roslaunch', 'rosrun'):
        if subprocess.call(['which', tool], stdout=subprocess.DEVNULL) != 0:
            raise RunError('%s not found: run `source setup.bash` (or `make demo`) first' % tool)
    for package in ('tb3_sim_nav', LAUNCH[0]):
        if subprocess.call(['rospack', 'find', package], stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL) != 0:
            raise RunError('ROS package %s not found: run `make setup` and `source setup.bash`' % package)
    if args.profile is not None:
        listing = subprocess.run(['roslaunch', '--ros-args'] + list(LAUNCH), stdout=subprocess.PIPE,
                                 stderr=subprocess.STDOUT, universal_newlines=True, timeout=60).stdout
        names = [line.split()[0] for line in listing.splitlines() if line.startswith('  ') and line.split()]
        if 'profile' not in names:
            raise RunError('--profile given, but %s has no `profile` argument (it has: %s)'
                            % (LAUNCH[1], ', '.join(names)))


def write_calibration(args, calibrated, total):
    before, after, linear, angular, corrections = calibrated
    text = '\n'.join(calibration.table(before, after, linear, angular, corrections, args.real_time_factor)
                     + ['', 'total wall time %.1f s' % total])
    print('\n' + text, flush=True)
    summary_file = os.path.join(args.output, 'calibration.txt')
    with open(summary_file, 'w') as summary:
        summary.write(text + '\n')
    picture = os.path.join(args.output, 'calibration_paths.png')
    report.plot_paths([before, after], picture, 'odom_out_and_back.py before and after calibration '
                      '(profile realistic, seed %d)' % calibration.SEED)
    say('wrote %s and %s' % (picture, summary_file))


def write_walkthrough(args, lines, total, table_name, picture_name, draw, *written):
    """A mapping or navigation walkthrough's table printed and written to OUTPUT/table_name,
    its picture drawn (draw(path)) to OUTPUT/picture_name."""
    text = '\n'.join(lines + ['', 'total wall time %.1f s' % total])
    print('\n' + text, flush=True)
    table, picture = os.path.join(args.output, table_name), os.path.join(args.output, picture_name)
    with open(table, 'w') as summary:
        summary.write(text + '\n')
    draw(picture)
    say('wrote %s' % ', '.join(list(written) + [table, picture]))


def main(argv=None):
    args = parse_args(argv)
    log_dir = os.path.join(args.output, 'logs')
    os.makedirs(log_dir, exist_ok=True)

    def on_sigterm(signum, _frame):
        raise Interrupted('signal %d' % signum)
    signal.signal(signal.SIGTERM, on_sigterm)
    signal.signal(signal.SIGINT, signal.default_int_handler)  # even if started with SIGINT ignored

    calibrated = mapped = navigated = explored = trained = None
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
            raise RunError('the demo node did not pick up /use_sim_time')
        if args.calibrate:
            calibrated = calibration.calibrate(args.real_time_factor, log_dir)
        if args.slam:
            mapped = mapping.map_world(log_dir, args.output, factor=args.real_time_factor)
        if args.nav:
            navigated = navigating.navigate_world(log_dir, factor=args.real_time_factor)
        if args.explore:
            launch, start, slam_args = exploring.WORLDS['turtlebot3_house']
            explored = exploring.explore_world(log_dir, args.output, 'turtlebot3_house', launch, start,
                                               factor=args.real_time_factor, timeout=EXPLORE_TIMEOUT,
                                               slam_command=exploring.SLAM_COMMAND + list(slam_args))
            navigated = navigating.navigate_world(log_dir, factor=args.real_time_factor, world='turtlebot3_house',
                                                  launch='tb3_house.launch', map_file=explored.map_yaml,
                                                  goals=navigating.HOUSE_GOALS, spawn=navigating.HOUSE_SPAWN)
        if args.dqn:
            trained = dqn.train(log_dir, args.output, factor=args.real_time_factor)
        for script, expected in scripts if not (args.calibrate or args.slam or args.nav or args.explore or args.dqn) \
                else ():
            # Started paused, time starting once the script has connected: as fast as possible
            # the simulator would otherwise run some 80 sim s while python starts the script.
            result, error = run_script(script, expected, argparse.Namespace(paused_start=True, **vars(args)), log_dir)
            results.append(result)
            if error:
                failures.append('%s: %s' % (script, error))
    except RunError as failure:
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
    if calibrated is not None:
        write_calibration(args, calibrated, total)
    if mapped is not None:
        write_walkthrough(args, mapping.table(mapped), total, 'slam.txt', 'slam_map.png',
                          lambda picture: mapping.draw(mapped, picture), mapped.map_yaml)
    if explored is not None and navigated is not None:
        write_walkthrough(args, exploring.table(explored) + [''] + navigating.table(navigated), total, 'explore.txt',
                          'explore.png', lambda picture: exploring.draw(explored, picture, navigated.truth),
                          explored.map_yaml)
    elif navigated is not None:
        write_walkthrough(args, navigating.table(navigated), total, 'nav.txt', 'nav_paths.png',
                          lambda picture: navigating.draw(navigated, picture))
    if trained is not None:
        write_walkthrough(args, dqn.table(trained[0]), total, 'dqn.txt', 'dqn_result.png', trained[1])
    model = args.model or os.environ.get('TURTLEBOT3_MODEL', 'burger')
    if results:
        header = ['tb3_sim_nav demo: the tutorial\'s scripts on the pybullet TurtleBot3 %s' % model,
                  'real_time_factor %g%s, total wall time %.1f s'
                  % (args.real_time_factor, ', profile %s' % args.profile if args.profile else '', total),
                  'sim time: from the unpause to the script\'s exit (its python exit runs in sim time too:',
                  'as fast as possible, tens of sim seconds)', '']
        lines = header
        for result in results:
            lines += report.table(result) + ['']
        text = '\n'.join(lines)
        print('\n' + text, flush=True)
        summary_file = os.path.join(args.output, 'summary.txt')
        with open(summary_file, 'w') as summary:
            summary.write(text)
        picture = os.path.join(args.output, 'demo_paths.png')
        report.plot_paths(results, picture,
                          'TurtleBot3 %s in pybullet, real_time_factor %g%s' % (
                              model, args.real_time_factor, ', profile %s' % args.profile if args.profile else ''))
        say('wrote %s and %s (process logs in %s)' % (picture, summary_file, log_dir))
    if failures:
        print('\ndemo FAILED:\n  ' + '\n  '.join(failure.replace('\n', '\n    ') for failure in failures),
              file=sys.stderr, flush=True)
        return 1
    if calibrated is not None:
        say('demo done: calibration walkthrough complete')
        return 0
    if navigated is not None:
        failed = [o for o in navigated.outcomes if o.state != 'SUCCEEDED']
        say('demo done: %d of %d goals SUCCEEDED' % (len(navigated.outcomes) - len(failed), len(navigated.outcomes)))
        return 1 if failed else 0
    if mapped is not None:
        missed = mapped.quality.failures()
        say('demo done: turtlebot3_world mapped%s' % ('; MISSED: ' + '; '.join(missed) if missed else ''))
        return 1 if missed else 0
    say('demo done: %d scripts, all exited 0' % len(results))
    return 0


if __name__ == '__main__':
    sys.exit(leftovers.run('make demo', main))
