"""ROBOTIS' machine-learning chapter (issue 30), typed as the e-manual types it, and its reproducibility.

    export TURTLEBOT3_MODEL=burger
    roslaunch turtlebot3_gazebo turtlebot3_stage_1.launch
    roslaunch turtlebot3_dqn turtlebot3_dqn_stage_1.launch

    roslaunch turtlebot3_dqn result_graph.launch

Each through bash on a master of the test's own (the graphs on a screen of
the test's own): episodes advance, `result` ([score, average max Q]) comes
once per episode, the result graph draws its red and green curves, and
Ctrl+C (SIGINT to roslaunch alone, which passes it on to its nodes) ends
every node within 2 s.
Then the first episodes twice with one seed, at real_time_factor 1 and 0:
the same score, step for step the same episodes. The first two end in a
collision and a reset_simulation; the third reaches a goal, whose respawn
in mid-episode (delete_model and spawn_sdf_model) must land at the same
step at both factors (it did not while the agent's log messages each asked
the master for a parameter: see doc/design.md).
"""
import csv
import os
import re
import signal
import time

import pytest

from tb3_harness import leftovers
from tb3_harness.screen import save_png, screenshot

from tb3_system_utils import Echo, alive, wait_until

EXPORT = 'export TURTLEBOT3_MODEL=burger'
STAGE = 'roslaunch turtlebot3_gazebo turtlebot3_stage_1.launch'
DQN = 'roslaunch turtlebot3_dqn turtlebot3_dqn_stage_1.launch'
GRAPHS = 'roslaunch turtlebot3_dqn result_graph.launch'
GONE_WITHIN = 2.0   # wall s from Ctrl+C to the end of every node of ours
OURS = ('tb3_sim_node', 'turtlebot3_dqn_stage_1', 'result_graph', 'action_graph')
EPISODE_LINE = re.compile(r'Ep: (\d+) score: (-?[\d.]+)')
SAME_EPISODES = 3   # episodes run twice, at factors 1 and 0 (the third reaches a goal)


@pytest.fixture
def launches(processes, ros_port, tmp_path, monkeypatch):
    """start(name, command): typed through bash, its processes tagged (leftovers.TAG); a master of its own.
    ROS_HOME in the test's folder: the agent saves its models and results there (~/.ros/turtlebot3_dqn)."""
    monkeypatch.setenv('ROS_HOME', str(tmp_path / 'ros_home'))
    processes.start_master('roscore', ros_port)

    def start(name, command):
        tag = '%s.%d.%d' % (name, os.getpid(), time.monotonic_ns())
        launch = processes.start(name, ['bash', '-c', '%s && %s' % (EXPORT, command)],
                                 env=dict(os.environ, PYTHONUNBUFFERED='1', **{leftovers.TAG: tag}))
        launch.tag = tag
        return launch
    return start


def log_text(launch):
    with open(launch.log, errors='replace') as stream:
        return stream.read()


def episodes(launch):
    return [(int(number), float(score)) for number, score in EPISODE_LINE.findall(log_text(launch))]


def roslaunch_pid(launch):
    return next(pid for pid, command in leftovers.tagged(launch.tag) if 'roslaunch' in command)


def ctrl_c(launch, what):
    """SIGINT to the roslaunch of `launch` alone: every node of ours it started gone within GONE_WITHIN."""
    nodes = dict((pid, command) for pid, command in leftovers.tagged(launch.tag)
                 if any(program in command for program in OURS))
    assert nodes, 'no node of ours under %s; %s' % (what, launch.describe())
    os.kill(roslaunch_pid(launch), signal.SIGINT)
    pressed = time.monotonic()
    gone = wait_until(lambda: not any(alive(pid) for pid in nodes), 20.0, poll=0.02)
    took = time.monotonic() - pressed
    print('MEASURED Ctrl+C on %s: its nodes gone after %.2f s' % (what, took))
    assert gone and took <= GONE_WITHIN, '%s: %s still running %.1f s after Ctrl+C; %s' % (
        what, [command for pid, command in nodes.items() if alive(pid)], took, launch.describe())
    assert launch.wait(30.0) is not None, launch.describe()
    left = leftovers.check(launch.tag, 'Ctrl+C on ' + what)
    assert not left, 'left running after Ctrl+C on %s: %s' % (what, left)


def pure(image, channel):
    """Pixels of a pure red (0) or green (1): pyqtgraph's pens (255, 0, 0) and (0, 255, 0)."""
    others = [image[..., index] for index in range(3) if index != channel]
    return int(((image[..., channel] > 200) & (others[0] < 60) & (others[1] < 60)).sum())


def test_the_chapters_commands_train_episode_after_episode_and_end_on_ctrl_c(launches, processes, screen, tmp_path):
    display = screen
    world = launches('stage_1', STAGE)
    results = Echo(processes, '/result')
    graphs = launches('result_graph', GRAPHS)
    agent = launches('dqn_stage_1', DQN)
    assert wait_until(lambda: len(episodes(agent)) >= 3 or not agent.running(), 300.0, poll=0.5), \
        'fewer than 3 episodes within 300 s: %s' % agent.describe()
    assert agent.running() and world.running(), agent.describe() + world.describe()
    done = episodes(agent)
    print('MEASURED episodes: %s' % done)
    assert [number for number, _ in done] == list(range(1, len(done) + 1))
    # `result` once per episode, [score, max Q], the score as the log says.
    rows = wait_until(lambda: len(results.rows()) >= len(done) and results.rows(), 10.0)
    assert len(rows) >= len(done)
    for (number, score), row in zip(done, rows):
        assert float(row['field.data0']) == pytest.approx(score, abs=0.01)
        assert row['field.data1'] != 'nan'
    text = log_text(agent)
    assert 'Goal position : 0.6, 0.0' in text  # the goal box spawned where respawnGoal puts it first
    assert 'Collision!!' in text or 'Time out' in text or 'Goal!!' in text
    time.sleep(1.0)  # the graph redraws every 0.2 s
    image = screenshot(display)
    save_png(image, str(tmp_path / 'result_graph.png'))
    print('MEASURED result graph: %d red, %d green pixels (%s)' % (pure(image, 0), pure(image, 1),
                                                                  tmp_path / 'result_graph.png'))
    assert pure(image, 0) > 50 and pure(image, 1) > 50, graphs.describe()
    ctrl_c(graphs, GRAPHS)
    ctrl_c(agent, DQN)
    ctrl_c(world, STAGE)


def run_episodes(launches, factor, save_dir):
    """The first SAME_EPISODES episodes (seed 0 in both): the rows of the agent's results CSV."""
    world = launches('stage_1_factor_%g' % factor, '%s real_time_factor:=%g' % (STAGE, factor))
    agent = launches('dqn_factor_%g' % factor, '%s episodes:=%d save_dir:=%s' % (DQN, SAME_EPISODES, save_dir))
    assert wait_until(lambda: not agent.running(), 900.0, poll=0.5), 'not done within 900 s: %s' % agent.describe()
    assert len(episodes(agent)) == SAME_EPISODES, agent.describe()
    ctrl_c(world, STAGE)
    with open(os.path.join(save_dir, 'stage_1_result.csv')) as stream:
        return list(csv.DictReader(stream))


def test_one_seed_gives_the_same_episodes_at_factor_1_and_0(launches, tmp_path):
    real_time = run_episodes(launches, 1.0, str(tmp_path / 'factor_1'))
    fastest = run_episodes(launches, 0.0, str(tmp_path / 'factor_0'))
    keys = ('episode', 'score', 'max_q', 'steps', 'goals', 'collided', 'sim_seconds')
    print('MEASURED factor 1: %s' % [[row[key] for key in keys] for row in real_time])
    print('MEASURED factor 0: %s' % [[row[key] for key in keys] for row in fastest])
    print('MEASURED wall s per episode, factor 1: %s; factor 0: %s' % (
        [row['wall_seconds'] for row in real_time], [row['wall_seconds'] for row in fastest]))
    assert [[row[key] for key in keys] for row in real_time] == [[row[key] for key in keys] for row in fastest]
