"""The READMEs and doc/ tell the truth: every command they show is run by a test,
every link resolves, the reference lists what the code offers, and the
Chinese README shows exactly the English one's commands."""
import ast
import glob
import os
import re
import subprocess
import sys
import warnings
import xml.etree.ElementTree as ElementTree

import pytest

from tb3_harness import readme
from tb3_sim_nav.params import PARAMETERS

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PAGES = ['README.md', 'README.zh-CN.md'] + sorted(os.path.relpath(path, ROOT)
                                                  for path in glob.glob(os.path.join(ROOT, 'doc', '*.md')))
# Where the commands of README.md are run: test code, and the two scripts that
# run what no test can run from inside `make test` (`make test` itself, and the
# rostests `catkin_make run_tests` runs).
SHELL_RUNNERS = ['.ci/run', 'tools/run_tests.sh']
READ_IN_FIVE_MINUTES = 1500  # words of prose (code and tables aside), at about 300 a minute


def _read(name):
    with open(os.path.join(ROOT, name), encoding='utf-8') as page:
        return page.read()


def _python_literals(path):
    """Every string literal of a python file that is not a docstring, each line of
    a multi-line one, and every list or tuple of string literals joined by spaces
    (an argv)."""
    with warnings.catch_warnings():  # a docstring's '\`' is not ours to judge here
        warnings.simplefilter('ignore', DeprecationWarning)
        tree = ast.parse(_read(path))
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and node.body:
            first = node.body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                docstrings.add(id(first.value))
    literals = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            literals.add(node.value)
            literals.update(line.strip() for line in node.value.split('\n'))
        elif isinstance(node, (ast.List, ast.Tuple)) and node.elts and all(
                isinstance(element, ast.Constant) and isinstance(element.value, str) for element in node.elts):
            literals.add(' '.join(element.value for element in node.elts))
    return literals


def _run_by(command, literals, shell_lines):
    return command in literals or any(command in line for line in shell_lines)


def test_every_command_the_readme_shows_is_run_by_a_test():
    literals = set()
    for path in glob.glob(os.path.join(ROOT, 'test', '**', '*.py'), recursive=True):
        literals |= _python_literals(path)
    shell_lines = [line for name in SHELL_RUNNERS for line in _read(name).split('\n')
                   if line.strip() and not line.lstrip().startswith('#')]
    shown = readme.commands(_read('README.md'))
    assert len(shown) >= 20, shown  # the parser finds the README's code blocks
    assert not [command for command in shown if not _run_by(command, literals, shell_lines)]


def test_the_chinese_readme_shows_exactly_the_english_commands():
    english, chinese = readme.commands(_read('README.md')), readme.commands(_read('README.zh-CN.md'))
    assert sorted(set(chinese)) == sorted(set(english))


@pytest.mark.parametrize('page', PAGES)
def test_every_link_resolves(page):
    text = _read(page)
    assert readme.links(text) or page.startswith('doc/'), 'no links found: the parser is broken'
    broken = []
    for target in readme.links(text):
        if re.match(r'[a-z]+://', target):
            continue  # the web is not checked from here
        path, _, anchor = target.partition('#')
        resolved = os.path.normpath(os.path.join(ROOT, os.path.dirname(page), path)) if path else \
            os.path.join(ROOT, page)
        if not os.path.exists(resolved):
            broken.append(target)
        elif anchor and anchor not in readme.anchors(_read(os.path.relpath(resolved, ROOT))):
            broken.append(target)
    assert not broken


def test_the_readme_reads_in_five_minutes():
    text = _read('README.md')
    code = set(number for number, _ in readme.code_lines(text))
    prose = [line for number, line in enumerate(text.split('\n'), 1)
             if number not in code and not line.startswith('|') and not line.startswith('![')]
    words = len(' '.join(prose).split())
    assert words <= READ_IN_FIVE_MINUTES, words


def test_the_readme_shows_the_two_commands_and_the_tutorials_commands():
    shown = readme.commands(_read('README.md'))
    for command in ('make demo', 'make test', 'roslaunch tb3_sim_bringup tb3_empty_world.launch',
                    'rosrun rviz rviz -d `rospack find tb3_sim_bringup`/rviz/demo.rviz',
                    "rostopic pub -r 10 /cmd_vel geometry_msgs/Twist '{linear: {x: 0.1, y: 0, z: 0}, "
                    "angular: {x: 0, y: 0, z: -0.5}}'",
                    "rostopic pub -1 /cmd_vel geometry_msgs/Twist '{}'",
                    'rosrun tb3_sim_nav timed_out_and_back.py', 'rosrun tb3_sim_nav odom_out_and_back.py',
                    'rosrun tb3_sim_nav nav_square.py', 'roslaunch tb3_sim_bringup tb3_teleop_key.launch'):
        assert command in shown, command


def test_the_ci_script_runs_the_readmes_test_command():
    assert 'make test' in _read('.ci/run')


def test_every_parameter_of_the_node_is_in_the_reference_table():
    table = _read('doc/reference.md')
    assert not [p.name for p in PARAMETERS if not re.search(r'`~%s`' % re.escape(p.name), table)]


def test_the_reference_parameter_table_is_the_generated_one():
    table = subprocess.run([sys.executable, os.path.join(ROOT, 'tools', 'params_table.py')],
                           stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    assert table.strip() in _read('doc/reference.md')


def test_the_reference_navigation_parameter_tables_are_the_generated_ones():
    tables = subprocess.run([sys.executable, os.path.join(ROOT, 'tools', 'params_table.py'), '--navigation'],
                            stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    reference = _read('doc/reference.md')
    missing = [table for table in tables.split('\n\n') if table.strip() and table.strip() not in reference]
    assert not missing, missing


@pytest.mark.parametrize('launch', sorted(os.listdir(os.path.join(ROOT, 'launch'))))
def test_every_launch_argument_is_documented(launch):
    root = ElementTree.parse(os.path.join(ROOT, 'launch', launch)).getroot()
    arguments = [arg for arg in root.findall('arg') if arg.get('default') is not None]
    assert not [arg.get('name') for arg in arguments if not arg.get('doc')]  # roslaunch --ros-args shows it
    docs = _read('README.md') + _read('doc/reference.md')
    assert not [arg.get('name') for arg in arguments if '`%s`' % arg.get('name') not in docs]
