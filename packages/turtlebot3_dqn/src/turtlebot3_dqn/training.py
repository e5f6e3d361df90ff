"""The loop of ROBOTIS' turtlebot3_dqn_stage_N over any environment with reset()/step(). No ROS here.

Per step, as ROBOTIS': act (epsilon-greedy), step, remember (a collision
ends the transition, a time-out does not), learn once the memory holds
train_start transitions (targets from the target network after the run's
first target_update steps), add the reward to the score. Per episode: the
target network takes the network's weights, epsilon decays, the result
([score, max Q]) goes out, the model is saved every save_every episodes.
Two departures: the max Q of an episode is the average over its steps of
the network's best Q of the state acted upon (the graph's title, "Average
max Q-value"; ROBOTIS' was the last Q it happened to compute, zeros after
a random action), and the model is saved once at the episode's end, not
at every step of it.
"""
import csv
import os
import time
from dataclasses import asdict, dataclass

import numpy as np

from .agent import DqnAgent

RESULT_FIELDS = ('episode', 'score', 'max_q', 'steps', 'goals', 'collided', 'sim_seconds', 'wall_seconds', 'epsilon')


@dataclass
class Episode:
    episode: int
    score: float
    max_q: float        # average over the episode's steps of the best Q of the state acted upon
    steps: int
    goals: int
    collided: bool
    sim_seconds: float  # sim time the episode took (its steps' scans)
    wall_seconds: float
    epsilon: float      # after the episode's decay


def run_episode(env, agent, number, learn=True, greedy=False, on_step=None, stop_at_goal=False, options=None):
    """One episode: an Episode. `learn`: remember and learn as ROBOTIS (else only act); `greedy`: always
    the best action; `on_step(action, score, reward)`: ROBOTIS' get_action; `stop_at_goal`: end at the
    first goal (evaluation)."""
    started = time.monotonic()
    state, info = env.reset(options=options)
    start_time = info['sim_time']
    score, q_sum, steps, goals, collided = 0.0, 0.0, 0, 0, False
    while True:
        action, max_q = agent.act(state, greedy=greedy)
        next_state, reward, terminated, truncated, info = env.step(action)
        steps, q_sum, score = steps + 1, q_sum + max_q, score + reward
        goals, collided = info['goals'], terminated
        if learn:
            agent.remember(state, action, reward, next_state, terminated)
            if agent.ready():
                agent.learn(target=agent.steps > agent.config.target_update)
            agent.steps += 1
        if on_step is not None:
            on_step(action, score, reward)
        state = next_state
        if terminated or truncated or (stop_at_goal and info['goal']):
            break
    if learn:
        agent.end_episode()
    return Episode(number, float(score), q_sum / steps, steps, goals, collided, info['sim_time'] - start_time,
                   time.monotonic() - started, agent.epsilon)


class Trainer(object):
    """ROBOTIS' main loop: episodes load_episode + 1 .. episodes, saved every save_every, results in a CSV."""

    def __init__(self, env, config, agent_config, stage, save_dir, log=print):
        self.env, self.config, self.stage, self.save_dir, self.log = env, config, stage, save_dir, log
        self.agent = DqnAgent(env.state_size, config=agent_config, seed=config.seed)
        self.first = 1
        if config.load_model:
            saved = self.agent.load(self.stem(config.load_episode))
            self.first = saved + 1
            log('loaded %s (epsilon %.3f)' % (self.stem(config.load_episode), self.agent.epsilon))
        if config.greedy:
            self.agent.epsilon = 0.0
        self.results = os.path.join(save_dir, 'stage_%d_result%s.csv' % (stage, '_greedy' if config.greedy else ''))

    def stem(self, episode):
        return os.path.join(self.save_dir, 'stage_%d_%d' % (self.stage, episode))

    def episodes(self, on_step=None):
        """Runs the episodes, yielding each Episode as it ends (saved first when due)."""
        os.makedirs(self.save_dir, exist_ok=True)
        fresh = not os.path.exists(self.results) or (self.first == 1 and not self.config.greedy)
        with open(self.results, 'w' if fresh else 'a', newline='') as stream:
            writer = csv.DictWriter(stream, RESULT_FIELDS)
            if fresh:
                writer.writeheader()
            for number in range(self.first, self.config.episodes + 1):
                episode = run_episode(self.env, self.agent, number, learn=not self.config.greedy,
                                      greedy=self.config.greedy, on_step=on_step)
                writer.writerow(asdict(episode))
                stream.flush()
                if not self.config.greedy and number % self.config.save_every == 0:
                    self.agent.save(self.stem(number), number)
                self.log('Ep: %d score: %.2f memory: %d epsilon: %.2f steps: %d goals: %d sim: %.0f s wall: %.1f s'
                         % (number, episode.score, len(self.agent.memory), episode.epsilon, episode.steps,
                            episode.goals, episode.sim_seconds, episode.wall_seconds))
                yield episode


def read_results(path):
    """The episodes of a results CSV: {field: numpy array}."""
    with open(path, newline='') as stream:
        rows = list(csv.DictReader(stream))
    return {field: np.array([float(row[field] == 'True') if field == 'collided' else float(row[field])
                             for row in rows]) for field in RESULT_FIELDS}
