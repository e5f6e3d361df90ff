"""A robot that maps a world by itself (issue 21), judged against the world file.

`roslaunch tb3_sim_bringup tb3_world.launch profile:=realistic real_time_factor:=0`,
then the README's `roslaunch tb3_sim_bringup tb3_slam.launch explore:=true`
through bash, rviz on a screen of the test's own, until the explore node says
it is done, then `rosrun map_server map_saver -f`, all through
tb3_harness.exploring (the demo runs it too): the reachable free floor mapped
as free (goal >= 90 %), the map as precise as the SLAM test wants it, and the
footprint never touching the world on the true path. rviz's last picture goes
to ~/.ros/test_results/tb3_sim_nav/emanual/explore.png (doc/'s is a copy).

Then the bad cases: a robot boxed in ends at once with a clear message and
then sits idle; a move_base that aborts every goal makes the explorer
blacklist them all and stop, not spin.
"""
import os
import re
import time

from test_emanual import FLOOR, SHOTS, WALL, colour_pixels, map_view

from tb3_harness import exploring
from tb3_harness.measure import cpu_seconds, node_pid
from tb3_harness.processes import Process, start_master, wait_until
from tb3_harness.report import figure, map_figures
from tb3_harness.screen import save_png, screenshot

HERE = os.path.dirname(os.path.abspath(__file__))
BOXED_IN = os.path.join(HERE, '..', 'data', 'worlds', 'boxed_in.yaml')
FREE_FLOOR_GOAL = 0.90
WORLD_TIMEOUT = 600.0   # wall s for turtlebot3_world (it took 66 s on a busy machine)
BAD_CASE_TIMEOUT = 120.0  # wall s for a bad case to end
IDLE_WATCH = 5.0        # wall s the explore node is watched after it is done
IDLE_CPU = 0.3          # share of a core it may use meanwhile (tf alone costs 5 %; a loop of searches, a core)


def _read(path):
    with open(path, errors='replace') as stream:
        return stream.read()


def _idle_after_done(log, pid):
    """(explore lines logged, share of a core used) over IDLE_WATCH s after the node said it was done."""
    before, cpu = _read(log).count('explore: ['), cpu_seconds(pid)
    time.sleep(IDLE_WATCH)
    return _read(log).count('explore: [') - before, (cpu_seconds(pid) - cpu) / IDLE_WATCH


def test_exploration_maps_turtlebot3_world_alone(tmp_path, monkeypatch, screen):
    folder, display = str(tmp_path), screen
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')
    master = start_master(folder)
    pictures = []

    def picture():
        image = screenshot(display)
        os.makedirs(SHOTS, exist_ok=True)
        save_png(image, os.path.join(SHOTS, 'explore.png'))
        pictures.append(image)
    try:
        run = exploring.explore_world(folder, folder, timeout=WORLD_TIMEOUT, when_saved=picture, slam_command=[
            'bash', '-c', 'roslaunch tb3_sim_bringup tb3_slam.launch explore:=true'])
    finally:
        master.stop()
    view = map_view(pictures[0])
    walls, floor = colour_pixels(view, WALL, 8), colour_pixels(view, FLOOR, 8)
    print('MEASURED rviz after exploring: %d wall pixels, %d floor pixels' % (walls, floor))
    figure('explore_rviz_wall_pixels', walls, 'min', 'px')
    figure('explore_rviz_floor_pixels', floor, 'min', 'px')
    assert walls > 2000 and floor > 20000  # the map, shown in rviz
    quality = run.quality
    print('MEASURED %s' % run.summary())
    figure('explore_free_floor_mapped', 100 * quality.free_floor_mapped, 'min', '%')
    map_figures('explore_map', quality)
    figure('explore_clearance', run.clearance, 'min', 'm')
    figure('explore_goals', run.goals, 'min')
    assert 'no frontier' in run.done_text and 'boxed in' not in run.done_text, run.done_text
    assert quality.free_floor_mapped >= FREE_FLOOR_GOAL, quality.summary()
    assert not quality.failures(), quality.failures()
    assert run.clearance > 0.0, run.clearance
    assert run.goals >= 2


def test_a_boxed_in_robot_ends_with_a_clear_message_and_then_idles(tmp_path):
    folder = str(tmp_path)
    master = start_master(folder)
    started = []
    try:
        started.append(Process('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_empty_world.launch',
                                       'world:=%s' % BOXED_IN, 'profile:=realistic', 'real_time_factor:=0'], folder))
        slam = Process('slam', ['roslaunch', 'tb3_sim_bringup', 'tb3_slam.launch', 'explore:=true',
                                'open_rviz:=false'], folder)
        started.append(slam)
        wait_until(lambda: exploring.progress(_read(slam.log))[2] is not None, BAD_CASE_TIMEOUT,
                   'the explore node\'s end', poll=0.5, watch=started)
        goals, _, done = exploring.progress(_read(slam.log))
        lines, cpu = _idle_after_done(slam.log, node_pid('/explore'))
    finally:
        for process in reversed(started):
            process.stop()
        master.stop()
    print('MEASURED boxed in: %r; %d goals sent; afterwards %d lines and %.1f %% of a core in %.0f s'
          % (done.group(0), goals, lines, 100 * cpu, IDLE_WATCH))
    figure('boxed_in_idle_cpu', 100 * cpu, 'max', '%')
    assert 'boxed in' in done.group(2), done.group(0)
    assert goals == 0
    assert lines == 0 and cpu < IDLE_CPU


def test_a_move_base_that_aborts_every_goal_makes_exploration_stop(tmp_path):
    folder = str(tmp_path)
    master = start_master(folder)
    started = []
    try:
        started.append(Process('sim', ['roslaunch', 'tb3_sim_bringup', 'tb3_world.launch', 'profile:=realistic',
                                       'real_time_factor:=0'], folder))
        started.append(Process('slam', ['roslaunch', 'tb3_sim_bringup', 'tb3_slam.launch', 'open_rviz:=false'],
                               folder))
        stand_in = Process('move_base', ['python3', os.path.join(HERE, 'aborting_move_base.py')], folder)
        started.append(stand_in)
        explore = Process('explore', ['rosrun', 'explore_lite', 'explore'], folder)
        started.append(explore)
        wait_until(lambda: exploring.progress(_read(explore.log))[2] is not None, BAD_CASE_TIMEOUT,
                   'the explore node\'s end', poll=0.5, watch=started)
        goals, last, done = exploring.progress(_read(explore.log))
        lines, cpu = _idle_after_done(explore.log, node_pid('/explore'))
        aborted = len(re.findall(r'aborted goal \d+', _read(stand_in.log)))
    finally:
        for process in reversed(started):
            process.stop()
        master.stop()
    print('MEASURED every goal aborted: %r; %d goals sent, %d aborted by the stand-in; afterwards %d lines and '
          '%.1f %% of a core in %.0f s' % (done.group(0), goals, aborted, lines, 100 * cpu, IDLE_WATCH))
    figure('all_aborted_idle_cpu', 100 * cpu, 'max', '%')
    assert 'blacklisted' in done.group(2) and 'boxed in' not in done.group(2), done.group(0)
    assert goals >= 2 and aborted == goals == int(done.group(8)), (goals, aborted, done.group(0))
    assert lines == 0 and cpu < IDLE_CPU
