"""How fast ROBOTIS' DQN learns stage 1 here, as a table (issue 30's benchmark).

Run inside `source setup.bash`, niced on a shared machine. A benchmark, not
a test: it starts a master and `roslaunch turtlebot3_gazebo
turtlebot3_stage_1.launch` (the fastest factor, 0, and the simulator's seed
0: the launch's defaults), then trains ROBOTIS' agent from scratch in this
process (turtlebot3_dqn's Env and Trainer, seed 0, ROBOTIS' values) and,
every --eval-every episodes, runs the greedy policy for --eval-episodes
episodes, each to its first goal, a collision or 500 steps, towards the same
goals each time (respawnGoal's rule, seed 1000). It stops when a share
--target of them reach the goal, or after --max-minutes of wall time, and
prints: sim s per wall s while training, the training's wall minutes until
then (the evaluations' own time apart), and what the same episodes would take
at Gazebo's real time (their sim time).

    python3 tools/bench_dqn.py [--eval-every 20] [--eval-episodes 20] [--target 0.8] [--max-minutes 45]
                               [--png doc/dqn_stage_1.png] [--csv FILE]
"""
import turtlebot3_dqn  # noqa: F401, I001 (first, before numpy: one BLAS thread, see tb3_common)

import argparse
import datetime
import os
import shutil
import sys
import tempfile
import time

from tb3_harness import leftovers
from tb3_harness.measure import machine
from tb3_harness.processes import Process, RunError, say, start_master, tail

EVAL_SEED = 1000


def evaluate(env, agent, goals, run_episode):
    """(successes, episodes' sim s, wall s) of the greedy policy towards each goal of `goals`."""
    successes, sim_seconds, started = 0, 0.0, time.monotonic()
    for goal in goals:
        episode = run_episode(env, agent, 0, learn=False, greedy=True, stop_at_goal=True, options={'goal': goal})
        successes += episode.goals > 0
        sim_seconds += episode.sim_seconds
    return successes, sim_seconds, time.monotonic() - started


def bench(args, log_dir):
    from turtlebot3_dqn import core
    from turtlebot3_dqn.config import AgentConfig, NodeConfig
    from turtlebot3_dqn.environment import Env
    from turtlebot3_dqn.graphs import write_png
    from turtlebot3_dqn.training import Trainer, read_results, run_episode

    from tb3_common.ros import lifecycle

    os.environ.setdefault('TURTLEBOT3_MODEL', 'burger')  # ROBOTIS' launch files read it whatever model:= says
    master = start_master(log_dir)
    world = None
    try:
        world = Process('stage_1', ['roslaunch', 'turtlebot3_gazebo', 'turtlebot3_stage_1.launch', 'model:=burger'],
                        log_dir)
        life = lifecycle.init_node('turtlebot3_dqn_bench')
        env = Env(1, seed=0, life=life)
        save_dir = os.path.join(log_dir, 'save_model')
        trainer = Trainer(env, NodeConfig(episodes=100000, save_dir=save_dir), AgentConfig(), 1, save_dir,
                          log=lambda text: None)
        goal_maker = core.Goals(1, EVAL_SEED)
        goals = [goal_maker.next() for _ in range(args.eval_episodes)]
        train_sim = train_wall = eval_sim = eval_wall = 0.0
        passed, rows = None, []
        for episode in trainer.episodes():
            train_sim += episode.sim_seconds
            train_wall += episode.wall_seconds
            if episode.episode % args.eval_every:
                continue
            successes, sim_seconds, wall_seconds = evaluate(env, trainer.agent, goals, run_episode)
            eval_sim, eval_wall = eval_sim + sim_seconds, eval_wall + wall_seconds
            rows.append((episode.episode, successes, train_wall / 60.0, train_sim / max(train_wall, 1e-9)))
            say('episode %d: greedy policy reached %d of %d goals; training so far %.1f wall min, %.0f sim s '
                '(%.1fx real time), evaluations %.1f wall min' % (episode.episode, successes, len(goals),
                                                                  train_wall / 60.0, train_sim, rows[-1][3],
                                                                  eval_wall / 60.0))
            if successes >= args.target * len(goals):
                passed = episode.episode
                break
            if (train_wall + eval_wall) / 60.0 > args.max_minutes:
                break
            if not world.running():
                raise RunError('the simulator ended: %s' % tail(world.log))
        if args.png:
            write_png(read_results(trainer.results), args.png, 'stage 1, seed 0: training from scratch')
        if args.csv:
            shutil.copy(trainer.results, args.csv)
        return rows, passed, (train_sim, train_wall, eval_sim, eval_wall), len(goals)
    finally:
        import rospy
        if rospy.core.is_initialized():
            rospy.signal_shutdown('bench done')
        if world is not None:
            world.stop()
        master.stop()


def table(rows, passed, totals, evaluations, args):
    train_sim, train_wall, eval_sim, eval_wall = totals
    lines = ['turtlebot3_dqn stage 1 from scratch (seed 0, factor 0), %s' % datetime.date.today().isoformat(),
             'machine: %s' % machine(), '',
             '| | |', '|---|---|',
             '| sim s per wall s while training | %.2fx |' % (train_sim / max(train_wall, 1e-9)),  # 9.98 is not 10
             '| episodes trained | %d |' % (rows[-1][0] if rows else 0),
             '| greedy policy reaches the goal in >= %d %% of %d episodes | %s |'
             % (round(args.target * 100), evaluations,
                'after episode %d' % passed if passed else 'not within %g wall min' % args.max_minutes),
             '| wall minutes of training until then | %.1f (evaluations: %.1f more) |'
             % (train_wall / 60.0, eval_wall / 60.0),
             '| the same episodes at Gazebo\'s real time | %.1f min of training (evaluations: %.1f more) |'
             % (train_sim / 60.0, eval_sim / 60.0), '',
             '| after episode | goals reached (greedy) | training wall min | sim s / wall s |', '|---|---|---|---|']
    lines += ['| %d | %d of %d | %.1f | %.1fx |' % (episode, successes, evaluations, minutes, speed)
              for episode, successes, minutes, speed in rows]
    return '\n'.join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--eval-every', type=int, default=20, help='episodes between two evaluations')
    parser.add_argument('--eval-episodes', type=int, default=20, help='greedy episodes of an evaluation')
    parser.add_argument('--target', type=float, default=0.8, help='share of them that must reach the goal')
    parser.add_argument('--max-minutes', type=float, default=45.0, help='wall minutes at most')
    parser.add_argument('--png', default='', help='write the graph of score and average max Q here')
    parser.add_argument('--csv', default='', help='copy the results (one row an episode) here')
    args = parser.parse_args(argv)
    log_dir = tempfile.mkdtemp(prefix='bench_dqn_')
    say('logs in %s' % log_dir)

    def run():
        rows, passed, totals, evaluations = bench(args, log_dir)
        print(table(rows, passed, totals, evaluations, args), flush=True)
        return 0 if passed else 1
    return leftovers.run('bench_dqn', run)


if __name__ == '__main__':
    sys.exit(main())
