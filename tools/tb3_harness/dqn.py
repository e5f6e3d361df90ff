"""`make demo DEMO_ARGS="--dqn"`: a short headless training of ROBOTIS' DQN agent in stage 1 (issue 30).

The e-manual's two launches (turtlebot3_gazebo's turtlebot3_stage_1.launch,
as fast as possible, and turtlebot3_dqn's turtlebot3_dqn_stage_1.launch) with
`episodes`, the models and results saved in OUTPUT/dqn/ and the graph of
score and average max Q per episode in OUTPUT/dqn_result.png.
"""
import csv
import os

from .processes import Process, RunError, say, tail, wait_until

DEMO_EPISODES = 20
TIMEOUT = 1800.0  # wall s for the whole training


def train(log_dir, output, episodes=DEMO_EPISODES, factor=0.0, timeout=TIMEOUT):
    """The training's rows (the agent's results CSV, a dict an episode) and draw(path), which draws their
    graph (the agent drew it too, at each save)."""
    save_dir, picture = os.path.join(output, 'dqn'), os.path.join(output, 'dqn_result.png')
    os.environ.setdefault('TURTLEBOT3_MODEL', 'burger')  # ROBOTIS' launch files read it whatever model:= says
    started = []
    try:
        world = Process('stage_1', ['roslaunch', 'turtlebot3_gazebo', 'turtlebot3_stage_1.launch', 'model:=burger',
                                    'real_time_factor:=%g' % factor], log_dir)
        started.append(world)
        agent = Process('dqn_stage_1', ['roslaunch', 'turtlebot3_dqn', 'turtlebot3_dqn_stage_1.launch',
                                        'episodes:=%d' % episodes, 'save_dir:=%s' % save_dir,
                                        'result_png:=%s' % picture], log_dir)
        started.append(agent)
        say('training stage 1 for %d episodes (factor %g): models and results in %s' % (episodes, factor, save_dir))
        wait_until(lambda: not agent.running(), timeout, 'end of %d episodes' % episodes, poll=1.0, watch=(world,))
        results = os.path.join(save_dir, 'stage_1_result.csv')
        if not os.path.exists(results):
            raise RunError('the agent wrote no results: %s' % tail(agent.log))
        with open(results) as stream:
            rows = list(csv.DictReader(stream))
        if len(rows) < episodes:
            raise RunError('the agent ended after %d of %d episodes: %s' % (len(rows), episodes, tail(agent.log)))
        return rows, lambda path: _draw(results, path)
    finally:
        for process in reversed(started):
            process.stop()


def _draw(results, path):
    from turtlebot3_dqn.graphs import write_png
    from turtlebot3_dqn.training import read_results
    write_png(read_results(results), path, 'stage 1: the first episodes')


def table(rows):
    sim, wall = sum(float(row['sim_seconds']) for row in rows), sum(float(row['wall_seconds']) for row in rows)
    lines = ['turtlebot3_dqn stage 1: %d episodes, %.0f s of sim time in %.0f s of wall time (%.1fx real time)'
             % (len(rows), sim, wall, sim / max(wall, 1e-9)), '',
             '| episode | score | average max Q | steps | goals | end |', '|---|---|---|---|---|---|']
    lines += ['| %s | %.1f | %.2f | %s | %s | %s |' % (row['episode'], float(row['score']), float(row['max_q']),
                                                     row['steps'], row['goals'],
                                                     'collision' if row['collided'] == 'True' else 'time out')
              for row in rows]
    return lines
