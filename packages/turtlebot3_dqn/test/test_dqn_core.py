"""turtlebot3_dqn's pure core against ROBOTIS' formulas (environment_stage_N.py, respawnGoal.py,
turtlebot3_dqn_stage_N, combination_obstacle_N), and the agent and training loop on a fake environment."""
import math
import os
import sys

import numpy as np
import pytest
import torch

sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', 'src'))

from turtlebot3_dqn import core  # noqa: E402
from turtlebot3_dqn.agent import DqnAgent  # noqa: E402
from turtlebot3_dqn.config import AgentConfig, NodeConfig  # noqa: E402
from turtlebot3_dqn.obstacles import Combination  # noqa: E402
from turtlebot3_dqn.training import Trainer, read_results, run_episode  # noqa: E402

from tb3_common.params import ParameterError  # noqa: E402


def robotis_yaw_reward(heading, action):
    """environment_stage_1.setReward's yaw_reward, verbatim."""
    angle = -math.pi / 4 + heading + (math.pi / 8 * action) + math.pi / 2
    return 1 - 4 * math.fabs(0.5 - math.modf(0.25 + 0.5 * angle % (2 * math.pi) / math.pi)[0])


def test_the_five_actions_turn_as_robotis_at_0_15_m_s():
    assert [core.twist(action) for action in range(5)] == [(0.15, 1.5), (0.15, 0.75), (0.15, 0.0), (0.15, -0.75),
                                                           (0.15, -1.5)]


def test_ranges_read_inf_as_3_5_and_nan_as_0():
    assert core.ranges_of([math.inf, math.nan, 1.25, -math.inf], 0.12) == [3.5, 0.0, 1.25, 0.12]


def test_the_state_of_stage_1_is_24_ranges_heading_and_distance():
    ranges = [1.0] * 24
    state, collided, at_goal = core.observe(core.STAGES[1], ranges, (0.0, 0.0, math.pi / 2), (0.6, 0.0))
    assert len(state) == 26 and state[-2:] == [round(-math.pi / 2, 2), 0.6]
    assert (collided, at_goal) == (False, False)


def test_later_stages_add_the_nearest_range_and_its_beam():
    ranges = [2.0] * 24
    ranges[7] = 0.456
    state, _, _ = core.observe(core.STAGES[2], ranges, (0.0, 0.0, 0.0), (1.0, 1.0))
    assert len(state) == 28 and state[-2:] == [0.46, 7] and state[-3] == 1.41


@pytest.mark.parametrize('nearest, collided', [(0.129, True), (0.13, False), (0.0, False), (0.5, False)])
def test_a_collision_is_a_range_between_0_and_0_13(nearest, collided):
    ranges = [3.5] * 24
    ranges[3] = nearest
    assert core.observe(core.STAGES[1], ranges, (0.0, 0.0, 0.0), (1.0, 0.0))[1] is collided


def test_the_goal_is_reached_within_0_2_m():
    assert core.observe(core.STAGES[1], [3.5] * 24, (0.41, 0.0, 0.0), (0.6, 0.0))[2]
    assert not core.observe(core.STAGES[1], [3.5] * 24, (0.39, 0.0, 0.0), (0.6, 0.0))[2]


@pytest.mark.parametrize('heading', np.linspace(-3.1, 3.1, 23))
def test_the_heading_terms_are_robotis(heading):
    assert core.heading_rewards(heading) == pytest.approx([robotis_yaw_reward(heading, a) for a in range(5)])


def test_the_reward_is_robotis_for_each_stage():
    state = [1.0] * 24 + [0.3, 0.8]
    expected = round(robotis_yaw_reward(0.3, 1) * 5, 2) * 2 ** (0.8 / 1.6)
    assert core.reward(core.STAGES[1], state, 1, 1.6, False, False) == pytest.approx(expected)
    assert core.reward(core.STAGES[1], state, 1, 1.6, True, False) == -200
    assert core.reward(core.STAGES[1], state, 1, 1.6, True, True) == 200
    near = [1.0] * 24 + [0.3, 0.8, 0.4, 3]
    assert core.reward(core.STAGES[2], near, 1, 1.6, True, False) == -150
    assert core.reward(core.STAGES[3], near, 1, 1.6, False, True) == 200
    assert core.reward(core.STAGES[4], near, 1, 1.6, False, False) == pytest.approx(expected - 5)
    assert core.reward(core.STAGES[4], near, 1, 1.6, True, False) == -500
    assert core.reward(core.STAGES[4], near, 1, 1.6, False, True) == 1000


def test_goals_follow_respawngoals_rules():
    goals = core.Goals(1, seed=3)
    assert goals.goal == (0.6, 0.0)
    last = goals.goal
    for _ in range(200):
        x, y = goals.next()
        assert -1.2 <= x <= 1.2 and -1.2 <= y <= 1.2 and round(x * 10) == x * 10
        assert not any(abs(x - ox) <= 0.4 and abs(y - oy) <= 0.4 for ox, oy in core.GOAL_KEEP_OUT)
        assert not (abs(x - last[0]) < 1 and abs(y - last[1]) < 1)
        last = (x, y)
    assert [core.Goals(1, seed=3).next() for _ in range(3)] == [core.Goals(1, seed=3).next()] * 3
    stage_4 = core.Goals(4, seed=1)
    picks = [stage_4.next() for _ in range(50)]
    assert all(pick in core.STAGE_4_GOALS for pick in picks)
    assert all(a != b for a, b in zip(picks, picks[1:]))


def test_combination_obstacle_1_walks_its_sixteen_legs_and_comes_back():
    mover, x, y = Combination('obstacle_1'), 2.0, 2.0
    x, y = mover.next(x, y)
    assert (x, y) == pytest.approx((1.995, 1.988))
    legs = set()
    for _ in range(20000):
        x, y = mover.next(x, y)
        legs.add(mover.leg)
    assert legs == set(range(16)) and max(abs(x), abs(y)) < 2.5


def test_the_agent_is_robotis_network_and_hyper_parameters():
    agent = DqnAgent(26, config=AgentConfig(), seed=0)
    shapes = [tuple(p.shape) for p in agent.model.parameters()]
    assert shapes == [(64, 26), (64,), (64, 64), (64,), (5, 64), (5,)]
    config = AgentConfig()
    assert (config.target_update, config.discount_factor, config.learning_rate, config.epsilon, config.epsilon_decay,
            config.epsilon_min, config.batch_size, config.train_start, config.memory) == \
        (2000, 0.99, 0.00025, 1.0, 0.99, 0.05, 64, 64, 1000000)
    assert NodeConfig().episodes == 3000 and NodeConfig().episode_step == 500 and NodeConfig().save_every == 10
    with pytest.raises(ParameterError, match='train_start'):
        AgentConfig(train_start=10)


def test_one_seed_gives_the_same_agent_and_learning():
    def run(seed):
        agent = DqnAgent(26, config=AgentConfig(), seed=seed)
        rng = np.random.default_rng(0)
        for _ in range(100):
            agent.remember(rng.random(26), int(rng.integers(5)), float(rng.random()), rng.random(26), False)
        losses = [agent.learn(target=index % 2 == 1) for index in range(5)]
        return losses, [agent.act(rng.random(26))[0] for _ in range(20)]
    assert run(1) == run(1)
    assert run(1) != run(2)


class LineWorld(object):
    """A fake environment: the robot at x in 0..10, the goal at 10; actions 0-1 go back, 3-4 on, 2 stays;
    below 0 it collides."""
    state_size = 26

    def __init__(self):
        self.x = 0.0

    def reset(self, seed=None, options=None):
        self.x, self.steps, self.goals, self.time = 2.0, 0, 0, 0.0
        return self._state(), {'sim_time': self.time}

    def _state(self):
        return np.array([self.x] * 24 + [0.0, 10.0 - self.x], np.float32)

    def step(self, action):
        self.x += {0: -1.0, 1: -0.5, 2: 0.0, 3: 0.5, 4: 1.0}[action]
        self.steps, self.time = self.steps + 1, self.time + 0.2
        goal, collided = self.x >= 10.0, self.x < 0.0
        if goal:
            self.goals, self.x = self.goals + 1, 2.0
        reward = 200.0 if goal else -200.0 if collided else (action - 2) * 1.0
        info = {'goal': goal, 'goals': self.goals, 'sim_time': self.time}
        return self._state(), reward, collided, self.steps > 50, info


def test_an_episode_learns_publishes_and_decays_epsilon_as_robotis():
    agent = DqnAgent(26, config=AgentConfig(), seed=0)
    seen = []
    episode = run_episode(LineWorld(), agent, 1, on_step=lambda *values: seen.append(values))
    assert episode.steps == len(seen) and seen[-1][1] == pytest.approx(episode.score)
    assert len(agent.memory) == episode.steps and agent.steps == episode.steps
    assert agent.epsilon == pytest.approx(0.99) and episode.sim_seconds == pytest.approx(0.2 * episode.steps)


def test_the_trainer_saves_every_n_episodes_and_resumes(tmp_path):
    config = NodeConfig(episodes=4, save_every=2, seed=5, save_dir=str(tmp_path))
    trainer = Trainer(LineWorld(), config, AgentConfig(), 1, str(tmp_path), log=lambda text: None)
    first = [episode.score for episode in trainer.episodes()]
    assert sorted(os.listdir(tmp_path)) == ['stage_1_2.json', 'stage_1_2.pt', 'stage_1_4.json', 'stage_1_4.pt',
                                            'stage_1_result.csv']
    assert list(read_results(trainer.results)['score']) == pytest.approx(first)
    resumed = Trainer(LineWorld(), config.replace(load_model=True, load_episode=4, episodes=5), AgentConfig(), 1,
                      str(tmp_path), log=lambda text: None)
    assert resumed.first == 5 and resumed.agent.epsilon == pytest.approx(0.99 ** 4)
    for name, value in resumed.agent.model.state_dict().items():
        assert torch.equal(value, trainer.agent.model.state_dict()[name])
    assert [episode.episode for episode in resumed.episodes()] == [5]
    assert len(read_results(trainer.results)['score']) == 5
    greedy = Trainer(LineWorld(), config.replace(load_model=True, load_episode=4, greedy=True), AgentConfig(), 1,
                     str(tmp_path), log=lambda text: None)
    assert greedy.agent.epsilon == 0.0 and [episode.episode for episode in greedy.episodes()] == []
