"""Calibration, as the README walks a learner through it: dynparam on the
simulator's live parameters, our calibrate_linear.py and calibrate_angular.py,
`make demo DEMO_ARGS="--calibrate"`, and a stopped robot that stays still (a
busy core, factors 1 and 0), all with the README's literal commands.

Each test has a roscore of its own on a free loopback port (conftest.py), and
every process it starts is stopped by its process group when it ends, also
when it fails.
"""
import math
import os
import re
import subprocess
import sys
import time

import pytest

from tb3_system_utils import run, wait_until

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REALISTIC = ['roslaunch', 'tb3_sim_bringup', 'tb3_empty_world.launch', 'profile:=realistic']
DYNPARAM_SET = 'rosrun dynamic_reconfigure dynparam set /tb3_sim odom_angular_scale_correction 0.99'
CALIBRATE = 'make demo DEMO_ARGS="--calibrate"'
AGAIN = 'rosrun dynamic_reconfigure dynparam set /calibrate_angular start_test true'
TIMEOUT = 60.0          # wall s for a start-up, one command or one message
DEMO_TIMEOUT = 900      # wall s for the calibration walkthrough (as fast as possible it takes about 20 s)
STILL_SPEED = 0.001     # m/s
STILL_TURN = 0.001      # rad/s
MOVING_TURN = 0.05      # rad/s: above this the robot is still turning as told
WATCH = 60.0            # sim s of stillness checked, from 1 s after the turn ended


def start_simulator(processes, *args):
    sim = processes.start('roslaunch', REALISTIC + list(args))
    ready = wait_until(lambda: run(['rostopic', 'echo', '-n', '1', '/odom/header/stamp'], TIMEOUT).returncode == 0,
                       TIMEOUT)
    assert ready, 'no /odom from %s' % ' '.join(REALISTIC)
    return sim


def parameter(name):
    printed = run(['rosparam', 'get', name], TIMEOUT)
    assert printed.returncode == 0, printed.stdout
    return printed.stdout.strip()


def launch_log(sim):
    with open(sim.log) as log:
        return log.read()


def test_dynparam_changes_a_live_parameter_at_once_logged_and_refuses_bad_values(ros_port, processes):
    processes.start_master('roscore', ros_port)
    sim = start_simulator(processes)
    done = run(DYNPARAM_SET.split(), TIMEOUT)
    assert done.returncode == 0, done.stdout
    assert float(parameter('/tb3_sim/odom_angular_scale_correction')) == 0.99
    assert wait_until(lambda: 'dynamic_reconfigure: odom_angular_scale_correction = 0.99' in launch_log(sim),
                      TIMEOUT), 'the change is not in the simulator\'s log'
    refusals = [('odom_angular_scale_correction', 'nan', 'must be a finite number'),
                ('odom_linear_scale_correction', '7', 'must be between 0.5 and 2'),
                ('cmd_vel_timeout', '-1', 'must be >= 0')]
    for name, value, reason in refusals:
        before = parameter('/tb3_sim/' + name)
        done = run(['rosrun', 'dynamic_reconfigure', 'dynparam', 'set', '/tb3_sim', name, '--', value], TIMEOUT)
        assert done.returncode == 0, done.stdout   # dynparam itself does not know the server refused
        assert wait_until(lambda: re.search(r'refused .*%s.*%s.*; nothing changed' % (name, re.escape(reason)),
                                            launch_log(sim)), TIMEOUT), (name, value, launch_log(sim)[-2000:])
        assert parameter('/tb3_sim/' + name) == before, 'refused, yet %s changed' % name
    # What `dynparam get` shows is what the simulator runs with.
    shown = run(['rosrun', 'dynamic_reconfigure', 'dynparam', 'get', '/tb3_sim'], TIMEOUT)
    assert "'odom_angular_scale_correction': 0.99" in shown.stdout
    assert "'odom_linear_scale_correction': 1.0" in shown.stdout
    assert "'cmd_vel_timeout': 0.5" in shown.stdout


def test_the_angular_correction_scales_odometry_at_once(ros_port, processes):
    """Turning at 0.5 rad/s: /odom's turn rate is the truth's times about 1.5 once the correction is 1.5."""
    processes.start_master('roscore', ros_port)
    start_simulator(processes)
    processes.start('turn', ['rostopic', 'pub', '-r', '10', '/cmd_vel', 'geometry_msgs/Twist',
                             '{angular: {z: 0.5}}'])

    def ratio():
        odom = run(['rostopic', 'echo', '-n', '1', '/odom/twist/twist/angular/z'], TIMEOUT)
        truth = run(['rostopic', 'echo', '-n', '1', '/base_pose_ground_truth/twist/twist/angular/z'], TIMEOUT)
        turning = float(truth.stdout.split()[0])
        return float(odom.stdout.split()[0]) / turning if abs(turning) > 0.1 else 0.0
    assert wait_until(lambda: abs(ratio() - 1.0) < 0.05, TIMEOUT), 'odometry never turned with the truth'
    done = run(['rosrun', 'dynamic_reconfigure', 'dynparam', 'set', '/tb3_sim', 'odom_angular_scale_correction',
                '1.5'], TIMEOUT)
    assert done.returncode == 0, done.stdout
    measured = ratio()
    assert measured == pytest.approx(1.5, abs=0.08), 'odom / truth turn rate %.3f after the change' % measured


def test_the_imu_covariance_follows_dynparam(ros_port, processes):
    """One Config: after `dynparam set /tb3_sim imu_gyro_noise`, the IMU messages'
    angular-velocity covariance is the new noise squared (the node once kept its
    own frozen copy of the config, and the covariance kept the old noise)."""
    processes.start_master('roscore', ros_port)
    start_simulator(processes)

    def covariance(field):
        shown = run(['rostopic', 'echo', '-n', '1', '/imu/%s_covariance' % field], TIMEOUT)
        assert shown.returncode == 0, shown.stdout
        return float(shown.stdout.strip('[]\n-').split(',')[0])
    assert covariance('angular_velocity') == pytest.approx(2e-3 ** 2)  # the realistic profile's 2e-3 rad/s
    for name, value, field in (('imu_gyro_noise', 0.01, 'angular_velocity'),
                               ('imu_accel_noise', 0.2, 'linear_acceleration')):
        done = run(['rosrun', 'dynamic_reconfigure', 'dynparam', 'set', '/tb3_sim', name, str(value)], TIMEOUT)
        assert done.returncode == 0, done.stdout
        assert wait_until(lambda: covariance(field) == pytest.approx(value ** 2), TIMEOUT), \
            '%s covariance %r after %s = %g' % (field, covariance(field), name, value)


def test_make_demo_calibrate_shrinks_the_odometry_error(tmp_path):
    """The walkthrough: our scripts reach their targets on odometry, the
    corrections come out near 1, and odom_out_and_back.py's odometry ends
    closer to the truth after calibrating than before."""
    env = dict((key, value) for key, value in os.environ.items() if key not in ('MAKEFLAGS', 'MAKELEVEL', 'MFLAGS'))
    output = os.path.join(REPO, 'demo_output')
    table = os.path.join(output, 'calibration.txt')
    before = os.path.getmtime(table) if os.path.exists(table) else 0.0
    done = subprocess.run(['bash', '-c', CALIBRATE], cwd=REPO, env=env, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=DEMO_TIMEOUT)
    assert done.returncode == 0, done.stdout[-3000:]
    assert os.path.getmtime(table) > before
    assert os.path.getsize(os.path.join(output, 'calibration_paths.png')) > 10000
    with open(table) as printed:
        text = printed.read()
    print(text)
    values = dict(re.findall(r'^(\S.*?)\s{2,}(\S+(?:\s+\S+)?)\s*$', text, re.M))
    corrections = [float(values[name]) for name in ('odom_linear_scale_correction', 'odom_angular_scale_correction')]
    assert all(0.97 < value < 1.03 for value in corrections), corrections
    drift_before, drift_after = (float(v) for v in values['odometry off the truth at the end (m)'].split())
    assert drift_after < drift_before / 3.0, (drift_before, drift_after)
    assert drift_after < 0.01
    # Each script stopped when odometry said it had arrived, within its tolerance.
    logs = os.path.join(output, 'logs')
    with open(os.path.join(logs, 'calibrate_linear.log')) as log:
        distance = float(re.search(r'Odometry says ([\d.]+) m', log.read()).group(1))
    with open(os.path.join(logs, 'calibrate_angular.log')) as log:
        angle = float(re.search(r'Odometry says ([\d.]+) degrees', log.read()).group(1))
    assert abs(distance - 1.0) <= 0.01 + 0.0005, distance    # ~test_distance 1 m, ~tolerance 0.01 m
    assert abs(angle - 360.0) <= 1.0 + 0.05, angle          # ~test_angle 360, ~tolerance 1 degree


@pytest.mark.parametrize('factor', ['1', '0'])
def test_a_stopped_robot_stays_still_with_a_busy_core(ros_port, processes, tmp_path, factor):
    """calibrate_angular.py's full turn at 0.5 rad/s, and once more the other way,
    while another program keeps a core busy; from 1 s after the second turn
    ended, a minute of sim time (as fast as possible: Gazebo's
    set_physics_properties) of ground truth below 1 mm/s and 0.001 rad/s."""
    processes.start('busy_core', [sys.executable, '-c', 'while True: pass'])
    processes.start_master('roscore', ros_port)
    start_simulator(processes, 'real_time_factor:=' + factor)
    recording = str(tmp_path / 'truth.csv')
    with open(recording, 'w') as out:
        processes.start('truth', ['rostopic', 'echo', '-p', '/base_pose_ground_truth'], stdout=out)
    turn = processes.start('calibrate_angular', ['rosrun', 'tb3_sim_nav', 'calibrate_angular.py'],
                           env=dict(os.environ, PYTHONUNBUFFERED='1'))   # its log, read while it runs

    def turned(times):
        """Until calibrate_angular.py has set its start_test false `times` times (counted in its log)."""
        return wait_until(lambda: open(turn.log).read().count('Odometry says') >= times, 180.0)
    assert turned(1), 'calibrate_angular.py did not finish its turn: %s' % open(turn.log).read()[-2000:]
    # Once more, the other way round, as the README shows.
    again = run(AGAIN.split(), TIMEOUT)
    assert again.returncode == 0, again.stdout
    assert turned(2), 'calibrate_angular.py did not turn again: %s' % open(turn.log).read()[-2000:]
    turn.stop()
    # The turns were what had to run at the factor; during the watch nothing
    # commands the robot and physics is the same at any factor: Gazebo's way
    # to change it runs the rest as fast as possible (a minute at factor 1).
    as_fast_as_possible()
    _, rows = read_truth(recording)
    turned_until = max(t for t, _, w in rows if w > MOVING_TURN)
    deadline = time.monotonic() + 120.0 + WATCH + 5.0
    while read_truth(recording)[1][-1][0] < turned_until + 1.0 + WATCH and time.monotonic() < deadline:
        time.sleep(1.0)
    rows = [row for row in read_truth(recording)[1] if turned_until + 1.0 <= row[0] <= turned_until + 1.0 + WATCH]
    assert rows and rows[-1][0] - rows[0][0] > WATCH - 0.5, 'ground truth covered only %.1f s of sim time' % (
        rows[-1][0] - rows[0][0] if rows else 0.0)
    fastest, quickest_turn = max(rows, key=lambda row: row[1]), max(rows, key=lambda row: row[2])
    assert fastest[1] < STILL_SPEED, 'moving at %.5f m/s at t = %.2f' % (fastest[1], fastest[0])
    assert quickest_turn[2] < STILL_TURN, 'turning at %.5f rad/s at t = %.2f, %.1f s after the turn' % (
        quickest_turn[2], quickest_turn[0], quickest_turn[0] - turned_until)


def as_fast_as_possible():
    """/gazebo/set_physics_properties with max_update_rate 0 and the rest as get_physics_properties gives it."""
    import yaml
    got = run(['rosservice', 'call', '/gazebo/get_physics_properties'], TIMEOUT)
    assert got.returncode == 0, got.stdout
    physics = yaml.safe_load(got.stdout)
    request = dict((key, physics[key]) for key in ('time_step', 'gravity', 'ode_config'))
    request['max_update_rate'] = 0.0
    done = run(['rosservice', 'call', '/gazebo/set_physics_properties', yaml.safe_dump(request)], TIMEOUT)
    assert done.returncode == 0 and 'success: True' in done.stdout, done.stdout


def read_truth(path):
    """The header and the (stamp s, |v| m/s, |w| rad/s) rows of a `rostopic echo -p` CSV of Odometry."""
    with open(path) as csv:
        lines = [line.rstrip('\n').split(',') for line in csv if line.strip()]
    header = lines[0]
    column = dict((name, index) for index, name in enumerate(header))
    rows = []
    for line in lines[1:]:
        if len(line) != len(header):
            continue   # the line being written
        value = dict((name, float(line[index])) for name, index in column.items()
                     if name.startswith('field.twist.twist') or name == 'field.header.stamp')
        rows.append((value['field.header.stamp'] * 1e-9,
                     math.hypot(value['field.twist.twist.linear.x'], value['field.twist.twist.linear.y']),
                     abs(value['field.twist.twist.angular.z'])))
    return header, rows
