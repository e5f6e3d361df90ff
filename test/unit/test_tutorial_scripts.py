"""The tutorial's scripts are shipped as the tutorial prints them.

test/data/tutorial_seed.txt is a copy of the tutorial page (seeds/000_1327880762fea54a.txt).
On that page each code block lost its layout: lines were joined without a separator and
their leading spaces dropped, though a few line breaks survived. Flattening a script
the same way must give the page's block exactly.
"""
import ast
import os
import py_compile

import pytest

START = '#!/usr/bin/env python'
END = 'rospy.loginfo("Out-and-Back node terminated.")'


def flatten(text):
    """Line breaks and leading indentation removed, trailing blanks kept (as on the page)."""
    return ''.join(line.lstrip() for line in text.splitlines())


def tutorial_block(repo, command):
    """The flattened code block that follows `command` on the tutorial page."""
    page = (repo / 'test' / 'data' / 'tutorial_seed.txt').read_text(encoding='utf-8')
    start = page.index(START, page.index(command))
    end = page.index(END, start) + len(END)
    return flatten(page[start:end])


@pytest.mark.parametrize('script', ['timed_out_and_back.py', 'odom_out_and_back.py'])
def test_script_equals_tutorial_code_block(repo, script):
    expected = tutorial_block(repo, 'rosrun tb3_sim_nav ' + script)
    shipped = flatten((repo / 'scripts' / script).read_text(encoding='utf-8'))
    assert shipped == expected


def test_tutorial_blocks_are_the_two_different_scripts(repo):
    timed = tutorial_block(repo, 'rosrun tb3_sim_nav timed_out_and_back.py')
    odom = tutorial_block(repo, 'rosrun tb3_sim_nav odom_out_and_back.py')
    assert timed != odom
    assert 'ticks = int(linear_duration * rate)' in timed
    assert 'self.tf_listener = tf.TransformListener()' in odom


@pytest.mark.parametrize('script', ['timed_out_and_back.py', 'odom_out_and_back.py', 'nav_square.py'])
def test_script_compiles_and_is_executable(repo, tmp_path, script):
    path = repo / 'scripts' / script
    py_compile.compile(str(path), cfile=str(tmp_path / (script + 'c')), doraise=True)
    assert os.access(str(path), os.X_OK), 'rosrun runs only executable files'


def test_nav_square_reads_its_private_parameters(repo):
    tree = ast.parse((repo / 'scripts' / 'nav_square.py').read_text(encoding='utf-8'))
    read = {node.args[0].value for node in ast.walk(tree)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and node.func.attr == 'get_param' and node.args
            and isinstance(node.args[0], ast.Constant)}
    assert {'~side', '~linear_speed', '~angular_speed', '~angular_tolerance'} <= read
