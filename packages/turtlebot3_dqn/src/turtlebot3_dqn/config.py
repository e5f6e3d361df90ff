"""The agent's parameters under ROBOTIS' names and values, and the node's own. No ROS here.

ROBOTIS' turtlebot3_dqn_stage_N sets its hyper-parameters in the agent's
constructor (the e-manual's "Set hyper parameters" table) and its
load_model/load_episode there too; here each is a private parameter of the
node (`~learning_rate`, `~load_model`, ...) with ROBOTIS' value as default.
"""
import dataclasses

from tb3_common.params import Checked, fail, non_negative, number, parameter, positive

probability = number(0.0, 1.0)
whole = number(1)


@dataclasses.dataclass(frozen=True)
class AgentConfig(Checked):
    """The DQN agent's hyper-parameters: ROBOTIS' names and values."""
    target_update: int = parameter(2000, 'steps of the whole run after which the targets come from the target '
                                   'network (copied from the network at each episode\'s end), not from the '
                                   'network itself, as ROBOTIS\' agent does', non_negative, 'steps')
    discount_factor: float = parameter(0.99, "how much a reward one step later is worth", probability)
    learning_rate: float = parameter(0.00025, "RMSprop's step size (rho 0.9, epsilon 1e-6)", positive)
    epsilon: float = parameter(1.0, 'the probability of a random action, at the start', probability)
    epsilon_decay: float = parameter(0.99, 'epsilon is multiplied by this after each episode', probability)
    epsilon_min: float = parameter(0.05, 'epsilon decays no lower', probability)
    batch_size: int = parameter(64, 'transitions drawn from the memory for each learning step', whole)
    train_start: int = parameter(64, 'learning starts once the memory holds this many transitions', whole)
    memory: int = parameter(1000000, 'the replay memory: the most transitions it keeps, the oldest dropped',
                            whole, 'transitions')
    dropout: float = parameter(0.2, 'the dropout after the second hidden layer, while learning', probability)
    hidden: int = parameter(64, 'units of each of the two hidden layers (relu)', whole)

    def check_together(self):
        if self.train_start < self.batch_size:
            fail('train_start', self.train_start, 'must be at least batch_size (%d)' % self.batch_size)


@dataclasses.dataclass(frozen=True)
class NodeConfig(Checked):
    """The training node's own parameters."""
    seed: int = parameter(0, 'seed of the network\'s weights, the exploration, the memory\'s draws and the goals: '
                          'with the simulator\'s ~seed, the same episodes at any real-time factor; -1: a new one '
                          'each run', number(-1))
    episodes: int = parameter(3000, 'the last episode of the run (ROBOTIS\' EPISODES)', whole)
    episode_step: int = parameter(500, 'an episode times out at this step (ROBOTIS\' `t >= 500`)', whole, 'steps')
    load_model: bool = parameter(False, 'start from the model saved after episode ~load_episode (its weights and '
                                 'epsilon), and go on from the next episode')
    load_episode: int = parameter(0, 'the saved episode to load with ~load_model', non_negative)
    save_every: int = parameter(10, 'save the model (and write the graph, ~result_png) every this many episodes',
                                whole, 'episodes')
    save_dir: str = parameter('', "where models are saved and loaded (stage_N_EPISODE.pt, .json) and the results "
                              "written (stage_N_result.csv); empty: ~/.ros/turtlebot3_dqn ($ROS_HOME; ROBOTIS' "
                              "wrote in its package)")
    result_png: str = parameter('', 'a PNG of each episode\'s score and average max Q, written at each save, for '
                                'a machine without a screen; empty: none')
    greedy: bool = parameter(False, 'watch a saved model (~load_model): always its best action, no learning, '
                             'nothing saved')
    scan_timeout: float = parameter(5.0, 'wall seconds a step waits for the next scan before it asks again, as '
                                    'ROBOTIS\' wait_for_message', positive, 's')
