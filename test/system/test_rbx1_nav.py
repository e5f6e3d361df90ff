"""ROS by Example's navigation scripts, as a learner brings them, against this project's navigation (issue 20).

The book's own files (test/data/rbx1_nav, unchanged; nav_test.py with only
its one Python 3 fix), started through their `#!/usr/bin/env python`
shebang as a learner starts a script of their own inside `source
setup.bash`:

- move_base_square.py, with `tb3_empty_world.launch` and
  `tb3_navigation.launch map_file:=` the book's blank map: no initial pose is
  published (amcl starts at 0, 0, 0, where the robot is), four goals on a
  1 m square, the robot back at its start.
- nav_test.py in the world built from the book's test_map, with the same
  map: it waits for a 2D Pose Estimate (sent here as rviz sends it, once it
  asks), then visits random named rooms, resting 10 s at each; two must
  succeed in a row.

Both at real time, as the README shows the commands.
"""
import math
import os
import re
import shutil
import subprocess

import yaml

from tb3_harness.processes import Process, start_master, tail, wait_until
from tb3_harness.report import figure

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BOOK = os.path.join(REPO, 'test', 'data', 'rbx1_nav')
PYTHON3_FIX = ('sequence = sample(locations, n_locations)', 'sequence = sample(list(locations), n_locations)')
RVIZ_POSE = ("{header: {frame_id: map}, pose: {pose: {orientation: {w: 1.0}}, covariance: [0.25, 0, 0, 0, 0, 0, "
             "0, 0.25, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, "
             "0.06853891945]}}")


# The README's commands, as a learner types them (rviz left out: no screen here).
SQUARE = ['roslaunch tb3_sim_bringup tb3_empty_world.launch',
          'roslaunch tb3_sim_bringup tb3_navigation.launch '
          'map_file:=`rospack find tb3_sim_nav`/maps/rbx1/blank_map.yaml',
          './move_base_square.py']
TOUR = ['roslaunch tb3_sim_bringup tb3_empty_world.launch world:=`rospack find tb3_sim_nav`/maps/rbx1/test_map.yaml',
        'roslaunch tb3_sim_bringup tb3_navigation.launch map_file:=`rospack find tb3_sim_nav`/maps/rbx1/test_map.yaml',
        './nav_test.py']
NO_RVIZ = ' open_rviz:=false'


def typed(name, command, folder):
    return Process(name, ['bash', '-c', command], folder, cwd=folder, die_with_parent=True)


def true_pose():
    printed = subprocess.run(['rostopic', 'echo', '-n', '1', '/base_pose_ground_truth/pose/pose'],
                             stdout=subprocess.PIPE, universal_newlines=True, timeout=60).stdout
    pose = next(yaml.safe_load_all(printed))
    return (pose['position']['x'], pose['position']['y'],
            2 * math.atan2(pose['orientation']['z'], pose['orientation']['w']))


def test_move_base_square_unchanged_drives_the_square_and_comes_home(tmp_path):
    folder = str(tmp_path)
    script = os.path.join(folder, 'move_base_square.py')
    shutil.copy2(os.path.join(BOOK, 'move_base_square.py'), script)
    master = start_master(folder)
    started = []
    try:
        started += [typed('sim', SQUARE[0], folder), typed('nav', SQUARE[1] + NO_RVIZ, folder)]
        square = typed('move_base_square', SQUARE[2], folder)
        started.append(square)
        wait_until(lambda: not square.running(), 900.0, 'the end of move_base_square.py', watch=started[:2])
        x, y, yaw = true_pose()
        succeeded = square.output(None).count('Goal succeeded!')
        print('MEASURED move_base_square.py: exit %s, %d goals succeeded, the robot ends at (%.3f, %.3f, %.3f)'
              % (square.popen.returncode, succeeded, x, y, yaw))
        figure('square_end_offset', max(abs(x), abs(y)), 'max', 'm')
        figure('square_end_yaw', abs(yaw), 'max', 'rad')
        assert square.popen.returncode == 0, tail(square.log)
        assert succeeded == 4, square.output()
        assert abs(x) < 0.1 and abs(y) < 0.1 and abs(yaw) < 0.2
    finally:
        for process in reversed(started):
            process.stop()
        master.stop()


def test_nav_test_with_its_python3_fix_visits_rooms_of_the_test_map(tmp_path):
    folder = str(tmp_path)
    script = os.path.join(folder, 'nav_test.py')
    with open(os.path.join(BOOK, 'nav_test.py')) as original:
        text = original.read()
    assert text.count(PYTHON3_FIX[0]) == 1
    with open(script, 'w') as fixed:
        fixed.write(text.replace(*PYTHON3_FIX))
    os.chmod(script, 0o755)
    master = start_master(folder)
    started = []
    try:
        started += [typed('sim', TOUR[0], folder), typed('nav', TOUR[1] + NO_RVIZ, folder)]
        tour = typed('nav_test', TOUR[2], folder)
        started.append(tour)
        wait_until(lambda: 'Click the 2D Pose Estimate' in tour.output(), 120.0, "nav_test.py's request for a pose",
                   watch=started)
        assert subprocess.call(['rostopic', 'pub', '-1', '/initialpose', 'geometry_msgs/PoseWithCovarianceStamped',
                                RVIZ_POSE], stdout=subprocess.DEVNULL, timeout=60) == 0
        wait_until(lambda: tour.output(None).count('Goal succeeded!') >= 2 or 'Goal failed' in tour.output(None),
                   900.0, 'two rooms reached', watch=started)
        rooms = re.findall(r'Going to: (\w+)', tour.output(None))
        print('MEASURED nav_test.py: rooms %s; %s'
              % (rooms, re.findall(r'Success so far: [^\n]*', tour.output(None))[-1]))
        assert 'Goal failed' not in tour.output(None), tour.output()
    finally:
        for process in reversed(started):
            process.stop()
        master.stop()
