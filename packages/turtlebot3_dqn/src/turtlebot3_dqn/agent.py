"""ROBOTIS' DQN agent on PyTorch (Debian's python3-torch), without ROS.

The network, its initialisation and its learning are those of
turtlebot3_dqn_stage_N's ReinforceAgent (Keras): Dense 64 relu, Dense 64 relu,
Dropout 0.2, Dense 5 linear, LeCun-uniform weights and zero biases; mean
squared error, RMSprop (lr 0.00025, rho 0.9, epsilon 1e-6). A learning step
(trainModel) draws a batch from the memory, makes each transition's target
(its reward, plus the discounted best next Q unless it ended the episode, from
the network itself for the run's first `target_update` steps and from the
target network after), adds for each transition that ended an episode its
next state with the reward as the target of every action, and fits once
(Keras' fit: the rows shuffled, a step per 64 of them). ROBOTIS' per-sample
predict calls become one batch: the same numbers, 30 times fewer calls.

Every random draw has a source of its own, seeded from the agent's seed: the
same seed gives the same weights, actions, batches and dropout.
"""
import json
import random

import numpy as np
import torch

from .config import AgentConfig

#: One thread: the network is small, and the simulator needs the other core (timings: doc/speed.md).
torch.set_num_threads(1)


class Memory(object):
    """The replay memory (ROBOTIS' deque(maxlen=memory)): the newest `capacity` transitions, in arrays
    that grow as they fill (a deque is slow to index far from its ends)."""

    def __init__(self, capacity, state_size):
        self.capacity = capacity
        self.size = self.next = 0
        self._arrays = self._allocate(min(capacity, 4096), state_size)

    @staticmethod
    def _allocate(rows, state_size):
        return dict(state=np.zeros((rows, state_size), np.float32), action=np.zeros(rows, np.int64),
                    reward=np.zeros(rows, np.float32), next_state=np.zeros((rows, state_size), np.float32),
                    done=np.zeros(rows, bool))

    def __len__(self):
        return self.size

    def append(self, state, action, reward, next_state, done):
        rows = len(self._arrays['action'])
        if self.next == rows and rows < self.capacity:
            grown = self._allocate(min(self.capacity, 2 * rows), self._arrays['state'].shape[1])
            for name, array in self._arrays.items():
                grown[name][:rows] = array
            self._arrays = grown
        row = self.next
        for name, value in zip(('state', 'action', 'reward', 'next_state', 'done'),
                               (state, action, reward, next_state, done)):
            self._arrays[name][row] = value
        self.next = (row + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)

    def batch(self, rows):
        """(states, actions, rewards, next states, dones) of the transitions at `rows`, as tensors."""
        return tuple(torch.from_numpy(self._arrays[name][rows]) for name in
                     ('state', 'action', 'reward', 'next_state', 'done'))


class Network(torch.nn.Module):
    """Dense, relu, dense, relu, dropout, dense: ROBOTIS' model. Its dropout draws from a generator
    of its own, so that learning is reproducible whatever else uses torch's."""

    def __init__(self, state_size, action_size, hidden, dropout, weights, drops):
        """`weights`, `drops`: the torch.Generators of the initial weights and of the dropout."""
        super(Network, self).__init__()
        self.layers = torch.nn.ModuleList([torch.nn.Linear(state_size, hidden), torch.nn.Linear(hidden, hidden),
                                           torch.nn.Linear(hidden, action_size)])
        self.dropout, self.drops = dropout, drops
        with torch.no_grad():
            for layer in self.layers:  # Keras' lecun_uniform: U(-sqrt(3 / fan_in), +sqrt(3 / fan_in))
                limit = (3.0 / layer.in_features) ** 0.5
                layer.weight.uniform_(-limit, limit, generator=weights)
                layer.bias.zero_()

    def forward(self, states):
        hidden = torch.relu(self.layers[1](torch.relu(self.layers[0](states))))
        if self.training and self.dropout > 0.0:
            kept = torch.rand(hidden.shape, generator=self.drops) >= self.dropout
            hidden = hidden * kept / (1.0 - self.dropout)
        return self.layers[2](hidden)


class DqnAgent(object):
    """act(), remember(), learn() and end_episode() as ROBOTIS' agent does them; save() and load()."""

    def __init__(self, state_size, action_size=5, config=AgentConfig(), seed=None):
        self.state_size, self.action_size, self.config = state_size, action_size, config
        seeds = np.random.SeedSequence(None if seed is None or seed < 0 else seed).generate_state(3)
        self.random = random.Random(int(seeds[0]))  # exploration and the memory's draws
        weights = torch.Generator().manual_seed(int(seeds[1]))
        self._shuffle = torch.Generator().manual_seed(int(seeds[2]))  # fit's order, and dropout
        self.model, self.target_model = (Network(state_size, action_size, config.hidden, config.dropout, weights,
                                                 self._shuffle) for _ in range(2))
        self.update_target_model()
        self.optimizer = torch.optim.RMSprop(self.model.parameters(), lr=config.learning_rate, alpha=0.9, eps=1e-6)
        self.memory = Memory(config.memory, state_size)
        self.epsilon = config.epsilon
        self.steps = 0  # ROBOTIS' global_step: the run's steps so far (the trainer counts them)
        self.model.eval()
        self.target_model.eval()

    def q_values(self, state):
        with torch.no_grad():
            return self.model(torch.as_tensor(np.asarray(state, np.float32)[None]))[0].numpy()

    def act(self, state, greedy=False):
        """(action, the network's best Q of `state`): a random action with probability epsilon (unless
        `greedy`), else the best."""
        q = self.q_values(state)
        if not greedy and self.random.random() <= self.epsilon:
            return self.random.randrange(self.action_size), float(q.max())
        return int(np.argmax(q)), float(q.max())

    def remember(self, state, action, reward, next_state, done):
        self.memory.append(state, action, reward, next_state, done)

    def ready(self):
        """True once the memory holds train_start transitions (ROBOTIS learns from then on)."""
        return len(self.memory) >= self.config.train_start

    def learn(self, target=False):
        """One of ROBOTIS' trainModel: targets from the target network if `target`, else the network."""
        batch = self.config.batch_size
        states, actions, rewards, next_states, dones = self.memory.batch(self.random.sample(range(len(self.memory)),
                                                                                            batch))
        with torch.no_grad():
            if target:
                q, following = self.model(states), self.target_model(next_states)
            else:
                q, following = self.model(torch.cat((states, next_states))).split(batch)
            wanted = q.clone()
            rows = torch.arange(batch)
            wanted[rows, actions] = torch.where(dones, rewards,
                                                rewards + self.config.discount_factor * following.max(1).values)
        inputs, outputs = states, wanted
        if dones.any():  # ROBOTIS' extra row: the last state, every action worth the final reward
            inputs = torch.cat((inputs, next_states[dones]))
            outputs = torch.cat((outputs, rewards[dones][:, None].expand(-1, self.action_size)))
        order = torch.randperm(len(inputs), generator=self._shuffle)
        self.model.train()
        for start in range(0, len(inputs), batch):
            rows = order[start:start + batch]
            self.optimizer.zero_grad()
            loss = torch.mean((self.model(inputs[rows]) - outputs[rows]) ** 2)
            loss.backward()
            self.optimizer.step()
        self.model.eval()
        return float(loss)

    def update_target_model(self):
        self.target_model.load_state_dict(self.model.state_dict())

    def end_episode(self):
        """What ROBOTIS' agent does when an episode ends: the target network takes the network's
        weights, and epsilon decays (to epsilon_min)."""
        self.update_target_model()
        if self.epsilon > self.config.epsilon_min:
            self.epsilon *= self.config.epsilon_decay

    def save(self, stem, episode):
        """`stem`.pt (the weights) and `stem`.json ({"epsilon", "episode"}), as ROBOTIS' .h5 and .json."""
        torch.save(self.model.state_dict(), stem + '.pt')
        with open(stem + '.json', 'w') as stream:
            json.dump({'epsilon': self.epsilon, 'episode': episode}, stream)

    def load(self, stem):
        """The weights and epsilon saved at `stem`; the episode they were saved after."""
        self.model.load_state_dict(torch.load(stem + '.pt'))
        self.update_target_model()
        with open(stem + '.json') as stream:
            saved = json.load(stream)
        self.epsilon = float(saved['epsilon'])
        return int(saved['episode'])
