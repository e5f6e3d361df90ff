"""The keyboard teleop's speeds (turtlebot3_teleop.keys): targets the keys set, held to each model's limits,
followed in half steps; its parameter; and turtlebot3_teleop_key.launch as roslaunch reads it. No ROS master.
(test/system/test_teleop.py types at the real node through a terminal.)"""
import os

import pytest
import roslaunch.config

from tb3_common.params import ParameterError
from turtlebot3_teleop.keys import LIMITS, Speeds, TeleopConfig

LAUNCH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'launch',
                      'turtlebot3_teleop_key.launch')


def typed(speeds, keys):
    return [speeds.press(key) for key in keys]


def test_keys_move_the_target_by_robotis_steps():
    speeds = Speeds('burger')
    assert typed(speeds, 'www') == ['speed'] * 3
    assert speeds.target_linear == 0.03   # exactly: rounded to the step
    typed(speeds, 'aad')
    assert speeds.target_angular == 0.1
    typed(speeds, 'xxxxx')
    assert speeds.target_linear == -0.02
    assert typed(speeds, 'q\x1b') == [None, None] and speeds.target_linear == -0.02


@pytest.mark.parametrize('model', sorted(LIMITS))
def test_targets_are_held_to_the_model_limits(model):
    speeds = Speeds(model)
    typed(speeds, 'w' * 40 + 'a' * 40)
    assert (speeds.target_linear, speeds.target_angular) == LIMITS[model]
    typed(speeds, 'x' * 80 + 'd' * 80)
    assert (speeds.target_linear, speeds.target_angular) == (-LIMITS[model][0], -LIMITS[model][1])
    assert LIMITS == {'burger': (0.22, 2.84), 'waffle': (0.26, 1.82), 'waffle_pi': (0.26, 1.82)}


def test_the_speed_sent_follows_the_target_in_half_steps():
    speeds = Speeds('burger')
    typed(speeds, 'ww' + 'a')
    sent = [speeds.step() for _ in range(5)]
    assert sent == [(0.005, 0.05), (0.01, 0.1), (0.015, 0.1), (0.02, 0.1), (0.02, 0.1)]


@pytest.mark.parametrize('key', ['s', ' '])
def test_a_stop_key_stops_at_once(key):
    speeds = Speeds('waffle')
    typed(speeds, 'wwww' + 'ddd')
    for _ in range(10):
        speeds.step()
    assert speeds.press(key) == 'stop'
    assert (speeds.target_linear, speeds.target_angular) == (0.0, 0.0)
    assert speeds.step() == (0.0, 0.0)


def test_the_model_parameter_is_one_of_the_three():
    assert TeleopConfig().model == 'burger' and TeleopConfig(model='waffle_pi').model == 'waffle_pi'
    with pytest.raises(ParameterError, match=r"model = 'turtlebot4': must be one of: burger, waffle, waffle_pi"):
        TeleopConfig(model='turtlebot4')


def test_the_launch_sets_model_where_robotis_node_reads_it(monkeypatch):
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'waffle')
    config = roslaunch.config.load_config_default([LAUNCH], None, verbose=False)
    node, = config.nodes
    assert (node.package, node.type, node.name, node.output) == (
        'turtlebot3_teleop', 'turtlebot3_teleop_key', 'turtlebot3_teleop_keyboard', 'screen')
    assert config.params['/model'].value == 'waffle'
