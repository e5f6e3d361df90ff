"""turtlebot3_remote.launch as roslaunch reads it (no master): ROBOTIS' arguments, robot_description of the
model (plain URDF: Debian has no xacro), one robot_state_publisher with ROBOTIS' rate and tf_prefix."""
import os

import pytest
import roslaunch.arg_dump
import roslaunch.config

LAUNCH = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'launch',
                      'turtlebot3_remote.launch')


@pytest.fixture(autouse=True)
def burger(monkeypatch):
    monkeypatch.setenv('TURTLEBOT3_MODEL', 'burger')


def test_robotis_arguments():
    args = roslaunch.arg_dump.get_args([LAUNCH])
    assert sorted(args) == ['model', 'multi_robot_name']
    assert args['model'] == ('model type [burger, waffle, waffle_pi]', 'burger') and args['multi_robot_name'][1] == ''


@pytest.mark.parametrize('args, model, prefix', [([], 'burger', ''),
                                                 (['model:=waffle', 'multi_robot_name:=tb3_1'], 'waffle', 'tb3_1')])
def test_description_and_one_robot_state_publisher(args, model, prefix):
    config = roslaunch.config.load_config_default([(LAUNCH, args)], None, verbose=False)
    node, = config.nodes
    assert (node.package, node.type, node.name) == ('robot_state_publisher', 'robot_state_publisher',
                                                    'robot_state_publisher')
    assert config.params['/robot_state_publisher/publish_frequency'].value == 50.0
    assert config.params['/robot_state_publisher/tf_prefix'].value == prefix
    urdf = config.params['/robot_description'].value
    assert '<robot name="turtlebot3_%s"' % model in urdf and 'base_scan' in urdf
