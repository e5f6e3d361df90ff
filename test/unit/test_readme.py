"""The README tells the truth about what the code offers."""
import os
import re
import xml.etree.ElementTree as ElementTree

from tb3_sim_nav.params import PARAMETERS

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _readme():
    with open(os.path.join(ROOT, 'README.md')) as readme:
        return readme.read()


def test_every_parameter_of_the_node_is_in_the_readme_table():
    table = _readme()
    missing = [p.name for p in PARAMETERS if not re.search(r'`~%s`' % re.escape(p.name), table)]
    assert not missing


def test_every_launch_argument_is_in_the_readme():
    readme = _readme()
    for launch in ('tb3_empty_world.launch', 'tb3_world.launch'):
        arguments = [arg.get('name') for arg in
                     ElementTree.parse(os.path.join(ROOT, 'launch', launch)).getroot().iter('arg')
                     if arg.get('default') is not None]
        assert arguments
        missing = [name for name in arguments if '`%s`' % name not in readme]
        assert not missing, (launch, missing)


def test_every_launch_argument_has_a_doc():
    for launch in os.listdir(os.path.join(ROOT, 'launch')):
        root = ElementTree.parse(os.path.join(ROOT, 'launch', launch)).getroot()
        undocumented = [arg.get('name') for arg in root.iter('arg')
                        if arg.get('default') is not None and not arg.get('doc')]
        assert not undocumented, (launch, undocumented)


def test_the_readme_shows_the_two_commands_and_the_tutorials_commands():
    readme = _readme()
    for command in ('make demo', 'make test', 'roslaunch tb3_sim_bringup tb3_empty_world.launch',
                    'rosrun rviz rviz -d `rospack find tb3_sim_bringup`/rviz/demo.rviz',
                    "rostopic pub -r 10 /cmd_vel geometry_msgs/Twist '{linear: {x: 0.1, y: 0, z: 0}, "
                    "angular: {x: 0, y: 0, z: -0.5}}'",
                    "rostopic pub -1 /cmd_vel geometry_msgs/Twist '{}'",
                    'rosrun tb3_sim_nav timed_out_and_back.py', 'rosrun tb3_sim_nav odom_out_and_back.py',
                    'rosrun tb3_sim_nav nav_square.py'):
        assert command in readme, command


def test_the_ci_script_runs_the_readmes_test_command():
    with open(os.path.join(ROOT, '.ci', 'run')) as ci:
        assert 'make test' in ci.read()


def test_the_readme_parameter_table_is_the_generated_one():
    import subprocess
    import sys
    table = subprocess.run([sys.executable, os.path.join(ROOT, 'tools', 'params_table.py')],
                           stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    assert table.strip() in _readme()
